//! The k-TAB engine under `hybrid`, `ktab` and `auto` (Maule et al. 2013, Algorithm 1): store
//! the nearest keys per pixel by atomic max, compute their visibility, shade core and tail in a
//! second geometry pass, composite. Accumulation in fixed point, so that frames do not depend
//! on fragment order (docs/methods.md, "hybrid"). Each pixel gets a uniform k or its own slots.

use super::accum::{blended, FloatTargets, ADD};
use super::frame::{FrameCtx, MethodReport};
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::{OitError, Result};
use crate::resources::{Counter, StorageGroup};
use crate::shader::Const;

/// Words per pixel of the accumulators, and of the sums (their own binding: the tail's count
/// and sums, the core's sums and T_core, in 64-bit words).
pub const ACCUM_WORDS: u64 = crate::consts::HYBRID_ACCUM_WORDS as u64;
pub const SUM_WORDS: u64 = (crate::consts::HYBRID_TAIL_WORDS + crate::consts::HYBRID_CORE_WORDS) as u64;

/// Bytes at W x H pixels with core size k: k-TAB and visibility (k words each), the
/// accumulators and sums, the slot-offset placeholder (a word: every pixel has k slots)
/// and the overflow counter.
pub fn memory_bytes(pixels: u64, k: u64) -> u64 {
    pixels * (2 * k + ACCUM_WORDS + SUM_WORDS) * 4 + 8
}

/// Bytes with tail = "compact" (Eq. 12's 2k + 2 words a pixel): k-TAB and visibility (k words
/// each) and the tail's RGBA16F sums (2 words), plus the slot-offset placeholder (which also
/// fills the sums' binding: this tail has none) and the overflow counter.
pub fn compact_memory_bytes(pixels: u64, k: u64) -> u64 {
    pixels * (2 * k + COMPACT_TAIL_WORDS) * 4 + 8
}

/// The overflow counter's buffer.
const COUNTER_BYTES: u64 = 4;
/// Words a pixel of the compact tail's RGBA16F target.
const COMPACT_TAIL_WORDS: u64 = 2;
const COMPACT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The binding fs_final_compact reads the compact tail's sums at (group 3).
const COMPACT_BINDINGS: &[(&str, u32)] = &[("compact_sums", 4)];

/// Bytes with each pixel's own slot count (`slots` in all): k-TAB and visibility (a word
/// each per slot), the accumulators and sums, the per-pixel offsets (pixels + 1 words) and
/// the counter.
pub fn memory_bytes_per_pixel(pixels: u64, slots: u64) -> u64 {
    2 * slots * 4 + pixels * (ACCUM_WORDS + SUM_WORDS) * 4 + (pixels + 1) * 4 + 4
}

/// How many k-TAB slots each pixel gets.
pub(crate) enum Slots<'s> {
    /// k for every pixel (the `k` parameter).
    Uniform(u32),
    /// Each pixel its own (row-major, one per pixel; auto's choice).
    PerPixel(&'s [u32]),
}

/// Bindings of the per-pixel slot offsets and of the sums in the group (shaders/hybrid.wgsl).
const OFFSETS: usize = 3;
const SUMS: usize = 4;

const SHADER: &str = "hybrid.wgsl";
/// Group 2: k-TAB, core visibility, accumulators, slot offsets, sums, then the overflow
/// counter.
const OWN: Layout = Layout::Storage(&["ktab", "vis", "accum", "offsets", "tail_words", "overflow"]);
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, OWN];
/// The buffers tail = "compact" keeps (its group binds the census counts at "accum").
const COMPACT_OWN: Layout = Layout::Storage(&["ktab", "vis", "offsets"]);

/// The k-TAB engine's pipelines (hybrid, ktab, auto).
pub(crate) const PIPELINES: &[PipelineSpec] = &[
    PipelineSpec::geometry(SHADER, "fs_store", GROUPS),
    PipelineSpec::compute(SHADER, "cs_visibility", GROUPS),
    PipelineSpec::geometry(SHADER, "fs_shade", GROUPS),
    PipelineSpec::fullscreen(SHADER, "fs_final", GROUPS),
    PipelineSpec::geometry(SHADER, "fs_shade_blend", GROUPS),
    // The blended sums at group 3.
    PipelineSpec::fullscreen(SHADER, "fs_final_blend", &[Layout::Scene, Layout::Targets, OWN, Layout::Textures(BLEND_BINDINGS)]),
    PipelineSpec::fullscreen(SHADER, "fs_clear", GROUPS),
    PipelineSpec::geometry(SHADER, "fs_shade_compact", GROUPS),
    PipelineSpec::fullscreen(SHADER, "fs_final_compact", &[Layout::Scene, Layout::Targets, OWN, Layout::Textures(COMPACT_BINDINGS)]),
];

