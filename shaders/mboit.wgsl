// Moment-based OIT (Münstermann, Krumpen, Klein, Peters 2018), power or trigonometric
// moments (MBOIT_BASIS 0 or 1) at 32 bits:
//   fs_moments4/fs_moments  pass 1: additive blending of b0 = sum of the optical depths
//                           -ln(1 - alpha) and b_k = sum of optical depth times warped depth^k,
//                           k = 1 .. MOMENTS (paper Sec. 3.1), or times cos and sin of j times
//                           its angle, j = 1 .. MOMENTS / 2 (Sec. 3.6);
//   fs_shade4/fs_shade      pass 2: each fragment's transmittance from the biased, normalized
//                           moments (Sec. 3.3, Algorithm 1: the Hankel solve, the kernel
//                           polynomial's roots, the interpolating polynomial through them with
//                           the overestimation at the fragment), adds (C alpha T, alpha T) and,
//                           in the companion target, its optical depth (b0 again), its share
//                           of the error bound and a count;
//   fs_resolve              the weighted average of the colors times 1 - exp(-b0), the opaque
//                           base times exp(-b0) (Sec. 3.4), and the per-pixel error bound.
// The warp: `warp`. MOMENTS, MBOIT_BIAS and MBOIT_OVERESTIMATION are
// injected; the bias vectors are shared constants (crates/oit-core/src/consts.rs). Model:
// python/oit/models.py `mboit`; docs/methods.md ("mboit").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

@group(2) @binding(0) var b0_tex: texture_2d<f32>;
@group(2) @binding(1) var low_tex: texture_2d<f32>;
@group(2) @binding(2) var high_tex: texture_2d<f32>;

//!include common/accum_targets.wgsl

// Half the moment count: the Hankel matrix is (N + 1) x (N + 1), the kernel polynomial of degree N.
const N: u32 = MOMENTS / 2u;
// 1/3 as a product (a division by 3.0 stays a division: its reciprocal is not exact).
const THIRD: f32 = 0.333333333;

//!include common/absorbance.wgsl

// z, z^2, ..., z^8 by repeated products.
fn powers(z: f32) -> array<f32, 8> {
    var p: array<f32, 8>;
    p[0] = z;
    for (var k = 1u; k < 8u; k++) {
        p[k] = p[k - 1u] * z;
    }
    return p;
}

struct Moments4 {
    @location(0) b0: vec4<f32>,
    @location(1) low: vec4<f32>,
}

struct Moments {
    @location(0) b0: vec4<f32>,
    @location(1) low: vec4<f32>,
    @location(2) high: vec4<f32>,
}

// What a fragment adds per unit of optical depth: the warped depth's powers z, .., z^8, or
// the trigonometric basis' cos(j phi), sin(j phi), j = 1 .. 4, at phi = angle(z).
fn basis(z: f32) -> array<f32, 8> {
    if MBOIT_BASIS == 0u {
        return powers(z);
    }
    var p: array<f32, 8>;
    let phi = angle(z);
    for (var j = 0u; j < 4u; j++) {
        p[2u * j] = cos(f32(j + 1u) * phi);
        p[2u * j + 1u] = sin(f32(j + 1u) * phi);
    }
    return p;
}

// The trigonometric basis' angle of a warped depth: [-1, 1] to [0, 2 pi - MBOIT_WRAP], the
// rest of the circle a wrapping zone between the farthest and the nearest depths (Sec. 3.6).
fn angle(z: f32) -> f32 {
    let half = 3.14159265 - 0.5 * MBOIT_WRAP;
    return z * half + half;
}

@fragment
fn fs_moments4(raw: VsOut) -> Moments4 {
    let in = shaded_alpha(raw);
    if in.color.a <= 0.0 { discard; }
    let od = optical_depth(in.color.a);
    let p = basis(warp(in.clip, in.view_w));
    return Moments4(vec4<f32>(od, 0.0, 0.0, 0.0), vec4<f32>(p[0], p[1], p[2], p[3]) * od);
}

