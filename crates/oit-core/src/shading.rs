//! Surfaces and lights: a mesh's material (shading mode, specular, opacity, texture), the
//! scene's directional lights and ambient term, their validation, angle-weighted vertex
//! normals, and the shading model in float64 for the reference. The WGSL twin is
//! `shaders/common/shading.wgsl`; the model is in docs/shading.md.

use glam::{DVec2, DVec3, DVec4};

use crate::error::{invalid, Result};

/// The most directional lights a scene holds (the frame uniform's light array).
pub const MAX_LIGHTS: u32 = 8;
/// A material's flags word: the `Shading` code in the low byte, then these bits.
pub const SHADING_MODE: u32 = 0xff;
pub const TWO_SIDED: u32 = 0x100;
pub const TEXTURED: u32 = 0x200;
/// Back faces (clockwise on screen) are not drawn: the vertex shader moves them off screen.
pub const CULL_BACK: u32 = 0x400;
/// The material has an emissive texture (multiplying its emissive color).
pub const EMISSIVE_TEXTURED: u32 = 0x800;
/// The material's alpha is tested against its cutoff (glTF's MASK).
pub const ALPHA_TEST: u32 = 0x4000;
/// A particle's falloff (`Falloff::code`) in bits 12 and 13: its alpha times a function of the
/// distance from its center (uv, the disc coordinates); 0 for every other surface.
pub const FALLOFF_SHIFT: u32 = 12;
pub const FALLOFF_MASK: u32 = 0x3000;

/// How a mesh's normal is found; `Unlit` keeps the vertex color (times texture and opacity).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Shading {
    #[default]
    Unlit,
    /// The triangle's geometric normal (counter-clockwise winding faces front).
    Flat,
    /// Vertex normals interpolated across the triangle and renormalized.
    Smooth,
    /// A strand's tangent (carried where other surfaces carry the normal) shades it:
    /// Kajiya and Kay's diffuse term with a half-vector highlight (docs/shading.md).
    Hair,
}

impl Shading {
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "unlit" => Ok(Self::Unlit),
            "flat" => Ok(Self::Flat),
            "smooth" => Ok(Self::Smooth),
            "hair" => Ok(Self::Hair),
            _ => Err(invalid!("shading must be 'unlit', 'flat', 'smooth' or 'hair', got '{name}'")),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Unlit => "unlit",
            Self::Flat => "flat",
            Self::Smooth => "smooth",
            Self::Hair => "hair",
        }
    }

    /// The code the shaders read (`SHADING_UNLIT`, `SHADING_FLAT`, `SHADING_SMOOTH`, `SHADING_HAIR`).
    pub fn code(self) -> u32 {
        self as u32
    }

    /// The material flags word of the shaders (`GpuMaterial::flags`).
    pub fn flags(material: &Material) -> u32 {
        material.shading.code()
            | if material.two_sided { TWO_SIDED } else { 0 }
            | if material.texture.is_some() { TEXTURED } else { 0 }
            | if material.cull_back_faces { CULL_BACK } else { 0 }
            | if material.emissive_texture.is_some() { EMISSIVE_TEXTURED } else { 0 }
            | if material.alpha_cutoff.is_some() { ALPHA_TEST } else { 0 }
            | material.falloff.code() << FALLOFF_SHIFT
    }
}

/// How a particle's alpha falls off from its center to its rim, as a factor of the distance
/// r from the center in radii (r > 1 is outside the disc: 0). `None` for every surface that is
/// not a particle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Falloff {
    #[default]
    None,
    /// 1 inside the disc.
    Hard,
    /// 1 - r.
    Linear,
    /// exp(-r² / (2σ²)) with σ = 1/3 (the rim at 3σ, where it is 0.011), cut at the rim.
    Gaussian,
}

impl Falloff {
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "hard" => Ok(Self::Hard),
            "linear" => Ok(Self::Linear),
            "gaussian" => Ok(Self::Gaussian),
            _ => Err(invalid!("falloff must be 'hard', 'linear' or 'gaussian', got '{name}'")),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Hard => "hard",
            Self::Linear => "linear",
            Self::Gaussian => "gaussian",
        }
    }

    pub fn code(self) -> u32 {
        self as u32
    }

    /// The factor at disc coordinates `uv` (the rim at |uv| = 1), and whether float32 may put
    /// the point on the other side of a hard rim (|uv| within 1e-5 of 1: an ambiguous pixel).
    pub fn factor(self, uv: DVec2) -> (f64, bool) {
        let r2 = uv.length_squared();
        let inside = r2 <= 1.0;
        match self {
            Self::None => (1.0, false),
            Self::Hard => (if inside { 1.0 } else { 0.0 }, (r2 - 1.0).abs() < 1e-5),
            Self::Linear => (if inside { 1.0 - r2.sqrt() } else { 0.0 }, false),
            Self::Gaussian => (if inside { (-4.5 * r2).exp() } else { 0.0 }, (r2 - 1.0).abs() < 1e-5),
        }
    }
}

