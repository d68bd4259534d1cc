//! The scene file's codec (`oit_core::scenefile`) for python/oit/scenefile.py: records as dicts
//! of numpy arrays in, the file's bytes out, and back. Python keeps what is Python's (BuiltScene
//! and MeshArrays, names, instances written once each); the bytes are the core's.

use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};

use oit_core::scenefile::{CameraSpec, FileMesh, FilePrimitive, FileSurface, SceneFile};
use oit_core::{Falloff, Light};

use crate::convert::{array, rows};
use crate::error::Error;
use crate::guard::guarded;
use crate::surface::Surface;

/// One mesh record; `surface` as `Scene.add_mesh` takes it (surface.rs).
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct MeshRecord<'py> {
    name: String,
    opaque: bool,
    positions: PyReadonlyArray2<'py, f32>,
    colors: PyReadonlyArray2<'py, f32>,
    indices: PyReadonlyArray2<'py, u32>,
    primitive: Option<PrimitiveRecord<'py>>,
    surface: Option<Surface<'py>>,
}

/// A strand set ("strands": counts, and widths as `sizes`), a particle set ("particles":
/// falloff, and radii as `sizes`; one size a point) or a splat set ("gaussians": scales,
/// rotations, and harmonics `sh` (n k, 3) of `degree` or none).
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct PrimitiveRecord<'py> {
    kind: String,
    counts: Option<PyReadonlyArray1<'py, u32>>,
    falloff: Option<String>,
    sizes: Option<PyReadonlyArray1<'py, f32>>,
    scales: Option<PyReadonlyArray2<'py, f32>>,
    rotations: Option<PyReadonlyArray2<'py, f32>>,
    sh: Option<PyReadonlyArray2<'py, f32>>,
    degree: Option<u32>,
}

/// A camera as the file has it: 1 and the 16 values of a row-major view-projection, or 2 and
/// eye, target, up, fov_y (degrees), near, far.
type CameraRecord = (u32, Vec<f64>);

/// (direction, color, intensity) of a light.
type LightRecord = ([f32; 3], [f32; 3], f32);

fn mesh_record(m: MeshRecord<'_>) -> PyResult<FileMesh> {
    let positions = rows(&m.positions, "positions")?;
    let n = positions.len();
    let primitive = match m.primitive {
        None => FilePrimitive::Triangles,
        Some(PrimitiveRecord { kind, scales: Some(scales), rotations: Some(rotations), sh, degree, .. }) if kind == "gaussians" => {
            let sh = sh.map(|s| rows(&s, "sh")).transpose()?.unwrap_or_default();
            FilePrimitive::Gaussians {
                scales: rows(&scales, "scales")?,
                rotations: rows(&rotations, "rotations")?,
                sh,
                degree: degree.unwrap_or(0),
            }
        }
        Some(p) => {
            let sizes = p.sizes.map(|s| s.as_array().to_vec()).unwrap_or_default();
            match (p.kind.as_str(), p.counts, p.falloff) {
                ("strands", Some(counts), _) => FilePrimitive::Strands { counts: counts.as_array().to_vec(), widths: sizes },
                ("particles", _, Some(falloff)) => {
                    FilePrimitive::Particles { falloff: Falloff::from_name(&falloff).map_err(Error::from)?, radii: sizes }
                }
                (kind, ..) => {
                    return Err(PyValueError::new_err(format!(
                        "primitive kind must be 'strands', 'particles' or 'gaussians' (with scales and rotations), got '{kind}'"
                    )))
                }
            }
        }
    };
    let surface = m.surface.map(|s| s.into_file(n)).transpose()?;
    let (colors, indices) = (rows(&m.colors, "colors")?, rows(&m.indices, "indices")?);
    Ok(FileMesh { name: m.name, opaque: m.opaque, positions, colors, indices, primitive, surface })
}

fn camera_spec(camera: Option<CameraRecord>) -> PyResult<Option<CameraSpec>> {
    Ok(match camera {
        None => None,
        Some((1, v)) if v.len() == 16 => Some(CameraSpec::Matrix(std::array::from_fn(|i| std::array::from_fn(|j| v[4 * i + j])))),
        Some((2, v)) if v.len() == 12 => {
            let xyz = |i: usize| [v[i], v[i + 1], v[i + 2]];
            Some(CameraSpec::LookAt { eye: xyz(0), target: xyz(3), up: xyz(6), fov_y: v[9], near: v[10], far: v[11] })
        }
        Some((kind, v)) => {
            return Err(PyValueError::new_err(format!(
                "camera must be (1, 16 matrix values) or (2, 12 look-at values), got kind {kind} with {} values",
                v.len()
            )))
        }
    })
}

