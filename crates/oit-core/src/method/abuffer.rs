//! `abuffer`: the exact A-buffer as per-pixel linked lists (Yang et al. 2010), resolved by
//! sorting each list front to back in batches and compositing (shaders/abuffer.wgsl).

use super::frame::{FrameCtx, Limits, Method, Outcome};
use super::info::{never, AntialiasMode, ErrorBound, Memory, MethodInfo, Order, SceneBytes};
use super::list_pipelines::{swept, FRAME, SAMPLES};
use super::lists::{ListLayout, ListMethod};
use super::pool::PoolAux;
use super::resolve_plan::{state_words, COUNTED_PIXEL_BYTES, STATE_WORDS};
use crate::cache::PipelineSpec;
use crate::context::GpuContext;
use crate::error::Result;
use crate::gpu_types::{CoverageNode, PoolNode};

const PIPELINES: &[PipelineSpec] = &swept("abuffer.wgsl", FRAME);
const COVERAGE: &[PipelineSpec] = &swept("abuffer_coverage.wgsl", SAMPLES);

pub const INFO: MethodInfo = MethodInfo {
    name: "abuffer",
    summary: "exact A-buffer: per-pixel linked lists in a node pool sized to the scene, sorted and composited per pixel",
    exact: true,
    bounded_memory: false,
    passes: &["capture (geometry)", "resolve (full screen)"],
    params: &[],
    features: wgpu::Features::empty(),
    order: Order::Bitwise,
    antialias_modes: &[AntialiasMode::Frames, AntialiasMode::Coverage],
    memory: Memory::Scene {
        storage: SceneBytes { per_pixel: COUNTED_PIXEL_BYTES, per_fragment: size_of::<PoolNode>() as u64, per_triangle: 0 },
        note: "(the node pool grows with the scene)",
    },
    error_bound: ErrorBound::Exact,
    census: true,
    census_when: never,
    main: None,
    pipelines: &[PIPELINES, COVERAGE],
    constants: &[],
    create: |gpu, limits| Box::new(ABuffer::new(gpu, limits)),
};

struct ABuffer {
    lists: ListMethod,
    /// The coverage-mask variant (shaders/abuffer_coverage.wgsl), made at its first frame.
    coverage: Option<ListMethod>,
}

impl ABuffer {
    fn new(gpu: &GpuContext, limits: &Limits) -> Self {
        let lists = ListMethod::new(
            gpu,
            limits,
            ListLayout {
                pipelines: PIPELINES,
                node_bytes: std::mem::size_of::<PoolNode>() as u64,
                state_words: STATE_WORDS,
                samples: 1,
                shades_at_resolve: false,
                aux: PoolAux::None,
                counts_in_capture: true,
            },
        );
        Self { lists, coverage: None }
    }
}

impl Method for ABuffer {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        match cx.coverage {
            Some(c) => {
                let lists = self.coverage.get_or_insert_with(|| {
                    ListMethod::new(
                        cx.gpu,
                        &cx.limits,
                        ListLayout {
                            pipelines: COVERAGE,
                            node_bytes: std::mem::size_of::<CoverageNode>() as u64,
                            state_words: state_words(c.samples),
                            samples: c.samples,
                            shades_at_resolve: false,
                            aux: PoolAux::None,
                            counts_in_capture: false,
                        },
                    )
                });
                lists.render(cx)
            }
            None => self.lists.render(cx),
        }
    }

    fn counts_in_capture(&self) -> bool {
        self.lists.counts_in_capture()
    }
}
