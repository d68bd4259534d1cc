//! The renderer's public entry points: a renderer at one size, its settings, and frames of any
//! method (averaged over samples when antialiased). The planner (`plan.rs`) decides a frame's
//! tiles; the executor (`execute.rs`) runs the opaque pass, the census and the method tile by
//! tile.

mod census;
mod execute;
mod into;
mod opaque;
mod plan;

use execute::Job;
pub use into::Target;

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use crate::antialias;
use crate::cache::Layout;
use crate::context::GpuContext;
use crate::error::{invalid, OitError, Result};
use crate::gpu_types::FrameUniform;
use crate::method::{self, AntialiasMode, Limits, Method, MethodInfo, ParamValue, Params};
use crate::scene::{Camera, Scene};
use crate::shader::SceneVariant;
use crate::shading::{Light, Lighting};
use crate::stats::SampleMerge;
pub use crate::stats::Stats;
use crate::targets::Targets;
use crate::timer::PassTimer;
use crate::upload::GpuScene;

/// Methods that take coverage masks (`AntialiasMode::Coverage` in their `antialias_modes`).
pub fn coverage_methods() -> Vec<&'static str> {
    method::methods().iter().filter(|m| m.antialias_modes.contains(&AntialiasMode::Coverage)).map(|m| m.name).collect()
}
/// How a frame is antialiased: `samples` a pixel, made the way `mode` says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Antialias {
    pub samples: u32,
    pub mode: AntialiasMode,
}

impl Antialias {
    /// One sample a pixel.
    pub const NONE: Self = Self { samples: 1, mode: AntialiasMode::Frames };
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
    uniform: wgpu::Buffer,
}

impl Shared {
    fn new(gpu: &GpuContext) -> Self {
        let d = &gpu.device;
        let scene_layout = gpu.cache.layout(d, Layout::Scene);
        let targets_layout = gpu.cache.layout(d, Layout::Targets);
        let uniform = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniform"),
            size: std::mem::size_of::<FrameUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self { scene_layout, targets_layout, uniform }
    }
}

/// Renders scenes at one size with any registered method.
pub struct Renderer {
    gpu: Arc<GpuContext>,
    width: u32,
    height: u32,
    shared: Shared,
    /// The frame's own targets, at the size of its largest tile (made at the first frame).
    targets: Option<Targets>,
    scene: Option<((u64, u64), GpuScene)>,
    methods: HashMap<&'static str, Box<dyn Method>>,
    timer: PassTimer,
    limits: Limits,
    /// Bytes a frame may allocate (its method's storage and its own targets and readbacks: tiles
    /// keep it within); None: what the adapter's bindings allow.
    memory_budget: Option<u64>,
    /// Made at the first coverage-mask frame, at the tile size.
    coverage: Option<execute::Coverage>,
    /// The lights and ambient term of the scene being rendered (the frame uniform's).
    lights: (Vec<Light>, [f32; 3]),
    /// Extra light evaluations per shaded fragment that leave its color unchanged (docs/shading.md).
    shading_cost: u32,
    /// Whether every frame runs the fragment census, not only those of methods that need it.
    census: bool,
    /// Whether the census counts with atomics even where the adapter blends float32.
    atomic_census: bool,
    /// The caller's textures while `render_into` renders into them.
    into: Option<into::IntoTarget>,
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
        let timer = PassTimer::new(&gpu);
        let limits = Limits { max_binding_bytes: gpu.max_binding_bytes() };
        Ok(Self {
            gpu,
            width,
            height,
            shared,
            targets: None,
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
            into: None,
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
            return Err(invalid!("max_binding_bytes must be at least 256 bytes, got {bytes}"));
        }
        self.limits.max_binding_bytes = bytes.min(self.gpu.max_binding_bytes());
        self.methods.clear();
        self.scene = None; // uploaded again, in chunks that fit the new limit
        Ok(())
    }

