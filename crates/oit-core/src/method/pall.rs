//! `pall`: primitive-allocated linked lists (Kerzner et al. 2013). A compute pass gives each
//! triangle one block of nodes, sized by the pixel centers of its screen bounding box (a
//! conservative bound of its fragments); fragments then link nodes of their triangle's
//! block without a global atomic. Resolved exactly like `abuffer` (shaders/pall.wgsl).

use super::frame::{FrameCtx, Method, Outcome};
use super::info::{never, ErrorBound, Memory, MethodInfo, Order, SceneBytes, FRAMES};
use super::list_pipelines::swept_after;
use super::lists::{ListLayout, ListMethod};
use super::pool::{pool_layout, PoolAux};
use super::resolve_plan::{PIXEL_BYTES, STATE_WORDS};
use crate::cache::{Layout, PipelineSpec};
use crate::error::Result;
use crate::gpu_types::{PallBlock, PoolNode};

/// Group 2: the node pool, with blocks at binding 7.
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, pool_layout!("blocks")];
const PIPELINES: &[PipelineSpec] = &swept_after(PipelineSpec::compute("pall.wgsl", "cs_allocate", GROUPS));

pub const INFO: MethodInfo = MethodInfo {
    name: "pall",
    summary: "primitive-allocated linked lists: one allocation per triangle (bounding-box bound), exact",
    exact: true,
    bounded_memory: false,
    passes: &["allocate per triangle (compute)", "capture (geometry)", "sweeps (compute)", "resolve (full screen)"],
    params: &[],
    features: wgpu::Features::empty(),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: Memory::Scene {
        storage: SceneBytes { per_pixel: PIXEL_BYTES, per_fragment: size_of::<PoolNode>() as u64, per_triangle: size_of::<PallBlock>() as u64 },
        note: "(a fragment's node for each pixel of its triangle's bounds)",
    },
    error_bound: ErrorBound::Exact,
    census: true,
    census_when: never,
    main: None,
    pipelines: &[PIPELINES],
    constants: &[],
    create: |gpu, limits| {
        Box::new(Pall(ListMethod::new(
            gpu,
            limits,
            ListLayout {
                pipelines: PIPELINES,
                node_bytes: std::mem::size_of::<PoolNode>() as u64,
                state_words: STATE_WORDS,
                samples: 1,
                shades_at_resolve: false,
                aux: PoolAux::PerTriangle(std::mem::size_of::<PallBlock>() as u64),
                counts_in_capture: false,
            },
        )))
    },
};

struct Pall(ListMethod);

impl Method for Pall {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        self.0.render(cx)
    }
}
