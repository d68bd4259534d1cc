//! A scene's transparent or opaque meshes as uploaded: chunks of vertex-pulling buffers, each
//! with its group 0, the placements the sorting methods order, and the draw calls over them.

use glam::Vec3;

use crate::context::GpuContext;
use crate::error::{OitError, Result};
use crate::gpu_types::{GpuInstance, GpuSegment};
use crate::primitive::{Primitive, PRIM_MESH};
use crate::scene::{Instance, Mesh};
use crate::shading::Shading;
use crate::targets::storage_buffer;

use super::atlas::Atlas;
use super::gather::{flat_corners, upload_set, Gather, Segment};

/// One instance of a mesh, in the drawn order: its centroid in world space, its mesh (within
/// this geometry) and its row of the instance table.
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    pub centroid: Vec3,
    pub mesh: usize,
    pub instance: u32,
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
    pub expand: Option<(wgpu::BindGroup, u32)>,
}

/// The transparent or the opaque meshes, concatenated in submission order and split into
/// chunks where their buffers would pass a storage binding; each mesh is drawn once for each
/// of its instances (`draw_all`).
pub struct Geometry {
    pub chunks: Vec<Chunk>,
    /// Triangles drawn, instances included.
    pub triangles: u32,
    pub placements: Vec<Placement>,
    /// A splat set's placement: its Gaussians' means in world space (its instance applied),
    /// what `sorted` orders them by (`splat_slots`); empty for every other placement.
    pub splat_means: Vec<Vec<Vec3>>,
    /// Per mesh of this geometry: its segments, its first instance and its instance count.
    segments: Vec<Vec<Segment>>,
    instances: Vec<(u32, u32)>,
    /// Whether the passes compile with transforms (else every instance is the identity, one
    /// a mesh, and a chunk draws in one call).
    pub instanced: bool,
    /// Bytes uploaded by what uploaded them (indexed by chunk kind: meshes with the instance
    /// and segment tables, strands, particles).
    pub bytes: [u64; 4],
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
    pub fn expand(&self, pass: &mut wgpu::ComputePass<'_>, pipeline: impl Fn(u32) -> wgpu::ComputePipeline) {
        for c in &self.chunks {
            if let Some((group, kind)) = &c.expand {
                pass.set_pipeline(&pipeline(*kind));
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

    /// Where splat set placement `p` draws its splats: for splat `k` of the set, its chunk and
    /// the indirect draw arguments of its quad (six vertices, one instance: vertex count,
    /// instance count, first vertex, first instance), for `multi_draw_indirect`; the instance
    /// is 0 where the passes read no instance table. Nothing is held a splat: a set's
    /// segments are few, and `k` finds its own by a binary search of their starts.
    pub fn splat_slots(&self, p: &Placement) -> impl Fn(u32) -> (usize, [u32; 4]) + '_ {
        let segments = &self.segments[p.mesh];
        // The set's first splat in each segment (two triangles a splat).
        let starts: Vec<u32> = segments.iter().scan(0, |n, s| Some(std::mem::replace(n, *n + (s.hi - s.lo) / 2))).collect();
        let instance = if self.instanced { p.instance } else { 0 };
        move |k| {
            let i = starts.partition_point(|&s| s <= k) - 1;
            let s = segments[i];
            (s.chunk, [6, 1, 3 * (s.lo + 2 * (k - starts[i])), instance])
        }
    }

    /// Binds chunk `chunk`'s group 0 (for draws of `splat_slots`).
    pub fn bind_chunk(&self, pass: &mut wgpu::RenderPass<'_>, chunk: usize) {
        pass.set_bind_group(0, &self.chunks[chunk].group, &[]);
    }

    fn draw_segment(&self, pass: &mut wgpu::RenderPass<'_>, s: Segment, instances: std::ops::Range<u32>) {
        if s.lo < s.hi && !instances.is_empty() {
            pass.set_bind_group(0, &self.chunks[s.chunk].group, &[]);
            pass.draw(3 * s.lo..3 * s.hi, instances);
        }
    }
}

/// What every chunk's group 0 binds besides its own buffers: the layouts, the frame uniform,
/// the surfaces table and the atlas, and how the scene compiles (shaded, instanced).
pub(super) struct SceneBindings<'a> {
    pub layout: &'a wgpu::BindGroupLayout,
    /// Group 0 of the expansion pass (`Layout::Expand`).
    pub expand_layout: &'a wgpu::BindGroupLayout,
    pub uniform: &'a wgpu::Buffer,
    pub surfaces: &'a wgpu::Buffer,
    pub atlas: &'a Atlas,
    pub shaded: bool,
    pub instanced: bool,
}

/// Uploads `meshes` (the scene's mesh number, the mesh, its instances) in chunks whose buffers
/// each fit `max_binding_bytes`, each chunk's group 0 binding `bindings`.
pub(super) fn upload<'a>(
    gpu: &GpuContext,
    label: &str,
    meshes: impl Iterator<Item = (usize, &'a Mesh, &'a [Instance])>,
    bindings: &SceneBindings<'_>,
    max_binding_bytes: u64,
) -> Result<Geometry> {
    let max = max_binding_bytes.max(48);
    let mut done: Vec<Gather> = Vec::new();
    let mut cur = Gather { shaded: bindings.shaded, ..Default::default() };
    let mut placements = Vec::new();
    let mut splat_means = Vec::new();
    let mut segments: Vec<Vec<Segment>> = Vec::new();
    let mut instances: Vec<(u32, u32)> = Vec::new();
    let mut table: Vec<GpuInstance> = Vec::new();
    let mut unique: u64 = 0;
    let mut drawn: u64 = 0;
    for (mesh, m, list) in meshes {
        let split;
        let m = if bindings.shaded && m.material.shading == Shading::Flat {
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
            splat_means.push(match m.primitive {
                Primitive::Gaussians { .. } => {
                    m.positions.iter().map(|p| inst.transform.transform_point3(glam::DVec3::from(p.map(|x| x as f64))).as_vec3()).collect()
                }
                _ => Vec::new(),
            });
            // Without instances the passes read no table: none is built.
            if bindings.instanced {
                table.push(GpuInstance::new(inst, (drawn as u32).wrapping_sub(unique as u32)));
            }
            drawn += tris;
        }
        unique += tris;
        let mut mine = Vec::new();
        if m.primitive != Primitive::Triangles {
            let first = if bindings.instanced { instances.last().expect("pushed above").0 } else { 0 };
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
            if bindings.instanced {
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
    let mut bytes = [table_bytes, 0, 0, 0];
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
                (0, bindings.uniform),
                (1, &pos),
                (2, &col),
                (3, &idx),
                (4, &info),
                (5, &attr),
                (6, bindings.surfaces),
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
            let group = bind(bindings.layout, label, None, &[(10, &bindings.atlas.view)]);
            let expand = (corners > 0).then(|| (bind(bindings.expand_layout, "expand", Some(8), &[]), g.kind));
            Chunk { group, triangles: g.triangles(), drawn: chunk_drawn[k], expand }
        })
        .collect();
    Ok(Geometry {
        chunks,
        triangles: drawn as u32,
        placements,
        splat_means,
        segments,
        instances,
        instanced: bindings.instanced,
        bytes,
        expanded_bytes,
    })
}
