//! `auto`: accuracy on demand. Given a tolerance t, it picks per frame the cheapest hybrid
//! whose per-pixel error bound (docs/methods.md, "hybrid") is at most t everywhere, or the
//! exact A-buffer. It decides before rendering: an estimate pass gathers per pixel the
//! optical depth of the fragments and their alpha-quantization error; with the census's
//! fragment counts that predicts hybrid's bound for every k (`predicted_bound`). The smallest k
//! predicted to meet t is rendered and its real bound read back; if it misses, k is doubled
//! once (at most 32), and then the exact A-buffer is rendered. When no k ≤ 32 is predicted to
//! meet t, the A-buffer is rendered directly.

use super::{FrameCtx, Method, MethodInfo, MethodReport, ParamInfo, ParamKind, ParamValue, Params};
use crate::context::GpuContext;
use crate::error::Result;
use crate::pipeline;
use crate::shader;
use crate::targets::{read_buffer, read_rows, storage_buffer};

pub const INFO: MethodInfo = MethodInfo {
    name: "auto",
    summary: "accuracy on demand: the cheapest hybrid (or the exact A-buffer) whose error bound is at most `tolerance`",
    exact: false,
    bounded_memory: false,
    passes: &["census", "estimate", "hybrid with the smallest k predicted to meet the tolerance, then twice that k if it misses, else abuffer"],
    params: &[ParamInfo {
        name: "tolerance",
        kind: ParamKind::Float { min: 0.0, max: 1.0, default: 1.0 / 255.0 },
        doc: "largest error allowed at any pixel and channel, against the exact composite",
    }],
    create: |gpu, limits| Box::new(Auto::new(gpu, limits)),
};

/// Slots hybrid can hold (its `k` range).
const MAX_K: u32 = 32;
/// Fixed-point scales of shaders/auto_estimate.wgsl.
const TAU_SCALE: f64 = 4096.0;
const TAU2_SCALE: f64 = 1024.0;
const QUANT_SCALE: f64 = 16_777_216.0;
/// Float32 and fixed-point rounding per term of hybrid's bound (hybrid.wgsl, fs_final).
const ROUNDING: f64 = 2.4e-7;

struct Estimate {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    /// (pixels, buffer, readback, group)
    buffers: Option<(u64, wgpu::Buffer, wgpu::Buffer, wgpu::BindGroup)>,
}

struct Auto {
    hybrid: Box<dyn Method>,
    exact: Box<dyn Method>,
    estimate: Option<Estimate>,
}

impl Auto {
    fn new(gpu: &GpuContext, limits: &super::Limits) -> Self {
        let hybrid = super::lookup("hybrid").expect("registered").instantiate(gpu, limits);
        let exact = super::lookup("abuffer").expect("registered").instantiate(gpu, limits);
        Self { hybrid, exact, estimate: None }
    }

