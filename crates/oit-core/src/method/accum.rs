//! Float render targets shared by the blended methods (`wsum`, `wavg`, `wboit`,
//! `stochastic`): premultiplied color summed into RGBA32F and a companion R32F target (a
//! count, or revealage multiplied down), drawn by one blended geometry pass and read by a
//! full-screen resolve. hybrid's blended tail (ktab.rs) keeps its four targets the same way.

use super::frame::FrameCtx;
use crate::cache::Layout;

pub(crate) const ACCUM_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub(crate) const AUX_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

pub(crate) use crate::pipeline::ADD;

/// dst * (1 - src): revealage, the product of (1 - alpha).
pub(crate) const REVEAL: wgpu::BlendComponent = wgpu::BlendComponent {
    src_factor: wgpu::BlendFactor::Zero,
    dst_factor: wgpu::BlendFactor::OneMinusSrc,
    operation: wgpu::BlendOperation::Add,
};

/// How the companion target blends and what it starts from.
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum Companion {
    /// Summed from zero (a count or an alpha sum).
    Sum,
    /// Multiplied down from one (revealage).
    Reveal,
}

/// A color target of `format` that fragments blend into by `blend` (color and alpha alike).
pub(crate) fn blended(format: wgpu::TextureFormat, blend: wgpu::BlendComponent) -> Option<wgpu::ColorTargetState> {
    Some(wgpu::ColorTargetState {
        format,
        blend: Some(wgpu::BlendState { color: blend, alpha: blend }),
        write_mask: wgpu::ColorWrites::ALL,
    })
}

/// The two color targets of the accumulation pass (`Accum` of shaders/common/accum_targets.wgsl).
pub(crate) fn accumulation_targets(aux: Companion) -> Vec<Option<wgpu::ColorTargetState>> {
    vec![blended(ACCUM_FORMAT, ADD), blended(AUX_FORMAT, if aux == Companion::Reveal { REVEAL } else { ADD })]
}

/// Bytes a pixel of the two targets.
pub const TARGET_BYTES: u64 = 16 + 4;

/// Float render targets of the frame's size that a geometry pass blends into and a resolve
/// reads back as textures: the blended methods' two (`ACCUM_FORMAT`, `AUX_FORMAT`) and
/// hybrid's blended tail's four (ktab.rs). Tiles of a frame share them, each drawing its part.
pub(crate) struct FloatTargets {
    size: (u32, u32),
    formats: Vec<wgpu::TextureFormat>,
    views: Vec<wgpu::TextureView>,
    /// The targets as textures at `bindings` (the layout `Layout::Textures(bindings)`, in the
    /// order of the formats).
    pub group: wgpu::BindGroup,
}

impl FloatTargets {
    /// The targets of `formats` in `slot`, made anew when the frame size or formats changed; a resolve
    /// reads them at `bindings` of its group.
    pub fn ensure<'s>(
        slot: &'s mut Option<FloatTargets>,
        cx: &FrameCtx<'_>,
        formats: &[wgpu::TextureFormat],
        bindings: &'static [(&'static str, u32)],
    ) -> &'s FloatTargets {
        let size = (cx.targets.width, cx.targets.height);
        if slot.as_ref().is_none_or(|t| t.size != size || t.formats != formats) {
            let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
            let views: Vec<wgpu::TextureView> = formats
                .iter()
                .map(|&f| {
                    crate::targets::texture(&cx.gpu.device, "float target", size.0, size.1, f, usage).create_view(&Default::default())
                })
                .collect();
            let resources: Vec<(&str, wgpu::BindingResource<'_>)> =
                bindings.iter().zip(&views).map(|((name, _), v)| (*name, wgpu::BindingResource::TextureView(v))).collect();
            let group = cx.group(Layout::Textures(bindings), &resources);
            *slot = Some(FloatTargets { size, formats: formats.to_vec(), views, group });
        }
        slot.as_ref().expect("made above")
    }

    /// The targets as a pass's color attachments, each cleared to its value in `clears`.
    pub fn attachments(&self, clears: &[wgpu::Color]) -> Vec<Option<wgpu::RenderPassColorAttachment<'_>>> {
        self.views
            .iter()
            .zip(clears)
            .map(|(view, &clear)| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
                })
            })
            .collect()
    }

    /// The blended methods' two targets: accumulated color and the companion.
    pub fn accumulation<'s>(
        slot: &'s mut Option<FloatTargets>,
        cx: &FrameCtx<'_>,
        bindings: &'static [(&'static str, u32)],
    ) -> &'s FloatTargets {
        Self::ensure(slot, cx, &[ACCUM_FORMAT, AUX_FORMAT], bindings)
    }

    /// Records the blended methods' accumulation pass (timed as "accumulate"): `pipeline` over
    /// the transparent geometry, tested against the opaque depth, scissored to the tile, with
    /// `groups` bound at 1, 2, ...
    pub fn accumulate(
        &self,
        cx: &mut FrameCtx<'_>,
        enc: &mut wgpu::CommandEncoder,
        aux: Companion,
        pipeline: &wgpu::RenderPipeline,
        groups: &[&wgpu::BindGroup],
    ) {
        let aux_clear = if aux == Companion::Reveal { wgpu::Color::WHITE } else { wgpu::Color::TRANSPARENT };
        self.blend("accumulate", cx, enc, &[wgpu::Color::TRANSPARENT, aux_clear], pipeline, groups);
    }

    /// Records a blended geometry pass named `label` into these targets, each cleared to its
    /// value in `clears`, as `accumulate` does.
    pub fn blend(
        &self,
        label: &'static str,
        cx: &mut FrameCtx<'_>,
        enc: &mut wgpu::CommandEncoder,
        clears: &[wgpu::Color],
        pipeline: &wgpu::RenderPipeline,
        groups: &[&wgpu::BindGroup],
    ) {
        let attachments = self.attachments(clears);
        let (depth, scene) = (&cx.targets.depth, cx.scene);
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment { view: depth, depth_ops: None, stencil_ops: None }),
            timestamp_writes: cx.timer.render_pass(label),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        cx.tile.scissor(&mut pass);
        pass.set_pipeline(pipeline);
        for (i, g) in groups.iter().enumerate() {
            pass.set_bind_group(1 + i as u32, *g, &[]);
        }
        scene.transparent.draw_all(&mut pass);
    }
}
