//! `depth_peeling` and `dual_depth_peeling`: one geometry pass per layer (per two layers for
//! dual), each shading the layer(s) found by the pass before and finding the next with 64-bit
//! atomic min/max over (depth, triangle) keys, so coplanar fragments peel one by one
//! (shaders/peel.wgsl, docs/methods.md).

use super::{ErrorBound, FRAMES, FrameCtx, Memory, Method, MethodInfo, MethodReport, Order, ParamInfo, ParamKind};
use crate::error::Result;
use crate::pipeline;
use crate::shader::{self, Const};
use crate::targets::{read_buffer, storage_buffer};

const LAYERS: ParamInfo = ParamInfo {
    name: "layers",
    kind: ParamKind::Int { min: 0, max: 1 << 20, default: 0 },
    doc: "most layers to peel; 0 peels until no fragment is left (the census depth complexity)",
};

pub const DEPTH_PEELING: MethodInfo = MethodInfo {
    name: "depth_peeling",
    summary: "front-to-back depth peeling with the under operator: one geometry pass per layer, exact",
    exact: true,
    bounded_memory: true,
    passes: &["per layer: peel (geometry) and composite (compute)", "resolve (full screen)"],
    params: &[LAYERS],
    features: wgpu::Features::SHADER_INT64.union(wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX),
    order: Order::BitwiseExceptTies,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::Exact,
    create: |_, _| Box::new(Peel::new(false)),
};

pub const DUAL_DEPTH_PEELING: MethodInfo = MethodInfo {
    name: "dual_depth_peeling",
    summary: "dual depth peeling (Bavoil & Myers 2008): nearest and farthest layers per pass, exact",
    exact: true,
    bounded_memory: true,
    passes: &["per two layers: peel (geometry) and composite (compute)", "resolve (full screen)"],
    params: &[LAYERS],
    features: wgpu::Features::SHADER_INT64.union(wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX),
    order: Order::BitwiseExceptTies,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::Exact,
    create: |_, _| Box::new(Peel::new(true)),
};

/// Words of per-pixel accumulation.
pub const PEEL_WORDS: u64 = crate::consts::PEEL_WORDS as u64;

/// Bytes either peeling method allocates: four 64-bit keys, two layer colors and the
/// accumulators per pixel, and a counter.
pub fn memory_bytes(pixels: u64) -> u64 {
    pixels * (4 * 8 + 2 * 16 + PEEL_WORDS * 4) + 4
}

const MEMORY: Memory = Memory::Frame { formula: "W·H·100 + 4", bytes: |px, _| memory_bytes(px) };

struct Pipelines {
    init: wgpu::ComputePipeline,
    peel: wgpu::RenderPipeline,
    composite: wgpu::ComputePipeline,
    resolve: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

struct Buffers {
    pixels: u64,
    group: wgpu::BindGroup,
    peeled: wgpu::Buffer,
    readback: wgpu::Buffer,
    _keep: Vec<wgpu::Buffer>,
}

struct Peel {
    dual: bool,
    pipelines: Option<Pipelines>,
    buffers: Option<Buffers>,
}

impl Peel {
    fn new(dual: bool) -> Self {
        Self { dual, pipelines: None, buffers: None }
    }

