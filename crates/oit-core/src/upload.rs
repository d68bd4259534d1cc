//! The scene on the GPU: transparent and opaque geometry, each as vertex-pulling buffers
//! (packed positions, RGBA per vertex, indices, and where the scene is shaded two vec4 of
//! normal, material and UVs per vertex) bound in group 0 with the frame uniform and the
//! material table with its textures (`surfaces`, shared by every chunk).

use glam::Vec3;

use crate::context::GpuContext;
use crate::error::{invalid, OitError, Result};
use crate::gpu_types::{GpuInstance, GpuMaterial, GpuSegment, GpuTextureMap, MATERIAL_VEC4S};
use crate::primitive::{self, Primitive, PRIM_MESH, PRIM_PARTICLES, PRIM_STRANDS};
use crate::scene::{Instance, Mesh, Scene};
use crate::shading::{Shading, Texture, TextureMap};
use crate::targets::storage_buffer;

/// One instance of a mesh, in the drawn order: its centroid in world space, its mesh (within
/// this geometry) and its row of the instance table.
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    pub centroid: Vec3,
    pub mesh: usize,
    pub instance: u32,
}

/// A mesh's triangles within one chunk: local triangles `lo .. hi`.
#[derive(Clone, Copy, Debug)]
struct Segment {
    chunk: usize,
    lo: u32,
    hi: u32,
}

/// A run of triangles uploaded as one set of buffers that each fit a binding.
pub struct Chunk {
    /// Group 0: the frame uniform, this chunk's positions, colors and indices, its place, the
    /// instance table and the chunk's segments.
    pub group: wgpu::BindGroup,
    /// The chunk's uploaded triangles.
    pub triangles: u32,
    /// Triangles drawn from it, instances included: what a compute pass over the drawn
    /// triangles dispatches (shaders/common/setup.wgsl).
    pub drawn: u32,
    /// A strand or particle chunk's group 0 for the expansion pass (`Layout::Expand`), and
    /// whether it holds strands (else particles: each kind has its own entry point).
    pub expand: Option<(wgpu::BindGroup, bool)>,
}

/// The transparent or the opaque meshes, concatenated in submission order and split into
/// chunks where their buffers would pass a storage binding; each mesh is drawn once for each
/// of its instances (upload.rs `draw_all`).
pub struct Geometry {
    pub chunks: Vec<Chunk>,
    /// Triangles drawn, instances included.
    pub triangles: u32,
    pub placements: Vec<Placement>,
    /// Per mesh of this geometry: its segments, its first instance and its instance count.
    segments: Vec<Vec<Segment>>,
    instances: Vec<(u32, u32)>,
    /// Whether the passes compile with transforms (else every instance is the identity, one
    /// a mesh, and a chunk draws in one call).
    pub instanced: bool,
    /// Bytes uploaded by what uploaded them (indexed by chunk kind: meshes with the instance
    /// and segment tables, strands, particles).
    pub bytes: [u64; 3],
    /// The part of `bytes` that the expansion pass writes on the GPU (not uploaded).
    pub expanded_bytes: u64,
}

impl Geometry {
    /// Group 0 for passes that use only the frame uniform (full-screen, per-pixel dispatches).
    pub fn group(&self) -> &wgpu::BindGroup {
        &self.chunks[0].group
    }

    /// Draws every triangle of every instance (three vertices each, pulled from storage) in
    /// submission order: chunk after chunk; instanced, a mesh's instances in one draw, or
    /// instance after instance where the mesh spans chunks.
    pub fn draw_all(&self, pass: &mut wgpu::RenderPass<'_>) {
        if !self.instanced {
            for c in &self.chunks {
                pass.set_bind_group(0, &c.group, &[]);
                pass.draw(0..3 * c.triangles, 0..1);
            }
            return;
        }
        for (segments, &(first, count)) in self.segments.iter().zip(&self.instances) {
            if let [s] = segments[..] {
                self.draw_segment(pass, s, first..first + count);
            } else {
                for i in first..first + count {
                    segments.iter().for_each(|&s| self.draw_segment(pass, s, i..i + 1));
                }
            }
        }
    }

