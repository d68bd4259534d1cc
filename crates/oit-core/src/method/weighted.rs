//! `wsum`, `wavg` and `wboit`: one geometry pass with additive (and, for wboit's revealage,
//! multiplicative) blending into two float targets, then a full-screen resolve.

use super::{ErrorBound, FRAMES, FrameCtx, Memory, Method, MethodInfo, MethodReport, Order, ParamInfo, ParamKind};
use crate::error::Result;
use crate::pipeline;
use crate::shader::{self, Const};

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Sum,
    Average,
    Blended,
}

pub const WSUM: MethodInfo = MethodInfo {
    name: "wsum",
    summary: "weighted sum (Meshkin 2007): sum(alpha C) + background (1 - sum(alpha)); saturates",
    exact: false,
    bounded_memory: true,
    passes: &["accumulate (geometry, blended)", "resolve (full screen)"],
    params: &[],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Rounding,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::None,
    create: |_, _| Box::new(Weighted::new(Kind::Sum)),
};

pub const WAVG: MethodInfo = MethodInfo {
    name: "wavg",
    summary: "weighted average (Bavoil & Myers 2008): average color, transmittance (1 - mean alpha)^n",
    exact: false,
    bounded_memory: true,
    passes: &["accumulate (geometry, blended)", "resolve (full screen)"],
    params: &[],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Rounding,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::None,
    create: |_, _| Box::new(Weighted::new(Kind::Average)),
};

/// Weight functions of McGuire & Bavoil 2013 by equation number.
pub const WBOIT_WEIGHTS: &[&str] = &["eq10", "eq7", "eq8", "eq9"];

pub const WBOIT: MethodInfo = MethodInfo {
    name: "wboit",
    summary: "weighted blended OIT (McGuire & Bavoil 2013): depth-weighted average, exact total coverage",
    exact: false,
    bounded_memory: true,
    passes: &["accumulate (geometry, blended)", "resolve (full screen)"],
    params: &[ParamInfo {
        name: "weight",
        kind: ParamKind::Choice { choices: WBOIT_WEIGHTS, default: "eq10" },
        doc: "weight function (paper's eq. 7-10); eq7-9 use the view distance, eq10 the window depth",
    }],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Rounding,
    antialias_modes: FRAMES,
    memory: MEMORY,
    error_bound: ErrorBound::None,
    create: |_, _| Box::new(Weighted::new(Kind::Blended)),
};

pub(crate) const ACCUM_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub(crate) const AUX_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// Bytes the weighted methods allocate: an RGBA32F and an R32F target.
pub fn memory_bytes(pixels: u64) -> u64 {
    pixels * (16 + 4)
}

const MEMORY: Memory = Memory::Frame { formula: "W·H·20", bytes: |px, _| memory_bytes(px) };

pub(crate) const ADD: wgpu::BlendComponent =
    wgpu::BlendComponent { src_factor: wgpu::BlendFactor::One, dst_factor: wgpu::BlendFactor::One, operation: wgpu::BlendOperation::Add };

/// dst * (1 - src): revealage, the product of (1 - alpha).
pub(crate) const REVEAL: wgpu::BlendComponent = wgpu::BlendComponent {
    src_factor: wgpu::BlendFactor::Zero,
    dst_factor: wgpu::BlendFactor::OneMinusSrc,
    operation: wgpu::BlendOperation::Add,
};

struct Pipelines {
    weight: String,
    accumulate: wgpu::RenderPipeline,
    resolve: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

struct Targets {
    size: (u32, u32),
    accum: wgpu::TextureView,
    aux: wgpu::TextureView,
    group: wgpu::BindGroup,
}

struct Weighted {
    kind: Kind,
    pipelines: Option<Pipelines>,
    targets: Option<Targets>,
}

impl Weighted {
    fn new(kind: Kind) -> Self {
        Self { kind, pipelines: None, targets: None }
    }

