//! `adaptive_lists`: adaptive transparency (Salvi et al. 2011) as the paper's proof of concept:
//! every fragment captured in per-pixel lists (unbounded memory, as theirs), then a
//! full-screen pass that builds a visibility function of at most `nodes` steps in submission
//! order and composites every fragment by it (shaders/adaptive_lists.wgsl).

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

const PIPELINES: &[PipelineSpec] = &single("adaptive_lists.wgsl", FRAME);

const NODES: IntParam = IntParam::new("nodes", (1, 32, 8), "steps of the per-pixel visibility function").compiled_as("NODES");

pub const INFO: MethodInfo = MethodInfo {
    name: "adaptive_lists",
    summary: "adaptive transparency built from captured lists (unbounded memory; `adaptive` is the bounded one)",
    exact: false,
    bounded_memory: false,
    passes: &["capture (geometry)", "build visibility and composite (full screen)"],
    params: &[NODES.0],
    features: wgpu::Features::empty(),
    order: Order::Submission,
    antialias_modes: FRAMES,
    memory: Memory::Scene { storage: SceneBytes { per_pixel: 4, per_fragment: size_of::<PrimNode>() as u64, per_triangle: 0 }, note: "(grows with the scene)" },
    error_bound: ErrorBound::None,
    census: true,
    census_when: never,
    main: Some("nodes"),
    pipelines: &[PIPELINES],
    constants: &[Const::U32("NODES_PLUS_ONE", 9)],
    create: |gpu, limits| {
        Box::new(AdaptiveLists(ListMethod::new(
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

struct AdaptiveLists(ListMethod);

impl Method for AdaptiveLists {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let nodes = NODES.of(cx.params);
        // Per fragment: an insertion and a lookup of up to `nodes` steps each.
        check_replay_budget(cx, "adaptive_lists", "nodes", nodes, 4 * nodes as u64)?;
        self.0.set_consts(vec![NODES.constant(cx.params), Const::U32("NODES_PLUS_ONE", nodes + 1)]);
        self.0.render(cx)
    }
}
