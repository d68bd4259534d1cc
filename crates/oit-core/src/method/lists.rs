//! Per-pixel linked lists in a global node pool (Yang et al. 2010), shared by the methods
//! that capture every fragment (abuffer, adaptive): one capture pass, one full-screen
//! resolve. The pool follows the scene: it grows to the counted fragments and the frame is
//! rendered again when the atomic counter says the pool overflowed (docs/methods.md).

use super::frame::{Dispatch, FrameCtx, Limits, MethodReport, Outcome};
use super::list_pipelines::SWEEPS;
pub(crate) use super::sweep_costs::{pixel_bytes, state_words, COUNTED_PIXEL_BYTES, PIXEL_BYTES, STATE_WORDS};
pub use super::sweep_costs::{resolve_dispatches, step_budget, StepCosts};
use crate::cache::{spec, Layout, PipelineSpec};
use crate::context::GpuContext;
use crate::error::{OitError, Result};
use crate::gpu_types::Alloc;
use crate::scan::Scan;
use crate::shader::Const;
use crate::targets::{read_buffer, storage_buffer};

/// Storage bindings the pool is split across (shaders/common/pool.wgsl).
pub const POOL_BINDINGS: u64 = 4;
/// Fragments the submission-order replays select per sweep (shaders/common/select.wgsl).
pub const BATCH: u32 = 32;
/// Fragments the exact resolve sorts in a local array at most (shaders/common/sweep.wgsl):
/// a list no longer takes one walk; a longer one is sorted in runs of RUN, then merged by
/// relinking its nodes. 128 keeps all but the deepest pixels of hair in one walk (the relinking
/// merges cost far more a node than the local ones); the array holds twice RUN entries of 8
/// bytes (24 where the runs hold whole fragments).
pub const RUN: u32 = 128;
/// The shortest run, sorted by insertion before the local merges (BLOCK in sweep.wgsl).
pub const BLOCK: u64 = 8;

/// The local array of a frame whose deepest pixel has n fragments: the smallest power of two
/// from BLOCK to RUN that holds it (a smaller array is cheaper to keep: it is zeroed at every
/// invocation).
pub fn run_length(n: u64) -> u32 {
    (n.next_power_of_two() as u32).clamp(BLOCK as u32, RUN)
}

const ALLOC_BYTES: u64 = std::mem::size_of::<Alloc>() as u64;
/// The indirect dispatch arguments (x, y, z workgroups) of the sorted resolve's first pass,
/// then of its deep phases.
const LIST_ARGS_BYTES: u64 = 24;

/// What a list method keeps at binding 7 besides its pool.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Aux {
    None,
    /// Bytes per transparent triangle, filled by a `cs_allocate` pass before capture.
    PerTriangle(u64),
    /// W * H + 1 words: per-pixel counts scanned into range starts (sbuffer).
    PixelOffsets,
}

/// A linked-list node pool with its heads and allocator, shared by list-based methods.
pub(crate) struct NodePool {
    node_bytes: u64,
    pub nodes_per_binding: u64,
    pub capacity: u64,
    pixels: u64,
    pub heads: wgpu::Buffer,
    pub alloc: wgpu::Buffer,
    alloc_readback: wgpu::Buffer,
    pub pools: Vec<wgpu::Buffer>,
    /// Per-pixel state carried between resolve sweeps (binding 6).
    state: wgpu::Buffer,
    pub state_words: u64,
    /// The sorted resolve's indirect dispatch arguments, copied from the allocator.
    list_args: wgpu::Buffer,
    /// Binding 7: per-triangle data of the allocation pass, or per-pixel offsets.
    pub aux: wgpu::Buffer,
    aux_kind: Aux,
    aux_len: u64,
    /// Binding 8: each pixel's fragments, where the capture counts them itself (`counting`),
    /// with its readback; a placeholder otherwise.
    counts: wgpu::Buffer,
    counts_readback: Option<wgpu::Buffer>,
    counting: bool,
    /// The group's layout, by the names of the method's shader (its table's group 2).
    pub layout: Layout,
    pub group: Option<wgpu::BindGroup>,
}

