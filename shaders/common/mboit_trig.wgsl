// mboit's trigonometric moments (Münstermann et al. 2018, Sec. 3.6): the transmittance in front
// of a fragment's angle from TRIG_N = MOMENTS / 2 complex moments. Complex numbers are vec2
// (re, im); C4 holds four of them a lane each (four real parts, four imaginary parts), so that
// the kernel polynomial's roots and their weights are found at once. Straight-line code: a
// loop indexing a local array runs lane by lane on a software rasterizer. Included by
// shaders/mboit.wgsl, which defines MOMENTS, MBOIT_BIAS, MBOIT_OVERESTIMATION, MBOIT_WRAP.

const TRIG_N: u32 = MOMENTS / 2u;

fn cmul(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

fn conj(a: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x, -a.y);
}

struct C4 {
    re: vec4<f32>,
    im: vec4<f32>,
}

fn c4(a: vec2<f32>) -> C4 {
    return C4(vec4<f32>(a.x), vec4<f32>(a.y));
}

fn c4mul(a: C4, b: C4) -> C4 {
    return C4(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re);
}

fn c4sub(a: C4, b: C4) -> C4 {
    return C4(a.re - b.re, a.im - b.im);
}

fn c4add(a: C4, b: C4) -> C4 {
    return C4(a.re + b.re, a.im + b.im);
}

fn c4div(a: C4, b: C4) -> C4 {
    let n = b.re * b.re + b.im * b.im;
    return C4((a.re * b.re + a.im * b.im) / n, (a.im * b.re - a.re * b.im) / n);
}

fn c4norm(a: C4) -> vec4<f32> {
    return a.re * a.re + a.im * a.im;
}

// The Hermitian Toeplitz matrix T[k][l] = m[k - l] (m[-j] = conj(m[j]), m0 = 1) as L D L^H:
// L's first column is m1 .. m4 itself (d0 = 1); l21, l31, l41 column 1, l32, l42 column 2, l43
// column 3; d = (d1 .. d4). L[i][j] = (m[i - j] - sum over k < j of L[i][k] conj(L[j][k]) d[k]) / d[j].
struct Toeplitz {
    m1: vec2<f32>,
    m2: vec2<f32>,
    m3: vec2<f32>,
    m4: vec2<f32>,
    l21: vec2<f32>,
    l31: vec2<f32>,
    l41: vec2<f32>,
    l32: vec2<f32>,
    l42: vec2<f32>,
    l43: vec2<f32>,
    d: vec4<f32>,
}

fn toeplitz(m1: vec2<f32>, m2: vec2<f32>, m3: vec2<f32>, m4: vec2<f32>) -> Toeplitz {
    var t: Toeplitz;
    t.m1 = m1;
    t.m2 = m2;
    t.m3 = m3;
    t.m4 = m4;
    t.d = vec4<f32>(1.0);
    t.d.x = 1.0 - dot(m1, m1);
    t.l21 = (m1 - cmul(m2, conj(m1))) / t.d.x;
    t.d.y = 1.0 - dot(m2, m2) - dot(t.l21, t.l21) * t.d.x;
    if TRIG_N >= 3u {
        t.l31 = (m2 - cmul(m3, conj(m1))) / t.d.x;
        t.l32 = (m1 - cmul(m3, conj(m2)) - cmul(t.l31, conj(t.l21)) * t.d.x) / t.d.y;
        t.d.z = 1.0 - dot(m3, m3) - dot(t.l31, t.l31) * t.d.x - dot(t.l32, t.l32) * t.d.y;
    }
    if TRIG_N >= 4u {
        t.l41 = (m3 - cmul(m4, conj(m1))) / t.d.x;
        t.l42 = (m2 - cmul(m4, conj(m2)) - cmul(t.l41, conj(t.l21)) * t.d.x) / t.d.y;
        t.l43 = (m1 - cmul(m4, conj(m3)) - cmul(t.l41, conj(t.l31)) * t.d.x - cmul(t.l42, conj(t.l32)) * t.d.y) / t.d.z;
        t.d.w = 1.0 - dot(m4, m4) - dot(t.l41, t.l41) * t.d.x - dot(t.l42, t.l42) * t.d.y - dot(t.l43, t.l43) * t.d.z;
    }
    return t;
}

