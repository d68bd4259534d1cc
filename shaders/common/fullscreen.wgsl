// One triangle that covers the screen; resolve passes run one fragment per pixel.
@vertex
fn vs_fullscreen(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

// Output of the resolves that also write the per-pixel error bound
// (oit_core::pipeline::fullscreen_with_bound).
struct Final {
    @location(0) color: vec4<f32>,
    // Per-pixel bound of |this image - the exact composite|, per channel (docs/methods.md).
    @location(1) bound: f32,
}
