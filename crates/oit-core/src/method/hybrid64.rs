//! `hybrid64`: single-pass hybrid transparency with 64-bit atomics. Each k-TAB slot holds a
//! whole fragment (depth, alpha, color) in one 64-bit word; the atomic bubble needs each
//! `atomicMax`'s previous value, hence `SHADER_INT64_ATOMIC_ALL_OPS` (min/max without a
//! result does not suffice); the word pushed off the table joins the tail in the same pass.
//! One geometry pass and one full-screen resolve (shaders/hybrid64.wgsl).

use super::{ErrorBound, FRAMES, FrameCtx, Memory, Method, MethodInfo, MethodReport, Order, ParamInfo, ParamKind};
use crate::error::Result;
use crate::pipeline;
use crate::shader::{self, Const};
use crate::targets::{read_buffer, storage_buffer};

pub const INFO: MethodInfo = MethodInfo {
    name: "hybrid64",
    summary: "single-pass hybrid: 64-bit k-TAB words with depth, alpha and color; the evicted join the tail",
    exact: false,
    bounded_memory: true,
    passes: &["insert and accumulate the tail (geometry)", "resolve (full screen)"],
    params: &[ParamInfo {
        name: "k",
        kind: ParamKind::Int { min: 1, max: 32, default: 8 },
        doc: "core size: fragments per pixel kept, sorted, with their colors",
    }],
    features: wgpu::Features::SHADER_INT64.union(wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: Memory::Frame { formula: "W·H·(8k + 36) + 4", bytes: |px, p| memory_bytes(px, p.int("k") as u64) },
    error_bound: ErrorBound::PerPixel,
    create: |_, _| Box::new(Hybrid64 { pipelines: None, buffers: None }),
};

/// Words per pixel of the tail accumulators.
pub const ACCUM_WORDS: u64 = crate::consts::HYBRID64_ACCUM_WORDS as u64;

/// Bytes hybrid64 allocates: k 64-bit words and the tail accumulators per pixel, a counter.
pub fn memory_bytes(pixels: u64, k: u64) -> u64 {
    pixels * (8 * k + 4 * ACCUM_WORDS) + 4
}

struct Pipelines {
    k: u32,
    insert: wgpu::RenderPipeline,
    resolve: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

struct Buffers {
    key: (u64, u32),
    ktab: wgpu::Buffer,
    accum: wgpu::Buffer,
    overflow: wgpu::Buffer,
    readback: wgpu::Buffer,
    group: wgpu::BindGroup,
}

struct Hybrid64 {
    pipelines: Option<Pipelines>,
    buffers: Option<Buffers>,
}

fn build(cx: &FrameCtx<'_>, k: u32) -> Pipelines {
    let d = &cx.gpu.device;
    let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("hybrid64"),
        entries: &(0..3).map(pipeline::storage_entry).collect::<Vec<_>>(),
    });
    let consts = [Const::U32("K", k)];
    let module = shader::module(d, "hybrid64.wgsl", &consts);
    let pl = pipeline::layout(d, &[cx.scene_layout, cx.targets_layout, &layout]);
    Pipelines {
        k,
        insert: pipeline::geometry(d, "hybrid64 insert", &module, &pl, "fs_insert", &[], pipeline::depth_test_only()),
        resolve: pipeline::fullscreen_with_bound(d, "hybrid64 resolve", &module, &pl, "fs_resolve"),
        layout,
    }
}

impl Method for Hybrid64 {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        let k = cx.params.int("k") as u32;
        if self.pipelines.as_ref().is_none_or(|p| p.k != k) {
            self.pipelines = Some(build(cx, k));
            self.buffers = None;
        }
        let t = cx.targets;
        let d = &cx.gpu.device;
        let pixels = t.width as u64 * t.height as u64;
        let p = self.pipelines.as_ref().expect("built above");
        let ktab_bytes = pixels * k as u64 * 8;
        cx.check_per_pixel(&format!("hybrid64 with k = {k}"), (8 * k as u64).max(4 * ACCUM_WORDS))?;
        if self.buffers.as_ref().is_none_or(|b| b.key != (pixels, k)) {
            let ktab = storage_buffer(d, "hybrid64 k-TAB", ktab_bytes, wgpu::BufferUsages::empty());
            let accum = storage_buffer(d, "hybrid64 tail", pixels * ACCUM_WORDS * 4, wgpu::BufferUsages::empty());
            let overflow = storage_buffer(d, "hybrid64 overflow", 4, wgpu::BufferUsages::COPY_SRC);
            let readback = d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("hybrid64 overflow readback"),
                size: 4,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("hybrid64"),
                layout: &p.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: ktab.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: accum.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: overflow.as_entire_binding() },
                ],
            });
            self.buffers = Some(Buffers { key: (pixels, k), ktab, accum, overflow, readback, group });
        }
        let b = self.buffers.as_ref().expect("made above");
        let geo = &cx.scene.transparent;
        let mut enc = d.create_command_encoder(&Default::default());
        enc.clear_buffer(&b.ktab, 0, None);
        enc.clear_buffer(&b.accum, 0, None);
        enc.clear_buffer(&b.overflow, 0, None);
        {
            let mut pass = pipeline::capture_pass(&mut enc, "hybrid64 insert", &t.depth, cx.timer.render_pass("insert"));
            pass.set_pipeline(&p.insert);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            geo.draw_all(&mut pass);
        }
        {
            let mut pass = pipeline::resolve_with_bound(&mut enc, "hybrid64 resolve", t, cx.timer.render_pass("resolve"));
            pass.set_pipeline(&p.resolve);
            pass.set_bind_group(0, &geo.group, &[]);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            pass.draw(0..3, 0..1);
        }
        enc.copy_buffer_to_buffer(&b.overflow, 0, &b.readback, 0, 4);
        cx.gpu.queue.submit([enc.finish()]);
        let raw = read_buffer(cx.gpu, &b.readback, 4)?;
        let tail = u32::from_le_bytes(raw[..4].try_into().expect("4 bytes")) as u64;
        Ok(MethodReport {
            memory_bytes: memory_bytes(pixels, k as u64),
            overflow_fragments: tail,
            extra: vec![("tail_fragments", tail as f64)],
            error_bound: true,
        })
    }
}
