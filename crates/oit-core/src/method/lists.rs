//! Per-pixel linked lists in a global node pool (Yang et al. 2010), shared by the methods
//! that capture every fragment (abuffer, adaptive_lists, ...): one capture pass, the sorted
//! resolve's dispatches where the method has them, one full-screen resolve. The pool (pool.rs)
//! follows the scene: it grows to the counted fragments and the frame is rendered again when
//! the atomic counter says the pool overflowed (docs/methods.md).

use super::frame::{Dispatch, FrameCtx, Limits, MethodReport, Outcome};
use super::list_pipelines::SWEEPS;
pub(crate) use super::pool::ListLayout;
use super::pool::{NodePool, PoolAux, LIST_ARGS_BYTES};
use super::resolve_plan::{run_length, ResolveStrategy, StepCosts};
use crate::cache::{spec, PipelineSpec};
use crate::consts::{BATCH, RUN};
use crate::context::GpuContext;
use crate::error::{OitError, Result};
use crate::gpu_types::Alloc;
use crate::scan::Scan;
use crate::shader::Const;

// What renderer/plan.rs reads by these paths.
pub(crate) use super::pool::POOL_BINDINGS;
pub(crate) use super::resolve_plan::pixel_bytes;

/// A capture-then-resolve method over a node pool.
pub(crate) struct ListMethod {
    pipelines: &'static [PipelineSpec],
    consts: Vec<Const>,
    pool: NodePool,
    /// Whether the resolve sorts each pixel's list before the full-screen pass (the sorted
    /// resolve, common/sweep.wgsl), and the samples a pixel it composites.
    sweeps: Option<u32>,
    aux: PoolAux,
    /// The prefix sum over binding 7, for `PoolAux::PixelOffsets`, and the pixels it is for.
    scan: Option<(u64, Scan)>,
    shades_at_resolve: bool,
    /// The nodes the pool grew to after the last render of this tile proved it short
    /// (`Outcome::Grow`), and how many times it grew for this tile.
    grown: Option<u64>,
    regrown: u32,
}

impl ListMethod {
    pub fn new(gpu: &GpuContext, limits: &Limits, layout: ListLayout) -> Self {
        Self {
            pipelines: layout.pipelines,
            consts: Vec::new(),
            pool: NodePool::new(gpu, limits, &layout),
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
        // light loop, the shading-cost loop, and the profile's margin for its other loops). Its
        // nodes' fragments and tie keys read the triangle's record, which costs no loop: runs
        // stay keyed.
        let steps = cx.gpu.profile.loop_limit.map(|l| l.sweep).unwrap_or_default();
        let shading = steps.shade as u64 + crate::shading::MAX_LIGHTS as u64 + cx.variant.shading_cost as u64;
        let shade = if self.shades_at_resolve { shading } else { 0 };
        let frag = 0;
        let run = (deepest as u64).min(RUN as u64);
        StepCosts { steps, samples: self.sweeps.unwrap_or(1) as u64, frag, shade, run }
    }

    /// A frame's shader constants: the pool's shape, the run length, the resolve's strategy and
    /// step costs (from the adapter's profile), whether the capture counts, and the method's own.
    fn consts_for(&self, gpu: &GpuContext, run: u32, costs: StepCosts, strategy: ResolveStrategy, counting: bool) -> Vec<Const> {
        let mut consts = self.pool.consts().to_vec();
        consts.push(Const::U32("RUN", run));
        consts.extend(strategy.consts());
        consts.extend(gpu.profile.sweep_consts());
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
            allocate: matches!(self.aux, PoolAux::PerTriangle(_)).then(|| cx.compute_pipeline(at("cs_allocate"), consts)),
            count: (self.aux == PoolAux::PixelOffsets).then(|| cx.capture_pipeline(at("fs_count"), consts)),
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
    /// dispatches of each deep phase, by the strategy the adapter's profile calls for.
    fn resolve_plan(&self, cx: &FrameCtx<'_>, deepest: u32, counting: bool) -> Result<(Vec<Const>, [u32; 3])> {
        let costs = self.step_costs(cx, deepest);
        let strategy = if self.sweeps.is_some() { ResolveStrategy::choose(&cx.gpu.profile, costs)? } else { ResolveStrategy::UNUSED };
        let sweeps = if self.sweeps.is_some() { strategy.dispatches(deepest as u64, costs) } else { [0; 3] };
        Ok((self.consts_for(cx.gpu, run_length(deepest as u64), costs, strategy, counting), sweeps))
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
        if self.aux == PoolAux::PixelOffsets && self.scan.as_ref().is_none_or(|(p, _)| *p != pixels) {
            self.scan = Some((pixels, Scan::new(cx.gpu, &self.pool.aux, pixels + 1)));
        }
        let mut enc = cx.gpu.device.create_command_encoder(&Default::default());
        if counting {
            // The capture alone, with the largest run in its constants (they do not change
            // its code, and so its pipeline stays the same from frame to frame); then the
            // counts plan the resolve.
            let consts = self.consts_for(cx.gpu, RUN, StepCosts::default(), ResolveStrategy::UNUSED, true);
            let capture = self.capture_pipelines(cx, &consts);
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
/// method (adaptive_lists, mlab_lists) could not finish under the adapter's loop limit:
/// (n / BATCH + 1) heap sweeps of the list, then `per_fragment` loop iterations for each fragment.
pub(crate) fn check_replay_budget(cx: &FrameCtx<'_>, method: &str, param: &str, value: u32, per_fragment: u64) -> Result<()> {
    let n = cx.frame_max_depth_complexity as u64;
    let iterations = (n / BATCH as u64 + 1) * n * 6 + n * per_fragment;
    match cx.gpu.profile.loop_iterations() {
        Some(limit) if iterations > limit => Err(OitError::Unsupported(format!(
            "{method} with {param} = {value} on a pixel with {n} fragments needs about {iterations} loop iterations in one \
             shader invocation, and {} ends a shader's loops after {limit}: use a hardware adapter, \
             a smaller {param} or fewer layers",
            cx.gpu.info.name
        ))),
        _ => Ok(()),
    }
}
