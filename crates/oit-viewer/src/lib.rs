//! oit-viewer: an egui/eframe application that shows every oit-core method live, beside the
//! exact A-buffer. The binary (main.rs) parses the command line; the tests drive `ViewerApp`.

pub mod app;
pub mod args;
pub mod gpu;
pub mod heatmap;
pub mod load;
pub mod native;
pub mod orbit;
pub mod panels;
pub mod scenefile;
pub mod screenshot;
pub mod state;
pub mod view;
mod window;

pub use app::ViewerApp;
pub use args::Options;
pub use state::{Action, Compare, Settings, ViewMode};

/// The settings the command line asks for, with the method and parameters checked.
pub fn settings(o: &Options) -> Result<Settings, String> {
    let info = oit_core::method::lookup(&o.method).map_err(|e| e.to_string())?;
    info.resolve_params(&o.params).map_err(|e| e.to_string())?;
    let mut s = Settings::new(&o.method);
    for (k, v) in &o.params {
        s.set_param(k, v.clone());
    }
    s.background = o.background;
    s.compare = o.compare;
    s.view = o.view;
    Ok(s)
}
