//! `adaptive`: adaptive transparency (Salvi et al. 2011) as the paper's proof of concept:
//! every fragment captured in per-pixel lists (unbounded memory, as theirs), then a
//! full-screen pass that builds a visibility function of at most `nodes` steps in submission
//! order and composites every fragment by it (shaders/adaptive.wgsl).

use super::lists::{loop_limited, Aux, ListLayout, ListMethod, BATCH, LLVMPIPE_LOOP_LIMIT};
use super::{ErrorBound, FrameCtx, Memory, Method, MethodInfo, MethodReport, Order, ParamInfo, ParamKind, FRAMES};
use crate::error::{OitError, Result};
use crate::gpu_types::PrimNode;
use crate::shader::Const;

pub const INFO: MethodInfo = MethodInfo {
    name: "adaptive",
    summary: "adaptive transparency: a visibility function of at most `nodes` steps per pixel, built from captured lists",
    exact: false,
    bounded_memory: false,
    passes: &["capture (geometry)", "build visibility and composite (full screen)"],
    params: &[ParamInfo {
        name: "nodes",
        kind: ParamKind::Int { min: 1, max: 32, default: 8 },
        doc: "steps of the per-pixel visibility function",
    }],
    features: wgpu::Features::empty(),
    order: Order::Submission,
    antialias_modes: FRAMES,
    memory: Memory::Scene { formula: "32 B/fragment + 4 B/pixel (grows with the scene)" },
    error_bound: ErrorBound::None,
    create: |gpu, limits| {
        Box::new(Adaptive(ListMethod::new(
            gpu,
            limits,
            ListLayout { shader: "adaptive.wgsl", node_bytes: std::mem::size_of::<PrimNode>() as u64, state_words: 0, aux: Aux::None },
        )))
    },
};

struct Adaptive(ListMethod);

/// Refuses a frame whose deepest pixel the one-invocation replay of a submission-order
/// method (adaptive, mlab) could not finish on llvmpipe: (n / BATCH + 1) heap sweeps of the
/// list, then `per_fragment` loop iterations for each fragment.
pub(crate) fn check_replay_budget(cx: &FrameCtx<'_>, method: &str, param: &str, value: u32, per_fragment: u64) -> Result<()> {
    let n = cx.max_depth_complexity as u64;
    let iterations = (n / BATCH as u64 + 1) * n * 6 + n * per_fragment;
    if loop_limited(cx.gpu) && iterations > LLVMPIPE_LOOP_LIMIT {
        return Err(OitError::Unsupported(format!(
            "{method} with {param} = {value} on a pixel with {n} fragments needs about {iterations} loop iterations in one \
             shader invocation, and llvmpipe ends a shader's loops after {LLVMPIPE_LOOP_LIMIT}: use a hardware adapter, \
             a smaller {param} or fewer layers"
        )));
    }
    Ok(())
}

impl Method for Adaptive {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        let nodes = cx.params.int("nodes") as u32;
        // Per fragment: an insertion and a lookup of up to `nodes` steps each.
        check_replay_budget(cx, "adaptive", "nodes", nodes, 4 * nodes as u64)?;
        self.0.set_consts(vec![Const::U32("NODES", nodes), Const::U32("NODES_PLUS_ONE", nodes + 1)]);
        self.0.render(cx)
    }
}
