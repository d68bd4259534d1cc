//! `adaptive` (Salvi et al. 2011) and `mlab` (Salvi & Vaidyanathan 2014) as the seeds design
//! them: a fixed number of entries a pixel, updated by each fragment inside its pixel's
//! critical section (shaders/common/pixel_lock.wgsl), so that memory does not grow with the
//! fragments. `adaptive` builds its visibility function in a first geometry pass and shades by
//! it in a second (shaders/adaptive.wgsl); `mlab` blends its layers in one (shaders/mlab.wgsl).
//! The list versions they replace are `adaptive_lists` and `mlab_lists`.

use super::accum::{blended, FloatTargets, ACCUM_FORMAT, ADD};
use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{never, ErrorBound, FrameBytes, Linear, Memory, MethodInfo, Order, FRAMES};
use super::params::{ParamInfo, ParamKind};
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::resources::{Readback, StorageGroup};
use crate::shader::Const;

/// Group 2: the entries, the lock words, and the two lock counts.
const ADAPTIVE_OWN: Layout = Layout::Storage(&["nodes", "locks", "lock_stats"]);
const MLAB_OWN: Layout = Layout::Storage(&["layers", "locks", "lock_stats"]);
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, ADAPTIVE_OWN];
const MLAB_GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, MLAB_OWN];
/// adaptive's resolve also reads the shading pass's sums at group 3.
const SUMS: &[(&str, u32)] = &[("accum_tex", 0)];
const RESOLVE: &[Layout] = &[Layout::Scene, Layout::Targets, ADAPTIVE_OWN, Layout::Textures(SUMS)];

const ADAPTIVE_SHADER: &str = "adaptive.wgsl";
const ADAPTIVE_PIPELINES: &[PipelineSpec] = &[
    PipelineSpec::geometry(ADAPTIVE_SHADER, "fs_insert", GROUPS),
    PipelineSpec::geometry(ADAPTIVE_SHADER, "fs_shade", GROUPS),
    PipelineSpec::fullscreen(ADAPTIVE_SHADER, "fs_resolve", RESOLVE),
];

const MLAB_SHADER: &str = "mlab.wgsl";
const MLAB_PIPELINES: &[PipelineSpec] =
    &[PipelineSpec::geometry(MLAB_SHADER, "fs_insert", MLAB_GROUPS), PipelineSpec::fullscreen(MLAB_SHADER, "fs_resolve", MLAB_GROUPS)];

/// Bytes of a pixel's lock word (with its entry count), and of the two lock counts.
const LOCK_BYTES: u64 = 4;
const LOCK_STATS_BYTES: u64 = 8;
/// Bytes of an adaptive node (depth, transmittance) and of an MLAB layer (color, transmittance, depth).
const NODE_BYTES: u64 = 8;
const LAYER_BYTES: u64 = 20;

/// adaptive: N nodes, the lock word and the shading pass's RGBA32F sums a pixel.
const ADAPTIVE_BYTES: FrameBytes = FrameBytes { per_pixel: Linear::per("nodes", NODE_BYTES, LOCK_BYTES + 16), fixed: LOCK_STATS_BYTES };

/// mlab: k layers and the lock word a pixel.
const MLAB_BYTES: FrameBytes = FrameBytes { per_pixel: Linear::per("layers", LAYER_BYTES, LOCK_BYTES), fixed: LOCK_STATS_BYTES };

pub const ADAPTIVE: MethodInfo = MethodInfo {
    name: "adaptive",
    summary: "adaptive transparency: a visibility function of at most `nodes` steps per pixel, built under per-pixel locks",
    exact: false,
    bounded_memory: true,
    passes: &[
        "insert into the visibility function (geometry, per-pixel lock)",
        "shade by it (geometry, blended)",
        "composite (full screen)",
    ],
    params: &[ParamInfo {
        name: "nodes",
        kind: ParamKind::Int { min: 1, max: 32, default: 8 },
        doc: "steps of the per-pixel visibility function",
    }],
    features: wgpu::Features::FLOAT32_BLENDABLE,
    order: Order::Submission,
    antialias_modes: FRAMES,
    memory: Memory::Frame(ADAPTIVE_BYTES),
    error_bound: ErrorBound::None,
    census: false,
    census_when: never,
    main: Some("nodes"),
    pipelines: &[ADAPTIVE_PIPELINES],
    create: |_, _| Box::new(Locked::new(Kind::Adaptive)),
};

