//! The CPU float64 reference: a ray through each pixel center between the near and far
//! planes, every intersection found with a BVH (obvhs), sorted by depth and composited
//! front to back in f64; the nearest opaque hit ends the ray. Each hit is shaded with the
//! model of src/shading/model.rs at its ray barycentrics (perspective-correct). The edge and tie
//! rule is in docs/methods.md ("The reference").

use glam::{DMat3, DMat4, DVec2, DVec3, DVec4, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::{builder::build_bvh2, Bvh2};
use obvhs::ray::Ray;
use obvhs::{Boundable, BvhBuildParams};

use crate::error::{invalid, Result};
use crate::scene::{Camera, Scene};
use crate::shading::{self, Lighting, Material, Shading};

/// A pixel center closer than this to a triangle edge (in pixels) is ambiguous: the
/// rasterizer snaps vertices to 1/256 pixel, so its coverage there can differ.
pub const EDGE_PIXELS: f64 = 0.01;
/// Hits whose NDC depths differ by less than this may sort differently in float32.
pub const DEPTH_TIE: f64 = 4e-6;

pub struct ReferenceImage {
    pub width: u32,
    pub height: u32,
    /// Row-major (height, width, 4): final RGB and background coverage, in f64.
    pub image: Vec<f64>,
    /// Pixels where a GPU may legitimately differ (edge or depth tie), row-major.
    pub ambiguous: Vec<bool>,
    pub depth_complexity: Vec<u32>,
}

struct Tri {
    v: [DVec3; 3],
    c: [DVec4; 3],
    /// Shading normals (the face normal's for flat shading) and UVs of the corners.
    n: [DVec3; 3],
    uv: [DVec2; 3],
    mesh: usize,
    opaque: bool,
    /// Vertex positions in pixels when all three are in front of the eye (w > 0).
    screen: Option<[DVec2; 3]>,
    /// Whether the material culls back faces, and whether the triangle is one under the
    /// frame's camera (clockwise on screen: `back_facing`).
    cull: bool,
    back: bool,
    /// Whether the triangle's instance mirrors: its front faces are clockwise.
    mirror: bool,
    /// A ray-depth splat's quad: the Gaussian's world mean and inverse covariance (its hits
    /// take the depth of its peak along the ray, `splat::ray_depth`).
    peak: Option<(DVec3, DMat3)>,
}

struct Bounds(Aabb);

impl Boundable for Bounds {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

struct Hit {
    z: f64,
    /// The depth the opaque surfaces are tested against: `z`, or for a ray-depth splat its
    /// quad's (its mean's), as the rasterizer's depth test sees it.
    quad_z: f64,
    color: DVec4,
    opaque: bool,
}

fn to_pixels(vp: &DMat4, p: DVec3, w: f64, h: f64) -> Option<DVec2> {
    let c = *vp * p.extend(1.0);
    (c.w > 0.0).then(|| DVec2::new((c.x / c.w + 1.0) * 0.5 * w, (1.0 - c.y / c.w) * 0.5 * h))
}

/// Signed distances (pixels) from `p` to the three edges of the screen triangle, positive
/// inside. Each edge is evaluated from its endpoints in a fixed (lexicographic) order, so two
/// triangles sharing an edge get exactly opposite values and the top-left rule gives the
/// center to exactly one of them.
fn edge_distances(s: &[DVec2; 3], p: DVec2) -> [f64; 3] {
    let area = (s[1] - s[0]).perp_dot(s[2] - s[0]);
    let sign = if area >= 0.0 { 1.0 } else { -1.0 };
    let mut d = [0.0; 3];
    for i in 0..3 {
        let (a, b) = (s[i], s[(i + 1) % 3]);
        let (lo, hi, flip) = if (a.x, a.y) <= (b.x, b.y) { (a, b, 1.0) } else { (b, a, -1.0) };
        let len = (hi - lo).length().max(1e-300);
        d[i] = sign * flip * (hi - lo).perp_dot(p - lo) / len;
    }
    d
}

/// Whether a triangle is clockwise on screen, wgpu's back face: det[x y w] of its clip corners
/// is not positive, the vertex shader's test (`faces_front` in shaders/common/scene.wgsl).
fn back_facing(vp: &DMat4, v: &[DVec3; 3]) -> bool {
    let c = v.map(|p| *vp * p.extend(1.0));
    let [a, b, c] = c.map(|c| DVec3::new(c.x, c.y, c.w));
    glam::DMat3::from_cols(a, b, c).determinant() <= 0.0
}

/// Möller-Trumbore in f64 on the line o + t * d: returns (t, u, v) without range checks.
fn intersect(t: &Tri, o: DVec3, d: DVec3) -> Option<(f64, f64, f64)> {
    let e1 = t.v[1] - t.v[0];
    let e2 = t.v[2] - t.v[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - t.v[0];
    let q = s.cross(e1);
    Some((e2.dot(q) * inv, s.dot(p) * inv, d.dot(q) * inv))
}

/// Whether the pixel center is covered, with the rasterizer's top-left rule for centers
/// exactly on an edge (so that a shared edge is drawn once); `dist` from `edge_distances`.
fn covered(s: &[DVec2; 3], dist: &[f64; 3]) -> bool {
    let area = (s[1] - s[0]).perp_dot(s[2] - s[0]);
    (0..3).all(|i| {
        if dist[i] != 0.0 {
            return dist[i] > 0.0;
        }
        // Edge direction with the interior on its positive side (y grows downwards).
        let d = if area >= 0.0 { s[(i + 1) % 3] - s[i] } else { s[i] - s[(i + 1) % 3] };
        (d.y == 0.0 && d.x > 0.0) || d.y < 0.0
    })
}

fn key_less(a: &Hit, b: &Hit) -> std::cmp::Ordering {
    a.z.total_cmp(&b.z)
        .then(a.color.x.total_cmp(&b.color.x))
        .then(a.color.y.total_cmp(&b.color.y))
        .then(a.color.z.total_cmp(&b.color.z))
        .then(a.color.w.total_cmp(&b.color.w))
}

pub fn reference(scene: &Scene, camera: &Camera, width: u32, height: u32, background: [f64; 3]) -> Result<ReferenceImage> {
    reference_antialiased(scene, camera, width, height, background, 1)
}

/// The reference of an `antialias`-sample frame: the mean of the references at the standard
/// sample positions (`antialias::sample_offsets`), a pixel ambiguous where any of its samples
/// is, its depth complexity the largest of its samples'. The triangles and their BVH are
/// built once; only the screen positions follow the camera from sample to sample.
pub fn reference_antialiased(
    scene: &Scene,
    camera: &Camera,
    width: u32,
    height: u32,
    background: [f64; 3],
    antialias: u32,
) -> Result<ReferenceImage> {
    if width == 0 || height == 0 {
        return Err(invalid!("width and height must be positive, got {width} x {height}"));
    }
    let offsets = crate::antialias::sample_offsets(antialias)?;
    let mut tris = Vec::new();
    // Every instance's triangles in world space, in f64: positions by the transform, normals by
    // its inverse transpose (renormalized), colors times the instance's.
    for (mesh, (m, instances)) in scene.placed().enumerate() {
        for inst in instances {
            if m.primitive != crate::primitive::Primitive::Triangles {
                // Strands and particles: the triangles the vertex stage builds, in float64.
                let peaks = ray_peaks(m, inst);
                let corners = crate::primitive::expand(m, inst, camera, DVec2::new(width as f64, height as f64));
                for (j, c) in corners.chunks_exact(3).enumerate() {
                    let c = [c[0], c[1], c[2]];
                    let (v, c, n, uv) = (c.map(|k| k.position), c.map(|k| k.color), c.map(|k| k.tangent), c.map(|k| k.uv));
                    // Two triangles a splat.
                    let peak = peaks.get(j / 2).copied();
                    tris.push(Tri { v, c, n, uv, mesh, opaque: m.opaque, screen: None, cull: false, mirror: false, back: false, peak });
                }
                continue;
            }
            let nm = inst.normal_matrix();
            let factor = DVec4::from(inst.color.map(|x| x as f64));
            let carry = |n: DVec3| (nm * n).normalize_or_zero();
            for ix in &m.indices {
                let local = ix.map(|i| DVec3::from(m.positions[i as usize].map(|x| x as f64)));
                let v = ix.map(|i| inst.apply(m.positions[i as usize]));
                let c = ix.map(|i| DVec4::from(m.colors[i as usize].map(|x| x as f64)) * factor);
                let n = match m.material.shading {
                    Shading::Flat => [carry((local[1] - local[0]).cross(local[2] - local[0]).normalize()); 3],
                    _ if m.normals.is_empty() => [DVec3::ZERO; 3],
                    _ => ix.map(|i| carry(DVec3::from(m.normals[i as usize].map(|x| x as f64)))),
                };
                let uv = if m.uvs.is_empty() { [DVec2::ZERO; 3] } else { ix.map(|i| DVec2::from(m.uvs[i as usize].map(|x| x as f64))) };
                let cull = m.material.cull_back_faces;
                tris.push(Tri { v, c, n, uv, mesh, opaque: m.opaque, screen: None, cull, mirror: inst.mirrors(), back: false, peak: None });
            }
        }
    }
    let materials: Vec<&Material> = scene.meshes().iter().map(|m| &m.material).collect();
    let appearance = |camera: &Camera| Appearance { materials: &materials, lighting: scene.lighting(camera), shaded: scene.shaded() };
    // The BVH is f32: pad each box so that rounding cannot drop a triangle the f64 test hits,
    // and by a thousandth of the scene, so that a pixel center just outside a triangle (within
    // the edge margin, where the rasterizer's snapping may cover it) still reaches the edge test.
    let scene_lo = tris.iter().flat_map(|t| t.v).fold(DVec3::splat(f64::MAX), DVec3::min);
    let scene_hi = tris.iter().flat_map(|t| t.v).fold(DVec3::splat(f64::MIN), DVec3::max);
    let scene_pad = if tris.is_empty() { 0.0 } else { (scene_hi - scene_lo).max_element() * 1e-3 };
    let bounds: Vec<Bounds> = tris
        .iter()
        .map(|t| {
            let lo = t.v[0].min(t.v[1]).min(t.v[2]);
            let hi = t.v[0].max(t.v[1]).max(t.v[2]);
            let pad = ((hi - lo).max_element().max(lo.abs().max_element()).max(hi.abs().max_element()) * 1e-5).max(scene_pad) + 1e-30;
            Bounds(Aabb::new((lo - pad).as_vec3().into(), (hi + pad).as_vec3().into()))
        })
        .collect();
    let bvh = if tris.is_empty() { None } else { Some(build_bvh2(&bounds, BvhBuildParams::fast_build(), &mut Default::default())) };
    if offsets.len() == 1 {
        return Ok(trace_frame(&mut tris, bvh.as_ref(), camera, &appearance(camera), width, height, background));
    }
    let mut out: Option<ReferenceImage> = None;
    for offset in &offsets {
        let jittered = camera.jittered(*offset, width, height);
        let r = trace_frame(&mut tris, bvh.as_ref(), &jittered, &appearance(&jittered), width, height, background);
        match &mut out {
            None => out = Some(r),
            Some(o) => {
                o.image.iter_mut().zip(&r.image).for_each(|(a, b)| *a += b);
                o.ambiguous.iter_mut().zip(&r.ambiguous).for_each(|(a, b)| *a |= b);
                o.depth_complexity.iter_mut().zip(&r.depth_complexity).for_each(|(a, b)| *a = (*a).max(*b));
            }
        }
    }
    let mut out = out.expect("at least one sample");
    let n = offsets.len() as f64;
    out.image.iter_mut().for_each(|v| *v /= n);
    Ok(out)
}

/// A ray-depth splat set's Gaussians placed by `inst`: world mean and inverse covariance,
/// splat after splat (empty for any other set).
fn ray_peaks(m: &crate::Mesh, inst: &crate::Instance) -> Vec<(DVec3, DMat3)> {
    let crate::primitive::Primitive::Gaussians { scales, rotations, .. } = &m.primitive else { return Vec::new() };
    if m.material.splat_depth != crate::shading::SplatDepth::Ray {
        return Vec::new();
    }
    let linear = DMat3::from_mat4(inst.transform);
    let placed = |i: usize| {
        (inst.apply(m.positions[i]), (linear * crate::splat::covariance(scales[i], rotations[i]) * linear.transpose()).inverse())
    };
    (0..scales.len()).map(placed).collect()
}

/// What the hits are shaded with: each mesh's material, the lights under the frame's camera.
struct Appearance<'a> {
    materials: &'a [&'a Material],
    lighting: Lighting,
    /// Whether any mesh is shaded (else a hit keeps its interpolated color).
    shaded: bool,
}

/// One reference frame of the pixel centers under `camera`, through the scene's BVH.
fn trace_frame(
    tris: &mut [Tri],
    bvh: Option<&Bvh2>,
    camera: &Camera,
    appearance: &Appearance<'_>,
    width: u32,
    height: u32,
    background: [f64; 3],
) -> ReferenceImage {
    let vp = camera.view_proj;
    let inv = vp.inverse();
    let (wf, hf) = (width as f64, height as f64);
    for t in tris.iter_mut() {
        t.screen = match (to_pixels(&vp, t.v[0], wf, hf), to_pixels(&vp, t.v[1], wf, hf), to_pixels(&vp, t.v[2], wf, hf)) {
            (Some(a), Some(b), Some(c)) => Some([a, b, c]),
            _ => None,
        };
        t.back = t.cull && back_facing(&vp, &t.v) != t.mirror;
    }
    let tris = &*tris;
    let pixels = width as usize * height as usize;
    let mut image = vec![0.0f64; pixels * 4];
    let mut ambiguous = vec![false; pixels];
    let mut complexity = vec![0u32; pixels];
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(height as usize);
    // Bands of a few rows handed out one at a time: the deep middle of a frame does not leave
    // one thread working alone.
    const ROWS_PER_JOB: usize = 4;
    let rows_done = std::sync::atomic::AtomicUsize::new(0);
    let band = ROWS_PER_JOB * width as usize;
    let jobs =
        std::sync::Mutex::new(image.chunks_mut(4 * band).zip(ambiguous.chunks_mut(band)).zip(complexity.chunks_mut(band)).enumerate());
    std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                let (inv, rows_done, jobs) = (&inv, &rows_done, &jobs);
                s.spawn(move || loop {
                    let next = jobs.lock().unwrap_or_else(|p| p.into_inner()).next();
                    let Some((i, ((img, amb), cx))) = next else { break };
                    let row0 = i * ROWS_PER_JOB;
                    for (k, px) in amb.iter_mut().enumerate() {
                        let (row, col) = (row0 + k / width as usize, k % width as usize);
                        let (x, y) = ((col as f64 + 0.5) * 2.0 / wf - 1.0, 1.0 - (row as f64 + 0.5) * 2.0 / hf);
                        let center = DVec2::new(col as f64 + 0.5, row as f64 + 0.5);
                        let (o, end) = camera.unproject_segment(inv, x, y);
                        let d = end - o;
                        let mut hits: Vec<Hit> = Vec::new();
                        let mut edge = false;
                        if let Some(bvh) = bvh {
                            let ray = PixelRay { o, d, center, ndc: DVec2::new(x, y), size: DVec2::new(wf, hf) };
                            trace(bvh, tris, appearance, &ray, &vp, &mut hits, &mut edge);
                        }
                        let (rgba, n, tie) = composite(&mut hits, background);
                        img[4 * k..4 * k + 4].copy_from_slice(&rgba);
                        *px = edge || tie;
                        cx[k] = n;
                    }
                    rows_done.fetch_add(amb.len() / width as usize, std::sync::atomic::Ordering::Relaxed);
                })
            })
            .collect();
        report_progress(&workers, &rows_done, height as usize);
    });
    ReferenceImage { width, height, image, ambiguous, depth_complexity: complexity }
}