@fragment
fn fs_moments(raw: VsOut) -> Moments {
    let in = shaded_alpha(raw);
    if in.color.a <= 0.0 { discard; }
    let od = optical_depth(in.color.a);
    let p = basis(warp(in.clip, in.view_w));
    return Moments(vec4<f32>(od, 0.0, 0.0, 0.0), vec4<f32>(p[0], p[1], p[2], p[3]) * od, vec4<f32>(p[4], p[5], p[6], p[7]) * od);
}

// The bias vector b* for MOMENTS as (b1 .. b4) and (b5 .. b8) (its odd moments are 0).
fn bias_lo() -> vec4<f32> {
    if MOMENTS == 4u {
        return vec4<f32>(0.0, MBOIT_STAR4_2, 0.0, MBOIT_STAR4_4);
    } else if MOMENTS == 6u {
        return vec4<f32>(0.0, MBOIT_STAR6_2, 0.0, MBOIT_STAR6_4);
    }
    return vec4<f32>(0.0, MBOIT_STAR8_2, 0.0, MBOIT_STAR8_4);
}

fn bias_hi() -> vec4<f32> {
    if MOMENTS == 6u {
        return vec4<f32>(0.0, MBOIT_STAR6_6, 0.0, 0.0);
    }
    return vec4<f32>(0.0, MBOIT_STAR8_6, 0.0, MBOIT_STAR8_8);
}

// The Hankel matrix H[i][j] = m[i + j], i, j = 0 .. N, of the normalized moments (m0 = 1) as
// L D L^T. L's first column is m = (m1 .. m4) itself (d0 = 1); `l1` is column 1 from row 1
// (L11 = 1, L21, L31, L41), `l2` column 2 from row 2, `l3` column 3 from row 3; d = (d1 .. d4).
// Straight-line vector code throughout: a loop indexing a local array runs lane by lane on a
// software rasterizer (it made this pass 25 times the cost of the moments pass).
struct Hankel {
    m: vec4<f32>,
    // 1 / d: the solves multiply by it (a division costs several multiplications).
    inv_d: vec4<f32>,
    l1: vec4<f32>,
    l2: vec3<f32>,
    l3: vec2<f32>,
    d: vec4<f32>,
}

fn hankel(lo: vec4<f32>, hi: vec4<f32>) -> Hankel {
    var h: Hankel;
    h.m = lo;
    h.d = vec4<f32>(1.0);
    // L[i][j] = (m[i + j] - sum over k < j of L[i][k] L[j][k] d[k]) / d[j].
    h.d.x = lo.y - lo.x * lo.x;
    h.inv_d = vec4<f32>(1.0);
    h.inv_d.x = 1.0 / h.d.x;
    h.l1 = (vec4<f32>(lo.yzw, hi.x) - lo * lo.x) * h.inv_d.x;
    h.d.y = lo.w - lo.y * lo.y - h.l1.y * h.l1.y * h.d.x;
    h.inv_d.y = 1.0 / h.d.y;
    h.l2 = (vec3<f32>(lo.w, hi.xy) - lo.yzw * lo.y - h.l1.yzw * h.l1.y * h.d.x) * h.inv_d.y;
    if N >= 3u {
        h.d.z = hi.y - lo.z * lo.z - h.l1.z * h.l1.z * h.d.x - h.l2.y * h.l2.y * h.d.y;
        h.inv_d.z = 1.0 / h.d.z;
        h.l3 = (hi.yz - lo.zw * lo.z - h.l1.zw * h.l1.z * h.d.x - h.l2.yz * h.l2.y * h.d.y) * h.inv_d.z;
    }
    if N >= 4u {
        h.d.w = hi.w - lo.w * lo.w - dot(vec3<f32>(h.l1.w, h.l2.z, h.l3.y) * vec3<f32>(h.l1.w, h.l2.z, h.l3.y), h.d.xyz);
        h.inv_d.w = 1.0 / h.d.w;
    }
    return h;
}

// L^-1 (1, x, .., x^N) at four points x at once: y1 .. y4, a component a point (y0 = 1).
struct Forward {
    y1: vec4<f32>,
    y2: vec4<f32>,
    y3: vec4<f32>,
    y4: vec4<f32>,
}