/// How a texture coordinate outside [0, 1] is brought back (glTF's `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    #[default]
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

impl Wrap {
    /// glTF's code (10497, 33648, 33071).
    pub fn from_gltf(code: u32) -> Result<Self> {
        match code {
            10497 => Ok(Self::Repeat),
            33648 => Ok(Self::MirroredRepeat),
            33071 => Ok(Self::ClampToEdge),
            _ => Err(invalid!("wrap mode {code} is not 10497 (REPEAT), 33648 (MIRRORED_REPEAT) or 33071 (CLAMP_TO_EDGE)")),
        }
    }

    /// Texel `i` of a row of `n` brought into [0, n), as Vulkan's addressing does.
    pub fn texel(self, i: i64, n: i64) -> i64 {
        match self {
            Self::Repeat => i.rem_euclid(n),
            Self::ClampToEdge => i.clamp(0, n - 1),
            Self::MirroredRepeat => {
                let m = i.rem_euclid(2 * n);
                if m < n {
                    m
                } else {
                    2 * n - 1 - m
                }
            }
        }
    }

    fn code(self) -> u32 {
        self as u32
    }
}

/// Nearest or linear filtering (within a level, or between levels).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    Nearest,
    #[default]
    Linear,
}

/// How a texture is filtered and wrapped: glTF's sampler. The default (a glTF texture without a
/// sampler, and `Scene.add_mesh`'s textures) is repeat wrap and trilinear filtering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampler {
    pub wrap_u: Wrap,
    pub wrap_v: Wrap,
    /// Where a texel covers more than a pixel (level 0).
    pub mag: Filter,
    /// Where a pixel covers more than a texel, within the level chosen.
    pub min: Filter,
    /// Between mip levels; None samples level 0 only.
    pub mipmap: Option<Filter>,
}

impl Default for Sampler {
    fn default() -> Self {
        Self { wrap_u: Wrap::Repeat, wrap_v: Wrap::Repeat, mag: Filter::Linear, min: Filter::Linear, mipmap: Some(Filter::Linear) }
    }
}

impl Sampler {
    /// From glTF's codes: magFilter 9728 NEAREST / 9729 LINEAR; minFilter those or
    /// 9984..9987 (NEAREST_MIPMAP_NEAREST, LINEAR_MIPMAP_NEAREST, NEAREST_MIPMAP_LINEAR,
    /// LINEAR_MIPMAP_LINEAR); an absent filter is linear (with linear mips).
    pub fn from_gltf(mag: Option<u32>, min: Option<u32>, wrap_s: u32, wrap_t: u32) -> Result<Self> {
        use Filter::{Linear, Nearest};
        let mag = match mag {
            None | Some(9729) => Linear,
            Some(9728) => Nearest,
            Some(c) => return Err(invalid!("magFilter {c} is not 9728 (NEAREST) or 9729 (LINEAR)")),
        };
        let (min, mipmap) = match min {
            None => (Linear, Some(Linear)),
            Some(9728) => (Nearest, None),
            Some(9729) => (Linear, None),
            Some(9984) => (Nearest, Some(Nearest)),
            Some(9985) => (Linear, Some(Nearest)),
            Some(9986) => (Nearest, Some(Linear)),
            Some(9987) => (Linear, Some(Linear)),
            Some(c) => return Err(invalid!("minFilter {c} is not one of 9728, 9729, 9984, 9985, 9986, 9987")),
        };
        Ok(Self { wrap_u: Wrap::from_gltf(wrap_s)?, wrap_v: Wrap::from_gltf(wrap_t)?, mag, min, mipmap })
    }

    /// The bits the shaders read (`SAMPLER_*` in shaders/common/shading.wgsl): wrap u in bits
    /// 0-1, wrap v in 2-3, mag linear bit 4, min linear bit 5, mips on bit 6, linear mips bit 7.
    pub fn bits(&self) -> u32 {
        self.wrap_u.code()
            | self.wrap_v.code() << 2
            | u32::from(self.mag == Filter::Linear) << 4
            | u32::from(self.min == Filter::Linear) << 5
            | u32::from(self.mipmap.is_some()) << 6
            | u32::from(self.mipmap == Some(Filter::Linear)) << 7
    }
}

