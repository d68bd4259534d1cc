//! `unsorted` and `sorted`: fixed-function over-blending onto the opaque image, in
//! submission order or per mesh back to front by centroid (docs/methods.md).

use super::{ErrorBound, FRAMES, FrameCtx, Memory, Method, MethodInfo, MethodReport, Order};
use crate::error::Result;
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
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Submission,
    antialias_modes: FRAMES,
    memory: Memory::Frame { formula: "0", bytes: |_, _| 0 },
    error_bound: ErrorBound::None,
    create: |_, _| Box::new(Blend::new(Kind::Unsorted)),
};

pub const SORTED: MethodInfo = MethodInfo {
    name: "sorted",
    summary: "per-mesh back-to-front sort by centroid, then over-blending (wrong for interpenetrating meshes)",
    exact: false,
    bounded_memory: true,
    passes: &["sort meshes (CPU)", "blend"],
    params: &[],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Submission,
    antialias_modes: FRAMES,
    memory: Memory::Frame { formula: "0", bytes: |_, _| 0 },
    error_bound: ErrorBound::None,
    create: |_, _| Box::new(Blend::new(Kind::Sorted)),
};

pub const ADDITIVE: MethodInfo = MethodInfo {
    name: "additive",
    summary: "additive blending (RTR 5.5): C = sum(alpha c) + background; brightens, never attenuates",
    exact: false,
    bounded_memory: true,
    passes: &["blend"],
    params: &[],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Rounding,
    antialias_modes: FRAMES,
    memory: Memory::Frame { formula: "0", bytes: |_, _| 0 },
    error_bound: ErrorBound::None,
    create: |_, _| Box::new(Blend::new(Kind::Additive)),
};

pub const FILTER: MethodInfo = MethodInfo {
    name: "filter",
    summary: "colored transmission (RTR 5.5): the scene behind multiplied by each surface's 1 - alpha (1 - c)",
    exact: false,
    bounded_memory: true,
    passes: &["blend"],
    params: &[],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Rounding,
    antialias_modes: FRAMES,
    memory: Memory::Frame { formula: "0", bytes: |_, _| 0 },
    error_bound: ErrorBound::None,
    create: |_, _| Box::new(Blend::new(Kind::Filter)),
};

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Unsorted,
    Sorted,
    Additive,
    Filter,
}

const fn component(src_factor: wgpu::BlendFactor, dst_factor: wgpu::BlendFactor) -> wgpu::BlendComponent {
    wgpu::BlendComponent { src_factor, dst_factor, operation: wgpu::BlendOperation::Add }
}

/// Coverage accumulates as a + (1 - a) * A for every blend method.
const COVERAGE: wgpu::BlendComponent = component(wgpu::BlendFactor::One, wgpu::BlendFactor::OneMinusSrcAlpha);

impl Kind {
    fn blend(self) -> wgpu::BlendState {
        use wgpu::BlendFactor as F;
        let color = match self {
            Kind::Unsorted | Kind::Sorted => component(F::SrcAlpha, F::OneMinusSrcAlpha),
            Kind::Additive => component(F::SrcAlpha, F::One),
            Kind::Filter => component(F::Zero, F::Src),
        };
        wgpu::BlendState { color, alpha: COVERAGE }
    }

    fn entry(self) -> &'static str {
        if self == Kind::Filter {
            "fs_filter"
        } else {
            "fs_blend"
        }
    }
}

struct Blend {
    kind: Kind,
    pipeline: Option<wgpu::RenderPipeline>,
}

impl Blend {
    fn new(kind: Kind) -> Self {
        Self { kind, pipeline: None }
    }
}

fn blend_pipeline(cx: &FrameCtx<'_>, kind: Kind) -> Result<wgpu::RenderPipeline> {
    let d = &cx.gpu.device;
    let module = shader::module(d, "blend.wgsl", &[]);
    let layout = pipeline::layout(d, &[cx.scene_layout]);
    let target = wgpu::ColorTargetState { format: COLOR_FORMAT, blend: Some(kind.blend()), write_mask: wgpu::ColorWrites::ALL };
    Ok(pipeline::geometry(d, "blend", &module, &layout, kind.entry(), &[Some(target)], pipeline::depth_test_only()))
}

impl Method for Blend {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport> {
        if self.pipeline.is_none() {
            self.pipeline = Some(blend_pipeline(cx, self.kind)?);
        }
        let geo = &cx.scene.transparent;
        let mut order: Vec<usize> = (0..geo.meshes.len()).collect();
        if self.kind == Kind::Sorted {
            let vp = cx.camera.matrix_f32();
            // Far to near: larger NDC depth first; meshes behind the eye (w <= 0) go first.
            let key = |i: usize| {
                let c = vp * geo.meshes[i].centroid.extend(1.0);
                if c.w > 0.0 {
                    c.z / c.w
                } else {
                    f32::INFINITY
                }
            };
            order.sort_by(|&a, &b| key(b).total_cmp(&key(a)));
        }
        let t = cx.targets;
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = pipeline::over_base_pass(&mut enc, "blend", t, &t.depth, None, cx.timer.render_pass("blend"));
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
