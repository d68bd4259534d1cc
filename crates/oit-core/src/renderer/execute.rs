//! The executor: runs a frame tile by tile as the planner says (`plan.rs`). Per tile it draws the
//! opaque pass into the tile-sized targets, asks the method for the tile and acts on its
//! `Outcome` (done, grown, retile, census needed), and streams the tile's pixels into the
//! frame's arrays; the census (census.rs) runs first where the frame needs it. Reports of the
//! tiles merge by declared rules (`stats::Merge`).

use std::time::Instant;

use super::{Frame, Renderer, COVERAGE_SAMPLES};
use crate::cache::Layout;
use crate::error::{OitError, Result};
use crate::method::{AntialiasMode, FrameCtx, Method, MethodInfo, MethodReport, Outcome, Params};
use crate::scene::Camera;
use crate::stats::{ExtraMerge, Stats};
use crate::targets::{read_buffers, Region, SampleTargets, Targets};
use crate::tiles::Tile;

/// One frame as the executor runs it: what is drawn with which method, and in which mode.
pub(super) struct Job<'a> {
    pub camera: &'a Camera,
    pub info: &'static MethodInfo,
    pub params: &'a Params,
    pub background: [f32; 3],
    /// A coverage-mask frame at COVERAGE_SAMPLES samples a pixel: the executor draws the
    /// opaque pass per sample and hands the method the per-sample targets (`FrameCtx::coverage`).
    pub coverage: bool,
}

/// Each timed pass's label and GPU milliseconds, in recording order.
type PassTimes = Vec<(&'static str, f64)>;

/// Where a frame's fragment counts come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Counting {
    /// No counts: the method plans from none and the caller asked for none.
    Off,
    /// The census runs before the method.
    Census,
    /// The method counts each pixel's fragments in its own capture (`Method::counts_in_capture`)
    /// and reports them; a frame that does not fit one tile needs the census after all.
    InCapture,
}

/// The tiles of a frame once rendered: how many, their merged report, their pass times, and
/// the frame's pixels.
struct Rendered {
    tiles: u32,
    report: MethodReport,
    pass_times: Option<PassTimes>,
    arrays: FrameArrays,
}

/// What a coverage-mask frame needs besides the frame targets: the per-sample targets (the
/// census is multisampled: `census_pipeline`), at the tile size.
pub(super) struct Coverage {
    pub(super) targets: SampleTargets,
    size: (u32, u32),
}

/// The frame's pixels as the tiles stream them in: the image, and the error bound where the
/// method derives one (empty for a frame into a caller's texture).
struct FrameArrays {
    width: u32,
    height: u32,
    image: Vec<f32>,
    bound: Option<Vec<f32>>,
}

impl FrameArrays {
    fn new(width: u32, height: u32) -> Self {
        Self { width, height, image: Vec::new(), bound: None }
    }

    /// Puts `values` (`tile`'s pixels row-major, `channels` a pixel) into `frame` at the tile: a
    /// whole frame's values become the array as they are.
    fn place(frame: &mut Vec<f32>, (width, height): (u32, u32), tile: Tile, values: Vec<f32>, channels: usize) {
        if tile.is_whole() {
            *frame = values;
            return;
        }
        if frame.is_empty() {
            *frame = vec![0.0; width as usize * height as usize * channels];
        }
        let line = tile.width as usize * channels;
        for (r, row) in values.chunks(line).enumerate() {
            let at = ((tile.y as usize + r) * width as usize + tile.x as usize) * channels;
            frame[at..at + line].copy_from_slice(row);
        }
    }
}

impl Renderer {
    /// One frame of `job` with the pixel centers where its camera puts them (the scene is
    /// uploaded).
    pub(super) fn render_sample(&mut self, job: &Job<'_>) -> Result<Frame> {
        match self.run_frame(job, true)? {
            Some(frame) => Ok(frame),
            // The method's own count did not fit one pool in one tile: the census plans tiles.
            None => Ok(self.run_frame(job, false)?.expect("a frame with the census is rendered")),
        }
    }

    /// Where this frame's counts come from; a method may count in its own capture (where
    /// `self_count`) in a whole, one-sample frame without a budget.
    fn counting(&self, job: &Job<'_>, method: &dyn Method, self_count: bool) -> Counting {
        let needs = job.info.needs_census(job.params);
        let in_capture = self_count && needs && !self.census && !job.coverage && self.memory_budget.is_none() && method.counts_in_capture();
        match () {
            _ if in_capture => Counting::InCapture,
            _ if needs || self.census => Counting::Census,
            _ => Counting::Off,
        }
    }

