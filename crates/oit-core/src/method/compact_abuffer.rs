//! `compact_abuffer`: the compact A-buffer (Kerzner et al. 2013). Nodes hold depth and the
//! triangle index only (12 bytes); each triangle's shading data (clip-space corners, colors,
//! normals, material and UVs: 176 bytes) is written once by a compute pass and the resolve
//! shades each fragment from it, deferred (shaders/compact_abuffer.wgsl, docs/shading.md).

use super::frame::{FrameCtx, Method, Outcome};
use super::info::{never, ErrorBound, Memory, MethodInfo, Order, SceneBytes, FRAMES};
use super::list_pipelines::swept_after;
use super::lists::{ListLayout, ListMethod};
use super::pool::{pool_layout, PoolAux};
use super::resolve_plan::{COUNTED_PIXEL_BYTES, STATE_WORDS};
use crate::cache::{Layout, PipelineSpec};
use crate::error::Result;
use crate::gpu_types::{CompactNode, PrimShading};

/// Group 2: the node pool, with shading at binding 7.
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, pool_layout!("shading")];
const PIPELINES: &[PipelineSpec] = &swept_after(PipelineSpec::compute("compact_abuffer.wgsl", "cs_allocate", GROUPS));

pub const INFO: MethodInfo = MethodInfo {
    name: "compact_abuffer",
    summary: "compact A-buffer: 12-byte nodes (depth, triangle), shading stored once per triangle, exact",
    exact: true,
    bounded_memory: false,
    passes: &["triangle setup (compute)", "capture (geometry)", "sweeps (compute)", "resolve (full screen)"],
    params: &[],
    features: wgpu::Features::empty(),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: Memory::Scene { storage: SceneBytes { per_pixel: COUNTED_PIXEL_BYTES, per_fragment: size_of::<CompactNode>() as u64, per_triangle: size_of::<PrimShading>() as u64 }, note: "" },
    error_bound: ErrorBound::Exact,
    census: true,
    census_when: never,
    main: None,
    pipelines: &[PIPELINES],
    constants: &[],
    create: |gpu, limits| {
        Box::new(Compact(ListMethod::new(
            gpu,
            limits,
            ListLayout {
                pipelines: PIPELINES,
                node_bytes: std::mem::size_of::<CompactNode>() as u64,
                state_words: STATE_WORDS,
                samples: 1,
                shades_at_resolve: true,
                aux: PoolAux::PerTriangle(std::mem::size_of::<PrimShading>() as u64),
                counts_in_capture: true,
            },
        )))
    },
};

struct Compact(ListMethod);

impl Method for Compact {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        self.0.render(cx)
    }

    fn counts_in_capture(&self) -> bool {
        self.0.counts_in_capture()
    }
}
