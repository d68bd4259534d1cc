// Order-independent accumulation in fixed point: integer atomic adds are associative, so a
// sum does not depend on the order fragments arrive in, and frames are bit-identical.
// CORE_SCALE is injected (oit_core::consts); docs/methods.md bounds the rounding (the tail's
// words are common/tail_words.wgsl). The including shader declares `accum: array<atomic<u32>>` (storage) for `word`.

// A term of a 32-bit sum of values in [0, 1] whose total stays below 2^32 / CORE_SCALE.
fn fixed32(v: f32) -> u32 {
    return u32(round(clamp(v, 0.0, 1.0) * CORE_SCALE));
}

fn read_fixed32(v: u32) -> f32 {
    return f32(v) / CORE_SCALE;
}

fn word(i: u32) -> u32 {
    return atomicLoad(&accum[i]);
}
