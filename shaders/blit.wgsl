// Copies a texture into a render target of another format, pixel for pixel: a caller's
// opaque picture into the base color, and a frame's output into a caller's texture
// (oit_core::renderer::Target; an sRGB target encodes on write, as fixed-function output does).
//!include common/fullscreen.wgsl

@group(0) @binding(0) var source: texture_2d<f32>;

@fragment
fn fs_blit(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(source, vec2<i32>(pos.xy), 0);
}