impl NodePool {
    pub fn new(
        gpu: &GpuContext,
        limits: &Limits,
        node_bytes: u64,
        state_words: u64,
        aux_kind: Aux,
        counting: bool,
        layout: Layout,
    ) -> Self {
        let d = &gpu.device;
        let alloc = storage_buffer(d, "alloc", ALLOC_BYTES, wgpu::BufferUsages::COPY_SRC);
        let alloc_readback = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("alloc readback"),
            size: ALLOC_BYTES,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            node_bytes,
            nodes_per_binding: (limits.max_binding_bytes / node_bytes).max(1).min(u32::MAX as u64 / POOL_BINDINGS),
            capacity: 0,
            pixels: 0,
            heads: storage_buffer(d, "heads", 4, wgpu::BufferUsages::empty()),
            alloc,
            alloc_readback,
            pools: Vec::new(),
            state: storage_buffer(d, "sweep state", 4, wgpu::BufferUsages::empty()),
            state_words,
            list_args: d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pixel list dispatch args"),
                size: LIST_ARGS_BYTES,
                usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            aux: storage_buffer(d, "list aux", 4, wgpu::BufferUsages::empty()),
            aux_kind,
            aux_len: 0,
            counts: storage_buffer(d, "capture counts", 4, wgpu::BufferUsages::empty()),
            counts_readback: None,
            counting,
            layout,
            group: None,
        }
    }

    /// The pool's shape for its shaders: nodes a binding, and bindings in use (1 lets them
    /// skip the switch over bindings).
    pub fn consts(&self) -> [Const; 2] {
        let split = if self.capacity <= self.nodes_per_binding { 1 } else { POOL_BINDINGS as u32 };
        [Const::U32("NODES_PER_BINDING", self.nodes_per_binding as u32), Const::U32("POOL_SPLIT", split)]
    }

    pub fn max_nodes(&self) -> u64 {
        self.nodes_per_binding * POOL_BINDINGS
    }

    /// Words of the state buffer a pixel: its sweep state and, with one, its entries of the
    /// pixel lists (shaders/common/sweep.wgsl).
    pub fn state_len(&self) -> u64 {
        self.state_words + 2 * (self.state_words > 0) as u64
    }

    /// Bytes a pixel keeps: its head, sweep state and list entries, and its count where the
    /// capture counts.
    pub fn pixel_bytes(&self) -> u64 {
        4 * (1 + self.state_len() + self.counting as u64)
    }

    pub fn bytes(&self) -> u64 {
        self.capacity * self.node_bytes + self.pixels * self.pixel_bytes() + self.aux_len + ALLOC_BYTES + LIST_ARGS_BYTES
    }

    /// Makes room for `nodes` nodes, `pixels` heads and `triangles` per-triangle records,
    /// reallocating only when needed.
    /// With `exact`, the pool is made exactly `nodes` large (a tile of a budgeted frame);
    /// otherwise it keeps a larger capacity unless less than a quarter would be used.
    pub fn reserve(&mut self, gpu: &GpuContext, nodes: u64, pixels: u64, triangles: u64, exact: bool) -> Result<()> {
        if nodes > self.max_nodes() {
            return Err(OitError::OutOfMemory(format!(
                "the frame has {nodes} transparent fragments but the node pool holds at most {} on this adapter \
                 ({POOL_BINDINGS} bindings of {} bytes): render at a smaller size or with a bounded method (e.g. hybrid)",
                self.max_nodes(),
                self.nodes_per_binding * self.node_bytes
            )));
        }
        let d = &gpu.device;
        let mut changed = self.group.is_none();
        if pixels != self.pixels {
            self.heads = storage_buffer(d, "heads", pixels * 4, wgpu::BufferUsages::empty());
            self.state = storage_buffer(d, "sweep state", pixels * 4 * self.state_len(), wgpu::BufferUsages::empty());
            if self.counting {
                self.counts = storage_buffer(d, "capture counts", pixels * 4, wgpu::BufferUsages::COPY_SRC);
                self.counts_readback = Some(d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("capture counts readback"),
                    size: ALLOC_BYTES + pixels * 4,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }));
            }
            self.pixels = pixels;
            changed = true;
        }
        let aux_len = match self.aux_kind {
            Aux::None => 0,
            // At least one record: a binding must hold one element even without triangles.
            Aux::PerTriangle(bytes) => triangles.max(1) * bytes,
            Aux::PixelOffsets => (pixels + 1) * 4,
        };
        if aux_len != self.aux_len {
            if aux_len > gpu.max_binding_bytes() {
                return Err(OitError::OutOfMemory(format!(
                    "this frame needs a {aux_len}-byte buffer of per-triangle or per-pixel data, past the adapter's \
                     {}-byte storage binding limit: split the scene or render a smaller frame",
                    gpu.max_binding_bytes()
                )));
            }
            self.aux = storage_buffer(d, "list aux", aux_len, wgpu::BufferUsages::COPY_SRC);
            self.aux_len = aux_len;
            changed = true;
        }
        // Grow to what was counted; shrink when less than a quarter is used.
        if nodes > self.capacity || nodes < self.capacity / 4 || (exact && nodes.max(1) != self.capacity) {
            self.capacity = nodes.max(1);
            self.pools = (0..POOL_BINDINGS)
                .map(|b| {
                    let n = self.capacity.saturating_sub(b * self.nodes_per_binding).min(self.nodes_per_binding).max(1);
                    storage_buffer(d, "node pool", n * self.node_bytes, wgpu::BufferUsages::empty())
                })
                .collect();
            changed = true;
        }
        if changed {
            let Some(names) = self.layout.named() else { unreachable!("a storage layout") };
            // Heads, allocator, pools, state, binding 7, counts: in the layout's order.
            let buffers = [&self.heads, &self.alloc].into_iter().chain(&self.pools).chain([&self.state, &self.aux, &self.counts]);
            let entries: Vec<(&str, wgpu::BindingResource<'_>)> =
                names.iter().zip(buffers).map(|((name, _), b)| (*name, b.as_entire_binding())).collect();
            self.group = Some(crate::cache::bind_named(&gpu.device, &gpu.cache, self.layout, "node pool", &entries));
        }
        Ok(())
    }

    /// Records the per-frame reset: empty lists and a zero counter with the capacity.
    pub fn clear(&self, gpu: &GpuContext, enc: &mut wgpu::CommandEncoder) {
        enc.clear_buffer(&self.heads, 0, None);
        enc.clear_buffer(&self.state, 0, None);
        let alloc = Alloc { capacity: self.capacity.min(u32::MAX as u64) as u32, ..Default::default() };
        gpu.queue.write_buffer(&self.alloc, 0, bytemuck::bytes_of(&alloc));
    }

    pub fn copy_count(&self, enc: &mut wgpu::CommandEncoder) {
        enc.copy_buffer_to_buffer(&self.alloc, 0, &self.alloc_readback, 0, ALLOC_BYTES);
    }

    /// Records the zeroing of the capture's per-pixel counts.
    fn clear_counts(&self, enc: &mut wgpu::CommandEncoder) {
        enc.clear_buffer(&self.counts, 0, None);
    }

    /// Records the copy of the allocator and the capture's per-pixel counts to one readback,
    /// so that the host waits once for both.
    fn copy_counts(&self, enc: &mut wgpu::CommandEncoder) {
        let r = self.counts_readback.as_ref().expect("a counting pool has its readback once reserved");
        enc.copy_buffer_to_buffer(&self.alloc, 0, r, 0, ALLOC_BYTES);
        enc.copy_buffer_to_buffer(&self.counts, 0, r, ALLOC_BYTES, self.pixels * 4);
    }

    /// The allocator after the capture and the capture's per-pixel counts, row-major in the
    /// tile (after `copy_counts` ran).
    fn read_counts(&self, gpu: &GpuContext) -> Result<(Alloc, Vec<u32>)> {
        let r = self.counts_readback.as_ref().expect("a counting pool has its readback once reserved");
        let raw = read_buffer(gpu, r, ALLOC_BYTES + self.pixels * 4)?;
        let (alloc, counts) = raw.split_at(ALLOC_BYTES as usize);
        Ok((bytemuck::pod_read_unaligned::<Alloc>(alloc), bytemuck::pod_collect_to_vec(counts)))
    }

    /// The allocator after the last capture: nodes asked for (may exceed the capacity) and
    /// fragments that escaped their allocation.
    pub fn read_alloc(&self, gpu: &GpuContext) -> Result<Alloc> {
        let raw = read_buffer(gpu, &self.alloc_readback, ALLOC_BYTES)?;
        Ok(bytemuck::pod_read_unaligned::<Alloc>(&raw))
    }
}

