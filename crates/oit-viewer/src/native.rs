//! Frames straight to the screen: the engine renders into a texture on eframe's device
//! (`Renderer::render_into`) and egui paints that texture, with no readback and no upload.
//! The plain image view uses it; the heatmaps, the comparison with the exact frame and frames
//! averaged over samples read frames back and upload them as egui images.

use eframe::egui;
use eframe::egui_wgpu;
use oit_core::{Camera, Frame, ParamValue, Renderer, Scene, Target};

/// A render target on eframe's device, registered with egui's renderer.
pub struct Native {
    render_state: egui_wgpu::RenderState,
    target: Option<(wgpu::Texture, egui::TextureId)>,
}

impl Native {
    pub fn new(render_state: egui_wgpu::RenderState) -> Self {
        Self { render_state, target: None }
    }

    /// The texture egui paints, once a frame has been rendered into it.
    pub fn texture_id(&self) -> Option<egui::TextureId> {
        self.target.as_ref().map(|(_, id)| *id)
    }

    /// Renders one frame of `method` into the target (made or resized to the renderer's size):
    /// its stats, in a frame without pixels on the CPU.
    pub fn render(
        &mut self,
        renderer: &mut Renderer,
        scene: &Scene,
        camera: &Camera,
        method: &str,
        params: &[(String, ParamValue)],
        background: [f32; 3],
    ) -> oit_core::Result<Frame> {
        let (w, h) = renderer.size();
        if self.target.as_ref().is_none_or(|(t, _)| (t.width(), t.height()) != (w, h)) {
            self.make_target(w, h);
        }
        let (texture, _) = self.target.as_ref().expect("made above");
        let stats =
            renderer.render_into(scene, camera, method, params, background, Target { color: texture, depth: None, encode_srgb: true })?;
        Ok(Frame { width: w, height: h, image: Vec::new(), depth_complexity: Vec::new(), error_bound: None, stats })
    }

    /// A target of `w` x `h` that holds sRGB-encoded bytes in a plain format: egui samples them
    /// as it does its own images (it blends in gamma space), and frames are encoded in the blit
    /// with the formula the viewer's CPU pictures use (heatmap::srgb8).
    fn make_target(&mut self, w: u32, h: u32) {
        let rs = &self.render_state;
        let texture = rs.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("oit-viewer frame"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        // Opaque from the start: frames write RGB only, and egui blends what it paints.
        let mut enc = rs.device.create_command_encoder(&Default::default());
        enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("oit-viewer frame clear"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        rs.queue.submit([enc.finish()]);
        let mut renderer = rs.renderer.write();
        let id = match self.target.take() {
            Some((_, id)) => {
                renderer.update_egui_texture_from_wgpu_texture(&rs.device, &view, wgpu::FilterMode::Nearest, id);
                id
            }
            None => renderer.register_native_texture(&rs.device, &view, wgpu::FilterMode::Nearest),
        };
        self.target = Some((texture, id));
    }
}
