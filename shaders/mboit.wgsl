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

// The even moments of the bias vector b* for MOMENTS (its odd ones are 0).
fn bias_vector(k: u32) -> f32 {
    if k % 2u == 1u {
        return 0.0;
    }
    var star: array<f32, 4>;
    if MOMENTS == 4u {
        star = array<f32, 4>(MBOIT_STAR4_2, MBOIT_STAR4_4, 0.0, 0.0);
    } else if MOMENTS == 6u {
        star = array<f32, 4>(MBOIT_STAR6_2, MBOIT_STAR6_4, MBOIT_STAR6_6, 0.0);
    } else {
        star = array<f32, 4>(MBOIT_STAR8_2, MBOIT_STAR8_4, MBOIT_STAR8_6, MBOIT_STAR8_8);
    }
    return star[k / 2u - 1u];
}

// p(x), p'(x), p''(x) of the polynomial c[0] + c[1] x + ... + c[deg] x^deg (Horner).
fn horner(coefs: array<f32, 5>, deg: u32, x: f32) -> vec3<f32> {
    var c = coefs;
    var v = vec3<f32>(c[deg], 0.0, 0.0);
    for (var k = i32(deg) - 1; k >= 0; k--) {
        v = vec3<f32>(v.x * x + c[k], v.y * x + v.x, v.z * x + 2.0 * v.y);
    }
    return v;
}

// The largest root of the polynomial c (degree N, all its roots real) that is not one of the
// `count` roots in `found`: Laguerre's method on c divided by (x - found[j]), the division
// implicit in the logarithmic derivatives (an explicit one loses the small roots to rounding
// after a large one), from above every root (Cauchy's bound), where it converges
// monotonically, cubically near the root.
fn largest_root(coefs: array<f32, 5>, given: array<f32, 5>, count: u32) -> f32 {
    var c = coefs;
    var found = given;
    var bound = 0.0;
    for (var k = 0u; k < N; k++) {
        bound = max(bound, abs(c[k] / c[N]));
    }
    var x = 1.0 + bound;
    let n = f32(N - count);
    for (var it = 0u; it < 40u; it++) {
        let v = horner(coefs, N, x);
        if v.x == 0.0 {
            break;
        }
        var g = v.y / v.x;
        var h = g * g - v.z / v.x;
        for (var j = 0u; j < count; j++) {
            let q = 1.0 / (x - found[j]);
            g -= q;
            h -= q * q;
        }
        let s = sqrt(max((n - 1.0) * (n * h - g * g), 0.0));
        let den = select(g - s, g + s, g >= 0.0);
        if den == 0.0 {
            break;
        }
        let step = n / den;
        x -= step;
        if abs(step) <= 1e-7 * abs(x) {
            break;
        }
    }
    return x;
}

// The integral against m of the polynomial through (x[i], f[i]), i = 0 .. N: Newton's divided
// differences, then its monomial coefficients.
fn integral(nodes: array<f32, 5>, values: array<f32, 5>, moments: array<f32, 9>) -> f32 {
    var x = nodes;
    var f = values;
    var m = moments;
    for (var j = 1u; j <= N; j++) {
        for (var i = N; i >= j; i--) {
            f[i] = (f[i] - f[i - 1u]) / (x[i] - x[i - j]);
        }
    }
    var p: array<f32, 5>;
    p[0] = f[N];
    for (var j = i32(N) - 1; j >= 0; j--) {
        for (var k = N - u32(j); k >= 1u; k--) {
            p[k] = p[k - 1u] - x[j] * p[k];
        }
        p[0] = f[j] - x[j] * p[0];
    }
    var sum = 0.0;
    for (var k = 0u; k <= N; k++) {
        sum += p[k] * m[k];
    }
    return sum;
}

