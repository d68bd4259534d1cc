//! The renderer: frame targets, the scene upload cache, the opaque pass, the census of
//! transparent fragments, and dispatch to the method by name.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use crate::antialias;
use crate::bindings::{COLOR_FORMAT, COUNT_FORMAT};
use crate::cache::{Draw, Layout, RenderDesc, ShaderKey};
use crate::context::GpuContext;
use crate::error::{invalid, OitError, Result};
use crate::gpu_types::{FrameUniform, GpuLight};
use crate::method::{self, AntialiasMode, FrameCtx, Limits, Method, MethodInfo, MethodReport, ParamValue, Params, Tiling};
use crate::passes;
use crate::pipeline;
use crate::scene::{Camera, Scene};
use crate::shader::SceneVariant;
use crate::shading::{Light, Lighting, MAX_LIGHTS};
pub use crate::stats::Stats;
use crate::targets::{read_buffer, read_rows, SampleTargets, Targets};
use crate::tiles::{self, Footprint, Tile};
use crate::timer::PassTimer;
use crate::upload::GpuScene;

/// Methods that take coverage masks (`AntialiasMode::Coverage` in their `antialias_modes`).
pub fn coverage_methods() -> Vec<&'static str> {
    method::methods().iter().filter(|m| m.antialias_modes.contains(&AntialiasMode::Coverage)).map(|m| m.name).collect()
}
/// Samples a pixel of a coverage-mask frame: WebGPU guarantees multisampling at 4 (lavapipe
/// offers no other count).
pub const COVERAGE_SAMPLES: u32 = 4;

pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// Row-major (height, width, 4) linear RGBA; row 0 is the top of the picture.
    pub image: Vec<f32>,
    /// Transparent fragments per pixel (same layout, one value a pixel); empty where the
    /// census did not run (`Stats::census`).
    pub depth_complexity: Vec<u32>,
    /// Per-pixel bound of the error against the exact composite (any RGB channel), for the
    /// methods that derive one.
    pub error_bound: Option<Vec<f32>>,
    pub stats: Stats,
}

/// Layouts and the uniform every frame uses, whatever the method; the opaque and census
/// pipelines come from the device's cache, specialized to the scene (`SceneVariant`).
struct Shared {
    scene_layout: wgpu::BindGroupLayout,
    targets_layout: wgpu::BindGroupLayout,
    counts_layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
}

impl Shared {
    fn new(gpu: &GpuContext) -> Self {
        let d = &gpu.device;
        let scene_layout = gpu.cache.layout(d, Layout::Scene);
        let targets_layout = gpu.cache.layout(d, Layout::Targets);
        let counts_layout = gpu.cache.layout(d, Layout::Storage(1));
        let uniform = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniform"),
            size: std::mem::size_of::<FrameUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self { scene_layout, targets_layout, counts_layout, uniform }
    }
}