    /// Runs the estimate pass; returns its sums per pixel.
    fn measure(&mut self, cx: &mut FrameCtx<'_>) -> Result<Vec<Sums>> {
        let d = &cx.gpu.device;
        let est = self.estimate.get_or_insert_with(|| {
            let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("auto estimate"),
                entries: &[pipeline::storage_entry(0)],
            });
            let module = shader::module(d, "auto_estimate.wgsl", &[]);
            let pl = pipeline::layout(d, &[cx.scene_layout, cx.targets_layout, &layout]);
            let pipeline = pipeline::geometry(d, "auto estimate", &module, &pl, "fs_estimate", &[], pipeline::depth_test_only());
            Estimate { pipeline, layout, buffers: None }
        });
        let t = cx.targets;
        let pixels = t.width as u64 * t.height as u64;
        if est.buffers.as_ref().is_none_or(|b| b.0 != pixels) {
            est.buffers = None;
            cx.check_per_pixel("auto's estimate", WORDS * 4)?;
            let buffer = storage_buffer(d, "auto estimate", pixels * WORDS * 4, wgpu::BufferUsages::COPY_SRC);
            let readback = d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("auto estimate readback"),
                size: pixels * WORDS * 4,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("auto estimate"),
                layout: &est.layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }],
            });
            est.buffers = Some((pixels, buffer, readback, group));
        }
        let (_, buffer, readback, group) = est.buffers.as_ref().expect("made above");
        let mut enc = d.create_command_encoder(&Default::default());
        enc.clear_buffer(buffer, 0, None);
        {
            let mut pass = pipeline::capture_pass(&mut enc, "auto estimate", &t.depth, cx.timer.render_pass("estimate"));
            pass.set_pipeline(&est.pipeline);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, group, &[]);
            cx.scene.transparent.draw_all(&mut pass);
        }
        enc.copy_buffer_to_buffer(buffer, 0, readback, 0, pixels * WORDS * 4);
        cx.gpu.queue.submit([enc.finish()]);
        let raw = read_buffer(cx.gpu, readback, pixels * WORDS * 4)?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&raw);
        Ok(words
            .chunks_exact(3)
            .map(|w| Sums { tau: w[0] as f64 / TAU_SCALE, tau2: w[1] as f64 / TAU2_SCALE, quant: w[2] as f64 / QUANT_SCALE })
            .collect())
    }
}

/// Words per pixel of the estimate pass.
const WORDS: u64 = 3;
/// How many standard deviations below its mean the nearest fragments' optical depth is taken.
const SPREAD: f64 = 3.0;

/// One pixel's estimate-pass sums over its transparent fragments: optical depth
/// Σ −ln(1 − α), its square Σ ln²(1 − α), and Σ |α − q(α)| (q: hybrid's 8-bit alpha).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sums {
    pub tau: f64,
    pub tau2: f64,
    pub quant: f64,
}

/// Predicted hybrid bound at a pixel of `n` fragments for k slots. The nearest k are taken as
/// a random draw from the pixel's fragments: their optical depth has mean k·μ and deviation
/// σ·√(k(n − k)/(n − 1)) (sampling without replacement), and the prediction takes it SPREAD
/// deviations thinner than its mean. It sums hybrid's terms: the quantization Σ|δ|·T' (|δ| at
/// twice its mean, T' falling at the mean rate) and D², the rounding, and T_core where a tail
/// exists. An estimate, not a bound — fragments sorted thin-first break it — which is why auto
/// checks the rendered bound.
pub fn predicted_bound(n: u32, s: Sums, k: u32) -> f64 {
    if n == 0 {
        return 0.0;
    }
    let nf = n as f64;
    let mean = s.tau / nf;
    let core = k.min(n);
    // |δ| is at most 1/510; alphas off the 8-bit grid have it spread evenly below that, so
    // twice the mean stands for the nearest fragments' (alphas on the grid give 0).
    let d = (2.0 * s.quant / nf).min(1.0 / 510.0);
    let quant_term: f64 = (0..core).map(|j| d * (-(j as f64) * mean).exp()).sum::<f64>() + (d * core as f64).min(s.quant).powi(2);
    let tail = if n > k {
        let kf = k as f64;
        let sd = (s.tau2 / nf - mean * mean).max(0.0).sqrt() * (kf * (nf - kf) / (nf - 1.0)).sqrt();
        (-(kf * mean - SPREAD * sd).max(0.0)).exp()
    } else {
        0.0
    };
    quant_term + tail + (k + n + 2) as f64 * ROUNDING
}

/// The smallest k ≤ min(32, deepest pixel) predicted to meet `tolerance` at every pixel.
pub fn choose_k(counts: &[u32], sums: &[Sums], tolerance: f64) -> Option<u32> {
    let deepest = counts.iter().copied().max().unwrap_or(0);
    let top = deepest.clamp(1, MAX_K);
    // Per pixel, the smallest k that meets t; the frame needs the largest of them.
    let mut need = 1;
    for (&n, &s) in counts.iter().zip(sums) {
        if n == 0 || predicted_bound(n, s, need) <= tolerance {
            continue;
        }
        need = (need + 1..=top).find(|&k| predicted_bound(n, s, k) <= tolerance)?;
    }
    Some(need)
}

