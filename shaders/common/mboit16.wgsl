// mboit at 16 bits (precision "16"): the paper's storage section renormalizes and quantizes
// the moments as each fragment adds its own, inside a rasterizer-ordered view; here inside the
// pixel's critical section (common/pixel_lock.wgsl), as mlab does. A pixel keeps b0 as a float
// (32 bits: the coverage 1 - exp(-b0) stays exact) and MOMENTS normalized moments in [-1, 1] at
// 16 bits each (unorm, (t + 1) / 2), two a word: WORDS16 words. The power basis stores
// Chebyshev moments T_k(z) rather than powers (docs/methods.md, "mboit"): each lies in [-1, 1]
// for any measure on [-1, 1], and the powers are recovered from them with coefficients of
// absolute sum 1, so a rounding of the stored value moves no power moment by more than it.
// The trigonometric moments lie in [-1, 1] already. Included by shaders/mboit.wgsl, after
// `warp`, `optical_depth`, `basis` and `shade_with`.

@group(2) @binding(0) var<storage, read_write> moments16: array<atomic<u32>>;

const WORDS16: u32 = 1u + MOMENTS / 2u;

struct Incoming {
    od: f32,
    lo: vec4<f32>,
    hi: vec4<f32>,
}

//!include common/pixel_lock.wgsl

// T_1(z) .. T_8(z) by the recurrence T_(k+1) = 2 z T_k - T_(k-1).
fn chebyshev(z: f32) -> array<vec4<f32>, 2> {
    let t2 = 2.0 * z * z - 1.0;
    let t3 = 2.0 * z * t2 - z;
    let t4 = 2.0 * z * t3 - t2;
    let t5 = 2.0 * z * t4 - t3;
    let t6 = 2.0 * z * t5 - t4;
    let t7 = 2.0 * z * t6 - t5;
    return array<vec4<f32>, 2>(vec4<f32>(z, t2, t3, t4), vec4<f32>(t5, t6, t7, 2.0 * z * t7 - t6));
}

// The power moments m_1 .. m_8 of a measure of mass 1 from its Chebyshev moments t_1 .. t_8:
// z^k as a combination of T_0 .. T_k (T_0 = 1).
fn powers_of(lo: vec4<f32>, hi: vec4<f32>) -> array<vec4<f32>, 2> {
    let m1 = lo.x;
    let m2 = (1.0 + lo.y) / 2.0;
    let m3 = (3.0 * lo.x + lo.z) / 4.0;
    let m4 = (3.0 + 4.0 * lo.y + lo.w) / 8.0;
    let m5 = (10.0 * lo.x + 5.0 * lo.z + hi.x) / 16.0;
    let m6 = (10.0 + 15.0 * lo.y + 6.0 * lo.w + hi.y) / 32.0;
    let m7 = (35.0 * lo.x + 21.0 * lo.z + 7.0 * hi.x + hi.z) / 64.0;
    let m8 = (35.0 + 56.0 * lo.y + 28.0 * lo.w + 8.0 * hi.y + hi.w) / 128.0;
    return array<vec4<f32>, 2>(vec4<f32>(m1, m2, m3, m4), vec4<f32>(m5, m6, m7, m8));
}

fn load16(w: u32) -> vec2<f32> {
    return unpack2x16unorm(atomicLoad(&moments16[w])) * 2.0 - 1.0;
}

// The pixel's stored normalized moments (1 .. 4, 5 .. 8; zero past MOMENTS) and b0, which is
// 0 where no fragment has entered yet (`count`, from its lock word: the storage is not cleared
// between frames, the lock words are).
fn stored(px: u32, count: u32) -> array<vec4<f32>, 3> {
    let at = WORDS16 * px;
    var hi = vec4<f32>(0.0);
    if MOMENTS >= 6u {
        hi = vec4<f32>(load16(at + 3u), 0.0, 0.0);
    }
    if MOMENTS >= 8u {
        hi = vec4<f32>(hi.xy, load16(at + 4u));
    }
    let b0 = select(0.0, bitcast<f32>(atomicLoad(&moments16[at])), count > 0u);
    return array<vec4<f32>, 3>(vec4<f32>(load16(at + 1u), load16(at + 2u)), hi, vec4<f32>(b0));
}

fn store16(w: u32, t: vec2<f32>) {
    atomicStore(&moments16[w], pack2x16unorm(t * 0.5 + 0.5));
}

// Inside pixel px's critical section: the stored moments renormalized with the fragment's
// optical depth added, t' = (t b0 + od p) / (b0 + od), and stored again at 16 bits.
fn critical(px: u32, count: u32, f: Incoming) -> u32 {
    let at = WORDS16 * px;
    let s = stored(px, count);
    let total = s[2].x + f.od;
    let keep = s[2].x / total;
    let add = f.od / total;
    let lo = s[0] * keep + f.lo * add;
    let hi = s[1] * keep + f.hi * add;
    store16(at + 1u, lo.xy);
    store16(at + 2u, lo.zw);
    if MOMENTS >= 6u {
        store16(at + 3u, hi.xy);
    }
    if MOMENTS >= 8u {
        store16(at + 4u, hi.zw);
    }
    atomicStore(&moments16[at], bitcast<u32>(total));
    return count + 1u;
}

@fragment @early_depth_test(force)
fn fs_moments16(raw: VsOut) {
    let in = shaded_alpha(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    let z = warp(in.clip, in.view_w);
    var p: array<vec4<f32>, 2>;
    if MBOIT_BASIS == 0u {
        p = chebyshev(z);
    } else {
        let b = basis(z);
        p = array<vec4<f32>, 2>(vec4<f32>(b[0], b[1], b[2], b[3]), vec4<f32>(b[4], b[5], b[6], b[7]));
    }
    with_pixel_lock(pixel_index(in.clip), Incoming(optical_depth(in.color.a), p[0], p[1]));
}

@fragment
fn fs_shade16(raw: VsOut) -> Accum {
    let px = pixel_index(raw.clip);
    let s = stored(px, entries(px));
    let b0 = s[2].x;
    // Every fragment of the pixel gave up on its lock (counted): nothing to weigh.
    if b0 <= 0.0 {
        discard;
    }
    var m = array<vec4<f32>, 2>(s[0], s[1]);
    if MBOIT_BASIS == 0u {
        m = powers_of(s[0], s[1]);
    }
    return shade_with(raw, b0, m[0] * b0, m[1] * b0);
}
