//! `oit._oit.Scene`: meshes, strands and particles from numpy arrays into the core's scene, and
//! what the scene holds back out.

use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::convert::{array, instances, matrix, rows, InstanceArrays};
use crate::error::{Error, Res};
use crate::guard::guarded;
use crate::surface::{Look, Surface};
use crate::{load, primitives};

/// Meshes in submission order (validated on the way in).
#[pyclass(module = "oit._oit")]
pub(crate) struct Scene {
    pub(crate) inner: oit_core::Scene,
}

guarded! {
#[pymethods]
impl Scene {
    #[new]
    fn new() -> Self {
        Self { inner: oit_core::Scene::new() }
    }

    /// positions (n, 3) float32, indices (m, 3) uint32, colors (n, 4) or (1, 4) float32; the
    /// surface a dict (surface.rs): normals (n, 3) and uvs (n, 2) float32 or None, texture (h, w,
    /// 4) float32 linear RGBA or None, shading "unlit", "flat", "smooth" or "hair", specular,
    /// shininess, opacity, two_sided, cull_back_faces. `transform` (4, 4) float64 places it (else
    /// it is drawn where its vertices are).
    #[pyo3(signature = (positions, indices, colors, opaque, surface, transform=None))]
    fn add_mesh(
        &mut self,
        positions: PyReadonlyArray2<'_, f32>,
        indices: PyReadonlyArray2<'_, u32>,
        colors: PyReadonlyArray2<'_, f32>,
        opaque: bool,
        surface: Surface<'_>,
        transform: Option<PyReadonlyArray2<'_, f64>>,
    ) -> PyResult<usize> {
        let placement = match transform {
            Some(t) => oit_core::Instance::from_rows(matrix(&t, "transform")?, [1.0; 4]).map_err(Error::from)?,
            None => oit_core::Instance::IDENTITY,
        };
        let mesh = oit_core::Mesh::new(rows(&positions, "positions")?, rows(&indices, "indices")?, rows(&colors, "colors")?, opaque)
            .map_err(Error::from)?;
        let (normals, uvs, material) = surface.into_core()?;
        let mesh = mesh.with_surface(normals, uvs, material).map_err(Error::from)?;
        Ok(self.inner.add_placed(mesh, vec![placement]))
    }

    /// A strand set: points (n, 3), counts (strands,) uint32, widths (n,) or (1,), colors (n, 4)
    /// or (1, 4) float32; the look a dict of shading ("unlit" or "hair"), specular, shininess and
    /// opacity.
    fn add_strands(
        &mut self,
        points: PyReadonlyArray2<'_, f32>,
        counts: PyReadonlyArray1<'_, u32>,
        widths: PyReadonlyArray1<'_, f32>,
        colors: PyReadonlyArray2<'_, f32>,
        opaque: bool,
        look: Look,
    ) -> PyResult<usize> {
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

    /// A splat set: means (n, 3), scales (n, 3), wxyz rotations (n, 4), opacities (n,), RGB
    /// colors (n, 3) float32, each with n rows or one; `look`: spherical harmonics ((n k, 3)
    /// coefficients, k = (degree + 1)², the DC first; degree) in place of the colors, or None,
    /// and the fragment depth ("center" or "ray").
    fn add_gaussians(
        &mut self,
        means: PyReadonlyArray2<'_, f32>,
        scales: PyReadonlyArray2<'_, f32>,
        rotations: PyReadonlyArray2<'_, f32>,
        opacities: PyReadonlyArray1<'_, f32>,
        colors: PyReadonlyArray2<'_, f32>,
        look: (Option<primitives::Harmonics<'_>>, String),
    ) -> PyResult<usize> {
        let (sh, splat_depth) = look;
        let mut mesh = primitives::gaussians(&means, &scales, &rotations, &opacities, &colors, sh.as_ref())?;
        mesh.material.splat_depth = oit_core::shading::SplatDepth::from_name(&splat_depth).map_err(Error::from)?;
        Ok(self.inner.add_mesh(mesh))
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
