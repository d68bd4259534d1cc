// Counts the transparent fragments of each pixel that pass the opaque depth test.
// Untimed: it feeds frame.stats (fragments, depth complexity), not the method.
//!include common/scene.wgsl
//!include common/targets.wgsl

@group(2) @binding(0) var<storage, read_write> counts: array<atomic<u32>>;

@fragment @early_depth_test(force)
fn fs_census(in: VsOut) {
    if behind_opaque(in.clip) {
        return;
    }
    atomicAdd(&counts[pixel_index(in.clip)], 1u);
}
