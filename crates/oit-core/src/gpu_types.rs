//! `#[repr(C)]` structs shared with WGSL. Each mirrors a struct in `shaders/`; the
//! `layout_sizes` test checks the sizes naga computes against these.

use bytemuck::{Pod, Zeroable};

/// Mirrors `FrameUniform` in `shaders/common/scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniform {
    pub view_proj: [[f32; 4]; 4],
    pub background: [f32; 4],
    pub size: [u32; 2],
    pub triangle_count: u32,
    pub seed: u32,
    /// The screen tile a pass renders, in its targets' pixels: per-pixel storage is indexed
    /// within it.
    pub tile_origin: [u32; 2],
    pub tile_size: [u32; 2],
    /// The frame pixel of the targets' pixel (0, 0): (0, 0) unless the targets are tile-sized.
    pub target_origin: [u32; 2],
    pub pad: [u32; 2],
    /// The inverse of `view_proj`: the eye direction of a pixel (shaders/common/shading.wgsl).
    pub inv_view_proj: [[f32; 4]; 4],
    /// Ambient RGB; w is 0, a factor the shading-cost loop's result is multiplied by.
    pub ambient: [f32; 4],
    pub lights: [GpuLight; crate::shading::MAX_LIGHTS as usize],
}

/// Mirrors `Light` in `shaders/common/scene.wgsl`: unit L (towards the light) and radiance.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLight {
    pub to_light: [f32; 4],
    pub radiance: [f32; 4],
}

/// Mirrors the material records of `surfaces` in `shaders/common/shading.wgsl`
/// (`MATERIAL_VEC4S` vec4 each): one record of the material table.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuMaterial {
    pub specular: f32,
    pub shininess: f32,
    pub opacity: f32,
    /// `Shading::code()`, plus the flag bits of `Shading::flags`.
    pub flags: u32,
    /// Linear emissive RGB, and the alpha cutoff (read where ALPHA_TEST is set).
    pub emissive: [f32; 3],
    pub alpha_cutoff: f32,
    /// The base color texture and the emissive texture.
    pub maps: [GpuTextureMap; 2],
}

/// A texture as a material uses it: where its image's record is in `surfaces` (a header
/// (levels, sRGB, width, height), then (x, y, layer, width | height << 16) a level in the
/// atlas), the sampler's bits (`Sampler::bits`), and the UV transform's two rows.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuTextureMap {
    pub image: u32,
    pub sampler: u32,
    pub transform: [f32; 6],
}

/// vec4 a material record.
pub const MATERIAL_VEC4S: u32 = (std::mem::size_of::<GpuMaterial>() / 16) as u32;

/// Mirrors `Instance` in `shaders/common/scene.wgsl`: one row of the instance table.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuInstance {
    /// The transform, columns.
    pub model: [[f32; 4]; 4],
    /// The normal matrix (`Instance::normal_matrix`), columns padded to vec4.
    pub normal: [[f32; 4]; 3],
    /// RGBA factor of the vertex colors.
    pub color: [f32; 4],
    /// Added to a triangle's uploaded index to give its drawn index (wrapping).
    pub prim_offset: u32,
    /// 1 where the transform mirrors (front faces are clockwise).
    pub mirror: u32,
    pub pad: [u32; 2],
}

impl GpuInstance {
    pub fn new(inst: &crate::scene::Instance, prim_offset: u32) -> Self {
        let n = inst.normal_matrix().as_mat3();
        let col = |v: glam::Vec3| [v.x, v.y, v.z, 0.0];
        Self {
            model: inst.transform.as_mat4().to_cols_array_2d(),
            normal: [col(n.x_axis), col(n.y_axis), col(n.z_axis)],
            color: inst.color,
            prim_offset,
            mirror: inst.mirrors() as u32,
            pad: [0; 2],
        }
    }
}

/// Mirrors `Segment` in shaders/common/setup.wgsl: a mesh's local triangles in a chunk and
/// where its drawn triangles start among the chunk's.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuSegment {
    pub drawn_first: u32,
    pub lo: u32,
    pub triangles: u32,
    pub first_instance: u32,
}

/// Mirrors `Node` in `shaders/abuffer.wgsl`: depth, next index, straight RGBA.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PoolNode {
    pub depth: f32,
    pub next: u32,
    pub rgba: [f32; 4],
}

/// Mirrors `Node` in `shaders/abuffer_coverage.wgsl`: a pool node with its sample mask.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CoverageNode {
    pub depth: f32,
    pub next: u32,
    pub rgba: [f32; 4],
    pub mask: u32,
    pub pad: u32,
}

/// Mirrors `Node` in `shaders/adaptive_lists.wgsl`: a pool node with its primitive index.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PrimNode {
    pub depth: f32,
    pub next: u32,
    pub rgba: [f32; 4],
    pub prim: u32,
    pub pad: u32,
}

/// Mirrors `Alloc` in `shaders/common/pool.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct Alloc {
    pub count: u32,
    pub capacity: u32,
    pub escaped: u32,
    /// The sorted resolve's pixel lists (pixels with fragments, deep pixels) and the
    /// workgroups of the dispatches over them.
    pub listed: u32,
    pub deep: u32,
    pub groups: [u32; 6],
    pub pad: u32,
}

impl Alloc {
    /// Bytes before `groups`: where the indirect dispatches' arguments are copied from.
    pub const GROUPS_OFFSET: u64 = 20;
}

/// Mirrors `Node` in `shaders/compact_abuffer.wgsl`: depth, next link, triangle index.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CompactNode {
    pub depth: f32,
    pub next: u32,
    pub prim: u32,
}

/// Mirrors `PrimShading` in `shaders/compact_abuffer.wgsl`: clip-space corners and colors,
/// and the corners' shading normals (material index in w) and UVs.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PrimShading {
    pub clip: [[f32; 4]; 3],
    pub color: [[f32; 4]; 3],
    pub normal: [[f32; 4]; 3],
    pub uv: [[f32; 2]; 3],
    pub pad: [f32; 2],
}

/// Mirrors `Block` in `shaders/pall.wgsl`: a triangle's node block and pixel box.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PallBlock {
    pub start: u32,
    pub origin: u32,
    pub extent: u32,
    pub pad: u32,
}