/// A capture-then-resolve method over a node pool.
pub(crate) struct ListMethod {
    pipelines: &'static [PipelineSpec],
    consts: Vec<Const>,
    pool: NodePool,
    /// Whether the resolve runs `cs_sweep` dispatches before the full-screen pass, and the
    /// samples a pixel it composites.
    sweeps: Option<u32>,
    aux: Aux,
    /// The prefix sum over binding 7, for `Aux::PixelOffsets`, and the pixels it is for.
    scan: Option<(u64, Scan)>,
    shades_at_resolve: bool,
    /// The nodes the pool grew to after the last render of this tile proved it short
    /// (`Outcome::Grow`), and how many times it grew for this tile.
    grown: Option<u64>,
    regrown: u32,
}

/// The storage layout of a list method.
pub(crate) struct ListLayout {
    /// The pipelines of its shader (list_pipelines.rs).
    pub pipelines: &'static [PipelineSpec],
    /// Bytes of one node.
    pub node_bytes: u64,
    /// Per-pixel words carried between resolve sweeps; 0 for a single-pass resolve.
    pub state_words: u64,
    /// Samples a pixel of the sorted resolve (common/sweep.wgsl); unused without sweeps.
    pub samples: u32,
    /// Whether turning a node into a fragment shades it (compact_abuffer): its loop
    /// iterations then count in the resolve's step budget.
    pub shades_at_resolve: bool,
    /// What binding 7 holds, and so which passes run before capture.
    pub aux: Aux,
    /// Whether the capture can count each pixel's fragments itself (its nodes are its
    /// fragments), so that a frame after the first needs no census (`ListMethod::counts_in_capture`).
    pub counts_in_capture: bool,
}