    /// Builds the corners of every strand and particle chunk under the frame uniform's camera
    /// (shaders/expand.wgsl), before the passes that draw them.
    pub fn expand(&self, pass: &mut wgpu::ComputePass<'_>, pipeline: impl Fn(bool) -> wgpu::ComputePipeline) {
        for c in &self.chunks {
            if let Some((group, strands)) = &c.expand {
                pass.set_pipeline(&pipeline(*strands));
                pass.set_bind_group(0, group, &[]);
                let groups = (c.triangles / 2).div_ceil(256);
                pass.dispatch_workgroups(groups.min(65_535), groups.div_ceil(65_535), 1);
            }
        }
    }

    /// Draws one placement's triangles.
    pub fn draw_placement(&self, pass: &mut wgpu::RenderPass<'_>, p: &Placement) {
        for &s in &self.segments[p.mesh] {
            self.draw_segment(pass, s, p.instance..p.instance + 1);
        }
    }

    fn draw_segment(&self, pass: &mut wgpu::RenderPass<'_>, s: Segment, instances: std::ops::Range<u32>) {
        if s.lo < s.hi && !instances.is_empty() {
            pass.set_bind_group(0, &self.chunks[s.chunk].group, &[]);
            pass.draw(3 * s.lo..3 * s.hi, instances);
        }
    }
}

pub struct GpuScene {
    pub transparent: Geometry,
    pub opaque: Geometry,
    /// Whether any mesh is shaded (the frame uniform's flag).
    pub shaded: bool,
    /// Whether any mesh is textured.
    pub textured: bool,
    /// Whether any mesh is drawn other than once in place (the constant INSTANCED), and the
    /// instances drawn.
    pub instanced: bool,
    pub instances: u64,
    /// Whether any set is strands or particles, or any mesh shades as hair (the constant
    /// PRIMITIVES, which compiles common/primitives.wgsl), and whether there are no triangle
    /// meshes at all, opaque or not (the constant SETS_ONLY).
    pub primitives: bool,
    pub sets_only: bool,
    /// Whether any surface, opaque or not, shades flat or smooth (the constant PHONG), and
    /// whether any has a falloff (FALLOFF).
    pub phong: bool,
    pub falloff: bool,
    /// Whether any material gives off light (EMISSIVE), and whether any tests alpha
    /// (ALPHA_TESTS).
    pub emissive: bool,
    pub alpha_test: bool,
    /// The bytes the materials' images with their mips take on the GPU (the atlas, bound in
    /// every chunk's group 0; 0 without textures: a 1-texel placeholder is bound).
    pub texture_bytes: u64,
    /// The matrices (`execute::expansion_view`) the corners in `expanded` were last built
    /// under; None until the first expansion.
    pub expanded_view: std::cell::Cell<Option<[u32; 32]>>,
}

/// Chunk contents on the host while they are gathered. A chunk of strands or particles
/// (`kind`) holds one set's points (x, y, z and half the width or the radius), their colors,
/// and for strands a word a segment (`primitive::segment_words`) where a mesh chunk has its
/// indices; the set's material is the chunk's.
#[derive(Default)]
struct Gather {
    positions: Vec<f32>,
    colors: Vec<[f32; 4]>,
    indices: Vec<u32>,
    /// Two a vertex where the scene is shaded, else none.
    attributes: Vec<[f32; 4]>,
    first_triangle: u32,
    shaded: bool,
    kind: u32,
    material: u32,
    /// A set's first row of the instance table (0 without instances) and its instance count:
    /// `expanded` holds its corners once an instance.
    set_instance: u32,
    set_instances: u32,
}

impl Gather {
    fn vertices(&self) -> u64 {
        self.colors.len() as u64
    }

    fn triangles(&self) -> u32 {
        match self.kind {
            PRIM_STRANDS => 2 * self.indices.len() as u32,
            PRIM_PARTICLES => 2 * self.colors.len() as u32,
            _ => (self.indices.len() / 3) as u32,
        }
    }

