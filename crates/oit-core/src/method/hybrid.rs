//! `hybrid` (Maule et al. 2013, Algorithm 1) and `ktab`, its core alone with the tail
//! discarded: the k-TAB engine (ktab.rs) with the `k` parameter.

use super::frame::{FrameCtx, Method, Outcome};
use super::info::{ErrorBound, Memory, MethodInfo, Order, FRAMES};
use super::ktab::{compact_memory_bytes, memory_bytes, KTab, Slots, TailSums};
use super::params::{ParamInfo, ParamKind, ParamValue};
use crate::error::Result;

const K_PARAM: ParamInfo = ParamInfo {
    name: "k",
    kind: ParamKind::Int { min: 1, max: 32, default: 8 },
    doc: "core size: fragments per pixel kept exactly, sorted (k-TAB slots)",
};

const TAIL_PARAM: ParamInfo = ParamInfo {
    name: "tail",
    kind: ParamKind::Choice { choices: &["exact", "blend", "compact"], default: "exact" },
    doc: "how the second pass sums core and tail: 'exact' by fixed-point atomics (bit-identical under any order), \
          'blend' by float blending as in the paper (faster; order changes the rounding), 'compact' by blending into \
          the output and one RGBA16F target at Eq. 12's 2k + 2 words a pixel, the tail count from the census \
          (docs/methods.md)",
};

pub const HYBRID: MethodInfo = MethodInfo {
    name: "hybrid",
    summary: "hybrid transparency: the k nearest fragments exactly (k-TAB), the rest by weighted average",
    exact: false,
    bounded_memory: true,
    passes: &["store k-TAB (geometry)", "visibility (compute)", "shade core and tail (geometry)", "final composite (full screen)"],
    params: &[K_PARAM, TAIL_PARAM],
    features: wgpu::Features::empty(),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::PerPixel,
    census: false,
    census_when: |p| p.0.get("tail").is_some_and(|t| matches!(t, ParamValue::Str(s) if s == "compact")),
    main: Some("k"),
    pipelines: &[super::ktab::PIPELINES],
    create: |_, _| Box::new(Hybrid(KTab::new(true))),
};

pub const KTAB: MethodInfo = MethodInfo {
    name: "ktab",
    summary: "k-TAB: the k nearest fragments composited exactly, the others discarded (hybrid's core alone)",
    passes: &["store k-TAB (geometry)", "visibility (compute)", "shade core (geometry)", "final composite (full screen)"],
    params: &[K_PARAM],
    census_when: super::info::never,
    create: |_, _| Box::new(Hybrid(KTab::new(false))),
    ..HYBRID
};

const MEMORY: Memory = Memory::Computed {
    formula: "W·H·(2k + 15)·4 + 8 (tail = 'compact': W·H·(2k + 2)·4 + 8)",
    bytes: |px, p| {
        let k = p.int("k") as u64;
        if p.0.get("tail").is_some_and(|t| matches!(t, ParamValue::Str(s) if s == "compact")) {
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
        let k = cx.params.int("k") as u32;
        // ktab has no tail, and sums its core as hybrid's default does.
        let sums = if cx.params.0.contains_key("tail") { TailSums::from_param(cx.params.choice("tail")) } else { TailSums::Exact };
        self.0.render_slots(cx, Slots::Uniform(k), sums).map(Outcome::Done)
    }
}
