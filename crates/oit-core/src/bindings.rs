//! The formats and bind-group layouts every pass shares: the frame's target formats, group 0
//! (the scene), group 1 (the opaque targets, single or per sample) and the entries of method
//! groups. Depends on wgpu alone, so that everything that builds pipelines can use it.

pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The census's count target: fragments add 1.0 by blending (exact below 2^24).
pub const COUNT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// Per-pixel error bound written by methods that derive one.
pub const BOUND_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

pub fn targets_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    opaque_layout(device, "targets", wgpu::TextureViewDimension::D2)
}

/// Group 1 of storage-writing and resolve passes: the opaque depth (binding 0) and base
/// color (binding 1), as single textures or, for coverage-mask frames, arrays of layers.
fn opaque_layout(device: &wgpu::Device, label: &str, view_dimension: wgpu::TextureViewDimension) -> wgpu::BindGroupLayout {
    let tex = |binding, sample_type| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture { sample_type, view_dimension, multisampled: false },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[tex(0, wgpu::TextureSampleType::Depth), tex(1, wgpu::TextureSampleType::Float { filterable: false })],
    })
}

/// Group 1 of a coverage-mask frame (shaders/common/targets_samples.wgsl): the opaque depth
/// and base color of each sample position, as layers of 2D arrays.
pub fn samples_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    opaque_layout(device, "sample targets", wgpu::TextureViewDimension::D2Array)
}

pub fn scene_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let storage_in = |binding, visibility| wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let storage = |binding| storage_in(binding, wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::COMPUTE);
    let uniform = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    };
    // The frame uniform, positions, colors, indices, the chunk's place in the scene, the
    // vertex attributes of shading, and the material table that fragments shade with.
    let all = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("scene"),
        entries: &[uniform(0), storage(1), storage(2), storage(3), uniform(4), storage(5), storage_in(6, all)],
    })
}

/// Layout entry of a read-write storage buffer visible to fragment and compute shaders.
pub fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: false },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
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