/// The opaque pass's pipeline for `variant`: straight color, writes depth.
fn opaque_pipeline(gpu: &GpuContext, variant: SceneVariant) -> wgpu::RenderPipeline {
    let desc = RenderDesc {
        shader: ShaderKey::new("opaque.wgsl", &variant.consts()),
        entry: "fs_opaque",
        groups: vec![Layout::Scene],
        draw: Draw::Geometry { depth: pipeline::depth_write(), samples: 1 },
        targets: vec![Some(COLOR_FORMAT.into())],
    };
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
/// vertex shader drops the back faces a material culls (common/scene.wgsl).
fn census_pipeline(gpu: &GpuContext, kind: CensusKind, shaded: bool) -> wgpu::RenderPipeline {
    let variant = SceneVariant { shaded, ..Default::default() }.consts();
    let add = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    let desc = match kind {
        CensusKind::Blend => RenderDesc {
            shader: ShaderKey::new("census.wgsl", &variant),
            entry: "fs_count",
            groups: vec![Layout::Scene],
            draw: Draw::Geometry { depth: pipeline::depth_test_only(), samples: 1 },
            targets: vec![Some(wgpu::ColorTargetState {
                format: COUNT_FORMAT,
                blend: Some(wgpu::BlendState { color: add, alpha: add }),
                write_mask: wgpu::ColorWrites::RED,
            })],
        },
        CensusKind::Atomic => RenderDesc {
            shader: ShaderKey::new("census.wgsl", &variant),
            entry: "fs_census",
            groups: vec![Layout::Scene, Layout::Targets, Layout::Storage(1)],
            draw: Draw::Geometry { depth: pipeline::depth_test_only(), samples: 1 },
            targets: vec![],
        },
        CensusKind::Samples => RenderDesc {
            shader: ShaderKey::new("census_samples.wgsl", &variant),
            entry: "fs_census",
            groups: vec![Layout::Scene, Layout::SampleTargets, Layout::Storage(1)],
            draw: Draw::Geometry { depth: pipeline::raster_only(), samples: COVERAGE_SAMPLES },
            targets: vec![],
        },
    };
    gpu.cache.render(&gpu.device, &desc)
}

/// Renders scenes at one size with any registered method.
pub struct Renderer {
    gpu: Arc<GpuContext>,
    width: u32,
    height: u32,
    shared: Shared,
    targets: Targets,
    scene: Option<((u64, u64), GpuScene)>,
    methods: HashMap<&'static str, Box<dyn Method>>,
    timer: PassTimer,
    limits: Limits,
    /// Bytes a method may allocate for a frame (tiles keep it within); None: what the adapter's
    /// bindings allow.
    memory_budget: Option<u64>,
    /// Made at the first coverage-mask frame.
    coverage: Option<Coverage>,
    /// The lights and ambient term of the scene being rendered (the frame uniform's).
    lights: (Vec<Light>, [f32; 3]),
    /// Extra light evaluations per shaded fragment that leave its color unchanged (docs/shading.md).
    shading_cost: u32,
    /// Whether every frame runs the fragment census, not only those of methods that need it.
    census: bool,
    /// Whether the census counts with atomics even where the adapter blends float32.
    atomic_census: bool,
}

/// One device per adapter choice, shared by every renderer in the process.
pub fn shared_context(adapter: Option<&str>) -> Result<Arc<GpuContext>> {
    static CONTEXTS: OnceLock<Mutex<HashMap<String, Arc<GpuContext>>>> = OnceLock::new();
    let key = adapter.map(str::to_string).or_else(|| std::env::var("OIT_ADAPTER").ok()).unwrap_or_default();
    let mut map = CONTEXTS.get_or_init(Default::default).lock().unwrap_or_else(|e| e.into_inner());
    if let Some(c) = map.get(&key) {
        return Ok(c.clone());
    }
    let ctx = Arc::new(GpuContext::new(adapter)?);
    map.insert(key, ctx.clone());
    Ok(ctx)
}

impl Renderer {
    pub fn new(gpu: Arc<GpuContext>, width: u32, height: u32) -> Result<Self> {
        let max = gpu.limits.max_texture_dimension_2d;
        if width == 0 || height == 0 {
            return Err(invalid!("width and height must be positive, got {width} x {height}"));
        }
        if width > max || height > max {
            return Err(OitError::OutOfMemory(format!(
                "{width} x {height} passes the adapter's largest texture ({max} x {max}): render at most {max} pixels a side"
            )));
        }
        // The census keeps a count per pixel in one storage binding.
        method::check_per_pixel(gpu.max_binding_bytes(), width, height, "the fragment census", 4)?;
        let shared = Shared::new(&gpu);
        let targets = Targets::new(&gpu, width, height, &shared.targets_layout, &shared.counts_layout);
        // Allocation failures are reported through the error handler: surface them now,
        // rather than at the first render.
        gpu.take_error()?;
        let timer = PassTimer::new(&gpu);
        let limits = Limits { max_binding_bytes: gpu.max_binding_bytes() };
        Ok(Self {
            gpu,
            width,
            height,
            shared,
            targets,
            scene: None,
            methods: HashMap::new(),
            timer,
            limits,
            memory_budget: None,
            coverage: None,
            lights: (Vec::new(), [0.0; 3]),
            shading_cost: 0,
            census: false,
            atomic_census: false,
        })
    }

    /// Makes every shaded fragment evaluate `count` extra lights whose sum is multiplied by 0
    /// (in a uniform the compiler cannot see through): the image is unchanged and the cost of
    /// shading grows (docs/shading.md, "Shading cost").
    pub fn set_shading_cost(&mut self, count: u32) -> Result<()> {
        if count > 1 << 16 {
            return Err(invalid!("shading_cost must be in [0, 65536] light evaluations, got {count}"));
        }
        self.shading_cost = count;
        Ok(())
    }

    /// Runs the fragment census (per-pixel transparent fragment counts: `Stats::fragments`,
    /// `max_depth_complexity`, `Frame::depth_complexity`) in every frame when `always`; else only
    /// for the methods that plan from it (`MethodInfo::census`), so that the others pay for no
    /// extra geometry pass.
    pub fn set_census(&mut self, always: bool) {
        self.census = always;
    }

    /// Makes the census count with an atomic a fragment, as it does on adapters that cannot
    /// blend float32, instead of by blending (the counts are the same: tests compare them).
    pub fn set_atomic_census(&mut self, on: bool) {
        self.atomic_census = on;
    }

    /// Sizes method buffers as if the adapter bound at most `bytes` per storage binding
    /// (never more than it really does). Methods are rebuilt.
    pub fn set_max_binding_bytes(&mut self, bytes: u64) -> Result<()> {
        if bytes < 256 {
            return Err(invalid!("max_binding_bytes must be at least 256, got {bytes}"));
        }
        self.limits.max_binding_bytes = bytes.min(self.gpu.max_binding_bytes());
        self.methods.clear();
        self.scene = None; // uploaded again, in chunks that fit the new limit
        Ok(())
    }

    /// Keeps each method's own allocations for a frame within `bytes` (None: what the adapter's
    /// bindings allow), rendering in screen tiles where needed (docs/methods.md, "Tiles").
    pub fn set_memory_budget(&mut self, bytes: Option<u64>) -> Result<()> {
        if bytes.is_some_and(|b| b < 1024) {
            return Err(invalid!("memory_budget must be at least 1024 bytes, got {}", bytes.unwrap_or(0)));
        }
        self.memory_budget = bytes;
        Ok(())
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    pub fn context(&self) -> &Arc<GpuContext> {
        &self.gpu
    }

    pub fn render(
        &mut self,
        scene: &Scene,
        camera: &Camera,
        method_name: &str,
        params: &[(String, ParamValue)],
        background: [f32; 3],
    ) -> Result<Frame> {
        self.render_antialiased(scene, camera, method_name, params, background, 1, AntialiasMode::Frames)
    }

    /// Renders `antialias` sample frames, each with the camera moved onto one position of the
    /// standard pattern (`antialias::sample_offsets`), and averages them: every method gets
    /// antialiasing with its own buffers reused from sample to sample (memory as at one
    /// sample, time about `antialias` times). Stats: fragments and overflow are summed over
    /// the samples, depth complexity is the largest per pixel, GPU time the sum, memory the
    /// largest of the samples; the error bound is the mean of the samples' bounds (the
    /// error of a mean is at most the mean of the errors).
    ///
    /// `AntialiasMode::Coverage` instead rasterizes the transparent geometry once,
    /// multisampled, and stores one fragment per pixel with its sample mask (the methods of
    /// `coverage_methods()`, at COVERAGE_SAMPLES samples); docs/methods.md, "Antialiasing".
    #[allow(clippy::too_many_arguments)]
    pub fn render_antialiased(
        &mut self,
        scene: &Scene,
        camera: &Camera,
        method_name: &str,
        params: &[(String, ParamValue)],
        background: [f32; 3],
        antialias: u32,
        mode: AntialiasMode,
    ) -> Result<Frame> {
        let start = Instant::now();
        let offsets = antialias::sample_offsets(antialias)?;
        let info = method::lookup(method_name)?;
        let params = info.resolve_params(params)?;
        method::check_features(info, &self.gpu)?;
        if background.iter().any(|c| !c.is_finite() || !(0.0..=1.0).contains(c)) {
            return Err(invalid!("background {background:?} must be three linear RGB values in [0, 1]"));
        }
        let coverage = mode == AntialiasMode::Coverage && antialias > 1;
        if coverage {
            if !info.antialias_modes.contains(&AntialiasMode::Coverage) {
                return Err(invalid!(
                    "antialias_mode 'coverage' is implemented by {} only; '{}' antialiases with antialias_mode 'frames'",
                    coverage_methods().join(", "),
                    info.name
                ));
            }
            if antialias != COVERAGE_SAMPLES {
                return Err(invalid!(
                    "antialias_mode 'coverage' rasterizes at {COVERAGE_SAMPLES} samples a pixel (the count every adapter \
                     multisamples at), got antialias={antialias}: use antialias={COVERAGE_SAMPLES}, or antialias_mode 'frames'"
                ));
            }
        }
        self.upload(scene)?;
        self.lights = (scene.lights().to_vec(), scene.ambient());
        if offsets.len() == 1 || coverage {
            let mut frame = self.render_sample(camera, info, &params, background, coverage)?;
            frame.stats.wall_time_ms = start.elapsed().as_secs_f64() * 1e3;
            frame.stats.antialias = antialias;
            frame.stats.antialias_mode = if coverage { AntialiasMode::Coverage } else { mode };
            frame.stats.finish(&self.gpu.info.name, frame.error_bound.as_deref());
            return Ok(frame);
        }
        let pixels = self.width as usize * self.height as usize;
        let mut image = vec![0.0f64; pixels * 4];
        let mut bound: Option<Vec<f64>> = None;
        let mut depth_complexity = Vec::new();
        let mut stats = Stats::default();
        for (i, offset) in offsets.iter().enumerate() {
            let jittered = camera.jittered(*offset, self.width, self.height);
            let f = self.render_sample(&jittered, info, &params, background, false)?;
            image.iter_mut().zip(&f.image).for_each(|(a, &v)| *a += v as f64);
            if let Some(b) = &f.error_bound {
                let sum = bound.get_or_insert_with(|| vec![0.0; pixels]);
                sum.iter_mut().zip(b).for_each(|(a, &v)| *a += v as f64);
            }
            if depth_complexity.is_empty() {
                depth_complexity = vec![0u32; f.depth_complexity.len()];
            }
            depth_complexity.iter_mut().zip(&f.depth_complexity).for_each(|(a, &v)| *a = (*a).max(v));
            let s = f.stats;
            if i == 0 {
                stats = Stats { fragments: 0, overflow_fragments: 0, memory_bytes: 0, gpu_time_ms: Some(0.0), ..s.clone() };
            }
            stats.fragments += s.fragments;
            stats.overflow_fragments += s.overflow_fragments;
            stats.max_depth_complexity = stats.max_depth_complexity.max(s.max_depth_complexity);
            stats.memory_bytes = stats.memory_bytes.max(s.memory_bytes);
            stats.peak_memory_bytes = stats.peak_memory_bytes.max(s.peak_memory_bytes);
            stats.gpu_time_ms = stats.gpu_time_ms.zip(s.gpu_time_ms).map(|(a, b)| a + b);
            if i > 0 {
                stats.tiles += s.tiles;
                stats.pass_times_ms.extend(s.pass_times_ms);
            }
            stats.extra = s.extra;
        }
        let n = offsets.len() as f64;
        stats.wall_time_ms = start.elapsed().as_secs_f64() * 1e3;
        stats.antialias = antialias;
        stats.antialias_mode = AntialiasMode::Frames;
        let error_bound: Option<Vec<f32>> = bound.map(|b| b.iter().map(|&v| (v / n) as f32).collect());
        stats.finish(&self.gpu.info.name, error_bound.as_deref());
        Ok(Frame {
            width: self.width,
            height: self.height,
            image: image.iter().map(|&v| (v / n) as f32).collect(),
            depth_complexity,
            error_bound,
            stats,
        })
    }

    /// One frame with the pixel centers where `camera` puts them (the scene is uploaded); with
    /// `coverage`, a coverage-mask frame at COVERAGE_SAMPLES samples a pixel.
    fn render_sample(
        &mut self,
        camera: &Camera,
        info: &'static MethodInfo,
        params: &Params,
        background: [f32; 3],
        coverage: bool,
    ) -> Result<Frame> {
        let start = Instant::now();
        let gpu = self.gpu.clone();
        if coverage && self.coverage.is_none() {
            self.coverage = Some(Coverage::new(&gpu, self.width, self.height));
            gpu.take_error()?;
        }
        let cov = if coverage { self.coverage.as_ref() } else { None };
        let (_, gpu_scene) = self.scene.as_ref().expect("uploaded by the caller");
        let census = info.census || self.census;
        self.opaque_and_census(gpu_scene, camera, background, cov, census);
        let depth_complexity = match census {
            true => self.read_census(coverage)?,
            false => Vec::new(),
        };
        let max_depth_complexity = depth_complexity.iter().copied().max().unwrap_or(0);
        let fragments: u64 = depth_complexity.iter().map(|&c| c as u64).sum();

        let limits = self.limits;
        let variant = self.variant(gpu_scene);
        // Out of the map while it renders, so that the loop can set each tile's uniform.
        let mut method = self.methods.remove(info.name).unwrap_or_else(|| info.instantiate(&gpu, &limits));
        // Tiles planned from the census; a method whose storage proves larger than planned (pall's
        // pool follows its triangles' bounding boxes, not the fragments) is planned again with
        // the budget divided by how far it went over.
        let mut squeeze = 1.0f64;
        let (tiles, report, pass_times) = loop {
            let tiles = self.plan_tiles(info, params, &depth_complexity, coverage, squeeze)?;
            let mut report = MethodReport::default();
            let mut pass_times: Option<Vec<(&'static str, f64)>> = None;
            for tile in &tiles {
                let counts: std::borrow::Cow<[u32]> = match tiles.len() {
                    _ if !census => (&[] as &[u32]).into(),
                    1 => depth_complexity.as_slice().into(),
                    _ => tile.crop(&depth_complexity, self.width).into(),
                };
                self.set_uniform(camera, gpu_scene, background, *tile);
                self.timer.reset();
                let mut cx = FrameCtx {
                    gpu: &gpu,
                    scene: gpu_scene,
                    camera,
                    targets: &self.targets,
                    timer: &mut self.timer,
                    params,
                    tile: *tile,
                    max_depth_complexity: counts.iter().copied().max().unwrap_or(0),
                    frame_max_depth_complexity: max_depth_complexity,
                    fragments: counts.iter().map(|&c| c as u64).sum(),
                    depth_complexity: &counts,
                    frame_uniform: &self.shared.uniform,
                    limits: self.limits,
                    coverage: cov.map(|c| &c.targets),
                    variant,
                };
                let r = method.render(&mut cx)?;
                if let Some(short) = r.pool_short {
                    report.pool_short = Some(report.pool_short.unwrap_or(1.0).max(short));
                    break;
                }
                if let Some(t) = self.timer.read(&gpu)? {
                    pass_times.get_or_insert_with(Vec::new).extend(t);
                }
                report.memory_bytes = report.memory_bytes.max(r.memory_bytes);
                report.overflow_fragments += r.overflow_fragments;
                report.error_bound |= r.error_bound;
                for (k, v) in r.extra {
                    match report.extra.iter_mut().find(|(name, _)| *name == k) {
                        // Counts add up over tiles; auto's k and the like keep their largest.
                        Some((_, total)) if k.ends_with("_k") || k == "auto_exact" || k == "resolve_sweeps" => *total = total.max(v),
                        Some((_, total)) => *total += v,
                        None => report.extra.push((k, v)),
                    }
                }
            }
            if let Some(short) = report.pool_short {
                if squeeze < 1e6 {
                    squeeze *= 1.25 * short;
                    continue;
                }
            }
            match self.memory_budget {
                Some(budget) if report.memory_bytes > budget && squeeze < 1e6 => {
                    squeeze *= 1.25 * report.memory_bytes as f64 / budget as f64;
                }
                Some(budget) if report.memory_bytes > budget => {
                    self.methods.insert(info.name, method);
                    return Err(OitError::OutOfMemory(format!(
                        "'{}' needed {} bytes in its smallest tiles, past the memory_budget of {budget} bytes: raise \
                         memory_budget or use a bounded method (e.g. hybrid)",
                        info.name, report.memory_bytes
                    )));
                }
                _ => break (tiles, report, pass_times),
            }
        };
        self.methods.insert(info.name, method);
        self.set_camera(camera, gpu_scene, background);
        let t = &self.targets;
        let image = read_rows(&gpu, &t.out_texture, &t.image_readback, 16)?;
        let error_bound = if report.error_bound { Some(read_rows(&gpu, &t.bound_texture, &t.bound_readback, 4)?) } else { None };
        let target_bytes = self.targets.bytes() + cov.map_or(0, |c| c.targets.bytes());
        let scene_bytes = gpu_scene.transparent.bytes + gpu_scene.opaque.bytes;
        let stats = Stats {
            method: info.name.to_string(),
            params: params.clone(),
            census,
            fragments,
            max_depth_complexity,
            memory_bytes: report.memory_bytes,
            target_bytes,
            scene_bytes,
            gpu_time_ms: pass_times.as_ref().map(|p| p.iter().map(|(_, t)| t).sum()),
            pass_times_ms: pass_times.unwrap_or_default(),
            overflow_fragments: report.overflow_fragments,
            wall_time_ms: start.elapsed().as_secs_f64() * 1e3,
            extra: report.extra,
            antialias: 1,
            antialias_mode: AntialiasMode::Frames,
            tiles: tiles.len() as u32,
            geometry_chunks: gpu_scene.transparent.chunks.len() as u32,
            peak_memory_bytes: report.memory_bytes + target_bytes + scene_bytes,
            ..Default::default()
        };
        Ok(Frame { width: self.width, height: self.height, image, depth_complexity, error_bound, stats })
    }

    /// The screen tiles `info`'s method renders this frame in: one unless its storage would pass
    /// a binding or the memory budget (docs/methods.md, "Tiles").
    fn plan_tiles(&self, info: &MethodInfo, params: &Params, counts: &[u32], coverage: bool, squeeze: f64) -> Result<Vec<Tile>> {
        let (w, h) = (self.width, self.height);
        let budget = self.memory_budget.unwrap_or(u64::MAX);
        // What tiles can make smaller, divided by `squeeze` when a first plan proved too loose.
        let variable = |rest: u64| if rest == u64::MAX { rest } else { (rest as f64 / squeeze) as u64 };
        let binding = self.limits.max_binding_bytes;
        let fp = match info.tiling {
            Tiling::Whole => {
                let bytes = info.memory_bytes(w as u64 * h as u64, params, None).unwrap_or(0);
                if bytes > budget {
                    return Err(OitError::OutOfMemory(format!(
                        "'{}' keeps {bytes} bytes of render targets for a {w} x {h} frame, past the memory_budget of {budget} \
                         bytes, and renders in one piece: raise memory_budget or use a method that tiles (e.g. hybrid)",
                        info.name
                    )));
                }
                return Ok(vec![Tile::frame(w, h)]);
            }
            Tiling::Formula { targets } => {
                let one = info.memory_bytes(1, params, None).unwrap_or(0);
                let per_pixel = info.memory_bytes(2, params, None).unwrap_or(0) - one - targets;
                // Frame-sized render targets, which no tile makes smaller.
                let shared = targets * w as u64 * h as u64;
                if shared > 0 && shared >= budget {
                    return Err(OitError::OutOfMemory(format!(
                        "'{}' keeps {shared} bytes of frame-sized render targets for a {w} x {h} frame, which no tile \
                         can make smaller and which pass the memory_budget of {budget} bytes: raise memory_budget",
                        info.name
                    )));
                }
                // Every buffer of the method within one binding: at most all of a tile's bytes.
                let fits = binding / per_pixel.max(1);
                Footprint {
                    per_pixel,
                    per_fragment: 0,
                    budget: variable(budget.saturating_sub(one - per_pixel - targets).saturating_sub(shared)),
                    max_pixels: fits,
                    max_fragments: u64::MAX,
                }
            }
            Tiling::Storage { per_pixel, per_fragment, per_triangle } => {
                // A coverage-mask frame keeps sweep state per sample and a mask per node.
                let (per_pixel, per_fragment) = if coverage {
                    (crate::method::lists::pixel_bytes(COVERAGE_SAMPLES), per_fragment + 8)
                } else {
                    (per_pixel, per_fragment)
                };
                let pool = crate::method::lists::POOL_BINDINGS * (binding / per_fragment);
                let fixed = per_triangle * self.scene.as_ref().map_or(0, |(_, s)| s.transparent.triangles as u64);
                if fixed >= budget {
                    return Err(OitError::OutOfMemory(format!(
                        "'{}' keeps {per_triangle} bytes for each transparent triangle, {fixed} bytes in all, which no tile \
                         can make smaller and which pass the memory_budget of {budget} bytes: raise memory_budget or use \
                         abuffer or sbuffer, which keep nothing per triangle",
                        info.name
                    )));
                }
                Footprint {
                    per_pixel,
                    per_fragment,
                    budget: variable(budget - fixed),
                    max_pixels: binding / per_pixel,
                    max_fragments: (pool as f64 / squeeze) as u64,
                }
            }
        };
        tiles::plan(w, h, counts, &fp)
    }

    fn upload(&mut self, scene: &Scene) -> Result<()> {
        if self.scene.as_ref().map(|(k, _)| *k) != Some(scene.key()) {
            self.scene = None; // free the old buffers first
            let s = GpuScene::new(&self.gpu, scene, &self.shared.scene_layout, &self.shared.uniform, self.limits.max_binding_bytes)?;
            self.scene = Some((scene.key(), s));
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

    /// The census's per-pixel counts, row-major.
    fn read_census(&self, coverage: bool) -> Result<Vec<u32>> {
        let t = &self.targets;
        Ok(match self.census_kind(coverage) {
            // Whole numbers below 2^24, exact in float32.
            CensusKind::Blend => read_rows(&self.gpu, &t.count_texture, &t.counts_readback, 4)?.iter().map(|&c| c as u32).collect(),
            _ => bytemuck::pod_collect_to_vec(&read_buffer(&self.gpu, &t.counts_readback, self.width as u64 * self.height as u64 * 4)?),
        })
    }

    /// What `scene`'s passes compile for: its surfaces, its light count (the headlight when it
    /// has none) and the shading-cost knob.
    fn variant(&self, scene: &GpuScene) -> SceneVariant {
        SceneVariant {
            shaded: scene.shaded,
            lights: Lighting::count(&self.lights.0),
            textured: scene.textured,
            shading_cost: self.shading_cost,
        }
    }

    /// Writes the frame uniform for `camera`.
    fn set_camera(&self, camera: &Camera, scene: &GpuScene, bg: [f32; 3]) {
        self.set_uniform(camera, scene, bg, Tile::frame(self.width, self.height));
    }

    /// Writes the frame uniform for `camera` and the screen tile `tile`.
    fn set_uniform(&self, camera: &Camera, scene: &GpuScene, bg: [f32; 3], tile: Tile) {
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
            tile_origin: [tile.x, tile.y],
            tile_size: [tile.width, tile.height],
            inv_view_proj: camera.view_proj.inverse().as_mat4().to_cols_array_2d(),
            ambient: [a.x, a.y, a.z, 0.0],
            lights,
        };
        self.gpu.queue.write_buffer(&self.shared.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Opaque geometry into a base color and depth target (under the current uniform).
    fn opaque_pass(
        &self,
        enc: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        color: &wgpu::TextureView,
        depth: &wgpu::TextureView,
        bg: [f32; 3],
    ) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("opaque"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r: bg[0] as f64, g: bg[1] as f64, b: bg[2] as f64, a: 0.0 }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&opaque_pipeline(&self.gpu, self.variant(scene)));
        scene.opaque.draw_all(&mut pass);
    }

    /// The opaque pass under `camera` (for a coverage-mask frame, one per sample position into
    /// the sample targets), then with `census` the untimed fragment census, copied to its readback.
    fn opaque_and_census(&self, scene: &GpuScene, camera: &Camera, bg: [f32; 3], coverage: Option<&Coverage>, census: bool) {
        let t = &self.targets;
        if let Some(c) = coverage {
            let offsets = antialias::sample_offsets(c.targets.samples).expect("a supported sample count");
            for (s, offset) in offsets.iter().enumerate() {
                self.set_camera(&camera.jittered(*offset, self.width, self.height), scene, bg);
                let mut enc = self.gpu.device.create_command_encoder(&Default::default());
                self.opaque_pass(&mut enc, scene, &c.targets.base_layers[s], &c.targets.depth_layers[s], bg);
                self.gpu.queue.submit([enc.finish()]);
            }
        }
        self.set_camera(camera, scene, bg);
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        if coverage.is_none() {
            self.opaque_pass(&mut enc, scene, &t.base, &t.depth, bg);
        }
        if census {
            match self.census_kind(coverage.is_some()) {
                CensusKind::Blend => {
                    let count = wgpu::RenderPassColorAttachment {
                        view: &t.count,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store },
                    };
                    let mut pass = passes::capture_into(&mut enc, "census", &t.depth, &[Some(count)], None);
                    pass.set_pipeline(&census_pipeline(&self.gpu, CensusKind::Blend, scene.shaded));
                    scene.transparent.draw_all(&mut pass);
                }
                kind => {
                    enc.clear_buffer(&t.counts, 0, None);
                    let (group, depth) = match coverage {
                        Some(c) => (&c.targets.group, &c.targets.raster_depth),
                        None => (&t.group, &t.depth),
                    };
                    {
                        let mut pass = passes::capture_pass(&mut enc, "census", depth, None);
                        pass.set_pipeline(&census_pipeline(&self.gpu, kind, scene.shaded));
                        pass.set_bind_group(1, group, &[]);
                        pass.set_bind_group(2, &t.counts_group, &[]);
                        scene.transparent.draw_all(&mut pass);
                    }
                    let bytes = t.counts.size().min(t.counts_readback.size());
                    enc.copy_buffer_to_buffer(&t.counts, 0, &t.counts_readback, 0, bytes);
                }
            }
        }
        self.gpu.queue.submit([enc.finish()]);
    }
}

/// What a coverage-mask frame needs besides the frame targets: the per-sample targets (the
/// census is multisampled: `census_pipeline`).
struct Coverage {
    targets: SampleTargets,
}

impl Coverage {
    fn new(gpu: &GpuContext, width: u32, height: u32) -> Self {
        let layout = gpu.cache.layout(&gpu.device, Layout::SampleTargets);
        Self { targets: SampleTargets::new(gpu, width, height, COVERAGE_SAMPLES, &layout) }
    }
}
