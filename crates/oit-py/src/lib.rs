//! Thin PyO3 layer over oit-core: array conversion, GIL release during GPU and reference
//! work, and one mapping from `OitError` to Python exceptions. The public API is
//! `python/oit`; this module (`oit._oit`) is private.

use std::sync::{Arc, Mutex};

use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::exceptions::{PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use oit_core::{OitError, ParamKind, ParamValue};

mod convert;
mod guard;
mod load;
mod primitives;

use convert::{array, instances, matrix, rows, InstanceArrays};
use guard::guarded;

struct Error(OitError);

impl From<OitError> for Error {
    fn from(e: OitError) -> Self {
        Self(e)
    }
}

impl From<Error> for PyErr {
    fn from(Error(e): Error) -> PyErr {
        let msg = e.to_string();
        match e {
            OitError::InvalidInput(_) => PyValueError::new_err(msg),
            OitError::NotFound(_) => pyo3::exceptions::PyFileNotFoundError::new_err(msg),
            OitError::OutOfMemory(_) => PyMemoryError::new_err(msg),
            OitError::NoAdapter(_) | OitError::Unsupported(_) | OitError::Device(_) => PyRuntimeError::new_err(msg),
        }
    }
}

type Res<T> = Result<T, Error>;

/// Meshes in submission order (validated on the way in).
#[pyclass(module = "oit._oit")]
struct Scene {
    inner: oit_core::Scene,
}

guarded! {
#[pymethods]
impl Scene {
    #[new]
    fn new() -> Self {
        Self { inner: oit_core::Scene::new() }
    }

    /// positions (n, 3) float32, indices (m, 3) uint32, colors (n, 4) or (1, 4) float32; the
    /// surface: normals (n, 3) and uvs (n, 2) float32, texture (h, w, 4) float32 linear RGBA,
    /// shading "unlit", "flat", "smooth" or "hair".
    /// `transform` (4, 4) float64 places it (else it is drawn where its vertices are).
    #[pyo3(signature = (positions, indices, colors, opaque, normals=None, uvs=None, texture=None, shading="unlit",
                        specular=0.0, shininess=32.0, opacity=1.0, two_sided=true, cull_back_faces=false, transform=None))]
    #[allow(clippy::too_many_arguments)]
    fn add_mesh(
        &mut self,
        positions: PyReadonlyArray2<'_, f32>,
        indices: PyReadonlyArray2<'_, u32>,
        colors: PyReadonlyArray2<'_, f32>,
        opaque: bool,
        normals: Option<PyReadonlyArray2<'_, f32>>,
        uvs: Option<PyReadonlyArray2<'_, f32>>,
        texture: Option<PyReadonlyArray3<'_, f32>>,
        shading: &str,
        specular: f32,
        shininess: f32,
        opacity: f32,
        two_sided: bool,
        cull_back_faces: bool,
        transform: Option<PyReadonlyArray2<'_, f64>>,
    ) -> PyResult<usize> {
        let placement = match transform {
            Some(t) => oit_core::Instance::from_rows(matrix(&t, "transform")?, [1.0; 4]).map_err(Error::from)?,
            None => oit_core::Instance::IDENTITY,
        };
        let mesh = oit_core::Mesh::new(rows(&positions, "positions")?, rows(&indices, "indices")?, rows(&colors, "colors")?, opaque)
            .map_err(Error::from)?;
        let texture = match texture {
            Some(t) => {
                let a = t.as_array();
                let (h, w, c) = a.dim();
                if c != 4 {
                    return Err(PyValueError::new_err(format!("texture must have shape (h, w, 4), got ({h}, {w}, {c})")));
                }
                let flat: Vec<f32> = a.iter().copied().collect();
                let texels = flat.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
                let image = oit_core::Texture::new(w as u32, h as u32, texels).map_err(Error::from)?;
                Some(oit_core::TextureMap::new(std::sync::Arc::new(image)))
            }
            None => None,
        };
        let material = oit_core::Material {
            shading: oit_core::Shading::from_name(shading).map_err(Error::from)?,
            specular,
            shininess,
            opacity,
            two_sided,
            cull_back_faces,
            texture,
            ..Default::default()
        };
        let normals = normals.map(|n| rows(&n, "normals")).transpose()?;
        let uvs = uvs.map(|u| rows(&u, "uvs")).transpose()?;
        let mesh = mesh.with_surface(normals, uvs, material).map_err(Error::from)?;
        Ok(self.inner.add_placed(mesh, vec![placement]))
    }

    /// A strand set: points (n, 3), counts (strands,) uint32, widths (n,) or (1,), colors (n, 4)
    /// or (1, 4) float32; shading "unlit" or "hair".
    #[pyo3(signature = (points, counts, widths, colors, opaque, shading="unlit", specular=0.0, shininess=32.0, opacity=1.0))]
    #[allow(clippy::too_many_arguments)]
    fn add_strands(
        &mut self,
        points: PyReadonlyArray2<'_, f32>,
        counts: PyReadonlyArray1<'_, u32>,
        widths: PyReadonlyArray1<'_, f32>,
        colors: PyReadonlyArray2<'_, f32>,
        opaque: bool,
        shading: &str,
        specular: f32,
        shininess: f32,
        opacity: f32,
    ) -> PyResult<usize> {
        let look = primitives::Look { shading, specular, shininess, opacity };
        Ok(self.inner.add_mesh(primitives::strands(&points, &counts, &widths, &colors, opaque, &look)?))
    }

    /// A particle set: centers (n, 3), radii (n,) or (1,), colors (n, 4) or (1, 4) float32.
    #[pyo3(signature = (centers, radii, colors, opaque, falloff="hard", opacity=1.0))]
    fn add_particles(
        &mut self,
        centers: PyReadonlyArray2<'_, f32>,
        radii: PyReadonlyArray1<'_, f32>,
        colors: PyReadonlyArray2<'_, f32>,
        opaque: bool,
        falloff: &str,
        opacity: f32,
    ) -> PyResult<usize> {
        Ok(self.inner.add_mesh(primitives::particles(&centers, &radii, &colors, opaque, falloff, opacity)?))
    }

    /// Mesh `mesh` as the triangles it is drawn as under `view_proj`.
    fn to_triangles<'py>(
        &self,
        py: Python<'py>,
        mesh: i64,
        view_proj: PyReadonlyArray2<'_, f64>,
    ) -> PyResult<primitives::TriangleArrays<'py>> {
        primitives::to_triangles(py, &self.inner.meshes()[self.mesh_index(mesh)?], &view_proj)
    }

    /// "triangles", "strands" or "particles" per mesh.
    fn mesh_primitives(&self) -> Vec<&'static str> {
        self.inner.meshes().iter().map(|m| m.primitive.name()).collect()
    }

    /// Appends instances to mesh `mesh`: transforms (n, 4, 4) float64, colors (n, 4) float32
    /// factors or None; returns the first new instance's index.
    #[pyo3(signature = (mesh, transforms, colors=None))]
    fn add_instances(
        &mut self,
        mesh: i64,
        transforms: PyReadonlyArray3<'_, f64>,
        colors: Option<PyReadonlyArray2<'_, f32>>,
    ) -> PyResult<usize> {
        let list = instances(&transforms, colors.as_ref())?;
        Ok(self.inner.add_instances(self.mesh_index(mesh)?, &list).map_err(Error::from)?)
    }

    /// Replaces the instances of mesh `mesh` (none: it stays uploaded but is not drawn).
    #[pyo3(signature = (mesh, transforms, colors=None))]
    fn set_instances(
        &mut self,
        mesh: i64,
        transforms: PyReadonlyArray3<'_, f64>,
        colors: Option<PyReadonlyArray2<'_, f32>>,
    ) -> PyResult<()> {
        let list = instances(&transforms, colors.as_ref())?;
        Ok(self.inner.set_instances(self.mesh_index(mesh)?, list).map_err(Error::from)?)
    }

    /// Transforms (n, 4, 4) row-major and color factors (n, 4) of mesh `mesh`'s instances.
    fn instances<'py>(&self, py: Python<'py>, mesh: i64) -> PyResult<InstanceArrays<'py>> {
        let list = self.inner.instances(self.mesh_index(mesh)?);
        let t: Vec<f64> = list.iter().flat_map(|i| i.transform.transpose().to_cols_array()).collect();
        let colors: Vec<[f32; 4]> = list.iter().map(|i| i.color).collect();
        let t = numpy::ndarray::Array3::from_shape_vec((list.len(), 4, 4), t).expect("n x 4 x 4");
        Ok((t.into_pyarray(py), array(py, &colors)))
    }

    /// A directional light travelling along `direction` (world space); returns its index.
    fn add_light(&mut self, direction: [f32; 3], color: [f32; 3], intensity: f32) -> Res<usize> {
        Ok(self.inner.add_light(oit_core::Light::new(direction, color, intensity)?)?)
    }

    fn clear_lights(&mut self) {
        self.inner.clear_lights();
    }

    /// (direction, color, intensity) per light.
    #[getter]
    fn lights(&self) -> Vec<([f32; 3], [f32; 3], f32)> {
        self.inner.lights().iter().map(|l| (l.direction, l.color, l.intensity)).collect()
    }

    #[getter]
    fn ambient(&self) -> [f32; 3] {
        self.inner.ambient()
    }

    fn set_ambient(&mut self, rgb: [f32; 3]) -> Res<()> {
        Ok(self.inner.set_ambient(rgb)?)
    }

    /// (shading, textured) per mesh.
    fn mesh_surfaces(&self) -> Vec<(&'static str, bool)> {
        self.inner.meshes().iter().map(|m| (m.material.shading.name(), m.material.texture.is_some())).collect()
    }

    fn set_mesh_alpha(&mut self, mesh: i64, alpha: f32) -> Res<()> {
        let index = self.inner.mesh_index(mesh)?;
        Ok(self.inner.set_mesh_alpha(index, alpha)?)
    }

    #[getter]
    fn mesh_count(&self) -> usize {
        self.inner.meshes().len()
    }

    /// Triangles drawn, instances included.
    #[getter]
    fn triangle_count(&self) -> usize {
        self.inner.triangle_count()
    }

    /// Triangles uploaded: each mesh's once.
    #[getter]
    fn unique_triangle_count(&self) -> usize {
        self.inner.unique_triangle_count()
    }

    #[getter]
    fn instance_count(&self) -> usize {
        self.inner.instance_count()
    }

    /// Per mesh: what its material and colors are (tests and `Scene.materials`).
    fn mesh_materials<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        load::mesh_materials(py, &self.inner)
    }

    /// The smallest and largest corner of every drawn vertex's box (instances placed); None
    /// when nothing is drawn.
    fn bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        self.inner.bounds().map(|(lo, hi)| (lo.to_array(), hi.to_array()))
    }

    /// (triangles, vertices, opaque) per mesh.
    fn mesh_summary(&self) -> Vec<(usize, usize, bool)> {
        self.inner.meshes().iter().map(|m| (m.triangle_count(), m.positions.len(), m.opaque)).collect()
    }
}
}

