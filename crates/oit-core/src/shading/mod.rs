//! Surfaces and lights: a mesh's material (shading mode, specular, opacity, texture), the
//! scene's directional lights and ambient term, their validation, angle-weighted vertex
//! normals, and the shading model in float64 for the reference. The WGSL twin is
//! `shaders/common/shading.wgsl`; the model is in docs/shading.md.
//! Samplers (sampler.rs), textures and the sRGB transfer function (texture.rs) and the float64
//! model (model.rs) have files of their own.

mod model;
mod sampler;
mod texture;

use glam::{DVec2, DVec3};

use crate::error::{invalid, Result};

pub use model::{shade, uv_footprint, Lighting, SurfacePoint};
pub use sampler::{Filter, Sampler, Wrap};
pub use texture::{srgb_table, srgb_to_linear, MipLevel, Real, Texture, TextureMap, UV_IDENTITY};

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
pub const ALPHA_TEST: u32 = 0x8000;
/// A particle's or splat's falloff (`Falloff::code`) in bits 12 to 14: its alpha times a
/// function of the distance from its center (uv, the disc coordinates); 0 for every other surface.
pub const FALLOFF_SHIFT: u32 = 12;
pub const FALLOFF_MASK: u32 = 0x7000;
/// A splat set whose fragments take the depth of the Gaussian's peak along the pixel's ray
/// (`SplatDepth::Ray`) rather than its mean's.
pub const RAY_DEPTH: u32 = 0x10000;

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
            | if material.splat_depth == SplatDepth::Ray { RAY_DEPTH } else { 0 }
    }
}

/// The depth a splat's fragments sort and are tested at (docs/methods.md, "Gaussian splats").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SplatDepth {
    /// The mean's depth, one a splat (3DGS).
    #[default]
    Center,
    /// The depth of the Gaussian's peak along the pixel's ray, t* = dᵀΣ⁻¹(μ - o) / dᵀΣ⁻¹d
    /// (StopThePop, Radl et al. 2024): one a fragment (`splat::ray_peak`).
    Ray,
}

impl SplatDepth {
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "center" => Ok(Self::Center),
            "ray" => Ok(Self::Ray),
            _ => Err(invalid!("splat_depth must be 'center' or 'ray', got '{name}'")),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Center => "center",
            Self::Ray => "ray",
        }
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
    /// A Gaussian splat's (src/splat.rs): `Gaussian`'s factor, then the alpha it gives
    /// clamped as 3DGS does (`splat::clamp_alpha`). Set by `Mesh::gaussians` alone.
    Splat,
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
            Self::Splat => "splat",
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
            Self::Gaussian | Self::Splat => (if inside { (-4.5 * r2).exp() } else { 0.0 }, (r2 - 1.0).abs() < 1e-5),
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
    /// A splat set's fragment depth (set by `Mesh::gaussians` and its callers; `Center` for
    /// every other surface, where it means nothing).
    pub splat_depth: SplatDepth,
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
            splat_depth: SplatDepth::Center,
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
