// Wavelet transparency (Aizenshtein, Smal, McGuire 2022) with Haar wavelets at 32 bits. The
// optical depth over the depth u in [0, 1) (mboit's warp, mapped from [-1, 1]) is a sum of
// Diracs tau_i delta(u - u_i), tau = -ln(1 - alpha); its projection onto RANK Haar functions
// (the scaling function, then the wavelets psi_i breadth first, i = 2^j + k):
//   fs_coefficients1..4  pass 1: additive blending of tau times the unnormalized Haar functions
//                        at the fragment's depth, h_0 = 1 and h_i = +1 / -1 on the near / far
//                        half of psi_i's support (RANK / 4 RGBA32F targets; d_0 is b0);
//   fs_shade1..4         pass 2: each fragment integrates the projection up to its depth,
//                        A(u) = d_0 u + sum_i 2^j d_i tent_i(u) (exact at the boundaries of
//                        the finest cells, linear within one), T = exp(-A) without the
//                        fragment's own share, adds (C alpha T, alpha T) and, in the companion
//                        target, tau, its share of the error bound (the range of the optical
//                        depth in front of it over its cell), a count and its largest |C|
//                        (blended by max);
//   fs_resolve           as mboit's: the weighted average of the colors times 1 - exp(-b0),
//                        the opaque base times exp(-b0), and the per-pixel error bound.
// RANK is injected. Model: python/oit/models_wavelet.py; docs/methods.md ("wavelet").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl
//!include common/absorbance.wgsl

@group(2) @binding(0) var coef0_tex: texture_2d<f32>;
@group(2) @binding(1) var coef1_tex: texture_2d<f32>;
@group(2) @binding(2) var coef2_tex: texture_2d<f32>;
@group(2) @binding(3) var coef3_tex: texture_2d<f32>;

//!include common/accum_targets.wgsl

// The coefficient targets, four Haar functions each.
const TARGETS: u32 = RANK / 4u;
// The largest float32 below 1: a fragment on the far plane lies in the last cell.
const BELOW_ONE: f32 = 0.99999994;

// The depth in [0, 1) that the Haar functions are defined over.
fn unit_depth(in: VsOut) -> f32 {
    return min(0.5 * warp(in.clip, in.view_w) + 0.5, BELOW_ONE);
}

// Haar functions 4t .. 4t + 3 at depth u, as x = u 2^j - k: the wavelet's support is x in
// [0, 1), its near half [0, 1/2). The scaling function (i = 0) has 2^j = 0 there (x = 0).
struct Lanes {
    scale: vec4<f32>,
    x: vec4<f32>,
}

fn lanes(u: f32, t: u32) -> Lanes {
    let i = vec4<u32>(4u * t) + vec4<u32>(0u, 1u, 2u, 3u);
    let level = vec4<u32>(1u) << firstLeadingBit(max(i, vec4<u32>(1u)));
    let first = i == vec4<u32>(0u);
    let scale = select(vec4<f32>(level), vec4<f32>(0.0), first);
    return Lanes(scale, u * scale - select(vec4<f32>(i - level), vec4<f32>(0.0), first));
}

fn inside(x: vec4<f32>) -> vec4<bool> {
    return (x >= vec4<f32>(0.0)) & (x < vec4<f32>(1.0));
}

// h_i(u) for the four functions of target t: what a unit of optical depth at u adds.
fn haar(u: f32, t: u32) -> vec4<f32> {
    let l = lanes(u, t);
    return select(vec4<f32>(0.0), select(vec4<f32>(-1.0), vec4<f32>(1.0), l.x < vec4<f32>(0.5)), inside(l.x));
}

// 2^j times the integral of h_i from 0 to u: a tent of height 1/2 over psi_i's support; u for
// the scaling function.
fn tents(u: f32, t: u32) -> vec4<f32> {
    let l = lanes(u, t);
    let tent = max(vec4<f32>(0.5) - abs(l.x - vec4<f32>(0.5)), vec4<f32>(0.0));
    return select(tent, vec4<f32>(u), l.scale == vec4<f32>(0.0));
}