/// Loop iterations llvmpipe allows one shader invocation (all loops together); past them
/// it silently ends the loops. Methods whose per-pixel work grows with the depth complexity
/// check their estimate against it on that adapter.
pub const LLVMPIPE_LOOP_LIMIT: u64 = 65_535;

/// Whether `gpu` is llvmpipe (lavapipe), which has [`LLVMPIPE_LOOP_LIMIT`].
pub fn loop_limited(gpu: &GpuContext) -> bool {
    gpu.info.name.contains("llvmpipe")
}

impl ListMethod {
    pub fn new(gpu: &GpuContext, limits: &Limits, layout: ListLayout) -> Self {
        Self {
            pipelines: layout.pipelines,
            consts: Vec::new(),
            pool: NodePool::new(
                gpu,
                limits,
                layout.node_bytes,
                layout.state_words,
                layout.aux,
                layout.counts_in_capture,
                layout.pipelines[0].groups[2],
            ),
            sweeps: (layout.state_words > 0).then_some(layout.samples),
            shades_at_resolve: layout.shades_at_resolve,
            aux: layout.aux,
            scan: None,
            grown: None,
            regrown: 0,
        }
    }

    /// Sets the shader constants (besides the pool's).
    pub fn set_consts(&mut self, consts: Vec<Const>) {
        self.consts = consts;
    }

    /// Whether this frame can go without the census: the capture counts each pixel's fragments
    /// itself, and an earlier frame sized the pool (a pool that proves too small grows to the
    /// count, and the capture runs again). The renderer then takes the frame's counts from the
    /// method's report.
    pub fn counts_in_capture(&self) -> bool {
        self.pool.counting && self.pool.capacity > 0
    }

