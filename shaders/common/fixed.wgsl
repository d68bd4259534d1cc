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