// The finest scale 2^j among the wavelets whose support holds u: its cells are 2^-(j + 1) wide.
fn finest(u: f32) -> f32 {
    var s = 0.0;
    for (var t = 0u; t < TARGETS; t++) {
        let l = lanes(u, t);
        let v = select(vec4<f32>(0.0), l.scale, inside(l.x));
        s = max(s, max(max(v.x, v.y), max(v.z, v.w)));
    }
    return s;
}

struct Coefficients {
    d0: vec4<f32>,
    d1: vec4<f32>,
    d2: vec4<f32>,
    d3: vec4<f32>,
}

// A(u): the projected optical depth integrated from 0 to u.
fn absorbance(d: Coefficients, u: f32) -> f32 {
    var a = dot(d.d0, tents(u, 0u));
    if TARGETS > 1u {
        a += dot(d.d1, tents(u, 1u));
    }
    if TARGETS > 2u {
        a += dot(d.d2, tents(u, 2u));
    }
    if TARGETS > 3u {
        a += dot(d.d3, tents(u, 3u));
    }
    return a;
}

// A fragment's optical depth and depth (or discard): what pass 1 adds.
fn splat(raw: VsOut) -> vec2<f32> {
    let in = shaded_alpha(raw);
    if in.color.a <= 0.0 { discard; }
    return vec2<f32>(optical_depth(in.color.a), unit_depth(in));
}

struct Coefficients1 {
    @location(0) d0: vec4<f32>,
}

struct Coefficients2 {
    @location(0) d0: vec4<f32>,
    @location(1) d1: vec4<f32>,
}

struct Coefficients3 {
    @location(0) d0: vec4<f32>,
    @location(1) d1: vec4<f32>,
    @location(2) d2: vec4<f32>,
}

struct Coefficients4 {
    @location(0) d0: vec4<f32>,
    @location(1) d1: vec4<f32>,
    @location(2) d2: vec4<f32>,
    @location(3) d3: vec4<f32>,
}

@fragment
fn fs_coefficients1(raw: VsOut) -> Coefficients1 {
    let f = splat(raw);
    return Coefficients1(f.x * haar(f.y, 0u));
}

@fragment
fn fs_coefficients2(raw: VsOut) -> Coefficients2 {
    let f = splat(raw);
    return Coefficients2(f.x * haar(f.y, 0u), f.x * haar(f.y, 1u));
}

@fragment
fn fs_coefficients3(raw: VsOut) -> Coefficients3 {
    let f = splat(raw);
    return Coefficients3(f.x * haar(f.y, 0u), f.x * haar(f.y, 1u), f.x * haar(f.y, 2u));
}

@fragment
fn fs_coefficients4(raw: VsOut) -> Coefficients4 {
    let f = splat(raw);
    return Coefficients4(f.x * haar(f.y, 0u), f.x * haar(f.y, 1u), f.x * haar(f.y, 2u), f.x * haar(f.y, 3u));
}

// A fragment's color weighted by alpha T, its optical depth, and its share of the error bound.
// T = exp(-A(u) + own): A(u) less the fragment's own share of it, its optical depth spread over
// its cell up to u. The true transmittance in front of it lies between exp(-A) at its cell's
// near boundary and exp(-A + tau) at its far one, where A is exact (docs/methods.md, "wavelet").
fn shade_with(raw: VsOut, d: Coefficients) -> Accum {
    let in = shaded(raw);
    let a = in.color.a;
    if a <= 0.0 { discard; }
    let tau = optical_depth(a);
    let u = unit_depth(in);
    let cells = 2.0 * finest(u);
    let near = floor(u * cells) / cells;
    let own = (u - near) * cells * tau;
    let t = clamp(exp(own - absorbance(d, u)), MBOIT_MIN_WEIGHT, 1.0);
    let upper = exp(-absorbance(d, near));
    let lower = exp(tau - absorbance(d, near + 1.0 / cells));
    let dev = max(max(t - lower, upper - t), 0.0) + MBOIT_MIN_TRANSMITTANCE;
    let w = a * t;
    let c = in.color.rgb;
    let m = max(max(abs(c.r), abs(c.g)), abs(c.b));
    return Accum(vec4<f32>(c * w, w), vec4<f32>(tau, a * m * dev, 1.0, m));
}