// L^-1 (1, w, .., w^TRIG_N) at four points w of the unit circle: y1 .. y4 (y0 = 1).
struct TrigForward {
    y1: C4,
    y2: C4,
    y3: C4,
    y4: C4,
}

fn trig_forward(t: Toeplitz, w: C4) -> TrigForward {
    var f: TrigForward;
    let w2 = c4mul(w, w);
    f.y1 = c4sub(w, c4(t.m1));
    f.y2 = c4sub(c4sub(w2, c4(t.m2)), c4mul(c4(t.l21), f.y1));
    if TRIG_N >= 3u {
        f.y3 = c4sub(c4sub(c4sub(c4mul(w2, w), c4(t.m3)), c4mul(c4(t.l31), f.y1)), c4mul(c4(t.l32), f.y2));
    }
    if TRIG_N >= 4u {
        let rest = c4add(c4add(c4mul(c4(t.l41), f.y1), c4mul(c4(t.l42), f.y2)), c4mul(c4(t.l43), f.y3));
        f.y4 = c4sub(c4sub(c4mul(w2, w2), c4(t.m4)), rest);
    }
    return f;
}

// The Christoffel function 1 / (e^H T^-1 e) = 1 / (1 + sum of |y_k|^2 / d_k): the weight of a
// node of the canonical representation there.
fn trig_christoffel(t: Toeplitz, f: TrigForward) -> vec4<f32> {
    var s = 1.0 + c4norm(f.y1) / t.d.x + c4norm(f.y2) / t.d.y;
    if TRIG_N >= 3u {
        s += c4norm(f.y3) / t.d.z;
    }
    if TRIG_N >= 4u {
        s += c4norm(f.y4) / t.d.w;
    }
    return 1.0 / s;
}

fn lane0(a: C4) -> vec2<f32> {
    return vec2<f32>(a.re.x, a.im.x);
}

// The roots of the monic z^TRIG_N + a3 z^3 + .. + a0 (the terms past its degree unused), on the
// unit circle: Aberth's simultaneous iteration, a root a lane, from points spread on the
// circle; `used` marks the TRIG_N lanes that hold one.
fn circle_roots(a0: vec2<f32>, a1: vec2<f32>, a2: vec2<f32>, a3: vec2<f32>, used: vec4<f32>) -> C4 {
    let spread = vec4<f32>(0.4) + 6.28318531 / f32(TRIG_N) * vec4<f32>(0.0, 1.0, 2.0, 3.0);
    var z = C4(select(vec4<f32>(8.0), cos(spread), used > vec4<f32>(0.0)), sin(spread) * used);
    for (var it = 0u; it < 48u; it++) {
        var p = c4(vec2<f32>(1.0, 0.0));
        var dp = c4(vec2<f32>(0.0));
        if TRIG_N >= 4u {
            dp = c4add(c4mul(dp, z), p);
            p = c4add(c4mul(p, z), c4(a3));
        }
        if TRIG_N >= 3u {
            dp = c4add(c4mul(dp, z), p);
            p = c4add(c4mul(p, z), c4(a2));
        }
        dp = c4add(c4mul(dp, z), p);
        p = c4add(c4mul(p, z), c4(a1));
        dp = c4add(c4mul(dp, z), p);
        p = c4add(c4mul(p, z), c4(a0));
        let ratio = c4div(p, dp);
        // Sum over the other roots of 1 / (z_i - z_j), the lanes rotated by one, two, three.
        let d1 = c4sub(z, C4(z.re.yzwx, z.im.yzwx));
        let d2 = c4sub(z, C4(z.re.zwxy, z.im.zwxy));
        let d3 = c4sub(z, C4(z.re.wxyz, z.im.wxyz));
        let n1 = used.yzwx / c4norm(d1);
        let n2 = used.zwxy / c4norm(d2);
        let n3 = used.wxyz / c4norm(d3);
        let pull = C4(d1.re * n1 + d2.re * n2 + d3.re * n3, -(d1.im * n1 + d2.im * n2 + d3.im * n3));
        let one = c4(vec2<f32>(1.0, 0.0));
        let step = c4div(ratio, c4sub(one, c4mul(ratio, pull)));
        z = c4sub(z, C4(step.re * used, step.im * used));
        // Converged once the step just taken is at most 10^-4: the iteration converges
        // cubically, so what is left is far below float32's resolution on the unit circle
        // (a bound of 10^-7 on the step itself, as before, can repeat there and ran all 48).
        if all(c4norm(step) * used <= vec4<f32>(1e-8)) {
            break;
        }
    }
    return z;
}