fn forward(h: Hankel, x: vec4<f32>) -> Forward {
    var f: Forward;
    let x2 = x * x;
    f.y1 = x - h.m.x;
    f.y2 = x2 - h.m.y - h.l1.y * f.y1;
    if N >= 3u {
        f.y3 = x2 * x - h.m.z - h.l1.z * f.y1 - h.l2.y * f.y2;
    }
    if N >= 4u {
        f.y4 = x2 * x2 - h.m.w - h.l1.w * f.y1 - h.l2.z * f.y2 - h.l3.y * f.y3;
    }
    return f;
}

// The Christoffel function 1 / (v(x)^T H^-1 v(x)) = 1 / (1 + sum of y_k^2 / d_k) at four
// points: the weight of a node of a representation of the moments there.
fn christoffel(h: Hankel, f: Forward) -> vec4<f32> {
    var s = 1.0 + f.y1 * f.y1 * h.inv_d.x + f.y2 * f.y2 * h.inv_d.y;
    if N >= 3u {
        s += f.y3 * f.y3 * h.inv_d.z;
    }
    if N >= 4u {
        s += f.y4 * f.y4 * h.inv_d.w;
    }
    return 1.0 / s;
}

// H^-1 v(z) from g = D^-1 L^-1 v(z): the kernel polynomial's coefficients (c0 .. c3) and c4,
// by the back substitution c_i = g_i - sum over k > i of L[k][i] c_k.
fn kernel(h: Hankel, g: vec4<f32>) -> array<vec4<f32>, 2> {
    var c = vec4<f32>(1.0, g.xyz);
    var c4 = 0.0;
    if N >= 4u {
        c4 = g.w;
        c.w -= h.l3.y * c4;
    }
    if N >= 3u {
        c.z -= h.l2.y * c.w + h.l2.z * c4;
    } else {
        c.w = 0.0;
    }
    c.y -= h.l1.y * c.z + h.l1.z * c.w;
    if N >= 4u {
        c.y -= h.l1.w * c4;
    }
    c.x = 1.0 - dot(h.m.xyz, c.yzw);
    if N >= 4u {
        c.x -= h.m.w * c4;
    }
    return array<vec4<f32>, 2>(c, vec4<f32>(c4, 0.0, 0.0, 0.0));
}