/// One level of a texture's mip chain: 8-bit RGBA texels, row-major.
#[derive(Clone, Debug)]
pub struct Level {
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
    levels: Vec<Level>,
}

/// 8-bit sRGB to linear in float64, from a table of the 256 codes built once (the reference reads
/// it for every texel it filters; `srgb_table` is the shaders' float32 copy).
fn srgb_decode(c: u8) -> f64 {
    static TABLE: std::sync::LazyLock<[f64; 256]> = std::sync::LazyLock::new(|| {
        std::array::from_fn(|c| {
            let c = c as f64 / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        })
    });
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
        let mut levels = vec![Level { width, height, texels }];
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
            levels.push(Level { width: w, height: h, texels });
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
    pub fn levels(&self) -> &[Level] {
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

/// What a mesh's surface looks like besides its vertex colors.
#[derive(Clone, Debug)]
pub struct Material {
    pub shading: Shading,
    pub specular: f32,
    pub shininess: f32,
    pub opacity: f32,
    pub two_sided: bool,
    /// Whether back faces (clockwise on screen, as wgpu's counter-clockwise front has it) are
    /// dropped, as glTF's `doubleSided: false` asks.
    pub cull_back_faces: bool,
    /// The base color texture: its color and alpha multiply the vertex color's.
    pub texture: Option<TextureMap>,
    /// Light the surface gives off, linear RGB (glTF's emissiveFactor times its strength; may
    /// exceed 1), added to the shaded color before it is clamped to [0, 1].
    pub emissive: [f32; 3],
    /// Multiplies `emissive` (sRGB color).
    pub emissive_texture: Option<TextureMap>,
    /// glTF's MASK: the alpha (vertex, texture, opacity) becomes 1 where it is at least the
    /// cutoff and 0 below, per fragment after filtering.
    pub alpha_cutoff: Option<f32>,
    /// A particle set's falloff (set by `Mesh::particles`; `None` for every other surface).
    pub falloff: Falloff,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            shading: Shading::Unlit,
            specular: 0.0,
            shininess: 32.0,
            opacity: 1.0,
            two_sided: true,
            cull_back_faces: false,
            texture: None,
            emissive: [0.0; 3],
            emissive_texture: None,
            alpha_cutoff: None,
            falloff: Falloff::None,
        }
    }
}

impl Material {
    pub fn validate(&self) -> Result<()> {
        if !(self.specular.is_finite() && self.specular >= 0.0) {
            return Err(invalid!("specular must be a finite number >= 0, got {}", self.specular));
        }
        if !(self.shininess.is_finite() && self.shininess > 0.0) {
            return Err(invalid!("shininess must be a finite number > 0, got {}", self.shininess));
        }
        if !(0.0..=1.0).contains(&self.opacity) {
            return Err(invalid!("opacity must be in [0, 1], got {}", self.opacity));
        }
        if self.emissive.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(invalid!("emissive must be finite linear RGB >= 0, got {:?}", self.emissive));
        }
        if self.alpha_cutoff.is_some_and(|c| !(0.0..=1.0).contains(&c)) {
            return Err(invalid!("alpha_cutoff must be in [0, 1], got {:?}", self.alpha_cutoff));
        }
        for map in [&self.texture, &self.emissive_texture].into_iter().flatten() {
            if map.transform.iter().flatten().any(|x| !x.is_finite()) {
                return Err(invalid!("a texture transform must be finite, got {:?}", map.transform));
            }
        }
        Ok(())
    }

    /// Whether the material leaves the vertex color as it is and every triangle drawn (today's
    /// unlit meshes): else the scene is drawn with its material table.
    pub fn is_plain(&self) -> bool {
        self.is_plain_surface() && self.falloff == Falloff::None
    }

    /// `is_plain` but for a particle set's falloff, which its primitive carries (scene files
    /// store it with the set, not with the surface).
    pub fn is_plain_surface(&self) -> bool {
        self.shading == Shading::Unlit
            && self.texture.is_none()
            && self.opacity == 1.0
            && !self.cull_back_faces
            && self.emissive == [0.0; 3]
            && self.alpha_cutoff.is_none()
    }
}

