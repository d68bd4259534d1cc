//! Strands and particles: meshes whose triangles the GPU builds from points, facing the
//! camera: a compute pass writes their corners once a frame (shaders/expand.wgsl) and the
//! vertex stage pulls them (shaders/common/primitives.wgsl). A strand set is polylines of
//! points with a width each, drawn as ribbons, two triangles a segment; a particle set is
//! centers with a radius each, drawn as discs on quads, two triangles a particle, whose alpha
//! falls off from the center (`Falloff`). The expansion is written once here in float64 for
//! the reference and `to_triangles`, and mirrored in WGSL (docs/methods.md, "Strands and
//! particles").

use glam::{DMat4, DVec2, DVec3, DVec4};

use crate::camera::Camera;
use crate::error::{invalid, Result};
use crate::mesh::{Instance, Mesh};
use crate::shading::{Falloff, Material, Shading};

pub use crate::mesh::{Primitive, PRIM_GAUSSIANS, PRIM_MESH, PRIM_PARTICLES, PRIM_STRANDS};

/// A strand segment's word: its first point within the chunk, and whether it is its strand's
/// first segment (no point before it) or last (no point after it).
pub const POINT_MASK: u32 = 0x3fff_ffff;
pub const FIRST_SEGMENT: u32 = 0x4000_0000;
pub const LAST_SEGMENT: u32 = 0x8000_0000;

/// `values` with one entry expanded to `n`, or one per splat.
fn one_each<T: Copy>(values: Vec<T>, n: usize, what: &str) -> Result<Vec<T>> {
    match values.len() {
        1 if n != 1 => Ok(vec![values[0]; n]),
        k if k == n => Ok(values),
        k => Err(invalid!("{what} has {k} rows for {n} splats: pass one per splat or a single one")),
    }
}

/// `values` with one entry expanded to `n`, checked finite and > 0.
fn per_point(mut values: Vec<f32>, n: usize, what: &str) -> Result<Vec<f32>> {
    if values.len() == 1 && n != 1 {
        values = vec![values[0]; n];
    }
    if values.len() != n {
        return Err(invalid!("{what} has {} entries for {n} points: pass one per point or a single value", values.len()));
    }
    if let Some(i) = values.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(invalid!("{what}[{i}] = {} must be a finite number > 0 (world units)", values[i]));
    }
    Ok(values)
}

impl Mesh {
    /// A strand set: `points` in strand order, `counts[i]` (>= 2) points in strand i, `widths`
    /// one per point or one for all (world units), `colors` one straight RGBA per point or one.
    pub fn strands(points: Vec<[f32; 3]>, counts: Vec<u32>, widths: Vec<f32>, colors: Vec<[f32; 4]>, opaque: bool) -> Result<Self> {
        let n = points.len();
        if let Some(i) = counts.iter().position(|&c| c < 2) {
            return Err(invalid!("counts[{i}] = {}: a strand needs at least two points", counts[i]));
        }
        let total: u64 = counts.iter().map(|&c| c as u64).sum();
        if total != n as u64 {
            return Err(invalid!("counts add up to {total} points but points has {n}: counts[i] is the number of points of strand i"));
        }
        if counts.iter().any(|&c| c > POINT_MASK) {
            return Err(invalid!("a strand has more than {POINT_MASK} points: split it"));
        }
        let widths = per_point(widths, n, "width")?;
        let mut mesh = Mesh::new(points, Vec::new(), colors, opaque)?;
        mesh.primitive = Primitive::Strands { counts, widths };
        Ok(mesh)
    }

    /// A particle set: a camera-facing disc at each of `centers`, `radii` one per particle or
    /// one for all (world units), `colors` one straight RGBA per particle or one, its alpha
    /// falling off as `falloff` says.
    pub fn particles(centers: Vec<[f32; 3]>, radii: Vec<f32>, colors: Vec<[f32; 4]>, opaque: bool, falloff: Falloff) -> Result<Self> {
        if falloff == Falloff::None {
            return Err(invalid!("particles need a falloff: 'hard', 'linear' or 'gaussian'"));
        }
        let radii = per_point(radii, centers.len(), "radius")?;
        let mut mesh = Mesh::new(centers, Vec::new(), colors, opaque)?;
        mesh.primitive = Primitive::Particles { radii };
        mesh.material.falloff = falloff;
        Ok(mesh)
    }

