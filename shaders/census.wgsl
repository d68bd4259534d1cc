// Counts the transparent fragments of each pixel that pass the opaque depth test.
// Untimed: it feeds frame.stats (fragments, depth complexity) and the methods that plan from
// the counts. fs_count adds 1 a fragment to an R32Float target by additive blending (exact
// below 2^24 fragments a pixel; no side effects, so the depth test runs before the shader and
// no atomic is taken); fs_census, for adapters that cannot blend float32, adds to a storage
// buffer with an atomic.
//!include common/scene.wgsl
//!include common/targets.wgsl

//!include common/census_counts.wgsl

@fragment @early_depth_test(force)
fn fs_census(in: VsOut) {
    if behind_opaque(in.clip) {
        return;
    }
    atomicAdd(&counts[pixel_index(in.clip)], 1u);
}

@fragment
fn fs_count(in: VsOut) -> @location(0) vec4<f32> {
    return vec4<f32>(1.0, 0.0, 0.0, 0.0);
}
