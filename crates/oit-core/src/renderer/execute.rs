//! The executor: runs a frame tile by tile as the planner says (`plan.rs`). Per tile it draws the
//! opaque pass into the tile-sized targets, runs the method, and streams the tile's pixels into
//! the frame's arrays; the census runs first, in bands of rows that the targets hold. Reports of
//! the tiles merge by declared rules (`stats::Merge`).

use std::time::Instant;

use super::{Frame, Renderer, COVERAGE_SAMPLES};
use crate::antialias;
use crate::bindings::{COLOR_FORMAT, COUNT_FORMAT};
use crate::cache::{Draw, Layout, CENSUS_ATOMIC, CENSUS_BLEND, CENSUS_SAMPLES, EXPAND_PARTICLES, EXPAND_STRANDS, OPAQUE};
use crate::context::GpuContext;
use crate::error::{OitError, Result};
use crate::gpu_types::{FrameUniform, GpuLight};
use crate::method::{AntialiasMode, FrameCtx, MethodInfo, MethodReport, Params};
use crate::passes;
use crate::pipeline;
use crate::scene::Camera;
use crate::shader::SceneVariant;
use crate::shading::{Lighting, MAX_LIGHTS};
use crate::stats::{ExtraMerge, Stats};
use crate::targets::{read_buffer, read_region, SampleTargets, Targets};
use crate::tiles::Tile;
use crate::upload::GpuScene;

/// The opaque pass's pipeline for `variant`: straight color, writes depth.
fn opaque_pipeline(gpu: &GpuContext, variant: SceneVariant) -> wgpu::RenderPipeline {
    let desc =
        OPAQUE.render(&variant.consts(), Draw::Geometry { depth: pipeline::depth_write(), samples: 1 }, vec![Some(COLOR_FORMAT.into())]);
    gpu.cache.render(&gpu.device, &desc)
}

/// How the census counts: by blending into the count target where the adapter blends float32
/// (one pass, no atomics), else with an atomic a fragment into the counts buffer; a
/// coverage-mask frame counts with atomics at each sample's coverage.
#[derive(Clone, Copy, PartialEq)]
enum CensusKind {
    Blend,
    Atomic,
    Samples,
}

/// The census pipeline of `kind`. The census reads only positions: its variant is the unlit
/// one, or for a scene with a material table (`shaded`) the shaded one without lights, whose
/// vertex shader drops the back faces a material culls (common/scene.wgsl); instanced where the
/// scene is.
fn census_pipeline(gpu: &GpuContext, kind: CensusKind, scene: &GpuScene) -> wgpu::RenderPipeline {
    let variant = SceneVariant {
        shaded: scene.shaded,
        instanced: scene.instanced,
        primitives: scene.primitives,
        sets_only: scene.sets_only,
        ..Default::default()
    }
    .consts();
    let add = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    let desc = match kind {
        CensusKind::Blend => CENSUS_BLEND.render(
            &variant,
            Draw::Geometry { depth: pipeline::depth_test_only(), samples: 1 },
            vec![Some(wgpu::ColorTargetState {
                format: COUNT_FORMAT,
                blend: Some(wgpu::BlendState { color: add, alpha: add }),
                write_mask: wgpu::ColorWrites::RED,
            })],
        ),
        CensusKind::Atomic => CENSUS_ATOMIC.render(&variant, Draw::Geometry { depth: pipeline::depth_test_only(), samples: 1 }, vec![]),
        CensusKind::Samples => {
            CENSUS_SAMPLES.render(&variant, Draw::Geometry { depth: pipeline::raster_only(), samples: COVERAGE_SAMPLES }, vec![])
        }
    };
    gpu.cache.render(&gpu.device, &desc)
}

/// What a coverage-mask frame needs besides the frame targets: the per-sample targets (the
/// census is multisampled: `census_pipeline`), at the tile size.
pub(super) struct Coverage {
    targets: SampleTargets,
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
    /// One frame with the pixel centers where `camera` puts them (the scene is uploaded); with
    /// `coverage`, a coverage-mask frame at COVERAGE_SAMPLES samples a pixel.
    pub(super) fn render_sample(
        &mut self,
        camera: &Camera,
        info: &'static MethodInfo,
        params: &Params,
        background: [f32; 3],
        coverage: bool,
    ) -> Result<Frame> {
        match self.render_counted(camera, info, params, background, coverage, true)? {
            Some(frame) => Ok(frame),
            // The method's own count did not fit one pool in one tile: the census plans tiles.
            None => Ok(self.render_counted(camera, info, params, background, coverage, false)?.expect("a census frame is rendered")),
        }
    }