    /// A set of Gaussian splats (src/splat.rs): means, standard deviations along their axes
    /// (`scales`, > 0), wxyz `rotations` (any nonzero length), `opacities` in [0, 1] and RGB
    /// `colors` in [0, 1], each one per splat (or one for all).
    pub fn gaussians(
        means: Vec<[f32; 3]>,
        scales: Vec<[f32; 3]>,
        rotations: Vec<[f32; 4]>,
        opacities: Vec<f32>,
        colors: Vec<[f32; 3]>,
    ) -> Result<Self> {
        let n = means.len();
        let scales = one_each(scales, n, "scales")?;
        let rotations = one_each(rotations, n, "rotations")?;
        let opacities = one_each(opacities, n, "opacities")?;
        let colors = one_each(colors, n, "colors")?;
        if let Some(i) = scales.iter().position(|s| s.iter().any(|x| !(x.is_finite() && *x > 0.0))) {
            return Err(invalid!(
                "scales[{i}] = {:?}: standard deviations must be finite and > 0 (world units; a 3DGS file stores their logs)",
                scales[i]
            ));
        }
        if let Some(i) = rotations.iter().position(|q| q.iter().any(|x| !x.is_finite()) || q.iter().all(|&x| x == 0.0)) {
            return Err(invalid!("rotations[{i}] = {:?}: a rotation is a finite nonzero wxyz quaternion (normalized here)", rotations[i]));
        }
        if let Some(i) = opacities.iter().position(|o| !(0.0..=1.0).contains(o)) {
            return Err(invalid!(
                "opacities[{i}] = {} is outside [0, 1] (or NaN): a 3DGS file stores logits, pass their sigmoid",
                opacities[i]
            ));
        }
        let rgba = colors.iter().zip(&opacities).map(|(c, &o)| [c[0], c[1], c[2], o]).collect();
        let mut mesh = Mesh::new(means, Vec::new(), rgba, false)?;
        mesh.primitive = Primitive::Gaussians { scales, rotations, sh: Vec::new(), degree: 0 };
        mesh.material.falloff = Falloff::Splat;
        Ok(mesh)
    }

    /// Splats whose color is spherical harmonics of `degree` (0 to 3) in the view direction:
    /// `sh` holds (degree + 1)² RGB coefficients a splat, splat after splat, the DC first, as
    /// 3DGS stores them (color = 0.5 + Σ Y_lm(dir) c_lm clamped to [0, 1], `splat::sh_color`).
    pub fn gaussians_sh(
        means: Vec<[f32; 3]>,
        scales: Vec<[f32; 3]>,
        rotations: Vec<[f32; 4]>,
        opacities: Vec<f32>,
        sh: Vec<[f32; 3]>,
        degree: u32,
    ) -> Result<Self> {
        if degree > 3 {
            return Err(invalid!("sh degree {degree}: spherical harmonics of degree 0 to 3 (1, 4, 9 or 16 coefficients a splat)"));
        }
        let k = ((degree + 1) * (degree + 1)) as usize;
        if sh.len() != k * means.len() {
            return Err(invalid!(
                "sh has {} coefficients for {} splats: pass {k} RGB coefficients a splat (degree {degree})",
                sh.len(),
                means.len()
            ));
        }
        if let Some(i) = sh.iter().position(|c| c.iter().any(|x| !x.is_finite())) {
            return Err(invalid!("sh coefficient {} of splat {} is not finite", i % k, i / k));
        }
        let dc = sh.chunks_exact(k).map(|c| c[0].map(|x| (0.5 + crate::splat::SH_C0 * x as f64).clamp(0.0, 1.0) as f32)).collect();
        let mut mesh = Self::gaussians(means, scales, rotations, opacities, dc)?;
        if let Primitive::Gaussians { sh: s, degree: d, .. } = &mut mesh.primitive {
            (*s, *d) = (sh, degree);
        }
        Ok(mesh)
    }

    /// A strand, particle or splat set's surface: strands shade "unlit" or "hair" (from their
    /// tangent), particles and splats only "unlit". Opacity multiplies alpha.
    pub fn with_primitive_surface(mut self, shading: Shading, specular: f32, shininess: f32, opacity: f32) -> Result<Self> {
        let allowed = match self.primitive {
            Primitive::Triangles => return Err(invalid!("with_primitive_surface is for strands and particles: use with_surface")),
            Primitive::Strands { .. } => matches!(shading, Shading::Unlit | Shading::Hair),
            Primitive::Particles { .. } | Primitive::Gaussians { .. } => shading == Shading::Unlit,
        };
        if !allowed {
            let which = if matches!(self.primitive, Primitive::Strands { .. }) { "'unlit' or 'hair'" } else { "'unlit'" };
            return Err(invalid!("{} shade {which}, got '{}'", self.primitive.name(), shading.name()));
        }
        let material = Material {
            shading,
            specular,
            shininess,
            opacity,
            falloff: self.material.falloff,
            splat_depth: self.material.splat_depth,
            ..Default::default()
        };
        material.validate()?;
        self.material = material;
        Ok(self)
    }
}

