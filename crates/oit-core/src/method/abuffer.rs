//! `abuffer`: the exact A-buffer as per-pixel linked lists (Yang et al. 2010), resolved by
//! sorting each list front to back in batches and compositing (shaders/abuffer.wgsl).

use super::lists::ListMethod;
use super::{FrameCtx, Limits, Method, MethodInfo, MethodReport};
use crate::context::GpuContext;
use crate::error::Result;
use crate::gpu_types::PoolNode;

pub const INFO: MethodInfo = MethodInfo {
    name: "abuffer",
    summary: "exact A-buffer: per-pixel linked lists in a node pool sized to the scene, sorted and composited per pixel",
    exact: true,
    bounded_memory: false,
    passes: &["capture (geometry)", "resolve (full screen)"],
    params: &[],
    create: |gpu, limits| Box::new(ABuffer::new(gpu, limits)),
};

struct ABuffer(ListMethod);

impl ABuffer {
    fn new(gpu: &GpuContext, limits: &Limits) -> Self {
        Self(ListMethod::new(gpu, limits, "abuffer.wgsl", std::mem::size_of::<PoolNode>() as u64))
    }
}

impl Method for ABuffer {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        self.0.render(cx)
    }
}
