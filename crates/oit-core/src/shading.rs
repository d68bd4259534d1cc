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

/// Straight linear RGBA texels, row-major, row 0 at v = 0.
#[derive(Clone, Debug)]
pub struct Texture {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 4]>,
}

impl Texture {
    pub fn new(width: u32, height: u32, texels: Vec<[f32; 4]>) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(invalid!("texture must have shape (h, w, 4) with h, w > 0, got ({height}, {width}, 4)"));
        }
        if texels.len() as u64 != width as u64 * height as u64 {
            return Err(invalid!("texture has {} texels for {width} x {height}", texels.len()));
        }
        if let Some(i) = texels.iter().position(|t| t.iter().any(|x| !(0.0..=1.0).contains(x))) {
            let (y, x) = (i / width as usize, i % width as usize);
            return Err(invalid!(
                "texture[{y}, {x}] = {:?} is outside [0, 1] (or NaN): float textures are linear RGBA in [0, 1]",
                texels[i]
            ));
        }
        Ok(Self { width, height, texels })
    }

    fn texel(&self, x: i64, y: i64) -> DVec4 {
        let (w, h) = (self.width as i64, self.height as i64);
        let (x, y) = (x.rem_euclid(w), y.rem_euclid(h));
        DVec4::from(self.texels[(y * w + x) as usize].map(|c| c as f64))
    }

    /// Bilinear, repeat wrap, texel centers at (i + 1/2) / w: what `texture_sample` computes.
    pub fn sample(&self, uv: DVec2) -> DVec4 {
        let p = uv * DVec2::new(self.width as f64, self.height as f64) - 0.5;
        let f = p.floor();
        let t = p - f;
        let (x, y) = (f.x as i64, f.y as i64);
        let top = self.texel(x, y) * (1.0 - t.x) + self.texel(x + 1, y) * t.x;
        let bottom = self.texel(x, y + 1) * (1.0 - t.x) + self.texel(x + 1, y + 1) * t.x;
        top * (1.0 - t.y) + bottom * t.y
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
    pub texture: Option<Texture>,
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
        self.shading == Shading::Unlit && self.texture.is_none() && self.opacity == 1.0 && !self.cull_back_faces
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

/// One surface point for the model: interpolated color and the attributes it shades with.
pub struct Surface<'a> {
    pub color: DVec4,
    /// The shading normal before renormalization (interpolated or the face normal).
    pub normal: DVec3,
    pub uv: DVec2,
    /// Unit vector to the eye.
    pub to_eye: DVec3,
    pub material: &'a Material,
}

/// The model of docs/shading.md in float64; returns straight RGBA and whether N . V is so close
/// to 0 that float32 may turn the normal the other way (an ambiguous pixel).
pub fn shade(s: &Surface<'_>, lighting: &Lighting) -> (DVec4, bool) {
    let m = s.material;
    let mut base = s.color;
    if let Some(t) = &m.texture {
        base *= t.sample(s.uv);
    }
    base.w *= m.opacity as f64;
    let (falloff, rim) = m.falloff.factor(s.uv);
    base.w *= falloff;
    if m.shading == Shading::Unlit {
        return (base, rim);
    }
    if m.shading == Shading::Hair {
        return (hair(base, s, lighting), false);
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
    let rgb = (base.truncate() * diffuse + m.specular as f64 * highlight).clamp(DVec3::ZERO, DVec3::ONE);
    (rgb.extend(base.w), m.two_sided && nv.abs() < 1e-5)
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
        let t = Texture::new(2, 1, vec![[0.0, 0.0, 0.0, 1.0], [1.0, 0.5, 0.25, 0.5]]).unwrap();
        assert_eq!(t.sample(DVec2::new(0.25, 0.5)), DVec4::new(0.0, 0.0, 0.0, 1.0));
        assert_eq!(t.sample(DVec2::new(0.75, 0.5)), DVec4::new(1.0, 0.5, 0.25, 0.5));
        // Halfway between the last texel and the first (repeat wrap), and one period away.
        assert_eq!(t.sample(DVec2::new(1.0, 0.5)), DVec4::new(0.5, 0.25, 0.125, 0.75));
        assert_eq!(t.sample(DVec2::new(-0.75, 3.5)), t.sample(DVec2::new(0.25, 0.5)));
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
        let s = |normal, material| Surface { color: DVec4::new(0.8, 0.6, 0.4, 0.5), normal, uv: DVec2::ZERO, to_eye: DVec3::Z, material };
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
