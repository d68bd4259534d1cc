//! Adapter and device selection. Prefers a hardware adapter, falls back to a software
//! one (lavapipe), honours `OIT_ADAPTER`; also wraps a Device/Queue made elsewhere (viewer).
//! The adapter's facts that generic code plans by (`DeviceProfile`) are read here, the one
//! place that matches an adapter's name.

use crate::consts::Const;
use crate::error::{invalid, OitError, Result};

/// What generic code needs to know of an adapter beyond its features and limits. Built from the
/// adapter's info by `DeviceProfile::for_adapter`; `OIT_LOOP_LIMIT` overrides its loop limit
/// (`none`, or a count of iterations counted as llvmpipe counts them), and tests may set
/// `GpuContext::profile` (or `with_profile`) before a renderer takes the context.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeviceProfile {
    /// The loop limiter of the driver, if it has one: the sorted resolve then sweeps in budgeted
    /// dispatches (method::resolve_plan::ResolveStrategy), and methods whose per-pixel work grows
    /// with the depth complexity refuse frames past it.
    pub loop_limit: Option<LoopLimit>,
}

/// A driver that silently ends one shader invocation's loops after `iterations` iterations, all
/// loops together (llvmpipe: 65,535), and what it counts for the sorted resolve's units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoopLimit {
    pub iterations: u64,
    pub sweep: SweepSteps,
}

/// What one unit of the sorted resolve costs in a loop limiter's count (shaders/common/sweep.wgsl
/// adds what turning a node into a fragment costs, FRAG_STEPS; method::resolve_plan::StepCosts
/// plans dispatches from the same numbers): a node loaded into a run, a node relinked, a merge
/// step, a fragment composited from the list (before its samples), and what shading a fragment
/// at composite costs besides its light loop and the shading-cost loop (`shade`: the other loops
/// of shading.wgsl's `shade`, each counted once even when skipped; compact_abuffer).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SweepSteps {
    pub load: u32,
    pub link: u32,
    pub merge: u32,
    pub composite: u32,
    pub shade: u32,
}

impl SweepSteps {
    /// The shader's constants (SWEEP_*_STEPS in shaders/common/sweep.wgsl; `shade` reaches it in
    /// SHADE_STEPS, method::lists).
    pub const fn consts(self) -> [Const; 4] {
        [
            Const::U32("SWEEP_LOAD_STEPS", self.load),
            Const::U32("SWEEP_LINK_STEPS", self.link),
            Const::U32("SWEEP_MERGE_STEPS", self.merge),
            Const::U32("SWEEP_COMPOSITE_STEPS", self.composite),
        ]
    }
}

/// llvmpipe's count of the sorted resolve's units (`DeviceProfile::LLVMPIPE`).
pub const LLVMPIPE_SWEEP: SweepSteps = SweepSteps { load: 2, link: 2, merge: 6, composite: 4, shade: 4 };

impl DeviceProfile {
    /// llvmpipe (lavapipe): 65,535 iterations an invocation, every `switch` counted as one (SPIR-V
    /// to NIR makes a switch a loop). A node loaded into a run costs its loop and the pool's
    /// switch; a node relinked its loop and append's switch; a merge step its switch, two
    /// fragments, the link and the append; a composited fragment four; shading it a margin of four.
    pub const LLVMPIPE: Self = Self { loop_limit: Some(LoopLimit { iterations: 65_535, sweep: LLVMPIPE_SWEEP }) };
    /// An adapter whose loops run to their end.
    pub const UNLIMITED: Self = Self { loop_limit: None };

    /// The profile of the adapter `info` describes.
    pub fn for_adapter(info: &wgpu::AdapterInfo) -> Self {
        Self::for_name(&info.name)
    }

    fn for_name(name: &str) -> Self {
        if name.contains("llvmpipe") {
            Self::LLVMPIPE
        } else {
            Self::UNLIMITED
        }
    }

    /// `self` with `OIT_LOOP_LIMIT` applied where it is set: `none` (no limit) or a count of
    /// iterations, counted as llvmpipe counts them.
    pub fn with_env(self) -> Result<Self> {
        match std::env::var("OIT_LOOP_LIMIT").ok().filter(|s| !s.is_empty()) {
            None => Ok(self),
            Some(v) if v.eq_ignore_ascii_case("none") => Ok(Self::UNLIMITED),
            Some(v) => match v.trim().parse::<u64>() {
                Ok(iterations) => Ok(Self { loop_limit: Some(LoopLimit { iterations, sweep: LLVMPIPE_SWEEP }) }),
                Err(_) => Err(invalid!("OIT_LOOP_LIMIT='{v}': set it to `none` or a number of loop iterations, or unset it")),
            },
        }
    }

    /// Iterations one invocation may loop, all loops together; None where they are not limited.
    pub fn loop_iterations(&self) -> Option<u64> {
        self.loop_limit.map(|l| l.iterations)
    }

    /// The sorted resolve's step costs as shader constants: the limiter's, or zeros where there
    /// is none (the plain resolve counts no steps).
    pub fn sweep_consts(&self) -> [Const; 4] {
        self.loop_limit.map_or(SweepSteps::default(), |l| l.sweep).consts()
    }
}

/// A device, its queue and what the adapter can do.
pub struct GpuContext {
    pub device: wgpu::Device,
    /// The first validation or out-of-memory error wgpu reported since the last `wait`.
    errors: std::sync::Arc<std::sync::Mutex<Option<String>>>,
    /// Times the host has waited for this device (`wait`), for tests of how often a frame does.
    waits: std::sync::atomic::AtomicU64,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub features: wgpu::Features,
    pub limits: wgpu::Limits,
    /// The adapter's facts that frames are planned by (its loop limit).
    pub profile: DeviceProfile,
    /// Modules, layouts and pipelines of this device, built at their first use.
    pub cache: crate::cache::PipelineCache,
}

