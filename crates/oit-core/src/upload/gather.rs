//! Chunk contents on the host while they are gathered: a mesh's vertices and indices, a strand
//! or particle set's points, and flat-shaded meshes split into corners; the segments that say
//! where a mesh's triangles went.

use crate::error::{OitError, Result};
use crate::primitive::{self, Primitive, PRIM_GAUSSIANS, PRIM_MESH, PRIM_PARTICLES, PRIM_STRANDS};
use crate::scene::Mesh;

/// Floats of `positions` a splat (shaders/common/primitives.wgsl reads them).
pub const SPLAT_FLOATS: u32 = 12;

/// A mesh's triangles within one chunk: local triangles `lo .. hi`.
#[derive(Clone, Copy, Debug)]
pub struct Segment {
    pub chunk: usize,
    pub lo: u32,
    pub hi: u32,
}

/// Chunk contents on the host while they are gathered. A chunk of strands or particles
/// (`kind`) holds one set's points (x, y, z and half the width or the radius; a splat's mean,
/// 0, then its covariance's upper triangle and two zeros: `SPLAT_FLOATS`), their colors,
/// and for strands a word a segment (`primitive::segment_words`) where a mesh chunk has its
/// indices; the set's material is the chunk's.
#[derive(Default)]
pub(super) struct Gather {
    pub positions: Vec<f32>,
    pub colors: Vec<[f32; 4]>,
    pub indices: Vec<u32>,
    /// Two a vertex where the scene is shaded, else none.
    pub attributes: Vec<[f32; 4]>,
    pub first_triangle: u32,
    pub shaded: bool,
    pub kind: u32,
    pub material: u32,
    /// A set's first row of the instance table (0 without instances) and its instance count:
    /// `expanded` holds its corners once an instance.
    pub set_instance: u32,
    pub set_instances: u32,
    /// A splat set's spherical-harmonic coefficients a splat (0: none, its colors).
    pub splat_sh: u32,
}

impl Gather {
    pub fn vertices(&self) -> u64 {
        self.colors.len() as u64
    }

    pub fn triangles(&self) -> u32 {
        match self.kind {
            PRIM_STRANDS => 2 * self.indices.len() as u32,
            PRIM_PARTICLES | PRIM_GAUSSIANS => 2 * self.colors.len() as u32,
            _ => (self.indices.len() / 3) as u32,
        }
    }

    /// The next chunk after this one, of `kind` with `material`: a set's next chunk keeps its
    /// instances, a mesh chunk has none of its own.
    pub fn next(&self, kind: u32, material: u32) -> Gather {
        let (set_instance, set_instances) = if kind == PRIM_MESH { (0, 0) } else { (self.set_instance, self.set_instances) };
        Gather {
            splat_sh: if kind == PRIM_MESH { 0 } else { self.splat_sh },
            first_triangle: self.first_triangle + self.triangles(),
            shaded: self.shaded,
            kind,
            material,
            set_instance,
            set_instances,
            ..Default::default()
        }
    }

    /// Vec4 of `expanded` a point (an instance): two corners and a tangent a strand point, four
    /// corners a particle (shaders/common/primitives.wgsl).
    pub fn expanded_per_point(&self) -> u64 {
        match self.kind {
            PRIM_STRANDS => 3,
            PRIM_PARTICLES | PRIM_GAUSSIANS => 4,
            _ => 0,
        }
    }

    /// Floats of `positions` a point: four, a splat's `SPLAT_FLOATS`.
    fn point_floats(&self) -> u64 {
        if self.kind == PRIM_GAUSSIANS {
            SPLAT_FLOATS as u64 + 3 * self.splat_sh as u64
        } else {
            4
        }
    }

    /// Whether `points` more points and `segments` more segment words fit `max` bytes each,
    /// their corners too, and one dispatch of the expansion (65,535 groups of 64 in x).
    pub fn room_points(&self, points: u64, segments: u64, max: u64) -> bool {
        let v = self.vertices() + points;
        let units = if self.kind == PRIM_STRANDS { self.indices.len() as u64 + segments } else { v };
        v * self.point_floats() * 4 <= max
            && units * 4 <= max
            && v * self.expanded_per_point() * 16 * self.set_instances.max(1) as u64 <= max
            && units <= 65_535 * 64 * 65_535
            && v <= primitive::POINT_MASK as u64
    }

    /// Points `range` of `m` (one strand, or particles) with their half widths or radii.
    fn push_points(&mut self, m: &Mesh, sizes: &[f32], scale: f32, range: std::ops::Range<usize>) {
        for v in range {
            self.positions.extend(m.positions[v]);
            self.positions.push(sizes[v] * scale);
            self.colors.push(m.colors[v]);
        }
    }

    /// Splats `range` of `m`: each mean, its count of spherical-harmonic coefficients k,
    /// its covariance Σ = R S Sᵀ Rᵀ (src/splat.rs, computed in f64) as xx xy xz yy yz zz, 0,
    /// 0, then its k RGB coefficients.
    fn push_splats(&mut self, m: &Mesh, range: std::ops::Range<usize>) {
        let Primitive::Gaussians { scales, rotations, sh, .. } = &m.primitive else { return };
        let k = self.splat_sh as usize;
        for v in range {
            self.positions.extend(m.positions[v]);
            self.positions.push(k as f32);
            let cov = crate::splat::upper(&crate::splat::covariance(scales[v], rotations[v]));
            self.positions.extend(cov.map(|x| x as f32));
            self.positions.extend([0.0; 2]);
            self.positions.extend(sh[k * v..k * (v + 1)].iter().flatten());
            self.colors.push(m.colors[v]);
        }
    }

