//! The pipelines of the list methods (lists.rs), a table per shader: capture into the node
//! pool, the sorted resolve's sweeps (common/sweep.wgsl) where the method keeps sweep state,
//! the full-screen resolve, and the pass before capture that binding 7 may need.

use super::lists::POOL_BINDINGS;
use crate::cache::{Layout, PipelineSpec};

/// The pool's group: heads, allocator, the `POOL_BINDINGS` pool bindings, sweep state, binding
/// 7 by the name the method's shader gives it ("_" where no shader of the method reads it),
/// and the per-pixel counts a capture that counts its own fragments keeps (binding 8).
macro_rules! pool_layout {
    ($aux:literal) => {
        crate::cache::Layout::Storage(&["heads", "alloc", "pool0", "pool1", "pool2", "pool3", "state", $aux, "pixel_counts"])
    };
}
pub(crate) use pool_layout;

/// The pool's group of a method that keeps nothing at binding 7.
pub(crate) const POOL_LAYOUT: Layout = pool_layout!("_");
const _: () = assert!(matches!(POOL_LAYOUT, Layout::Storage(n) if n.len() as u64 == 5 + POOL_BINDINGS));
/// The groups of a list method's passes.
pub(crate) const FRAME: &[Layout] = &[Layout::Scene, Layout::Targets, POOL_LAYOUT];
/// The groups of its passes in a coverage-mask frame.
pub(crate) const SAMPLES: &[Layout] = &[Layout::Scene, Layout::SampleTargets, POOL_LAYOUT];

/// The sorted resolve's dispatches, in the order they run: the pixel lists and their
/// workgroups, the first dispatch, then the deeper pixels' runs, merges and composite.
pub(crate) const SWEEPS: [&str; 6] = ["cs_active", "cs_groups", "cs_sort", "cs_runs", "cs_merge", "cs_composite"];

/// A shader that captures and resolves in one full-screen pass.
pub(crate) const fn single(shader: &'static str, groups: &'static [Layout]) -> [PipelineSpec; 2] {
    [PipelineSpec::geometry(shader, "fs_capture", groups), PipelineSpec::fullscreen(shader, "fs_resolve", groups)]
}

/// A shader whose resolve sweeps its sorted lists before the full-screen pass.
pub(crate) const fn swept(shader: &'static str, groups: &'static [Layout]) -> [PipelineSpec; 8] {
    let [capture, resolve] = single(shader, groups);
    let [a, b, c, d, e, f] = SWEEPS;
    let g = groups;
    [
        capture,
        PipelineSpec::compute(shader, a, g),
        PipelineSpec::compute(shader, b, g),
        PipelineSpec::compute(shader, c, g),
        PipelineSpec::compute(shader, d, g),
        PipelineSpec::compute(shader, e, g),
        PipelineSpec::compute(shader, f, g),
        resolve,
    ]
}

/// A swept shader with a pass before capture (`first`: the allocation or the count).
pub(crate) const fn swept_after(first: PipelineSpec) -> [PipelineSpec; 9] {
    let [a, b, c, d, e, f, g, h] = swept(first.shader, first.groups);
    [first, a, b, c, d, e, f, g, h]
}
