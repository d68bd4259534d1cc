//! An egui_kittest renderer on egui-wgpu, after egui_kittest's own `WgpuTestRenderer`: that
//! one comes with its "wgpu" feature, which turns on wgpu's GL backend (and, with "eframe",
//! accesskit's D-Bus stack), a second build of wgpu that oit-core does not share. This one
//! uses the viewer's device setup, so the app and egui render on one device as in eframe.

use std::sync::Arc;

use eframe::egui;
use eframe::egui_wgpu::{self, RenderState, ScreenDescriptor};
use egui_kittest::TestRenderer;
use oit_core::GpuContext;

pub struct WgpuRenderer {
    pub state: RenderState,
}

impl WgpuRenderer {
    /// A device from `oit_viewer::gpu::setup` on the software adapter when there is one.
    pub fn new() -> Self {
        let setup = oit_viewer::gpu::setup(None, true);
        let instance = pollster::block_on(setup.new_instance());
        let config = egui_wgpu::WgpuConfiguration { wgpu_setup: setup, ..Default::default() };
        let state = pollster::block_on(RenderState::create(&config, &instance, None, egui_wgpu::RendererOptions::PREDICTABLE))
            .expect("a wgpu device for the tests");
        Self { state }
    }

    /// The engine's context on this device, as the app gets it from eframe.
    pub fn context(&self) -> Result<Arc<GpuContext>, String> {
        oit_viewer::gpu::context(Some(&self.state))
    }
}

impl TestRenderer for WgpuRenderer {
    fn handle_delta(&mut self, delta: &mut egui::TexturesDelta) {
        let mut renderer = self.state.renderer.write();
        #[allow(clippy::iter_over_hash_type)] // order does not matter
        for (id, images) in delta.set.drain() {
            for image in images {
                renderer.update_texture(&self.state.device, &self.state.queue, id, &image);
            }
        }
        #[allow(clippy::iter_over_hash_type)]
        for id in delta.free.drain() {
            renderer.free_texture(&id);
        }
    }

    fn render(&mut self, ctx: &egui::Context, output: &egui::FullOutput) -> Result<image::RgbaImage, String> {
        let (device, queue) = (&self.state.device, &self.state.queue);
        let mut renderer = self.state.renderer.write();
        let size = ctx.content_rect().size() * ctx.pixels_per_point();
        let screen =
            ScreenDescriptor { pixels_per_point: ctx.pixels_per_point(), size_in_pixels: [size.x.round() as u32, size.y.round() as u32] };
        let shapes = ctx.tessellate(output.shapes.clone(), ctx.pixels_per_point());
        let mut encoder = device.create_command_encoder(&Default::default());
        let user = renderer.update_buffers(device, queue, &mut encoder, &shapes, &screen);
        let [w, h] = screen.size_in_pixels;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("kittest frame"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.state.target_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        {
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("kittest egui"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        resolve_target: None,
                        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
                        depth_slice: None,
                    })],
                    ..Default::default()
                })
                .forget_lifetime();
            renderer.render(&mut pass, &shapes, &screen);
        }
        let row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("kittest readback"),
            size: row as u64 * h as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: None },
            },
            texture.size(),
        );
        queue.submit(user.into_iter().chain([encoder.finish()]));
        let (tx, rx) = std::sync::mpsc::channel();
        buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| drop(tx.send(r)));
        device.poll(wgpu::PollType::Wait { submission_index: None, timeout: None }).map_err(|e| format!("waiting for the GPU: {e}"))?;
        rx.recv().map_err(|e| e.to_string())?.map_err(|e| e.to_string())?;
        let mapped = buffer.slice(..).get_mapped_range().map_err(|e| format!("{e:?}"))?;
        let mut data: Vec<u8> = mapped.chunks_exact(row as usize).flat_map(|r| &r[..w as usize * 4]).copied().collect();
        if matches!(self.state.target_format, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb) {
            data.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
        }
        image::RgbaImage::from_raw(w, h, data).ok_or_else(|| "readback size mismatch".to_string())
    }
}
