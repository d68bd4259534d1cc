//! Textures: 8-bit RGBA images with their mip chains, the sRGB transfer function, and a
//! texture as a material maps it (sampler and UV transform), sampled in float64 as the shaders
//! sample it.

use glam::{DVec2, DVec4};

use super::sampler::{Filter, Sampler, Wrap};
use crate::error::{invalid, Result};

/// One level of a texture's mip chain: 8-bit RGBA texels, row-major.
#[derive(Clone, Debug)]
pub struct MipLevel {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[u8; 4]>,
}

/// An image as every method and the reference sample it: 8-bit RGBA, row 0 at v = 0, the
/// color channels sRGB-encoded where `srgb` (alpha is linear), with its full mip chain
/// (each level half the one before, rounded down, at least 1; a texel the mean of the 2 x 2
/// (or fewer, at an odd edge) texels under it, in linear values, rounded to 8 bits).
#[derive(Clone, Debug)]
pub struct Texture {
    pub width: u32,
    pub height: u32,
    pub srgb: bool,
    levels: Vec<MipLevel>,
}

/// f32 or f64: the sRGB transfer function is written once and computed in either, each in its
/// own arithmetic (the loaders decode file colors in f32, the reference its texels in f64).
pub trait Real: Copy + PartialOrd + std::ops::Add<Output = Self> + std::ops::Div<Output = Self> {
    /// `x` rounded to this type.
    fn of(x: f64) -> Self;
    fn powf(self, e: Self) -> Self;
}

impl Real for f32 {
    fn of(x: f64) -> Self {
        x as f32
    }

    fn powf(self, e: Self) -> Self {
        f32::powf(self, e)
    }
}

impl Real for f64 {
    fn of(x: f64) -> Self {
        x
    }

    fn powf(self, e: Self) -> Self {
        f64::powf(self, e)
    }
}

/// An sRGB-encoded channel in [0, 1] to linear (IEC 61966-2-1).
pub fn srgb_to_linear<T: Real>(c: T) -> T {
    if c <= T::of(0.04045) {
        c / T::of(12.92)
    } else {
        ((c + T::of(0.055)) / T::of(1.055)).powf(T::of(2.4))
    }
}

/// 8-bit sRGB to linear in float64, from a table of the 256 codes built once (the reference reads
/// it for every texel it filters; `srgb_table` is the shaders' float32 copy).
fn srgb_decode(c: u8) -> f64 {
    static TABLE: std::sync::LazyLock<[f64; 256]> = std::sync::LazyLock::new(|| std::array::from_fn(|c| srgb_to_linear(c as f64 / 255.0)));
    TABLE[c as usize]
}

/// The linear value of each 8-bit sRGB code, in float32: what the shaders decode texels with.
pub fn srgb_table() -> [f32; 256] {
    std::array::from_fn(|c| srgb_decode(c as u8) as f32)
}

/// Linear in [0, 1] to the nearest 8-bit sRGB code.
fn srgb_encode(c: f64) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.0031308 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0).round() as u8
}

impl Texture {
    /// The largest side a texture may have (the device limit every adapter offers).
    pub const MAX_SIZE: u32 = 8192;

