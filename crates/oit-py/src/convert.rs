//! Python values into the core's types and back: rows of N values, 4 x 4 matrices, instance lists,
//! method parameters. Shapes and types are checked here, where the values are taken apart; the
//! values themselves are the core's to check.

use numpy::{IntoPyArray, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use oit_core::ParamValue;

pub(crate) fn rows<T: Copy + numpy::Element, const N: usize>(a: &PyReadonlyArray2<'_, T>, name: &str) -> PyResult<Vec<[T; N]>> {
    let shape = a.as_array().shape().to_vec();
    if shape[1] != N {
        return Err(PyValueError::new_err(format!("{name} must have shape (n, {N}), got {shape:?}")));
    }
    let flat: Vec<T> = a.as_array().iter().copied().collect();
    Ok(flat.chunks_exact(N).map(|c| c.try_into().expect("chunk of N")).collect())
}

/// Rows of N values as an (n, N) numpy array: the inverse of `rows`.
pub(crate) fn array<'py, T: numpy::Element + Copy, const N: usize>(py: Python<'py>, v: &[[T; N]]) -> Bound<'py, numpy::PyArray2<T>> {
    let flat: Vec<T> = v.iter().flatten().copied().collect();
    numpy::ndarray::Array2::from_shape_vec((v.len(), N), flat).expect("n x N").into_pyarray(py)
}

pub(crate) fn matrix(m: &PyReadonlyArray2<'_, f64>, name: &str) -> PyResult<[[f64; 4]; 4]> {
    let a = m.as_array();
    if a.shape() != [4, 4] {
        return Err(PyValueError::new_err(format!("{name} must be 4 x 4, got {:?}", a.shape())));
    }
    let mut out = [[0.0; 4]; 4];
    for r in 0..4 {
        for c in 0..4 {
            out[r][c] = a[[r, c]];
        }
    }
    Ok(out)
}

/// Transforms (n, 4, 4) and color factors (n, 4), as numpy arrays.
pub(crate) type InstanceArrays<'py> = (Bound<'py, numpy::PyArray3<f64>>, Bound<'py, numpy::PyArray2<f32>>);

/// Instances from transforms (n, 4, 4) and optional color factors (n, 4).
pub(crate) fn instances(
    transforms: &PyReadonlyArray3<'_, f64>,
    colors: Option<&PyReadonlyArray2<'_, f32>>,
) -> PyResult<Vec<oit_core::Instance>> {
    let t = transforms.as_array();
    let n = t.shape()[0];
    if t.shape()[1..] != [4, 4] {
        return Err(PyValueError::new_err(format!("transforms must have shape (n, 4, 4), got {:?}", t.shape())));
    }
    let colors: Vec<[f32; 4]> = match colors {
        Some(c) => rows(c, "instance colors")?,
        None => vec![[1.0; 4]; n],
    };
    if colors.len() != n {
        return Err(PyValueError::new_err(format!(
            "colors has {} rows but transforms has {n}: pass one RGBA factor an instance",
            colors.len()
        )));
    }
    (0..n)
        .map(|i| {
            let rows: [[f64; 4]; 4] = std::array::from_fn(|r| std::array::from_fn(|c| t[[i, r, c]]));
            oit_core::Instance::from_rows(rows, colors[i]).map_err(|e| PyValueError::new_err(format!("instance {i}: {e}")))
        })
        .collect()
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

/// A parameter dict as the core takes it: names with ints, floats or strings.
pub(crate) fn param_list(params: &Bound<'_, PyDict>) -> PyResult<Vec<(String, ParamValue)>> {
    let mut plist = Vec::new();
    for (k, v) in params.iter() {
        let name: String = k.extract()?;
        plist.push((name.clone(), param_value(&v, &name)?));
    }
    Ok(plist)
}

pub(crate) fn value_to_py<'py>(py: Python<'py>, v: &ParamValue) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        ParamValue::Int(i) => i.into_pyobject(py)?.into_any(),
        ParamValue::Float(f) => f.into_pyobject(py)?.into_any(),
        ParamValue::Str(s) => s.into_pyobject(py)?.into_any(),
    })
}
