//! `hybrid` (Maule et al. 2013, Algorithm 1) and `ktab`, its core alone with the tail
//! discarded: the k-TAB engine (ktab.rs) with the `k` parameter.

use super::frame::{FrameCtx, Method, MethodReport};
use super::info::{ErrorBound, Memory, MethodInfo, Order, Tiling, FRAMES};
use super::ktab::{memory_bytes, KTab, Slots};
use super::params::{ParamInfo, ParamKind};
use crate::error::Result;

const K_PARAM: ParamInfo = ParamInfo {
    name: "k",
    kind: ParamKind::Int { min: 1, max: 32, default: 8 },
    doc: "core size: fragments per pixel kept exactly, sorted (k-TAB slots)",
};

pub const HYBRID: MethodInfo = MethodInfo {
    name: "hybrid",
    summary: "hybrid transparency: the k nearest fragments exactly (k-TAB), the rest by weighted average",
    exact: false,
    bounded_memory: true,
    passes: &["store k-TAB (geometry)", "visibility (compute)", "shade core and tail (geometry)", "final composite (full screen)"],
    params: &[K_PARAM],
    features: wgpu::Features::empty(),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::PerPixel,
    tiling: Tiling::Formula,
    create: |_, _| Box::new(Hybrid(KTab::new(true))),
};

pub const KTAB: MethodInfo = MethodInfo {
    name: "ktab",
    summary: "k-TAB: the k nearest fragments composited exactly, the others discarded (hybrid's core alone)",
    passes: &["store k-TAB (geometry)", "visibility (compute)", "shade core (geometry)", "final composite (full screen)"],
    create: |_, _| Box::new(Hybrid(KTab::new(false))),
    ..HYBRID
};

const MEMORY: Memory = Memory::Frame { formula: "W·H·(2k + 18)·4 + 4", bytes: |px, p| memory_bytes(px, p.int("k") as u64) };

/// `hybrid` and `ktab`: the k-TAB engine with a uniform k.
struct Hybrid(KTab);

impl Method for Hybrid {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        let k = cx.params.int("k") as u32;
        self.0.render_slots(cx, Slots::Uniform(k))
    }
}
