//! The shading model of docs/shading.md in float64, for the reference: the lights under a
//! view, a surface point's attributes, and the UV footprint that picks a texture's level.

use glam::{DVec2, DVec3, DVec4};

use super::{Light, Material, Shading};

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
pub struct SurfacePoint<'a> {
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
pub fn shade(s: &SurfacePoint<'_>, lighting: &Lighting) -> (DVec4, bool) {
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
    if m.falloff == super::Falloff::Splat {
        let (alpha, cut) = crate::splat::clamp_alpha(base.w);
        (base.w, ambiguous) = (alpha, ambiguous | cut);
    }
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
fn hair(base: DVec4, s: &SurfacePoint<'_>, lighting: &Lighting) -> DVec4 {
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
    fn the_model_lights_ambient_specular_and_two_sidedness() {
        let lighting = Lighting { lights: vec![(DVec3::Z, DVec3::splat(0.5))], ambient: DVec3::splat(0.1) };
        let m = Material { shading: Shading::Smooth, specular: 0.25, ..Default::default() };
        let s = |normal, material| SurfacePoint {
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