    /// The next chunk after this one, of `kind` with `material`: a set's next chunk keeps its
    /// instances, a mesh chunk has none of its own.
    fn next(&self, kind: u32, material: u32) -> Gather {
        let (set_instance, set_instances) = if kind == PRIM_MESH { (0, 0) } else { (self.set_instance, self.set_instances) };
        Gather {
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
    fn expanded_per_point(&self) -> u64 {
        match self.kind {
            PRIM_STRANDS => 3,
            PRIM_PARTICLES => 4,
            _ => 0,
        }
    }

    /// Whether `points` more points and `segments` more segment words fit `max` bytes each,
    /// their corners too, and one dispatch of the expansion (65,535 groups of 64 in x).
    fn room_points(&self, points: u64, segments: u64, max: u64) -> bool {
        let v = self.vertices() + points;
        let units = if self.kind == PRIM_STRANDS { self.indices.len() as u64 + segments } else { v };
        v * 16 <= max
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

    /// Whether `vertices` more vertices and `triangles` more triangles keep every buffer within `max` bytes.
    fn room(&self, vertices: u64, triangles: u64, max: u64) -> bool {
        let v = self.vertices() + vertices;
        let attributes = if self.shaded { v * 32 } else { 0 };
        v * 16 <= max
            && v * 12 <= max
            && attributes <= max
            && (self.indices.len() as u64 + 3 * triangles) * 4 <= max
            && v <= u32::MAX as u64
    }

    /// Vertex `v` of `m`, the scene's mesh number `mesh`.
    fn push_vertex(&mut self, m: &Mesh, mesh: usize, v: usize) {
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

/// Where a scene's group 0 comes from: its layout, the frame uniform, the surfaces table.
struct Shared<'a> {
    layout: &'a wgpu::BindGroupLayout,
    /// Group 0 of the expansion pass (`Layout::Expand`).
    expand_layout: &'a wgpu::BindGroupLayout,
    uniform: &'a wgpu::Buffer,
    surfaces: &'a wgpu::Buffer,
    atlas: &'a Atlas,
    shaded: bool,
    instanced: bool,
}

fn upload<'a>(
    gpu: &GpuContext,
    label: &str,
    meshes: impl Iterator<Item = (usize, &'a Mesh, &'a [Instance])>,
    shared: &Shared<'_>,
    max_binding_bytes: u64,
) -> Result<Geometry> {
    let max = max_binding_bytes.max(48);
    let mut done: Vec<Gather> = Vec::new();
    let mut cur = Gather { shaded: shared.shaded, ..Default::default() };
    let mut placements = Vec::new();
    let mut segments: Vec<Vec<Segment>> = Vec::new();
    let mut instances: Vec<(u32, u32)> = Vec::new();
    let mut table: Vec<GpuInstance> = Vec::new();
    let mut unique: u64 = 0;
    let mut drawn: u64 = 0;
    for (mesh, m, list) in meshes {
        let split;
        let m = if shared.shaded && m.material.shading == Shading::Flat {
            split = flat_corners(m);
            &split
        } else {
            m
        };
        let tris = m.triangle_count() as u64;
        if drawn + tris * list.len() as u64 > u32::MAX as u64 / 3 {
            return Err(OitError::OutOfMemory(format!(
                "the {label} meshes draw more than {} triangles (instances included), the most one frame numbers: \
                 split the scene or draw fewer instances",
                u32::MAX / 3
            )));
        }
        let local = segments.len();
        let centroid = if m.positions.is_empty() {
            glam::DVec3::ZERO
        } else {
            m.positions.iter().map(|p| glam::DVec3::from(p.map(|x| x as f64))).sum::<glam::DVec3>() / m.positions.len() as f64
        };
        instances.push((placements.len() as u32, list.len() as u32));
        for inst in list {
            let instance = placements.len() as u32;
            placements.push(Placement { centroid: inst.transform.transform_point3(centroid).as_vec3(), mesh: local, instance });
            // Without instances the passes read no table: none is built.
            if shared.instanced {
                table.push(GpuInstance::new(inst, (drawn as u32).wrapping_sub(unique as u32)));
            }
            drawn += tris;
        }
        unique += tris;
        let mut mine = Vec::new();
        if m.primitive != Primitive::Triangles {
            let first = if shared.instanced { instances.last().expect("pushed above").0 } else { 0 };
            cur = upload_set(cur, &mut done, &mut mine, m, (mesh as u32, first, list.len() as u32), max)?;
        } else if cur.room(m.positions.len() as u64, tris, max) {
            // The whole mesh: its vertices in order, its indices offset.
            let base = cur.vertices() as u32;
            mine.push(Segment { chunk: done.len(), lo: cur.triangles(), hi: cur.triangles() + tris as u32 });
            (0..m.positions.len()).for_each(|v| cur.push_vertex(m, mesh, v));
            cur.indices.extend(m.indices.iter().flatten().map(|&i| i + base));
        } else {
            // Triangle by triangle, each chunk with the vertices its triangles use.
            let mut local = vec![u32::MAX; m.positions.len()];
            let mut stamp = vec![usize::MAX; m.positions.len()];
            mine.push(Segment { chunk: done.len(), lo: cur.triangles(), hi: cur.triangles() });
            for tri in &m.indices {
                if !cur.room(3, 1, max) {
                    let next = cur.next(PRIM_MESH, 0);
                    done.push(std::mem::replace(&mut cur, next));
                    mine.push(Segment { chunk: done.len(), lo: 0, hi: 0 });
                }
                let id = done.len();
                for &v in tri {
                    let v = v as usize;
                    if stamp[v] != id {
                        stamp[v] = id;
                        local[v] = cur.vertices() as u32;
                        cur.push_vertex(m, mesh, v);
                    }
                    cur.indices.push(local[v]);
                }
                mine.last_mut().expect("pushed above").hi += 1;
            }
        }
        mine.retain(|s| s.lo < s.hi);
        segments.push(mine);
    }
    done.push(cur);
    // Chunks that hold no triangle are dropped (but one is kept for its group): renumber.
    let kept: Vec<usize> = (0..done.len()).filter(|&c| done[c].triangles() > 0 || c == 0).collect();
    let mut renumber = vec![usize::MAX; done.len()];
    kept.iter().enumerate().for_each(|(k, &c)| renumber[c] = k);
    segments.iter_mut().flatten().for_each(|s| s.chunk = renumber[s.chunk]);
    // Each chunk's segments, in drawn order, for compute passes over the drawn triangles (with
    // instances only: the passes read them with instances alone); every chunk's drawn count.
    let mut chunk_segments: Vec<Vec<GpuSegment>> = vec![Vec::new(); kept.len()];
    let mut chunk_drawn = vec![0u32; kept.len()];
    for (mine, &(first, count)) in segments.iter().zip(&instances) {
        for s in mine {
            if count == 0 {
                continue;
            }
            let at = chunk_drawn[s.chunk];
            if shared.instanced {
                chunk_segments[s.chunk].push(GpuSegment { drawn_first: at, lo: s.lo, triangles: s.hi - s.lo, first_instance: first });
            }
            chunk_drawn[s.chunk] = at + (s.hi - s.lo) * count;
        }
    }
    let make = |name: &str, bytes: &[u8]| {
        let b = storage_buffer(&gpu.device, name, bytes.len() as u64, wgpu::BufferUsages::empty());
        if !bytes.is_empty() {
            gpu.queue.write_buffer(&b, 0, bytes);
        }
        b
    };
    let table_bytes = table.len() as u64 * std::mem::size_of::<GpuInstance>() as u64;
    if table_bytes > max {
        return Err(OitError::OutOfMemory(format!(
            "the {label} meshes have {} instances, whose table ({table_bytes} bytes) passes a storage binding ({max} bytes): \
             draw fewer instances",
            table.len()
        )));
    }
    let segment_bytes = std::mem::size_of::<GpuSegment>() as u64;
    if let Some(list) = chunk_segments.iter().find(|l| l.len() as u64 * segment_bytes > max) {
        return Err(OitError::OutOfMemory(format!(
            "a chunk of the {label} meshes holds {} instanced meshes, whose segment table passes a storage binding \
             ({max} bytes): merge meshes",
            list.len()
        )));
    }
    let instance_table = make("instances", bytemuck::cast_slice(&table));
    let mut bytes = [table_bytes, 0, 0];
    let mut expanded_bytes = 0;
    let chunks = kept
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            let g = &done[c];
            bytes[g.kind as usize] +=
                g.positions.len() as u64 * 4 + g.colors.len() as u64 * 16 + g.indices.len() as u64 * 4 + g.attributes.len() as u64 * 16;
            let list = &chunk_segments[k];
            bytes[PRIM_MESH as usize] += list.len() as u64 * segment_bytes;
            let points = g.vertices() as u32;
            let place = [g.first_triangle, g.triangles(), list.len() as u32, chunk_drawn[k], g.kind, g.material, g.set_instance, points];
            let info = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("chunk"),
                size: std::mem::size_of_val(&place) as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            gpu.queue.write_buffer(&info, 0, bytemuck::cast_slice(&place));
            let pos = make("positions", bytemuck::cast_slice(&g.positions));
            let col = make("colors", bytemuck::cast_slice(&g.colors));
            let idx = make("indices", bytemuck::cast_slice(&g.indices));
            let attr = make("attributes", bytemuck::cast_slice(&g.attributes));
            let seg = make("segments", bytemuck::cast_slice(list));
            // A set's corners, written by the expansion pass each frame (or 16 bytes unused).
            let corners = g.vertices() * g.expanded_per_point() * 16 * g.set_instances as u64;
            let expanded = storage_buffer(&gpu.device, "expanded", corners.max(16), wgpu::BufferUsages::empty());
            bytes[g.kind as usize] += corners;
            expanded_bytes += corners;
            // One list of the chunk's buffers for its group and, without the segments (8),
            // for its expansion pass's group (`Layout::Expand`, the corners writable).
            let buffers = [
                (0, shared.uniform),
                (1, &pos),
                (2, &col),
                (3, &idx),
                (4, &info),
                (5, &attr),
                (6, shared.surfaces),
                (7, &instance_table),
                (8, &seg),
                (9, &expanded),
            ];
            let bind = |layout: &wgpu::BindGroupLayout, label: &str, skip: Option<u32>, views: &[(u32, &wgpu::TextureView)]| {
                let entries: Vec<wgpu::BindGroupEntry> = buffers
                    .iter()
                    .filter(|(binding, _)| Some(*binding) != skip)
                    .map(|&(binding, b)| wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() })
                    .chain(
                        views.iter().map(|&(binding, v)| wgpu::BindGroupEntry { binding, resource: wgpu::BindingResource::TextureView(v) }),
                    )
                    .collect();
                gpu.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
            };
            let group = bind(shared.layout, label, None, &[(10, &shared.atlas.view)]);
            let expand = (corners > 0).then(|| (bind(shared.expand_layout, "expand", Some(8), &[]), g.kind == PRIM_STRANDS));
            Chunk { group, triangles: g.triangles(), drawn: chunk_drawn[k], expand }
        })
        .collect();
    Ok(Geometry { chunks, triangles: drawn as u32, placements, segments, instances, instanced: shared.instanced, bytes, expanded_bytes })
}

