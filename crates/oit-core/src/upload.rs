//! The scene on the GPU: transparent and opaque geometry, each as vertex-pulling buffers
//! (packed positions, RGBA per vertex, indices, and where the scene is shaded two vec4 of
//! normal, material and UVs per vertex) bound in group 0 with the frame uniform and the
//! material table with its textures (`surfaces`, shared by every chunk).

use glam::Vec3;

use crate::context::GpuContext;
use crate::error::{OitError, Result};
use crate::gpu_types::GpuMaterial;
use crate::scene::{Mesh, Scene};
use crate::shading::Shading;
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
    /// Whether any mesh is shaded (the frame uniform's flag).
    pub shaded: bool,
    /// Whether any mesh is textured.
    pub textured: bool,
}

/// Chunk contents on the host while they are gathered.
#[derive(Default)]
struct Gather {
    positions: Vec<f32>,
    colors: Vec<[f32; 4]>,
    indices: Vec<u32>,
    /// Two a vertex where the scene is shaded, else none.
    attributes: Vec<[f32; 4]>,
    first_triangle: u32,
    shaded: bool,
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
    uniform: &'a wgpu::Buffer,
    surfaces: &'a wgpu::Buffer,
    shaded: bool,
}

fn upload<'a>(
    gpu: &GpuContext,
    label: &str,
    meshes: impl Iterator<Item = (usize, &'a Mesh)>,
    shared: &Shared<'_>,
    max_binding_bytes: u64,
) -> Result<Geometry> {
    let max = max_binding_bytes.max(48);
    let mut done: Vec<Gather> = Vec::new();
    let mut cur = Gather { shaded: shared.shaded, ..Default::default() };
    let mut ranges = Vec::new();
    let mut triangles: u64 = 0;
    for (mesh, m) in meshes {
        let split;
        let m = if shared.shaded && m.material.shading == Shading::Flat {
            split = flat_corners(m);
            &split
        } else {
            m
        };
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
            (0..m.positions.len()).for_each(|v| cur.push_vertex(m, mesh, v));
            cur.indices.extend(m.indices.iter().flatten().map(|&i| i + base));
            continue;
        }
        // Triangle by triangle, each chunk with the vertices its triangles use.
        let mut local = vec![u32::MAX; m.positions.len()];
        let mut stamp = vec![usize::MAX; m.positions.len()];
        for tri in &m.indices {
            if !cur.room(3, 1, max) {
                let next = cur.first_triangle + cur.triangles();
                done.push(std::mem::replace(&mut cur, Gather { first_triangle: next, shaded: shared.shaded, ..Default::default() }));
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
            bytes +=
                g.positions.len() as u64 * 4 + g.colors.len() as u64 * 16 + g.indices.len() as u64 * 4 + g.attributes.len() as u64 * 16;
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
            let attr = make("attributes", bytemuck::cast_slice(&g.attributes));
            let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout: shared.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: shared.uniform.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: pos.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: col.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: idx.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: info.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 5, resource: attr.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 6, resource: shared.surfaces.as_entire_binding() },
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
        let shaded = scene.shaded();
        let table = if shaded { surfaces(scene) } else { vec![[0.0; 4]; 2] };
        if table.len() as u64 * 16 > max_binding_bytes {
            return Err(OitError::OutOfMemory(format!(
                "the scene's materials and textures take {} bytes, past a storage binding ({max_binding_bytes} bytes): \
                 use smaller textures",
                table.len() * 16
            )));
        }
        let buffer = storage_buffer(&gpu.device, "surfaces", table.len() as u64 * 16, wgpu::BufferUsages::empty());
        gpu.queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&table));
        let shared = Shared { layout, uniform, surfaces: &buffer, shaded };
        let meshes = || scene.meshes().iter().enumerate();
        let mut transparent = upload(gpu, "transparent", meshes().filter(|(_, m)| !m.opaque), &shared, max_binding_bytes)?;
        let opaque = upload(gpu, "opaque", meshes().filter(|(_, m)| m.opaque), &shared, max_binding_bytes)?;
        if shaded {
            transparent.bytes += table.len() as u64 * 16;
        }
        let textured = shaded && scene.meshes().iter().any(|m| m.material.texture.is_some());
        Ok(Self { transparent, opaque, shaded, textured })
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
    };
    for t in &m.indices {
        let p = t.map(|v| glam::DVec3::from(m.positions[v as usize].map(|x| x as f64)));
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero().as_vec3().to_array();
        out.normals.extend([n; 3]);
    }
    out
}

/// The material table (two vec4 a mesh: `GpuMaterial`), then the texels of every texture.
fn surfaces(scene: &Scene) -> Vec<[f32; 4]> {
    let meshes = scene.meshes();
    let mut texels: Vec<[f32; 4]> = Vec::new();
    let mut table: Vec<[f32; 4]> = Vec::with_capacity(2 * meshes.len());
    for m in meshes {
        let mat = &m.material;
        let flags = Shading::flags(mat);
        let mut texture = [0; 3];
        if let Some(t) = &mat.texture {
            texture = [(2 * meshes.len() + texels.len()) as u32, t.width, t.height];
            texels.extend_from_slice(&t.texels);
        }
        let g = GpuMaterial { specular: mat.specular, shininess: mat.shininess, opacity: mat.opacity, flags, texture, pad: 0 };
        table.extend_from_slice(bytemuck::cast_slice(&[g]));
        debug_assert!(mat.shading != Shading::Smooth || m.normals.len() == m.positions.len());
    }
    table.extend(texels);
    table
}
