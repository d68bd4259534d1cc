//! `oit._oit.Renderer`: a frame rendered with the GIL released, returned as numpy arrays and the
//! stats dict the core's table gives (oit_core::stats).

use std::sync::{Arc, Mutex};

use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use oit_core::{Antialias, OitError};

use crate::convert::{matrix, param_list, value_to_py};
use crate::error::{Error, Res};
use crate::guard::guarded;
use crate::scene::Scene;
use crate::surface::FrameOptions;

#[pyclass(module = "oit._oit")]
pub(crate) struct Renderer {
    inner: Mutex<oit_core::Renderer>,
    context: Arc<oit_core::GpuContext>,
}

fn stats_dict<'py>(py: Python<'py>, s: &oit_core::Stats) -> PyResult<Bound<'py, PyDict>> {
    use oit_core::stats::StatValue;
    let numbers = |pairs: &[(&str, f64)]| -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in pairs {
            d.set_item(*k, v)?;
        }
        Ok(d)
    };
    let d = PyDict::new(py);
    for (key, value) in s.entries() {
        match value {
            StatValue::Bool(b) => d.set_item(key, b)?,
            StatValue::Int(i) => d.set_item(key, i)?,
            StatValue::Float(f) => d.set_item(key, f)?,
            StatValue::Str(text) => d.set_item(key, text)?,
            StatValue::Params(params) => {
                let p = PyDict::new(py);
                for (k, v) in &params.0 {
                    p.set_item(*k, value_to_py(py, v)?)?;
                }
                d.set_item(key, p)?
            }
            StatValue::Numbers(pairs) => d.set_item(key, numbers(&pairs)?)?,
        }
    }
    Ok(d)
}

guarded! {
#[pymethods]
impl Renderer {
    #[new]
    #[pyo3(signature = (width, height, adapter=None, max_binding_bytes=None, memory_budget=None))]
    fn new(
        py: Python<'_>,
        width: i64,
        height: i64,
        adapter: Option<String>,
        max_binding_bytes: Option<i64>,
        memory_budget: Option<i64>,
    ) -> Res<Self> {
        if width <= 0 || height <= 0 || width > u32::MAX as i64 || height > u32::MAX as i64 {
            return Err(OitError::InvalidInput(format!("width and height must be positive integers, got {width} x {height}")).into());
        }
        let (w, h) = (width as u32, height as u32);
        py.detach(|| {
            let context = oit_core::shared_context(adapter.as_deref())?;
            let mut inner = oit_core::Renderer::new(context.clone(), w, h)?;
            // The core checks both limits; a negative count (which u64 cannot hold) is below
            // either, and is refused in the core's words.
            let below = |what: &str, least: u32, b: i64| OitError::InvalidInput(format!("{what} must be at least {least} bytes, got {b}"));
            if let Some(b) = max_binding_bytes {
                inner.set_max_binding_bytes(u64::try_from(b).map_err(|_| below("max_binding_bytes", 256, b))?)?;
            }
            if let Some(b) = memory_budget {
                inner.set_memory_budget(Some(u64::try_from(b).map_err(|_| below("memory_budget", 1024, b))?))?;
            }
            Ok(Self { inner: Mutex::new(inner), context })
        })
    }

    /// Pipelines the adapter's device has built so far (render and compute; renderers on one
    /// adapter share them): a frame that needs no new one leaves it as it was.
    #[getter]
    fn pipelines_built(&self) -> usize {
        self.context.cache.pipelines()
    }

    #[getter]
    fn adapter_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let i = &self.context.info;
        let d = PyDict::new(py);
        d.set_item("name", &i.name)?;
        d.set_item("backend", format!("{:?}", i.backend))?;
        d.set_item("device_type", format!("{:?}", i.device_type))?;
        d.set_item("driver", &i.driver)?;
        d.set_item("driver_info", &i.driver_info)?;
        d.set_item("timestamps", self.context.has(wgpu::Features::TIMESTAMP_QUERY))?;
        d.set_item("float32_blendable", self.context.has(wgpu::Features::FLOAT32_BLENDABLE))?;
        d.set_item("int64_atomic_min_max", self.context.has(wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX))?;
        d.set_item("max_storage_binding_bytes", self.context.max_binding_bytes())?;
        // The device profile's loop limit (iterations one invocation may loop), None where loops
        // run to their end (oit_core::context::DeviceProfile).
        d.set_item("loop_limit", self.context.profile.loop_iterations())?;
        d.set_item("features", oit_core::method::feature_names(self.context.features))?;
        let works: Vec<&str> = oit_core::methods().iter().filter(|m| self.context.features.contains(m.features)).map(|m| m.name).collect();
        d.set_item("methods", works)?;
        Ok(d)
    }

    /// Returns (image (h, w, 4) float32, depth complexity (h, w) uint32 or None without a
    /// census, stats dict, error bound (h, w) float32 or None); `options` a dict (surface.rs):
    /// background, antialias, antialias_mode, shading_cost, census.
    fn render<'py>(
        &self,
        py: Python<'py>,
        scene: PyRef<'py, Scene>,
        view_proj: PyReadonlyArray2<'py, f64>,
        method: &str,
        params: Bound<'py, PyDict>,
        options: FrameOptions,
    ) -> PyResult<Bound<'py, PyAny>> {
        let FrameOptions { background, antialias, antialias_mode, shading_cost, census } = options;
        let mode = match antialias_mode.as_str() {
            "frames" => oit_core::AntialiasMode::Frames,
            "coverage" => oit_core::AntialiasMode::Coverage,
            other => return Err(PyValueError::new_err(format!("antialias_mode must be 'frames' or 'coverage', got '{other}'"))),
        };
        let camera = oit_core::Camera::from_rows(matrix(&view_proj, "camera matrix")?).map_err(Error::from)?;
        let plist = param_list(&params)?;
        let inner_scene = &scene.inner;
        let bg = [background.0, background.1, background.2];
        let frame = py
            .detach(|| {
                let mut r = self.inner.lock().unwrap_or_else(|p| p.into_inner());
                r.set_shading_cost(shading_cost)?;
                r.set_census(census);
                r.render_antialiased(inner_scene, &camera, method, &plist, bg, Antialias { samples: antialias, mode })
            })
            .map_err(Error::from)?;
        let (h, w) = (frame.height as usize, frame.width as usize);
        let image = frame.image.into_pyarray(py).reshape([h, w, 4])?;
        let dc = match frame.stats.census {
            true => Some(frame.depth_complexity.into_pyarray(py).reshape([h, w])?),
            false => None,
        };
        let stats = stats_dict(py, &frame.stats)?;
        let bound = match frame.error_bound {
            Some(b) => Some(b.into_pyarray(py).reshape([h, w])?),
            None => None,
        };
        Ok((image, dc, stats, bound).into_pyobject(py)?.into_any())
    }
}
}