impl Scene {
    fn mesh_index(&self, mesh: i64) -> PyResult<usize> {
        Ok(self.inner.mesh_index(mesh).map_err(Error::from)?)
    }
}

#[pyclass(module = "oit._oit")]
struct Renderer {
    inner: Mutex<oit_core::Renderer>,
    context: Arc<oit_core::GpuContext>,
}

fn param_value(v: &Bound<'_, PyAny>, name: &str) -> PyResult<ParamValue> {
    if v.is_instance_of::<pyo3::types::PyBool>() {
        return Err(PyValueError::new_err(format!("parameter '{name}' must be a number or a string, not a bool")));
    }
    if let Ok(i) = v.extract::<i64>() {
        return Ok(ParamValue::Int(i));
    }
    if let Ok(f) = v.extract::<f64>() {
        return Ok(ParamValue::Float(f));
    }
    if let Ok(s) = v.extract::<String>() {
        return Ok(ParamValue::Str(s));
    }
    Err(PyValueError::new_err(format!("parameter '{name}' must be a number or a string, got {}", v.get_type().name()?)))
}

fn param_list(params: &Bound<'_, PyDict>) -> PyResult<Vec<(String, ParamValue)>> {
    let mut plist = Vec::new();
    for (k, v) in params.iter() {
        let name: String = k.extract()?;
        plist.push((name.clone(), param_value(&v, &name)?));
    }
    Ok(plist)
}