    /// An image of `width` x `height` 8-bit RGBA texels (`rgba` row-major, 4 bytes a texel),
    /// its color sRGB-encoded where `srgb`; builds the mip chain.
    pub fn from_rgba8(width: u32, height: u32, rgba: Vec<u8>, srgb: bool) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(invalid!("texture must have shape (h, w, 4) with h, w > 0, got ({height}, {width}, 4)"));
        }
        if width > Self::MAX_SIZE || height > Self::MAX_SIZE {
            return Err(invalid!(
                "texture of {width} x {height} is past the largest side a texture may have ({}): downscale it",
                Self::MAX_SIZE
            ));
        }
        if rgba.len() as u64 != 4 * width as u64 * height as u64 {
            return Err(invalid!("texture has {} bytes for {width} x {height} RGBA texels", rgba.len()));
        }
        let texels = bytemuck::cast_slice::<u8, [u8; 4]>(&rgba).to_vec();
        let mut levels = vec![MipLevel { width, height, texels }];
        let decode: [f64; 256] = std::array::from_fn(|c| if srgb { srgb_decode(c as u8) } else { c as f64 / 255.0 });
        while let Some(last) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
            let (w, h) = ((last.width / 2).max(1), (last.height / 2).max(1));
            let mut texels = Vec::with_capacity((w * h) as usize);
            for y in 0..h {
                for x in 0..w {
                    let xs = [2 * x, (2 * x + 1).min(last.width - 1)];
                    let ys = [2 * y, (2 * y + 1).min(last.height - 1)];
                    let mut sum = [0.0f64; 4];
                    for sy in ys {
                        for sx in xs {
                            let t = last.texels[(sy * last.width + sx) as usize];
                            (0..3).for_each(|i| sum[i] += decode[t[i] as usize]);
                            sum[3] += t[3] as f64 / 255.0;
                        }
                    }
                    let mean = sum.map(|v| v / 4.0);
                    let encode = |v: f64| if srgb { srgb_encode(v) } else { (v.clamp(0.0, 1.0) * 255.0).round() as u8 };
                    texels.push([encode(mean[0]), encode(mean[1]), encode(mean[2]), (mean[3] * 255.0).round() as u8]);
                }
            }
            levels.push(MipLevel { width: w, height: h, texels });
        }
        Ok(Self { width, height, srgb, levels })
    }

    /// From straight linear RGBA floats in [0, 1] (row-major): stored as 8-bit sRGB color and
    /// 8-bit alpha, each rounded to the nearest code (docs/shading.md).
    pub fn new(width: u32, height: u32, texels: Vec<[f32; 4]>) -> Result<Self> {
        if texels.len() as u64 != width as u64 * height as u64 {
            return Err(invalid!("texture has {} texels for {width} x {height}", texels.len()));
        }
        if let Some(i) = texels.iter().position(|t| t.iter().any(|x| !(0.0..=1.0).contains(x))) {
            let (y, x) = (i / width.max(1) as usize, i % width.max(1) as usize);
            return Err(invalid!(
                "texture[{y}, {x}] = {:?} is outside [0, 1] (or NaN): float textures are linear RGBA in [0, 1]",
                texels[i]
            ));
        }
        let rgba = texels
            .iter()
            .flat_map(|t| {
                [srgb_encode(t[0] as f64), srgb_encode(t[1] as f64), srgb_encode(t[2] as f64), (t[3] as f64 * 255.0).round() as u8]
            })
            .collect();
        Self::from_rgba8(width, height, rgba, true)
    }

    /// The mip chain, level 0 first.
    pub fn levels(&self) -> &[MipLevel] {
        &self.levels
    }

    /// Level 0 as straight linear RGBA floats (what `new` takes back to the same texels).
    pub fn linear_texels(&self) -> Vec<[f32; 4]> {
        let w = self.width as i64;
        (0..self.levels[0].texels.len() as i64).map(|i| self.texel(0, i % w, i / w).as_vec4().to_array()).collect()
    }

    /// Bytes on the GPU: 4 a texel, every level.
    pub fn bytes(&self) -> u64 {
        self.levels.iter().map(|l| 4 * l.texels.len() as u64).sum()
    }

    /// Whether some texel of level 0 has an alpha strictly between 0 and 1.
    pub fn has_partial_alpha(&self) -> bool {
        self.levels[0].texels.iter().any(|t| t[3] > 0 && t[3] < 255)
    }

    /// Texel (x, y) of `level` as linear RGBA.
    pub fn texel(&self, level: usize, x: i64, y: i64) -> DVec4 {
        let l = &self.levels[level];
        let t = l.texels[(y * l.width as i64 + x) as usize];
        let c = |i: usize| if self.srgb { srgb_decode(t[i]) } else { t[i] as f64 / 255.0 };
        DVec4::new(c(0), c(1), c(2), t[3] as f64 / 255.0)
    }

    /// `level` at `uv` with `filter` and the wrap modes, texel centers at (i + 1/2) / w.
    fn sample_level(&self, level: usize, uv: DVec2, filter: Filter, wrap: (Wrap, Wrap)) -> DVec4 {
        let l = &self.levels[level];
        let (w, h) = (l.width as i64, l.height as i64);
        let at = |x: i64, y: i64| self.texel(level, wrap.0.texel(x, w), wrap.1.texel(y, h));
        let p = uv * DVec2::new(w as f64, h as f64);
        if filter == Filter::Nearest {
            let f = p.floor();
            return at(f.x as i64, f.y as i64);
        }
        let p = p - 0.5;
        let f = p.floor();
        let t = p - f;
        let (x, y) = (f.x as i64, f.y as i64);
        let top = at(x, y) * (1.0 - t.x) + at(x + 1, y) * t.x;
        let bottom = at(x, y + 1) * (1.0 - t.x) + at(x + 1, y + 1) * t.x;
        top * (1.0 - t.y) + bottom * t.y
    }
}

