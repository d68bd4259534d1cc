//! `adaptive`: adaptive transparency (Salvi et al. 2011) as the seed designs it: a visibility
//! function of at most `nodes` steps a pixel, built in a first geometry pass inside each pixel's
//! critical section (pixel_lock.rs), then each fragment shaded by it in a second, blended, and
//! composited (shaders/adaptive.wgsl). `adaptive_lists` is the list version it replaces.

use super::accum::{blended, FloatTargets, ACCUM_FORMAT, ADD};
use super::frame::{FrameCtx, Method, Outcome};
use super::info::{never, ErrorBound, FrameBytes, Linear, Memory, MethodInfo, Order, FRAMES};
use super::params::IntParam;
use super::pixel_lock::{locked_layout, PixelLocks, LOCK_BYTES, LOCK_STATS_BYTES};
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::shader::Const;

const OWN: Layout = locked_layout!("nodes");
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, OWN];
/// The resolve also reads the shading pass's sums at group 3.
const SUMS: &[(&str, u32)] = &[("accum_tex", 0)];
const RESOLVE: &[Layout] = &[Layout::Scene, Layout::Targets, OWN, Layout::Textures(SUMS)];

const SHADER: &str = "adaptive.wgsl";
const PIPELINES: &[PipelineSpec] = &[
    PipelineSpec::geometry(SHADER, "fs_insert", GROUPS),
    PipelineSpec::geometry(SHADER, "fs_shade", GROUPS),
    PipelineSpec::fullscreen(SHADER, "fs_resolve", RESOLVE),
];

/// Bytes of a node (depth, transmittance).
const NODE_BYTES: u64 = 8;

/// N nodes, the lock word and the shading pass's RGBA32F sums a pixel.
const BYTES: FrameBytes = FrameBytes { per_pixel: Linear::per(NODES, NODE_BYTES, LOCK_BYTES + 16), fixed: LOCK_STATS_BYTES };

const NODES: IntParam = IntParam::new("nodes", (1, 32, 8), "steps of the per-pixel visibility function").compiled_as("NODES");

pub const INFO: MethodInfo = MethodInfo {
    name: "adaptive",
    summary: "adaptive transparency: a visibility function of at most `nodes` steps per pixel, built under per-pixel locks",
    exact: false,
    bounded_memory: true,
    passes: &[
        "insert into the visibility function (geometry, per-pixel lock)",
        "shade by it (geometry, blended)",
        "composite (full screen)",
    ],
    params: &[NODES.0],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Submission,
    antialias_modes: FRAMES,
    memory: Memory::Frame(BYTES),
    error_bound: ErrorBound::None,
    census: false,
    census_when: never,
    main: Some("nodes"),
    pipelines: &[PIPELINES],
    constants: &[Const::U32("NODES_PLUS_ONE", 9), Const::U32("READ_NODES", 0)],
    create: |_, _| Box::<Adaptive>::default(),
};

#[derive(Default)]
struct Adaptive {
    locks: PixelLocks,
    sums: Option<FloatTargets>,
}

impl Method for Adaptive {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let n = NODES.of(cx.params);
        let consts = [NODES.constant(cx.params), Const::U32("NODES_PLUS_ONE", n + 1), Const::U32("READ_NODES", 0)];
        let (group, mut enc) = self.locks.begin(cx, OWN, &format!("adaptive with nodes = {n}"), (NODE_BYTES, n))?;
        // The passes after the insert only read the nodes (READ_NODES: plain loads).
        let read = [consts[0], consts[1], Const::U32("READ_NODES", 1)];
        cx.capture(&mut enc, "insert", &cx.capture_pipeline(spec(PIPELINES, "fs_insert"), &consts), group);
        let sums = FloatTargets::ensure(&mut self.sums, cx, &[ACCUM_FORMAT], SUMS);
        let target = blended(ACCUM_FORMAT, ADD);
        let shade = cx.draw_pipeline(spec(PIPELINES, "fs_shade"), &read, vec![target], crate::pipeline::depth_test_only());
        cx.capture_into(&mut enc, "shade", &shade, group, &sums.attachments(&[wgpu::Color::TRANSPARENT]));
        let resolve = cx.resolve_pipeline(spec(PIPELINES, "fs_resolve"), &read, false);
        cx.resolve_groups(&mut enc, "composite", &resolve, &[group, &sums.group], false);
        let memory = BYTES.at(cx.pixels(), cx.params);
        self.locks.finish(cx, enc, memory).map(Outcome::Done)
    }
}
