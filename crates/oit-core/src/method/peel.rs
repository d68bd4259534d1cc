//! `depth_peeling` and `dual_depth_peeling`: one geometry pass per layer (per two layers for
//! dual), each shading the layer(s) found by the pass before and finding the next with 64-bit
//! atomic min/max over (depth, triangle) keys, so coplanar fragments peel one by one
//! (shaders/peel.wgsl, docs/methods.md).

use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{buffer_sizes, never, Buffer, ErrorBound, FRAMES, FrameBytes, Linear, Memory, MethodInfo, Order};
use super::params::IntParam;
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::resources::{Counter, StorageGroup};
use crate::shader::Const;

const LAYERS: IntParam =
    IntParam::new("layers", (0, 1 << 20, 0), "most layers to peel; 0 peels until no fragment is left (the census depth complexity)");

pub const DEPTH_PEELING: MethodInfo = MethodInfo {
    name: "depth_peeling",
    summary: "front-to-back depth peeling with the under operator: one geometry pass per layer, exact",
    exact: true,
    bounded_memory: true,
    passes: &["per layer: peel (geometry) and composite (compute)", "resolve (full screen)"],
    params: &[LAYERS.0],
    features: wgpu::Features::SHADER_INT64.union(wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX),
    order: Order::BitwiseExceptTies,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::Exact,
    census: true,
    census_when: never,
    main: Some("layers"),
    pipelines: &[PIPELINES],
    constants: &[Const::U32("DUAL", 1)],
    create: |_, _| Box::new(Peel { dual: false, buffers: None, peeled: None }),
};

pub const DUAL_DEPTH_PEELING: MethodInfo = MethodInfo {
    name: "dual_depth_peeling",
    summary: "dual depth peeling (Bavoil & Myers 2008): nearest and farthest layers per pass, exact",
    passes: &["per two layers: peel (geometry) and composite (compute)", "resolve (full screen)"],
    create: |_, _| Box::new(Peel { dual: true, buffers: None, peeled: None }),
    ..DEPTH_PEELING
};

const SHADER: &str = "peel.wgsl";
/// Group 2: keys, layer colors, accumulators, then the peeled counter.
const OWN: Layout = Layout::Storage(&["keys", "layers", "acc", "peeled"]);
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, OWN];
const PIPELINES: &[PipelineSpec] = &[
    PipelineSpec::compute(SHADER, "cs_init", GROUPS),
    PipelineSpec::geometry(SHADER, "fs_peel", GROUPS),
    PipelineSpec::compute(SHADER, "cs_composite", GROUPS),
    PipelineSpec::fullscreen(SHADER, "fs_resolve", GROUPS),
];

/// Words of per-pixel accumulation.
pub const PEEL_WORDS: u64 = crate::consts::PEEL_WORDS as u64;

/// Bytes either peeling method allocates: four 64-bit keys, two layer colors and the
/// accumulators per pixel, and a counter.
const BUFFERS: &[Buffer] = &[
    Buffer::per_pixel("keys", Linear::bytes(4 * 8)),
    Buffer::per_pixel("layers", Linear::bytes(2 * 16)),
    Buffer::per_pixel("acc", Linear::bytes(PEEL_WORDS * 4)),
];
/// The buffers and the peeled counter.
const BYTES: FrameBytes = FrameBytes::of(BUFFERS, 4);
const MEMORY: Memory = Memory::Frame(BYTES);

struct Peel {
    dual: bool,
    buffers: Option<StorageGroup>,
    peeled: Option<Counter>,
}

impl Method for Peel {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let pixels = cx.pixels();
        let name = if self.dual { "dual_depth_peeling" } else { "depth_peeling" };
        cx.check_per_pixel(name, 4 * PEEL_WORDS.max(8))?;
        let peeled = self.peeled.get_or_insert_with(|| Counter::new(cx.gpu, "peeled count"));
        let sizes = buffer_sizes(BUFFERS, pixels, cx.params);
        let b = StorageGroup::ensure(&mut self.buffers, cx.gpu, OWN, &sizes, &[("peeled", peeled)]);
        let limit = LAYERS.of(cx.params) as u64;
        let n = cx.max_depth_complexity as u64;
        let layers = if limit == 0 { n } else { limit.min(n) };
        // The first pass only finds; each later pass shades one layer (two when dual).
        let passes = if self.dual { layers.div_ceil(2) } else { layers } + 1;
        let consts = [Const::U32("DUAL", self.dual as u32)];
        let init = cx.compute_pipeline(spec(PIPELINES, "cs_init"), &consts);
        let composite = cx.compute_pipeline(spec(PIPELINES, "cs_composite"), &consts);
        let peel = cx.capture_pipeline(spec(PIPELINES, "fs_peel"), &consts);
        let mut enc = cx.encoder();
        peeled.clear(&mut enc);
        // One timed span from the first dispatch to the last composite, around every pass.
        let span = cx.timer.span("peel");
        let compute = |cx: &mut FrameCtx<'_>, enc: &mut wgpu::CommandEncoder, pipeline, begin: bool, end: bool| {
            let timestamps = cx.timer.span_compute(span, begin, end);
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("peel"), timestamp_writes: timestamps });
            cx.bind_dispatch(&mut pass, pipeline, &b.group);
        };
        compute(cx, &mut enc, &init, true, false);
        for i in 0..passes {
            cx.capture_untimed(&mut enc, "peel", &peel, &b.group);
            compute(cx, &mut enc, &composite, false, i + 1 == passes);
        }
        cx.resolve(&mut enc, "resolve", &cx.resolve_pipeline(spec(PIPELINES, "fs_resolve"), &consts, false), &b.group, false);
        peeled.copy(&mut enc);
        cx.submit(enc);
        let peeled = peeled.read(cx.gpu)?;
        Ok(Outcome::Done(MethodReport {
            memory_bytes: BYTES.at(pixels, cx.params),
            overflow_fragments: cx.fragments.saturating_sub(peeled),
            extra: vec![("geometry_passes", passes as f64), ("peeled_fragments", peeled as f64)],
            ..Default::default()
        }))
    }
}