const NO_ADAPTER_HELP: &str = "no GPU adapter found: install a Vulkan driver, or the software \
rasterizer lavapipe with `apt-get install mesa-vulkan-drivers` (Debian/Ubuntu); if it is installed \
but not found, set VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";

/// Features every method may use when the adapter offers them; none is required by all.
/// A device made elsewhere (the viewer's) should ask for those of them its adapter has.
pub fn wanted_features() -> wgpu::Features {
    wgpu::Features::TIMESTAMP_QUERY
        | wgpu::Features::FLOAT32_BLENDABLE
        | wgpu::Features::SHADER_INT64
        | wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX
        | wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS
        | wgpu::Features::SHADER_EARLY_DEPTH_TEST
        | wgpu::Features::INDIRECT_FIRST_INSTANCE
}

/// Adapter preference, lower first: hardware before software (lavapipe).
pub fn adapter_rank(info: &wgpu::AdapterInfo) -> u32 {
    match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

impl GpuContext {
    /// Picks an adapter: the one whose name contains `name` (or `OIT_ADAPTER`) when given,
    /// else the best hardware adapter, else a software one.
    pub fn new(name: Option<&str>) -> Result<Self> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY),
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        let env_name = std::env::var("OIT_ADAPTER").ok().filter(|s| !s.is_empty());
        let wanted = name.map(str::to_string).or(env_name);
        let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
        let adapter = match &wanted {
            Some(w) => {
                let lw = w.to_lowercase();
                adapters.into_iter().find(|a| a.get_info().name.to_lowercase().contains(&lw)).ok_or_else(|| {
                    if names.is_empty() {
                        OitError::NoAdapter(NO_ADAPTER_HELP.to_string())
                    } else {
                        OitError::NoAdapter(format!("no adapter name contains '{w}'; available: {}", names.join(", ")))
                    }
                })?
            }
            None => adapters
                .into_iter()
                .min_by_key(|a| adapter_rank(&a.get_info()))
                .ok_or_else(|| OitError::NoAdapter(NO_ADAPTER_HELP.to_string()))?,
        };
        let info = adapter.get_info();
        let features = adapter.features() & wanted_features();
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("oit"),
            required_features: features,
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| OitError::Device(format!("could not open a device on '{}': {e}", info.name)))?;
        let profile = DeviceProfile::for_adapter(&info).with_env()?;
        Ok(Self { profile, ..Self::from_device(device, queue, info) })
    }

    /// The context with `profile` in place of its adapter's (tests: the plain resolve on llvmpipe).
    pub fn with_profile(self, profile: DeviceProfile) -> Self {
        Self { profile, ..self }
    }

    /// Wraps a device created elsewhere (the viewer's eframe device); features and limits
    /// are read from the device itself, the profile from `info` (an invalid `OIT_LOOP_LIMIT` is
    /// ignored here; `new` refuses it).
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Self {
        let features = device.features();
        let limits = device.limits();
        let errors: std::sync::Arc<std::sync::Mutex<Option<String>>> = Default::default();
        let sink = errors.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            let mut slot = sink.lock().unwrap_or_else(|p| p.into_inner());
            slot.get_or_insert_with(|| e.to_string());
        }));
        let adapter = DeviceProfile::for_adapter(&info);
        let profile = adapter.with_env().unwrap_or(adapter);
        Self { device, errors, waits: Default::default(), queue, info, features, limits, profile, cache: Default::default() }
    }

    pub fn has(&self, f: wgpu::Features) -> bool {
        self.features.contains(f)
    }

    /// Largest storage binding, in bytes.
    pub fn max_binding_bytes(&self) -> u64 {
        self.limits.max_storage_buffer_binding_size.min(self.limits.max_buffer_size)
    }

    /// Blocks until the queue is idle; a device fault or an error wgpu reported since the
    /// last call becomes an error.
    pub fn wait(&self) -> Result<()> {
        self.waits.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.device
            .poll(wgpu::PollType::Wait { submission_index: None, timeout: None })
            .map_err(|e| OitError::Device(format!("waiting for the GPU failed: {e}")))?;
        self.take_error()
    }

    /// Times the host has waited for this device so far.
    pub fn waits(&self) -> u64 {
        self.waits.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Returns (and clears) the first error wgpu reported since the last check.
    pub fn take_error(&self) -> Result<()> {
        match self.errors.lock().unwrap_or_else(|p| p.into_inner()).take() {
            None => Ok(()),
            Some(e) if e.to_lowercase().contains("out of memory") => {
                Err(OitError::OutOfMemory(format!("the GPU ran out of memory: {e}; render smaller frames or scenes")))
            }
            Some(e) => Err(OitError::Device(format!("GPU error: {e}"))),
        }
    }

    /// A one-line description: name, backend, device type, driver.
    pub fn describe(&self) -> String {
        let i = &self.info;
        format!("{} ({:?}, {:?}, {} {})", i.name, i.backend, i.device_type, i.driver, i.driver_info)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn llvmpipe_alone_has_a_loop_limit() {
        let lavapipe = DeviceProfile::for_name("llvmpipe (LLVM 15.0.6, 256 bits)");
        assert_eq!(lavapipe.loop_iterations(), Some(65_535));
        assert!(matches!(lavapipe.sweep_consts()[2], Const::U32("SWEEP_MERGE_STEPS", 6)));
        assert_eq!(DeviceProfile::for_name("NVIDIA H200"), DeviceProfile::UNLIMITED);
        assert!(matches!(DeviceProfile::UNLIMITED.sweep_consts()[0], Const::U32("SWEEP_LOAD_STEPS", 0)));
    }
}