    /// What a step of the sorted resolve costs in a frame whose deepest pixel has `deepest`
    /// fragments.
    fn step_costs(&self, cx: &FrameCtx<'_>, deepest: u32) -> StepCosts {
        // Shading at composite (compact_abuffer's frag_shaded): shading.wgsl's `shade` (its
        // light loop, the shading-cost loop, and a margin for its other loops, each of which
        // llvmpipe's limiter counts once even when skipped). Its nodes' fragments and tie keys
        // read the triangle's record, which costs no loop: runs stay keyed.
        let shade = if self.shades_at_resolve { 4 + crate::shading::MAX_LIGHTS as u64 + cx.variant.shading_cost as u64 } else { 0 };
        let frag = 0;
        let run = (deepest as u64).min(RUN as u64);
        StepCosts { samples: self.sweeps.unwrap_or(1) as u64, frag, shade, run }
    }

    fn consts_for(&self, run: u32, costs: StepCosts, budget: u64, counting: bool) -> Vec<Const> {
        let mut consts = self.pool.consts().to_vec();
        consts.push(Const::U32("BATCH", BATCH));
        consts.push(Const::U32("RUN", run));
        consts.push(Const::U32("STEP_BUDGET", budget as u32));
        consts.push(Const::U32("FRAG_STEPS", costs.frag as u32));
        consts.push(Const::U32("SHADE_STEPS", costs.shade as u32));
        consts.push(Const::U32("KEYED", costs.keyed() as u32));
        consts.push(Const::U32("COUNTING", counting as u32));
        consts.extend(self.consts.iter().copied());
        consts
    }

    /// The capture's pipelines: the pass before it that binding 7 may need, and the capture.
    fn capture_pipelines(&self, cx: &FrameCtx<'_>, consts: &[Const]) -> CapturePipelines {
        let at = |entry| spec(self.pipelines, entry);
        CapturePipelines {
            allocate: matches!(self.aux, Aux::PerTriangle(_)).then(|| cx.compute_pipeline(at("cs_allocate"), consts)),
            count: (self.aux == Aux::PixelOffsets).then(|| cx.capture_pipeline(at("fs_count"), consts)),
            capture: cx.capture_pipeline(at("fs_capture"), consts),
        }
    }

    /// The resolve's pipelines: the sorted resolve's sweeps, where the method has them, and the
    /// full-screen pass.
    fn resolve_pipelines(&self, cx: &FrameCtx<'_>, consts: &[Const]) -> ResolvePipelines {
        let at = |entry| spec(self.pipelines, entry);
        ResolvePipelines {
            sweep: self.sweeps.map(|_| SWEEPS.map(|entry| cx.compute_pipeline(at(entry), consts))),
            resolve: cx.resolve_pipeline(at("fs_resolve"), consts, false),
        }
    }

