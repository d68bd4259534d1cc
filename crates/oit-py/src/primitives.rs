//! Strand and particle sets from numpy arrays, and any set as the triangles it is drawn as.
//! Shapes are checked here; values are the core's to check (oit_core::primitive).

use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{array, matrix, rows};
use crate::error::Error;
use crate::surface::Look;

fn surfaced(mesh: oit_core::Mesh, look: &Look) -> PyResult<oit_core::Mesh> {
    let shading = oit_core::Shading::from_name(&look.shading).map_err(Error::from)?;
    Ok(mesh.with_primitive_surface(shading, look.specular, look.shininess, look.opacity).map_err(Error::from)?)
}

pub(crate) fn strands(
    points: &PyReadonlyArray2<'_, f32>,
    counts: &PyReadonlyArray1<'_, u32>,
    widths: &PyReadonlyArray1<'_, f32>,
    colors: &PyReadonlyArray2<'_, f32>,
    opaque: bool,
    look: &Look,
) -> PyResult<oit_core::Mesh> {
    let counts = counts.as_array().to_vec();
    let widths = widths.as_array().to_vec();
    let mesh = oit_core::Mesh::strands(rows(points, "points")?, counts, widths, rows(colors, "colors")?, opaque).map_err(Error::from)?;
    surfaced(mesh, look)
}

pub(crate) fn particles(
    centers: &PyReadonlyArray2<'_, f32>,
    radii: &PyReadonlyArray1<'_, f32>,
    colors: &PyReadonlyArray2<'_, f32>,
    opaque: bool,
    falloff: &str,
    opacity: f32,
) -> PyResult<oit_core::Mesh> {
    let falloff = oit_core::Falloff::from_name(falloff).map_err(Error::from)?;
    let radii = radii.as_array().to_vec();
    let mesh =
        oit_core::Mesh::particles(rows(centers, "centers")?, radii, rows(colors, "colors")?, opaque, falloff).map_err(Error::from)?;
    surfaced(mesh, &Look { shading: "unlit".into(), specular: 0.0, shininess: 32.0, opacity })
}

/// A splat set's spherical harmonics: (n k, 3) RGB coefficients, the DC first, and their degree.
pub(crate) type Harmonics<'py> = (PyReadonlyArray2<'py, f32>, u32);

/// A splat set: means (n, 3), scales (n, 3), wxyz rotations (n, 4), opacities (n,), RGB
/// colors (n, 3), each row count n or 1; its color from `sh` instead where given.
pub(crate) fn gaussians(
    means: &PyReadonlyArray2<'_, f32>,
    scales: &PyReadonlyArray2<'_, f32>,
    rotations: &PyReadonlyArray2<'_, f32>,
    opacities: &PyReadonlyArray1<'_, f32>,
    colors: &PyReadonlyArray2<'_, f32>,
    sh: Option<&Harmonics<'_>>,
) -> PyResult<oit_core::Mesh> {
    let (means, scales, rotations) = (rows(means, "means")?, rows(scales, "scales")?, rows(rotations, "rotations")?);
    let opacities = opacities.as_array().to_vec();
    let mesh = match sh {
        None => oit_core::Mesh::gaussians(means, scales, rotations, opacities, rows(colors, "colors")?),
        Some((sh, degree)) => oit_core::Mesh::gaussians_sh(means, scales, rotations, opacities, rows(sh, "sh")?, *degree),
    };
    Ok(mesh.map_err(Error::from)?)
}

/// Positions (n, 3), indices (m, 3), colors (n, 4), normals (n, 3) or None, uvs (n, 2) or None.
pub(crate) type TriangleArrays<'py> = (
    Bound<'py, numpy::PyArray2<f32>>,
    Bound<'py, numpy::PyArray2<u32>>,
    Bound<'py, numpy::PyArray2<f32>>,
    Option<Bound<'py, numpy::PyArray2<f32>>>,
    Option<Bound<'py, numpy::PyArray2<f32>>>,
);

/// `mesh` as triangles under the camera `view_proj` (strands and particles face it).
pub(crate) fn to_triangles<'py>(
    py: Python<'py>,
    mesh: &oit_core::Mesh,
    view_proj: &PyReadonlyArray2<'_, f64>,
) -> PyResult<TriangleArrays<'py>> {
    let camera = oit_core::Camera::from_rows(matrix(view_proj, "camera matrix")?).map_err(Error::from)?;
    // Splats take their low-pass as on a 1024 x 1024 frame (the camera carries no size).
    let m = oit_core::primitive::to_triangles(mesh, &camera, glam::DVec2::splat(1024.0));
    let optional = |v: Bound<'py, numpy::PyArray2<f32>>, empty: bool| (!empty).then_some(v);
    Ok((
        array(py, &m.positions),
        array(py, &m.indices),
        array(py, &m.colors),
        optional(array(py, &m.normals), m.normals.is_empty()),
        optional(array(py, &m.uvs), m.uvs.is_empty()),
    ))
}
