//! `bucket_peeling`: bucket depth peeling (Liu et al. 2009; RTR 5.5): up to `buckets` layers
//! per pixel from a uniform split of its depth range, the nearest fragment of each bucket
//! kept, the others dropped and counted (shaders/bucket_peeling.wgsl).

use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{buffer_sizes, never, Buffer, ErrorBound, FRAMES, FrameBytes, Linear, Memory, MethodInfo, Order};
use super::params::IntParam;
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::resources::{Counter, StorageGroup};

const BUCKETS: IntParam = IntParam::new("buckets", (1, 32, 32), "buckets (layers) per pixel").compiled_as("BUCKETS");

pub const INFO: MethodInfo = MethodInfo {
    name: "bucket_peeling",
    summary: "bucket depth peeling: the depth range split into buckets, one fragment kept per bucket",
    exact: false,
    bounded_memory: true,
    passes: &["depth bounds (geometry)", "bucket keys (geometry)", "bucket colors (geometry)", "resolve (full screen)"],
    params: &[BUCKETS.0],
    features: wgpu::Features::SHADER_INT64.union(wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX),
    order: Order::BitwiseExceptTies,
    antialias_modes: FRAMES,
    memory: Memory::Frame(BYTES),
    error_bound: ErrorBound::None,
    census: false,
    census_when: never,
    main: Some("buckets"),
    pipelines: &[PIPELINES],
    constants: &[],
    create: |_, _| Box::new(Buckets { buffers: None, dropped: None }),
};

/// Bytes bucket_peeling allocates: depth bounds, a 64-bit key and a color per bucket, and the
/// dropped counter.
const BUFFERS: &[Buffer] = &[
    Buffer::per_pixel("bounds", Linear::bytes(8)),
    Buffer::per_pixel("keys", Linear::per(BUCKETS, 8, 0)),
    Buffer::per_pixel("bucket_colors", Linear::per(BUCKETS, 16, 0)),
];
const BYTES: FrameBytes = FrameBytes::of(BUFFERS, 4);

const SHADER: &str = "bucket_peeling.wgsl";
/// Group 2: bounds, keys, bucket colors, then the dropped counter.
const OWN: Layout = Layout::Storage(&["bounds", "keys", "bucket_colors", "dropped"]);
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, OWN];
const PIPELINES: &[PipelineSpec] = &[
    PipelineSpec::geometry(SHADER, "fs_bounds", GROUPS),
    PipelineSpec::geometry(SHADER, "fs_keys", GROUPS),
    PipelineSpec::geometry(SHADER, "fs_shade", GROUPS),
    PipelineSpec::fullscreen(SHADER, "fs_resolve", GROUPS),
];

struct Buckets {
    buffers: Option<StorageGroup>,
    dropped: Option<Counter>,
}

impl Method for Buckets {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let buckets = BUCKETS.of(cx.params);
        let pixels = cx.pixels();
        cx.check_per_pixel(&format!("bucket_peeling with {buckets} buckets"), 16 * buckets as u64)?;
        let dropped = self.dropped.get_or_insert_with(|| Counter::new(cx.gpu, "bucket dropped"));
        let sizes = buffer_sizes(BUFFERS, pixels, cx.params);
        let b = StorageGroup::ensure(&mut self.buffers, cx.gpu, OWN, &sizes, &[("dropped", dropped)]);
        let consts = [BUCKETS.constant(cx.params)];
        let mut enc = cx.encoder();
        b.clear(&mut enc);
        dropped.clear(&mut enc);
        for (fs, label) in [("fs_bounds", "bounds"), ("fs_keys", "keys"), ("fs_shade", "colors")] {
            cx.capture(&mut enc, label, &cx.capture_pipeline(spec(PIPELINES, fs), &consts), &b.group);
        }
        cx.resolve(&mut enc, "resolve", &cx.resolve_pipeline(spec(PIPELINES, "fs_resolve"), &consts, false), &b.group, false);
        let tally = dropped.tally(&mut enc, None);
        cx.submit(enc);
        Ok(Outcome::Done(MethodReport { memory_bytes: BYTES.at(pixels, cx.params), tallies: vec![tally], ..Default::default() }))
    }
}