    /// S-buffer preparation: per-pixel counts into binding 7, their exclusive prefix sum in
    /// place (entry W * H becomes the total), the starts copied to the fill cursors (heads)
    /// and the total to the allocator's count, so that the capacity check works as for lists.
    fn count_and_scan(
        &self,
        cx: &mut FrameCtx<'_>,
        enc: &mut wgpu::CommandEncoder,
        count: &wgpu::RenderPipeline,
        scan: &Scan,
        pixels: u64,
    ) {
        let group = self.pool.group.as_ref().expect("reserved");
        enc.clear_buffer(&self.pool.aux, 0, None);
        cx.capture(enc, "count", count, group);
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("prefix sum"),
                timestamp_writes: cx.timer.compute_pass("prefix sum"),
            });
            scan.record(&mut pass);
        }
        enc.copy_buffer_to_buffer(&self.pool.aux, 0, &self.pool.heads, 0, pixels * 4);
        enc.copy_buffer_to_buffer(&self.pool.aux, pixels * 4, &self.pool.alloc, 0, 4);
    }

    /// Records the per-frame reset and the capture: the pass binding 7 needs, then the
    /// geometry into the pool (counting each pixel's fragments where `counting`), and the copy
    /// of the allocator (and the counts) to their readbacks.
    fn record_capture(&self, cx: &mut FrameCtx<'_>, enc: &mut wgpu::CommandEncoder, p: &CapturePipelines, pixels: u64, counting: bool) {
        let group = self.pool.group.as_ref().expect("reserved");
        self.pool.clear(cx.gpu, enc);
        if counting {
            self.pool.clear_counts(enc);
        }
        let triangles = cx.scene.transparent.triangles as u64;
        if let (Some(allocate), true) = (&p.allocate, triangles > 0) {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("list allocate"),
                timestamp_writes: cx.timer.compute_pass("allocate"),
            });
            pass.set_pipeline(allocate);
            pass.set_bind_group(1, cx.targets_group(), &[]);
            pass.set_bind_group(2, group, &[]);
            // One invocation a drawn triangle, chunk after chunk (shaders/common/setup.wgsl).
            for chunk in &cx.scene.transparent.chunks {
                pass.set_bind_group(0, &chunk.group, &[]);
                let groups = chunk.drawn.div_ceil(64);
                pass.dispatch_workgroups(groups.min(65535), groups.div_ceil(65535), 1);
            }
        }
        if let (Some(count), Some((_, scan))) = (&p.count, &self.scan) {
            self.count_and_scan(cx, enc, count, scan, pixels);
        }
        cx.capture(enc, "capture", &p.capture, group);
        if counting {
            self.pool.copy_counts(enc);
        } else {
            self.pool.copy_count(enc);
        }
    }

    /// Records the resolve: the sorted resolve's dispatches (`sweeps` of each deep phase) where
    /// the method has them, then the full-screen pass.
    fn record_resolve(&self, cx: &mut FrameCtx<'_>, enc: &mut wgpu::CommandEncoder, p: &ResolvePipelines, sweeps: [u32; 3]) {
        let group = self.pool.group.as_ref().expect("reserved");
        if let Some([active, groups, sort, phases @ ..]) = &p.sweep {
            // Each phase runs over a list of the pixels with work in it: cs_active lists
            // those with fragments, cs_sort the deep ones; cs_groups sizes the dispatches.
            let (alloc, args) = (&self.pool.alloc, &self.pool.list_args);
            {
                let timestamp_writes = cx.timer.compute_pass("pixel lists");
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("pixel lists"), timestamp_writes });
                cx.bind_dispatch(&mut pass, active, group);
                cx.bind_dispatch_with(&mut pass, groups, group, Dispatch::One);
            }
            enc.copy_buffer_to_buffer(alloc, Alloc::GROUPS_OFFSET, args, 0, LIST_ARGS_BYTES);
            cx.dispatch_with(enc, "sort", sort, group, Dispatch::Indirect(args, 0));
            if sweeps.iter().any(|&n| n > 0) {
                cx.dispatch_with(enc, "deep list", groups, group, Dispatch::One);
                enc.copy_buffer_to_buffer(alloc, Alloc::GROUPS_OFFSET, args, 0, LIST_ARGS_BYTES);
            }
            for ((label, pipeline), n) in ["runs", "merge", "composite"].into_iter().zip(phases).zip(sweeps) {
                if n > 0 {
                    let timestamp_writes = cx.timer.compute_pass(label);
                    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes });
                    for _ in 0..n {
                        cx.bind_dispatch_with(&mut pass, pipeline, group, Dispatch::Indirect(args, 12));
                    }
                }
            }
        }
        cx.resolve(enc, "resolve", &p.resolve, group, false);
    }

    /// The resolve's plan for a deepest pixel of `deepest` fragments: its constants, and the
    /// dispatches of each deep phase.
    fn resolve_plan(&self, cx: &FrameCtx<'_>, deepest: u32, counting: bool) -> Result<(Vec<Const>, [u32; 3])> {
        let costs = self.step_costs(cx, deepest);
        let budget = if self.sweeps.is_some() { step_budget(cx.gpu, costs)? } else { 1 };
        let sweeps = if self.sweeps.is_some() { resolve_dispatches(deepest as u64, costs, budget) } else { [0; 3] };
        Ok((self.consts_for(run_length(deepest as u64), costs, budget, counting), sweeps))
    }

    /// The report of a frame whose capture asked for `count` nodes.
    fn report(&mut self, cx: &FrameCtx<'_>, count: u64, sweeps: Option<[u32; 3]>, counts: Option<Vec<u32>>) -> Result<Outcome> {
        let regrown = std::mem::take(&mut self.regrown) as f64;
        let memory = self.pool.bytes() + self.scan.as_ref().map_or(0, |(_, s)| s.bytes);
        // Shrink for the next frame when this one used little of the pool.
        if count < self.pool.capacity / 4 {
            let triangles = cx.scene.transparent.triangles as u64;
            self.pool.reserve(cx.gpu, count, cx.pixels(), triangles, !cx.tile.is_whole())?;
        }
        let mut extra = vec![
            ("pool_regrown", regrown),
            ("resolve_sweeps", sweeps.map_or(1.0, |s| 1.0 + s.iter().sum::<u32>() as f64)),
            ("pool_nodes", count as f64),
        ];
        if self.pool.counting {
            extra.push(("counted_in_capture", counts.is_some() as u32 as f64));
        }
        Ok(Outcome::Done(MethodReport { memory_bytes: memory, extra, counts, ..Default::default() }))
    }

    /// Grows the pool to `nodes` for the next render of this tile (`Outcome::Grow`).
    fn grow(&mut self, cx: &FrameCtx<'_>, nodes: u64) -> Result<Outcome> {
        let triangles = cx.scene.transparent.triangles as u64;
        self.pool.reserve(cx.gpu, nodes, cx.pixels(), triangles, !cx.tile.is_whole())?;
        self.grown = Some(nodes);
        self.regrown += 1;
        Ok(Outcome::Grow)
    }

    pub fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<Outcome> {
        let tile = cx.tile;
        let pixels = cx.pixels();
        cx.check_per_pixel(
            &format!("{} (its per-pixel heads and sweep state)", self.pipelines[0].shader.trim_end_matches(".wgsl")),
            self.pool.pixel_bytes(),
        )?;
        // Without a census the capture counts each pixel's fragments itself, and the host reads
        // them back before it plans the resolve. The renderer skips the census only for a whole
        // frame of a method that `counts_in_capture`: any other frame without counts would plan
        // its resolve for empty pixels.
        let counting = cx.depth_complexity.is_empty();
        if counting && !(self.counts_in_capture() && tile.is_whole()) {
            return Err(OitError::Device(format!(
                "{} was given no fragment census for a frame it cannot count itself; please report this with the scene",
                self.pipelines[0].shader.trim_end_matches(".wgsl")
            )));
        }
        // A tile of a larger frame gets a pool of its counted fragments, so that tiles planned
        // within a memory budget stay in it; a whole frame keeps the pool it has, grown to the
        // census's count where that is more (a first frame, or a moving camera, renders once,
        // not again after an overflow). Where nodes are not fragments (pall's are its triangles'
        // bounds) the capture's own count still regrows the pool below.
        let tiled = !tile.is_whole();
        let planned = if tiled { cx.fragments } else { self.pool.capacity.max(cx.fragments) };
        let initial = self.grown.take().unwrap_or(planned).clamp(1, self.pool.max_nodes());
        let triangles = cx.scene.transparent.triangles as u64;
        self.pool.reserve(cx.gpu, initial, pixels, triangles, tiled)?;
        if self.aux == Aux::PixelOffsets && self.scan.as_ref().is_none_or(|(p, _)| *p != pixels) {
            self.scan = Some((pixels, Scan::new(cx.gpu, &self.pool.aux, pixels + 1)));
        }
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        if counting {
            // The capture alone, with the largest run in its constants (they do not change
            // its code, and so its pipeline stays the same from frame to frame); then the
            // counts plan the resolve.
            let capture = self.capture_pipelines(cx, &self.consts_for(RUN, StepCosts::default(), 1, true));
            self.record_capture(cx, &mut enc, &capture, pixels, true);
            cx.gpu.queue.submit([enc.finish()]);
            let (alloc, counts) = self.pool.read_counts(cx.gpu)?;
            let count = alloc.count as u64;
            if count > self.pool.capacity {
                if count > self.pool.max_nodes() {
                    // More than one pool holds: the renderer plans tiles from a census.
                    self.regrown = 0;
                    return Ok(Outcome::NeedCensus);
                }
                return self.grow(cx, count);
            }
            // The capture's allocator is the frame's: the resolve allocates nothing, so the
            // frame is reported without waiting for it (the renderer waits for the image).
            let deepest = counts.iter().copied().max().unwrap_or(0);
            let (consts, sweeps) = self.resolve_plan(cx, deepest, true)?;
            let p = self.resolve_pipelines(cx, &consts);
            let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
            self.record_resolve(cx, &mut enc, &p, sweeps);
            cx.gpu.queue.submit([enc.finish()]);
            return self.report(cx, count, self.sweeps.is_some().then_some(sweeps), Some(counts));
        }
        let (consts, sweeps) = self.resolve_plan(cx, cx.max_depth_complexity, false)?;
        let capture = self.capture_pipelines(cx, &consts);
        self.record_capture(cx, &mut enc, &capture, pixels, false);
        let p = self.resolve_pipelines(cx, &consts);
        self.record_resolve(cx, &mut enc, &p, sweeps);
        cx.gpu.queue.submit([enc.finish()]);
        let alloc = self.pool.read_alloc(cx.gpu)?;
        if alloc.escaped > 0 {
            return Err(OitError::Device(format!(
                "{} fragments fell outside their triangle's allocation (a bound that should be conservative \
                     was not); please report this with the scene",
                alloc.escaped
            )));
        }
        let count = alloc.count as u64;
        let sweeps = self.sweeps.is_some().then_some(sweeps);
        if count <= self.pool.capacity {
            return self.report(cx, count, sweeps, None);
        }
        if count > self.pool.max_nodes() && cx.tile.pixels() > 1 {
            // More nodes than the census planned for (pall's bounding boxes): the renderer
            // plans smaller tiles. A single pixel past the pool is refused by reserve.
            self.regrown = 0;
            return Ok(Outcome::Retile { factor: count as f64 / self.pool.max_nodes() as f64 });
        }
        self.grow(cx, count)
    }
}

