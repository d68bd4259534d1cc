//! Numbers shared by Rust, WGSL and Python. Each is defined here once: `shader::compose`
//! prepends every one of them to every shader, and `oit.constants()` exports them to Python
//! (python/oit/models.py reads them there). Depends on nothing. `tests/shader_validation.rs` checks that naga sees
//! the same values and that no shader defines one of its own.

/// A compile-time constant injected in front of a shader.
#[derive(Clone, Copy, Debug)]
pub enum Const {
    U32(&'static str, u32),
    F32(&'static str, f32),
}

impl Const {
    /// The WGSL name it is declared as.
    pub const fn name(&self) -> &'static str {
        match *self {
            Const::U32(n, _) | Const::F32(n, _) => n,
        }
    }
}

/// Whether two names are the same, in `const` code (a declaration checked at compile time).
pub const fn same_str(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    let mut i = 0;
    while i < a.len() && i < b.len() && a[i] == b[i] {
        i += 1;
    }
    i == a.len() && i == b.len()
}

/// Words per pixel of hybrid's accumulators, kept by atomicMax: the nearest evicted key and the
/// tail colors' smallest and largest channel (shaders/hybrid.wgsl).
pub const HYBRID_ACCUM_WORDS: u32 = 3;
/// 32-bit words per pixel of hybrid's and hybrid64's tail: its count and sums packed in three
/// 64-bit words (shaders/common/tail_words.wgsl).
pub const HYBRID_TAIL_WORDS: u32 = 6;
/// 32-bit words per pixel of hybrid's core sums, two error-bound sums and T_core, in three 64-bit
/// words beside the tail's (shaders/hybrid.wgsl).
pub const HYBRID_CORE_WORDS: u32 = 6;
/// Words per pixel of the peeling methods' accumulators (shaders/peel.wgsl).
pub const PEEL_WORDS: u32 = 9;
/// Fixed-point scale of hybrid's core sums (values in [0, 1], total <= 1): 2^31.
pub const CORE_SCALE: f32 = 2_147_483_648.0;
/// Fixed-point scale of hybrid's tail sums (64-bit pairs): 2^24.
pub const TAIL_SCALE: f32 = 16_777_216.0;
/// Window depth to the 24-bit depth of k-TAB keys: z · DEPTH_SCALE, at most DEPTH_MAX (the
/// largest value leaves 0xffffff free, so that an empty slot sorts behind every fragment).
pub const DEPTH_SCALE: f32 = 16_777_215.0;
pub const DEPTH_MAX: u32 = 0x00ff_fffe;
/// The 8-bit alpha's rounding bias, 2^-10 of a step (shaders/common/alpha8.wgsl).
pub const ALPHA_8BIT_BIAS: f32 = 0.000_976_562_5;
/// Largest |q - alpha| of the biased 8-bit alpha: (1/2 + 2^-10) / 255.
pub const ALPHA_8BIT_ERROR: f64 = (0.5 + 1.0 / 1024.0) / 255.0;
/// Float32 and fixed-point rounding per term of hybrid's error bound (docs/methods.md).
pub const ROUNDING_TERM: f64 = 2.4e-7;
/// auto's estimate: optical depth per fragment capped at TAU_CAP, and the fixed-point scales of
/// its sums of τ, τ² and |alpha - q| (shaders/auto_estimate.wgsl).
pub const TAU_CAP: f32 = 16.0;
pub const TAU_SCALE: f32 = 4096.0;
pub const TAU2_SCALE: f32 = 1024.0;
pub const QUANT_SCALE: f32 = 16_777_216.0;

/// Fragments the submission-order replays select per sweep (shaders/common/select.wgsl).
pub const BATCH: u32 = 32;
/// Fragments the exact resolve sorts in a local array at most (shaders/common/sweep_sort.wgsl,
/// where the frame's own run length, RUN, is injected: `method::resolve_plan::run_length`): a
/// longer list is sorted in runs, then merged by relinking its nodes. 128 keeps all but the
/// deepest pixels of hair in one walk (the relinking merges cost far more a node than the local
/// ones); the array holds twice RUN entries of 8 bytes (24 where the runs hold whole fragments).
pub const RUN: u32 = 128;
/// The shortest run, sorted by insertion before the local merges.
pub const SWEEP_BLOCK: u32 = 8;
/// Words of a pixel's sweep state besides its samples', and words a sample of it keeps (its
/// accumulated color and transmittance): STATE_WORDS = SWEEP_PIXEL_WORDS + SWEEP_SAMPLE_WORDS ·
/// samples (shaders/common/sweep.wgsl; `method::resolve_plan::state_words`).
pub const SWEEP_PIXEL_WORDS: u32 = 12;
pub const SWEEP_SAMPLE_WORDS: u32 = 4;

/// Attempts a fragment makes at its pixel's lock before it gives up and is counted
/// (`lock_failures`; shaders/common/pixel_lock.wgsl): far more than one pixel's fragments can
/// queue for in one wave, and far below llvmpipe's 65,535-iteration loop limit.
pub const LOCK_TRIES: u32 = 4096;

/// mboit: the smallest 1 - alpha its optical depth -ln(1 - alpha) takes (alpha 1 would be
/// infinite), 2^-24: T = exp(-b0) stays within 2^-24 of 0 behind an alpha-1 fragment.
pub const MBOIT_MIN_TRANSMITTANCE: f32 = 5.960_464_5e-8;
/// mboit's smallest transmittance in front of a fragment, 2^-100: a pixel whose weights alpha T
/// would all underflow float32 (thousands of dense layers) averages its colors by alpha instead
/// of showing none, and alpha T C stays a normal float.
pub const MBOIT_MIN_WEIGHT: f32 = 7.888_609e-31;
/// mboit's bias vectors b* (even moments; the odd ones are 0) for 4, 6 and 8 power moments at
/// 32 bits, the paper's (Münstermann et al. 2018, Sec. 3.5; shaders/mboit.wgsl).
pub const MBOIT_STAR4: [f32; 2] = [0.375, 0.375];
pub const MBOIT_STAR6: [f32; 3] = [0.48, 0.451, 0.45];
pub const MBOIT_STAR8: [f32; 4] = [0.75, 0.676_666_7, 0.63, 0.600_303];
/// mboit's default moment bias for 4, 6 and 8 power moments at 32 bits: 5e-6, 5e-6 and 1e-5,
/// the smallest on a grid (1e-6 to 5e-5) at which reordering nearly coplanar layers changes the
/// image by float rounding only (tests/test_mboit.py): below it, float32's rounding of the sums
/// moves the nearly singular Hankel matrix's kernel roots across the fragment's depth. The
/// paper's (Sec. 3.5) are 5e-7, 5e-6 and 5e-5 (docs/methods.md, "mboit").
pub const MBOIT_BIAS: [f32; 3] = [5e-6, 5e-6, 1e-5];
/// mboit's default moment bias for 2, 3 and 4 complex trigonometric moments (4, 6, 8 real) at
/// 32 bits (toward 0, the moments of the uniform angle).
pub const MBOIT_TRIG_BIAS: [f32; 3] = [4e-7, 3.8e-7, 8e-7];
/// mboit's default moment bias at 16 bits (precision "16"), power 4, 6, 8 and trigonometric
/// 2, 3, 4 complex moments: larger than at 32 bits, so that the quantization of the stored
/// moments (2^-16 of their range) cannot make the biased Hankel or Toeplitz matrix singular;
/// chosen on a grid by the mean error and the outliers on the built-in scenes (docs/methods.md).
pub const MBOIT_BIAS16: [f32; 3] = [5e-5, 5e-5, 2e-4];
pub const MBOIT_TRIG_BIAS16: [f32; 3] = [1e-4, 5e-5, 1e-4];
/// The angle of the trigonometric basis' wrapping zone, 0.1 pi (the paper's code's default).
pub const MBOIT_WRAP: f32 = 0.314_159_27;

/// Every shared constant, in the order they are prepended (float64 ones as the float32 the
/// shaders compute with).
pub const SHARED: &[Const] = &[
    Const::U32("HYBRID_ACCUM_WORDS", HYBRID_ACCUM_WORDS),
    Const::U32("HYBRID_TAIL_WORDS", HYBRID_TAIL_WORDS),
    Const::U32("HYBRID_CORE_WORDS", HYBRID_CORE_WORDS),
    Const::U32("PEEL_WORDS", PEEL_WORDS),
    Const::F32("CORE_SCALE", CORE_SCALE),
    Const::F32("TAIL_SCALE", TAIL_SCALE),
    Const::F32("DEPTH_SCALE", DEPTH_SCALE),
    Const::U32("DEPTH_MAX", DEPTH_MAX),
    Const::F32("ALPHA_8BIT_BIAS", ALPHA_8BIT_BIAS),
    Const::F32("ALPHA_8BIT_ERROR", ALPHA_8BIT_ERROR as f32),
    Const::F32("ROUNDING_TERM", ROUNDING_TERM as f32),
    Const::F32("TAU_CAP", TAU_CAP),
    Const::F32("TAU_SCALE", TAU_SCALE),
    Const::F32("TAU2_SCALE", TAU2_SCALE),
    Const::F32("QUANT_SCALE", QUANT_SCALE),
    Const::U32("MAX_LIGHTS", crate::shading::MAX_LIGHTS),
    Const::U32("SHADING_MODE", crate::shading::SHADING_MODE),
    Const::U32("SHADING_UNLIT", crate::shading::Shading::Unlit as u32),
    Const::U32("SHADING_FLAT", crate::shading::Shading::Flat as u32),
    Const::U32("SHADING_SMOOTH", crate::shading::Shading::Smooth as u32),
    Const::U32("TWO_SIDED", crate::shading::TWO_SIDED),
    Const::U32("RAY_DEPTH", crate::shading::RAY_DEPTH),
    Const::U32("TEXTURED", crate::shading::TEXTURED),
    Const::U32("CULL_BACK", crate::shading::CULL_BACK),
    Const::U32("EMISSIVE_TEXTURED", crate::shading::EMISSIVE_TEXTURED),
    Const::U32("ALPHA_TEST", crate::shading::ALPHA_TEST),
    Const::U32("MATERIAL_VEC4S", crate::gpu_types::MATERIAL_VEC4S),
    Const::U32("SHADING_HAIR", crate::shading::Shading::Hair as u32),
    Const::U32("FALLOFF_SHIFT", crate::shading::FALLOFF_SHIFT),
    Const::U32("FALLOFF_MASK", crate::shading::FALLOFF_MASK),
    Const::U32("FALLOFF_HARD", crate::shading::Falloff::Hard as u32),
    Const::U32("FALLOFF_LINEAR", crate::shading::Falloff::Linear as u32),
    Const::U32("FALLOFF_GAUSSIAN", crate::shading::Falloff::Gaussian as u32),
    Const::U32("FALLOFF_SPLAT", crate::shading::Falloff::Splat as u32),
    Const::F32("SPLAT_ALPHA_MAX", crate::splat::ALPHA_MAX as f32),
    Const::F32("SPLAT_ALPHA_MIN", crate::splat::ALPHA_MIN as f32),
    Const::F32("SPLAT_LOW_PASS", crate::splat::LOW_PASS as f32),
    Const::F32("SPLAT_SIGMAS", crate::splat::SIGMAS as f32),
    Const::F32("SH_C0", crate::splat::SH_C0 as f32),
    Const::F32("SH_C1", crate::splat::SH_C1 as f32),
    Const::F32("SH_C2_0", crate::splat::SH_C2[0] as f32),
    Const::F32("SH_C2_1", crate::splat::SH_C2[1] as f32),
    Const::F32("SH_C2_2", crate::splat::SH_C2[2] as f32),
    Const::F32("SH_C2_3", crate::splat::SH_C2[3] as f32),
    Const::F32("SH_C2_4", crate::splat::SH_C2[4] as f32),
    Const::F32("SH_C3_0", crate::splat::SH_C3[0] as f32),
    Const::F32("SH_C3_1", crate::splat::SH_C3[1] as f32),
    Const::F32("SH_C3_2", crate::splat::SH_C3[2] as f32),
    Const::F32("SH_C3_3", crate::splat::SH_C3[3] as f32),
    Const::F32("SH_C3_4", crate::splat::SH_C3[4] as f32),
    Const::F32("SH_C3_5", crate::splat::SH_C3[5] as f32),
    Const::F32("SH_C3_6", crate::splat::SH_C3[6] as f32),
    Const::U32("PRIM_MESH", crate::primitive::PRIM_MESH),
    Const::U32("PRIM_STRANDS", crate::primitive::PRIM_STRANDS),
    Const::U32("PRIM_PARTICLES", crate::primitive::PRIM_PARTICLES),
    Const::U32("PRIM_GAUSSIANS", crate::primitive::PRIM_GAUSSIANS),
    Const::U32("FIRST_SEGMENT", crate::primitive::FIRST_SEGMENT),
    Const::U32("LAST_SEGMENT", crate::primitive::LAST_SEGMENT),
    Const::U32("POINT_MASK", crate::primitive::POINT_MASK),
    Const::U32("BATCH", BATCH),
    Const::U32("SWEEP_BLOCK", SWEEP_BLOCK),
    Const::U32("SWEEP_PIXEL_WORDS", SWEEP_PIXEL_WORDS),
    Const::U32("SWEEP_SAMPLE_WORDS", SWEEP_SAMPLE_WORDS),
    Const::U32("LOCK_TRIES", LOCK_TRIES),
    Const::F32("MBOIT_MIN_TRANSMITTANCE", MBOIT_MIN_TRANSMITTANCE),
    Const::F32("MBOIT_MIN_WEIGHT", MBOIT_MIN_WEIGHT),
    Const::F32("MBOIT_STAR4_2", MBOIT_STAR4[0]),
    Const::F32("MBOIT_STAR4_4", MBOIT_STAR4[1]),
    Const::F32("MBOIT_STAR6_2", MBOIT_STAR6[0]),
    Const::F32("MBOIT_STAR6_4", MBOIT_STAR6[1]),
    Const::F32("MBOIT_STAR6_6", MBOIT_STAR6[2]),
    Const::F32("MBOIT_STAR8_2", MBOIT_STAR8[0]),
    Const::F32("MBOIT_STAR8_4", MBOIT_STAR8[1]),
    Const::F32("MBOIT_STAR8_6", MBOIT_STAR8[2]),
    Const::F32("MBOIT_STAR8_8", MBOIT_STAR8[3]),
    Const::F32("MBOIT_BIAS_4", MBOIT_BIAS[0]),
    Const::F32("MBOIT_BIAS_6", MBOIT_BIAS[1]),
    Const::F32("MBOIT_BIAS_8", MBOIT_BIAS[2]),
    Const::F32("MBOIT_TRIG_BIAS_2", MBOIT_TRIG_BIAS[0]),
    Const::F32("MBOIT_TRIG_BIAS_3", MBOIT_TRIG_BIAS[1]),
    Const::F32("MBOIT_TRIG_BIAS_4", MBOIT_TRIG_BIAS[2]),
    Const::F32("MBOIT_BIAS16_4", MBOIT_BIAS16[0]),
    Const::F32("MBOIT_BIAS16_6", MBOIT_BIAS16[1]),
    Const::F32("MBOIT_BIAS16_8", MBOIT_BIAS16[2]),
    Const::F32("MBOIT_TRIG_BIAS16_2", MBOIT_TRIG_BIAS16[0]),
    Const::F32("MBOIT_TRIG_BIAS16_3", MBOIT_TRIG_BIAS16[1]),
    Const::F32("MBOIT_TRIG_BIAS16_4", MBOIT_TRIG_BIAS16[2]),
    Const::F32("MBOIT_WRAP", MBOIT_WRAP),
];