    /// `render_sample`; None where the method counted in its capture and the frame needs the
    /// census after all (`Outcome::NeedCensus`).
    fn run_frame(&mut self, job: &Job<'_>, self_count: bool) -> Result<Option<Frame>> {
        let start = Instant::now();
        let info = job.info;
        let (w, h) = (self.width, self.height);
        if self.memory_budget.is_some() {
            // Under a budget no method keeps storage between frames: what the frame allocates
            // is what it reports, and the census runs with the targets alone.
            self.methods.remove(info.name);
        }
        let limits = self.limits;
        // Out of the map while it renders, so that the loop can set each tile's uniform.
        let mut method = self.methods.remove(info.name).unwrap_or_else(|| info.instantiate(&self.gpu, &limits));
        let counting = self.counting(job, &*method, self_count);
        let expand_times = self.expand_primitives(job.camera, job.background)?;
        let (mut counts, drawn) = match counting {
            Counting::Census => self.count_fragments(job)?,
            _ => (Vec::new(), None),
        };
        let result = self.run_tiles(&mut *method, job, counting, &counts, drawn);
        if self.memory_budget.is_none() {
            self.methods.insert(info.name, method);
        }
        let Some(Rendered { tiles, mut report, mut pass_times, arrays }) = result? else {
            return Ok(None);
        };
        if let Some(c) = report.counts.take() {
            counts = c;
        }
        if let (Some(p), Some(mut e)) = (pass_times.as_mut(), expand_times) {
            e.append(p);
            *p = e;
        }
        if let (Some(into), Some(t)) = (&self.into, &self.targets) {
            let mut enc = self.gpu.device.create_command_encoder(&Default::default());
            self.blit(&mut enc, &t.out, &into.color, wgpu::ColorWrites::COLOR, into.encode_srgb);
            self.gpu.queue.submit([enc.finish()]);
        }
        let (_, gpu_scene) = self.scene.as_ref().expect("uploaded by the caller");
        self.set_uniform(job.camera, gpu_scene, job.background, Tile::frame(w, h));
        let target_bytes = self.held_target_bytes();
        let stats = Stats {
            method: info.name.to_string(),
            params: job.params.clone(),
            census: counting != Counting::Off,
            fragments: counts.iter().map(|&c| c as u64).sum(),
            max_depth_complexity: counts.iter().copied().max().unwrap_or(0),
            memory_bytes: report.memory_bytes,
            target_bytes,
            scene_bytes: gpu_scene.bytes().iter().sum(),
            scene_bytes_by_primitive: gpu_scene.bytes(),
            expanded_bytes: gpu_scene.transparent.expanded_bytes + gpu_scene.opaque.expanded_bytes,
            texture_bytes: gpu_scene.texture_bytes,
            gpu_time_ms: pass_times.as_ref().map(|p| p.iter().map(|(_, t)| t).sum()),
            pass_times_ms: pass_times.unwrap_or_default(),
            overflow_fragments: report.overflow_fragments,
            wall_time_ms: start.elapsed().as_secs_f64() * 1e3,
            extra: report.extra,
            antialias: 1,
            antialias_mode: AntialiasMode::Frames,
            tiles,
            geometry_chunks: gpu_scene.transparent.chunks.len() as u32,
            instances: gpu_scene.instances,
            peak_memory_bytes: report.memory_bytes + target_bytes,
            ..Default::default()
        };
        Ok(Some(Frame { width: w, height: h, image: arrays.image, depth_complexity: counts, error_bound: arrays.bound, stats }))
    }