/// A list method's capture pipelines (`ListMethod::capture_pipelines`).
struct CapturePipelines {
    allocate: Option<wgpu::ComputePipeline>,
    count: Option<wgpu::RenderPipeline>,
    capture: wgpu::RenderPipeline,
}

/// A list method's resolve pipelines: the sorted resolve (the pixel lists and their
/// workgroups, the first dispatch, then the deeper pixels' runs, merges and composite) and the
/// full-screen pass.
struct ResolvePipelines {
    sweep: Option<[wgpu::ComputePipeline; 6]>,
    resolve: wgpu::RenderPipeline,
}

/// Refuses a frame whose deepest pixel the one-invocation replay of a submission-order
/// method (adaptive, mlab) could not finish on llvmpipe: (n / BATCH + 1) heap sweeps of the
/// list, then `per_fragment` loop iterations for each fragment.
pub(crate) fn check_replay_budget(cx: &FrameCtx<'_>, method: &str, param: &str, value: u32, per_fragment: u64) -> Result<()> {
    let n = cx.frame_max_depth_complexity as u64;
    let iterations = (n / BATCH as u64 + 1) * n * 6 + n * per_fragment;
    if loop_limited(cx.gpu) && iterations > LLVMPIPE_LOOP_LIMIT {
        return Err(OitError::Unsupported(format!(
            "{method} with {param} = {value} on a pixel with {n} fragments needs about {iterations} loop iterations in one \
             shader invocation, and llvmpipe ends a shader's loops after {LLVMPIPE_LOOP_LIMIT}: use a hardware adapter, \
             a smaller {param} or fewer layers"
        )));
    }
    Ok(())
}
