//! One device for egui and the engine: eframe opens it with the features and limits
//! oit-core wants, and the engine wraps it with `GpuContext::from_device`.

use std::sync::Arc;

use eframe::egui_wgpu::{self, WgpuSetup, WgpuSetupCreateNew};
use oit_core::context::{adapter_rank, wanted_features};
use oit_core::GpuContext;

/// eframe's wgpu setup: Vulkan (or WGPU_BACKEND), the adapter named by `adapter` or
/// OIT_ADAPTER, else the best one (the software one first when `prefer_software`, for
/// tests), and a device with every wanted feature the adapter has and its full limits.
pub fn setup(adapter: Option<String>, prefer_software: bool) -> WgpuSetup {
    let mut s = WgpuSetupCreateNew::without_display_handle();
    s.instance_descriptor.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
    let wanted = adapter.or_else(|| std::env::var("OIT_ADAPTER").ok()).filter(|s| !s.is_empty());
    s.native_adapter_selector = Some(Arc::new(move |adapters, surface| {
        let usable: Vec<&wgpu::Adapter> = adapters.iter().filter(|a| surface.is_none_or(|s| a.is_surface_supported(s))).collect();
        let names: Vec<String> = usable.iter().map(|a| a.get_info().name).collect();
        let chosen = match &wanted {
            Some(w) => usable
                .iter()
                .find(|a| a.get_info().name.to_lowercase().contains(&w.to_lowercase()))
                .ok_or_else(|| format!("no adapter name contains '{w}'; available: {}", names.join(", ")))?,
            None => usable
                .iter()
                .min_by_key(|a| {
                    let rank = adapter_rank(&a.get_info());
                    if prefer_software {
                        4 - rank
                    } else {
                        rank
                    }
                })
                .ok_or_else(|| {
                    "no GPU adapter found: install a Vulkan driver, or lavapipe with \
                     `apt-get install mesa-vulkan-drivers` (Debian/Ubuntu)"
                        .to_string()
                })?,
        };
        Ok((*chosen).clone())
    }));
    s.device_descriptor = Arc::new(|adapter| wgpu::DeviceDescriptor {
        label: Some("oit-viewer"),
        required_features: adapter.features() & wanted_features(),
        required_limits: adapter.limits(),
        ..Default::default()
    });
    WgpuSetup::CreateNew(s)
}

/// The engine's context on eframe's device; without a wgpu render state (another
/// integration), a device of its own.
pub fn context(render_state: Option<&egui_wgpu::RenderState>) -> Result<Arc<GpuContext>, String> {
    match render_state {
        Some(rs) => Ok(Arc::new(GpuContext::from_device(rs.device.clone(), rs.queue.clone(), rs.adapter.get_info()))),
        None => oit_core::shared_context(None).map_err(|e| e.to_string()),
    }
}
