//! `auto`: accuracy on demand. Given a tolerance t, it picks per frame the cheapest of mboit,
//! hybrid and the exact A-buffer whose per-pixel error bound (docs/methods.md, "mboit",
//! "hybrid") is at most t everywhere. It decides before rendering: an estimate pass gathers per
//! pixel the optical depth of the fragments and their alpha-quantization error. Where every
//! pixel's colors times its coverage are within t (`weighted_average_bound`: the error of any
//! average that keeps the exact coverage, as mboit's does), mboit with 4 moments is rendered
//! first, at less memory than any hybrid, and kept if its own bound meets t. Otherwise, with the
//! census's fragment counts, the sums predict hybrid's bound for every k (`predicted_bound`). Each pixel gets
//! the smallest k predicted to meet t (its own slots: `Slots::PerPixel`, no more than its
//! fragments) and the real bound is read back; where it misses, those pixels get twice the
//! slots once, and then the exact A-buffer is rendered. When some pixel has no k ≤ 32
//! predicted to meet t, the A-buffer is rendered directly.

use super::frame::{FrameCtx, Method, Outcome};
use super::info::{never, ErrorBound, Memory, MethodInfo, Order, SceneBytes, FRAMES};
use super::ktab::{self, KTab, Slots};
use super::params::{FloatParam, ParamValue, Params};
use crate::cache::{spec, Layout, PipelineSpec};
use crate::consts::{self, ALPHA_8BIT_ERROR, ROUNDING_TERM as ROUNDING};
use crate::context::GpuContext;
use crate::error::Result;
use crate::resources::{Readback, StorageGroup};
use crate::targets::read_region;

/// The estimate pass, into its sums (group 2); the frame itself is the k-TAB engine's.
const OWN: Layout = Layout::Storage(&["sums"]);
const PIPELINES: &[PipelineSpec] = &[PipelineSpec::geometry("auto_estimate.wgsl", "fs_estimate", &[Layout::Scene, Layout::Targets, OWN])];

const TOLERANCE: FloatParam =
    FloatParam::new("tolerance", (0.0, 1.0, 1.0 / 255.0), "largest error allowed at any pixel and channel, against the exact composite");

pub const INFO: MethodInfo = MethodInfo {
    name: "auto",
    summary: "accuracy on demand: the cheapest hybrid (or the exact A-buffer) whose error bound is at most `tolerance`",
    exact: false,
    bounded_memory: false,
    passes: &[
        "census",
        "estimate",
        "mboit with 4 moments where every pixel's colors times its coverage are within the tolerance",
        "hybrid with each pixel's smallest k predicted to meet the tolerance (twice that where it misses), else abuffer",
    ],
    params: &[TOLERANCE.0],
    features: wgpu::Features::empty(),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: Memory::Slots {
        formula: "W·H·(20 + 52) (mboit with 4 moments and the estimate), 2·Σk·4 + W·H·84 + 8 (hybrid with per-pixel slots and the estimate), or the A-buffer's",
        bytes: memory_bytes,
        storage: SceneBytes { per_pixel: 84, per_fragment: 24, per_triangle: 0 },
    },
    error_bound: ErrorBound::PerPixel,
    census: true,
    census_when: never,
    main: None,
    pipelines: &[PIPELINES, ktab::PIPELINES, super::mboit::INFO.pipelines[0]],
    constants: &[],
    create: |gpu, limits| Box::new(Auto::new(gpu, limits)),
};

/// Slots hybrid can hold (its `k` range).
const MAX_K: u32 = 32;
/// Fixed-point scales of shaders/auto_estimate.wgsl.
const TAU_SCALE: f64 = consts::TAU_SCALE as f64;
const TAU2_SCALE: f64 = consts::TAU2_SCALE as f64;
const QUANT_SCALE: f64 = consts::QUANT_SCALE as f64;

struct Auto {
    moments: Box<dyn Method>,
    hybrid: KTab,
    exact: Box<dyn Method>,
    /// The estimate pass's sums, and their readback by size.
    estimate: Option<StorageGroup>,
    readback: Option<(u64, Readback)>,
}

impl Auto {
    fn new(gpu: &GpuContext, limits: &super::frame::Limits) -> Self {
        let hybrid = KTab::new(true);
        let exact = super::abuffer::INFO.instantiate(gpu, limits);
        let moments = super::mboit::INFO.instantiate(gpu, limits);
        Self { moments, hybrid, exact, estimate: None, readback: None }
    }