    /// Keeps what a frame allocates (the method's storage, the frame's targets and readbacks)
    /// within `bytes` (None: what the adapter's bindings allow), rendering in screen tiles where
    /// needed (docs/methods.md, "Tiles"). Under a budget no method keeps storage between frames.
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
        self.render_antialiased(scene, camera, method_name, params, background, Antialias::NONE)
    }

    /// Renders `antialias.samples` sample frames, each with the camera moved onto one position of the
    /// standard pattern (`antialias::sample_offsets`), and averages them: every method gets
    /// antialiasing with its own buffers reused from sample to sample (memory as at one
    /// sample, time about `antialias` times). The samples' stats merge by each key's rule
    /// (`stats::SCHEMA`); depth complexity is the largest per pixel, and the error bound the mean
    /// of the samples' bounds (the error of a mean is at most the mean of the errors).
    ///
    /// `AntialiasMode::Coverage` instead rasterizes the transparent geometry once,
    /// multisampled, and stores one fragment per pixel with its sample mask (the methods of
    /// `coverage_methods()`, at COVERAGE_SAMPLES samples); docs/methods.md, "Antialiasing".
    pub fn render_antialiased(
        &mut self,
        scene: &Scene,
        camera: &Camera,
        method_name: &str,
        params: &[(String, ParamValue)],
        background: [f32; 3],
        Antialias { samples: antialias, mode }: Antialias,
    ) -> Result<Frame> {
        let start = Instant::now();
        let offsets = antialias::sample_offsets(antialias)?;
        let (info, params) = self.prepare(scene, method_name, params, background)?;
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
        if offsets.len() == 1 || coverage {
            let mut frame = self.render_sample(&Job { camera, info, params: &params, background, coverage })?;
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
        let mut merged = SampleMerge::default();
        for offset in &offsets {
            let jittered = camera.jittered(*offset, self.width, self.height);
            let f = self.render_sample(&Job { camera: &jittered, info, params: &params, background, coverage: false })?;
            image.iter_mut().zip(&f.image).for_each(|(a, &v)| *a += v as f64);
            if let Some(b) = &f.error_bound {
                let sum = bound.get_or_insert_with(|| vec![0.0; pixels]);
                sum.iter_mut().zip(b).for_each(|(a, &v)| *a += v as f64);
            }
            if depth_complexity.is_empty() {
                depth_complexity = vec![0u32; f.depth_complexity.len()];
            }
            depth_complexity.iter_mut().zip(&f.depth_complexity).for_each(|(a, &v)| *a = (*a).max(v));
            merged.add(f.stats);
        }
        let mut stats = merged.finish();
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

    /// The method and its parameters, checked, with the scene uploaded and its lights taken.
    fn prepare(
        &mut self,
        scene: &Scene,
        method_name: &str,
        params: &[(String, ParamValue)],
        background: [f32; 3],
    ) -> Result<(&'static MethodInfo, Params)> {
        let info = method::lookup(method_name)?;
        let params = info.resolve_params(params)?;
        method::check_features(info, &self.gpu)?;
        if background.iter().any(|c| !c.is_finite() || !(0.0..=1.0).contains(c)) {
            return Err(invalid!("background {background:?} must be three linear RGB values in [0, 1]"));
        }
        self.upload(scene)?;
        self.lights = (scene.lights().to_vec(), scene.ambient());
        Ok((info, params))
    }

    fn upload(&mut self, scene: &Scene) -> Result<()> {
        if self.scene.as_ref().map(|(k, _)| *k) != Some(scene.key()) {
            self.scene = None; // free the old buffers first
            let s = GpuScene::new(&self.gpu, scene, &self.shared.scene_layout, &self.shared.uniform, self.limits.max_binding_bytes)?;
            self.scene = Some((scene.key(), s));
        }
        Ok(())
    }

    /// What `scene`'s passes compile for: its surfaces, its light count (the headlight when it
    /// has none), the shading-cost knob, whether it has instances, strands or particles, and meshes.
    fn variant(&self, scene: &GpuScene) -> SceneVariant {
        SceneVariant {
            shaded: scene.shaded,
            lights: Lighting::count(&self.lights.0),
            textured: scene.textured,
            shading_cost: self.shading_cost,
            instanced: scene.instanced,
            primitives: scene.primitives,
            sets_only: scene.sets_only,
            phong: scene.phong,
            falloff: scene.falloff,
            emissive: scene.emissive,
            alpha_test: scene.alpha_test,
            splat_ray: scene.splat_ray,
        }
    }
}