/// A texture as a material uses it: the image (shared: uploaded once however many materials
/// use it), its sampler, and an affine map of the UVs (glTF's KHR_texture_transform):
/// uv' = transform * [u, v, 1].
#[derive(Clone, Debug)]
pub struct TextureMap {
    pub image: std::sync::Arc<Texture>,
    pub sampler: Sampler,
    pub transform: [[f32; 3]; 2],
}

/// The identity UV map.
pub const UV_IDENTITY: [[f32; 3]; 2] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

impl TextureMap {
    /// `image` with the default sampler and no UV transform.
    pub fn new(image: std::sync::Arc<Texture>) -> Self {
        Self { image, sampler: Sampler::default(), transform: UV_IDENTITY }
    }

    /// The level of detail λ = log2(ρ), ρ the larger of the texel-space lengths of the UV
    /// derivatives along x and y (after the transform): what the shaders compute from
    /// dpdxFine / dpdyFine.
    pub fn lod(&self, duv_dx: DVec2, duv_dy: DVec2) -> f64 {
        let size = DVec2::new(self.image.width as f64, self.image.height as f64);
        let (dx, dy) = (self.linear(duv_dx) * size, self.linear(duv_dy) * size);
        dx.length().max(dy.length()).log2()
    }

    fn linear(&self, d: DVec2) -> DVec2 {
        let m = self.transform.map(|r| r.map(|x| x as f64));
        DVec2::new(m[0][0] * d.x + m[0][1] * d.y, m[1][0] * d.x + m[1][1] * d.y)
    }

    /// Whether float32 may sample this point differently: within a thousandth of a pixel of a
    /// nearest filter's texel edge, or of a level of detail where the sampler switches level
    /// (nearest mips) or filter (magnification against minification).
    pub fn ambiguous(&self, uv: DVec2, duv_dx: DVec2, duv_dy: DVec2) -> bool {
        let s = &self.sampler;
        let lod = self.lod(duv_dx, duv_dy);
        let near = |x: f64, tol: f64| (x - x.round()).abs() < tol;
        let switch = (s.mag != s.min && lod.abs() < 1e-3) || (s.mipmap == Some(Filter::Nearest) && lod > 0.0 && near(lod + 0.5, 1e-3));
        let filter = if lod.is_nan() || lod <= 0.0 { s.mag } else { s.min };
        let edge = filter == Filter::Nearest && {
            let level = if lod > 0.0 && s.mipmap.is_some() { lod.max(0.0).round() as u32 } else { 0 };
            let size = DVec2::new((self.image.width >> level).max(1) as f64, (self.image.height >> level).max(1) as f64);
            let p = self.map_uv(uv) * size;
            let texels_a_pixel = 2f64.powf(lod.max(0.0)).max(1.0);
            near(p.x, 1e-3 * texels_a_pixel + 1e-4) || near(p.y, 1e-3 * texels_a_pixel + 1e-4)
        };
        switch || edge
    }

    /// The UVs after the transform.
    pub fn map_uv(&self, uv: DVec2) -> DVec2 {
        let m = self.transform.map(|r| r.map(|x| x as f64));
        DVec2::new(m[0][0] * uv.x + m[0][1] * uv.y + m[0][2], m[1][0] * uv.x + m[1][1] * uv.y + m[1][2])
    }

