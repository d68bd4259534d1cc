// Fixed-function blend methods. Over (unsorted, sorted): C = a c + (1 - a) C; additive:
// C = a c + C; filter (colored transmission, RTR 5.5): C = C (1 - a (1 - c)). Coverage
// always blends as A = a + (1 - a) A.
//!include common/scene.wgsl

@fragment
fn fs_blend(raw: VsOut) -> @location(0) vec4<f32> {
    let in = shaded(raw);
    return in.color;
}

// Colored transmission: the fraction of each channel the surface lets through.
@fragment
fn fs_filter(raw: VsOut) -> @location(0) vec4<f32> {
    let in = shaded(raw);
    return vec4<f32>(1.0 - in.color.a * (1.0 - in.color.rgb), in.color.a);
}
