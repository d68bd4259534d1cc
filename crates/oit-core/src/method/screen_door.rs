//! `screen_door`: screen-door transparency (RTR 5.5) with a 4 x 4 ordered dither: one
//! geometry pass that draws the nearest fragment whose alpha beats its pixel's threshold,
//! opaque (shaders/screen_door.wgsl).

use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{never, ErrorBound, FrameBytes, Linear, Memory, MethodInfo, Order, FRAMES};
use crate::bindings::{COLOR_FORMAT, DEPTH_FORMAT};
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::passes;
use crate::pipeline;
use crate::targets::texture;

pub const INFO: MethodInfo = MethodInfo {
    name: "screen_door",
    summary: "screen-door transparency: a 4x4 ordered-dither mask of alpha, nearest survivor drawn opaque",
    exact: false,
    bounded_memory: true,
    passes: &["dithered geometry (depth test and write)"],
    params: &[],
    features: wgpu::Features::empty(),
    order: Order::BitwiseExceptTies,
    antialias_modes: FRAMES,
    memory: Memory::Frame(BYTES),
    error_bound: ErrorBound::None,
    census: false,
    census_when: never,
    main: None,
    pipelines: &[PIPELINES],
    constants: &[],
    create: |_, _| Box::new(ScreenDoor { depth: None }),
};

/// Bytes screen_door allocates: its own depth buffer.
const BYTES: FrameBytes = FrameBytes { per_pixel: Linear::bytes(4), fixed: 0 };

const PIPELINES: &[PipelineSpec] = &[PipelineSpec::geometry("screen_door.wgsl", "fs_door", &[Layout::Scene])];

struct ScreenDoor {
    depth: Option<((u32, u32), wgpu::Texture, wgpu::TextureView)>,
}

impl Method for ScreenDoor {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let d = &cx.gpu.device;
        let t = cx.targets;
        let pipeline = cx.draw_pipeline(spec(PIPELINES, "fs_door"), &[], vec![Some(COLOR_FORMAT.into())], pipeline::depth_write());
        let size = (t.width, t.height);
        if self.depth.as_ref().is_none_or(|(s, _, _)| *s != size) {
            let tex = texture(
                d,
                "screen door depth",
                size.0,
                size.1,
                DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_DST,
            );
            let view = tex.create_view(&Default::default());
            self.depth = Some((size, tex, view));
        }
        let (_, depth_tex, depth_view) = self.depth.as_ref().expect("made above");
        let mut enc = d.create_command_encoder(&Default::default());
        enc.copy_texture_to_texture(t.depth_texture.as_image_copy(), depth_tex.as_image_copy(), depth_tex.size());
        {
            let depth_ops = Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store });
            let mut pass =
                passes::over_base_pass(&mut enc, "screen door", t, depth_view, depth_ops, cx.tile, cx.timer.render_pass("dither"));
            pass.set_pipeline(&pipeline);
            cx.scene.transparent.draw_all(&mut pass);
        }
        cx.gpu.queue.submit([enc.finish()]);
        Ok(Outcome::Done(MethodReport { memory_bytes: BYTES.at(size.0 as u64 * size.1 as u64, cx.params), ..Default::default() }))
    }
}
