// Plain over-blending in draw order (unsorted, sorted): the fixed-function blend does
// C = a * c + (1 - a) * C and A = a + (1 - a) * A.
//!include common/scene.wgsl

@fragment
fn fs_blend(in: VsOut) -> @location(0) vec4<f32> {
    return in.color;
}