/// Uploads a strand or particle set, the scene's mesh `material`, into chunks of its own after
/// `cur` (closed first where it holds anything): whole strands or particles while they fit a
/// binding. Returns the mesh chunk that follows it; `mine` gets the set's segments.
fn upload_set(
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
            Primitive::Triangles => unreachable!("meshes are uploaded by upload"),
        }
        mine.last_mut().expect("started above").hi = cur.triangles();
    }
    let next = cur.next(PRIM_MESH, 0);
    done.push(cur);
    Ok(next)
}

impl GpuScene {
    /// The scene's buffers by what uploaded them: meshes (with materials, textures and the
    /// instance tables), strands, particles.
    pub fn bytes(&self) -> [u64; 3] {
        std::array::from_fn(|k| self.transparent.bytes[k] + self.opaque.bytes[k])
    }

    /// Uploads `scene` in chunks whose buffers each fit `max_binding_bytes`.
    pub fn new(
        gpu: &GpuContext,
        scene: &Scene,
        layout: &wgpu::BindGroupLayout,
        uniform: &wgpu::Buffer,
        max_binding_bytes: u64,
    ) -> Result<Self> {
        let shaded = scene.shaded();
        let images = if shaded { images(scene) } else { Vec::new() };
        let (atlas, places) = Atlas::new(gpu, &images)?;
        let table = if shaded { surfaces(scene, &images, &places) } else { vec![[0.0; 4]; MATERIAL_VEC4S as usize] };
        if table.len() as u64 * 16 > max_binding_bytes {
            return Err(OitError::OutOfMemory(format!(
                "the scene's material table takes {} bytes, past a storage binding ({max_binding_bytes} bytes): use fewer meshes or materials",
                table.len() * 16
            )));
        }
        let buffer = storage_buffer(&gpu.device, "surfaces", table.len() as u64 * 16, wgpu::BufferUsages::empty());
        gpu.queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&table));
        let instanced = scene.instanced();
        let expand_layout = gpu.cache.layout(&gpu.device, crate::cache::Layout::Expand);
        let shared = Shared { layout, expand_layout: &expand_layout, uniform, surfaces: &buffer, atlas: &atlas, shaded, instanced };
        let meshes = || scene.placed().enumerate().map(|(i, (m, list))| (i, m, list));
        let mut transparent = upload(gpu, "transparent", meshes().filter(|(_, m, _)| !m.opaque), &shared, max_binding_bytes)?;
        let opaque = upload(gpu, "opaque", meshes().filter(|(_, m, _)| m.opaque), &shared, max_binding_bytes)?;
        if shaded {
            transparent.bytes[PRIM_MESH as usize] += table.len() as u64 * 16 + atlas.bytes;
        }
        let textured = !images.is_empty();
        let primitives = scene.meshes().iter().any(|m| m.primitive != Primitive::Triangles || m.material.shading == Shading::Hair);
        let sets_only = scene.meshes().iter().all(|m| m.primitive != Primitive::Triangles);
        let phong = scene.meshes().iter().any(|m| matches!(m.material.shading, Shading::Flat | Shading::Smooth));
        let falloff = scene.meshes().iter().any(|m| m.material.falloff != crate::shading::Falloff::None);
        let instances = scene.instance_count() as u64;
        let emissive = scene.meshes().iter().any(|m| m.material.emissive != [0.0; 3]);
        let alpha_test = scene.meshes().iter().any(|m| m.material.alpha_cutoff.is_some());
        Ok(Self {
            emissive,
            alpha_test,
            transparent,
            opaque,
            shaded,
            textured,
            instanced,
            instances,
            primitives,
            sets_only,
            phong,
            falloff,
            texture_bytes: atlas.bytes,
            expanded_view: Default::default(),
        })
    }
}

