//! `auto`: accuracy on demand. Given a tolerance t, it picks per frame the cheapest
//! configuration whose per-pixel error bound (docs/methods.md, "hybrid") is at most t
//! everywhere: hybrid with k = the frame's depth complexity when that fits in 32 slots (no
//! tail at all), else hybrid with k = 8, 16, 32 in turn, and the exact S-buffer when no
//! hybrid meets t. The census gives the depth complexity before anything is allocated; each
//! hybrid attempt reads its bound back to decide.

use super::{FrameCtx, Method, MethodInfo, MethodReport, ParamInfo, ParamKind, ParamValue, Params};
use crate::context::GpuContext;
use crate::error::Result;
use crate::targets::read_rows;

pub const INFO: MethodInfo = MethodInfo {
    name: "auto",
    summary: "accuracy on demand: the cheapest hybrid (or the exact S-buffer) whose error bound is at most `tolerance`",
    exact: false,
    bounded_memory: false,
    passes: &["census", "hybrid with growing k until its bound meets the tolerance, else sbuffer"],
    params: &[ParamInfo {
        name: "tolerance",
        kind: ParamKind::Float { min: 0.0, max: 1.0, default: 1.0 / 255.0 },
        doc: "largest error allowed at any pixel and channel, against the exact composite",
    }],
    create: |gpu, limits| Box::new(Auto::new(gpu, limits)),
};

/// Slots hybrid can hold (its `k` range).
const MAX_K: u32 = 32;

struct Auto {
    hybrid: Box<dyn Method>,
    exact: Box<dyn Method>,
}

impl Auto {
    fn new(gpu: &GpuContext, limits: &super::Limits) -> Self {
        let hybrid = super::lookup("hybrid").expect("registered").instantiate(gpu, limits);
        let exact = super::lookup("sbuffer").expect("registered").instantiate(gpu, limits);
        Self { hybrid, exact }
    }
}

/// The k values to try for a frame whose deepest pixel has `n` fragments.
fn candidates(n: u32) -> Vec<u32> {
    if n <= MAX_K {
        return vec![n.max(1)];
    }
    vec![8, 16, MAX_K]
}

impl Method for Auto {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        let tolerance = cx.params.float("tolerance") as f32;
        let mut attempts = 0.0;
        for k in candidates(cx.max_depth_complexity) {
            attempts += 1.0;
            let params = Params([("k", ParamValue::Int(k as i64))].into_iter().collect());
            cx.timer.reset();
            let mut report = self.hybrid.render(&mut cx.with_params(&params))?;
            let t = cx.targets;
            let bound = read_rows(cx.gpu, &t.bound_texture, &t.bound_readback, 4)?;
            let worst = bound.iter().copied().fold(0.0f32, f32::max);
            if worst <= tolerance {
                report.extra.extend([("auto_k", k as f64), ("auto_exact", 0.0), ("auto_attempts", attempts), ("error_bound_max", worst as f64)]);
                return Ok(report);
            }
        }
        cx.timer.reset();
        let mut report = self.exact.render(&mut cx.with_params(&Params::default()))?;
        // Exact up to float32 compositing: (n + 2) roundings of at most 2^-24 each, doubled.
        let rounding = (cx.max_depth_complexity as f64 + 2.0) * 2.4e-7;
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("auto bound"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &cx.targets.bound,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r: rounding, g: 0.0, b: 0.0, a: 0.0 }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        cx.gpu.queue.submit([enc.finish()]);
        report.error_bound = true;
        report.extra.extend([("auto_k", 0.0), ("auto_exact", 1.0), ("auto_attempts", attempts + 1.0), ("error_bound_max", rounding)]);
        Ok(report)
    }
}