    fn build(&self, cx: &FrameCtx<'_>) -> Pipelines {
        let d = &cx.gpu.device;
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("peel"),
            entries: &(0..4).map(pipeline::storage_entry).collect::<Vec<_>>(),
        });
        let module = shader::module(d, "peel.wgsl", &[Const::U32("DUAL", self.dual as u32)]);
        let pl = pipeline::layout(d, &[cx.scene_layout, cx.targets_layout, &layout]);
        let compute = |entry: &str| pipeline::compute(d, &pl, &module, entry);
        Pipelines {
            init: compute("cs_init"),
            peel: pipeline::geometry(d, "peel", &module, &pl, "fs_peel", &[], pipeline::depth_test_only()),
            composite: compute("cs_composite"),
            resolve: pipeline::fullscreen(d, "peel resolve", &module, &pl, "fs_resolve"),
            layout,
        }
    }

    fn reserve(&mut self, cx: &FrameCtx<'_>, pixels: u64) -> Result<()> {
        if self.buffers.as_ref().is_some_and(|b| b.pixels == pixels) {
            return Ok(());
        }
        let d = &cx.gpu.device;
        let name = if self.dual { "dual_depth_peeling" } else { "depth_peeling" };
        cx.check_per_pixel(name, 4 * PEEL_WORDS.max(8))?;
        let keys = storage_buffer(d, "peel keys", pixels * 32, wgpu::BufferUsages::empty());
        let layers = storage_buffer(d, "peel layers", pixels * 32, wgpu::BufferUsages::empty());
        let acc = storage_buffer(d, "peel accumulators", pixels * PEEL_WORDS * 4, wgpu::BufferUsages::empty());
        let peeled = storage_buffer(d, "peeled count", 4, wgpu::BufferUsages::COPY_SRC);
        let readback = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("peeled readback"),
            size: 4,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let p = self.pipelines.as_ref().expect("built before reserve");
        let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("peel"),
            layout: &p.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: keys.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: layers.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: acc.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: peeled.as_entire_binding() },
            ],
        });
        self.buffers = Some(Buffers { pixels, group, peeled, readback, _keep: vec![keys, layers, acc] });
        Ok(())
    }
}

impl Method for Peel {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        if self.pipelines.is_none() {
            self.pipelines = Some(self.build(cx));
        }
        let t = cx.targets;
        let pixels = t.width as u64 * t.height as u64;
        self.reserve(cx, pixels)?;
        let limit = cx.params.int("layers") as u64;
        let n = cx.max_depth_complexity as u64;
        let layers = if limit == 0 { n } else { limit.min(n) };
        // The first pass only finds; each later pass shades one layer (two when dual).
        let passes = if self.dual { layers.div_ceil(2) } else { layers } + 1;
        let p = self.pipelines.as_ref().expect("built above");
        let b = self.buffers.as_ref().expect("reserved above");
        let geo = &cx.scene.transparent;
        let groups = (t.width.div_ceil(8), t.height.div_ceil(8));
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&b.peeled, 0, None);
        let span = cx.timer.span("peel");
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("peel init"),
                timestamp_writes: cx.timer.span_compute(span, true, false),
            });
            pass.set_pipeline(&p.init);
            pass.set_bind_group(0, &geo.group, &[]);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
        }
        for i in 0..passes {
            {
                let mut pass = pipeline::capture_pass(&mut enc, "peel", &t.depth, None);
                pass.set_pipeline(&p.peel);
                pass.set_bind_group(1, &t.group, &[]);
                pass.set_bind_group(2, &b.group, &[]);
                geo.draw_all(&mut pass);
            }
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("peel composite"),
                timestamp_writes: cx.timer.span_compute(span, false, i + 1 == passes),
            });
            pass.set_pipeline(&p.composite);
            pass.set_bind_group(0, &geo.group, &[]);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
        }
        {
            let mut pass = pipeline::resolve_pass(&mut enc, "peel resolve", &t.out, cx.timer.render_pass("resolve"));
            pass.set_pipeline(&p.resolve);
            pass.set_bind_group(0, &geo.group, &[]);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            pass.draw(0..3, 0..1);
        }
        enc.copy_buffer_to_buffer(&b.peeled, 0, &b.readback, 0, 4);
        cx.gpu.queue.submit([enc.finish()]);
        let raw = read_buffer(cx.gpu, &b.readback, 4)?;
        let peeled = u32::from_le_bytes(raw[..4].try_into().expect("4 bytes")) as u64;
        Ok(MethodReport {
            memory_bytes: memory_bytes(pixels),
            overflow_fragments: cx.fragments.saturating_sub(peeled),
            extra: vec![("geometry_passes", passes as f64), ("peeled_fragments", peeled as f64)],
            ..Default::default()
        })
    }
}
