//! `mlab`: multi-layer alpha blending (Salvi & Vaidyanathan 2014) as the seed designs it:
//! `layers` depth-sorted blended layers a pixel, updated by each fragment inside its pixel's
//! critical section (pixel_lock.rs) in one geometry pass, the farthest two merged on overflow,
//! then composited (shaders/mlab.wgsl). `mlab_lists` is the list version it replaces.

use super::adaptive;
use super::frame::{FrameCtx, Method, Outcome};
use super::info::{FrameBytes, Linear, Memory, MethodInfo};
use super::params::IntParam;
use super::pixel_lock::{locked_layout, PixelLocks, LOCK_BYTES, LOCK_STATS_BYTES};
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::shader::Const;

const OWN: Layout = locked_layout!("layers");
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, OWN];
const SHADER: &str = "mlab.wgsl";
const PIPELINES: &[PipelineSpec] =
    &[PipelineSpec::geometry(SHADER, "fs_insert", GROUPS), PipelineSpec::fullscreen(SHADER, "fs_resolve", GROUPS)];

/// Bytes of a layer (color, transmittance, depth).
const LAYER_BYTES: u64 = 20;

/// k layers and the lock word a pixel.
const BYTES: FrameBytes = FrameBytes { per_pixel: Linear::per(LAYERS, LAYER_BYTES, LOCK_BYTES), fixed: LOCK_STATS_BYTES };

const LAYERS: IntParam = IntParam::new("layers", (1, 32, 4), "blended layers kept per pixel").compiled_as("LAYERS");

pub const INFO: MethodInfo = MethodInfo {
    name: "mlab",
    summary: "multi-layer alpha blending: `layers` depth-sorted blended layers per pixel under per-pixel locks, the farthest two merged on overflow",
    passes: &["insert into the layers (geometry, per-pixel lock)", "composite (full screen)"],
    params: &[LAYERS.0],
    features: wgpu::Features::empty(),
    memory: Memory::Frame(BYTES),
    main: Some("layers"),
    pipelines: &[PIPELINES],
    constants: &[Const::U32("LAYERS_PLUS_ONE", 5)],
    create: |_, _| Box::<Mlab>::default(),
    ..adaptive::INFO
};

#[derive(Default)]
struct Mlab {
    locks: PixelLocks,
}

impl Method for Mlab {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let n = LAYERS.of(cx.params);
        let consts = [LAYERS.constant(cx.params), Const::U32("LAYERS_PLUS_ONE", n + 1)];
        let (group, mut enc) = self.locks.begin(cx, OWN, &format!("mlab with layers = {n}"), (LAYER_BYTES, n))?;
        cx.capture(&mut enc, "insert", &cx.capture_pipeline(spec(PIPELINES, "fs_insert"), &consts), group);
        let resolve = cx.resolve_pipeline(spec(PIPELINES, "fs_resolve"), &consts, false);
        cx.resolve(&mut enc, "composite", &resolve, group, false);
        let memory = BYTES.at(cx.pixels(), cx.params);
        self.locks.finish(cx, enc, memory).map(Outcome::Done)
    }
}