    /// Renders the method over the planned tiles, each into the targets and then into the
    /// frame's arrays, acting on each tile's `Outcome`. A method whose storage proves larger
    /// than planned (pall's pool follows its triangles' bounding boxes, not the fragments), or a
    /// frame past the memory budget, is planned again with the budget divided by how far it went
    /// over. None where the method counts in its capture (no census ran) and the frame would
    /// need more than one tile or pool.
    fn run_tiles(
        &mut self,
        method: &mut dyn Method,
        job: &Job<'_>,
        counting: Counting,
        counts: &[u32],
        mut drawn: Option<Tile>,
    ) -> Result<Option<Rendered>> {
        let (w, h) = (self.width, self.height);
        let in_capture = counting == Counting::InCapture;
        let mut squeeze = 1.0f64;
        loop {
            let plan = self.plan_tiles(job.info, job.params, counts, job.coverage, squeeze, in_capture)?;
            if self.into.is_some() && plan.targets != (w, h) {
                return Err(self.target_refused());
            }
            let tiles = plan.tiles;
            if in_capture && !(tiles.len() == 1 && tiles[0].is_whole()) {
                return Ok(None);
            }
            if self.ensure_targets(plan.targets.0, plan.targets.1, job.coverage)? {
                drawn = None;
            }
            let mut report = MethodReport::default();
            let mut extra = ExtraMerge::default();
            let mut pass_times: Option<PassTimes> = None;
            let mut arrays = FrameArrays::new(w, h);
            let mut retile = None;
            for tile in &tiles {
                let tile_counts: std::borrow::Cow<[u32]> = match tiles.len() {
                    _ if counts.is_empty() => (&[] as &[u32]).into(),
                    1 => counts.into(),
                    _ => tile.crop(counts, w).into(),
                };
                if drawn != Some(*tile) {
                    self.draw_opaque(*tile, job, false);
                }
                drawn = None; // the method's passes overwrite what the next tile would reuse
                let r = match self.render_tile(method, job, *tile, &tile_counts, counts)? {
                    Outcome::Done(r) if in_capture && r.counts.is_none() => return Ok(None),
                    Outcome::Done(r) => r,
                    Outcome::NeedCensus => return Ok(None),
                    Outcome::Retile { factor } => {
                        retile = Some(factor);
                        break;
                    }
                    Outcome::Grow => unreachable!("render_tile renders a grown tile again"),
                };
                let (r, times) = self.read_tile(*tile, r, &mut arrays)?;
                if let Some(t) = times {
                    pass_times.get_or_insert_with(Vec::new).extend(t);
                }
                report.memory_bytes = report.memory_bytes.max(r.memory_bytes);
                report.counts = r.counts;
                report.overflow_fragments += r.overflow_fragments;
                extra.add(&r.extra, tile.pixels() as f64);
            }
            report.extra = extra.finish();
            if let Some(factor) = retile {
                if squeeze < 1e6 {
                    squeeze *= 1.25 * factor;
                    continue;
                }
            }
            let peak = report.memory_bytes + self.held_target_bytes();
            match self.memory_budget {
                Some(budget) if peak > budget && squeeze < 1e6 => {
                    squeeze *= 1.25 * peak as f64 / budget as f64;
                }
                Some(budget) if peak > budget => {
                    return Err(OitError::OutOfMemory(format!(
                        "'{}' needed {peak} bytes in its smallest tiles (its storage and the frame's targets), past the \
                         memory_budget of {budget} bytes: raise memory_budget or use a bounded method (e.g. hybrid)",
                        job.info.name
                    )));
                }
                _ => return Ok(Some(Rendered { tiles: tiles.len() as u32, report, pass_times, arrays })),
            }
        }
    }

    /// The method's outcome for `tile` (its pixels' counts `tile_counts`, the frame's
    /// `frame_counts`): rendered again for as long as the method grows its storage.
    fn render_tile(
        &mut self,
        method: &mut dyn Method,
        job: &Job<'_>,
        tile: Tile,
        tile_counts: &[u32],
        frame_counts: &[u32],
    ) -> Result<Outcome> {
        let (_, gpu_scene) = self.scene.as_ref().expect("uploaded by the caller");
        self.set_uniform(job.camera, gpu_scene, job.background, tile);
        let variant = self.variant(gpu_scene);
        let memory_left = self.memory_budget.map(|b| b.saturating_sub(self.held_target_bytes()));
        loop {
            self.timer.reset();
            let mut cx = FrameCtx {
                gpu: &self.gpu,
                scene: gpu_scene,
                camera: job.camera,
                targets: self.targets.as_ref().expect("made by ensure_targets"),
                timer: &mut self.timer,
                params: job.params,
                tile,
                max_depth_complexity: tile_counts.iter().copied().max().unwrap_or(0),
                frame_max_depth_complexity: frame_counts.iter().copied().max().unwrap_or(0),
                fragments: tile_counts.iter().map(|&c| c as u64).sum(),
                depth_complexity: tile_counts,
                frame_uniform: &self.shared.uniform,
                limits: self.limits,
                memory_left,
                coverage: self.coverage.as_ref().filter(|_| job.coverage).map(|c| &c.targets),
                variant,
            };
            match method.render(&mut cx)? {
                // The storage grew to what the tile needs: the tile again, over the same opaque pass.
                Outcome::Grow => continue,
                outcome => return Ok(outcome),
            }
        }
    }