/// A directional light: `direction` is where the light travels (world space).
#[derive(Clone, Copy, Debug)]
pub struct Light {
    pub direction: [f32; 3],
    pub color: [f32; 3],
    pub intensity: f32,
}

impl Light {
    pub fn new(direction: [f32; 3], color: [f32; 3], intensity: f32) -> Result<Self> {
        let d = DVec3::from(direction.map(|x| x as f64));
        if !d.is_finite() || d.length() == 0.0 {
            return Err(invalid!("light direction {direction:?} must be finite and non-zero: it is where the light travels"));
        }
        if color.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(invalid!("light color {color:?} must be finite linear RGB >= 0"));
        }
        if !(intensity.is_finite() && intensity >= 0.0) {
            return Err(invalid!("light intensity must be a finite number >= 0, got {intensity}"));
        }
        Ok(Self { direction, color, intensity })
    }

    /// L (towards the light, unit) and color times intensity, as the shaders get them.
    pub fn to_light_radiance(&self) -> (DVec3, DVec3) {
        let d = DVec3::from(self.direction.map(|x| x as f64));
        (-d.normalize(), DVec3::from(self.color.map(|x| x as f64)) * self.intensity as f64)
    }
}

/// Unit normals from the caller (each renormalized); a zero or non-finite one is refused.
pub fn check_normals(normals: Vec<[f32; 3]>, n: usize) -> Result<Vec<[f32; 3]>> {
    if normals.len() != n {
        return Err(invalid!("normals has {} rows but positions has {n}: pass one normal per vertex", normals.len()));
    }
    normals
        .into_iter()
        .enumerate()
        .map(|(i, v)| {
            let d = DVec3::from(v.map(|x| x as f64));
            if !d.is_finite() || d.length() == 0.0 {
                return Err(invalid!("normals[{i}] = {v:?} is zero or not finite: pass unit vertex normals (or none to compute them)"));
            }
            Ok((d / d.length()).as_vec3().to_array())
        })
        .collect()
}

/// Angle-weighted vertex normals (each triangle adds its unit normal times its corner angle);
/// a vertex no proper triangle touches gets +z.
pub fn vertex_normals(positions: &[[f32; 3]], indices: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut sum = vec![DVec3::ZERO; positions.len()];
    let p = |i: u32| DVec3::from(positions[i as usize].map(|x| x as f64));
    for t in indices {
        let v = t.map(p);
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        if n.length() == 0.0 || !n.is_finite() {
            continue;
        }
        let n = n.normalize();
        for k in 0..3 {
            let (a, b) = (v[(k + 1) % 3] - v[k], v[(k + 2) % 3] - v[k]);
            let angle = a.angle_between(b);
            if angle.is_finite() {
                sum[t[k] as usize] += n * angle;
            }
        }
    }
    sum.iter().map(|s| if s.length() > 0.0 { s.normalize().as_vec3().to_array() } else { [0.0, 0.0, 1.0] }).collect()
}

/// The scene's lighting for one view: L and radiance per light, the ambient term.
#[derive(Clone, Debug)]
pub struct Lighting {
    pub lights: Vec<(DVec3, DVec3)>,
    pub ambient: DVec3,
}

impl Lighting {
    /// How many lights `new` gives for `lights`: them, or the headlight alone.
    pub fn count(lights: &[Light]) -> u32 {
        lights.len().max(1) as u32
    }

    /// `lights` (or, when there are none, one white headlight travelling along `view`, the
    /// unit direction of the ray through the middle of the view: `Camera::view_direction`) and
    /// `ambient`.
    pub fn new(lights: &[Light], ambient: [f32; 3], view: DVec3) -> Self {
        let lights = if lights.is_empty() { vec![(-view, DVec3::ONE)] } else { lights.iter().map(|l| l.to_light_radiance()).collect() };
        Self { lights, ambient: DVec3::from(ambient.map(|x| x as f64)) }
    }
}