    /// `render_sample`; with `self_count`, a method that counts its fragments in its own
    /// capture (`Method::counts_in_capture`) does so in place of the census, where the frame
    /// is whole, one sample and without a budget. None: that frame did not fit one tile, and
    /// needs the census after all.
    fn render_counted(
        &mut self,
        camera: &Camera,
        info: &'static MethodInfo,
        params: &Params,
        background: [f32; 3],
        coverage: bool,
        self_count: bool,
    ) -> Result<Option<Frame>> {
        let start = Instant::now();
        let gpu = self.gpu.clone();
        let (w, h) = (self.width, self.height);
        if self.memory_budget.is_some() {
            // Under a budget no method keeps storage between frames: what the frame allocates
            // is what it reports, and the census runs with the targets alone.
            self.methods.remove(info.name);
        }
        let limits = self.limits;
        // Out of the map while it renders, so that the loop can set each tile's uniform.
        let mut method = self.methods.remove(info.name).unwrap_or_else(|| info.instantiate(&gpu, &limits));
        // A method that counts in its capture reports the counts the census would have.
        let self_counted = self_count
            && info.needs_census(params)
            && !self.census
            && !coverage
            && self.memory_budget.is_none()
            && method.counts_in_capture();
        let census = (info.needs_census(params) && !self_counted) || self.census;
        let expand_times = self.expand_primitives(camera, background)?;
        // The census, in bands of rows the targets hold; `drawn` is the tile whose opaque pass
        // the targets hold.
        let mut counts = Vec::new();
        let mut drawn = None;
        if census {
            let rows = self.census_rows(coverage)?;
            counts = vec![0u32; w as usize * h as usize];
            for y in (0..h).step_by(rows as usize) {
                let mut band = Tile { x: 0, y, width: w, height: rows.min(h - y), frame: (w, h), origin: (0, 0) };
                if rows < h {
                    band = band.own_targets();
                }
                self.ensure_targets(w, rows, coverage)?;
                self.draw_opaque(band, camera, background, coverage, true);
                let values = self.read_census(band, coverage)?;
                counts[(y * w) as usize..(y * w) as usize + values.len()].copy_from_slice(&values);
                drawn = Some(band);
            }
        }
        let result = self.run_tiles(&mut *method, camera, info, params, background, coverage, &counts, drawn, self_counted);
        if self.memory_budget.is_none() {
            self.methods.insert(info.name, method);
        }
        let Some((tiles, mut report, mut pass_times, arrays)) = result? else {
            return Ok(None);
        };
        if let Some(c) = report.counts.take() {
            counts = c;
        }
        let max_depth_complexity = counts.iter().copied().max().unwrap_or(0);
        let fragments: u64 = counts.iter().map(|&c| c as u64).sum();
        if let (Some(p), Some(mut e)) = (pass_times.as_mut(), expand_times) {
            e.append(p);
            *p = e;
        }
        if let (Some(into), Some(t)) = (&self.into, &self.targets) {
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            self.blit(&mut enc, &t.out, &into.color, wgpu::ColorWrites::COLOR, into.encode_srgb);
            gpu.queue.submit([enc.finish()]);
        }
        let (_, gpu_scene) = self.scene.as_ref().expect("uploaded by the caller");
        self.set_uniform(camera, gpu_scene, background, Tile::frame(w, h));
        let target_bytes = self.held_target_bytes();
        let stats = Stats {
            method: info.name.to_string(),
            params: params.clone(),
            census: census || self_counted,
            fragments,
            max_depth_complexity,
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
            tiles: tiles.len() as u32,
            geometry_chunks: gpu_scene.transparent.chunks.len() as u32,
            instances: gpu_scene.instances,
            peak_memory_bytes: report.memory_bytes + target_bytes,
            ..Default::default()
        };
        Ok(Some(Frame { width: w, height: h, image: arrays.image, depth_complexity: counts, error_bound: arrays.bound, stats }))
    }

