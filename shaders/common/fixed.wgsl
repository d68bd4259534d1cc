// Order-independent accumulation in fixed point: integer atomic adds are associative, so a
// sum does not depend on the order fragments arrive in, and frames are bit-identical.
// CORE_SCALE and TAIL_SCALE are injected (oit_core::method::hybrid); docs/methods.md bounds
// the rounding. The including shader declares `accum: array<atomic<u32>>` (storage).

// A 32-bit sum of values in [0, 1] whose total stays below 2^32 / CORE_SCALE.
fn add_fixed32(i: u32, v: f32) {
    atomicAdd(&accum[i], u32(round(clamp(v, 0.0, 1.0) * CORE_SCALE)));
}

fn read_fixed32(v: u32) -> f32 {
    return f32(v) / CORE_SCALE;
}

// A 64-bit sum kept as words (i, i + 1) = (lo, hi): the carry is taken from the value
// atomicAdd returns, so concurrent adds never lose one.
fn add_fixed64(i: u32, v: f32) {
    let q = u32(round(clamp(v, 0.0, 1.0) * TAIL_SCALE));
    let old = atomicAdd(&accum[i], q);
    if old > 0xffffffffu - q {
        atomicAdd(&accum[i + 1u], 1u);
    }
}

fn read_fixed64(lo: u32, hi: u32) -> f32 {
    return (f32(hi) * 4294967296.0 + f32(lo)) / TAIL_SCALE;
}

fn word(i: u32) -> u32 {
    return atomicLoad(&accum[i]);
}

// Adds a fragment to the tail sums at words sums..sums+7 (eqs. 5-6): C*alpha for r, g, b and
// alpha, each a 64-bit fixed-point pair.
fn add_tail_sums(sums: u32, rgb: vec3<f32>, a: f32) {
    add_fixed64(sums, rgb.r * a);
    add_fixed64(sums + 2u, rgb.g * a);
    add_fixed64(sums + 4u, rgb.b * a);
    add_fixed64(sums + 6u, a);
}

// The tail of hybrid transparency (Maule et al. 2013, eqs. 7-10) from its fixed-point sums:
// words sums..sums+7 hold (lo, hi) pairs of sum C*alpha for r, g, b and of sum alpha, over
// `count` fragments. Returns the tail's premultiplied color C_tail * alpha_tail and its
// transmittance T_tail = (1 - alpha_avg)^count.
struct Tail {
    color: vec3<f32>,
    trans: f32,
}

fn resolve_tail(sums: u32, count: u32) -> Tail {
    if count == 0u {
        return Tail(vec3<f32>(0.0), 1.0);
    }
    let sum_c = vec3<f32>(
        read_fixed64(word(sums), word(sums + 1u)),
        read_fixed64(word(sums + 2u), word(sums + 3u)),
        read_fixed64(word(sums + 4u), word(sums + 5u)),
    );
    return tail_from_sums(sum_c, read_fixed64(word(sums + 6u), word(sums + 7u)), count);
}

// Eqs. 7-10 from the sums of C * alpha (sum_c) and alpha (sum_a) over count fragments.
fn tail_from_sums(sum_c: vec3<f32>, sum_a: f32, count: u32) -> Tail {
    var tail = Tail(vec3<f32>(0.0), 1.0);
    if count == 0u || sum_a <= 0.0 {
        return tail;
    }
    let n = f32(count);
    let a_avg = min(sum_a / n, 1.0);                            // eq. 8
    tail.trans = select(pow(1.0 - a_avg, n), 0.0, a_avg >= 1.0); // eq. 9
    tail.color = (sum_c / sum_a) * (1.0 - tail.trans);           // eqs. 7 and 10
    return tail;
}
