//! `oit-viewer`: see `oit-viewer --help` and docs/viewer.md.

use eframe::egui;
use oit_viewer::{app::ScreenshotJob, args, gpu, load, ViewerApp};

fn fail(msg: &str, code: i32) -> ! {
    eprintln!("oit-viewer: error: {msg}");
    std::process::exit(code);
}

fn main() {
    // The Vulkan loader's window-system code complains when XDG_RUNTIME_DIR is unset (CI,
    // xvfb-run); a private directory keeps it quiet, as the Python package does.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        let dir = std::env::temp_dir().join(format!("oit-runtime-{}", std::process::id()));
        if std::fs::create_dir_all(&dir).is_ok() {
            std::env::set_var("XDG_RUNTIME_DIR", dir);
        }
    }
    let o = match args::parse(std::env::args().skip(1)) {
        Ok(Some(o)) => o,
        Ok(None) => {
            println!("{}", args::USAGE);
            return;
        }
        Err(e) => fail(&format!("{e}\n{}", args::USAGE), 2),
    };
    let settings = oit_viewer::settings(&o).unwrap_or_else(|e: String| fail(&e, 2));
    let data = load::load_all(&o.files, o.alpha).unwrap_or_else(|e: String| fail(&e, 2));
    let title: Vec<String> = o.files.iter().filter_map(|f| f.file_name()).map(|f| f.to_string_lossy().into_owned()).collect();
    let title = title.join(", ");
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default().with_inner_size(o.size).with_title(format!("oit viewer: {title}")),
        wgpu_options: eframe::egui_wgpu::WgpuConfiguration { wgpu_setup: gpu::setup(o.adapter.clone(), false), ..Default::default() },
        ..Default::default()
    };
    let result = eframe::run_native(
        "oit-viewer",
        options,
        Box::new(move |cc| {
            let mut app = ViewerApp::new(cc, data, settings, title);
            app.show_panel = !o.hide_panel;
            if let Some(path) = o.screenshot.clone() {
                app.screenshot = Some(ScreenshotJob::new(path, o.frames, o.crop_view, true));
            }
            Ok(Box::new(app))
        }),
    );
    if let Err(e) = result {
        fail(&format!("{e} (a window needs a display: under no display, run it with xvfb-run)"), 1);
    }
}
