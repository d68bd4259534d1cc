//! oit-viewer: an egui/eframe application that shows every oit-core method live, beside the
//! exact A-buffer. The binary (main.rs) parses the command line; the tests drive `ViewerApp`.

pub mod app;
pub mod args;
pub mod gpu;
pub mod heatmap;
pub mod load;
pub mod orbit;
pub mod panels;
pub mod scenefile;
pub mod screenshot;
pub mod view;

pub use app::{Compare, Settings, ViewMode, ViewerApp};
pub use args::Options;

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

/// Exports a built-in scene of the Python package into a temporary scene file and reads it.
pub fn builtin_scene(name: &str, alpha: Option<f32>) -> Result<scenefile::SceneData, String> {
    let python = std::env::var("OIT_PYTHON").unwrap_or_else(|_| "python3".into());
    let path = std::env::temp_dir().join(format!("oit-viewer-{}-{name}.oitscene", std::process::id()));
    let help = format!("run `python -m oit view --scene {name}` with the Python that has oit installed, or point OIT_PYTHON at it");
    let status = std::process::Command::new(&python)
        .args(["-m", "oit", "view", "--scene", name, "--export"])
        .arg(&path)
        .status()
        .map_err(|e| format!("could not run {python} to export the scene '{name}' ({e}): {help}"))?;
    if !status.success() {
        return Err(format!("`{python} -m oit view --scene {name} --export ...` failed ({status}): {help}"));
    }
    let data = load::load(&path, alpha);
    std::fs::remove_file(&path).ok();
    data
}
