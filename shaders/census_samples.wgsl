// The census of a coverage-mask frame: a pixel's fragment count is the number of triangles
// with a visible sample in it (each becomes one node of abuffer_coverage.wgsl).
//!include common/scene.wgsl
//!include common/targets_samples.wgsl

//!include common/census_counts.wgsl

@fragment
fn fs_census(in: VsOut, @builtin(sample_mask) coverage: u32) {
    let slope = vec2<f32>(dpdx(in.clip.z), dpdy(in.clip.z));
    if visible_samples(in.clip, slope, coverage) == 0u {
        return;
    }
    atomicAdd(&counts[pixel_index(in.clip)], 1u);
}