    /// Renders `method` over the planned tiles, each into the targets and then into the frame's
    /// arrays. A method whose storage proves larger than planned (pall's pool follows its
    /// triangles' bounding boxes, not the fragments) is planned again with the budget divided by
    /// how far it went over. With `self_counted` (no census ran: the method counts in its own
    /// capture), None where the frame would need more than one tile or pool.
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn run_tiles(
        &mut self,
        method: &mut dyn crate::method::Method,
        camera: &Camera,
        info: &'static MethodInfo,
        params: &Params,
        background: [f32; 3],
        coverage: bool,
        counts: &[u32],
        mut drawn: Option<Tile>,
        self_counted: bool,
    ) -> Result<Option<(Vec<Tile>, MethodReport, Option<Vec<(&'static str, f64)>>, FrameArrays)>> {
        let gpu = self.gpu.clone();
        let (w, h) = (self.width, self.height);
        let frame_max_depth_complexity = counts.iter().copied().max().unwrap_or(0);
        let mut squeeze = 1.0f64;
        loop {
            let plan = self.plan_tiles(info, params, counts, coverage, squeeze, self_counted)?;
            if self.into.is_some() && plan.targets != (w, h) {
                return Err(self.target_refused());
            }
            let tiles = plan.tiles;
            if self_counted && !(tiles.len() == 1 && tiles[0].is_whole()) {
                return Ok(None);
            }
            if self.ensure_targets(plan.targets.0, plan.targets.1, coverage)? {
                drawn = None;
            }
            let mut report = MethodReport::default();
            let mut extra = ExtraMerge::default();
            let mut pass_times: Option<Vec<(&'static str, f64)>> = None;
            let mut arrays = FrameArrays::new(w, h);
            for tile in &tiles {
                let tile_counts: std::borrow::Cow<[u32]> = match tiles.len() {
                    _ if counts.is_empty() => (&[] as &[u32]).into(),
                    1 => counts.into(),
                    _ => tile.crop(counts, w).into(),
                };
                if drawn != Some(*tile) {
                    self.draw_opaque(*tile, camera, background, coverage, false);
                }
                drawn = None; // the method's passes overwrite what the next tile would reuse
                let (_, gpu_scene) = self.scene.as_ref().expect("uploaded by the caller");
                self.set_uniform(camera, gpu_scene, background, *tile);
                self.timer.reset();
                let variant = self.variant(gpu_scene);
                let mut cx = FrameCtx {
                    gpu: &gpu,
                    scene: gpu_scene,
                    camera,
                    targets: self.targets.as_ref().expect("made above"),
                    timer: &mut self.timer,
                    params,
                    tile: *tile,
                    max_depth_complexity: tile_counts.iter().copied().max().unwrap_or(0),
                    frame_max_depth_complexity,
                    fragments: tile_counts.iter().map(|&c| c as u64).sum(),
                    depth_complexity: &tile_counts,
                    frame_uniform: &self.shared.uniform,
                    limits: self.limits,
                    coverage: self.coverage.as_ref().filter(|_| coverage).map(|c| &c.targets),
                    variant,
                };
                let r = method.render(&mut cx)?;
                if self_counted && (r.pool_short.is_some() || r.counts.is_none()) {
                    return Ok(None);
                }
                if let Some(short) = r.pool_short {
                    report.pool_short = Some(short);
                    break;
                }
                if let Some(t) = self.timer.read(&gpu)? {
                    pass_times.get_or_insert_with(Vec::new).extend(t);
                }
                report.memory_bytes = report.memory_bytes.max(r.memory_bytes);
                report.counts = r.counts;
                report.overflow_fragments += r.overflow_fragments;
                extra.add(&r.extra, tile.pixels() as f64);
                self.read_tile(*tile, r.error_bound, &mut arrays)?;
            }
            report.extra = extra.finish();
            if let Some(short) = report.pool_short {
                if squeeze < 1e6 {
                    squeeze *= 1.25 * short;
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
                        info.name
                    )));
                }
                _ => return Ok(Some((tiles, report, pass_times, arrays))),
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
            self.targets = Some(Targets::new(&self.gpu, width, height, &self.shared.targets_layout, &self.shared.counts_layout));
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

    /// Reads `tile`'s output (and its error bound, with `bound`) into the frame's arrays; a
    /// frame into a caller's texture is copied there instead, once whole.
    fn read_tile(&self, tile: Tile, bound: bool, arrays: &mut FrameArrays) -> Result<()> {
        let t = self.targets.as_ref().expect("made by ensure_targets");
        if self.into.is_some() {
            return Ok(());
        }
        let size = (arrays.width, arrays.height);
        let image = read_region(&self.gpu, &t.out_texture, &t.image_readback, 16, tile.local())?;
        FrameArrays::place(&mut arrays.image, size, tile, image, 4);
        if bound {
            let values = read_region(&self.gpu, &t.bound_texture, &t.bound_readback, 4, tile.local())?;
            FrameArrays::place(arrays.bound.get_or_insert_with(Vec::new), size, tile, values, 1);
        }
        Ok(())
    }

    /// How this frame's census counts (`CensusKind`).
    fn census_kind(&self, coverage: bool) -> CensusKind {
        match coverage {
            true => CensusKind::Samples,
            false if !self.atomic_census && self.gpu.device.features().contains(wgpu::Features::FLOAT32_BLENDABLE) => CensusKind::Blend,
            false => CensusKind::Atomic,
        }
    }

    /// The census's per-pixel counts of `tile`, row-major.
    fn read_census(&self, tile: Tile, coverage: bool) -> Result<Vec<u32>> {
        let t = self.targets.as_ref().expect("made by ensure_targets");
        Ok(match self.census_kind(coverage) {
            // Whole numbers below 2^24, exact in float32.
            CensusKind::Blend => {
                read_region(&self.gpu, &t.count_texture, &t.counts_readback, 4, tile.local())?.iter().map(|&c| c as u32).collect()
            }
            _ => bytemuck::pod_collect_to_vec(&read_buffer(&self.gpu, &t.counts_readback, tile.pixels() * 4)?),
        })
    }

    /// Builds the strand and particle corners under `camera` (shaders/expand.wgsl), once a
    /// frame before any pass draws them; nothing where the scene has none, or where the corners
    /// in `expanded` were built for this scene under the same matrices (a still camera, or
    /// another method of `oit compare` on the same view: no pass "expand" then).
    /// Its time is the frame's pass "expand": the wall time of its submission, waited for, and
    /// not timestamps, because on lavapipe a compute pass's timestamp queries make the draws
    /// after it up to twice as slow (docs/results.md, "Strands against triangle ribbons").
    fn expand_primitives(&mut self, camera: &Camera, bg: [f32; 3]) -> Result<Option<Vec<(&'static str, f64)>>> {
        let (w, h) = (self.width, self.height);
        let Some((_, scene)) = self.scene.as_ref().filter(|(_, s)| s.primitives) else { return Ok(None) };
        // The corners depend on the uploaded scene and on the two matrices the uniform carries;
        // a scene that changes is uploaded again (GpuScene::new, which forgets the view).
        let view = expansion_view(camera);
        if scene.expanded_view.get() == Some(view) {
            return Ok(None);
        }
        self.set_uniform(camera, scene, bg, Tile::frame(w, h));
        let consts = self.variant(scene).consts();
        // Compiled for the kinds the scene has (the cache keeps them).
        let pipeline = |strands: bool| {
            let spec = if strands { &EXPAND_STRANDS } else { &EXPAND_PARTICLES };
            self.gpu.cache.compute(&self.gpu.device, &spec.compute_desc(&consts))
        };
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("expand"), timestamp_writes: None });
            scene.transparent.expand(&mut pass, pipeline);
            scene.opaque.expand(&mut pass, pipeline);
        }
        scene.expanded_view.set(Some(view));
        if !self.timer.enabled() {
            self.gpu.queue.submit([enc.finish()]);
            return Ok(None);
        }
        let start = Instant::now();
        self.gpu.queue.submit([enc.finish()]);
        self.gpu.wait()?;
        Ok(Some(vec![("expand", start.elapsed().as_secs_f64() * 1e3)]))
    }

    /// Writes the frame uniform for `camera` and the screen tile `tile`.
    pub(super) fn set_uniform(&self, camera: &Camera, scene: &GpuScene, bg: [f32; 3], tile: Tile) {
        let lighting = Lighting::new(&self.lights.0, self.lights.1, camera.view_direction());
        let mut lights = [GpuLight::default(); MAX_LIGHTS as usize];
        for (g, (l, radiance)) in lights.iter_mut().zip(&lighting.lights) {
            g.to_light = l.as_vec3().extend(0.0).to_array();
            g.radiance = radiance.as_vec3().extend(0.0).to_array();
        }
        let a = lighting.ambient.as_vec3();
        let uniform = FrameUniform {
            view_proj: camera.matrix_f32().to_cols_array_2d(),
            background: [bg[0], bg[1], bg[2], 0.0],
            size: [self.width, self.height],
            triangle_count: scene.transparent.triangles,
            seed: 0,
            tile_origin: [tile.x - tile.origin.0, tile.y - tile.origin.1],
            tile_size: [tile.width, tile.height],
            target_origin: [tile.origin.0, tile.origin.1],
            pad: [0; 2],
            inv_view_proj: camera.view_proj.inverse().as_mat4().to_cols_array_2d(),
            ambient: [a.x, a.y, a.z, 0.0],
            lights,
        };
        self.gpu.queue.write_buffer(&self.shared.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Opaque geometry into a base color and depth target over `tile` (under the current
    /// uniform), over the background or, in a frame into a caller's texture with its depth, over
    /// the caller's picture and depth.
    fn opaque_pass(&self, enc: &mut wgpu::CommandEncoder, tile: Tile, color: &wgpu::TextureView, depth: &wgpu::TextureView, bg: [f32; 3]) {
        let (_, scene) = self.scene.as_ref().expect("uploaded by the caller");
        let over = self.into.as_ref().and_then(|i| i.depth.as_ref().map(|d| (&i.color, d)));
        let (color_load, depth_load) = match over {
            Some((picture, caller_depth)) => {
                let t = self.targets.as_ref().expect("made by ensure_targets");
                enc.copy_texture_to_texture(caller_depth.as_image_copy(), t.depth_texture.as_image_copy(), caller_depth.size());
                self.blit(enc, &picture.create_view(&Default::default()), &t.base_texture, wgpu::ColorWrites::ALL, false);
                (wgpu::LoadOp::Load, wgpu::LoadOp::Load)
            }
            None => {
                (wgpu::LoadOp::Clear(wgpu::Color { r: bg[0] as f64, g: bg[1] as f64, b: bg[2] as f64, a: 0.0 }), wgpu::LoadOp::Clear(1.0))
            }
        };
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("opaque"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: color_load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations { load: depth_load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        tile.scissor(&mut pass);
        pass.set_pipeline(&opaque_pipeline(&self.gpu, self.variant(scene)));
        scene.opaque.draw_all(&mut pass);
    }

    /// The opaque pass of `tile` under `camera` (for a coverage-mask frame, one per sample
    /// position into the sample targets), then with `census` the untimed fragment census,
    /// copied to its readback.
    fn draw_opaque(&self, tile: Tile, camera: &Camera, bg: [f32; 3], coverage: bool, census: bool) {
        let t = self.targets.as_ref().expect("made by ensure_targets");
        let (_, scene) = self.scene.as_ref().expect("uploaded by the caller");
        let cov = self.coverage.as_ref().filter(|_| coverage);
        if let Some(c) = cov {
            let offsets = antialias::sample_offsets(c.targets.samples).expect("a supported sample count");
            for (s, offset) in offsets.iter().enumerate() {
                self.set_uniform(&camera.jittered(*offset, self.width, self.height), scene, bg, tile);
                let mut enc = self.gpu.device.create_command_encoder(&Default::default());
                self.opaque_pass(&mut enc, tile, &c.targets.base_layers[s], &c.targets.depth_layers[s], bg);
                self.gpu.queue.submit([enc.finish()]);
            }
        }
        self.set_uniform(camera, scene, bg, tile);
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        if cov.is_none() {
            self.opaque_pass(&mut enc, tile, &t.base, &t.depth, bg);
        }
        if census {
            match self.census_kind(coverage) {
                CensusKind::Blend => {
                    let count = wgpu::RenderPassColorAttachment {
                        view: &t.count,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
                    };
                    let mut pass = passes::capture_into(&mut enc, "census", &t.depth, &[Some(count)], None);
                    tile.scissor(&mut pass);
                    pass.set_pipeline(&census_pipeline(&self.gpu, CensusKind::Blend, scene));
                    scene.transparent.draw_all(&mut pass);
                }
                kind => {
                    enc.clear_buffer(&t.counts, 0, None);
                    let (group, depth) = match cov {
                        Some(c) => (&c.targets.group, &c.targets.raster_depth),
                        None => (&t.group, &t.depth),
                    };
                    {
                        let mut pass = passes::capture_pass(&mut enc, "census", depth, None);
                        tile.scissor(&mut pass);
                        pass.set_pipeline(&census_pipeline(&self.gpu, kind, scene));
                        pass.set_bind_group(1, group, &[]);
                        pass.set_bind_group(2, &t.counts_group, &[]);
                        scene.transparent.draw_all(&mut pass);
                    }
                    let bytes = (tile.pixels() * 4).min(t.counts.size()).min(t.counts_readback.size());
                    enc.copy_buffer_to_buffer(&t.counts, 0, &t.counts_readback, 0, bytes);
                }
            }
        }
        self.gpu.queue.submit([enc.finish()]);
    }
}

/// What the expansion reads of the camera, as the frame uniform carries it: the view-projection
/// and its inverse, float32 bits (their equality is the corners').
fn expansion_view(camera: &Camera) -> [u32; 32] {
    let mut bits = [0u32; 32];
    let a = camera.matrix_f32().to_cols_array();
    let b = camera.view_proj.inverse().as_mat4().to_cols_array();
    for (o, v) in bits.iter_mut().zip(a.iter().chain(&b)) {
        *o = v.to_bits();
    }
    bits
}