fn value_to_py<'py>(py: Python<'py>, v: &ParamValue) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        ParamValue::Int(i) => i.into_pyobject(py)?.into_any(),
        ParamValue::Float(f) => f.into_pyobject(py)?.into_any(),
        ParamValue::Str(s) => s.into_pyobject(py)?.into_any(),
    })
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
        d.set_item("features", oit_core::method::feature_names(self.context.features))?;
        let works: Vec<&str> = oit_core::methods().iter().filter(|m| self.context.features.contains(m.features)).map(|m| m.name).collect();
        d.set_item("methods", works)?;
        Ok(d)
    }

    /// Returns (image (h, w, 4) float32, depth complexity (h, w) uint32 or None without a
    /// census, stats dict, error bound (h, w) float32 or None).
    #[pyo3(signature = (scene, view_proj, method, background, params, antialias=1, antialias_mode="frames", shading_cost=0, census=false))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        scene: PyRef<'py, Scene>,
        view_proj: PyReadonlyArray2<'py, f64>,
        method: &str,
        background: (f32, f32, f32),
        params: Bound<'py, PyDict>,
        antialias: u32,
        antialias_mode: &str,
        shading_cost: u32,
        census: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let mode = match antialias_mode {
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
                r.render_antialiased(inner_scene, &camera, method, &plist, bg, antialias, mode)
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

guarded! { fns GUARDED_FUNCTIONS;

/// Every method: name, summary, exact, bounded memory, passes, parameters.
#[pyfunction]
fn methods<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
    let out = PyList::empty(py);
    for m in oit_core::methods() {
        let d = PyDict::new(py);
        d.set_item("name", m.name)?;
        d.set_item("summary", m.summary)?;
        d.set_item("exact", m.exact)?;
        d.set_item("bounded_memory", m.bounded_memory)?;
        d.set_item("passes", m.passes.to_vec())?;
        d.set_item("features", oit_core::method::feature_names(m.features))?;
        d.set_item("order", m.order.name())?;
        d.set_item("order_independent", m.order.independent())?;
        d.set_item("antialias_modes", m.antialias_modes.iter().map(|a| a.name()).collect::<Vec<_>>())?;
        let memory = PyDict::new(py);
        memory.set_item("kind", m.memory.kind())?;
        memory.set_item("formula", m.memory.formula())?;
        d.set_item("memory", memory)?;
        d.set_item("error_bound", m.error_bound.name())?;
        let tiling = PyDict::new(py);
        tiling.set_item("kind", m.tiling.name())?;
        if let oit_core::Tiling::Storage { per_pixel, per_fragment, per_triangle } = m.tiling {
            tiling.set_item("per_pixel", per_pixel)?;
            tiling.set_item("per_fragment", per_fragment)?;
            tiling.set_item("per_triangle", per_triangle)?;
        }
        d.set_item("tiling", tiling)?;
        d.set_item("census", m.census)?;
        d.set_item("main", m.main)?;
        let params = PyList::empty(py);
        for p in m.params {
            let pd = PyDict::new(py);
            pd.set_item("name", p.name)?;
            pd.set_item("doc", p.doc)?;
            match p.kind {
                ParamKind::Int { min, max, default } => {
                    pd.set_item("type", "int")?;
                    pd.set_item("min", min)?;
                    pd.set_item("max", max)?;
                    pd.set_item("default", default)?;
                }
                ParamKind::Float { min, max, default } => {
                    pd.set_item("type", "float")?;
                    pd.set_item("min", min)?;
                    pd.set_item("max", max)?;
                    pd.set_item("default", default)?;
                }
                ParamKind::Choice { choices, default } => {
                    pd.set_item("type", "choice")?;
                    pd.set_item("choices", choices.to_vec())?;
                    pd.set_item("default", default)?;
                }
            }
            params.append(pd)?;
        }
        d.set_item("params", params)?;
        out.append(d)?;
    }
    Ok(out)
}

/// GPU bytes `method` allocates at `width` x `height` with `params` (its memory formula), or
/// None when that grows with the scene; `slots` is auto's k-TAB slots in all.
#[pyfunction]
#[pyo3(signature = (method, width, height, params, slots=None))]
fn memory_bytes(method: &str, width: i64, height: i64, params: Bound<'_, PyDict>, slots: Option<i64>) -> PyResult<Option<u64>> {
    if width <= 0 || height <= 0 || width > u32::MAX as i64 || height > u32::MAX as i64 {
        return Err(PyValueError::new_err(format!("width and height must be positive integers, got {width} x {height}")));
    }
    let slots = slots.map(|s| u64::try_from(s).map_err(|_| PyValueError::new_err(format!("slots must be >= 0, got {s}")))).transpose()?;
    let plist = param_list(&params)?;
    Ok(oit_core::memory_bytes(method, width as u32, height as u32, &plist, slots).map_err(Error::from)?)
}

/// The keys of a frame's stats: (name, Python type, meaning), in order
/// (crates/oit-core/src/stats.rs).
#[pyfunction]
fn stats_schema() -> Vec<(&'static str, &'static str, &'static str)> {
    oit_core::stats::SCHEMA.iter().map(|k| (k.name, k.ty, k.doc)).collect()
}

/// Every extra number a method reports, with how tiles and samples merge it ('sum', 'max',
/// 'mean'; crates/oit-core/src/stats.rs, EXTRAS).
#[pyfunction]
fn extra_merge_rules() -> Vec<(&'static str, &'static str)> {
    oit_core::stats::EXTRAS.iter().map(|(n, m)| (*n, m.name())).collect()
}

/// The numbers shared by the core, its shaders and Python (crates/oit-core/src/consts.rs).
#[pyfunction]
fn constants<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for c in oit_core::consts::SHARED {
        match *c {
            oit_core::shader::Const::U32(n, v) => d.set_item(n, v)?,
            oit_core::shader::Const::F32(n, v) => d.set_item(n, v as f64)?,
        }
    }
    d.set_item("ALPHA_8BIT_ERROR", oit_core::consts::ALPHA_8BIT_ERROR)?;
    d.set_item("ROUNDING_TERM", oit_core::consts::ROUNDING_TERM)?;
    d.set_item("COVERAGE_SAMPLES", oit_core::COVERAGE_SAMPLES)?;
    d.set_item("ANTIALIAS_SAMPLES", oit_core::antialias::SAMPLE_COUNTS.to_vec())?;
    Ok(d)
}

