//! `hybrid` (Maule et al. 2013, Algorithm 1) and `ktab`, its core alone with the tail
//! discarded. Two geometry passes, a visibility pass and a final composite; accumulation in
//! fixed point so that frames do not depend on fragment order (docs/methods.md).

use std::collections::HashMap;

use super::{ErrorBound, FRAMES, FrameCtx, Memory, Method, MethodInfo, MethodReport, Order, ParamInfo, ParamKind};
use crate::error::Result;
use crate::pipeline;
use crate::shader::{self, Const};
use crate::targets::{read_buffer, storage_buffer};

const K_PARAM: ParamInfo = ParamInfo {
    name: "k",
    kind: ParamKind::Int { min: 1, max: 32, default: 8 },
    doc: "core size: fragments per pixel kept exactly, sorted (k-TAB slots)",
};

pub const HYBRID: MethodInfo = MethodInfo {
    name: "hybrid",
    summary: "hybrid transparency: the k nearest fragments exactly (k-TAB), the rest by weighted average",
    exact: false,
    bounded_memory: true,
    passes: &["store k-TAB (geometry)", "visibility (compute)", "shade core and tail (geometry)", "final composite (full screen)"],
    params: &[K_PARAM],
    features: wgpu::Features::empty(),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::PerPixel,
    create: |_, _| Box::new(Hybrid::new(true)),
};

pub const KTAB: MethodInfo = MethodInfo {
    name: "ktab",
    summary: "k-TAB: the k nearest fragments composited exactly, the others discarded (hybrid's core alone)",
    exact: false,
    bounded_memory: true,
    passes: &["store k-TAB (geometry)", "visibility (compute)", "shade core (geometry)", "final composite (full screen)"],
    params: &[K_PARAM],
    features: wgpu::Features::empty(),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::PerPixel,
    create: |_, _| Box::new(Hybrid::new(false)),
};

/// Words per pixel of the accumulators.
pub const ACCUM_WORDS: u64 = crate::consts::HYBRID_ACCUM_WORDS as u64;

/// Bytes hybrid allocates at W x H pixels with core size k: k-TAB and visibility (k words
/// each), the accumulators, and the overflow counter.
pub fn memory_bytes(pixels: u64, k: u64) -> u64 {
    pixels * (2 * k + ACCUM_WORDS) * 4 + 4
}

const MEMORY: Memory = Memory::Frame { formula: "W·H·(2k + 18)·4 + 4", bytes: |px, p| memory_bytes(px, p.int("k") as u64) };

/// Bytes with each pixel's own slot count (`slots` in all): k-TAB and visibility (a word
/// each per slot), the accumulators, the per-pixel offsets (pixels + 1 words) and the counter.
pub fn memory_bytes_per_pixel(pixels: u64, slots: u64) -> u64 {
    2 * slots * 4 + pixels * ACCUM_WORDS * 4 + (pixels + 1) * 4 + 4
}

/// How many k-TAB slots each pixel gets.
pub(crate) enum Slots<'s> {
    /// k for every pixel (the `k` parameter).
    Uniform(u32),
    /// Each pixel its own (row-major, one per pixel; auto's choice).
    PerPixel(&'s [u32]),
}

/// Pipelines key for per-pixel slots (k itself is the key otherwise).
const PER_PIXEL_KEY: u32 = 0;

struct Pipelines {
    store: wgpu::RenderPipeline,
    visibility: wgpu::ComputePipeline,
    shade: wgpu::RenderPipeline,
    finish: wgpu::RenderPipeline,
}

struct Buffers {
    /// (pixels, slots in all, per-pixel)
    key: (u64, u64, bool),
    ktab: wgpu::Buffer,
    offsets: wgpu::Buffer,
    _vis: wgpu::Buffer,
    accum: wgpu::Buffer,
    overflow: wgpu::Buffer,
    overflow_readback: wgpu::Buffer,
    group: wgpu::BindGroup,
}

pub(crate) struct Hybrid {
    tail: bool,
    layout: Option<wgpu::BindGroupLayout>,
    /// Pipelines by k (k is a shader constant): switching k, as auto does, rebuilds nothing.
    pipelines: HashMap<u32, Pipelines>,
    buffers: Option<Buffers>,
}

impl Hybrid {
    pub(crate) fn new(tail: bool) -> Self {
        Self { tail, layout: None, pipelines: HashMap::new(), buffers: None }
    }

    fn build(&self, cx: &FrameCtx<'_>, layout: &wgpu::BindGroupLayout, k: u32) -> Pipelines {
        let d = &cx.gpu.device;
        let consts = [
            Const::U32("K", k.max(1)),
            Const::U32("PER_PIXEL", (k == PER_PIXEL_KEY) as u32),
            Const::U32("TAIL", self.tail as u32),
        ];
        let module = shader::module(d, "hybrid.wgsl", &consts);
        let pl = pipeline::layout(d, &[cx.scene_layout, cx.targets_layout, layout]);
        let store = pipeline::geometry(d, "hybrid store", &module, &pl, "fs_store", &[], pipeline::depth_test_only());
        let shade = pipeline::geometry(d, "hybrid shade", &module, &pl, "fs_shade", &[], pipeline::depth_test_only());
        let finish = pipeline::fullscreen_with_bound(d, "hybrid final", &module, &pl, "fs_final");
        let visibility = pipeline::compute(d, &pl, &module, "cs_visibility");
        Pipelines { store, visibility, shade, finish }
    }

