//! `hybrid64`: single-pass hybrid transparency with 64-bit atomics. Each k-TAB slot holds a
//! whole fragment (depth, alpha, color) in one 64-bit word; the atomic bubble needs each
//! `atomicMax`'s previous value, hence `SHADER_INT64_ATOMIC_ALL_OPS` (min/max without a
//! result does not suffice); the word pushed off the table joins the tail in the same pass.
//! One geometry pass and one full-screen resolve (shaders/hybrid64.wgsl).

use super::frame::{FrameCtx, Method, MethodReport, Outcome};
use super::info::{buffer_sizes, never, Buffer, ErrorBound, FRAMES, FrameBytes, Linear, Memory, MethodInfo, Order};
use super::params::IntParam;
use crate::cache::{spec, Layout, PipelineSpec};
use crate::error::Result;
use crate::resources::{Counter, StorageGroup};

const K: IntParam = IntParam::new("k", (1, 32, 8), "core size: fragments per pixel kept, sorted, with their colors").compiled_as("K");

pub const INFO: MethodInfo = MethodInfo {
    name: "hybrid64",
    summary: "single-pass hybrid: 64-bit k-TAB words with depth, alpha and color; the evicted join the tail",
    exact: false,
    bounded_memory: true,
    passes: &["insert and accumulate the tail (geometry)", "resolve (full screen)"],
    params: &[K.0],
    features: wgpu::Features::SHADER_INT64.union(wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS),
    order: Order::Bitwise,
    antialias_modes: FRAMES,
    memory: Memory::Frame(BYTES),
    error_bound: ErrorBound::PerPixel,
    census: false,
    census_when: never,
    main: Some("k"),
    pipelines: &[PIPELINES],
    constants: &[],
    create: |_, _| Box::new(Hybrid64 { buffers: None, tail: None }),
};

/// Group 2: the k-TAB words, the tail accumulators, then the tail counter.
const OWN: Layout = Layout::Storage(&["ktab", "tail_words", "overflow"]);
const GROUPS: &[Layout] = &[Layout::Scene, Layout::Targets, OWN];
const PIPELINES: &[PipelineSpec] =
    &[PipelineSpec::geometry("hybrid64.wgsl", "fs_insert", GROUPS), PipelineSpec::fullscreen("hybrid64.wgsl", "fs_resolve", GROUPS)];

/// 32-bit words per pixel of the tail's count and sums (three 64-bit words).
pub const ACCUM_WORDS: u64 = crate::consts::HYBRID_TAIL_WORDS as u64;

/// Bytes hybrid64 allocates: k 64-bit words and the tail's words per pixel, a counter.
const BUFFERS: &[Buffer] =
    &[Buffer::per_pixel("ktab", Linear::per(K, 8, 0)), Buffer::per_pixel("tail_words", Linear::bytes(4 * ACCUM_WORDS))];
/// The buffers and the tail counter.
const BYTES: FrameBytes = FrameBytes::of(BUFFERS, 4);

struct Hybrid64 {
    buffers: Option<StorageGroup>,
    tail: Option<Counter>,
}

impl Method for Hybrid64 {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let k = K.of(cx.params);
        let pixels = cx.pixels();
        cx.check_per_pixel(&format!("hybrid64 with k = {k}"), (8 * k as u64).max(4 * ACCUM_WORDS))?;
        let tail = self.tail.get_or_insert_with(|| Counter::new(cx.gpu, "hybrid64 tail count"));
        let sizes = buffer_sizes(BUFFERS, pixels, cx.params);
        let b = StorageGroup::ensure(&mut self.buffers, cx.gpu, OWN, &sizes, &[("overflow", tail)]);
        let consts = [K.constant(cx.params)];
        let insert = cx.capture_pipeline(spec(PIPELINES, "fs_insert"), &consts);
        let resolve = cx.resolve_pipeline(spec(PIPELINES, "fs_resolve"), &consts, true);
        let mut enc = cx.encoder();
        b.clear(&mut enc);
        tail.clear(&mut enc);
        cx.capture(&mut enc, "insert", &insert, &b.group);
        cx.resolve(&mut enc, "resolve", &resolve, &b.group, true);
        let tally = tail.tally(&mut enc, Some("tail_fragments"));
        cx.submit(enc);
        Ok(Outcome::Done(MethodReport {
            memory_bytes: BYTES.at(pixels, cx.params),
            tallies: vec![tally],
            error_bound: true,
            ..Default::default()
        }))
    }
}
