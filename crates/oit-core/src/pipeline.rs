//! Builders for the two kinds of pipeline every method uses: geometry passes over the
//! scene (vertex pulling) and full-screen passes.

use crate::targets::DEPTH_FORMAT;

/// Depth state of transparent geometry passes: test against the opaque depth, never write.
pub fn depth_test_only() -> Option<wgpu::DepthStencilState> {
    read_only_depth(wgpu::CompareFunction::Less)
}

/// Depth state of a coverage-mask geometry pass: the multisampled attachment only gives the
/// pass its sample count; the shader tests each sample against its own opaque depth.
pub fn raster_only() -> Option<wgpu::DepthStencilState> {
    read_only_depth(wgpu::CompareFunction::Always)
}

fn read_only_depth(compare: wgpu::CompareFunction) -> Option<wgpu::DepthStencilState> {
    Some(wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(false),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    })
}

pub fn layout(device: &wgpu::Device, groups: &[&wgpu::BindGroupLayout]) -> wgpu::PipelineLayout {
    let groups: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(|g| Some(*g)).collect();
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: None, bind_group_layouts: &groups, immediate_size: 0 })
}

/// A pipeline drawing scene triangles with `vs_main` and the fragment entry `fs`.
pub fn geometry(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    fs: &str,
    targets: &[Option<wgpu::ColorTargetState>],
    depth: Option<wgpu::DepthStencilState>,
) -> wgpu::RenderPipeline {
    geometry_samples(device, label, module, layout, fs, targets, depth, 1)
}

/// [`geometry`] rasterized at `samples` samples a pixel (the shader reads the coverage mask).
#[allow(clippy::too_many_arguments)]
pub fn geometry_samples(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    fs: &str,
    targets: &[Option<wgpu::ColorTargetState>],
    depth: Option<wgpu::DepthStencilState>,
    samples: u32,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState { module, entry_point: Some("vs_main"), compilation_options: Default::default(), buffers: &[] },
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        depth_stencil: depth,
        multisample: wgpu::MultisampleState { count: samples, ..Default::default() },
        fragment: Some(wgpu::FragmentState { module, entry_point: Some(fs), compilation_options: Default::default(), targets }),
        multiview_mask: None,
        cache: None,
    })
}

/// A full-screen pass writing `targets` with the fragment entry `fs`.
pub fn fullscreen_targets(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    fs: &str,
    targets: &[Option<wgpu::ColorTargetState>],
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState { module, entry_point: Some("vs_fullscreen"), compilation_options: Default::default(), buffers: &[] },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState { module, entry_point: Some(fs), compilation_options: Default::default(), targets }),
        multiview_mask: None,
        cache: None,
    })
}

/// A compute pipeline for the entry `entry` of `module`.
pub fn compute(device: &wgpu::Device, layout: &wgpu::PipelineLayout, module: &wgpu::ShaderModule, entry: &str) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
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

/// A geometry pass that only reads the opaque depth (bound as a texture at the same time).
pub fn capture_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    depth: &'e wgpu::TextureView,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment { view: depth, depth_ops: None, stencil_ops: None }),
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// A pass that draws over the opaque scene: the base color is copied to the output first, and
/// the pass blends into it against `depth` (read-only with `depth_ops` None).
pub fn over_base_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    targets: &'e crate::targets::Targets,
    depth: &'e wgpu::TextureView,
    depth_ops: Option<wgpu::Operations<f32>>,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    let out = &targets.out_texture;
    enc.copy_texture_to_texture(targets.base_texture.as_image_copy(), out.as_image_copy(), out.size());
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &targets.out,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment { view: depth, depth_ops, stencil_ops: None }),
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

fn cleared(view: &wgpu::TextureView) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
    })
}

/// A pass that writes `target` entirely (full-screen resolves).
pub fn resolve_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    target: &'e wgpu::TextureView,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    resolve_targets(enc, label, &[cleared(target)], timestamps)
}

/// A full-screen resolve that also writes the per-pixel error bound.
pub fn resolve_with_bound<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    targets: &'e crate::targets::Targets,
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    resolve_targets(enc, label, &[cleared(&targets.out), cleared(&targets.bound)], timestamps)
}

fn resolve_targets<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &str,
    attachments: &[Option<wgpu::RenderPassColorAttachment<'e>>],
    timestamps: Option<wgpu::RenderPassTimestampWrites<'e>>,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: attachments,
        depth_stencil_attachment: None,
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}