// The normalized absorbance in front of warped depth z from b = (b0, b1, .., b8) (paper
// Algorithm 1), with the biased measure's mass in front of z and up to it (the moment
// problem's lower and upper bounds: the reconstruction with 0 and with 1 at z).
fn transmittance(given: array<f32, 9>, z: f32) -> vec3<f32> {
    var b = given;
    // Normalized and biased toward b*: m = (1 - beta) b / b0 + beta b*.
    var m: array<f32, 9>;
    m[0] = 1.0;
    for (var k = 1u; k <= 2u * N; k++) {
        m[k] = mix(b[k] / b[0], bias_vector(k), MBOIT_BIAS);
    }
    // Hankel matrix H[i][j] = m[i + j] = L D L^T.
    var l: array<array<f32, 5>, 5>;
    var d: array<f32, 5>;
    for (var i = 0u; i <= N; i++) {
        for (var j = 0u; j < i; j++) {
            var s = m[i + j];
            for (var k = 0u; k < j; k++) {
                s -= l[i][k] * l[j][k] * d[k];
            }
            l[i][j] = s / d[j];
        }
        var e = m[2u * i];
        for (var k = 0u; k < i; k++) {
            e -= l[i][k] * l[i][k] * d[k];
        }
        d[i] = e;
    }
    // H c = (1, z, .., z^N): the kernel polynomial's coefficients.
    var c: array<f32, 5>;
    var zk = 1.0;
    for (var i = 0u; i <= N; i++) {
        var s = zk;
        for (var k = 0u; k < i; k++) {
            s -= l[i][k] * c[k];
        }
        c[i] = s;
        zk *= z;
    }
    for (var i = 0u; i <= N; i++) {
        c[i] /= d[i];
    }
    for (var i = i32(N); i >= 0; i--) {
        var s = c[i];
        for (var k = u32(i) + 1u; k <= N; k++) {
            s -= l[k][i] * c[k];
        }
        c[i] = s;
    }
    // Nodes: z (value: the overestimation), then the kernel polynomial's N roots (value 1 in
    // front of z, 0 behind it), largest first.
    var x: array<f32, 5>;
    var f: array<f32, 5>;
    x[0] = z;
    f[0] = MBOIT_OVERESTIMATION;
    var roots: array<f32, 5>;
    for (var r = 0u; r < N; r++) {
        roots[r] = largest_root(c, roots, r);
        x[r + 1u] = roots[r];
        f[r + 1u] = select(0.0, 1.0, roots[r] < z);
    }
    // The interpolating polynomial through (x, f), integrated against the biased moments.
    let estimate = integral(x, f, m);
    f[0] = 0.0;
    let lower = integral(x, f, m);
    f[0] = 1.0;
    return vec3<f32>(estimate, lower, integral(x, f, m));
}

// ---- trigonometric moments (Sec. 3.6): complex numbers as vec2 (re, im).

// The trigonometric moments: MOMENTS real values, MOMENTS / 2 complex moments.
const TRIG_N: u32 = MOMENTS / 2u;

fn cmul(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

fn cdiv(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return cmul(a, vec2<f32>(b.x, -b.y)) / dot(b, b);
}

fn conj(a: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x, -a.y);
}

// The Hermitian Toeplitz matrix of the moments, T[k][l] = m[k - l] (m[-j] = conj(m[j])),
// factored as L D L^H; `christoffel` and `kernel` solve with it.
struct Toeplitz {
    l: array<array<vec2<f32>, 5>, 5>,
    d: array<f32, 5>,
}

fn toeplitz(m: array<vec2<f32>, 5>) -> Toeplitz {
    var mm = m;
    var t: Toeplitz;
    for (var i = 0u; i <= TRIG_N; i++) {
        for (var j = 0u; j < i; j++) {
            var s = mm[i - j];
            for (var k = 0u; k < j; k++) {
                s -= cmul(t.l[i][k], conj(t.l[j][k])) * t.d[k];
            }
            t.l[i][j] = s / t.d[j];
        }
        var e = 1.0;
        for (var k = 0u; k < i; k++) {
            e -= dot(t.l[i][k], t.l[i][k]) * t.d[k];
        }
        t.d[i] = e;
    }
    return t;
}

// L^-1 (1, e^(i theta), .., e^(i TRIG_N theta)).
fn forward(t: Toeplitz, theta: f32) -> array<vec2<f32>, 5> {
    var tt = t;
    var y: array<vec2<f32>, 5>;
    for (var i = 0u; i <= TRIG_N; i++) {
        var s = vec2<f32>(cos(f32(i) * theta), sin(f32(i) * theta));
        for (var k = 0u; k < i; k++) {
            s -= cmul(tt.l[i][k], y[k]);
        }
        y[i] = s;
    }
    return y;
}

// The Christoffel function 1 / (e^H T^-1 e) at angle theta: the weight of a node there.
fn christoffel(t: Toeplitz, theta: f32) -> f32 {
    var tt = t;
    var y = forward(t, theta);
    var k = 0.0;
    for (var i = 0u; i <= TRIG_N; i++) {
        k += dot(y[i], y[i]) / tt.d[i];
    }
    return 1.0 / k;
}