/// The k-TAB engine's constants besides `k` (its per-pixel slots, its tail, the compact tail),
/// validated with the tail and uniform slots.
pub(crate) const CONSTANTS: &[Const] = &[Const::U32("PER_PIXEL", 0), Const::U32("TAIL", 1), Const::U32("COMPACT", 0)];

/// How the second geometry pass sums the core and the tail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TailSums {
    /// Fixed-point storage atomics: bit-identical under any fragment order.
    Exact,
    /// Fixed-function additive (and max) blending into float targets, as Maule et al. do:
    /// fewer atomics, but float sums that round differently in another order.
    Blend,
    /// Eq. 12's memory: the core blended into the output, the tail into one RGBA16F target, the
    /// tail count from the census; no accumulator words.
    Compact,
}

/// The blended sums' targets, as shaders/hybrid.wgsl's `Shade`: core color and tail count;
/// tail C * alpha and alpha; the quantization sums and the tail's largest channel (max); one
/// minus its smallest (max).
const BLEND_FORMATS: [wgpu::TextureFormat; 4] =
    [wgpu::TextureFormat::Rgba32Float, wgpu::TextureFormat::Rgba32Float, wgpu::TextureFormat::Rgba32Float, wgpu::TextureFormat::R32Float];
const BLEND_BINDINGS: &[(&str, u32)] = &[("shade_core", 0), ("shade_tail", 1), ("shade_quant", 2), ("shade_low", 3)];

/// Bytes a frame pixel of the blended sums' targets.
pub const BLEND_BYTES_PER_PIXEL: u64 = 3 * 16 + 4;

const MAX: wgpu::BlendComponent =
    wgpu::BlendComponent { src_factor: wgpu::BlendFactor::One, dst_factor: wgpu::BlendFactor::One, operation: wgpu::BlendOperation::Max };

fn blend_targets() -> Vec<Option<wgpu::ColorTargetState>> {
    let states = [(ADD, ADD), (ADD, ADD), (ADD, MAX), (MAX, MAX)];
    BLEND_FORMATS
        .iter()
        .zip(states)
        .map(|(&format, (color, alpha))| {
            Some(wgpu::ColorTargetState { format, blend: Some(wgpu::BlendState { color, alpha }), write_mask: wgpu::ColorWrites::ALL })
        })
        .collect()
}

pub(crate) struct KTab {
    /// Whether fragments behind the core form the tail (hybrid) or are discarded (ktab).
    tail: bool,
    buffers: Option<StorageGroup>,
    overflow: Option<Counter>,
    blend: Option<FloatTargets>,
    compact: Option<FloatTargets>,
}

impl KTab {
    pub(crate) fn new(tail: bool) -> Self {
        Self { tail, buffers: None, overflow: None, blend: None, compact: None }
    }

    /// Refuses buffers past a binding, and returns the slots in all and whether they are per pixel.
    fn plan(&self, cx: &FrameCtx<'_>, slots: &Slots<'_>) -> Result<(u64, bool)> {
        let name = if self.tail { "hybrid" } else { "ktab" };
        let pixels = cx.pixels();
        match slots {
            Slots::Uniform(k) => {
                cx.check_per_pixel(&format!("{name} with k = {k}"), 4 * (*k as u64).max(ACCUM_WORDS).max(SUM_WORDS))?;
                Ok((pixels * *k as u64, false))
            }
            Slots::PerPixel(s) => {
                cx.check_per_pixel(&format!("{name}'s accumulators"), 4 * ACCUM_WORDS.max(SUM_WORDS))?;
                let total: u64 = s.iter().map(|&k| k as u64).sum();
                if total * 4 > cx.limits.max_binding_bytes {
                    return Err(OitError::OutOfMemory(format!(
                        "{name} with per-pixel slots needs {total} slots ({} bytes), past the {}-byte storage binding \
                         limit: render a smaller frame or use a larger tolerance",
                        total * 4,
                        cx.limits.max_binding_bytes
                    )));
                }
                Ok((total, true))
            }
        }
    }