/// The words of a strand set's segments (`FIRST_SEGMENT`, `LAST_SEGMENT`), first points
/// numbered from `base`.
pub fn segment_words(counts: &[u32], base: u32) -> Vec<u32> {
    let mut out = Vec::with_capacity(counts.iter().map(|&c| c as usize - 1).sum());
    let mut first = base;
    for &c in counts {
        for s in 0..c - 1 {
            let flags = if s == 0 { FIRST_SEGMENT } else { 0 } | if s == c - 2 { LAST_SEGMENT } else { 0 };
            out.push((first + s) | flags);
        }
        first += c;
    }
    out
}

/// One corner of an expanded triangle, world space: its position, color (times the
/// instance's), the strand's unit tangent (zero for particles) and the disc coordinates
/// (particles; zero for strands).
#[derive(Clone, Copy, Debug)]
pub struct Corner {
    pub position: DVec3,
    pub color: DVec4,
    pub tangent: DVec3,
    pub uv: DVec2,
}

/// Where a strand or particle corner's triangles sit among its segment's (particle's) six
/// corners: (end of the segment or v of the quad, side), the order the WGSL reads.
pub const CORNERS: [(u32, i32); 6] = [(0, -1), (0, 1), (1, -1), (1, -1), (0, 1), (1, 1)];

/// The homogeneous eye: the camera's center, or its view direction at infinity for an
/// orthographic camera (`inv_view_proj` times (0, 0, 1, 0): the point clip space sees at w = 0
/// on its axis).
fn eye(camera: &Camera) -> DVec4 {
    camera.view_proj.inverse().z_axis
}

/// From `p` towards the eye (not normalized): `E.xyz - p E.w`.
fn towards_eye(e: DVec4, p: DVec3) -> DVec3 {
    e.truncate() - p * e.w
}

/// The triangles of a strand or particle set placed by `inst` under `camera`, three corners
/// each in the drawn order (segment after segment, particle after particle; corners as
/// `CORNERS`). A triangle mesh has none: its triangles are its own. Splats depend on the
/// frame's `size` in pixels (their low-pass, src/splat.rs).
pub fn expand(m: &Mesh, inst: &Instance, camera: &Camera, size: DVec2) -> Vec<Corner> {
    let e = eye(camera);
    let color = |i: usize| DVec4::from(m.colors[i].map(|x| x as f64)) * DVec4::from(inst.color.map(|x| x as f64));
    let mut out = Vec::new();
    match &m.primitive {
        Primitive::Triangles => {}
        Primitive::Strands { counts, widths } => {
            let words = segment_words(counts, 0);
            let at = |i: u32| inst.apply(m.positions[i as usize]);
            for w in words {
                let first = w & POINT_MASK;
                let point = |end: u32| {
                    let i = first + end;
                    let prev = if end == 0 && w & FIRST_SEGMENT != 0 { i } else { i - 1 };
                    let next = if end == 1 && w & LAST_SEGMENT != 0 { i } else { i + 1 };
                    let p = at(i);
                    let t = at(next) - at(prev);
                    let side = t.cross(towards_eye(e, p));
                    let l2 = side.length_squared();
                    let half = widths[i as usize] as f64 * 0.5;
                    let side = if l2 > 1e-30 { side / l2.sqrt() * half } else { DVec3::ZERO };
                    (p, side, t.normalize_or_zero(), color(i as usize))
                };
                let ends = [point(0), point(1)];
                for (end, s) in CORNERS {
                    let (p, side, tangent, c) = ends[end as usize];
                    out.push(Corner { position: p + side * s as f64, color: c, tangent, uv: DVec2::ZERO });
                }
            }
        }
        Primitive::Particles { radii } => {
            // The camera's up (the world direction of clip y) orients the quads; only the
            // corners' alpha-free area depends on it.
            let up_hint = DMat4::transpose(&camera.view_proj).y_axis.truncate();
            for (i, &r) in radii.iter().enumerate() {
                let c = inst.apply(m.positions[i]);
                let (right, up) = disc_axes(towards_eye(e, c), up_hint);
                for (v, u) in CORNERS {
                    let uv = DVec2::new(u as f64, 2.0 * v as f64 - 1.0);
                    let position = c + (right * uv.x + up * uv.y) * r as f64;
                    out.push(Corner { position, color: color(i), tangent: DVec3::ZERO, uv });
                }
            }
        }
        Primitive::Gaussians { scales, rotations, sh, degree } => {
            let inv = camera.view_proj.inverse();
            let k = ((degree + 1) * (degree + 1)) as usize;
            let linear = glam::DMat3::from_mat4(inst.transform);
            for (i, (s, q)) in scales.iter().zip(rotations).enumerate() {
                let mean = inst.apply(m.positions[i]);
                let cov = linear * crate::splat::covariance(*s, *q) * linear.transpose();
                let f = crate::splat::footprint(mean, &cov, &camera.view_proj, size);
                let mut c = color(i);
                if !sh.is_empty() {
                    let rgb = crate::splat::sh_color(&sh[k * i..k * (i + 1)], crate::splat::view_direction(e, mean));
                    c = (rgb * DVec4::from(inst.color.map(|x| x as f64)).truncate()).extend(c.w);
                }
                for (v, u) in CORNERS {
                    let uv = DVec2::new(u as f64, 2.0 * v as f64 - 1.0);
                    // Behind the eye: a point, no fragments (the GPU's too).
                    let position = f.map_or(mean, |f| crate::splat::corner(&f, uv, &inv, size));
                    out.push(Corner { position, color: c, tangent: DVec3::ZERO, uv });
                }
            }
        }
    }
    out
}