/// CPU float64 reference: (image (h, w, 4) float64, ambiguous (h, w) bool, depth complexity),
/// the mean over the standard pattern's positions when `antialias` > 1.
#[pyfunction]
#[pyo3(signature = (scene, view_proj, width, height, background, antialias=1))]
fn reference<'py>(
    py: Python<'py>,
    scene: PyRef<'py, Scene>,
    view_proj: PyReadonlyArray2<'py, f64>,
    width: i64,
    height: i64,
    background: (f64, f64, f64),
    antialias: u32,
) -> PyResult<Bound<'py, PyAny>> {
    if width <= 0 || height <= 0 || width > 1 << 16 || height > 1 << 16 {
        return Err(PyValueError::new_err(format!("width and height must be in [1, 65536], got {width} x {height}")));
    }
    let camera = oit_core::Camera::from_rows(matrix(&view_proj, "camera matrix")?).map_err(Error::from)?;
    let inner_scene = &scene.inner;
    let bg = [background.0, background.1, background.2];
    let r = py
        .detach(|| oit_core::reference_antialiased(inner_scene, &camera, width as u32, height as u32, bg, antialias))
        .map_err(Error::from)?;
    let (h, w) = (height as usize, width as usize);
    let image = r.image.into_pyarray(py).reshape([h, w, 4])?;
    let amb = r.ambiguous.into_pyarray(py).reshape([h, w])?;
    let dc = r.depth_complexity.into_pyarray(py).reshape([h, w])?;
    Ok((image, amb, dc).into_pyobject(py)?.into_any())
}

