//! `mboit`: moment-based OIT (Münstermann, Krumpen, Klein, Peters 2018) with power or
//! trigonometric moments: a pass of the optical depth's moments (blended into float targets at
//! 32 bits; at 16 bits renormalized and quantized in each pixel's critical section, as the
//! paper's rasterizer-ordered storage does), a blended pass of each fragment's color weighted by
//! the transmittance reconstructed from them, and a resolve that composites with the total
//! transmittance exp(-b0) (shaders/mboit.wgsl, docs/methods.md "mboit").

use super::accum::{blended, FloatTargets, ADD, AUX_FORMAT};
use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{never, ErrorBound, Memory, MethodInfo, Order, FRAMES};
use super::params::{ChoiceParam, FloatParam, IntParam, Params};
use super::pixel_lock::{locked_layout, PixelLocks, LOCK_BYTES, LOCK_STATS_BYTES};
use crate::cache::{spec, Layout, PipelineSpec};
use crate::consts::{MBOIT_BIAS, MBOIT_BIAS16, MBOIT_TRIG_BIAS, MBOIT_TRIG_BIAS16};
use crate::error::Result;
use crate::pipeline;
use crate::shader::Const;

const MOMENTS: IntParam = IntParam::new(
    "moments",
    (4, 8, 6),
    "real moments of the optical depth: 4, 6 or 8 (the trigonometric basis: 2, 3 or 4 complex moments); more: closer to the exact composite",
)
.stepped(2)
.compiled_as("MOMENTS");
const BASIS: ChoiceParam<u32> = ChoiceParam::new(
    "basis",
    &["power", "trigonometric"],
    &[0, 1],
    0,
    "moment basis: powers of the warped depth, or cos and sin of multiples of its angle",
)
.compiled_as("MBOIT_BASIS");
const PRECISION: ChoiceParam<u32> = ChoiceParam::new(
    "precision",
    &["32", "16"],
    &[32, 16],
    0,
    "bits a stored moment: 32 (float targets, blended), or 16 (quantized in each pixel's critical section)",
);
const BIAS: FloatParam = FloatParam::new(
    "bias",
    (0.0, 0.5, 0.0),
    "moment bias toward the bias vector; 0: the default for the basis, count and precision (consts.rs MBOIT_BIAS, MBOIT_TRIG_BIAS, MBOIT_BIAS16, MBOIT_TRIG_BIAS16)",
);
const OVERESTIMATION: FloatParam =
    FloatParam::new("overestimation", (0.0, 1.0, 0.25), "share of the fragment's own depth's mass counted in front of it");

/// The moment counts (real values: a complex trigonometric moment is two).
const COUNTS: [u32; 3] = [4, 6, 8];

/// The shade pass's two RGBA32F targets: the weighted color, and the optical depth, the error
/// bound's sum and the fragment count.
const SHADE_FORMATS: [wgpu::TextureFormat; 2] = [wgpu::TextureFormat::Rgba32Float; 2];

/// At 32 bits b0 (R32F), the moments (4 a texel: RGBA32F, then RG32F or RGBA32F) and the shade
/// pass's targets; at 16 bits b0 (a float), the moments at 2 bytes, the lock word and its
/// counts, and the shade pass's targets.
fn bytes(pixels: u64, params: &Params) -> u64 {
    let m = MOMENTS.of(params) as u64;
    match PRECISION.of(params) {
        32 => pixels * (4 * m + 4 + 32),
        _ => pixels * (2 * m + 4 + LOCK_BYTES + 32) + LOCK_STATS_BYTES,
    }
}

pub const INFO: MethodInfo = MethodInfo {
    name: "mboit",
    summary: "moment-based OIT (Münstermann et al. 2018): transmittance reconstructed from power moments of optical depth",
    exact: false,
    bounded_memory: true,
    passes: &["moments (geometry, blended)", "shade (geometry, blended)", "resolve (full screen)"],
    params: &[MOMENTS.0, BASIS.info, PRECISION.info, BIAS.0, OVERESTIMATION.0],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Rounding,
    antialias_modes: FRAMES,
    memory: Memory::Computed { formula: "W·H·(4·moments + 36) at 32 bits; W·H·(2·moments + 40) + 8 at 16", bytes },
    error_bound: ErrorBound::PerPixel,
    census: false,
    census_when: never,
    main: Some("moments"),
    pipelines: &[PIPELINES],
    constants: &[Const::F32("MBOIT_BIAS", MBOIT_BIAS[1]), Const::F32("MBOIT_OVERESTIMATION", 0.25)],
    create: |_, _| Box::new(Mboit { moments: None, accum: None, locks: PixelLocks::default() }),
};

