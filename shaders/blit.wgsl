// Copies a texture into a render target of another format, pixel for pixel: a caller's
// opaque picture into the base color, and a frame's output into a caller's texture
// (oit_core::renderer::Target; an sRGB target encodes on write, as fixed-function output does).
//!include common/fullscreen.wgsl

@group(0) @binding(0) var source: texture_2d<f32>;

@fragment
fn fs_blit(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(source, vec2<i32>(pos.xy), 0);
}

// The same, sRGB-encoded in the shader (IEC 61966-2-1) for a target whose format does not
// encode: an egui native texture, which egui samples as encoded bytes. Alpha is copied.
@fragment
fn fs_blit_srgb(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let c = textureLoad(source, vec2<i32>(pos.xy), 0);
    let l = clamp(c.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    let encoded = select(1.055 * pow(l, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * l, l <= vec3<f32>(0.0031308));
    return vec4<f32>(encoded, c.a);
}