/// The unit world-space direction camera `view_proj` looks along at the picture's center (the
/// core's `Camera::view_direction`: the headlight and the strands' ribbons use the same).
#[pyfunction]
fn view_direction(view_proj: PyReadonlyArray2<'_, f64>) -> PyResult<(f64, f64, f64)> {
    let camera = oit_core::Camera::from_rows(matrix(&view_proj, "camera matrix")?).map_err(Error::from)?;
    Ok(camera.view_direction().into())
}

/// Panics on purpose, under the guard: tests/test_load_entry_points.py proves it arrives as a
/// RuntimeError, not as PanicException.
#[pyfunction]
fn _panic_for_test() -> PyResult<()> {
    panic!("a panic on purpose (oit._oit._panic_for_test)")
}
}

#[pymodule]
fn _oit(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<Renderer>()?;
    m.add_function(wrap_pyfunction!(methods, m)?)?;
    m.add_function(wrap_pyfunction!(reference, m)?)?;
    m.add_function(wrap_pyfunction!(view_direction, m)?)?;
    m.add_function(wrap_pyfunction!(memory_bytes, m)?)?;
    m.add_function(wrap_pyfunction!(constants, m)?)?;
    m.add_function(wrap_pyfunction!(stats_schema, m)?)?;
    m.add_function(wrap_pyfunction!(extra_merge_rules, m)?)?;
    m.add_function(wrap_pyfunction!(load::load_file, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    let classes = [("Scene", Scene::GUARDED), ("Renderer", Renderer::GUARDED)];
    let mut guarded: Vec<String> = classes.iter().flat_map(|(c, names)| names.iter().map(move |n| format!("{c}.{n}"))).collect();
    guarded.extend(GUARDED_FUNCTIONS.iter().chain(load::GUARDED).map(|n| n.to_string()));
    m.add("_GUARDED", guarded)?;
    Ok(())
}