    /// Renders mboit with 4 power moments: Ok(report with auto's extras) when its bound meets
    /// `tolerance` at every pixel, Err(the bytes its targets hold) when it does not (the caller
    /// goes on to hybrid; the targets stay for the next frame, and count in this one's memory).
    fn try_moments(&mut self, cx: &mut FrameCtx<'_>, tolerance: f64) -> Result<std::result::Result<Outcome, u64>> {
        let given = [("moments".to_string(), ParamValue::Int(4))];
        let params = super::mboit::INFO.resolve_params(&given)?;
        let Outcome::Done(mut report) = self.moments.render(&mut cx.with_params(&params))? else {
            unreachable!("mboit's memory is per pixel: it never asks to grow or retile")
        };
        let (t, tile) = (cx.targets, cx.tile);
        let bound = read_region(cx.gpu, &t.bound_texture, &t.bound_readback, 4, tile.local())?;
        if bound.iter().any(|&b| b as f64 > tolerance) {
            return Ok(Err(report.memory_bytes));
        }
        report.memory_bytes += cx.pixels() * WORDS * 4;
        report.extra.extend(extras((0.0, 0.0, 0.0), 0.0, 0.0, MOMENTS_KEPT, 1.0));
        Ok(Ok(Outcome::Done(report)))
    }

    /// Runs the estimate pass; returns its sums per pixel.
    fn measure(&mut self, cx: &mut FrameCtx<'_>) -> Result<Vec<PixelSums>> {
        let bytes = cx.pixels() * WORDS * 4;
        cx.check_per_pixel("auto's estimate", WORDS * 4)?;
        let b = StorageGroup::ensure(&mut self.estimate, cx.gpu, OWN, &[("sums", bytes)], &[]);
        if self.readback.as_ref().is_none_or(|(n, _)| *n != bytes) {
            self.readback = Some((bytes, Readback::new(cx.gpu, "auto estimate readback", bytes)));
        }
        let (_, readback) = self.readback.as_ref().expect("made above");
        let pipeline = cx.capture_pipeline(spec(PIPELINES, "fs_estimate"), &[]);
        let mut enc = cx.encoder();
        b.clear(&mut enc);
        cx.capture(&mut enc, "estimate", &pipeline, &b.group);
        readback.copy(&mut enc, &b.buffers[0]);
        cx.submit(enc);
        let raw = readback.read(cx.gpu)?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&raw);
        Ok(words
            .chunks_exact(WORDS as usize)
            .map(|w| PixelSums {
                tau: w[0] as f64 / TAU_SCALE,
                tau2: w[1] as f64 / TAU2_SCALE,
                quant: w[2] as f64 / QUANT_SCALE,
                range: if w[3] == 0 { 0.0 } else { (f32::from_bits(w[4]) - f32::from_bits(!w[3])).max(0.0) as f64 },
            })
            .collect())
    }
}

/// Words per pixel of the estimate pass.
const WORDS: u64 = 5;

/// Bytes auto allocates when it renders hybrid with `slots` k-TAB slots in all: hybrid's
/// per-pixel-slot buffers and the estimate's words.
pub fn memory_bytes(pixels: u64, slots: u64) -> u64 {
    super::ktab::memory_bytes_per_pixel(pixels, slots) + pixels * WORDS * 4
}
/// How many standard deviations below its mean the nearest fragments' optical depth is taken.
const SPREAD: f64 = 3.0;

/// One pixel's estimate-pass sums over its transparent fragments: optical depth
/// Σ −ln(1 − α), its square Σ ln²(1 − α), Σ |α − q(α)| (q: hybrid's 8-bit alpha), and the
/// range of the color channels of the fragments and the base behind them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelSums {
    pub tau: f64,
    pub tau2: f64,
    pub quant: f64,
    pub range: f64,
}

