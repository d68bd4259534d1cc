//! An engine's own opaque pass, as a caller of `Renderer::render_into` draws it before oit's
//! transparent pass: a full-screen triangle at NDC depth `z` in one color, into the caller's
//! color and depth textures (the example `over_opaque` and tests/render_into.rs share it).

/// The caller's textures: its picture and its depth.
pub struct Picture {
    pub color: wgpu::Texture,
    pub depth: wgpu::Texture,
}

/// Draws the caller's opaque picture: `rgb` at depth `z` over the left `cover` fraction of
/// the frame, the clear color `clear` (at depth 1) elsewhere.
pub fn draw_opaque(
    gpu: &oit_core::GpuContext,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    z: f32,
    rgb: [f32; 3],
    cover: f32,
    clear: [f64; 3],
) -> Picture {
    let d = &gpu.device;
    let texture = |label, format, usage| {
        d.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    use wgpu::TextureUsages as U;
    let color = texture("caller color", format, U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC | U::COPY_DST);
    let depth = texture("caller depth", wgpu::TextureFormat::Depth32Float, U::RENDER_ATTACHMENT | U::COPY_SRC);
    // A full-screen triangle, kept left of x = cover * width.
    let edge = cover * size.0 as f32;
    let source = format!(
        "@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {{
            let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
            return vec4<f32>(uv * 2.0 - 1.0, {z:?}, 1.0);
        }}
        @fragment fn fs(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {{
            if pos.x > {edge:?} {{ discard; }}
            return vec4<f32>({:?}, {:?}, {:?}, 1.0);
        }}",
        rgb[0], rgb[1], rgb[2]
    );
    let module =
        d.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some("caller"), source: wgpu::ShaderSource::Wgsl(source.into()) });
    let pipeline = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("caller opaque"),
        layout: None,
        vertex: wgpu::VertexState { module: &module, entry_point: Some("vs"), compilation_options: Default::default(), buffers: &[] },
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let color_view = color.create_view(&Default::default());
        let depth_view = depth.create_view(&Default::default());
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("caller opaque"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r: clear[0], g: clear[1], b: clear[2], a: 1.0 }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.draw(0..3, 0..1);
    }
    gpu.queue.submit([enc.finish()]);
    Picture { color, depth }
}

/// The pixels of a texture of `bytes_per_pixel` bytes a pixel, row-major.
pub fn read_texture(gpu: &oit_core::GpuContext, texture: &wgpu::Texture, bytes_per_pixel: u32) -> Vec<u8> {
    let (w, h) = (texture.width(), texture.height());
    let row = (w * bytes_per_pixel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("caller readback"),
        size: (row * h) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: None },
        },
        texture.size(),
    );
    gpu.queue.submit([enc.finish()]);
    buffer.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    gpu.wait().expect("the GPU finishes");
    let data = buffer.slice(..).get_mapped_range().expect("mapped").to_vec();
    data.chunks(row as usize).flat_map(|r| r[..(w * bytes_per_pixel) as usize].to_vec()).collect()
}
