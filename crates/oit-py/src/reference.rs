//! The CPU float64 reference image, and the camera's view direction as the core computes it.

use numpy::{IntoPyArray, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::matrix;
use crate::error::Error;
use crate::guard::guarded;
use crate::scene::Scene;

guarded! { fns GUARDED;

/// CPU float64 reference: (image (h, w, 4) float64, ambiguous (h, w) bool, depth complexity),
/// the mean over the standard pattern's positions when `antialias` > 1.
#[pyfunction]
#[pyo3(signature = (scene, view_proj, width, height, background, antialias=1))]
pub fn reference<'py>(
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
pub fn view_direction(view_proj: PyReadonlyArray2<'_, f64>) -> PyResult<(f64, f64, f64)> {
    let camera = oit_core::Camera::from_rows(matrix(&view_proj, "camera matrix")?).map_err(Error::from)?;
    Ok(camera.view_direction().into())
}
}
