//! Turning frames into pictures: sRGB encoding, the error against the exact A-buffer and its
//! heatmap, the depth-complexity heatmap, and the split-screen composite.

use eframe::egui::{Color32, ColorImage};

/// The sRGB transfer function (IEC 61966-2-1) to 8 bits, as python/oit/imageio.py does it.
pub fn srgb8(linear: f32) -> u8 {
    let c = if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) as f64 };
    let s = if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0).round() as u8
}

/// A frame's RGB (linear, already over the background) as an opaque sRGB picture.
pub fn color_image(width: u32, height: u32, image: &[f32]) -> ColorImage {
    let pixels = image.chunks_exact(4).map(|p| Color32::from_rgb(srgb8(p[0]), srgb8(p[1]), srgb8(p[2]))).collect();
    ColorImage::new([width as usize, height as usize], pixels)
}

/// Inferno-like stops, sRGB: 0 is black, 1 is pale yellow.
const STOPS: [[u8; 3]; 7] = [[0, 0, 4], [40, 11, 84], [101, 21, 110], [159, 42, 99], [212, 72, 66], [245, 125, 21], [252, 255, 164]];

/// The colormap at t in [0, 1] (clamped).
pub fn colormap(t: f32) -> Color32 {
    let x = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) } * (STOPS.len() - 1) as f32;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let c: [u8; 3] = std::array::from_fn(|k| (STOPS[i][k] as f32 * (1.0 - f) + STOPS[i + 1][k] as f32 * f).round() as u8);
    Color32::from_rgb(c[0], c[1], c[2])
}

/// Per-pixel error of a frame against the exact one: the largest absolute difference of the
/// three linear color channels.
#[derive(Clone, Debug)]
pub struct ErrorMap {
    pub per_pixel: Vec<f32>,
    pub mean: f64,
    pub max: f32,
}

impl ErrorMap {
    pub fn new(image: &[f32], exact: &[f32]) -> Self {
        let per_pixel: Vec<f32> = image
            .chunks_exact(4)
            .zip(exact.chunks_exact(4))
            .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max))
            .collect();
        let mean = per_pixel.iter().map(|&e| e as f64).sum::<f64>() / per_pixel.len().max(1) as f64;
        let max = per_pixel.iter().copied().fold(0.0, f32::max);
        Self { per_pixel, mean, max }
    }

    /// Error `scale` and above is the top of the colormap.
    pub fn image(&self, width: u32, height: u32, scale: f32) -> ColorImage {
        let pixels = self.per_pixel.iter().map(|&e| colormap(e / scale.max(1e-9))).collect();
        ColorImage::new([width as usize, height as usize], pixels)
    }
}

/// Fragments per pixel, 0 to `max` over the colormap (0 stays black).
pub fn complexity_image(width: u32, height: u32, counts: &[u32], max: u32) -> ColorImage {
    let pixels = counts.iter().map(|&c| if c == 0 { Color32::BLACK } else { colormap(c as f32 / max.max(1) as f32) }).collect();
    ColorImage::new([width as usize, height as usize], pixels)
}

/// Left of `split` (a fraction of the width) from `left`, the rest from `right`, with a
/// one-pixel white divider.
pub fn split(left: &ColorImage, right: &ColorImage, split: f32) -> ColorImage {
    let [w, h] = left.size;
    let at = ((split.clamp(0.0, 1.0) * w as f32).round() as usize).min(w);
    let mut out = left.clone();
    for y in 0..h {
        let row = y * w;
        out.pixels[row + at..row + w].copy_from_slice(&right.pixels[row + at..row + w]);
        if at > 0 && at < w {
            out.pixels[row + at] = Color32::WHITE;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_matches_the_python_encoder() {
        // imageio.to_srgb8 of 0, 0.0031308, 0.2, 0.5, 1 (numpy, rint).
        assert_eq!([0.0, 0.0031308, 0.2, 0.5, 1.0].map(srgb8), [0, 10, 124, 188, 255]);
        assert_eq!(srgb8(f32::NAN), 0);
        assert_eq!(srgb8(2.0), 255);
    }

    #[test]
    fn error_map_mean_and_max() {
        let a = [0.5, 0.5, 0.5, 1.0, 0.0, 0.0, 0.0, 1.0];
        let b = [0.5, 0.7, 0.5, 1.0, 0.0, 0.0, 0.0, 0.0];
        let e = ErrorMap::new(&a, &b);
        assert!((e.max - 0.2).abs() < 1e-6 && (e.mean - 0.1).abs() < 1e-6);
        assert_eq!(e.image(2, 1, 0.2).pixels[1], colormap(0.0));
    }

    #[test]
    fn colormap_ends_and_split() {
        assert_eq!(colormap(0.0), Color32::from_rgb(0, 0, 4));
        assert_eq!(colormap(1.0), Color32::from_rgb(252, 255, 164));
        let l = ColorImage::filled([4, 2], Color32::RED);
        let r = ColorImage::filled([4, 2], Color32::BLUE);
        let s = split(&l, &r, 0.5);
        assert_eq!(s.pixels[..4], [Color32::RED, Color32::RED, Color32::WHITE, Color32::BLUE]);
    }
}