/// Predicted hybrid bound at a pixel of `n` fragments for k slots. The nearest k are taken as
/// a random draw from the pixel's fragments: their optical depth has mean k·μ and deviation
/// σ·√(k(n − k)/(n − 1)) (sampling without replacement), and the prediction takes it SPREAD
/// deviations thinner than its mean. It sums hybrid's terms: the quantization Σ|δ|·T' (|δ| at
/// twice its mean, T' falling at the mean rate) and D², the rounding, and T_core times the
/// range of the colors behind it where a tail exists. An estimate, not a bound — fragments sorted thin-first break it — which is why auto
/// checks the rendered bound.
pub fn predicted_bound(n: u32, s: PixelSums, k: u32) -> f64 {
    if n == 0 {
        return 0.0;
    }
    let nf = n as f64;
    let mean = s.tau / nf;
    let core = k.min(n);
    // |δ| is at most ALPHA_8BIT_ERROR (half a step of 1/255 and the rounding bias); alphas
    // off the 8-bit grid have it spread evenly below that, so twice the mean stands for the
    // nearest fragments' (alphas on the grid give 0).
    let d = (2.0 * s.quant / nf).min(ALPHA_8BIT_ERROR);
    let quant_term: f64 = (0..core).map(|j| d * (-(j as f64) * mean).exp()).sum::<f64>() + (d * core as f64).min(s.quant).powi(2);
    let tail = if n > k {
        let kf = k as f64;
        let sd = (s.tau2 / nf - mean * mean).max(0.0).sqrt() * (kf * (nf - kf) / (nf - 1.0)).sqrt();
        (-(kf * mean - SPREAD * sd).max(0.0)).exp() * s.range
    } else {
        0.0
    };
    quant_term + tail + (k + n + 2) as f64 * ROUNDING
}

/// The error bound of any composite that weights a pixel's colors by weights summing to its
/// exact coverage 1 − e^(−τ) (mboit's resolve does): |Σ Cᵢ(wᵢ' − wᵢ)| ≤ range·(1 − e^(−τ)), with
/// the colors' range from the estimate pass; the largest over the pixels, with the estimate's
/// fixed-point rounding of τ (half a step a fragment) and float32 compositing's rounding.
pub fn weighted_average_bound(counts: &[u32], sums: &[PixelSums]) -> f64 {
    counts
        .iter()
        .zip(sums)
        .filter(|(&n, _)| n > 0)
        .map(|(&n, s)| {
            let tau = s.tau + 0.5 * n as f64 / TAU_SCALE;
            s.range * -(-tau).exp_m1() + (n + 2) as f64 * ROUNDING
        })
        .fold(0.0, f64::max)
}

/// Each pixel's smallest k ≤ min(32, its fragments) predicted to meet `tolerance` (0 where it
/// has no fragments); None when some pixel has no such k.
pub fn choose_slots(counts: &[u32], sums: &[PixelSums], tolerance: f64) -> Option<Vec<u32>> {
    counts
        .iter()
        .zip(sums)
        .map(|(&n, &s)| if n == 0 { Some(0) } else { (1..=n.min(MAX_K)).find(|&k| predicted_bound(n, s, k) <= tolerance) })
        .collect()
}

/// The slots of a second attempt: twice as many (at most min(32, n)) where the rendered bound
/// missed `tolerance`; None when a missing pixel already has all it can get.
fn widen(slots: &[u32], counts: &[u32], bound: &[f32], tolerance: f64) -> Option<Vec<u32>> {
    slots
        .iter()
        .zip(counts)
        .zip(bound)
        .map(|((&k, &n), &b)| {
            let cap = n.min(MAX_K);
            match (b as f64 <= tolerance, k < cap) {
                (true, _) => Some(k),
                (false, true) => Some((2 * k).clamp(1, cap)),
                (false, false) => None,
            }
        })
        .collect()
}

/// `auto_moments`: mboit was tried and its bound missed the tolerance; it was kept (the frame is
/// mboit's with 4 moments). 0: not tried.
const MOMENTS_MISSED: f64 = 1.0;
const MOMENTS_KEPT: f64 = 2.0;