impl Method for Auto {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        let tolerance = cx.params.float("tolerance");
        let t = cx.targets;
        let pixels = t.width as u64 * t.height as u64;
        let counts: Vec<u32> = bytemuck::pod_collect_to_vec(&read_buffer(cx.gpu, &t.counts_readback, pixels * 4)?);
        let sums = self.measure(cx)?;
        let predicted = choose_k(&counts, &sums, tolerance);
        let mut attempts = 0.0;
        // The hybrid buffers of a missed attempt stay allocated (reused by the next frame).
        let mut hybrid_bytes = 0;
        let tries = predicted.map(|k| vec![k, (2 * k).min(MAX_K)]).unwrap_or_default();
        for (i, &k) in tries.iter().enumerate() {
            if i > 0 && k == tries[0] {
                break; // already at 32 slots
            }
            attempts += 1.0;
            let params = Params([("k", ParamValue::Int(k as i64))].into_iter().collect());
            let mut report = self.hybrid.render(&mut cx.with_params(&params))?;
            let bound = read_rows(cx.gpu, &t.bound_texture, &t.bound_readback, 4)?;
            let worst = bound.iter().copied().fold(0.0f32, f32::max) as f64;
            hybrid_bytes = report.memory_bytes;
            if worst <= tolerance {
                report.memory_bytes += pixels * WORDS * 4;
                report.extra.extend([
                    ("auto_k", k as f64),
                    ("auto_predicted_k", tries[0] as f64),
                    ("auto_exact", 0.0),
                    ("auto_attempts", attempts),
                    ("error_bound_max", worst),
                ]);
                return Ok(report);
            }
        }
        let mut report = self.exact.render(&mut cx.with_params(&Params::default()))?;
        // Exact up to float32 compositing: (n + 2) roundings of at most 2^-24 each, doubled.
        let rounding = (cx.max_depth_complexity as f64 + 2.0) * ROUNDING;
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
        report.memory_bytes += pixels * WORDS * 4 + hybrid_bytes;
        report.extra.extend([
            ("auto_k", 0.0),
            ("auto_predicted_k", predicted.map_or(0.0, |k| k as f64)),
            ("auto_exact", 1.0),
            ("auto_attempts", attempts + 1.0),
            ("error_bound_max", rounding),
        ]);
        Ok(report)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn alike(n: u32, alpha: f64) -> Sums {
        let tau = -(1.0 - alpha).ln();
        Sums { tau: n as f64 * tau, tau2: n as f64 * tau * tau, quant: 0.0 }
    }

    #[test]
    fn no_tail_when_k_covers_the_pixel() {
        assert!(predicted_bound(4, alike(4, 0.5), 4) < 1e-5);
        // Alike fragments have no spread: the remainder behind two of them is exactly 1/4.
        assert!((predicted_bound(4, alike(4, 0.5), 2) - 0.25).abs() < 1e-5);
    }

    #[test]
    fn spread_makes_the_prediction_more_careful() {
        let even = alike(20, 0.3);
        let uneven = Sums { tau2: even.tau2 * 1.5, ..even };
        assert!(predicted_bound(20, uneven, 8) > predicted_bound(20, even, 8));
    }

    #[test]
    fn the_smallest_k_that_meets_the_tolerance() {
        let counts = [10, 0, 3];
        let sums = [alike(10, 0.5), Sums::default(), alike(3, 0.5)];
        // 0.5^k <= 0.01 first at k = 7.
        assert_eq!(choose_k(&counts, &sums, 0.01), Some(7));
        // 100 fragments of optical depth 0.01 each: 32 slots leave e^-0.32, no k meets 0.01.
        assert_eq!(choose_k(&[100], &[alike(100, 1.0 - (-0.01f64).exp())], 0.01), None);
    }
}