/// Unit axes of the plane facing `d`: right = up_hint × d normalized (or x × d where the hint
/// is along d), up = d × right normalized.
fn disc_axes(d: DVec3, up_hint: DVec3) -> (DVec3, DVec3) {
    let d = d.normalize_or_zero();
    let mut right = up_hint.cross(d);
    if right.length_squared() <= 1e-30 {
        right = DVec3::X.cross(d);
    }
    let right = right.normalize_or_zero();
    (right, d.cross(right).normalize_or_zero())
}

/// A strand or particle set as a triangle mesh under `camera` (world space, its identity
/// placement): each triangle with its own three corners, the tangents as normals (what
/// `Shading::Hair` reads), the disc coordinates as UVs and the set's material, so that it
/// renders as the set does, on a frame of `size` pixels (splats' low-pass). A triangle mesh is
/// returned as it is.
pub fn to_triangles(m: &Mesh, camera: &Camera, size: DVec2) -> Mesh {
    if m.primitive == Primitive::Triangles {
        return m.clone();
    }
    let corners = expand(m, &Instance::IDENTITY, camera, size);
    let f = |v: DVec3| v.as_vec3().to_array();
    Mesh {
        positions: corners.iter().map(|c| f(c.position)).collect(),
        indices: (0..corners.len() as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
        colors: corners.iter().map(|c| c.color.as_vec4().to_array()).collect(),
        opaque: m.opaque,
        normals: if m.material.shading == Shading::Hair { corners.iter().map(|c| f(c.tangent)).collect() } else { Vec::new() },
        uvs: if m.material.falloff != Falloff::None { corners.iter().map(|c| c.uv.as_vec2().to_array()).collect() } else { Vec::new() },
        material: m.material.clone(),
        primitive: Primitive::Triangles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        // The eye at (0, 0, 3) looking down -z, 90 degrees, depth 0.1 .. 10 to [0, 1].
        let (n, f) = (0.1, 10.0);
        let rows = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, f / (n - f), n * f / (n - f)], [0.0, 0.0, -1.0, 0.0]];
        let proj = DMat4::from_cols_array_2d(&rows).transpose();
        Camera { view_proj: proj * DMat4::from_translation(DVec3::new(0.0, 0.0, -3.0)) }
    }

    #[test]
    fn segment_words_flag_each_strands_ends() {
        assert_eq!(segment_words(&[2, 3], 10), vec![10 | FIRST_SEGMENT | LAST_SEGMENT, 12 | FIRST_SEGMENT, 13 | LAST_SEGMENT]);
    }

    #[test]
    fn ribbons_share_their_joint_corners_and_face_the_eye() {
        let m = Mesh::strands(vec![[-1.0, 0.0, 0.0], [0.0, 0.2, 0.0], [1.0, 0.0, 0.0]], vec![3], vec![0.1], vec![[1.0; 4]], false).unwrap();
        let c = expand(&m, &Instance::IDENTITY, &camera(), DVec2::splat(100.0));
        assert_eq!(c.len(), 12);
        // Segment 0's far end (corners 2, 3, 5) is segment 1's near end (corners 6, 7, 10).
        assert_eq!(c[2].position, c[6].position);
        assert_eq!(c[5].position, c[10].position);
        for k in [0, 1] {
            let side = c[k].position - DVec3::new(-1.0, 0.0, 0.0);
            assert!((side.length() - 0.05).abs() < 1e-8);
            // Across the strand and across the view: the ribbon faces the eye.
            assert!(side.dot(DVec3::new(1.0, 0.2, 0.0)).abs() < 1e-8);
            let to_eye = DVec3::new(0.0, 0.0, 3.0) - DVec3::new(-1.0, 0.0, 0.0);
            assert!(side.dot(to_eye).abs() < 1e-8);
        }
    }

    #[test]
    fn particles_are_discs_facing_the_eye() {
        let m = Mesh::particles(vec![[0.5, 0.0, 0.0]], vec![0.25], vec![[1.0; 4]], false, Falloff::Linear).unwrap();
        let c = expand(&m, &Instance::IDENTITY, &camera(), DVec2::splat(100.0));
        let to_eye = (DVec3::new(0.0, 0.0, 3.0) - DVec3::new(0.5, 0.0, 0.0)).normalize();
        for k in &c {
            let off = k.position - DVec3::new(0.5, 0.0, 0.0);
            assert!(off.dot(to_eye).abs() < 1e-12);
            assert!((off.length() - 0.25 * 2f64.sqrt()).abs() < 1e-12);
        }
    }

    #[test]
    fn bad_sets_are_refused_with_what_to_do() {
        let bad = |r: Result<Mesh>| r.unwrap_err().to_string();
        assert!(bad(Mesh::strands(vec![[0.0; 3]; 3], vec![1, 2], vec![1.0], vec![[1.0; 4]], false)).contains("at least two points"));
        assert!(bad(Mesh::strands(vec![[0.0; 3]; 3], vec![2], vec![1.0], vec![[1.0; 4]], false)).contains("add up to 2"));
        assert!(bad(Mesh::strands(vec![[0.0; 3]; 2], vec![2], vec![0.0], vec![[1.0; 4]], false)).contains("> 0"));
        assert!(bad(Mesh::particles(vec![[0.0; 3]; 2], vec![1.0; 3], vec![[1.0; 4]], false, Falloff::Hard)).contains("3 entries"));
    }

    #[test]
    fn bad_gaussians_are_refused_with_what_to_do() {
        let g = |mean: [f32; 3], s: [f32; 3], q: [f32; 4], o: f32, n: usize| {
            Mesh::gaussians(vec![mean; 2], vec![s; n], vec![q], vec![o], vec![[1.0; 3]]).unwrap_err().to_string()
        };
        let (ok_s, ok_q) = ([1.0; 3], [1.0, 0.0, 0.0, 0.0]);
        assert!(g([f32::NAN, 0.0, 0.0], ok_s, ok_q, 0.5, 1).contains("not finite"));
        assert!(g([0.0; 3], [1.0, 0.0, 1.0], ok_q, 0.5, 1).contains("> 0"));
        assert!(g([0.0; 3], [1.0, f32::NAN, 1.0], ok_q, 0.5, 1).contains("> 0"));
        assert!(g([0.0; 3], ok_s, [0.0; 4], 0.5, 1).contains("nonzero"));
        assert!(g([0.0; 3], ok_s, ok_q, 1.5, 1).contains("[0, 1]"));
        assert!(g([0.0; 3], ok_s, ok_q, f32::NAN, 1).contains("[0, 1]"));
        assert!(g([0.0; 3], ok_s, ok_q, 0.5, 3).contains("3 rows for 2 splats"));
        let m = Mesh::gaussians(vec![[0.0; 3]; 2], vec![[1.0; 3]], vec![[2.0, 0.0, 0.0, 0.0]], vec![0.5], vec![[1.0; 3]]).unwrap();
        assert_eq!((m.triangle_count(), m.colors[1]), (4, [1.0, 1.0, 1.0, 0.5]));
    }
}
