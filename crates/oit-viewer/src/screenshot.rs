//! Screenshots: a `--screenshot` job or one the window asks for, the window picture taken when
//! the frames it waits for are drawn, and the 8-bit RGBA PNG written from it (what egui shows,
//! already sRGB).

use std::path::{Path, PathBuf};

use eframe::egui::{self, ColorImage};

use crate::ViewerApp;

/// `--screenshot`: after `frames` frames, grab the window, save it, and maybe quit.
#[derive(Clone, Debug)]
pub struct ScreenshotJob {
    pub path: PathBuf,
    pub frames: u32,
    pub crop_view: bool,
    pub exit: bool,
    requested: bool,
}

impl ScreenshotJob {
    pub fn new(path: PathBuf, frames: u32, crop_view: bool, exit: bool) -> Self {
        Self { path, frames, crop_view, exit, requested: false }
    }
}

impl ViewerApp {
    /// Saves the window picture of a finished screenshot request.
    pub(crate) fn take_screenshot(&mut self, ctx: &egui::Context) {
        let Some(job) = self.screenshot.as_mut() else { return };
        let events = ctx.input(|i| i.raw.events.clone());
        for e in events {
            let egui::Event::Screenshot { image, .. } = e else { continue };
            if let Some(err) = self.render_error.as_ref().filter(|_| job.exit) {
                // A picture of the error banner is no screenshot: fail as the command line does.
                eprintln!("oit-viewer: error: {err}");
                std::process::exit(1);
            }
            let ppp = ctx.pixels_per_point();
            let img = if job.crop_view { image.region(&self.view_rect, Some(ppp)) } else { (*image).clone() };
            let result = write_png(&job.path, &img);
            let ok = result.is_ok();
            let job = self.screenshot.take().expect("checked above");
            match result {
                Ok(()) => {
                    self.status = format!("saved {}", job.path.display());
                    println!("oit-viewer: wrote {} ({} x {})", job.path.display(), img.width(), img.height());
                }
                Err(e) => {
                    self.status = format!("screenshot failed: {e}");
                    eprintln!("oit-viewer: {}", self.status);
                }
            }
            if job.exit {
                if !ok {
                    std::process::exit(1);
                }
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
            return;
        }
        if job.frames > 0 {
            job.frames -= 1;
        } else if !job.requested {
            job.requested = true;
            ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(Default::default()));
        }
        ctx.request_repaint();
    }

    /// A screenshot of the window into the working directory, named by the time.
    pub fn request_screenshot(&mut self) {
        let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
        self.screenshot = Some(ScreenshotJob::new(PathBuf::from(format!("oit-viewer-{secs}.png")), 0, false, false));
    }
}

pub fn write_png(path: &Path, image: &ColorImage) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| fail(&e))?;
    }
    let [w, h] = image.size;
    let file = std::io::BufWriter::new(std::fs::File::create(path).map_err(|e| fail(&e))?);
    let mut enc = png::Encoder::new(file, w as u32, h as u32);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    // Unfiltered rows: tests/test_viewer.py reads them with zlib alone.
    enc.set_filter(png::Filter::NoFilter);
    let mut writer = enc.write_header().map_err(|e| fail(&e))?;
    // egui's pixels are premultiplied; screenshots are opaque, so unmultiplying is exact.
    let data: Vec<u8> = image.pixels.iter().flat_map(|p| p.to_srgba_unmultiplied()).collect();
    writer.write_image_data(&data).map_err(|e| fail(&e))?;
    writer.finish().map_err(|e| fail(&e))
}
