//! `unsorted` and `sorted`: fixed-function over-blending onto the opaque image, in
//! submission order or per mesh back to front by centroid (docs/methods.md).

use super::{FrameCtx, Method, MethodInfo, MethodReport};
use crate::error::{OitError, Result};
use crate::pipeline;
use crate::shader;
use crate::targets::COLOR_FORMAT;

pub const UNSORTED: MethodInfo = MethodInfo {
    name: "unsorted",
    summary: "over-blending in submission order (what a renderer does without OIT)",
    exact: false,
    bounded_memory: true,
    passes: &["blend"],
    params: &[],
    create: |_, _| Box::new(Blend::new(false)),
};

pub const SORTED: MethodInfo = MethodInfo {
    name: "sorted",
    summary: "per-mesh back-to-front sort by centroid, then over-blending (wrong for interpenetrating meshes)",
    exact: false,
    bounded_memory: true,
    passes: &["sort meshes (CPU)", "blend"],
    params: &[],
    create: |_, _| Box::new(Blend::new(true)),
};

/// Over operator with straight alpha; alpha accumulates coverage a + (1 - a) * A.
const OVER: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::SrcAlpha,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
};

struct Blend {
    sort: bool,
    pipeline: Option<wgpu::RenderPipeline>,
}

impl Blend {
    fn new(sort: bool) -> Self {
        Self { sort, pipeline: None }
    }
}

/// Builds the blend pipeline; shared with the floor measurement of the benchmark.
pub(crate) fn blend_pipeline(cx: &FrameCtx<'_>) -> Result<wgpu::RenderPipeline> {
    if !cx.gpu.has(wgpu::Features::FLOAT32_BLENDABLE) {
        return Err(OitError::Unsupported(format!(
            "adapter '{}' cannot blend into RGBA32F targets (feature FLOAT32_BLENDABLE), which the blend \
             methods (unsorted, sorted) need; the exact and storage-based methods still work",
            cx.gpu.info.name
        )));
    }
    let d = &cx.gpu.device;
    let module = shader::module(d, "blend.wgsl", &[]);
    let layout = pipeline::layout(d, &[cx.scene_layout]);
    let target = wgpu::ColorTargetState { format: COLOR_FORMAT, blend: Some(OVER), write_mask: wgpu::ColorWrites::ALL };
    Ok(pipeline::geometry(d, "blend", &module, &layout, "fs_blend", &[Some(target)], pipeline::depth_test_only()))
}

impl Method for Blend {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        if self.pipeline.is_none() {
            self.pipeline = Some(blend_pipeline(cx)?);
        }
        let geo = &cx.scene.transparent;
        let mut order: Vec<usize> = (0..geo.meshes.len()).collect();
        if self.sort {
            let vp = cx.camera.matrix_f32();
            // Far to near: larger NDC depth first; meshes behind the eye (w <= 0) go first.
            let key = |i: usize| {
                let c = vp * geo.meshes[i].centroid.extend(1.0);
                if c.w > 0.0 { c.z / c.w } else { f32::INFINITY }
            };
            order.sort_by(|&a, &b| key(b).total_cmp(&key(a)));
        }
        let t = cx.targets;
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_texture(
            t.base_texture.as_image_copy(),
            t.out_texture.as_image_copy(),
            t.out_texture.size(),
        );
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("blend"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &t.out,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &t.depth,
                    depth_ops: None,
                    stencil_ops: None,
                }),
                timestamp_writes: cx.timer.render_pass("blend"),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(self.pipeline.as_ref().expect("built above"));
            pass.set_bind_group(0, &geo.group, &[]);
            for i in order {
                let m = geo.meshes[i];
                if m.triangles > 0 {
                    pass.draw(3 * m.first_triangle..3 * (m.first_triangle + m.triangles), 0..1);
                }
            }
        }
        cx.gpu.queue.submit([enc.finish()]);
        Ok(MethodReport::default())
    }
}