    /// One frame with the k-TAB slots `slots` gives each pixel, its sums made as `sums` says.
    pub(crate) fn render_slots(&mut self, cx: &mut FrameCtx<'_>, slots: Slots<'_>, sums: TailSums) -> Result<MethodReport> {
        if sums != TailSums::Exact && !cx.gpu.device.features().contains(wgpu::Features::FLOAT32_BLENDABLE) {
            return Err(OitError::Unsupported(
                "tail = 'blend' and 'compact' blend into float32 targets, which this adapter cannot (FLOAT32_BLENDABLE): use \
                 tail = 'exact'"
                    .into(),
            ));
        }
        if sums == TailSums::Compact {
            // Checked by its own words: it keeps no accumulators, which `plan` counts.
            return self.render_compact(cx, &slots);
        }
        let (total, per_pixel) = self.plan(cx, &slots)?;
        let pixels = cx.pixels();
        let overflow = self.overflow.get_or_insert_with(|| Counter::new(cx.gpu, "hybrid overflow"));
        let sizes = [
            ("ktab", total.max(1) * 4),
            ("vis", total.max(1) * 4),
            ("accum", pixels * ACCUM_WORDS * 4),
            ("offsets", if per_pixel { (pixels + 1) * 4 } else { 4 }),
            ("tail_words", pixels * SUM_WORDS * 4),
        ];
        let b = StorageGroup::ensure(&mut self.buffers, cx.gpu, OWN, &sizes, &[("overflow", overflow)]);
        if let Slots::PerPixel(s) = slots {
            write_offsets(cx, &b.buffers[OFFSETS], s);
        }
        let k = match slots {
            Slots::Uniform(k) => k,
            Slots::PerPixel(_) => 1,
        };
        let consts =
            [Const::U32("K", k), Const::U32("PER_PIXEL", per_pixel as u32), Const::U32("TAIL", self.tail as u32), Const::U32("COMPACT", 0)];
        let mut enc = cx.encoder();
        enc.clear_buffer(&b.buffers[0], 0, None);
        enc.clear_buffer(&b.buffers[2], 0, None);
        enc.clear_buffer(&b.buffers[SUMS], 0, None);
        overflow.clear(&mut enc);
        cx.capture(&mut enc, "store", &cx.capture_pipeline(spec(PIPELINES, "fs_store"), &consts), &b.group);
        cx.dispatch(&mut enc, "visibility", &cx.compute_pipeline(spec(PIPELINES, "cs_visibility"), &consts), &b.group);
        match sums {
            TailSums::Exact => {
                cx.capture(&mut enc, "shade", &cx.capture_pipeline(spec(PIPELINES, "fs_shade"), &consts), &b.group);
                cx.resolve(&mut enc, "final", &cx.resolve_pipeline(spec(PIPELINES, "fs_final"), &consts, true), &b.group, true);
            }
            TailSums::Compact => unreachable!("render_compact"),
            TailSums::Blend => {
                let targets = FloatTargets::ensure(&mut self.blend, cx, &BLEND_FORMATS, BLEND_BINDINGS);
                let shade_blend = spec(PIPELINES, "fs_shade_blend");
                let shade = cx.draw_pipeline(shade_blend, &consts, blend_targets(), crate::pipeline::depth_test_only());
                cx.capture_into(&mut enc, "shade", &shade, &b.group, &targets.attachments(&[wgpu::Color::TRANSPARENT; 4]));
                let fin = cx.resolve_pipeline(spec(PIPELINES, "fs_final_blend"), &consts, true);
                cx.resolve_groups(&mut enc, "final", &fin, &[&b.group, &targets.group], true);
            }
        }
        let tally = overflow.tally(&mut enc, Some("tail_fragments"));
        cx.submit(enc);
        // What the frame allocated: the formulas above name each buffer, and the tests hold
        // these bytes to them.
        let mut memory = b.bytes() + COUNTER_BYTES;
        if sums == TailSums::Blend {
            memory += BLEND_BYTES_PER_PIXEL * cx.targets.width as u64 * cx.targets.height as u64;
        }
        Ok(MethodReport { memory_bytes: memory, tallies: vec![tally], error_bound: true, ..Default::default() })
    }
}

