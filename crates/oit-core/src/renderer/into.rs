//! Frames into a caller's texture: the engine's transparent pass drawn over an opaque picture
//! the caller rendered itself (its color and depth, on this renderer's device), written into
//! the caller's color texture with no readback (`Renderer::render_into`).

use super::Renderer;
use crate::bindings::DEPTH_FORMAT;
use crate::cache::{bind_named, Draw, BLIT, BLIT_SRGB};
use crate::error::{invalid, Result};
use crate::method::ParamValue;
use crate::scene::{Camera, Scene};
use crate::stats::Stats;

/// A caller's texture to render into, on the renderer's device, at the renderer's size.
pub struct Target<'a> {
    /// Receives the composite's RGB; its alpha channel is left as it is (any color format the
    /// device renders to; needs RENDER_ATTACHMENT, and TEXTURE_BINDING where `depth` is given:
    /// its contents are then the opaque picture the transparent geometry is drawn over).
    pub color: &'a wgpu::Texture,
    /// The caller's opaque depth (Depth32Float with COPY_SRC, cleared to 1 and drawn with the
    /// camera's projection): it hides transparent fragments behind it. None: the picture under
    /// the transparent geometry is the scene's own opaque meshes over the background, as in
    /// `Renderer::render`.
    pub depth: Option<&'a wgpu::Texture>,
    /// Writes sRGB-encoded RGB into a `color` whose format does not encode (an egui native
    /// texture of Rgba8Unorm, which egui samples as encoded bytes); false for an sRGB or a float
    /// format, which take linear values.
    pub encode_srgb: bool,
}

/// The caller's textures while a frame renders into them.
pub(super) struct IntoTarget {
    pub color: wgpu::Texture,
    pub depth: Option<wgpu::Texture>,
    pub encode_srgb: bool,
}

impl Renderer {
    /// Renders `scene` with `method_name` into `target` (see [`Target`]): the scene's opaque
    /// meshes are drawn over the caller's picture and depth, then the method's transparent
    /// pass, and the composite is written into `target.color`. Returns the frame's stats; the
    /// frame's targets stay frame-sized (a memory budget that cannot hold them is refused).
    pub fn render_into(
        &mut self,
        scene: &Scene,
        camera: &Camera,
        method_name: &str,
        params: &[(String, ParamValue)],
        background: [f32; 3],
        target: Target<'_>,
    ) -> Result<Stats> {
        let size = |t: &wgpu::Texture| (t.width(), t.height());
        let want = (self.width, self.height);
        if size(target.color) != want {
            return Err(invalid!(
                "the target's color texture is {:?}, the renderer renders {want:?}: make them the same size",
                size(target.color)
            ));
        }
        let usage = target.color.usage();
        if !usage.contains(wgpu::TextureUsages::RENDER_ATTACHMENT) {
            return Err(invalid!("the target's color texture needs RENDER_ATTACHMENT usage"));
        }
        if let Some(d) = target.depth {
            if size(d) != want || d.format() != DEPTH_FORMAT || !d.usage().contains(wgpu::TextureUsages::COPY_SRC) {
                return Err(invalid!(
                    "the target's depth texture must be Depth32Float with COPY_SRC usage at {want:?}, got {:?} at {:?}",
                    d.format(),
                    size(d)
                ));
            }
            if !usage.contains(wgpu::TextureUsages::TEXTURE_BINDING) {
                return Err(invalid!(
                    "with a depth texture, the target's color texture is read as the opaque picture: it needs TEXTURE_BINDING usage"
                ));
            }
        }
        // Refused before any work: the census would otherwise draw into tile-sized targets.
        if !self.frame_targets(false) {
            return Err(self.target_refused());
        }
        let (info, params) = self.prepare(scene, method_name, params, background)?;
        self.into = Some(IntoTarget { color: target.color.clone(), depth: target.depth.cloned(), encode_srgb: target.encode_srgb });
        let frame = self.render_sample(&super::execute::Job { camera, info, params: &params, background, coverage: false });
        self.into = None;
        let mut stats = frame?.stats;
        stats.finish(&self.gpu.info.name, None);
        Ok(stats)
    }

    /// Draws `source` into the channels `mask` of `target`, pixel for pixel, sRGB-encoded with
    /// `encode_srgb` (`shaders/blit.wgsl`).
    pub(super) fn blit(
        &self,
        enc: &mut wgpu::CommandEncoder,
        source: &wgpu::TextureView,
        target: &wgpu::Texture,
        mask: wgpu::ColorWrites,
        encode_srgb: bool,
    ) {
        let d = &self.gpu.device;
        let color = wgpu::ColorTargetState { format: target.format(), blend: None, write_mask: mask };
        let spec = if encode_srgb { &BLIT_SRGB } else { &BLIT };
        let pipeline = self.gpu.cache.render(d, &spec.render(&[], Draw::Fullscreen, vec![Some(color)]));
        let group = bind_named(
            &self.gpu.device,
            &self.gpu.cache,
            BLIT.groups[0],
            "blit",
            &[("source", wgpu::BindingResource::TextureView(source))],
        );
        let view = target.create_view(&Default::default());
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("blit"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }
}