pub const MLAB: MethodInfo = MethodInfo {
    name: "mlab",
    summary: "multi-layer alpha blending: `layers` depth-sorted blended layers per pixel under per-pixel locks, the farthest two merged on overflow",
    passes: &["insert into the layers (geometry, per-pixel lock)", "composite (full screen)"],
    params: &[ParamInfo { name: "layers", kind: ParamKind::Int { min: 1, max: 32, default: 4 }, doc: "blended layers kept per pixel" }],
    features: wgpu::Features::empty(),
    memory: Memory::Frame(MLAB_BYTES),
    main: Some("layers"),
    pipelines: &[MLAB_PIPELINES],
    create: |_, _| Box::new(Locked::new(Kind::Mlab)),
    ..ADAPTIVE
};

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Adaptive,
    Mlab,
}

struct Locked {
    kind: Kind,
    buffers: Option<StorageGroup>,
    sums: Option<FloatTargets>,
    lock_stats: Option<Readback>,
}

impl Locked {
    fn new(kind: Kind) -> Self {
        Self { kind, buffers: None, sums: None, lock_stats: None }
    }
}

impl Method for Locked {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let (param, entry_bytes) = match self.kind {
            Kind::Adaptive => ("nodes", NODE_BYTES),
            Kind::Mlab => ("layers", LAYER_BYTES),
        };
        let n = cx.params.int(param) as u32;
        let name = if self.kind == Kind::Adaptive { "adaptive" } else { "mlab" };
        cx.check_per_pixel(&format!("{name} with {param} = {n}"), entry_bytes * n as u64)?;
        let pixels = cx.pixels();
        let consts = match self.kind {
            Kind::Adaptive => vec![Const::U32("NODES", n), Const::U32("NODES_PLUS_ONE", n + 1), Const::U32("READ_NODES", 0)],
            Kind::Mlab => vec![Const::U32("LAYERS", n), Const::U32("LAYERS_PLUS_ONE", n + 1)],
        };
        let (own, entries) = match self.kind {
            Kind::Adaptive => (ADAPTIVE_OWN, "nodes"),
            Kind::Mlab => (MLAB_OWN, "layers"),
        };
        let sizes = [(entries, pixels * entry_bytes * n as u64), ("locks", pixels * LOCK_BYTES), ("lock_stats", LOCK_STATS_BYTES)];
        let b = StorageGroup::ensure(&mut self.buffers, cx.gpu, own, &sizes, &[]);
        let readback = self.lock_stats.get_or_insert_with(|| Readback::new(cx.gpu, "lock counts", LOCK_STATS_BYTES));
        let mut enc = cx.encoder();
        enc.clear_buffer(&b.buffers[1], 0, None);
        enc.clear_buffer(&b.buffers[2], 0, None);
        let memory = match self.kind {
            Kind::Adaptive => {
                let pipelines = ADAPTIVE_PIPELINES;
                // The passes after the insert only read the nodes (READ_NODES: plain loads).
                let read = [consts[0], consts[1], Const::U32("READ_NODES", 1)];
                cx.capture(&mut enc, "insert", &cx.capture_pipeline(spec(pipelines, "fs_insert"), &consts), &b.group);
                let sums = FloatTargets::ensure(&mut self.sums, cx, &[ACCUM_FORMAT], SUMS);
                let target = blended(ACCUM_FORMAT, ADD);
                let shade = cx.draw_pipeline(spec(pipelines, "fs_shade"), &read, vec![target], crate::pipeline::depth_test_only());
                cx.capture_into(&mut enc, "shade", &shade, &b.group, &sums.attachments(&[wgpu::Color::TRANSPARENT]));
                let resolve = cx.resolve_pipeline(spec(pipelines, "fs_resolve"), &read, false);
                cx.resolve_groups(&mut enc, "composite", &resolve, &[&b.group, &sums.group], false);
                ADAPTIVE_BYTES.at(pixels, cx.params)
            }
            Kind::Mlab => {
                let pipelines = MLAB_PIPELINES;
                cx.capture(&mut enc, "insert", &cx.capture_pipeline(spec(pipelines, "fs_insert"), &consts), &b.group);
                let resolve = cx.resolve_pipeline(spec(pipelines, "fs_resolve"), &consts, false);
                cx.resolve(&mut enc, "composite", &resolve, &b.group, false);
                MLAB_BYTES.at(pixels, cx.params)
            }
        };
        readback.copy(&mut enc, &b.buffers[2]);
        cx.submit(enc);
        let raw = readback.read(cx.gpu)?;
        let count = |i: usize| u32::from_le_bytes(raw[4 * i..4 * i + 4].try_into().expect("4 bytes")) as u64;
        let (failures, waits) = (count(0), count(1));
        Ok(Outcome::Done(MethodReport {
            memory_bytes: memory,
            // A fragment that gave up on its pixel's lock is one the structure did not take.
            overflow_fragments: failures,
            extra: vec![("lock_failures", failures as f64), ("lock_waits", waits as f64)],
            ..Default::default()
        }))
    }
}