// The coefficients of a pixel as the shade pass reads them, one entry point a target count
// (each binds only its own targets).
fn load(tex: texture_2d<f32>, raw: VsOut) -> vec4<f32> {
    return textureLoad(tex, vec2<i32>(raw.clip.xy), 0);
}

const ZERO: vec4<f32> = vec4<f32>(0.0);

@fragment
fn fs_shade1(raw: VsOut) -> Accum {
    return shade_with(raw, Coefficients(load(coef0_tex, raw), ZERO, ZERO, ZERO));
}

@fragment
fn fs_shade2(raw: VsOut) -> Accum {
    return shade_with(raw, Coefficients(load(coef0_tex, raw), load(coef1_tex, raw), ZERO, ZERO));
}

@fragment
fn fs_shade3(raw: VsOut) -> Accum {
    return shade_with(raw, Coefficients(load(coef0_tex, raw), load(coef1_tex, raw), load(coef2_tex, raw), ZERO));
}

@fragment
fn fs_shade4(raw: VsOut) -> Accum {
    return shade_with(raw, Coefficients(load(coef0_tex, raw), load(coef1_tex, raw), load(coef2_tex, raw), load(coef3_tex, raw)));
}

@group(2) @binding(4) var accum_tex: texture_2d<f32>;
@group(2) @binding(5) var aux_tex: texture_2d<f32>;

// float32's unit roundoff, and WGSL log's absolute error on [0.5, 2] (2^-21).
const UNIT_ROUNDOFF: f32 = 5.9604645e-8;
const LOG_ERROR: f32 = 4.7683716e-7;

// C = sum(C alpha T) / sum(alpha T) (1 - exp(-b0)) + exp(-b0) C_bg, and its bound as mboit's
// (|s - 1| max(sum C alpha T) + sum alpha max(C) dev, s the factor the average scales the sums
// by, and a rounding term a fragment), plus 3 (e^E - 1) for float32's error E in every A: the
// n-term sums into the coefficients and the reconstruction's, each term at most b0, and each
// tau's log. Both composites weigh the colors by weights summing to 1 - exp(-b0), so it is also
// at most that times the largest |C| (aux.a, blended by max), plus exp(-b0)'s own float32 error
// times the colors (docs/methods.md, "wavelet").
@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> Final {
    let base = base_at(pos);
    let p = vec2<i32>(pos.xy);
    let acc = textureLoad(accum_tex, p, 0);
    let aux = textureLoad(aux_tex, p, 0);
    let t = exp(-aux.r);
    let n = aux.b;
    let sums = 3.0 * (aux.r * UNIT_ROUNDOFF * (n + f32(RANK) + 4.0) + n * LOG_ERROR);
    let total = aux.r * UNIT_ROUNDOFF * n + n * LOG_ERROR;
    let rounding = (n + 2.0) * ROUNDING_TERM;
    let colors = aux.a + max(max(abs(base.r), abs(base.g)), abs(base.b));
    let convex = (1.0 - t) * aux.a + t * (exp(min(total, 80.0)) - 1.0) * colors + rounding;
    let out = vec4<f32>(base.rgb * t, 1.0 - t * (1.0 - base.a));
    if acc.a <= 0.0 {
        return Final(out, min(aux.g + (1.0 - t) + rounding + 3.0 * (exp(min(sums, 80.0)) - 1.0), convex));
    }
    let s = (1.0 - t) / acc.a;
    let bound = abs(s - 1.0) * max(max(acc.r, acc.g), acc.b) + aux.g + rounding + 3.0 * (exp(min(sums, 80.0)) - 1.0);
    return Final(vec4<f32>(acc.rgb / acc.a * (1.0 - t) + out.rgb, out.a), min(bound, convex));
}