/// A surface record as python/oit/scenefile.py reads it: the arrays the file has, only.
fn surface_dict<'py>(py: Python<'py>, s: &FileSurface) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("shading", s.shading.name())?;
    d.set_item("two_sided", s.two_sided)?;
    d.set_item("cull_back_faces", s.cull_back_faces)?;
    d.set_item("specular", s.specular)?;
    d.set_item("shininess", s.shininess)?;
    d.set_item("opacity", s.opacity)?;
    if !s.normals.is_empty() {
        d.set_item("normals", array(py, &s.normals))?;
    }
    if !s.uvs.is_empty() {
        d.set_item("uvs", array(py, &s.uvs))?;
    }
    if let Some(t) = &s.texture {
        let flat: Vec<f32> = t.texels.iter().flatten().copied().collect();
        let shape = (t.height as usize, t.width as usize, 4);
        d.set_item("texture", numpy::ndarray::Array3::from_shape_vec(shape, flat).expect("h x w x 4").into_pyarray(py))?;
    }
    Ok(d)
}

fn mesh_dict<'py>(py: Python<'py>, m: &FileMesh) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", &m.name)?;
    d.set_item("opaque", m.opaque)?;
    d.set_item("positions", array(py, &m.positions))?;
    d.set_item("colors", array(py, &m.colors))?;
    d.set_item("indices", array(py, &m.indices))?;
    let primitive = match &m.primitive {
        FilePrimitive::Triangles => None,
        FilePrimitive::Strands { counts, widths } => {
            let p = PyDict::new(py);
            p.set_item("kind", "strands")?;
            p.set_item("counts", counts.clone().into_pyarray(py))?;
            p.set_item("widths", widths.clone().into_pyarray(py))?;
            Some(p)
        }
        FilePrimitive::Particles { falloff, radii } => {
            let p = PyDict::new(py);
            p.set_item("kind", "particles")?;
            p.set_item("radii", radii.clone().into_pyarray(py))?;
            p.set_item("falloff", falloff.name())?;
            Some(p)
        }
        FilePrimitive::Gaussians { scales, rotations, sh, degree } => {
            let p = PyDict::new(py);
            p.set_item("kind", "gaussians")?;
            p.set_item("scales", array(py, scales))?;
            p.set_item("rotations", array(py, rotations))?;
            p.set_item("sh", (!sh.is_empty()).then(|| array(py, sh)))?;
            p.set_item("degree", *degree)?;
            Some(p)
        }
    };
    d.set_item("primitive", primitive)?;
    d.set_item("surface", m.surface.as_ref().map(|s| surface_dict(py, s)).transpose()?)?;
    Ok(d)
}

/// What `decode_scene` returns: mesh dicts, the camera record, the size, the lights, the ambient term.
type Decoded<'py> = (Bound<'py, PyList>, Option<CameraRecord>, Option<(u32, u32)>, Vec<LightRecord>, [f32; 3]);

guarded! { fns GUARDED;

/// A scene file's bytes from mesh records (dicts: name, opaque, positions, colors, indices,
/// primitive, surface), a camera record, the size, lights and the ambient term.
#[pyfunction]
pub fn encode_scene<'py>(
    py: Python<'py>,
    meshes: Vec<MeshRecord<'py>>,
    camera: Option<CameraRecord>,
    size: Option<(u32, u32)>,
    lights: Vec<LightRecord>,
    ambient: [f32; 3],
) -> PyResult<Bound<'py, PyBytes>> {
    let meshes = meshes.into_iter().map(mesh_record).collect::<PyResult<_>>()?;
    let lights = lights.into_iter().map(|(direction, color, intensity)| Light { direction, color, intensity }).collect();
    let file = SceneFile { size, camera: camera_spec(camera)?, meshes, lights, ambient };
    Ok(PyBytes::new(py, &file.encode()))
}

/// The file's magic bytes and its newest version.
#[pyfunction]
pub fn scene_file_format(py: Python<'_>) -> (Bound<'_, PyBytes>, u32) {
    (PyBytes::new(py, oit_core::scenefile::MAGIC), oit_core::scenefile::VERSION)
}

/// A scene file's records from its bytes: mesh dicts (a surface has only the arrays the file
/// has), the camera record, the size, the lights and the ambient term.
#[pyfunction]
pub fn decode_scene<'py>(py: Python<'py>, data: &[u8]) -> PyResult<Decoded<'py>> {
    let file = SceneFile::parse(data).map_err(Error::from)?;
    let meshes = PyList::empty(py);
    for m in &file.meshes {
        meshes.append(mesh_dict(py, m)?)?;
    }
    let camera = file.camera.map(|c| match c {
        CameraSpec::Matrix(m) => (1, m.as_flattened().to_vec()),
        CameraSpec::LookAt { eye, target, up, fov_y, near, far } => (2, [&eye[..], &target, &up, &[fov_y, near, far]].concat()),
    });
    let lights = file.lights.iter().map(|l| (l.direction, l.color, l.intensity)).collect();
    Ok((meshes, camera, file.size, lights, file.ambient))
}
}
