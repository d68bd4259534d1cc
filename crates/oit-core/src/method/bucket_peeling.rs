//! `bucket_peeling`: bucket depth peeling (Liu et al. 2009; RTR 5.5): up to `buckets` layers
//! per pixel from a uniform split of its depth range, the nearest fragment of each bucket
//! kept, the others dropped and counted (shaders/bucket_peeling.wgsl).

use super::{ErrorBound, FRAMES, FrameCtx, Memory, Method, MethodInfo, MethodReport, Order, ParamInfo, ParamKind};
use crate::error::Result;
use crate::pipeline;
use crate::shader::{self, Const};
use crate::targets::{read_buffer, storage_buffer};

pub const INFO: MethodInfo = MethodInfo {
    name: "bucket_peeling",
    summary: "bucket depth peeling: the depth range split into buckets, one fragment kept per bucket",
    exact: false,
    bounded_memory: true,
    passes: &["depth bounds (geometry)", "bucket keys (geometry)", "bucket colors (geometry)", "resolve (full screen)"],
    params: &[ParamInfo { name: "buckets", kind: ParamKind::Int { min: 1, max: 32, default: 32 }, doc: "buckets (layers) per pixel" }],
    features: wgpu::Features::SHADER_INT64.union(wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX),
    order: Order::BitwiseExceptTies,
    antialias_modes: FRAMES,
    memory: Memory::Frame { formula: "W·H·(8 + 24·buckets) + 4", bytes: |px, p| memory_bytes(px, p.int("buckets") as u64) },
    error_bound: ErrorBound::None,
    create: |_, _| Box::new(Buckets { pipelines: None, buffers: None }),
};

/// Bytes bucket_peeling allocates: depth bounds, and a 64-bit key and a color per bucket.
pub fn memory_bytes(pixels: u64, buckets: u64) -> u64 {
    pixels * (8 + buckets * (8 + 16)) + 4
}

struct Pipelines {
    buckets: u32,
    bounds: wgpu::RenderPipeline,
    keys: wgpu::RenderPipeline,
    shade: wgpu::RenderPipeline,
    resolve: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

struct Buffers {
    key: (u64, u32),
    group: wgpu::BindGroup,
    bounds: wgpu::Buffer,
    keys: wgpu::Buffer,
    dropped: wgpu::Buffer,
    readback: wgpu::Buffer,
    _colors: wgpu::Buffer,
}

struct Buckets {
    pipelines: Option<Pipelines>,
    buffers: Option<Buffers>,
}

fn build(cx: &FrameCtx<'_>, buckets: u32) -> Pipelines {
    let d = &cx.gpu.device;
    let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("bucket peeling"),
        entries: &(0..4).map(pipeline::storage_entry).collect::<Vec<_>>(),
    });
    let module = shader::module(d, "bucket_peeling.wgsl", &[Const::U32("BUCKETS", buckets)]);
    let pl = pipeline::layout(d, &[cx.scene_layout, cx.targets_layout, &layout]);
    let geometry = |label, fs| pipeline::geometry(d, label, &module, &pl, fs, &[], pipeline::depth_test_only());
    Pipelines {
        buckets,
        bounds: geometry("bucket bounds", "fs_bounds"),
        keys: geometry("bucket keys", "fs_keys"),
        shade: geometry("bucket colors", "fs_shade"),
        resolve: pipeline::fullscreen(d, "bucket resolve", &module, &pl, "fs_resolve"),
        layout,
    }
}

impl Method for Buckets {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        let buckets = cx.params.int("buckets") as u32;
        if self.pipelines.as_ref().is_none_or(|p| p.buckets != buckets) {
            self.pipelines = Some(build(cx, buckets));
            self.buffers = None;
        }
        let t = cx.targets;
        let d = &cx.gpu.device;
        let pixels = t.width as u64 * t.height as u64;
        let p = self.pipelines.as_ref().expect("built above");
        let color_bytes = pixels * buckets as u64 * 16;
        cx.check_per_pixel(&format!("bucket_peeling with {buckets} buckets"), 16 * buckets as u64)?;
        if self.buffers.as_ref().is_none_or(|b| b.key != (pixels, buckets)) {
            let bounds = storage_buffer(d, "bucket bounds", pixels * 8, wgpu::BufferUsages::empty());
            let keys = storage_buffer(d, "bucket keys", pixels * buckets as u64 * 8, wgpu::BufferUsages::empty());
            let colors = storage_buffer(d, "bucket colors", color_bytes, wgpu::BufferUsages::empty());
            let dropped = storage_buffer(d, "bucket dropped", 4, wgpu::BufferUsages::COPY_SRC);
            let readback = d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("bucket dropped readback"),
                size: 4,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("bucket peeling"),
                layout: &p.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: bounds.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: keys.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: colors.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: dropped.as_entire_binding() },
                ],
            });
            self.buffers = Some(Buffers { key: (pixels, buckets), group, bounds, keys, dropped, readback, _colors: colors });
        }
        let b = self.buffers.as_ref().expect("made above");
        let geo = &cx.scene.transparent;
        let mut enc = d.create_command_encoder(&Default::default());
        enc.clear_buffer(&b.bounds, 0, None);
        enc.clear_buffer(&b.keys, 0, None);
        enc.clear_buffer(&b.dropped, 0, None);
        for (pipeline, label) in [(&p.bounds, "bounds"), (&p.keys, "keys"), (&p.shade, "colors")] {
            let mut pass = pipeline::capture_pass(&mut enc, label, &t.depth, cx.timer.render_pass(label));
            pass.set_pipeline(pipeline);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            geo.draw_all(&mut pass);
        }
        {
            let mut pass = pipeline::resolve_pass(&mut enc, "bucket resolve", &t.out, cx.timer.render_pass("resolve"));
            pass.set_pipeline(&p.resolve);
            pass.set_bind_group(0, &geo.group, &[]);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            pass.draw(0..3, 0..1);
        }
        enc.copy_buffer_to_buffer(&b.dropped, 0, &b.readback, 0, 4);
        cx.gpu.queue.submit([enc.finish()]);
        let raw = read_buffer(cx.gpu, &b.readback, 4)?;
        let dropped = u32::from_le_bytes(raw[..4].try_into().expect("4 bytes")) as u64;
        Ok(MethodReport { memory_bytes: memory_bytes(pixels, buckets as u64), overflow_fragments: dropped, ..Default::default() })
    }
}