/// A flat-shaded mesh with a vertex per triangle corner, each carrying its triangle's unit
/// normal (computed in f64 from the positions, as the reference does): the vertex shader then
/// needs no flat case.
fn flat_corners(m: &Mesh) -> Mesh {
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

/// Every image the scene's materials use, once however many use it, in first-use order.
fn images(scene: &Scene) -> Vec<&Texture> {
    let mut seen = std::collections::HashSet::new();
    let maps = scene.meshes().iter().flat_map(|m| [&m.material.texture, &m.material.emissive_texture]);
    maps.flatten().filter(|t| seen.insert(std::sync::Arc::as_ptr(&t.image))).map(|t| &*t.image).collect()
}

/// The material table (`MATERIAL_VEC4S` vec4 a mesh: `GpuMaterial`), then, where there are
/// images, the sRGB decoding table (the linear value of each 8-bit code, four a vec4) and each
/// image's record: a header (levels, the table's place or 0 for a linear image, width, height)
/// and, a level, its place in the atlas (x, y, layer, width | height << 16).
fn surfaces(scene: &Scene, images: &[&Texture], places: &[Vec<[u32; 4]>]) -> Vec<[f32; 4]> {
    let meshes = scene.meshes();
    let base = MATERIAL_VEC4S as usize * meshes.len();
    let mut records: Vec<[u32; 4]> = Vec::new();
    if !images.is_empty() {
        let decode = crate::shading::srgb_table();
        records.extend(decode.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]].map(f32::to_bits)));
    }
    let mut first = Vec::with_capacity(images.len());
    for (image, levels) in images.iter().zip(places) {
        first.push((base + records.len()) as u32);
        let table = if image.srgb { base as u32 } else { 0 };
        records.push([levels.len() as u32, table, image.width, image.height]);
        records.extend_from_slice(levels);
    }
    let map = |t: &Option<TextureMap>| {
        t.as_ref().map_or(GpuTextureMap::default(), |t| {
            let at = images.iter().position(|i| std::ptr::eq(*i, &*t.image)).expect("every image is in the atlas");
            let [a, b] = t.transform;
            GpuTextureMap { image: first[at], sampler: t.sampler.bits(), transform: [a[0], a[1], a[2], b[0], b[1], b[2]] }
        })
    };
    let mut table: Vec<[f32; 4]> = Vec::with_capacity(base + records.len());
    for m in meshes {
        let mat = &m.material;
        let g = GpuMaterial {
            specular: mat.specular,
            shininess: mat.shininess,
            opacity: mat.opacity,
            flags: Shading::flags(mat),
            emissive: mat.emissive,
            alpha_cutoff: mat.alpha_cutoff.unwrap_or(0.0),
            maps: [map(&mat.texture), map(&mat.emissive_texture)],
        };
        table.extend_from_slice(bytemuck::cast_slice(&[g]));
        debug_assert!(mat.shading != Shading::Smooth || m.normals.len() == m.positions.len());
    }
    table.extend(records.iter().map(|r| r.map(f32::from_bits)));
    table
}

