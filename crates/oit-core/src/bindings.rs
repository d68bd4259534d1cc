//! The formats and bind-group layout entries every pass shares: the frame's target formats,
//! group 0 (the scene), group 1 (the opaque targets, single or per sample) and the entries of
//! method groups (`cache::Layout::entries` puts them together). Depends on wgpu alone, so that
//! everything that builds pipelines can use it.

pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The census's count target: fragments add 1.0 by blending (exact below 2^24).
pub const COUNT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// Per-pixel error bound written by methods that derive one.
pub const BOUND_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// Group 1 of storage-writing and resolve passes (`cache::Layout::Targets` and
/// `SampleTargets`): the opaque depth (binding 0) and base color (binding 1), as single
/// textures or, for coverage-mask frames (shaders/common/targets_samples.wgsl), as 2D arrays
/// with a layer per sample position.
pub fn opaque_entries(view_dimension: wgpu::TextureViewDimension) -> Vec<wgpu::BindGroupLayoutEntry> {
    let tex = |binding, sample_type| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture { sample_type, view_dimension, multisampled: false },
        count: None,
    };
    vec![tex(0, wgpu::TextureSampleType::Depth), tex(1, wgpu::TextureSampleType::Float { filterable: false })]
}

fn buffer_entry(binding: u32, visibility: wgpu::ShaderStages, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

/// Group 0 (shaders/common/scene.wgsl): the frame uniform, positions, colors, indices, the
/// chunk's place in the scene, the vertex attributes of shading, the material table that
/// fragments shade with, the instance table, the chunk's segments (compute passes over the
/// drawn triangles) and a strand or particle set's corners (common/primitives.wgsl).
pub fn scene_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    let all = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
    let read = wgpu::BufferBindingType::Storage { read_only: true };
    let storage = |binding| buffer_entry(binding, wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::COMPUTE, read);
    let uniform = |binding| buffer_entry(binding, all, wgpu::BufferBindingType::Uniform);
    let compute = |binding| buffer_entry(binding, wgpu::ShaderStages::COMPUTE, read);
    vec![
        uniform(0),
        storage(1),
        storage(2),
        storage(3),
        uniform(4),
        storage(5),
        buffer_entry(6, all, read),
        storage(7),
        compute(8),
        storage(9),
        atlas_entry(10),
    ]
}

/// The texture atlas (upload/atlas.rs `Atlas`): every image of the scene's materials with its mips,
/// read texel by texel (shaders/common/shading.wgsl filters and decodes sRGB).
fn atlas_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
        count: None,
    }
}

/// Group 0 of the expansion pass (shaders/expand.wgsl): the scene's bindings with the expanded
/// corners (binding 9) writable, for a compute pass alone.
pub fn expand_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    let compute = wgpu::ShaderStages::COMPUTE;
    let read = wgpu::BufferBindingType::Storage { read_only: true };
    let uniform = |binding| buffer_entry(binding, compute, wgpu::BufferBindingType::Uniform);
    let storage = |binding| buffer_entry(binding, compute, read);
    let written = buffer_entry(9, compute, wgpu::BufferBindingType::Storage { read_only: false });
    vec![uniform(0), storage(1), storage(2), storage(3), uniform(4), storage(5), storage(6), storage(7), written]
}

/// The prefix sum's group (shaders/scan.wgsl): the data and the block sums, read-write, and
/// the level's uniform.
pub fn scan_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    let storage = wgpu::BufferBindingType::Storage { read_only: false };
    let compute = wgpu::ShaderStages::COMPUTE;
    vec![buffer_entry(0, compute, storage), buffer_entry(1, compute, storage), buffer_entry(2, compute, wgpu::BufferBindingType::Uniform)]
}

/// Layout entry of a read-write storage buffer visible to fragment and compute shaders.
pub fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    let visibility = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
    buffer_entry(binding, visibility, wgpu::BufferBindingType::Storage { read_only: false })
}

/// Layout entry of an unfilterable float texture read by fragment shaders (accumulation
/// targets a resolve pass loads).
pub fn float_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}
