// Frame targets of a coverage-mask frame (group 1), in place of common/targets.wgsl: for each
// sample s of the pixel, the opaque depth and base color that the opaque pass rendered with the
// camera moved onto sample position s (layer s of 2D arrays; oit_core::antialias). Transparent
// geometry is rasterized multisampled at the standard positions; a fragment keeps the samples it
// covers in front of their own opaque depth.
@group(1) @binding(0) var opaque_depth: texture_depth_2d_array;
@group(1) @binding(1) var base_color: texture_2d_array<f32>;

// The standard 4-sample pattern (oit_core::antialias::sample_offsets(4)), pixels from the
// center, y down, in the order of the rasterizer's coverage mask bits.
const PIXEL_SAMPLES: u32 = 4u;
const SAMPLE_OFFSETS = array<vec2<f32>, 4>(
    vec2<f32>(-0.125, -0.375), vec2<f32>(0.375, -0.125), vec2<f32>(-0.375, 0.125), vec2<f32>(0.125, 0.375),
);

fn base_at_sample(pos: vec4<f32>, s: u32) -> vec4<f32> {
    return textureLoad(base_color, vec2<i32>(pos.xy), i32(s), 0);
}

fn base_at(pos: vec4<f32>) -> vec4<f32> {
    return base_at_sample(pos, 0u);
}

// The covered samples (`coverage`: the rasterizer's mask) whose own depth, the fragment's plane
// (depth at the center plus `slope`, its screen derivatives, times the offset) is in front of
// that sample's opaque depth.
fn visible_samples(pos: vec4<f32>, slope: vec2<f32>, coverage: u32) -> u32 {
    var mask = 0u;
    for (var s = 0u; s < PIXEL_SAMPLES; s++) {
        if (coverage & (1u << s)) != 0u {
            let z = pos.z + dot(slope, SAMPLE_OFFSETS[s]);
            if z < textureLoad(opaque_depth, vec2<i32>(pos.xy), i32(s), 0) {
                mask |= 1u << s;
            }
        }
    }
    return mask;
}
