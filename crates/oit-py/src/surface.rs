//! The values Python passes as one argument, taken apart by name: a mesh's surface into the core's
//! `Material` with the mesh's normals and UVs, a strand set's look, and how a frame is rendered.
//! Each is a dict with every key (python/oit/_scene.py `add_mesh`, `_primitives.py`, `_render.py`
//! `Renderer.render`), whose types are checked there and whose defaults are the public API's.

use std::sync::Arc;

use numpy::{PyReadonlyArray2, PyReadonlyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::rows;
use crate::error::Error;

/// A mesh's surface as `Scene.add_mesh` takes it.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct Surface<'py> {
    normals: Option<PyReadonlyArray2<'py, f32>>,
    uvs: Option<PyReadonlyArray2<'py, f32>>,
    /// (h, w, 4) float32 linear RGBA.
    texture: Option<PyReadonlyArray3<'py, f32>>,
    shading: String,
    specular: f32,
    shininess: f32,
    opacity: f32,
    two_sided: bool,
    cull_back_faces: bool,
}

/// A mesh's normals, UVs and material, as `Mesh::with_surface` takes them.
pub(crate) type Surfaced = (Option<Vec<[f32; 3]>>, Option<Vec<[f32; 2]>>, oit_core::Material);

impl Surface<'_> {
    pub fn into_core(self) -> PyResult<Surfaced> {
        let texture = match self.texture {
            Some(t) => {
                let a = t.as_array();
                let (h, w, c) = a.dim();
                if c != 4 {
                    return Err(PyValueError::new_err(format!("texture must have shape (h, w, 4), got ({h}, {w}, {c})")));
                }
                let flat: Vec<f32> = a.iter().copied().collect();
                let texels = flat.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
                let image = oit_core::Texture::new(w as u32, h as u32, texels).map_err(Error::from)?;
                Some(oit_core::TextureMap::new(Arc::new(image)))
            }
            None => None,
        };
        let material = oit_core::Material {
            shading: oit_core::Shading::from_name(&self.shading).map_err(Error::from)?,
            specular: self.specular,
            shininess: self.shininess,
            opacity: self.opacity,
            two_sided: self.two_sided,
            cull_back_faces: self.cull_back_faces,
            texture,
            ..Default::default()
        };
        let normals = self.normals.map(|n| rows(&n, "normals")).transpose()?;
        let uvs = self.uvs.map(|u| rows(&u, "uvs")).transpose()?;
        Ok((normals, uvs, material))
    }
}

impl Surface<'_> {
    /// The surface as a scene file's record of a mesh of `n` vertices (texels as they are).
    pub fn into_file(self, n: usize) -> PyResult<oit_core::scenefile::FileSurface> {
        let texture = match self.texture {
            Some(t) => {
                let (h, w, _) = t.as_array().dim();
                let flat: Vec<f32> = t.as_array().iter().copied().collect();
                let texels = flat.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
                Some(oit_core::scenefile::FileTexture { width: w as u32, height: h as u32, texels })
            }
            None => None,
        };
        let normals: Vec<[f32; 3]> = self.normals.map(|a| rows(&a, "normals")).transpose()?.unwrap_or_default();
        let uvs: Vec<[f32; 2]> = self.uvs.map(|a| rows(&a, "uvs")).transpose()?.unwrap_or_default();
        for (what, len) in [("normals", normals.len()), ("uvs", uvs.len())] {
            if len != 0 && len != n {
                return Err(PyValueError::new_err(format!("{what} has {len} rows for {n} vertices: give one a vertex")));
            }
        }
        Ok(oit_core::scenefile::FileSurface {
            shading: oit_core::Shading::from_name(&self.shading).map_err(Error::from)?,
            two_sided: self.two_sided,
            cull_back_faces: self.cull_back_faces,
            specular: self.specular,
            shininess: self.shininess,
            opacity: self.opacity,
            normals,
            uvs,
            texture,
        })
    }
}

/// The surface words of a strand set (a particle set's are fixed but for its opacity).
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct Look {
    pub shading: String,
    pub specular: f32,
    pub shininess: f32,
    pub opacity: f32,
}

/// How a frame is rendered, besides its scene, camera, method and parameters.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct FrameOptions {
    pub background: (f32, f32, f32),
    pub antialias: u32,
    pub antialias_mode: String,
    pub shading_cost: u32,
    pub census: bool,
}