// The kernel polynomial's N roots (all real) in the first N components: the quadratic's
// formula; the cubic's trigonometric one and the quartic's (Ferrari's), each root polished by a
// Newton step.
fn kernel_roots(kc: array<vec4<f32>, 2>) -> vec4<f32> {
    let c = kc[0];
    if N == 2u {
        let p = 0.5 * c.y / c.z;
        let r = sqrt(max(p * p - c.x / c.z, 0.0));
        return vec4<f32>(-p - r, -p + r, 0.0, 0.0);
    }
    if N == 3u {
        // x^3 + a.z x^2 + a.y x + a.x; x = t - s gives t^3 + p t + q.
        let a = c.xyz * (1.0 / c.w);
        let s = a.z * THIRD;
        let p = a.y - 3.0 * s * s;
        let q = (2.0 * s * s - a.y) * s + a.x;
        let rho = sqrt(max(-p * THIRD, 0.0));
        let cos3 = clamp(-q / max(2.0 * rho * rho * rho, 1e-30), -1.0, 1.0);
        // cos(theta - 2 pi k / 3) from cos and sin of theta = acos(cos3) / 3 in [0, pi / 3].
        let c0 = cos(acos(cos3) * THIRD);
        let s0 = sqrt(max(1.0 - c0 * c0, 0.0)) * 0.866025404;
        var x = 2.0 * rho * vec3<f32>(c0, -0.5 * c0 - s0, -0.5 * c0 + s0) - s;
        let v = ((x + a.z) * x + a.y) * x + a.x;
        let dv = (3.0 * x + 2.0 * a.z) * x + a.y;
        x -= select(vec3<f32>(0.0), v / dv, dv != vec3<f32>(0.0));
        return vec4<f32>(x, 0.0);
    }
    // x^4 + a.w x^3 + a.z x^2 + a.y x + a.x; x = y - s gives y^4 + p y^2 + q y + r, which is
    // (y^2 + p / 2 + m)^2 - 2 m (y - q / (4 m))^2 at the largest root m of Ferrari's resolvent
    // m^3 + p m^2 + (p^2 / 4 - r) m - q^2 / 8 (the cubic's trigonometric formula): two
    // quadratics. Where q is 0 (m = 0) the quartic is a quadratic in y^2.
    let a = c * (1.0 / kc[1].x);
    let s = a.w / 4.0;
    let p = a.z - 6.0 * s * s;
    let q = a.y - 2.0 * a.z * s + 8.0 * s * s * s;
    let r = a.x - a.y * s + a.z * s * s - 3.0 * s * s * s * s;
    let e2 = p * THIRD;
    let e1 = 0.25 * p * p - r;
    let pp = e1 - 3.0 * e2 * e2;
    let qq = (2.0 * e2 * e2 - e1) * e2 - 0.125 * q * q;
    let rho = sqrt(max(-pp * THIRD, 0.0));
    let m = max(2.0 * rho * cos(acos(clamp(-qq / max(2.0 * rho * rho * rho, 1e-30), -1.0, 1.0)) * THIRD) - e2, 0.0);
    var y: vec4<f32>;
    if m > 1e-12 {
        let w = sqrt(2.0 * m);
        let k = 0.5 * p + m + vec2<f32>(0.5, -0.5) * q / w;
        let d = sqrt(max(2.0 * m - 4.0 * k, vec2<f32>(0.0)));
        y = 0.5 * vec4<f32>(w - d.x, w + d.x, -w - d.y, -w + d.y);
    } else {
        let h = sqrt(max(p * p - 4.0 * r, 0.0));
        let u = sqrt(max(0.5 * vec2<f32>(-p - h, -p + h), vec2<f32>(0.0)));
        y = vec4<f32>(-u.y, -u.x, u.x, u.y);
    }
    // In float32 the formula loses close roots to cancellation: two steps of Aberth's
    // simultaneous iteration (Newton's with the other roots divided out) restore them.
    var x = y - s;
    for (var it = 0u; it < 2u; it++) {
        let v = (((x + a.w) * x + a.z) * x + a.y) * x + a.x;
        let dv = ((4.0 * x + 3.0 * a.w) * x + 2.0 * a.z) * x + a.y;
        let ratio = v / dv;
        let pull = 1.0 / (x - x.yzwx) + 1.0 / (x - x.zwxy) + 1.0 / (x - x.wxyz);
        let step = ratio / (1.0 - ratio * pull);
        x -= select(vec4<f32>(0.0), step, abs(step) < vec4<f32>(1.0));
    }
    return x;
}

// The normalized absorbance in front of warped depth z from b0 and the moments b1 .. b8 (paper
// Algorithm 1), with the biased measure's mass in front of z and up to it (the moment problem's
// lower and upper bounds). The nodes of the representation through z are z and the kernel
// polynomial's roots; integrating the polynomial interpolating the overestimation at z, 1 at the
// roots in front and 0 behind is summing the nodes' Christoffel weights with those factors.
fn transmittance(b0: f32, lo: vec4<f32>, hi: vec4<f32>, z: f32) -> vec3<f32> {
    let inv_b0 = 1.0 / b0;
    let h = hankel(mix(lo * inv_b0, bias_lo(), MBOIT_BIAS), mix(hi * inv_b0, bias_hi(), MBOIT_BIAS));
    // In one lane: the other lanes' work is dropped (components past N are 0 in y, 1 in 1 / d).
    let at_z = forward(h, vec4<f32>(z));
    let own = christoffel(h, at_z).x;
    let g = vec4<f32>(at_z.y1.x, at_z.y2.x, at_z.y3.x, at_z.y4.x) * h.inv_d;
    let roots = kernel_roots(kernel(h, g));
    // Summed lane by lane up to N, so that the compiler drops the unused lanes' work.
    let w = christoffel(h, forward(h, roots)) * select(vec4<f32>(0.0), vec4<f32>(1.0), roots < vec4<f32>(z));
    var front = w.x + w.y;
    if N >= 3u {
        front += w.z;
    }
    if N >= 4u {
        front += w.w;
    }
    return vec3<f32>(front + MBOIT_OVERESTIMATION * own, front, front + own);
}

