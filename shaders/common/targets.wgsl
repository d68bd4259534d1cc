// Frame targets (group 1): the opaque depth and the opaque color with coverage.
// base.rgb is the opaque surface or the background, base.a is 1 where an opaque surface was hit.
@group(1) @binding(0) var opaque_depth: texture_depth_2d;
@group(1) @binding(1) var base_color: texture_2d<f32>;

// Storage-writing passes test the opaque depth themselves: a fragment shader with side
// effects may run its depth test late, after its atomics already happened. They also ask
// for the test before the shader (`@early_depth_test(force)`), which an adapter with
// SHADER_EARLY_DEPTH_TEST must honour: there (EARLY_DEPTH = 1, set per device by
// oit_core::shader::module) a fragment behind the opaque scene never reaches the shader, and
// the test here compiles to nothing.
fn behind_opaque(pos: vec4<f32>) -> bool {
    if EARLY_DEPTH != 0u {
        return false;
    }
    return pos.z >= textureLoad(opaque_depth, vec2<i32>(pos.xy), 0);
}

fn base_at(pos: vec4<f32>) -> vec4<f32> {
    return textureLoad(base_color, vec2<i32>(pos.xy), 0);
}

// One sample a pixel (coverage-mask frames use common/targets_samples.wgsl instead).
const PIXEL_SAMPLES: u32 = 1u;

fn base_at_sample(pos: vec4<f32>, s: u32) -> vec4<f32> {
    return base_at(pos);
}
