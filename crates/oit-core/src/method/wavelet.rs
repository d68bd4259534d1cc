//! `wavelet`: wavelet transparency (Aizenshtein, Smal, McGuire 2022) with Haar wavelets at 32
//! bits: a blended pass of the optical depth's Haar coefficients over depth, a blended pass of
//! each fragment's color weighted by the transmittance integrated from them, and mboit's resolve
//! (shaders/wavelet.wgsl, docs/methods.md "wavelet").

use super::accum::{blended, FloatTargets, ADD};
use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{never, ErrorBound, FrameBytes, Linear, Memory, MethodInfo, Order, FRAMES};
use super::params::IntParam;
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::pipeline;

const RANK: IntParam = IntParam::new(
    "rank",
    (4, 16, 16),
    "Haar functions a pixel keeps (the scaling function and rank - 1 wavelets, coarse to fine): 4, 8, 12 or 16; more: finer in depth",
)
.stepped(4)
.compiled_as("RANK");

/// The coefficient targets (four a texel) and the shade pass's two: the weighted color, and
/// the optical depth, the error bound's sum, the fragment count and the largest |C|.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
const SHADE_FORMATS: [wgpu::TextureFormat; 2] = [FORMAT; 2];

/// The shade pass's companion target: the optical depth, the bound's sum and the count added,
/// the largest |C| in alpha by max.
const COMPANION: wgpu::BlendState = wgpu::BlendState {
    color: ADD,
    alpha: wgpu::BlendComponent { src_factor: wgpu::BlendFactor::One, dst_factor: wgpu::BlendFactor::One, operation: wgpu::BlendOperation::Max },
};

/// The coefficients (RGBA32F, four a texel) and the shade pass's targets.
const BYTES: FrameBytes = FrameBytes { per_pixel: Linear::per(RANK, 4, 32), fixed: 0 };

pub const INFO: MethodInfo = MethodInfo {
    name: "wavelet",
    summary: "wavelet transparency (Aizenshtein et al. 2022): transmittance integrated from Haar coefficients of optical depth",
    exact: false,
    bounded_memory: true,
    passes: &["coefficients (geometry, blended)", "shade (geometry, blended)", "resolve (full screen)"],
    params: &[RANK.0],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Rounding,
    antialias_modes: FRAMES,
    memory: Memory::Frame(BYTES),
    error_bound: ErrorBound::PerPixel,
    census: false,
    census_when: never,
    main: Some("rank"),
    pipelines: &[PIPELINES],
    constants: &[],
    create: |_, _| Box::new(Wavelet { coefficients: None, accum: None }),
};

const SHADER: &str = "wavelet.wgsl";
/// The coefficient targets as the shade pass reads them (group 2), by target count.
const COEFFICIENTS: [&[(&str, u32)]; 4] = [
    &[("coef0_tex", 0)],
    &[("coef0_tex", 0), ("coef1_tex", 1)],
    &[("coef0_tex", 0), ("coef1_tex", 1), ("coef2_tex", 2)],
    &[("coef0_tex", 0), ("coef1_tex", 1), ("coef2_tex", 2), ("coef3_tex", 3)],
];
/// The accumulation targets as the resolve reads them (group 2).
const TEXTURES: &[(&str, u32)] = &[("accum_tex", 4), ("aux_tex", 5)];
const PASS1: [&str; 4] = ["fs_coefficients1", "fs_coefficients2", "fs_coefficients3", "fs_coefficients4"];
const PASS2: [&str; 4] = ["fs_shade1", "fs_shade2", "fs_shade3", "fs_shade4"];
const PIPELINES: &[PipelineSpec] = &[
    PipelineSpec::geometry(SHADER, PASS1[0], &[Layout::Scene]),
    PipelineSpec::geometry(SHADER, PASS1[1], &[Layout::Scene]),
    PipelineSpec::geometry(SHADER, PASS1[2], &[Layout::Scene]),
    PipelineSpec::geometry(SHADER, PASS1[3], &[Layout::Scene]),
    PipelineSpec::geometry(SHADER, PASS2[0], &[Layout::Scene, Layout::Targets, Layout::Textures(COEFFICIENTS[0])]),
    PipelineSpec::geometry(SHADER, PASS2[1], &[Layout::Scene, Layout::Targets, Layout::Textures(COEFFICIENTS[1])]),
    PipelineSpec::geometry(SHADER, PASS2[2], &[Layout::Scene, Layout::Targets, Layout::Textures(COEFFICIENTS[2])]),
    PipelineSpec::geometry(SHADER, PASS2[3], &[Layout::Scene, Layout::Targets, Layout::Textures(COEFFICIENTS[3])]),
    PipelineSpec::fullscreen(SHADER, "fs_resolve", &[Layout::Scene, Layout::Targets, Layout::Textures(TEXTURES)]),
];

struct Wavelet {
    coefficients: Option<FloatTargets>,
    accum: Option<FloatTargets>,
}

impl Method for Wavelet {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let targets = (RANK.of(cx.params) / 4) as usize;
        let at = targets - 1;
        let consts = [RANK.constant(cx.params)];
        let formats = vec![FORMAT; targets];
        let blend_targets = formats.iter().map(|&f| blended(f, ADD)).collect();
        let gather = cx.draw_pipeline(spec(PIPELINES, PASS1[at]), &consts, blend_targets, pipeline::depth_test_only());
        let companion = wgpu::ColorTargetState { format: FORMAT, blend: Some(COMPANION), write_mask: wgpu::ColorWrites::ALL };
        let shade_targets = vec![blended(FORMAT, ADD), Some(companion)];
        let shade = cx.draw_pipeline(spec(PIPELINES, PASS2[at]), &consts, shade_targets, pipeline::depth_test_only());
        let resolve = cx.resolve_pipeline(spec(PIPELINES, "fs_resolve"), &consts, true);
        let coefficients = FloatTargets::ensure(&mut self.coefficients, cx, &formats, COEFFICIENTS[at]);
        let accum = FloatTargets::ensure(&mut self.accum, cx, &SHADE_FORMATS, TEXTURES);
        let mut enc = cx.encoder();
        coefficients.blend("coefficients", cx, &mut enc, &vec![wgpu::Color::TRANSPARENT; targets], &gather, &[]);
        accum.blend("shade", cx, &mut enc, &[wgpu::Color::TRANSPARENT; 2], &shade, &[cx.targets_group(), &coefficients.group]);
        cx.resolve(&mut enc, "resolve", &resolve, &accum.group, true);
        cx.submit(enc);
        Ok(Outcome::Done(MethodReport { memory_bytes: BYTES.at(cx.pixels(), cx.params), error_bound: true, ..Default::default() }))
    }
}