/// Places `rects` (image, level, width, height) in shelves, tallest first, in square layers of
/// `side`: (x, y, layer, width | height << 16) each, and the layers used.
fn shelves(rects: &[(usize, usize, u32, u32)], side: u32) -> (Vec<[u32; 4]>, u32) {
    let mut order: Vec<usize> = (0..rects.len()).collect();
    order.sort_by_key(|&k| std::cmp::Reverse((rects[k].3, rects[k].2)));
    let mut at = vec![[0u32; 4]; rects.len()];
    let (mut x, mut y, mut shelf, mut layer) = (0u32, 0u32, 0u32, 0u32);
    for k in order {
        let (_, _, w, h) = rects[k];
        if x + w > side {
            (x, y, shelf) = (0, y + shelf, 0);
        }
        if y + h > side {
            (x, y, shelf, layer) = (0, 0, 0, layer + 1);
        }
        at[k] = [x, y, layer, w | h << 16];
        x += w;
        shelf = shelf.max(h);
    }
    (at, layer + 1)
}

/// The scene's images with their mip chains, packed level by level into the layers of one
/// 8-bit RGBA 2D array texture (shelves of rectangles, tallest first), read as stored (sRGB
/// color decoded in the shader): 4 bytes a texel plus a third for the mips, and what packing
/// leaves.
pub struct Atlas {
    pub view: wgpu::TextureView,
    /// Bytes of the texture (0 for the placeholder of a scene without textures).
    pub bytes: u64,
}

