//! `abuffer`: the exact A-buffer as per-pixel linked lists (Yang et al. 2010), resolved by
//! sorting each list front to back in batches and compositing (shaders/abuffer.wgsl).

use super::lists::{loop_limited, Aux, ListLayout, ListMethod, BATCH, LLVMPIPE_LOOP_LIMIT};
use super::{AntialiasMode, ErrorBound, FrameCtx, Limits, Memory, Method, MethodInfo, MethodReport, Order};
use crate::context::GpuContext;
use crate::error::{OitError, Result};
use crate::gpu_types::{CoverageNode, PoolNode};

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
    memory: Memory::Scene { formula: "24 B/fragment + 52 B/pixel (the node pool grows with the scene)" },
    error_bound: ErrorBound::Exact,
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
                shader: "abuffer.wgsl",
                node_bytes: std::mem::size_of::<PoolNode>() as u64,
                state_words: STATE_WORDS,
                aux: Aux::None,
            },
        );
        Self { lists, coverage: None }
    }
}

/// Words of per-pixel sweep state at one sample a pixel (STATE_WORDS in
/// shaders/common/sweep.wgsl: 8 + 4 per sample).
pub(crate) const STATE_WORDS: u64 = state_words(1);

pub(crate) const fn state_words(samples: u32) -> u64 {
    8 + 4 * samples as u64
}

/// Loop iterations of one sweep over a list of n fragments, at worst: one per node and
/// log2(BATCH) heap steps per node kept, then the batch's heap sort.
pub fn sweep_iterations(n: u64) -> u64 {
    let log = BATCH.ilog2() as u64;
    n * (1 + log) + BATCH as u64 * (log + 1)
}

/// Refuses a frame whose deepest pixel one sweep could not walk on llvmpipe.
pub(crate) fn check_sweep_budget(cx: &FrameCtx<'_>) -> Result<()> {
    let n = cx.max_depth_complexity as u64;
    if loop_limited(cx.gpu) && sweep_iterations(n) > LLVMPIPE_LOOP_LIMIT {
        return Err(OitError::Unsupported(format!(
            "a pixel has {n} transparent fragments; on llvmpipe one resolve sweep handles at most about {} \
             (the driver ends a shader's loops after {LLVMPIPE_LOOP_LIMIT} iterations): use a hardware adapter, \
             fewer layers, or a bounded method such as hybrid",
            (LLVMPIPE_LOOP_LIMIT - BATCH as u64 * 6) / 6
        )));
    }
    Ok(())
}

impl Method for ABuffer {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        check_sweep_budget(cx)?;
        match cx.coverage {
            Some(c) => {
                let lists = self.coverage.get_or_insert_with(|| {
                    ListMethod::new(
                        cx.gpu,
                        &cx.limits,
                        ListLayout {
                            shader: "abuffer_coverage.wgsl",
                            node_bytes: std::mem::size_of::<CoverageNode>() as u64,
                            state_words: state_words(c.samples),
                            aux: Aux::None,
                        },
                    )
                });
                lists.render(cx)
            }
            None => self.lists.render(cx),
        }
    }
}