const SHADER: &str = "mboit.wgsl";
/// The moment targets as the shade pass reads them (group 2): 4 moments, or 6 and 8.
const MOMENTS4: &[(&str, u32)] = &[("b0_tex", 0), ("low_tex", 1)];
const MOMENTS8: &[(&str, u32)] = &[("b0_tex", 0), ("low_tex", 1), ("high_tex", 2)];
/// The accumulation targets as the resolve reads them (group 2).
const TEXTURES: &[(&str, u32)] = &[("accum_tex", 3), ("aux_tex", 4)];
/// The 16-bit moments (group 2): b0 and the packed moments a pixel, with the lock words.
const OWN16: Layout = locked_layout!("moments16");
const PIPELINES: &[PipelineSpec] = &[
    PipelineSpec::geometry(SHADER, "fs_moments4", &[Layout::Scene]),
    PipelineSpec::geometry(SHADER, "fs_moments", &[Layout::Scene]),
    PipelineSpec::geometry(SHADER, "fs_shade4", &[Layout::Scene, Layout::Targets, Layout::Textures(MOMENTS4)]),
    PipelineSpec::geometry(SHADER, "fs_shade", &[Layout::Scene, Layout::Targets, Layout::Textures(MOMENTS8)]),
    PipelineSpec::fullscreen(SHADER, "fs_resolve", &[Layout::Scene, Layout::Targets, Layout::Textures(TEXTURES)]),
    PipelineSpec::geometry(SHADER, "fs_moments16", &[Layout::Scene, Layout::Targets, OWN16]),
    PipelineSpec::geometry(SHADER, "fs_shade16", &[Layout::Scene, Layout::Targets, OWN16]),
];

struct Mboit {
    moments: Option<FloatTargets>,
    accum: Option<FloatTargets>,
    locks: PixelLocks,
}

impl Method for Mboit {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let (m, basis) = (MOMENTS.of(cx.params), BASIS.of(cx.params) as usize);
        let at = COUNTS.iter().position(|&c| c == m).expect("resolve_params checked the range and step");
        let sixteen = PRECISION.of(cx.params) == 16;
        let bias = match BIAS.of(cx.params) {
            b if b > 0.0 => b as f32,
            _ if sixteen => [MBOIT_BIAS16, MBOIT_TRIG_BIAS16][basis][at],
            _ => [MBOIT_BIAS, MBOIT_TRIG_BIAS][basis][at],
        };
        let consts = [
            MOMENTS.constant(cx.params),
            BASIS.constant_or(cx.params, 0),
            Const::F32("MBOIT_BIAS", bias),
            Const::F32("MBOIT_OVERESTIMATION", OVERESTIMATION.of(cx.params) as f32),
        ];
        if sixteen {
            return self.render16(cx, &consts, m);
        }
        let f32x4 = wgpu::TextureFormat::Rgba32Float;
        let (formats, bindings, moments_fs, shade_fs) = match m {
            4 => (vec![AUX_FORMAT, f32x4], MOMENTS4, "fs_moments4", "fs_shade4"),
            6 => (vec![AUX_FORMAT, f32x4, wgpu::TextureFormat::Rg32Float], MOMENTS8, "fs_moments", "fs_shade"),
            _ => (vec![AUX_FORMAT, f32x4, f32x4], MOMENTS8, "fs_moments", "fs_shade"),
        };
        let targets: Vec<_> = formats.iter().map(|&f| blended(f, ADD)).collect();
        let gather = cx.draw_pipeline(spec(PIPELINES, moments_fs), &consts, targets, pipeline::depth_test_only());
        let moments = FloatTargets::ensure(&mut self.moments, cx, &formats, bindings);
        let mut enc = cx.encoder();
        moments.blend("moments", cx, &mut enc, &vec![wgpu::Color::TRANSPARENT; formats.len()], &gather, &[]);
        shade_and_resolve(cx, &mut enc, &mut self.accum, &consts, shade_fs, &moments.group);
        cx.submit(enc);
        Ok(Outcome::Done(MethodReport { memory_bytes: bytes(cx.pixels(), cx.params), error_bound: true, ..Default::default() }))
    }
}

impl Mboit {
    /// The 16-bit frame: the moments pass in each pixel's critical section, then shade and
    /// resolve as at 32 bits. No bound: the quantization's effect on the reconstruction has none
    /// a priori (docs/methods.md, "mboit").
    fn render16(&mut self, cx: &mut FrameCtx<'_>, consts: &[Const], m: u32) -> Result<Outcome> {
        let what = format!("mboit with moments = {m} at 16 bits");
        let gather = cx.capture_pipeline(spec(PIPELINES, "fs_moments16"), consts);
        let (group, mut enc) = self.locks.begin(cx, OWN16, &what, (4 * (1 + m as u64 / 2), 1))?;
        cx.capture(&mut enc, "moments", &gather, group);
        shade_and_resolve(cx, &mut enc, &mut self.accum, consts, "fs_shade16", group);
        let report = self.locks.finish(cx, enc, bytes(cx.pixels(), cx.params))?;
        Ok(Outcome::Done(report))
    }
}

/// Records the shade pass (entry `shade_fs`, reading the moments bound as `moments`) into the
/// accumulation targets `accum` keeps, and the resolve: what both precisions share.
fn shade_and_resolve(
    cx: &mut FrameCtx<'_>,
    enc: &mut wgpu::CommandEncoder,
    accum: &mut Option<FloatTargets>,
    consts: &[Const],
    shade_fs: &str,
    moments: &wgpu::BindGroup,
) {
    let shade_targets = SHADE_FORMATS.iter().map(|&f| blended(f, ADD)).collect();
    let shade = cx.draw_pipeline(spec(PIPELINES, shade_fs), consts, shade_targets, pipeline::depth_test_only());
    let resolve = cx.resolve_pipeline(spec(PIPELINES, "fs_resolve"), consts, true);
    let accum = FloatTargets::ensure(accum, cx, &SHADE_FORMATS, TEXTURES);
    accum.blend("shade", cx, enc, &[wgpu::Color::TRANSPARENT; 2], &shade, &[cx.targets_group(), moments]);
    cx.resolve(enc, "resolve", &resolve, &accum.group, true);
}
