//! Writing pictures: 8-bit RGBA PNG of what egui shows (already sRGB).

use std::path::Path;

use eframe::egui::ColorImage;

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
