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

pub struct Geometry {
    pub group: wgpu::BindGroup,
    pub triangles: u32,
    pub meshes: Vec<MeshRange>,
    pub bytes: u64,
}

impl Geometry {
    /// Draws every triangle (three vertices each, pulled from storage).
    pub fn draw_all(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.triangles > 0 {
            pass.set_bind_group(0, &self.group, &[]);
            pass.draw(0..3 * self.triangles, 0..1);
        }
    }
}

pub struct GpuScene {
    pub transparent: Geometry,
    pub opaque: Geometry,
}

fn upload<'a>(
    gpu: &GpuContext,
    label: &str,
    meshes: impl Iterator<Item = &'a Mesh>,
    layout: &wgpu::BindGroupLayout,
    uniform: &wgpu::Buffer,
) -> Result<Geometry> {
    let mut positions: Vec<f32> = Vec::new();
    let mut colors: Vec<[f32; 4]> = Vec::new();
    let mut indices: Vec<u32> = Vec::new();
    let mut ranges = Vec::new();
    for m in meshes {
        let base = (positions.len() / 3) as u64;
        let first = (indices.len() / 3) as u32;
        if base + m.positions.len() as u64 > u32::MAX as u64 {
            return Err(OitError::OutOfMemory("the scene has more than 2^32 vertices".into()));
        }
        positions.extend(m.positions.iter().flatten());
        colors.extend_from_slice(&m.colors);
        indices.extend(m.indices.iter().flatten().map(|&i| i + base as u32));
        let centroid = if m.positions.is_empty() {
            Vec3::ZERO
        } else {
            m.positions.iter().map(|p| Vec3::from(*p)).sum::<Vec3>() / m.positions.len() as f32
        };
        ranges.push(MeshRange { first_triangle: first, triangles: m.indices.len() as u32, centroid });
    }
    let max = gpu.max_binding_bytes();
    let sizes = [positions.len() as u64 * 4, colors.len() as u64 * 16, indices.len() as u64 * 4];
    if let Some(big) = sizes.iter().find(|&&s| s > max) {
        return Err(OitError::OutOfMemory(format!(
            "{label} geometry needs a {big}-byte buffer but the adapter binds at most {max} bytes: \
             split the scene or decimate its meshes"
        )));
    }
    let make = |name: &str, bytes: &[u8]| {
        let b = storage_buffer(&gpu.device, name, bytes.len() as u64, wgpu::BufferUsages::empty());
        if !bytes.is_empty() {
            gpu.queue.write_buffer(&b, 0, bytes);
        }
        b
    };
    let pos = make("positions", bytemuck::cast_slice(&positions));
    let col = make("colors", bytemuck::cast_slice(&colors));
    let idx = make("indices", bytemuck::cast_slice(&indices));
    let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: pos.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: col.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 3, resource: idx.as_entire_binding() },
        ],
    });
    Ok(Geometry { group, triangles: (indices.len() / 3) as u32, meshes: ranges, bytes: sizes.iter().sum() })
}

impl GpuScene {
    pub fn new(gpu: &GpuContext, scene: &Scene, layout: &wgpu::BindGroupLayout, uniform: &wgpu::Buffer) -> Result<Self> {
        Ok(Self {
            transparent: upload(gpu, "transparent", scene.transparent(), layout, uniform)?,
            opaque: upload(gpu, "opaque", scene.opaque(), layout, uniform)?,
        })
    }
}