impl Atlas {
    /// Packs and uploads `images`; returns the atlas and, an image, its levels' places.
    fn new(gpu: &GpuContext, images: &[&Texture]) -> Result<(Self, Vec<Vec<[u32; 4]>>)> {
        let max_side = gpu.limits.max_texture_dimension_2d;
        let rects: Vec<(usize, usize, u32, u32)> = images
            .iter()
            .enumerate()
            .flat_map(|(i, t)| t.levels().iter().enumerate().map(move |(l, level)| (i, l, level.width, level.height)))
            .collect();
        if let Some(&(i, _, w, h)) = rects.iter().find(|r| r.2 > max_side || r.3 > max_side) {
            return Err(invalid!("texture {i} is {w} x {h}, past the adapter's largest texture side ({max_side}): downscale it"));
        }
        // The square side that packs into the fewest bytes: from the largest rectangle's power
        // of two up to the adapter's largest side (a few layers of the smallest side often
        // waste less than one large layer).
        let largest = rects.iter().map(|r| r.2.max(r.3)).max().unwrap_or(1).next_power_of_two().min(max_side);
        let sides = std::iter::successors(Some(largest), |&s| (s < max_side).then(|| (2 * s).min(max_side)));
        let max_layers = gpu.limits.max_texture_array_layers;
        let packings: Vec<(u32, Vec<[u32; 4]>, u32)> = sides
            .map(|side| {
                let (at, layers) = shelves(&rects, side);
                (side, at, layers)
            })
            .collect();
        let fewest = packings.iter().map(|p| p.2).min().unwrap_or(1);
        let Some((side, at, layers)) = packings
            .into_iter()
            .filter(|p| p.2 <= max_layers)
            .min_by_key(|&(side, _, layers)| (side as u64 * side as u64 * layers as u64, layers))
        else {
            return Err(OitError::OutOfMemory(format!(
                "the scene's textures need {fewest} layers of {max_side} x {max_side} texels, past the adapter's {max_layers}: \
                 use fewer or smaller textures"
            )));
        };
        let (size, layers) = if rects.is_empty() { (1, 1) } else { (side, layers) };
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("texture atlas"),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let mut places: Vec<Vec<[u32; 4]>> = images.iter().map(|t| Vec::with_capacity(t.levels().len())).collect();
        for (&(i, l, w, h), &place) in rects.iter().zip(&at) {
            let [x, y, z, _] = place;
            gpu.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x, y, z },
                    aspect: wgpu::TextureAspect::All,
                },
                bytemuck::cast_slice(&images[i].levels()[l].texels),
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * w), rows_per_image: Some(h) },
                wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            );
            places[i].push(place);
        }
        let view = texture
            .create_view(&wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() });
        let bytes = if rects.is_empty() { 0 } else { 4 * side as u64 * side as u64 * layers as u64 };
        let atlas = Self { view, bytes };
        Ok((atlas, places))
    }
}