    /// Whether `vertices` more vertices and `triangles` more triangles keep every buffer within `max` bytes.
    pub fn room(&self, vertices: u64, triangles: u64, max: u64) -> bool {
        let v = self.vertices() + vertices;
        let attributes = if self.shaded { v * 32 } else { 0 };
        v * 16 <= max
            && v * 12 <= max
            && attributes <= max
            && (self.indices.len() as u64 + 3 * triangles) * 4 <= max
            && v <= u32::MAX as u64
    }

    /// Vertex `v` of `m`, the scene's mesh number `mesh`.
    pub fn push_vertex(&mut self, m: &Mesh, mesh: usize, v: usize) {
        self.positions.extend(m.positions[v]);
        self.colors.push(m.colors[v]);
        if self.shaded {
            let n = m.normals.get(v).copied().unwrap_or([0.0; 3]);
            let uv = m.uvs.get(v).copied().unwrap_or([0.0; 2]);
            self.attributes.push([n[0], n[1], n[2], f32::from_bits(mesh as u32)]);
            self.attributes.push([uv[0], uv[1], 0.0, 0.0]);
        }
    }
}

/// Uploads a strand or particle set, the scene's mesh `material`, into chunks of its own after
/// `cur` (closed first where it holds anything): whole strands or particles while they fit a
/// binding. Returns the mesh chunk that follows it; `mine` gets the set's segments.
pub(super) fn upload_set(
    cur: Gather,
    done: &mut Vec<Gather>,
    mine: &mut Vec<Segment>,
    m: &Mesh,
    (material, set_instance, set_instances): (u32, u32, u32),
    max: u64,
) -> Result<Gather> {
    let kind = m.primitive.kind();
    let mut cur = if cur.vertices() > 0 || !cur.indices.is_empty() {
        let next = cur.next(kind, material);
        done.push(cur);
        next
    } else {
        Gather { kind, material, ..cur }
    };
    (cur.set_instance, cur.set_instances) = (set_instance, set_instances);
    if let Primitive::Gaussians { sh, .. } = &m.primitive {
        cur.splat_sh = (sh.len() / m.positions.len().max(1)) as u32;
    }
    let start = |mine: &mut Vec<Segment>, done: &Vec<Gather>| mine.push(Segment { chunk: done.len(), lo: 0, hi: 0 });
    start(mine, done);
    let units: Vec<(usize, usize)> = match &m.primitive {
        Primitive::Strands { counts, .. } => {
            let mut first = 0;
            counts
                .iter()
                .map(|&c| {
                    first += c as usize;
                    (first - c as usize, c as usize)
                })
                .collect()
        }
        _ => (0..m.positions.len()).map(|i| (i, 1)).collect(),
    };
    for (first, points) in units {
        let segments = if kind == PRIM_STRANDS { points as u64 - 1 } else { 0 };
        if !cur.room_points(points as u64, segments, max) {
            if cur.vertices() == 0 {
                return Err(OitError::OutOfMemory(format!(
                    "a strand of {points} points (or its corners, {set_instances} instances) passes a storage binding ({max} bytes): \
                     split it or draw fewer instances"
                )));
            }
            let next = cur.next(kind, material);
            done.push(std::mem::replace(&mut cur, next));
            start(mine, done);
        }
        let base = cur.vertices() as u32;
        match &m.primitive {
            Primitive::Strands { widths, .. } => {
                cur.push_points(m, widths, 0.5, first..first + points);
                cur.indices.extend(primitive::segment_words(&[points as u32], base));
            }
            Primitive::Particles { radii } => cur.push_points(m, radii, 1.0, first..first + points),
            Primitive::Gaussians { .. } => cur.push_splats(m, first..first + points),
            Primitive::Triangles => unreachable!("meshes are uploaded by upload"),
        }
        mine.last_mut().expect("started above").hi = cur.triangles();
    }
    let next = cur.next(PRIM_MESH, 0);
    done.push(cur);
    Ok(next)
}

/// A flat-shaded mesh with a vertex per triangle corner, each carrying its triangle's unit
/// normal (computed in f64 from the positions, as the reference does): the vertex shader then
/// needs no flat case.
pub(super) fn flat_corners(m: &Mesh) -> Mesh {
    let corners = m.indices.iter().flatten().map(|&v| v as usize);
    let mut out = Mesh {
        positions: corners.clone().map(|v| m.positions[v]).collect(),
        colors: corners.clone().map(|v| m.colors[v]).collect(),
        uvs: if m.uvs.is_empty() { Vec::new() } else { corners.map(|v| m.uvs[v]).collect() },
        indices: (0..m.indices.len() as u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
        opaque: m.opaque,
        normals: Vec::with_capacity(3 * m.indices.len()),
        material: Default::default(),
        primitive: Primitive::Triangles,
    };
    for t in &m.indices {
        let p = t.map(|v| glam::DVec3::from(m.positions[v as usize].map(|x| x as f64)));
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero().as_vec3().to_array();
        out.normals.extend([n; 3]);
    }
    out
}