/// auto's figures in the frame's stats: the largest and mean k and all the slots of the hybrid
/// it rendered (0 for mboit and the A-buffer), the largest k predicted, whether it rendered the
/// A-buffer, what became of mboit (`MOMENTS_MISSED`, `MOMENTS_KEPT`), and its attempts.
fn extras((k, mean_k, slots): (f64, f64, f64), predicted_k: f64, exact: f64, moments: f64, attempts: f64) -> [(&'static str, f64); 7] {
    [
        ("auto_k", k),
        ("auto_mean_k", mean_k),
        ("auto_slots", slots),
        ("auto_predicted_k", predicted_k),
        ("auto_exact", exact),
        ("auto_attempts", attempts),
        ("auto_moments", moments),
    ]
}

impl Method for Auto {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let tolerance = TOLERANCE.of(cx.params);
        let (t, tile) = (cx.targets, cx.tile);
        let pixels = cx.pixels();
        let counts = cx.depth_complexity;
        let sums = self.measure(cx)?;
        // What became of mboit, and its targets' bytes where it was tried and missed (they count
        // in the frame's memory).
        let (moments, tried) = if weighted_average_bound(counts, &sums) <= tolerance {
            match self.try_moments(cx, tolerance)? {
                Ok(done) => return Ok(done),
                Err(bytes) => (MOMENTS_MISSED, bytes),
            }
        } else {
            (0.0, 0)
        };
        let predicted = choose_slots(counts, &sums, tolerance);
        let predicted_k = predicted.as_ref().map_or(0, |s| s.iter().copied().max().unwrap_or(0));
        let mut attempts = 0u32;
        // The hybrid buffers of a missed attempt stay allocated (reused by the next frame).
        let mut hybrid_bytes = 0;
        let mut slots = predicted;
        while let Some(current) = slots.take() {
            attempts += 1;
            let mut report = self.hybrid.render_slots(cx, Slots::PerPixel(&current), ktab::TailSums::Exact)?;
            let bound = read_region(cx.gpu, &t.bound_texture, &t.bound_readback, 4, tile.local())?;
            let worst = bound.iter().copied().fold(0.0f32, f32::max) as f64;
            hybrid_bytes = report.memory_bytes;
            if worst <= tolerance {
                let covered = counts.iter().filter(|&&n| n > 0).count().max(1) as f64;
                let total: u64 = current.iter().map(|&k| k as u64).sum();
                report.memory_bytes += pixels * WORDS * 4 + tried;
                let k = current.iter().copied().max().unwrap_or(0) as f64;
                let tries = attempts as f64 + moments.min(1.0);
                report.extra.extend(extras((k, total as f64 / covered, total as f64), predicted_k as f64, 0.0, moments, tries));
                return Ok(Outcome::Done(report));
            }
            if attempts < 2 {
                slots = widen(&current, counts, &bound, tolerance);
            }
        }
        // The exact A-buffer's pool may need to grow or its tile to shrink: the executor sees to it.
        let mut report = match self.exact.render(&mut cx.with_params(&Params::default()))? {
            Outcome::Done(report) => report,
            other => return Ok(other),
        };
        // Exact up to float32 compositing: (n + 2) roundings of at most 2^-24 each, doubled.
        let rounding = (cx.max_depth_complexity as f64 + 2.0) * ROUNDING;
        // The tile's bound, written from here (the exact resolve writes none).
        let fill = vec![rounding as f32; tile.pixels() as usize];
        cx.gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &t.bound_texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&fill),
            wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * tile.width), rows_per_image: None },
            wgpu::Extent3d { width: tile.width, height: tile.height, depth_or_array_layers: 1 },
        );
        report.error_bound = true;
        report.memory_bytes += pixels * WORDS * 4 + hybrid_bytes + tried;
        let tries = (attempts + 1) as f64 + moments.min(1.0);
        report.extra.extend(extras((0.0, 0.0, 0.0), predicted_k as f64, 1.0, moments, tries));
        Ok(Outcome::Done(report))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn alike(n: u32, alpha: f64) -> PixelSums {
        let tau = -(1.0 - alpha).ln();
        PixelSums { tau: n as f64 * tau, tau2: n as f64 * tau * tau, quant: 0.0, range: 1.0 }
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
        let uneven = PixelSums { tau2: even.tau2 * 1.5, ..even };
        assert!(predicted_bound(20, uneven, 8) > predicted_bound(20, even, 8));
    }

    #[test]
    fn each_pixel_gets_the_smallest_k_that_meets_the_tolerance() {
        let counts = [10, 0, 3];
        let sums = [alike(10, 0.5), PixelSums::default(), alike(3, 0.5)];
        // 0.5^k <= 0.01 first at k = 7; three fragments fit in three slots (no tail); none, none.
        assert_eq!(choose_slots(&counts, &sums, 0.01), Some(vec![7, 0, 3]));
        // 100 fragments of optical depth 0.01 each: 32 slots leave e^-0.32, no k meets 0.01.
        assert_eq!(choose_slots(&[100, 1], &[alike(100, 1.0 - (-0.01f64).exp()), alike(1, 0.5)], 0.01), None);
    }

    #[test]
    fn a_missed_pixel_gets_twice_the_slots_up_to_what_it_can_use() {
        let (counts, slots) = ([40, 12, 40, 3], [8, 8, 32, 3]);
        assert_eq!(widen(&slots, &counts, &[0.5, 0.5, 0.0, 0.0], 0.1), Some(vec![16, 12, 32, 3]));
        assert_eq!(widen(&slots, &counts, &[0.0, 0.0, 0.5, 0.0], 0.1), None);
    }
}
