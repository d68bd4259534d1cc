//! The scene on the GPU: transparent and opaque geometry, each as vertex-pulling buffers
//! (packed positions, RGBA per vertex, indices) bound in group 0 with the frame uniform.

use glam::Vec3;

use crate::context::GpuContext;
use crate::error::{OitError, Result};
use crate::scene::{Mesh, Scene};
use crate::targets::storage_buffer;

/// A mesh's place in the concatenated geometry.
#[derive(Clone, Copy, Debug)]
pub struct MeshRange {
    pub first_triangle: u32,
    pub triangles: u32,
    pub centroid: Vec3,
}

/// A run of triangles uploaded as one set of buffers that each fit a binding.
pub struct Chunk {
    /// Group 0: the frame uniform, this chunk's positions, colors and indices, and its place.
    pub group: wgpu::BindGroup,
    pub first_triangle: u32,
    pub triangles: u32,
}

/// The transparent or the opaque meshes, concatenated in submission order and split into
/// chunks where their buffers would pass a storage binding.
pub struct Geometry {
    pub chunks: Vec<Chunk>,
    pub triangles: u32,
    pub meshes: Vec<MeshRange>,
    pub bytes: u64,
}

impl Geometry {
    /// Group 0 for passes that use only the frame uniform (full-screen, per-pixel dispatches).
    pub fn group(&self) -> &wgpu::BindGroup {
        &self.chunks[0].group
    }

    /// Draws every triangle (three vertices each, pulled from storage), chunk after chunk.
    pub fn draw_all(&self, pass: &mut wgpu::RenderPass<'_>) {
        self.draw_range(pass, 0, self.triangles);
    }

    /// Draws triangles `first .. first + count` of the submission order.
    pub fn draw_range(&self, pass: &mut wgpu::RenderPass<'_>, first: u32, count: u32) {
        for c in &self.chunks {
            let lo = first.max(c.first_triangle);
            let hi = (first + count).min(c.first_triangle + c.triangles);
            if lo < hi {
                pass.set_bind_group(0, &c.group, &[]);
                pass.draw(3 * (lo - c.first_triangle)..3 * (hi - c.first_triangle), 0..1);
            }
        }
    }
}

pub struct GpuScene {
    pub transparent: Geometry,
    pub opaque: Geometry,
}

/// Chunk contents on the host while they are gathered.
#[derive(Default)]
struct Gather {
    positions: Vec<f32>,
    colors: Vec<[f32; 4]>,
    indices: Vec<u32>,
    first_triangle: u32,
}

impl Gather {
    fn vertices(&self) -> u64 {
        self.colors.len() as u64
    }

    fn triangles(&self) -> u32 {
        (self.indices.len() / 3) as u32
    }

    /// Whether `vertices` more vertices and `triangles` more triangles keep every buffer within `max` bytes.
    fn room(&self, vertices: u64, triangles: u64, max: u64) -> bool {
        let v = self.vertices() + vertices;
        v * 16 <= max && v * 12 <= max && (self.indices.len() as u64 + 3 * triangles) * 4 <= max && v <= u32::MAX as u64
    }
}

fn upload<'a>(
    gpu: &GpuContext,
    label: &str,
    meshes: impl Iterator<Item = &'a Mesh>,
    layout: &wgpu::BindGroupLayout,
    uniform: &wgpu::Buffer,
    max_binding_bytes: u64,
) -> Result<Geometry> {
    let max = max_binding_bytes.max(48);
    let mut done: Vec<Gather> = Vec::new();
    let mut cur = Gather::default();
    let mut ranges = Vec::new();
    let mut triangles: u64 = 0;
    for m in meshes {
        if triangles + m.indices.len() as u64 > u32::MAX as u64 / 3 {
            return Err(OitError::OutOfMemory(format!(
                "the {label} meshes have more than {} triangles, the most one draw numbers: split the scene",
                u32::MAX / 3
            )));
        }
        let centroid = if m.positions.is_empty() {
            Vec3::ZERO
        } else {
            m.positions.iter().map(|p| Vec3::from(*p)).sum::<Vec3>() / m.positions.len() as f32
        };
        ranges.push(MeshRange { first_triangle: triangles as u32, triangles: m.indices.len() as u32, centroid });
        triangles += m.indices.len() as u64;
        if cur.room(m.positions.len() as u64, m.indices.len() as u64, max) {
            // The whole mesh: its vertices in order, its indices offset.
            let base = cur.vertices() as u32;
            cur.positions.extend(m.positions.iter().flatten());
            cur.colors.extend_from_slice(&m.colors);
            cur.indices.extend(m.indices.iter().flatten().map(|&i| i + base));
            continue;
        }
        // Triangle by triangle, each chunk with the vertices its triangles use.
        let mut local = vec![u32::MAX; m.positions.len()];
        let mut stamp = vec![usize::MAX; m.positions.len()];
        for tri in &m.indices {
            if !cur.room(3, 1, max) {
                let next = cur.first_triangle + cur.triangles();
                done.push(std::mem::replace(&mut cur, Gather { first_triangle: next, ..Default::default() }));
            }
            let id = done.len();
            for &v in tri {
                let v = v as usize;
                if stamp[v] != id {
                    stamp[v] = id;
                    local[v] = cur.vertices() as u32;
                    cur.positions.extend(m.positions[v]);
                    cur.colors.push(m.colors[v]);
                }
                cur.indices.push(local[v]);
            }
        }
    }
    done.push(cur);
    let make = |name: &str, bytes: &[u8]| {
        let b = storage_buffer(&gpu.device, name, bytes.len() as u64, wgpu::BufferUsages::empty());
        if !bytes.is_empty() {
            gpu.queue.write_buffer(&b, 0, bytes);
        }
        b
    };
    let mut bytes = 0;
    let chunks = done
        .iter()
        .filter(|g| g.triangles() > 0 || done.len() == 1)
        .map(|g| {
            bytes += g.positions.len() as u64 * 4 + g.colors.len() as u64 * 16 + g.indices.len() as u64 * 4;
            let info = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("chunk"),
                size: 16,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            gpu.queue.write_buffer(&info, 0, bytemuck::cast_slice(&[g.first_triangle, g.triangles(), 0, 0]));
            let pos = make("positions", bytemuck::cast_slice(&g.positions));
            let col = make("colors", bytemuck::cast_slice(&g.colors));
            let idx = make("indices", bytemuck::cast_slice(&g.indices));
            let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: pos.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: col.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: idx.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: info.as_entire_binding() },
                ],
            });
            Chunk { group, first_triangle: g.first_triangle, triangles: g.triangles() }
        })
        .collect();
    Ok(Geometry { chunks, triangles: triangles as u32, meshes: ranges, bytes })
}

impl GpuScene {
    /// Uploads `scene` in chunks whose buffers each fit `max_binding_bytes`.
    pub fn new(
        gpu: &GpuContext,
        scene: &Scene,
        layout: &wgpu::BindGroupLayout,
        uniform: &wgpu::Buffer,
        max_binding_bytes: u64,
    ) -> Result<Self> {
        Ok(Self {
            transparent: upload(gpu, "transparent", scene.transparent(), layout, uniform, max_binding_bytes)?,
            opaque: upload(gpu, "opaque", scene.opaque(), layout, uniform, max_binding_bytes)?,
        })
    }
}