impl KTab {
    /// hybrid with tail = "compact" (shaders/hybrid.wgsl, COMPACT): store and visibility as the
    /// other tails, then the tile's output zeroed, the core blended into it and the tail's sums
    /// into one RGBA16F target, and the final pass added over it. Group 2's accumulator binding
    /// is the frame's census counts buffer, holding this tile's counts.
    fn render_compact(&mut self, cx: &mut FrameCtx<'_>, slots: &Slots<'_>) -> Result<MethodReport> {
        let Slots::Uniform(k) = *slots else { unreachable!("auto renders exact tails") };
        cx.check_per_pixel(&format!("hybrid with k = {k}"), 4 * k as u64)?;
        let pixels = cx.pixels();
        let overflow = self.overflow.get_or_insert_with(|| Counter::new(cx.gpu, "hybrid overflow"));
        let sizes = [("ktab", pixels * k as u64 * 4), ("vis", pixels * k as u64 * 4), ("offsets", 4)];
        let b = StorageGroup::ensure(&mut self.buffers, cx.gpu, COMPACT_OWN, &sizes, &[]);
        let counts = &cx.targets.counts;
        cx.gpu.queue.write_buffer(counts, 0, bytemuck::cast_slice(cx.depth_complexity));
        let resources = [
            ("ktab", b.buffers[0].as_entire_binding()),
            ("vis", b.buffers[1].as_entire_binding()),
            ("accum", counts.as_entire_binding()),
            ("offsets", b.buffers[2].as_entire_binding()),
            // No sums: the unused slot offsets fill their binding too (never accessed).
            ("tail_words", b.buffers[2].as_entire_binding()),
            ("overflow", overflow.buffer.as_entire_binding()),
        ];
        let group = cx.group(OWN, &resources);
        // ATOMIC64 0: the sums' binding holds the 4-byte slot-offset placeholder, which the 32-bit
        // pairs' declaration accepts (a 64-bit array would need 8 bytes); nothing reads it.
        let consts =
            [Const::U32("K", k), Const::U32("PER_PIXEL", 0), Const::U32("TAIL", 1), Const::U32("COMPACT", 1), Const::U32("ATOMIC64", 0)];
        let sums = FloatTargets::ensure(&mut self.compact, cx, &[COMPACT_FORMAT], COMPACT_BINDINGS);
        let shade = cx.draw_pipeline(
            spec(PIPELINES, "fs_shade_compact"),
            &consts,
            vec![blended(crate::bindings::COLOR_FORMAT, ADD), blended(COMPACT_FORMAT, ADD)],
            crate::pipeline::depth_test_only(),
        );
        let clear = cx.resolve_pipeline(spec(PIPELINES, "fs_clear"), &consts, false);
        let fin = cx.resolve_pipeline_adding(spec(PIPELINES, "fs_final_compact"), &consts);
        let mut enc = cx.encoder();
        enc.clear_buffer(&b.buffers[0], 0, None);
        enc.clear_buffer(&b.buffers[1], 0, None);
        overflow.clear(&mut enc);
        cx.capture(&mut enc, "store", &cx.capture_pipeline(spec(PIPELINES, "fs_store"), &consts), &group);
        cx.dispatch(&mut enc, "visibility", &cx.compute_pipeline(spec(PIPELINES, "cs_visibility"), &consts), &group);
        cx.resolve(&mut enc, "clear", &clear, &group, false);
        let out = wgpu::RenderPassColorAttachment {
            view: &cx.targets.out,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
        };
        let mut attachments = vec![Some(out)];
        attachments.extend(sums.attachments(&[wgpu::Color::TRANSPARENT]));
        cx.capture_into(&mut enc, "shade", &shade, &group, &attachments);
        cx.resolve_groups(&mut enc, "final", &fin, &[&group, &sums.group], true);
        let tally = overflow.tally(&mut enc, Some("tail_fragments"));
        cx.submit(enc);
        let target_pixels = cx.targets.width as u64 * cx.targets.height as u64;
        Ok(MethodReport {
            memory_bytes: b.bytes() + target_pixels * COMPACT_TAIL_WORDS * 4 + COUNTER_BYTES,
            tallies: vec![tally],
            error_bound: true,
            ..Default::default()
        })
    }
}

/// Each pixel's first slot (an exclusive prefix sum of its count) and the total at the end.
fn write_offsets(cx: &FrameCtx<'_>, buffer: &wgpu::Buffer, slots: &[u32]) {
    let mut offsets = Vec::with_capacity(slots.len() + 1);
    let mut sum = 0u32;
    for &k in slots {
        offsets.push(sum);
        sum += k;
    }
    offsets.push(sum);
    cx.gpu.queue.write_buffer(buffer, 0, bytemuck::cast_slice(&offsets));
}
