//! The core's loader (`oit_core::load`) for `oit.Scene.from_file` and the command line: the
//! scene, its mesh names, the file's cameras as dicts, and the viewing-alpha note.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use oit_core::load::{self, Projection, Surface};

use crate::error::Error;
use crate::guard::{self, guarded};
use crate::scene::Scene;

guarded! { fns GUARDED;

/// Reads `path`; `shading` and `specular` style every surface (`load::Surface`). `alpha`
/// makes every mesh transparent at it; `viewing` adds the command line's convenience (every
/// mesh at VIEWING_ALPHA when nothing blends) and returns its note; `point_radius` sizes a point
/// cloud's particles (None: 1/200 of its box's diagonal). Returns the scene, its mesh names, the
/// file's cameras, the note and the loader's warnings (one sentence a feature not drawn). A
/// panic while reading is a RuntimeError naming the file (`guard::bug`).
#[pyfunction]
#[pyo3(signature = (path, shading="smooth", specular=0.25, alpha=None, viewing=false, point_radius=None))]
#[allow(clippy::type_complexity)]
pub fn load_file<'py>(
    py: Python<'py>,
    path: PathBuf,
    shading: &str,
    specular: f32,
    alpha: Option<f32>,
    viewing: bool,
    point_radius: Option<f32>,
) -> PyResult<(Scene, Vec<String>, Bound<'py, PyList>, Option<String>, Vec<String>)> {
    let surface = Surface { shading: oit_core::Shading::from_name(shading).map_err(Error::from)?, specular, point_radius };
    let read = || -> oit_core::Result<_> {
        let mut file = load::load_file(&path, surface)?;
        let note = match (viewing, alpha) {
            (true, a) => load::viewing_alpha(&mut file.meshes, a)?,
            (false, Some(a)) => load::set_alpha(&mut file.meshes, a).map(|_| None)?,
            (false, None) => None,
        };
        Ok((file, note))
    };
    let (file, note) = py
        .detach(|| catch_unwind(AssertUnwindSafe(read)))
        .map_err(|payload| guard::bug(&format!("loading {}", path.display()), &*payload))?
        .map_err(Error::from)?;
    let cameras = PyList::empty(py);
    for c in &file.cameras {
        let d = PyDict::new(py);
        d.set_item("name", &c.name)?;
        d.set_item("view", c.view.to_vec())?;
        let (near, far) = match c.projection {
            Projection::Perspective { yfov, aspect, near, far } => {
                d.set_item("type", "perspective")?;
                d.set_item("yfov", yfov)?;
                d.set_item("aspect", aspect)?;
                (near, far)
            }
            Projection::Orthographic { xmag, ymag, near, far } => {
                d.set_item("type", "orthographic")?;
                d.set_item("xmag", xmag)?;
                d.set_item("ymag", ymag)?;
                (near, far)
            }
        };
        d.set_item("near", near)?;
        d.set_item("far", far)?;
        cameras.append(d)?;
    }
    let names = file.meshes.iter().map(|m| m.name.clone()).collect();
    let warnings = file.warnings.clone();
    Ok((Scene { inner: file.scene() }, names, cameras, note, warnings))
}
}

/// One dict a mesh: opaque, shading, textured, two_sided, cull_back_faces, the vertex
/// alphas' range and the mean vertex color.
pub fn mesh_materials<'py>(py: Python<'py>, scene: &oit_core::Scene) -> PyResult<Bound<'py, PyList>> {
    let out = PyList::empty(py);
    for m in scene.meshes() {
        let d = PyDict::new(py);
        let n = m.colors.len().max(1) as f64;
        let mean: [f64; 4] = std::array::from_fn(|i| m.colors.iter().map(|c| c[i] as f64).sum::<f64>() / n);
        let alphas = m.colors.iter().map(|c| c[3]);
        d.set_item("opaque", m.opaque)?;
        d.set_item("shading", m.material.shading.name())?;
        d.set_item("textured", m.material.texture.is_some())?;
        d.set_item("two_sided", m.material.two_sided)?;
        d.set_item("cull_back_faces", m.material.cull_back_faces)?;
        d.set_item("alpha_min", alphas.clone().fold(f32::INFINITY, f32::min))?;
        d.set_item("alpha_max", alphas.fold(f32::NEG_INFINITY, f32::max))?;
        d.set_item("color_mean", mean)?;
        d.set_item("has_normals", !m.normals.is_empty())?;
        d.set_item("has_uvs", !m.uvs.is_empty())?;
        d.set_item("emissive", m.material.emissive)?;
        d.set_item("alpha_cutoff", m.material.alpha_cutoff)?;
        if let Some(t) = &m.material.texture {
            let wrap = |w: oit_core::Wrap| match w {
                oit_core::Wrap::Repeat => "repeat",
                oit_core::Wrap::MirroredRepeat => "mirrored_repeat",
                oit_core::Wrap::ClampToEdge => "clamp_to_edge",
            };
            let filter = |f: oit_core::Filter| match f {
                oit_core::Filter::Nearest => "nearest",
                oit_core::Filter::Linear => "linear",
            };
            let s = &t.sampler;
            let texture = PyDict::new(py);
            texture.set_item("size", (t.image.width, t.image.height))?;
            texture.set_item("levels", t.image.levels().len())?;
            texture.set_item("wrap", (wrap(s.wrap_u), wrap(s.wrap_v)))?;
            texture.set_item("filters", (filter(s.mag), filter(s.min), s.mipmap.map(filter)))?;
            texture.set_item("transform", t.transform)?;
            d.set_item("texture", texture)?;
        }
        out.append(d)?;
    }
    Ok(out)
}
