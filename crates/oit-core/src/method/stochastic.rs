//! `stochastic`: stochastic transparency (Enderton et al. 2010) with alpha correction, on
//! `samples` coverage samples per pixel kept in a storage buffer: a stochastic depth pass,
//! an accumulation pass and a resolve (shaders/stochastic.wgsl). Deterministic for a seed.

use super::accum::{accumulation_targets, Companion, FloatTargets};
use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{never, ErrorBound, FrameBytes, Linear, Memory, MethodInfo, Order, FRAMES};
use super::params::IntParam;
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::gpu_types::FrameUniform;
use crate::pipeline;
use crate::resources::StorageGroup;

const SAMPLES: IntParam =
    IntParam::new("samples", (1, 64, 8), "coverage samples per pixel (the estimate's noise falls as 1/sqrt(samples))")
        .compiled_as("SAMPLES");
const SEED: IntParam = IntParam::new("seed", (0, u32::MAX as i64, 0), "random seed of the coverage masks");

pub const INFO: MethodInfo = MethodInfo {
    name: "stochastic",
    summary: "stochastic transparency: random per-sample coverage by alpha, stochastic depth, alpha-corrected average",
    exact: false,
    bounded_memory: true,
    passes: &["stochastic depth (geometry)", "accumulate (geometry, blended)", "resolve (full screen)"],
    params: &[SAMPLES.0, SEED.0],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Submission,
    antialias_modes: FRAMES,
    memory: Memory::Frame(FrameBytes { per_pixel: Linear::per(SAMPLES, 4, super::accum::TARGET_BYTES), fixed: 0 }),
    error_bound: ErrorBound::None,
    census: false,
    census_when: never,
    main: Some("samples"),
    pipelines: &[PIPELINES],
    constants: &[],
    create: |_, _| Box::new(Stochastic { samples: None, targets: None }),
};

const SHADER: &str = "stochastic.wgsl";
/// Group 2 of the geometry passes: the per-pixel depth samples.
const OWN: Layout = Layout::Storage(&["samples"]);
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, OWN];
/// The bindings the resolve reads the accumulation targets at (group 2).
const TEXTURES: &[(&str, u32)] = &[("accum_tex", 1), ("aux_tex", 2)];
const PIPELINES: &[PipelineSpec] = &[
    PipelineSpec::geometry(SHADER, "fs_depth", GROUPS),
    PipelineSpec::geometry(SHADER, "fs_accum", GROUPS),
    PipelineSpec::fullscreen(SHADER, "fs_resolve", &[Layout::Scene, Layout::Targets, Layout::Textures(TEXTURES)]),
];

struct Stochastic {
    samples: Option<StorageGroup>,
    targets: Option<FloatTargets>,
}

impl Method for Stochastic {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let samples = SAMPLES.of(cx.params);
        let seed = SEED.of(cx.params);
        let pixels = cx.pixels();
        cx.check_per_pixel(&format!("stochastic with {samples} samples"), 4 * samples as u64)?;
        let b = StorageGroup::ensure(&mut self.samples, cx.gpu, OWN, &[("samples", pixels * samples as u64 * 4)], &[]);
        // The accumulation targets are read only by the resolve.
        let w = FloatTargets::accumulation(&mut self.targets, cx, TEXTURES);
        let consts = [SAMPLES.constant(cx.params)];
        let depth = cx.capture_pipeline(spec(PIPELINES, "fs_depth"), &consts);
        let accumulate =
            cx.draw_pipeline(spec(PIPELINES, "fs_accum"), &consts, accumulation_targets(Companion::Reveal), pipeline::depth_test_only());
        let resolve = cx.resolve_pipeline(spec(PIPELINES, "fs_resolve"), &consts, false);
        let offset = std::mem::offset_of!(FrameUniform, seed) as u64;
        cx.gpu.queue.write_buffer(cx.frame_uniform, offset, bytemuck::bytes_of(&seed));
        let mut enc = cx.encoder();
        b.clear(&mut enc);
        cx.capture(&mut enc, "depth", &depth, &b.group);
        w.accumulate(cx, &mut enc, Companion::Reveal, &accumulate, &[&cx.targets.group, &b.group]);
        cx.resolve(&mut enc, "resolve", &resolve, &w.group, false);
        cx.submit(enc);
        // The samples are the tile's; the targets are the frame's, shared by its tiles.
        let frame_pixels = cx.targets.width as u64 * cx.targets.height as u64;
        let memory = pixels * samples as u64 * 4 + frame_pixels * super::accum::TARGET_BYTES;
        Ok(Outcome::Done(MethodReport { memory_bytes: memory, ..Default::default() }))
    }
}
