//! What the core declares, for Python: the methods and their parameters, the memory formula,
//! the stats schema, the extras' merge rules, a surface's defaults and the shared constants.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use oit_core::ParamKind;

use crate::convert::param_list;
use crate::error::Error;
use crate::guard::guarded;

guarded! { fns GUARDED;

/// Every method: name, summary, exact, bounded memory, passes, parameters.
#[pyfunction]
pub fn methods<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
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
        tiling.set_item("kind", m.tiling().name())?;
        if let oit_core::Tiling::Storage { per_pixel, per_fragment, per_triangle } = m.tiling() {
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
                ParamKind::Int { min, max, default, step } => {
                    pd.set_item("type", "int")?;
                    pd.set_item("min", min)?;
                    pd.set_item("max", max)?;
                    pd.set_item("step", step)?;
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
pub fn memory_bytes(method: &str, width: i64, height: i64, params: Bound<'_, PyDict>, slots: Option<i64>) -> PyResult<Option<u64>> {
    if width <= 0 || height <= 0 || width > u32::MAX as i64 || height > u32::MAX as i64 {
        return Err(PyValueError::new_err(format!("width and height must be positive integers, got {width} x {height}")));
    }
    let slots = slots.map(|s| u64::try_from(s).map_err(|_| PyValueError::new_err(format!("slots must be >= 0, got {s}")))).transpose()?;
    let plist = param_list(&params)?;
    Ok(oit_core::memory_bytes(method, width as u32, height as u32, &plist, slots).map_err(Error::from)?)
}

/// The keys of a frame's stats: (name, Python type, meaning), in order
/// (crates/oit-core/src/stats/).
#[pyfunction]
pub fn stats_schema() -> Vec<(&'static str, &'static str, &'static str)> {
    oit_core::stats::SCHEMA.iter().map(|k| (k.name, k.ty, k.doc)).collect()
}

/// Every extra number a method reports, with how tiles and samples merge it ('sum', 'max',
/// 'mean'; crates/oit-core/src/stats/extras.rs, EXTRAS).
#[pyfunction]
pub fn extra_merge_rules() -> Vec<(&'static str, &'static str)> {
    oit_core::stats::EXTRAS.iter().map(|(n, m)| (*n, m.name())).collect()
}

/// The surface a mesh has unless told otherwise (the core's `Material::default()`): the
/// defaults of the API's surface keywords (`Scene.add_mesh`, `add_strands`...).
#[pyfunction]
pub fn surface_defaults<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let m = oit_core::Material::default();
    let d = PyDict::new(py);
    d.set_item("shading", m.shading.name())?;
    d.set_item("specular", m.specular)?;
    d.set_item("shininess", m.shininess)?;
    d.set_item("opacity", m.opacity)?;
    d.set_item("two_sided", m.two_sided)?;
    d.set_item("cull_back_faces", m.cull_back_faces)?;
    Ok(d)
}

/// The numbers shared by the core, its shaders and Python (crates/oit-core/src/consts.rs).
#[pyfunction]
pub fn constants<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
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
}
