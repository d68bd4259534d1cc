//! `mlab_lists`: multi-layer alpha blending (Salvi & Vaidyanathan 2014), replayed in submission
//! order over captured lists: the proof of concept beside the bounded `mlab` (mlab.rs); memory is that of
//! the lists, unbounded (shaders/mlab_lists.wgsl).

use super::frame::{FrameCtx, Method, Outcome};
use super::info::{never, ErrorBound, Memory, MethodInfo, Order, SceneBytes, FRAMES};
use super::list_pipelines::{single, FRAME};
use super::lists::{check_replay_budget, ListLayout, ListMethod};
use super::params::IntParam;
use super::pool::PoolAux;
use crate::cache::PipelineSpec;
use crate::error::Result;
use crate::gpu_types::PrimNode;
use crate::shader::Const;

const PIPELINES: &[PipelineSpec] = &single("mlab_lists.wgsl", FRAME);

const LAYERS: IntParam = IntParam::new("layers", (1, 32, 4), "blended layers kept per pixel").compiled_as("LAYERS");

pub const INFO: MethodInfo = MethodInfo {
    name: "mlab_lists",
    summary: "multi-layer alpha blending replayed from captured lists (unbounded memory; `mlab` is the bounded one)",
    exact: false,
    bounded_memory: false,
    passes: &["capture (geometry)", "replay in submission order and composite (full screen)"],
    params: &[LAYERS.0],
    features: wgpu::Features::empty(),
    order: Order::Submission,
    antialias_modes: FRAMES,
    memory: Memory::Scene { storage: SceneBytes { per_pixel: 4, per_fragment: size_of::<PrimNode>() as u64, per_triangle: 0 }, note: "(grows with the scene)" },
    error_bound: ErrorBound::None,
    census: true,
    census_when: never,
    main: Some("layers"),
    pipelines: &[PIPELINES],
    constants: &[Const::U32("LAYERS_PLUS_ONE", 5)],
    create: |gpu, limits| {
        Box::new(MlabLists(ListMethod::new(
            gpu,
            limits,
            ListLayout {
                pipelines: PIPELINES,
                node_bytes: std::mem::size_of::<PrimNode>() as u64,
                state_words: 0,
                samples: 1,
                shades_at_resolve: false,
                aux: PoolAux::None,
                counts_in_capture: false,
            },
        )))
    },
};

struct MlabLists(ListMethod);

impl Method for MlabLists {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let layers = LAYERS.of(cx.params);
        // Per fragment: an insertion shifting up to `layers` entries.
        check_replay_budget(cx, "mlab_lists", "layers", layers, layers as u64 + 2)?;
        self.0.set_consts(vec![LAYERS.constant(cx.params), Const::U32("LAYERS_PLUS_ONE", layers + 1)]);
        self.0.render(cx)
    }
}