    /// Bytes of the frame's targets and readbacks as they are now.
    fn held_target_bytes(&self) -> u64 {
        self.targets.as_ref().map_or(0, Targets::bytes) + self.coverage.as_ref().map_or(0, |c| c.targets.bytes())
    }

    /// Makes the frame's targets (and a coverage-mask frame's per-sample ones) `width` x
    /// `height` unless they are; returns whether they were made anew.
    pub(super) fn ensure_targets(&mut self, width: u32, height: u32, coverage: bool) -> Result<bool> {
        let mut made = false;
        if self.targets.as_ref().is_none_or(|t| (t.width, t.height) != (width, height)) {
            self.targets = None; // free the old ones first
            self.targets = Some(Targets::new(&self.gpu, width, height, &self.shared.targets_layout));
            made = true;
        }
        if !coverage {
            self.coverage = None; // a frame holds only the targets it uses
        }
        if coverage && self.coverage.as_ref().is_none_or(|c| c.size != (width, height)) {
            self.coverage = None;
            let layout = self.gpu.cache.layout(&self.gpu.device, Layout::SampleTargets);
            let targets = SampleTargets::new(&self.gpu, width, height, COVERAGE_SAMPLES, &layout);
            self.coverage = Some(Coverage { targets, size: (width, height) });
            made = true;
        }
        // Allocation failures are reported through the error handler: surface them now.
        self.gpu.take_error()?;
        Ok(made)
    }

    /// Reads what `tile` left to read, after one submission and one wait: its output (and
    /// its error bound, where the method wrote one) into the frame's arrays (a frame into a
    /// caller's texture is copied there instead, once whole), the pass times, and the counts
    /// of `report`'s tallies, which it adds to the report.
    fn read_tile(&self, tile: Tile, mut report: MethodReport, arrays: &mut FrameArrays) -> Result<(MethodReport, Option<PassTimes>)> {
        let t = self.targets.as_ref().expect("made by ensure_targets");
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        let times = self.timer.record_read(&mut enc);
        let mut reads: Vec<(&wgpu::Buffer, u64)> = report.tallies.iter().map(|t| (&t.readback, 4)).collect();
        reads.extend(times.as_ref().map(|(b, n)| (b, *n)));
        let image = self.into.is_none().then(|| Region::copy(&mut enc, &t.out_texture, &t.image_readback, 16, tile.local()));
        let bound = (self.into.is_none() && report.error_bound)
            .then(|| Region::copy(&mut enc, &t.bound_texture, &t.bound_readback, 4, tile.local()));
        reads.extend(image.map(|r| (&t.image_readback, r.bytes())));
        reads.extend(bound.map(|r| (&t.bound_readback, r.bytes())));
        self.gpu.queue.submit([enc.finish()]);
        let mut raw = read_buffers(&self.gpu, &reads)?.into_iter();
        let tallies = std::mem::take(&mut report.tallies);
        let mut named = Vec::new();
        for tally in &tallies {
            let bytes = raw.next().expect("a tally's count");
            let count = u32::from_le_bytes(bytes[..4].try_into().expect("4 bytes")) as u64;
            report.overflow_fragments += count;
            named.extend(tally.extra.map(|name| (name, count as f64)));
        }
        // A tally's stat comes first, as the method's own extras follow its passes.
        report.extra.splice(0..0, named);
        let times = match times {
            Some(_) => Some(self.timer.durations(&raw.next().expect("the pass times"))),
            // Timed, with no pass recorded: no time.
            None => self.timer.enabled().then(Vec::new),
        };
        let size = (arrays.width, arrays.height);
        if let Some(r) = image {
            FrameArrays::place(&mut arrays.image, size, tile, r.unpack(&raw.next().expect("the image")), 4);
        }
        if let Some(r) = bound {
            FrameArrays::place(arrays.bound.get_or_insert_with(Vec::new), size, tile, r.unpack(&raw.next().expect("the bound")), 1);
        }
        Ok((report, times))
    }
}
