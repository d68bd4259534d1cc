//! `sbuffer`: the S-buffer (Vasilakis & Fudos 2012; the dynamic fragment buffer of Maule et
//! al. 2012 is the same idea): count fragments per pixel, prefix-sum the counts into
//! contiguous per-pixel ranges (compute), capture into them, and resolve like `abuffer`.
//! The pool holds exactly the counted fragments (shaders/sbuffer.wgsl).

use super::frame::{FrameCtx, Method, Outcome};
use super::info::{never, ErrorBound, Memory, MethodInfo, Order, SceneBytes, FRAMES};
use super::list_pipelines::swept_after;
use super::lists::{ListLayout, ListMethod};
use super::pool::{pool_layout, PoolAux};
use super::resolve_plan::{PIXEL_BYTES, STATE_WORDS};
use crate::cache::{Layout, PipelineSpec};
use crate::error::Result;
use crate::gpu_types::PoolNode;

/// Group 2: the node pool, with offsets at binding 7.
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, pool_layout!("offsets")];
const PIPELINES: &[PipelineSpec] = &swept_after(PipelineSpec::geometry("sbuffer.wgsl", "fs_count", GROUPS));

pub const INFO: MethodInfo = MethodInfo {
    name: "sbuffer",
    summary: "S-buffer: per-pixel counts, a prefix sum, fragments in contiguous per-pixel ranges, exact",
    exact: true,
    bounded_memory: false,
    passes: &["count (geometry)", "prefix sum (compute)", "capture (geometry)", "sweeps (compute)", "resolve (full screen)"],
    params: &[],
    features: wgpu::Features::empty(),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: Memory::Scene { storage: SceneBytes { per_pixel: PIXEL_BYTES + 8, per_fragment: size_of::<PoolNode>() as u64, per_triangle: 0 }, note: "+ scan sums" },
    error_bound: ErrorBound::Exact,
    census: true,
    census_when: never,
    main: None,
    pipelines: &[PIPELINES],
    constants: &[],
    create: |gpu, limits| {
        Box::new(SBuffer(ListMethod::new(
            gpu,
            limits,
            ListLayout {
                pipelines: PIPELINES,
                node_bytes: std::mem::size_of::<PoolNode>() as u64,
                state_words: STATE_WORDS,
                samples: 1,
                shades_at_resolve: false,
                aux: PoolAux::PixelOffsets,
                counts_in_capture: false,
            },
        )))
    },
};

struct SBuffer(ListMethod);

impl Method for SBuffer {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        self.0.render(cx)
    }
}