// The transmittance in front of angle phi from b = (b0, Re b1, Im b1, ..): the nodes of the
// canonical representation through phi are the kernel polynomial's roots on the unit circle
// (Durand-Kerner); each weighs its Christoffel number, counted in front of phi (1), behind it
// (0), or in the wrapping zone rising from 0 at its far end to 1 at its near one.
fn trig_transmittance(given: array<f32, 9>, phi: f32) -> vec3<f32> {
    var b = given;
    var m: array<vec2<f32>, 5>;
    m[0] = vec2<f32>(1.0, 0.0);
    for (var j = 1u; j <= TRIG_N; j++) {
        m[j] = (1.0 - MBOIT_BIAS) * vec2<f32>(b[2u * j - 1u], b[2u * j]) / b[0];
    }
    var t = toeplitz(m);
    // q = T^-1 e(phi); the kernel polynomial sum conj(q[k]) z^k.
    var q = forward(t, phi);
    for (var i = 0u; i <= TRIG_N; i++) {
        q[i] /= t.d[i];
    }
    for (var i = i32(TRIG_N); i >= 0; i--) {
        var s = q[i];
        for (var k = u32(i) + 1u; k <= TRIG_N; k++) {
            s -= cmul(conj(t.l[k][i]), q[k]);
        }
        q[i] = s;
    }
    var c: array<vec2<f32>, 5>;
    for (var i = 0u; i <= TRIG_N; i++) {
        c[i] = cdiv(conj(q[i]), conj(q[TRIG_N])); // monic
    }
    var r: array<vec2<f32>, 4>;
    var start = vec2<f32>(1.0, 0.0);
    for (var j = 0u; j < TRIG_N; j++) {
        r[j] = start;
        start = cmul(start, vec2<f32>(0.4, 0.9));
    }
    for (var it = 0u; it < 64u; it++) {
        var moved = 0.0;
        for (var j = 0u; j < TRIG_N; j++) {
            var v = c[TRIG_N];
            for (var k = i32(TRIG_N) - 1; k >= 0; k--) {
                v = cmul(v, r[j]) + c[k];
            }
            var den = vec2<f32>(1.0, 0.0);
            for (var k = 0u; k < TRIG_N; k++) {
                if k != j {
                    den = cmul(den, r[j] - r[k]);
                }
            }
            let step = cdiv(v, den);
            r[j] -= step;
            moved = max(moved, dot(step, step));
        }
        // Converged to float32 (the roots are on the unit circle).
        if moved <= 1e-14 {
            break;
        }
    }
    let zone = 6.28318531 - MBOIT_WRAP;
    let own = christoffel(t, phi);
    var front = 0.0;
    var zone_part = 0.0;
    var zone_mass = 0.0;
    for (var j = 0u; j < TRIG_N; j++) {
        var theta = atan2(r[j].y, r[j].x);
        theta = select(theta, theta + 6.28318531, theta < 0.0);
        let w = christoffel(t, theta);
        if theta > zone {
            zone_part += (theta - zone) / MBOIT_WRAP * w;
            zone_mass += w;
        } else if theta < phi {
            front += w;
        }
    }
    // The bounds count the wrapping zone's nodes out, then in (the zone holds no depth).
    return vec3<f32>(front + zone_part + MBOIT_OVERESTIMATION * own, front, front + own + zone_mass);
}

// A fragment's color weighted by alpha T (T from the estimate of the absorbance in front of
// it), its optical depth, and its share of the error bound: alpha max(C) times how far T can
// be from the transmittance of every measure with these moments (docs/methods.md, "mboit").
fn shade_with(raw: VsOut, b: array<f32, 9>) -> Accum {
    let in = shaded(raw);
    let a = in.color.a;
    if a <= 0.0 { discard; }
    let z = warp(in.clip, in.view_w);
    var masses: vec3<f32>;
    if MBOIT_BASIS == 0u {
        masses = transmittance(b, z);
    } else {
        masses = trig_transmittance(b, angle(z));
    }
    let t = clamp(exp(-b[0] * masses.x), MBOIT_MIN_WEIGHT, 1.0);
    // The bias mixed beta of another measure in: the true mass in front is within
    // [(lower - beta) / (1 - beta), upper / (1 - beta)].
    let lower = max(masses.y - MBOIT_BIAS, 0.0) / (1.0 - MBOIT_BIAS);
    let upper = min(masses.z / (1.0 - MBOIT_BIAS), 1.0);
    let dev = max(max(t - exp(-b[0] * upper), exp(-b[0] * lower) - t), 0.0) + MBOIT_MIN_TRANSMITTANCE;
    let w = a * t;
    let c = in.color.rgb;
    return Accum(vec4<f32>(c * w, w), vec4<f32>(optical_depth(a), a * max(max(c.r, c.g), c.b) * dev, 1.0, 0.0));
}

@fragment
fn fs_shade4(raw: VsOut) -> Accum {
    let p = vec2<i32>(raw.clip.xy);
    let lo = textureLoad(low_tex, p, 0);
    let b = array<f32, 9>(textureLoad(b0_tex, p, 0).r, lo.x, lo.y, lo.z, lo.w, 0.0, 0.0, 0.0, 0.0);
    return shade_with(raw, b);
}

@fragment
fn fs_shade(raw: VsOut) -> Accum {
    let p = vec2<i32>(raw.clip.xy);
    let lo = textureLoad(low_tex, p, 0);
    let hi = textureLoad(high_tex, p, 0);
    let b = array<f32, 9>(textureLoad(b0_tex, p, 0).r, lo.x, lo.y, lo.z, lo.w, hi.x, hi.y, hi.z, hi.w);
    return shade_with(raw, b);
}

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