//!include common/mboit_trig.wgsl

// A fragment's color weighted by alpha T (T from the estimate of the absorbance in front of
// it), its optical depth, and its share of the error bound: alpha max(C) times how far T can
// be from the transmittance of every measure with these moments (docs/methods.md, "mboit").
fn shade_with(raw: VsOut, b0: f32, lo: vec4<f32>, hi: vec4<f32>) -> Accum {
    let in = shaded(raw);
    let a = in.color.a;
    if a <= 0.0 { discard; }
    let z = warp(in.clip, in.view_w);
    var masses: vec3<f32>;
    if MBOIT_BASIS == 0u {
        masses = transmittance(b0, lo, hi, z);
    } else {
        masses = trig_transmittance(b0, lo, hi, angle(z));
    }
    let t = clamp(exp(-b0 * masses.x), MBOIT_MIN_WEIGHT, 1.0);
    // The bias mixed beta of another measure in: the true mass in front is within
    // [(lower - beta) / (1 - beta), upper / (1 - beta)].
    let lower = max(masses.y - MBOIT_BIAS, 0.0) / (1.0 - MBOIT_BIAS);
    let upper = min(masses.z / (1.0 - MBOIT_BIAS), 1.0);
    let dev = max(max(t - exp(-b0 * upper), exp(-b0 * lower) - t), 0.0) + MBOIT_MIN_TRANSMITTANCE;
    let w = a * t;
    let c = in.color.rgb;
    return Accum(vec4<f32>(c * w, w), vec4<f32>(optical_depth(a), a * max(max(c.r, c.g), c.b) * dev, 1.0, 0.0));
}

@fragment
fn fs_shade4(raw: VsOut) -> Accum {
    let p = vec2<i32>(raw.clip.xy);
    return shade_with(raw, textureLoad(b0_tex, p, 0).r, textureLoad(low_tex, p, 0), vec4<f32>(0.0));
}

@fragment
fn fs_shade(raw: VsOut) -> Accum {
    let p = vec2<i32>(raw.clip.xy);
    return shade_with(raw, textureLoad(b0_tex, p, 0).r, textureLoad(low_tex, p, 0), textureLoad(high_tex, p, 0));
}

//!include common/mboit16.wgsl

@group(2) @binding(3) var accum_tex: texture_2d<f32>;
@group(2) @binding(4) var aux_tex: texture_2d<f32>;

// C = sum(C alpha T) / sum(alpha T) (1 - exp(-b0)) + exp(-b0) C_bg. Its bound: with s the
// factor the average scales the sums by, |s - 1| max(sum C alpha T) + sum alpha max(C) dev,
// and a rounding term a fragment (docs/methods.md, "mboit").
@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> Final {
    let base = base_at(pos);
    let p = vec2<i32>(pos.xy);
    let acc = textureLoad(accum_tex, p, 0);
    let aux = textureLoad(aux_tex, p, 0);
    let t = exp(-aux.r);
    let rounding = (aux.b + 2.0) * ROUNDING_TERM;
    if acc.a <= 0.0 {
        return Final(vec4<f32>(base.rgb * t, 1.0 - t * (1.0 - base.a)), aux.g + (1.0 - t) + rounding);
    }
    let s = (1.0 - t) / acc.a;
    let bound = abs(s - 1.0) * max(max(acc.r, acc.g), acc.b) + aux.g + rounding;
    return Final(vec4<f32>(acc.rgb / acc.a * (1.0 - t) + base.rgb * t, 1.0 - t * (1.0 - base.a)), bound);
}