/// How a triangle's UVs change along the frame's x and y (in pixels) at the NDC point `ndc`,
/// perspective-correct and exact: the triangle's clip-space corners `clip` and UVs `uv` give
/// its barycentrics at (px, py) as c / (c0 + c1 + c2), c = C0 - px Cx - py Cy (the cross
/// products of the corners' x, y and w), so each UV is a ratio of two planes in NDC, whose
/// derivative is exact. `size` is the frame in pixels. shaders/common/scene.wgsl
/// (`uv_planes`) and shading.wgsl (`uv_footprint`) compute the same in float32.
pub fn uv_footprint(clip: [DVec4; 3], uv: [DVec2; 3], ndc: DVec2, size: DVec2) -> (DVec2, DVec2) {
    let x = DVec3::new(clip[0].x, clip[1].x, clip[2].x);
    let y = DVec3::new(clip[0].y, clip[1].y, clip[2].y);
    let w = DVec3::new(clip[0].w, clip[1].w, clip[2].w);
    let (c0, cx, cy) = (x.cross(y), w.cross(y), x.cross(w));
    let plane = |f: DVec3| DVec3::new(f.dot(c0), f.dot(cx), f.dot(cy));
    let (pu, pv, pd) = (plane(DVec3::new(uv[0].x, uv[1].x, uv[2].x)), plane(DVec3::new(uv[0].y, uv[1].y, uv[2].y)), plane(DVec3::ONE));
    let at = |p: DVec3| p.x - ndc.x * p.y - ndc.y * p.z;
    let (nu, nv, d) = (at(pu), at(pv), at(pd));
    // d/dpx (n / d) = (-p.y d + n pd.y) / d², and likewise along py; then NDC to pixels.
    let along = |k: usize| {
        let (du, dv, dd) = (pu[k], pv[k], pd[k]);
        DVec2::new((-du * d + nu * dd) / (d * d), (-dv * d + nv * dd) / (d * d))
    };
    (along(1) * (2.0 / size.x), along(2) * (-2.0 / size.y))
}

/// One surface point for the model: interpolated color and the attributes it shades with.
pub struct Surface<'a> {
    pub color: DVec4,
    /// The shading normal before renormalization (interpolated or the face normal).
    pub normal: DVec3,
    pub uv: DVec2,
    /// How the UVs change to the pixel's neighbours across its 2 x 2 quad, along x and y (what
    /// dpdxFine and dpdyFine give the shaders): they choose a texture's mip level.
    pub duv_dx: DVec2,
    pub duv_dy: DVec2,
    /// Unit vector to the eye.
    pub to_eye: DVec3,
    pub material: &'a Material,
}

/// The model of docs/shading.md in float64; returns straight RGBA and whether N . V is so close
/// to 0 that float32 may turn the normal the other way (an ambiguous pixel).
pub fn shade(s: &Surface<'_>, lighting: &Lighting) -> (DVec4, bool) {
    let m = s.material;
    let mut base = s.color;
    let maps = [&m.texture, &m.emissive_texture];
    let mut ambiguous = maps.into_iter().flatten().any(|t| t.ambiguous(s.uv, s.duv_dx, s.duv_dy));
    if let Some(t) = &m.texture {
        base *= t.sample(s.uv, s.duv_dx, s.duv_dy);
    }
    base.w *= m.opacity as f64;
    let (falloff, rim) = m.falloff.factor(s.uv);
    ambiguous |= rim;
    base.w *= falloff;
    if let Some(cutoff) = m.alpha_cutoff {
        // float32 (and its UVs, a fraction of a pixel off) may land on the other side of the
        // cutoff: an ambiguous pixel.
        ambiguous |= (base.w - cutoff as f64).abs() < 2e-3;
        base.w = if base.w >= cutoff as f64 { 1.0 } else { 0.0 };
    }
    let mut emissive = DVec3::from(m.emissive.map(|x| x as f64));
    if let Some(t) = &m.emissive_texture {
        emissive *= t.sample(s.uv, s.duv_dx, s.duv_dy).truncate();
    }
    if m.shading == Shading::Unlit {
        return ((base.truncate() + emissive).clamp(DVec3::ZERO, DVec3::ONE).extend(base.w), ambiguous);
    }
    if m.shading == Shading::Hair {
        let lit = hair(base, s, lighting);
        return ((lit.truncate() + emissive).clamp(DVec3::ZERO, DVec3::ONE).extend(lit.w), ambiguous);
    }
    let mut n = s.normal.normalize();
    let nv = n.dot(s.to_eye);
    if m.two_sided && nv < 0.0 {
        n = -n;
    }
    let mut diffuse = lighting.ambient;
    let mut highlight = DVec3::ZERO;
    for &(l, radiance) in &lighting.lights {
        diffuse += radiance * n.dot(l).max(0.0);
        let h = (l + s.to_eye).normalize_or_zero();
        highlight += radiance * n.dot(h).max(0.0).powf(m.shininess as f64);
    }
    let rgb = (base.truncate() * diffuse + m.specular as f64 * highlight + emissive).clamp(DVec3::ZERO, DVec3::ONE);
    (rgb.extend(base.w), ambiguous || (m.two_sided && nv.abs() < 1e-5))
}

