//! `unsorted` and `sorted`: fixed-function over-blending onto the opaque image, in
//! submission order or per mesh back to front by centroid (docs/methods.md).

use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{never, ErrorBound, FrameBytes, Linear, Memory, MethodInfo, Order, FRAMES};
use crate::bindings::COLOR_FORMAT;
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::{OitError, Result};
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
        if self.kind == Blending::Sorted {
            let memory_bytes = sorted(cx, &pipeline)?;
            return Ok(Outcome::Done(MethodReport { memory_bytes, ..Default::default() }));
        }
        let t = cx.targets;
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = passes::over_base_pass(&mut enc, "blend", t, &t.depth, None, cx.tile, cx.timer.render_pass("blend"));
            pass.set_pipeline(&pipeline);
            cx.scene.transparent.draw_all(&mut pass);
        }
        cx.gpu.queue.submit([enc.finish()]);
        Ok(Outcome::Done(MethodReport::default()))
    }
}

/// One draw of a sorted frame: a placement's triangles, or `count` sorted splats of chunk
/// `chunk` whose draw arguments are at `at` in the batch.
enum SortedDraw {
    Placement(usize),
    Splats { chunk: usize, at: u32, count: u32 },
}

/// Bytes of one splat's indirect draw arguments.
const SPLAT_DRAW_BYTES: u64 = 16;

/// `sorted`: the placements far to near by their centroids, a splat set's splats far to near
/// by their means (3DGS's order, ties in the set's order), sorted on the host each frame and
/// drawn by one indirect draw a splat (a run a chunk). The draw arguments go through one
/// buffer of at most what the memory budget leaves beside the targets (`memory_left`): where
/// the splats' 16 bytes each do not fit, the frame is drawn in batches, a pass each, each
/// blending over the last. Returns the buffer's bytes (0 without splats).
fn sorted(cx: &mut FrameCtx<'_>, pipeline: &wgpu::RenderPipeline) -> Result<u64> {
    let scene = cx.scene;
    let geo = &scene.transparent;
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
    let mut order: Vec<usize> = (0..geo.placements.len()).collect();
    order.sort_by(|&a, &b| key(geo.placements[b].centroid).total_cmp(&key(geo.placements[a].centroid)));
    let splats: u64 = geo.splat_means.iter().map(|m| m.len() as u64).sum();
    let room = cx.memory_left.map_or(u64::MAX, |b| b / SPLAT_DRAW_BYTES);
    if splats > 0 && room == 0 {
        return Err(OitError::OutOfMemory(format!(
            "'sorted' draws each splat by {SPLAT_DRAW_BYTES} bytes of draw arguments, and the memory_budget leaves {} bytes \
             beside the frame's targets: raise memory_budget",
            cx.memory_left.unwrap_or(0)
        )));
    }
    let batch = splats.min(room) as usize;
    // Without INDIRECT_FIRST_INSTANCE an instanced set's splats are drawn directly, one a draw.
    let indirect = cx.gpu.device.features().contains(wgpu::Features::INDIRECT_FIRST_INSTANCE);
    let buffer = (batch > 0).then(|| {
        cx.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sorted splats"),
            size: batch as u64 * SPLAT_DRAW_BYTES,
            usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    });
    let span = cx.timer.span("blend");
    let mut args: Vec<[u32; 4]> = Vec::with_capacity(batch);
    let mut draws: Vec<SortedDraw> = Vec::new();
    let mut first = true;
    // Records and submits the draws gathered so far, their arguments written first.
    let mut flush = |args: &mut Vec<[u32; 4]>, draws: &mut Vec<SortedDraw>, last: bool| {
        if let Some(b) = &buffer {
            cx.gpu.queue.write_buffer(b, 0, bytemuck::cast_slice(args));
        }
        let t = cx.targets;
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        {
            let times = cx.timer.span_render(span, first, last);
            let mut pass = if first {
                passes::over_base_pass(&mut enc, "blend", t, &t.depth, None, cx.tile, times)
            } else {
                passes::over_pass(&mut enc, "blend", t, &t.depth, None, cx.tile, times)
            };
            pass.set_pipeline(pipeline);
            for d in draws.iter() {
                match *d {
                    SortedDraw::Placement(i) => geo.draw_placement(&mut pass, &geo.placements[i]),
                    SortedDraw::Splats { chunk, at, count } => {
                        geo.bind_chunk(&mut pass, chunk);
                        let run = &args[at as usize..(at + count) as usize];
                        match &buffer {
                            Some(b) if indirect || run[0][3] == 0 => pass.multi_draw_indirect(b, at as u64 * SPLAT_DRAW_BYTES, count),
                            _ => run.iter().for_each(|&[n, _, v, i]| pass.draw(v..v + n, i..i + 1)),
                        }
                    }
                }
            }
        }
        cx.gpu.queue.submit([enc.finish()]);
        first = false;
        args.clear();
        draws.clear();
    };
    for &i in &order {
        let means = &geo.splat_means[i];
        if means.is_empty() {
            draws.push(SortedDraw::Placement(i));
            continue;
        }
        let keys: Vec<f32> = means.iter().map(|&m| key(m)).collect();
        let mut splat_order: Vec<u32> = (0..means.len() as u32).collect();
        splat_order.sort_by(|&a, &b| keys[b as usize].total_cmp(&keys[a as usize]));
        drop(keys);
        let slot = geo.splat_slots(&geo.placements[i]);
        // A run is one placement's (each instance of a set draws the same chunks).
        let mut fresh = true;
        for k in splat_order {
            if args.len() == batch {
                flush(&mut args, &mut draws, false);
            }
            let (chunk, a) = slot(k);
            let at = args.len() as u32;
            args.push(a);
            match draws.last_mut() {
                Some(SortedDraw::Splats { chunk: c, count, .. }) if *c == chunk && !fresh => *count += 1,
                _ => draws.push(SortedDraw::Splats { chunk, at, count: 1 }),
            }
            fresh = false;
        }
    }
    flush(&mut args, &mut draws, true);
    Ok(buffer.map_or(0, |b| b.size()))
}
