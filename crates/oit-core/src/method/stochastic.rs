//! `stochastic`: stochastic transparency (Enderton et al. 2010) with alpha correction, on
//! `samples` coverage samples per pixel kept in a storage buffer: a stochastic depth pass,
//! an accumulation pass and a resolve (shaders/stochastic.wgsl). Deterministic for a seed.

use super::weighted::{accumulation_targets, target, ACCUM_FORMAT, AUX_FORMAT, REVEAL};
use super::{ErrorBound, FRAMES, FrameCtx, Memory, Method, MethodInfo, MethodReport, Order, ParamInfo, ParamKind};
use crate::error::Result;
use crate::gpu_types::FrameUniform;
use crate::pipeline;
use crate::shader::{self, Const};
use crate::targets::storage_buffer;

pub const INFO: MethodInfo = MethodInfo {
    name: "stochastic",
    summary: "stochastic transparency: random per-sample coverage by alpha, stochastic depth, alpha-corrected average",
    exact: false,
    bounded_memory: true,
    passes: &["stochastic depth (geometry)", "accumulate (geometry, blended)", "resolve (full screen)"],
    params: &[
        ParamInfo {
            name: "samples",
            kind: ParamKind::Int { min: 1, max: 64, default: 8 },
            doc: "coverage samples per pixel (the estimate's noise falls as 1/sqrt(samples))",
        },
        ParamInfo {
            name: "seed",
            kind: ParamKind::Int { min: 0, max: u32::MAX as i64, default: 0 },
            doc: "random seed of the coverage masks",
        },
    ],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Submission,
    antialias_modes: FRAMES,
    memory: Memory::Frame { formula: "W·H·(4·samples + 20)", bytes: |px, p| memory_bytes(px, p.int("samples") as u64) },
    error_bound: ErrorBound::None,
    create: |_, _| Box::new(Stochastic { pipelines: None, buffers: None }),
};

/// Bytes stochastic allocates: `samples` depth words per pixel and two float targets.
pub fn memory_bytes(pixels: u64, samples: u64) -> u64 {
    pixels * (samples * 4 + 16 + 4)
}

struct Pipelines {
    samples: u32,
    depth: wgpu::RenderPipeline,
    accum: wgpu::RenderPipeline,
    resolve: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    resolve_layout: wgpu::BindGroupLayout,
}

struct Buffers {
    key: (u32, u32, u32),
    samples: wgpu::Buffer,
    accum: wgpu::TextureView,
    aux: wgpu::TextureView,
    group: wgpu::BindGroup,
    resolve_group: wgpu::BindGroup,
}

struct Stochastic {
    pipelines: Option<Pipelines>,
    buffers: Option<Buffers>,
}

fn build(cx: &FrameCtx<'_>, samples: u32) -> Pipelines {
    let d = &cx.gpu.device;
    let module = shader::module(d, "stochastic.wgsl", &[Const::U32("SAMPLES", samples)]);
    // The accumulation targets are read only by the resolve, so they get their own group.
    let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("stochastic samples"),
        entries: &[pipeline::storage_entry(0)],
    });
    let resolve_layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("stochastic resolve"),
        entries: &[pipeline::float_texture_entry(1), pipeline::float_texture_entry(2)],
    });
    let pl = pipeline::layout(d, &[cx.scene_layout, cx.targets_layout, &layout]);
    let resolve_pl = pipeline::layout(d, &[cx.scene_layout, cx.targets_layout, &resolve_layout]);
    let targets = accumulation_targets(REVEAL);
    Pipelines {
        samples,
        depth: pipeline::geometry(d, "stochastic depth", &module, &pl, "fs_depth", &[], pipeline::depth_test_only()),
        accum: pipeline::geometry(d, "stochastic accumulate", &module, &pl, "fs_accum", &targets, pipeline::depth_test_only()),
        resolve: pipeline::fullscreen(d, "stochastic resolve", &module, &resolve_pl, "fs_resolve"),
        layout,
        resolve_layout,
    }
}

impl Method for Stochastic {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        let samples = cx.params.int("samples") as u32;
        let seed = cx.params.int("seed") as u32;
        if self.pipelines.as_ref().is_none_or(|p| p.samples != samples) {
            self.pipelines = Some(build(cx, samples));
            self.buffers = None;
        }
        let t = cx.targets;
        let d = &cx.gpu.device;
        let p = self.pipelines.as_ref().expect("built above");
        let pixels = t.width as u64 * t.height as u64;
        cx.check_per_pixel(&format!("stochastic with {samples} samples"), 4 * samples as u64)?;
        let key = (t.width, t.height, samples);
        if self.buffers.as_ref().is_none_or(|b| b.key != key) {
            let samples_buf = storage_buffer(d, "stochastic samples", pixels * samples as u64 * 4, wgpu::BufferUsages::empty());
            let accum = target(d, (t.width, t.height), ACCUM_FORMAT);
            let aux = target(d, (t.width, t.height), AUX_FORMAT);
            let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("stochastic"),
                layout: &p.layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: samples_buf.as_entire_binding() }],
            });
            let resolve_group = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("stochastic resolve"),
                layout: &p.resolve_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&accum) },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&aux) },
                ],
            });
            self.buffers = Some(Buffers { key, samples: samples_buf, accum, aux, group, resolve_group });
        }
        let b = self.buffers.as_ref().expect("made above");
        let offset = std::mem::offset_of!(FrameUniform, seed) as u64;
        cx.gpu.queue.write_buffer(cx.frame_uniform, offset, bytemuck::bytes_of(&seed));
        let geo = &cx.scene.transparent;
        let mut enc = d.create_command_encoder(&Default::default());
        enc.clear_buffer(&b.samples, 0, None);
        {
            let mut pass = pipeline::capture_pass(&mut enc, "stochastic depth", &t.depth, cx.timer.render_pass("depth"));
            pass.set_pipeline(&p.depth);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            geo.draw_all(&mut pass);
        }
        {
            let attach = |view, clear| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
                })
            };
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("stochastic accumulate"),
                color_attachments: &[attach(&b.accum, wgpu::Color::TRANSPARENT), attach(&b.aux, wgpu::Color::WHITE)],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &t.depth,
                    depth_ops: None,
                    stencil_ops: None,
                }),
                timestamp_writes: cx.timer.render_pass("accumulate"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&p.accum);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.group, &[]);
            geo.draw_all(&mut pass);
        }
        {
            let mut pass = pipeline::resolve_pass(&mut enc, "stochastic resolve", &t.out, cx.timer.render_pass("resolve"));
            pass.set_pipeline(&p.resolve);
            pass.set_bind_group(0, &geo.group, &[]);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &b.resolve_group, &[]);
            pass.draw(0..3, 0..1);
        }
        cx.gpu.queue.submit([enc.finish()]);
        Ok(MethodReport { memory_bytes: memory_bytes(pixels, samples as u64), ..Default::default() })
    }
}
