//! `wsum`, `wavg` and `wboit`: one geometry pass with additive (and, for wboit's revealage,
//! multiplicative) blending into two float targets, then a full-screen resolve.

use super::accum::{accumulation_targets, Companion, FloatTargets, TARGET_BYTES};
use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{never, ErrorBound, FrameBytes, Linear, Memory, MethodInfo, Order, FRAMES};
use super::params::ChoiceParam;
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::pipeline;

const SHADER: &str = "weighted.wgsl";
/// The bindings the resolves read the two targets at (group 2).
const TEXTURES: &[(&str, u32)] = &[("accum_tex", 0), ("aux_tex", 1)];
const RESOLVE: &[Layout] = &[Layout::Scene, Layout::Targets, Layout::Textures(TEXTURES)];
const PIPELINES: &[PipelineSpec] = &[
    PipelineSpec::geometry(SHADER, "fs_sum", &[Layout::Scene]),
    PipelineSpec::geometry(SHADER, "fs_wboit", &[Layout::Scene]),
    PipelineSpec::fullscreen(SHADER, "fs_resolve_wsum", RESOLVE),
    PipelineSpec::fullscreen(SHADER, "fs_resolve_wavg", RESOLVE),
    PipelineSpec::fullscreen(SHADER, "fs_resolve_wboit", RESOLVE),
];

#[derive(Clone, Copy, PartialEq)]
enum Weighting {
    Sum,
    Average,
    Blended,
}

pub const WSUM: MethodInfo = MethodInfo {
    name: "wsum",
    summary: "weighted sum (Meshkin 2007): sum(alpha C) + background (1 - sum(alpha)); saturates",
    exact: false,
    bounded_memory: true,
    passes: &["accumulate (geometry, blended)", "resolve (full screen)"],
    params: &[],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Rounding,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::None,
    census: false,
    census_when: never,
    main: None,
    pipelines: &[PIPELINES],
    constants: &[],
    create: |_, _| Box::new(Weighted::new(Weighting::Sum)),
};

pub const WAVG: MethodInfo = MethodInfo {
    name: "wavg",
    summary: "weighted average (Bavoil & Myers 2008): average color, transmittance (1 - mean alpha)^n",
    params: &[],
    create: |_, _| Box::new(Weighted::new(Weighting::Average)),
    ..WSUM
};

/// Weight functions of McGuire & Bavoil 2013, by equation number (the shader's WEIGHT).
const WEIGHT: ChoiceParam<u32> = ChoiceParam::new(
    "weight",
    &["eq10", "eq7", "eq8", "eq9"],
    &[10, 7, 8, 9],
    0,
    "weight function (paper's eq. 7-10); eq7-9 use the view distance, eq10 the window depth",
)
.compiled_as("WEIGHT");

pub const WBOIT: MethodInfo = MethodInfo {
    name: "wboit",
    summary: "weighted blended OIT (McGuire & Bavoil 2013): depth-weighted average, exact total coverage",
    params: &[WEIGHT.info],
    create: |_, _| Box::new(Weighted::new(Weighting::Blended)),
    ..WSUM
};

/// The two targets: RGBA32F color and the R32F companion.
const BYTES: FrameBytes = FrameBytes { per_pixel: Linear::bytes(TARGET_BYTES), fixed: 0 };
const MEMORY: Memory = Memory::Frame(BYTES);

struct Weighted {
    kind: Weighting,
    targets: Option<FloatTargets>,
}

impl Weighted {
    fn new(kind: Weighting) -> Self {
        Self { kind, targets: None }
    }
}

impl Method for Weighted {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        // wsum and wavg weigh nothing; their shaders compile with wboit's default.
        let consts = [WEIGHT.constant_or(cx.params, 10)];
        let (fs, resolve_fs, aux) = match self.kind {
            Weighting::Sum => ("fs_sum", "fs_resolve_wsum", Companion::Sum),
            Weighting::Average => ("fs_sum", "fs_resolve_wavg", Companion::Sum),
            Weighting::Blended => ("fs_wboit", "fs_resolve_wboit", Companion::Reveal),
        };
        let accumulate = cx.draw_pipeline(spec(PIPELINES, fs), &consts, accumulation_targets(aux), pipeline::depth_test_only());
        let resolve = cx.resolve_pipeline(spec(PIPELINES, resolve_fs), &consts, false);
        let w = FloatTargets::accumulation(&mut self.targets, cx, TEXTURES);
        let mut enc = cx.encoder();
        w.accumulate(cx, &mut enc, aux, &accumulate, &[]);
        cx.resolve(&mut enc, "resolve", &resolve, &w.group, false);
        cx.submit(enc);
        Ok(Outcome::Done(MethodReport { memory_bytes: BYTES.at(cx.pixels(), cx.params), ..Default::default() }))
    }
}