/// On a long run (past PROGRESS_AFTER), a line on stderr every PROGRESS_EVERY with the share of
/// rows done, until the workers finish.
fn report_progress<T>(workers: &[std::thread::ScopedJoinHandle<'_, T>], rows_done: &std::sync::atomic::AtomicUsize, rows: usize) {
    const PROGRESS_AFTER: std::time::Duration = std::time::Duration::from_secs(5);
    const PROGRESS_EVERY: std::time::Duration = std::time::Duration::from_secs(5);
    let start = std::time::Instant::now();
    let mut next = PROGRESS_AFTER;
    while !workers.iter().all(|w| w.is_finished()) {
        std::thread::sleep(std::time::Duration::from_millis(50));
        if start.elapsed() >= next {
            let done = rows_done.load(std::sync::atomic::Ordering::Relaxed);
            eprintln!(
                "oit reference: {done} of {rows} rows ({:.0} %), {:.0} s",
                100.0 * done as f64 / rows as f64,
                start.elapsed().as_secs_f64()
            );
            next += PROGRESS_EVERY;
        }
    }
}

/// The ray through one pixel center: from its near-plane point `o` along `d` to the far plane;
/// the center in pixels, in NDC, and the frame's size in pixels (for the UV footprint).
struct PixelRay {
    o: DVec3,
    d: DVec3,
    center: DVec2,
    ndc: DVec2,
    size: DVec2,
}

/// Every hit of `ray` into `hits`; `edge` set where the pixel is ambiguous.
fn trace(bvh: &Bvh2, tris: &[Tri], appearance: &Appearance<'_>, ray: &PixelRay, vp: &DMat4, hits: &mut Vec<Hit>, edge: &mut bool) {
    let PixelRay { o, d, center, ndc, size } = *ray;
    let to_eye = -d.normalize();
    let ray = Ray::new(Vec3A::from(o.as_vec3()), Vec3A::from(d.as_vec3()), -1e-3, 1.0 + 1e-3);
    bvh.ray_traverse_anyhit(ray, |_, id| {
        let t = &tris[bvh.primitive_indices[id] as usize];
        if t.back {
            return;
        }
        let Some((tt, u, v)) = intersect(t, o, d) else { return };
        let inside = match &t.screen {
            Some(s) => {
                let dist = edge_distances(s, center);
                if dist.iter().all(|&e| e > -EDGE_PIXELS) && dist.iter().any(|&e| e.abs() < EDGE_PIXELS) {
                    *edge = true;
                }
                covered(s, &dist)
            }
            None => {
                if u.min(v).min(1.0 - u - v).abs() < 1e-9 {
                    *edge = true;
                }
                u >= 0.0 && v >= 0.0 && u + v <= 1.0
            }
        };
        // Depth in [0, 1): the far plane itself is clipped, as the cleared depth buffer
        // (1.0) rejects it on the GPU.
        if inside && (0.0..1.0).contains(&tt) {
            let p = o + d * tt;
            let c = *vp * p.extend(1.0);
            let w = 1.0 - u - v;
            let mut color = t.c[0] * w + t.c[1] * u + t.c[2] * v;
            if appearance.shaded {
                let material = appearance.materials[t.mesh];
                let (duv_dx, duv_dy) = if material.texture.is_some() || material.emissive_texture.is_some() {
                    shading::uv_footprint(t.v.map(|p| *vp * p.extend(1.0)), t.uv, ndc, size)
                } else {
                    (DVec2::ZERO, DVec2::ZERO)
                };
                let surface = shading::SurfacePoint {
                    color,
                    normal: t.n[0] * w + t.n[1] * u + t.n[2] * v,
                    uv: t.uv[0] * w + t.uv[1] * u + t.uv[2] * v,
                    duv_dx,
                    duv_dy,
                    to_eye,
                    material,
                };
                let (shaded, grazing) = shading::shade(&surface, &appearance.lighting);
                color = shaded;
                *edge |= grazing;
            }
            let quad_z = c.z / c.w;
            let z = t.peak.map_or(quad_z, |(mean, precision)| crate::splat::ray_depth(vp, mean, &precision, o, d).0);
            hits.push(Hit { z, quad_z, color, opaque: t.opaque });
        }
    });
}

/// Front-to-back composite of the hits before the nearest opaque one. Returns the pixel,
/// the transparent depth complexity and whether two relevant depths nearly tie.
fn composite(hits: &mut [Hit], background: [f64; 3]) -> ([f64; 4], u32, bool) {
    hits.sort_by(key_less);
    let mut tie = hits.iter().any(|h| h.z.abs() < DEPTH_TIE || (1.0 - h.z).abs() < DEPTH_TIE);
    let opaque = hits.iter().position(|h| h.opaque);
    let end = opaque.unwrap_or(hits.len());
    for w in hits[..(end + 1).min(hits.len())].windows(2) {
        if (w[1].z - w[0].z).abs() < DEPTH_TIE && (w[0].color != w[1].color || w[0].opaque != w[1].opaque) {
            tie = true;
        }
    }
    // What the opaque surface hides: a hit behind it in the depth order, but a ray-depth
    // splat's by its quad's depth (the rasterizer's test), so that one in front by its quad
    // and behind by its peak is still composited, last but in its ray-depth order.
    let opaque_z = opaque.map_or(f64::INFINITY, |i| hits[i].z);
    let shown: Vec<&Hit> = hits
        .iter()
        .enumerate()
        .filter(|(k, h)| !h.opaque && if h.quad_z == h.z { *k < end } else { h.quad_z < opaque_z })
        .map(|(_, h)| h)
        .collect();
    tie |= hits.iter().any(|h| h.quad_z != h.z && (h.quad_z - opaque_z).abs() < DEPTH_TIE);
    tie |= shown.windows(2).any(|w| (w[1].z - w[0].z).abs() < DEPTH_TIE && w[0].color != w[1].color);
    let end = shown.len();
    let mut accum = DVec3::ZERO;
    let mut trans = 1.0f64;
    for h in shown {
        accum += trans * h.color.w * h.color.truncate();
        trans *= 1.0 - h.color.w;
    }
    let (behind, cover) = match opaque {
        Some(i) => (hits[i].color.truncate(), 1.0),
        None => (DVec3::from(background), 0.0),
    };
    let rgb = accum + trans * behind;
    ([rgb.x, rgb.y, rgb.z, 1.0 - trans * (1.0 - cover)], end as u32, tie)
}
