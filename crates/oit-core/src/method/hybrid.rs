//! `hybrid` (Maule et al. 2013, Algorithm 1) and `ktab`, its core alone with the tail
//! discarded: the k-TAB engine (ktab.rs) with the `k` parameter.

use super::frame::{FrameCtx, Method, Outcome};
use super::info::{ErrorBound, Memory, MethodInfo, Order, FRAMES};
use super::ktab::{compact_memory_bytes, memory_bytes, KTab, Slots, TailSums};
use super::params::{ChoiceParam, IntParam};
use crate::error::Result;

const K: IntParam = IntParam::new("k", (1, 32, 8), "core size: fragments per pixel kept exactly, sorted (k-TAB slots)").compiled_as("K");

const TAIL: ChoiceParam<TailSums> = ChoiceParam::new(
    "tail",
    &["exact", "blend", "compact"],
    &[TailSums::Exact, TailSums::Blend, TailSums::Compact],
    0,
    "how the second pass sums core and tail: 'exact' by fixed-point atomics (bit-identical under any order), \
          'blend' by float blending as in the paper (faster; order changes the rounding), 'compact' by blending into \
          the output and one RGBA16F target at Eq. 12's 2k + 2 words a pixel, the tail count from the census \
          (docs/methods.md)",
);

pub const HYBRID: MethodInfo = MethodInfo {
    name: "hybrid",
    summary: "hybrid transparency: the k nearest fragments exactly (k-TAB), the rest by weighted average",
    exact: false,
    bounded_memory: true,
    passes: &["store k-TAB (geometry)", "visibility (compute)", "shade core and tail (geometry)", "final composite (full screen)"],
    params: &[K.0, TAIL.info],
    features: wgpu::Features::empty(),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::PerPixel,
    census: false,
    census_when: |p| TAIL.is(p, TailSums::Compact),
    main: Some("k"),
    pipelines: &[super::ktab::PIPELINES],
    constants: super::ktab::CONSTANTS,
    create: |_, _| Box::new(Hybrid(KTab::new(true))),
};

pub const KTAB: MethodInfo = MethodInfo {
    name: "ktab",
    summary: "k-TAB: the k nearest fragments composited exactly, the others discarded (hybrid's core alone)",
    passes: &["store k-TAB (geometry)", "visibility (compute)", "shade core (geometry)", "final composite (full screen)"],
    params: &[K.0],
    census_when: super::info::never,
    create: |_, _| Box::new(Hybrid(KTab::new(false))),
    ..HYBRID
};

const MEMORY: Memory = Memory::Computed {
    formula: "W·H·(2k + 15)·4 + 8 (tail = 'compact': W·H·(2k + 2)·4 + 8)",
    bytes: |px, p| {
        let k = K.of(p) as u64;
        if TAIL.is(p, TailSums::Compact) {
            compact_memory_bytes(px, k)
        } else {
            memory_bytes(px, k)
        }
    },
};

/// `hybrid` and `ktab`: the k-TAB engine with a uniform k.
struct Hybrid(KTab);

impl Method for Hybrid {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let k = K.of(cx.params);
        // ktab has no tail, and sums its core as hybrid's default does.
        let sums = TAIL.or(cx.params, TailSums::Exact);
        self.0.render_slots(cx, Slots::Uniform(k), sums).map(Outcome::Done)
    }
}
