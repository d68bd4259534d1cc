//! `unsorted` and `sorted`: fixed-function over-blending onto the opaque image, in
//! submission order or per mesh back to front by centroid (docs/methods.md).

use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{never, ErrorBound, FrameBytes, Linear, Memory, MethodInfo, Order, FRAMES};
use crate::bindings::COLOR_FORMAT;
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::passes;
use crate::pipeline;

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
    memory: Memory::Frame(FrameBytes { per_pixel: Linear::bytes(0), fixed: 0 }),
    error_bound: ErrorBound::None,
    census: false,
    census_when: never,
    main: None,
    pipelines: &[PIPELINES],
    constants: &[],
    create: |_, _| Box::new(Blend { kind: Blending::Unsorted }),
};

pub const SORTED: MethodInfo = MethodInfo {
    name: "sorted",
    summary: "per-mesh back-to-front sort by centroid, a splat set's splats by their means (3DGS), then over-blending (wrong for interpenetrating meshes)",
    passes: &["sort meshes and splats (CPU)", "blend"],
    order: Order::Submission,
    create: |_, _| Box::new(Blend { kind: Blending::Sorted }),
    ..UNSORTED
};

pub const ADDITIVE: MethodInfo = MethodInfo {
    name: "additive",
    summary: "additive blending (RTR 5.5): C = sum(alpha c) + background; brightens, never attenuates",
    passes: &["blend"],
    order: Order::Rounding,
    create: |_, _| Box::new(Blend { kind: Blending::Additive }),
    ..UNSORTED
};

pub const FILTER: MethodInfo = MethodInfo {
    name: "filter",
    summary: "colored transmission (RTR 5.5): the scene behind multiplied by each surface's 1 - alpha (1 - c)",
    passes: &["blend"],
    order: Order::Rounding,
    create: |_, _| Box::new(Blend { kind: Blending::Filter }),
    ..UNSORTED
};

#[derive(Clone, Copy, PartialEq)]
enum Blending {
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

impl Blending {
    fn blend(self) -> wgpu::BlendState {
        use wgpu::BlendFactor as F;
        let color = match self {
            Blending::Unsorted | Blending::Sorted => component(F::SrcAlpha, F::OneMinusSrcAlpha),
            Blending::Additive => component(F::SrcAlpha, F::One),
            Blending::Filter => component(F::Zero, F::Src),
        };
        wgpu::BlendState { color, alpha: COVERAGE }
    }

    fn entry(self) -> &'static str {
        if self == Blending::Filter {
            "fs_filter"
        } else {
            "fs_blend"
        }
    }
}

const PIPELINES: &[PipelineSpec] = &[
    PipelineSpec::geometry("blend.wgsl", "fs_blend", &[Layout::Scene]),
    PipelineSpec::geometry("blend.wgsl", "fs_filter", &[Layout::Scene]),
];

struct Blend {
    kind: Blending,
}

impl Method for Blend {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let target = wgpu::ColorTargetState { format: COLOR_FORMAT, blend: Some(self.kind.blend()), write_mask: wgpu::ColorWrites::ALL };
        let pipeline = cx.draw_pipeline(spec(PIPELINES, self.kind.entry()), &[], vec![Some(target)], pipeline::depth_test_only());
        let geo = &cx.scene.transparent;
        let mut order: Vec<usize> = (0..geo.placements.len()).collect();
        let vp = cx.camera.matrix_f32();
        // Far to near: larger NDC depth first; behind the eye (w <= 0) first.
        let key = |p: glam::Vec3| {
            let c = vp * p.extend(1.0);
            if c.w > 0.0 {
                c.z / c.w
            } else {
                f32::INFINITY
            }
        };
        // A splat set's splats far to near by their means (3DGS's order), sorted on the host
        // and drawn by one indirect draw a splat (a run a chunk).
        let mut splats: Vec<Option<Vec<SplatRun>>> = Vec::new();
        if self.kind == Blending::Sorted {
            order.sort_by(|&a, &b| key(geo.placements[b].centroid).total_cmp(&key(geo.placements[a].centroid)));
            splats = geo.splat_means.iter().enumerate().map(|(i, means)| (!means.is_empty()).then(|| sorted_splats(cx, i, means, &key))).collect();
        }
        let t = cx.targets;
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = passes::over_base_pass(&mut enc, "blend", t, &t.depth, None, cx.tile, cx.timer.render_pass("blend"));
            pass.set_pipeline(&pipeline);
            if self.kind == Blending::Sorted {
                for &i in &order {
                    match &splats[i] {
                        Some(runs) => runs.iter().for_each(|r| {
                            geo.bind_chunk(&mut pass, r.chunk);
                            match &r.buffer {
                                Some(b) => pass.multi_draw_indirect(b, 0, r.args.len() as u32),
                                None => r.args.iter().for_each(|&[n, _, first, inst]| pass.draw(first..first + n, inst..inst + 1)),
                            }
                        }),
                        None => geo.draw_placement(&mut pass, &geo.placements[i]),
                    }
                }
            } else {
                geo.draw_all(&mut pass);
            }
        }
        cx.gpu.queue.submit([enc.finish()]);
        Ok(Outcome::Done(MethodReport::default()))
    }
}

/// A run of a splat set's sorted draws in one chunk: its indirect draw arguments, and the
/// buffer that holds them (None where the device cannot start an indirect draw at an
/// instance other than 0 and the set has instances: then one direct draw a splat).
struct SplatRun {
    chunk: usize,
    args: Vec<[u32; 4]>,
    buffer: Option<wgpu::Buffer>,
}

/// Placement `i`'s splats (world means `means`) sorted far to near by `key` (ties in the set's
/// order), as its runs of draws (`Geometry::splat_draws`).
fn sorted_splats(cx: &FrameCtx<'_>, i: usize, means: &[glam::Vec3], key: &impl Fn(glam::Vec3) -> f32) -> Vec<SplatRun> {
    use wgpu::util::DeviceExt;
    let keys: Vec<f32> = means.iter().map(|&m| key(m)).collect();
    let mut order: Vec<u32> = (0..means.len() as u32).collect();
    order.sort_by(|&a, &b| keys[b as usize].total_cmp(&keys[a as usize]));
    let geo = &cx.scene.transparent;
    let indirect = cx.gpu.device.features().contains(wgpu::Features::INDIRECT_FIRST_INSTANCE);
    geo.splat_draws(&geo.placements[i], &order)
        .into_iter()
        .map(|(chunk, args)| {
            let buffer = (indirect || args.iter().all(|a| a[3] == 0)).then(|| {
                let contents: Vec<u8> = args.iter().flatten().flat_map(|w| w.to_le_bytes()).collect();
                let desc = wgpu::util::BufferInitDescriptor { label: Some("sorted splats"), contents: &contents, usage: wgpu::BufferUsages::INDIRECT };
                cx.gpu.device.create_buffer_init(&desc)
            });
            SplatRun { chunk, args, buffer }
        })
        .collect()
}