    /// Linear RGBA at `uv` for a pixel whose UVs change by `duv_dx` and `duv_dy` to its
    /// neighbours: level and filters as the sampler and Vulkan's rules choose them (λ <= 0
    /// magnifies from level 0; nearest mips round λ, ties down; linear mips blend floor(λ) and
    /// the next level), exactly as shaders/common/shading.wgsl does.
    pub fn sample(&self, uv: DVec2, duv_dx: DVec2, duv_dy: DVec2) -> DVec4 {
        let uv = self.map_uv(uv);
        let s = &self.sampler;
        let wrap = (s.wrap_u, s.wrap_v);
        let lod = self.lod(duv_dx, duv_dy);
        let top = self.image.levels.len() - 1;
        // λ <= 0, and NaN (a degenerate footprint), magnify, as the shaders' `!(lod > 0.0)`.
        if lod.is_nan() || lod <= 0.0 {
            return self.image.sample_level(0, uv, s.mag, wrap);
        }
        match s.mipmap {
            None => self.image.sample_level(0, uv, s.min, wrap),
            Some(Filter::Nearest) => {
                let level = ((lod + 0.5).ceil() - 1.0).clamp(0.0, top as f64) as usize;
                self.image.sample_level(level, uv, s.min, wrap)
            }
            Some(Filter::Linear) => {
                let base = lod.floor().min(top as f64);
                let level = base as usize;
                let t = if level == top { 0.0 } else { lod - base };
                let a = self.image.sample_level(level, uv, s.min, wrap);
                if t == 0.0 {
                    return a;
                }
                a * (1.0 - t) + self.image.sample_level(level + 1, uv, s.min, wrap) * t
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_centers_sample_exactly_and_wrap() {
        let t = Texture::from_rgba8(2, 1, vec![0, 0, 0, 255, 255, 128, 64, 128], false).unwrap();
        let map = TextureMap::new(std::sync::Arc::new(t));
        let at = |u: f64, v: f64| map.sample(DVec2::new(u, v), DVec2::ZERO, DVec2::ZERO);
        let (a, b) = (DVec4::new(0.0, 0.0, 0.0, 1.0), DVec4::new(1.0, 128.0 / 255.0, 64.0 / 255.0, 128.0 / 255.0));
        assert_eq!(at(0.25, 0.5), a);
        assert_eq!(at(0.75, 0.5), b);
        // Halfway between the last texel and the first (repeat wrap), and one period away.
        assert_eq!(at(1.0, 0.5), (a + b) * 0.5);
        assert_eq!(at(-0.75, 3.5), at(0.25, 0.5));
    }

    #[test]
    fn mips_halve_to_one_texel_and_levels_follow_the_footprint() {
        // A 4 x 2 checker of black and white: level 1 is 2 x 1 gray, level 2 one gray texel.
        let rgba: Vec<u8> = (0..8).flat_map(|i| if (i + i / 4) % 2 == 0 { [0, 0, 0, 255] } else { [255; 4] }).collect();
        let t = Texture::from_rgba8(4, 2, rgba, true).unwrap();
        assert_eq!(t.levels().iter().map(|l| (l.width, l.height)).collect::<Vec<_>>(), [(4, 2), (2, 1), (1, 1)]);
        assert_eq!(t.bytes(), 4 * (8 + 2 + 1));
        // The mean of black and white in linear light (0.5), stored as sRGB 188.
        assert_eq!(t.levels()[2].texels[0], [188, 188, 188, 255]);
        let map = TextureMap::new(std::sync::Arc::new(t));
        // One texel a pixel (λ = 0) magnifies level 0; four (λ = 2) reads the last level.
        let d = |texels: f64| DVec2::new(texels / 4.0, 0.0);
        assert_eq!(map.lod(d(1.0), DVec2::ZERO), 0.0);
        let gray = map.sample(DVec2::new(0.3, 0.2), d(4.0), DVec2::ZERO);
        assert!((gray.x - srgb_decode(188)).abs() < 1e-12, "{gray}");
        // Halfway between levels 1 and 2 (λ = 1.5) blends them equally.
        let mid = map.sample(DVec2::new(0.25, 0.5), d(2f64.powf(1.5)), DVec2::ZERO);
        assert!((mid.x - srgb_decode(188)).abs() < 1e-12, "{mid}");
    }

    #[test]
    fn float_textures_round_to_the_nearest_srgb_code_and_back() {
        let codes: Vec<u8> = (0..=255).collect();
        let texels = codes.iter().map(|&c| [srgb_decode(c) as f32, 0.0, 1.0, c as f32 / 255.0]).collect();
        let t = Texture::new(256, 1, texels).unwrap();
        assert!(t.levels()[0].texels.iter().zip(&codes).all(|(t, &c)| t[0] == c && t[3] == c));
    }

    #[test]
    fn one_srgb_decoding_gives_the_f32_and_f64_values_written_out_before() {
        // The two definitions this one replaced, each in its own arithmetic.
        let f32_formula = |c: f32| if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
        let f64_formula = |c: f64| if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
        for code in 0..=255u8 {
            let c = code as f32 / 255.0;
            assert_eq!(srgb_to_linear(c).to_bits(), f32_formula(c).to_bits(), "code {code}");
            assert_eq!(srgb_decode(code).to_bits(), f64_formula(code as f64 / 255.0).to_bits(), "code {code}");
        }
        // The constants round to the same f32 through f64, so every f32 input gives what it gave.
        for (wide, narrow) in [(0.04045, 0.04045f32), (12.92, 12.92), (0.055, 0.055), (1.055, 1.055), (2.4, 2.4)] {
            assert_eq!(f32::of(wide).to_bits(), narrow.to_bits());
        }
        // Every f32 between the codes too (the loaders decode file colors of any value).
        for k in 0..=(1u32 << 20) {
            let c = k as f32 / (1u32 << 20) as f32;
            assert_eq!(srgb_to_linear(c).to_bits(), f32_formula(c).to_bits(), "{c}");
        }
    }
}