    fn build(&self, cx: &FrameCtx<'_>, weight: &str) -> Pipelines {
        let d = &cx.gpu.device;
        let eq = weight.trim_start_matches("eq").parse::<u32>().expect("choices are eqN");
        let module = shader::module(d, "weighted.wgsl", &[Const::U32("WEIGHT", eq)]);
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("weighted"),
            entries: &[pipeline::float_texture_entry(0), pipeline::float_texture_entry(1)],
        });
        let targets = accumulation_targets(if self.kind == Kind::Blended { REVEAL } else { ADD });
        let (fs, resolve_fs) = match self.kind {
            Kind::Sum => ("fs_sum", "fs_resolve_wsum"),
            Kind::Average => ("fs_sum", "fs_resolve_wavg"),
            Kind::Blended => ("fs_wboit", "fs_resolve_wboit"),
        };
        let accumulate = pipeline::geometry(
            d,
            "weighted accumulate",
            &module,
            &pipeline::layout(d, &[cx.scene_layout]),
            fs,
            &targets,
            pipeline::depth_test_only(),
        );
        let resolve = pipeline::fullscreen(
            d,
            "weighted resolve",
            &module,
            &pipeline::layout(d, &[cx.scene_layout, cx.targets_layout, &layout]),
            resolve_fs,
        );
        Pipelines { weight: weight.to_string(), accumulate, resolve, layout }
    }
}

/// The two accumulation targets: premultiplied color summed in ACCUM_FORMAT, and the
/// auxiliary target (ACCUM_FORMAT's companion) blended by `aux_blend`.
pub(crate) fn accumulation_targets(aux_blend: wgpu::BlendComponent) -> [Option<wgpu::ColorTargetState>; 2] {
    [
        Some(wgpu::ColorTargetState {
            format: ACCUM_FORMAT,
            blend: Some(wgpu::BlendState { color: ADD, alpha: ADD }),
            write_mask: wgpu::ColorWrites::ALL,
        }),
        Some(wgpu::ColorTargetState {
            format: AUX_FORMAT,
            blend: Some(wgpu::BlendState { color: aux_blend, alpha: aux_blend }),
            write_mask: wgpu::ColorWrites::ALL,
        }),
    ]
}

pub(crate) fn target(device: &wgpu::Device, size: (u32, u32), format: wgpu::TextureFormat) -> wgpu::TextureView {
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("weighted accumulation"),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

impl Method for Weighted {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        let weight = if self.kind == Kind::Blended { cx.params.choice("weight").to_string() } else { "eq10".into() };
        if self.pipelines.as_ref().is_none_or(|p| p.weight != weight) {
            self.pipelines = Some(self.build(cx, &weight));
            self.targets = None;
        }
        let p = self.pipelines.as_ref().expect("built above");
        let t = cx.targets;
        let size = (t.width, t.height);
        if self.targets.as_ref().is_none_or(|x| x.size != size) {
            let d = &cx.gpu.device;
            let accum = target(d, size, ACCUM_FORMAT);
            let aux = target(d, size, AUX_FORMAT);
            let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("weighted"),
                layout: &p.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&accum) },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&aux) },
                ],
            });
            self.targets = Some(Targets { size, accum, aux, group });
        }
        let w = self.targets.as_ref().expect("made above");
        let aux_clear = if self.kind == Kind::Blended { wgpu::Color::WHITE } else { wgpu::Color::TRANSPARENT };
        let attach = |view, clear| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
            })
        };
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("weighted accumulate"),
                color_attachments: &[attach(&w.accum, wgpu::Color::TRANSPARENT), attach(&w.aux, aux_clear)],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &t.depth,
                    depth_ops: None,
                    stencil_ops: None,
                }),
                timestamp_writes: cx.timer.render_pass("accumulate"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&p.accumulate);
            cx.scene.transparent.draw_all(&mut pass);
        }
        {
            let mut pass = pipeline::resolve_pass(&mut enc, "weighted resolve", &t.out, cx.timer.render_pass("resolve"));
            pass.set_pipeline(&p.resolve);
            pass.set_bind_group(0, &cx.scene.transparent.group, &[]);
            pass.set_bind_group(1, &t.group, &[]);
            pass.set_bind_group(2, &w.group, &[]);
            pass.draw(0..3, 0..1);
        }
        cx.gpu.queue.submit([enc.finish()]);
        Ok(MethodReport { memory_bytes: memory_bytes(size.0 as u64 * size.1 as u64), ..Default::default() })
    }
}
