//! Adapter and device selection. Prefers a hardware adapter, falls back to a software
//! one (lavapipe), honours `OIT_ADAPTER`; also wraps a Device/Queue made elsewhere (viewer).

use crate::error::{OitError, Result};

/// A device, its queue and what the adapter can do.
pub struct GpuContext {
    pub device: wgpu::Device,
    /// The first validation or out-of-memory error wgpu reported since the last `wait`.
    errors: std::sync::Arc<std::sync::Mutex<Option<String>>>,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub features: wgpu::Features,
    pub limits: wgpu::Limits,
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
        Ok(Self::from_device(device, queue, info))
    }

    /// Wraps a device created elsewhere (the viewer's eframe device); features and limits
    /// are read from the device itself.
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Self {
        let features = device.features();
        let limits = device.limits();
        let errors: std::sync::Arc<std::sync::Mutex<Option<String>>> = Default::default();
        let sink = errors.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            let mut slot = sink.lock().unwrap_or_else(|p| p.into_inner());
            slot.get_or_insert_with(|| e.to_string());
        }));
        Self { device, errors, queue, info, features, limits, cache: Default::default() }
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
        self.device
            .poll(wgpu::PollType::Wait { submission_index: None, timeout: None })
            .map_err(|e| OitError::Device(format!("waiting for the GPU failed: {e}")))?;
        self.take_error()
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
