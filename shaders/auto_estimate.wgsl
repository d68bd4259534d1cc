// auto's estimate pass: per pixel, the optical depth of its transparent fragments and how far
// their alphas are from hybrid's 8-bit keys, so that auto can predict hybrid's error bound for
// every k before rendering (docs/methods.md, "auto"). Five words a pixel: the optical depth,
// its square (for the spread of the nearest fragments' share) and the quantization error in
// fixed point, and the smallest and largest color channel of the fragments and the base
// behind them (f32 bits; the smallest inverted, 0 = none), whose range scales hybrid's tail term.
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/alpha8.wgsl

@group(2) @binding(0) var<storage, read_write> sums: array<atomic<u32>>;

// Optical depth -ln(1 - alpha) per fragment, capped (alpha = 1 gives the cap), at 2^-12 per
// unit: 65,536 capped fragments fit in a word; its square at 2^-10 (16,384 capped fragments).
// Alpha quantization at 2^-24 per unit, rounded up.
// TAU_CAP and the scales TAU_SCALE, TAU2_SCALE, QUANT_SCALE come from crates/oit-core/src/consts.rs.

@fragment @early_depth_test(force)
fn fs_estimate(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    let a = min(in.color.a, 1.0);
    let px = pixel_index(in.clip);
    let tau = select(min(-log(1.0 - a), TAU_CAP), TAU_CAP, a >= 1.0);
    let at = 5u * px;
    atomicAdd(&sums[at], u32(round(tau * TAU_SCALE)));
    atomicAdd(&sums[at + 1u], u32(round(tau * tau * TAU2_SCALE)));
    let q = f32(alpha_8bit(a)) / 255.0;
    atomicAdd(&sums[at + 2u], u32(ceil(abs(a - q) * QUANT_SCALE)));
    let c = clamp(in.color.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    let b = base_at(in.clip).rgb;
    atomicMax(&sums[at + 3u], ~bitcast<u32>(min(min(c.r, min(c.g, c.b)), min(b.r, min(b.g, b.b)))));
    atomicMax(&sums[at + 4u], bitcast<u32>(max(max(c.r, max(c.g, c.b)), max(b.r, max(b.g, b.b)))));
}