    fn reserve(&mut self, cx: &FrameCtx<'_>, pixels: u64, slots: &Slots<'_>) -> Result<()> {
        let name = if self.tail { "hybrid" } else { "ktab" };
        let (total, per_pixel) = match slots {
            Slots::Uniform(k) => {
                cx.check_per_pixel(&format!("{name} with k = {k}"), 4 * (*k as u64).max(ACCUM_WORDS))?;
                (pixels * *k as u64, false)
            }
            Slots::PerPixel(s) => {
                cx.check_per_pixel(&format!("{name}'s accumulators"), 4 * ACCUM_WORDS)?;
                let total: u64 = s.iter().map(|&k| k as u64).sum();
                if total * 4 > cx.limits.max_binding_bytes {
                    return Err(crate::error::OitError::OutOfMemory(format!(
                        "{name} with per-pixel slots needs {total} slots ({} bytes), past the {}-byte storage binding \
                         limit: render a smaller frame or use a larger tolerance",
                        total * 4,
                        cx.limits.max_binding_bytes
                    )));
                }
                (total, true)
            }
        };
        let d = &cx.gpu.device;
        if let (Slots::PerPixel(s), Some(b)) = (slots, &self.buffers) {
            if b.key == (pixels, total, true) {
                write_offsets(cx, &b.offsets, s);
                return Ok(());
            }
        }
        if self.buffers.as_ref().is_some_and(|b| b.key == (pixels, total, per_pixel)) {
            return Ok(());
        }
        self.buffers = None;
        let ktab_bytes = total.max(1) * 4;
        let accum_bytes = pixels * ACCUM_WORDS * 4;
        let ktab = storage_buffer(d, "k-TAB", ktab_bytes, wgpu::BufferUsages::empty());
        let vis = storage_buffer(d, "core visibility", ktab_bytes, wgpu::BufferUsages::empty());
        let accum = storage_buffer(d, "hybrid accumulators", accum_bytes, wgpu::BufferUsages::empty());
        let offsets_bytes = if per_pixel { (pixels + 1) * 4 } else { 4 };
        let offsets = storage_buffer(d, "slot offsets", offsets_bytes, wgpu::BufferUsages::COPY_DST);
        let overflow = storage_buffer(d, "hybrid overflow", 4, wgpu::BufferUsages::COPY_SRC);
        let overflow_readback = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("overflow readback"),
            size: 4,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("hybrid"),
            layout: self.layout.as_ref().expect("made before reserve"),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: ktab.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: vis.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: accum.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: overflow.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: offsets.as_entire_binding() },
            ],
        });
        if let Slots::PerPixel(s) = slots {
            write_offsets(cx, &offsets, s);
        }
        self.buffers =
            Some(Buffers { key: (pixels, total, per_pixel), ktab, offsets, _vis: vis, accum, overflow, overflow_readback, group });
        Ok(())
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

impl Method for Hybrid {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        let k = cx.params.int("k") as u32;
        self.render_slots(cx, Slots::Uniform(k))
    }
}

impl Hybrid {
    /// One frame with the k-TAB slots `slots` gives each pixel.
    pub(crate) fn render_slots(&mut self, cx: &mut FrameCtx<'_>, slots: Slots<'_>) -> Result<MethodReport> {
        let k = match slots {
            Slots::Uniform(k) => k,
            Slots::PerPixel(_) => PER_PIXEL_KEY,
        };
        if self.layout.is_none() {
            self.layout = Some(cx.gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("hybrid"),
                entries: &(0..5).map(pipeline::storage_entry).collect::<Vec<_>>(),
            }));
        }
        if !self.pipelines.contains_key(&k) {
            let built = self.build(cx, self.layout.as_ref().expect("made above"), k);
            self.pipelines.insert(k, built);
        }
        let t = cx.targets;
        let pixels = t.width as u64 * t.height as u64;
        self.reserve(cx, pixels, &slots)?;
        let p = &self.pipelines[&k];
        let b = self.buffers.as_ref().expect("reserved above");
        let geo = &cx.scene.transparent;
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&b.ktab, 0, None);
        enc.clear_buffer(&b.accum, 0, None);
        enc.clear_buffer(&b.overflow, 0, None);
        {
            let mut pass = pipeline::capture_pass(&mut enc, "hybrid store", &t.depth, cx.timer.render_pass("store"));
            pass.set_pipeline(&p.store);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            geo.draw_all(&mut pass);
        }
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("hybrid visibility"),
                timestamp_writes: cx.timer.compute_pass("visibility"),
            });
            pass.set_pipeline(&p.visibility);
            pass.set_bind_group(0, &geo.group, &[]);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            pass.dispatch_workgroups(t.width.div_ceil(8), t.height.div_ceil(8), 1);
        }
        {
            let mut pass = pipeline::capture_pass(&mut enc, "hybrid shade", &t.depth, cx.timer.render_pass("shade"));
            pass.set_pipeline(&p.shade);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            geo.draw_all(&mut pass);
        }
        {
            let mut pass = pipeline::resolve_with_bound(&mut enc, "hybrid final", t, cx.timer.render_pass("final"));
            pass.set_pipeline(&p.finish);
            pass.set_bind_group(0, &geo.group, &[]);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            pass.draw(0..3, 0..1);
        }
        enc.copy_buffer_to_buffer(&b.overflow, 0, &b.overflow_readback, 0, 4);
        cx.gpu.queue.submit([enc.finish()]);
        let raw = read_buffer(cx.gpu, &b.overflow_readback, 4)?;
        let overflow = u32::from_le_bytes(raw[..4].try_into().expect("4 bytes")) as u64;
        let memory = match slots {
            Slots::Uniform(k) => memory_bytes(pixels, k as u64),
            Slots::PerPixel(_) => memory_bytes_per_pixel(pixels, b.key.1),
        };
        Ok(MethodReport {
            memory_bytes: memory,
            overflow_fragments: overflow,
            extra: vec![("tail_fragments", overflow as f64)],
            error_bound: true,
        })
    }
}
