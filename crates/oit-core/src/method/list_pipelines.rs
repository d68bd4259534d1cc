//! The pipelines of the list methods (lists.rs), a table per shader: capture into the node
//! pool, the sorted resolve's sweeps (common/sweep.wgsl) where the method keeps sweep state,
//! the full-screen resolve, and the pass before capture that binding 7 may need.

use super::pool::POOL_LAYOUT;
use crate::cache::{Layout, PipelineSpec};

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