// The transmittance's masses in front of angle phi from b0 and the real and imaginary parts of
// the moments b1 .. b4 in `lo` and `hi`: the nodes of the canonical representation through phi
// are the kernel polynomial's roots on the unit circle, each weighing its Christoffel number,
// counted in front of phi (1), behind it (0), or in the wrapping zone rising from 0 at its far
// end to 1 at its near one; the estimate, and the bounds counting the zone's nodes out, then in.
fn trig_transmittance(b0: f32, lo: vec4<f32>, hi: vec4<f32>, phi: f32) -> vec3<f32> {
    let m = (1.0 - MBOIT_BIAS) / b0;
    let t = toeplitz(lo.xy * m, lo.zw * m, hi.xy * m, hi.zw * m);
    let e = vec2<f32>(cos(phi), sin(phi));
    let at_phi = trig_forward(t, c4(e));
    let own = trig_christoffel(t, at_phi).x;
    // q = T^-1 e(phi): g = D^-1 y, then q_i = g_i - sum over k > i of conj(L[k][i]) q_k.
    let g1 = lane0(at_phi.y1) / t.d.x;
    let g2 = lane0(at_phi.y2) / t.d.y;
    let g3 = lane0(at_phi.y3) / t.d.z;
    let g4 = lane0(at_phi.y4) / t.d.w;
    var q4 = vec2<f32>(0.0);
    var q3 = vec2<f32>(0.0);
    var q2 = g2;
    if TRIG_N >= 4u {
        q4 = g4;
        q3 = g3 - cmul(conj(t.l43), q4);
    } else if TRIG_N >= 3u {
        q3 = g3;
    }
    if TRIG_N >= 3u {
        q2 = g2 - cmul(conj(t.l32), q3) - cmul(conj(t.l42), q4);
    }
    let q1 = g1 - cmul(conj(t.l21), q2) - cmul(conj(t.l31), q3) - cmul(conj(t.l41), q4);
    let q0 = vec2<f32>(1.0, 0.0) - cmul(conj(t.m1), q1) - cmul(conj(t.m2), q2) - cmul(conj(t.m3), q3) - cmul(conj(t.m4), q4);
    // The kernel polynomial sum of conj(q_k) z^k, made monic.
    var lead = q2;
    if TRIG_N == 3u {
        lead = q3;
    } else if TRIG_N == 4u {
        lead = q4;
    }
    let c = lead / dot(lead, lead); // 1 / conj(lead)
    let used = vec4<f32>(1.0, 1.0, select(0.0, 1.0, TRIG_N >= 3u), select(0.0, 1.0, TRIG_N >= 4u));
    let z = circle_roots(cmul(conj(q0), c), cmul(conj(q1), c), cmul(conj(q2), c), cmul(conj(q3), c), used);
    let r = sqrt(c4norm(z));
    let w = trig_christoffel(t, trig_forward(t, C4(z.re / r, z.im / r))) * used;
    var theta = atan2(z.im, z.re);
    theta = select(theta, theta + 6.28318531, theta < vec4<f32>(0.0));
    let zone = 6.28318531 - MBOIT_WRAP;
    let in_zone = theta > vec4<f32>(zone);
    let front = dot(w, select(vec4<f32>(0.0), vec4<f32>(1.0), theta < vec4<f32>(phi) & !in_zone));
    let zone_part = dot(w, select(vec4<f32>(0.0), (theta - zone) / MBOIT_WRAP, in_zone));
    let zone_mass = dot(w, select(vec4<f32>(0.0), vec4<f32>(1.0), in_zone));
    return vec3<f32>(front + zone_part + MBOIT_OVERESTIMATION * own, front, front + own + zone_mass);
}
