// The exact resolve shared by the fragment-storing methods (abuffer, sbuffer, pall,
// compact_abuffer): each pixel's list is sorted once, in place, in O(n log n), then
// composited front to back; a full-screen pass adds the opaque scene or background.
//   - A pixel of at most RUN fragments (most pixels) loads them into a local array, sorts it
//     (insertion within blocks of BLOCK, then local merges) and composites it: one walk of
//     its list.
//   - A deeper pixel sorts its list in runs of RUN (each run sorted locally and relinked),
//     then merges the runs bottom-up by relinking the nodes' `next` fields (no scratch
//     memory), then walks the sorted list to composite it.
//   - Each phase runs over a list of the pixels with work in it (cs_active, cs_sort), by
//     indirect dispatch.
// Two strategies, chosen from the adapter's profile (oit_core::method::resolve_plan::
// ResolveStrategy): where a loop limiter ends long invocations (llvmpipe: 65,535 iterations in
// all, every `switch` counted as one, since SPIR-V to NIR makes a switch a loop; each pool access
// is one, common/nodes.wgsl), BUDGETED: a deep pixel's work is a state machine that stops after
// STEP_BUDGET steps and resumes in the next dispatch, so any depth completes, and the host
// dispatches enough sweeps for the deepest pixel (resolve_plan::resolve_steps mirrors the counts
// below). Elsewhere cs_sort takes each deep pixel through its phases in one go. Where the work
// pauses does not change the result: the sorted order is unique and the composite runs in that
// order.
// The including shader defines
//   fn list_head(px: u32) -> u32             the link (node index + 1) of the first node, 0: none
//   fn walk(link: u32, px: u32) -> Walked    a node's fragment and link, from one load
//   fn frag_mask(f: Frag) -> u32             the pixel's samples it covers (bit s: sample s)
//   fn frag_shaded(f: Frag, px: u32) -> Frag the fragment as composited (compact_abuffer shades
//                                            it here, once; the others as stored:
//                                            common/stored_color.wgsl)
//   fn tie_key(f: Frag) -> u32               what orders fragments of equal depth and color
//                                            before their links (0: nothing)
// and declares the `state` storage binding; common/nodes.wgsl gives load_next/store_next.
// docs/methods.md ("abuffer"). The pieces:
//   common/sweep_composite.wgsl  front-to-back compositing per sample, and fs_resolve
//   common/sweep_sort.wgsl       a run's local sort (keys, insertion within blocks, local merges)
//   common/sweep_merge.wgsl      a deep pixel's state machine: runs relinked, then merged
//   common/sweep_passes.wgsl     the dispatches over the pixel lists, and the budget
//!include common/sweep_composite.wgsl
//!include common/sweep_sort.wgsl
//!include common/sweep_merge.wgsl
//!include common/sweep_passes.wgsl

// Per-pixel state (STATE_WORDS words: SWEEP_PIXEL_WORDS, then SWEEP_SAMPLE_WORDS per sample of
// the pixel, PIXEL_SAMPLES from the targets include: 1, or the coverage-mask sample count) its
// accumulated color and transmittance. oit_core::consts holds both numbers.
const STATE_WORDS: u32 = SWEEP_PIXEL_WORDS + SWEEP_SAMPLE_WORDS * PIXEL_SAMPLES;
const S_PHASE: u32 = 0u; // phase | sub-phase << 4 | MULTI (this pass wrote more than one run)
const S_WIDTH: u32 = 1u; // run length of the merge pass
const S_SRC: u32 = 2u;   // next node this pass has not reached; the composite's cursor
const S_TAIL: u32 = 3u;  // last node of this pass's output (0: none yet)
const S_A: u32 = 4u;     // the pair being merged: its first run's next node and count left,
const S_NA: u32 = 5u;
const S_B: u32 = 6u;     // the second run's,
const S_NB: u32 = 7u;
const S_REST: u32 = 8u;  // and the node after the pair
const SAMPLE_STATE: u32 = SWEEP_PIXEL_WORDS;

const FRESH: u32 = 0u; // the cleared state: no pass has reached the pixel (fs_resolve: the base)
const RUNS: u32 = 1u;
const MERGE: u32 = 2u;
const COMPOSITE: u32 = 3u;
const DONE: u32 = 4u;
const SPLIT_A: u32 = 0u;
const SPLIT_B: u32 = 1u;
const MERGING: u32 = 2u;
const MULTI: u32 = 0x100u;
// Steps per node loaded into a run, per node relinked, per merge step and per fragment
// composited from the list: the SWEEP_*_STEPS constants (injected from the adapter's profile,
// oit_core::context::SweepSteps, where they are explained; oit_core::method::resolve_plan::
// StepCosts plans the dispatches from the same ones), plus FRAG_STEPS
// (injected), what turning a node into a fragment adds, and SHADE_STEPS (injected), what
// frag_shaded adds to a composited fragment (compact_abuffer shades it there).
const LOAD_STEPS: u32 = SWEEP_LOAD_STEPS + FRAG_STEPS;
const LINK_STEPS: u32 = SWEEP_LINK_STEPS;
const MERGE_STEPS: u32 = SWEEP_MERGE_STEPS + 2u * FRAG_STEPS;
const COMPOSITE_STEPS: u32 = SWEEP_COMPOSITE_STEPS + PIXEL_SAMPLES + FRAG_STEPS + SHADE_STEPS;

// `id`: the node's link, or where runs are KEYED anything unique in the pixel the includer
// reads back (compact_abuffer: the triangle).
struct Frag {
    depth: f32,
    color: vec4<f32>,
    id: u32,
}

struct Walked {
    frag: Frag,
    next: u32,
}

// Strict total order: depth, then color, then the includer's tie key, then node link.
// Fragments equal in all but their links are interchangeable (the same composited color), so
// the composite does not depend on submission order.
fn frag_less(a: Frag, b: Frag) -> bool {
    if a.depth != b.depth { return a.depth < b.depth; }
    if a.color.r != b.color.r { return a.color.r < b.color.r; }
    if a.color.g != b.color.g { return a.color.g < b.color.g; }
    if a.color.b != b.color.b { return a.color.b < b.color.b; }
    if a.color.a != b.color.a { return a.color.a < b.color.a; }
    let ka = tie_key(a);
    let kb = tie_key(b);
    if ka != kb { return ka < kb; }
    return a.id < b.id;
}

