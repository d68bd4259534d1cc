// Opaque geometry: straight color, coverage 1, writes depth.
//!include common/scene.wgsl

@fragment
fn fs_opaque(raw: VsOut) -> @location(0) vec4<f32> {
    let in = shaded(raw);
    return vec4<f32>(in.color.rgb, 1.0);
}
