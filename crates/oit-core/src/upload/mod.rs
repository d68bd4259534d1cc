//! The scene on the GPU: transparent and opaque geometry, each as vertex-pulling buffers
//! (packed positions, RGBA per vertex, indices, and where the scene is shaded two vec4 of
//! normal, material and UVs per vertex) bound in group 0 with the frame uniform and the
//! material table with its textures (`surfaces`, shared by every chunk).

mod atlas;
mod gather;
mod geometry;

use crate::context::GpuContext;
use crate::error::{OitError, Result};
use crate::gpu_types::{GpuMaterial, GpuTextureMap, MATERIAL_VEC4S};
use crate::primitive::{Primitive, PRIM_MESH};
use crate::scene::Scene;
use crate::shading::{Shading, Texture, TextureMap};
use crate::targets::storage_buffer;
use atlas::Atlas;
use geometry::{Geometry, SceneBindings};

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
    /// Whether any splat set takes the depth of its peak along the ray (SPLAT_RAY).
    pub splat_ray: bool,
    /// Whether any material gives off light (EMISSIVE), and whether any tests alpha
    /// (ALPHA_TESTS).
    pub emissive: bool,
    pub alpha_test: bool,
    /// The bytes the materials' images with their mips take on the GPU (the atlas, bound in
    /// every chunk's group 0; 0 without textures: a 1-texel placeholder is bound).
    pub texture_bytes: u64,
    /// The matrices (`execute::expansion_view`) the corners in `expanded` were last built
    /// under; None until the first expansion.
    pub expanded_view: std::cell::Cell<Option<[u32; 34]>>,
}

impl GpuScene {
    /// The scene's buffers by what uploaded them: meshes (with materials, textures and the
    /// instance tables), strands, particles.
    pub fn bytes(&self) -> [u64; 4] {
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
        let bindings =
            SceneBindings { layout, expand_layout: &expand_layout, uniform, surfaces: &buffer, atlas: &atlas, shaded, instanced };
        let meshes = || scene.placed().enumerate().map(|(i, (m, list))| (i, m, list));
        let mut transparent = geometry::upload(gpu, "transparent", meshes().filter(|(_, m, _)| !m.opaque), &bindings, max_binding_bytes)?;
        let opaque = geometry::upload(gpu, "opaque", meshes().filter(|(_, m, _)| m.opaque), &bindings, max_binding_bytes)?;
        if shaded {
            transparent.bytes[PRIM_MESH as usize] += table.len() as u64 * 16 + atlas.bytes;
        }
        let textured = !images.is_empty();
        let primitives = scene.meshes().iter().any(|m| m.primitive != Primitive::Triangles || m.material.shading == Shading::Hair);
        let sets_only = scene.meshes().iter().all(|m| m.primitive != Primitive::Triangles);
        let phong = scene.meshes().iter().any(|m| matches!(m.material.shading, Shading::Flat | Shading::Smooth));
        let falloff = scene.meshes().iter().any(|m| m.material.falloff != crate::shading::Falloff::None);
        let splat_ray = scene.meshes().iter().any(|m| m.material.splat_depth == crate::shading::SplatDepth::Ray);
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
            splat_ray,
            texture_bytes: atlas.bytes,
            expanded_view: Default::default(),
        })
    }
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