/// Kajiya and Kay's strand model with the tangent T (the surface's `normal`): diffuse
/// sin(T, L) = sqrt(1 - (T·L)²), and a highlight sin(T, H)^shininess with H the half vector of
/// L and V (docs/shading.md).
fn hair(base: DVec4, s: &Surface<'_>, lighting: &Lighting) -> DVec4 {
    let m = s.material;
    let t = s.normal.normalize();
    let sine = |c: f64| (1.0 - c * c).max(0.0).sqrt();
    let mut diffuse = lighting.ambient;
    let mut highlight = DVec3::ZERO;
    for &(l, radiance) in &lighting.lights {
        diffuse += radiance * sine(t.dot(l));
        let h = (l + s.to_eye).normalize_or_zero();
        let th = t.dot(h);
        highlight += radiance * (1.0 - th * th).max(0.0).powf(0.5 * m.shininess as f64);
    }
    (base.truncate() * diffuse + m.specular as f64 * highlight).clamp(DVec3::ZERO, DVec3::ONE).extend(base.w)
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
    fn wrap_modes_address_texels_as_vulkan_does() {
        let row = |w: Wrap| (-4..6).map(|i| w.texel(i, 3)).collect::<Vec<_>>();
        assert_eq!(row(Wrap::Repeat), [2, 0, 1, 2, 0, 1, 2, 0, 1, 2]);
        assert_eq!(row(Wrap::ClampToEdge), [0, 0, 0, 0, 0, 1, 2, 2, 2, 2]);
        assert_eq!(row(Wrap::MirroredRepeat), [2, 2, 1, 0, 0, 1, 2, 2, 1, 0]);
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
    fn angle_weighted_normals_of_a_cube_corner_point_along_the_diagonal() {
        // Three faces of a cube meeting at the origin, counter-clockwise seen from outside.
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let n = vertex_normals(&p, &[[0, 2, 1], [0, 1, 3], [0, 3, 2]]);
        let d = -1.0 / 3f32.sqrt();
        n[0].iter().for_each(|c| assert!((c - d).abs() < 1e-6, "{:?}", n[0]));
        assert_eq!(vertex_normals(&p, &[])[0], [0.0, 0.0, 1.0]);
    }

    #[test]
    fn bad_surfaces_are_refused_with_what_to_do() {
        let bad = |m: Material| m.validate().unwrap_err().to_string();
        assert!(bad(Material { specular: -1.0, ..Default::default() }).contains("specular"));
        assert!(bad(Material { shininess: 0.0, ..Default::default() }).contains("shininess"));
        assert!(bad(Material { opacity: 1.5, ..Default::default() }).contains("opacity"));
        assert!(Light::new([0.0; 3], [1.0; 3], 1.0).is_err());
        assert!(Light::new([0.0, 0.0, -1.0], [-1.0, 1.0, 1.0], 1.0).is_err());
        assert!(check_normals(vec![[0.0; 3]], 1).is_err());
        assert!(Texture::new(1, 1, vec![[2.0, 0.0, 0.0, 1.0]]).is_err());
    }

    #[test]
    fn the_model_lights_ambient_specular_and_two_sidedness() {
        let lighting = Lighting { lights: vec![(DVec3::Z, DVec3::splat(0.5))], ambient: DVec3::splat(0.1) };
        let m = Material { shading: Shading::Smooth, specular: 0.25, ..Default::default() };
        let s = |normal, material| Surface {
            color: DVec4::new(0.8, 0.6, 0.4, 0.5),
            normal,
            uv: DVec2::ZERO,
            duv_dx: DVec2::ZERO,
            duv_dy: DVec2::ZERO,
            to_eye: DVec3::Z,
            material,
        };
        let (front, _) = shade(&s(DVec3::Z, &m), &lighting);
        let want = DVec3::new(0.8, 0.6, 0.4) * 0.6 + 0.25 * 0.5;
        assert!((front.truncate() - want).abs().max_element() < 1e-15 && front.w == 0.5);
        // Facing away: two-sided turns it round, one-sided leaves the ambient term alone.
        assert_eq!(shade(&s(-DVec3::Z, &m), &lighting).0, front);
        let one = Material { two_sided: false, ..m.clone() };
        let (back, _) = shade(&s(-DVec3::Z, &one), &lighting);
        assert!((back.truncate() - DVec3::new(0.8, 0.6, 0.4) * 0.1).abs().max_element() < 1e-15);
    }
}
