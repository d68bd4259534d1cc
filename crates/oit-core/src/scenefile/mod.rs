//! The scene interchange file (`.oitscene`), read and written here only: Python's `oit.scenefile`
//! calls it through the binding, and the viewer reads its scenes with it. The layout is
//! specified in docs/viewer.md. [`SceneFile`] holds the records as the file has them (arrays
//! unchecked, texels exact); [`FileMesh::to_mesh`] makes a checked core mesh of one and
//! [`FileMesh::from_mesh`] the record of one.

use std::sync::Arc;

use crate::error::{invalid, Result};
use crate::load::NamedMesh;
use crate::primitive::Primitive;
use crate::scene::Mesh;
use crate::shading::{Falloff, Light, Material, Shading, Texture, TextureMap};

pub const MAGIC: &[u8; 8] = b"OITSCENE";
/// The newest version; a file without surfaces, lights or ambient term is written as 1, one
/// without strands, particles or "hair" shading as 2 (older readers read them).
pub const VERSION: u32 = 3;

/// A camera as a scene file stores it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraSpec {
    /// View-projection, row-major (`clip = M @ [x, y, z, 1]`), wgpu clip space, made for
    /// the file's size (its aspect ratio).
    Matrix([[f64; 4]; 4]),
    /// A right-handed perspective camera; `fov_y` in degrees.
    LookAt { eye: [f64; 3], target: [f64; 3], up: [f64; 3], fov_y: f64, near: f64, far: f64 },
}

/// What a mesh record's vertices are (flags bit 2, version 3).
#[derive(Clone, Debug, PartialEq)]
pub enum FilePrimitive {
    Triangles,
    /// Points per strand, and a width per point.
    Strands {
        counts: Vec<u32>,
        widths: Vec<f32>,
    },
    /// A radius per particle.
    Particles {
        falloff: Falloff,
        radii: Vec<f32>,
    },
    /// Gaussian splats: standard deviations and wxyz rotations (their opacity is the colors' alpha).
    /// Spherical harmonics of `degree` where `sh` is not empty ((degree + 1)² a splat).
    Gaussians {
        scales: Vec<[f32; 3]>,
        rotations: Vec<[f32; 4]>,
        sh: Vec<[f32; 3]>,
        degree: u32,
    },
}

/// A base color texture as the file stores it: linear RGBA, row 0 first.
#[derive(Clone, Debug, PartialEq)]
pub struct FileTexture {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 4]>,
}

/// A mesh's surface (flags bit 1). A strand or particle set's has no normals, UVs or texture.
#[derive(Clone, Debug, PartialEq)]
pub struct FileSurface {
    pub shading: Shading,
    pub two_sided: bool,
    pub cull_back_faces: bool,
    pub specular: f32,
    pub shininess: f32,
    pub opacity: f32,
    /// None or one a vertex.
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub texture: Option<FileTexture>,
}

/// One mesh record.
#[derive(Clone, Debug, PartialEq)]
pub struct FileMesh {
    pub name: String,
    pub opaque: bool,
    pub positions: Vec<[f32; 3]>,
    /// Straight linear RGBA, one a vertex.
    pub colors: Vec<[f32; 4]>,
    pub indices: Vec<[u32; 3]>,
    pub primitive: FilePrimitive,
    pub surface: Option<FileSurface>,
}

/// A whole file: meshes in submission order, the camera they come with, the frame size they are
/// meant for, lights (none: the headlight) and the ambient term (docs/shading.md).
#[derive(Clone, Debug, Default)]
pub struct SceneFile {
    pub size: Option<(u32, u32)>,
    pub camera: Option<CameraSpec>,
    pub meshes: Vec<FileMesh>,
    pub lights: Vec<Light>,
    pub ambient: [f32; 3],
}

impl SceneFile {
    /// The oldest version that holds the file: 3 with a strand or particle set or "hair"
    /// shading, 2 with a surface, a light or an ambient term, else 1.
    pub fn version(&self) -> u32 {
        let newest =
            |m: &FileMesh| m.primitive != FilePrimitive::Triangles || m.surface.as_ref().is_some_and(|s| s.shading == Shading::Hair);
        if self.meshes.iter().any(newest) {
            VERSION
        } else if !self.lights.is_empty() || self.ambient != [0.0; 3] || self.meshes.iter().any(|m| m.surface.is_some()) {
            2
        } else {
            1
        }
    }

    /// The file's bytes, little-endian.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Writer(Vec::new());
        w.0.extend(MAGIC);
        let version = self.version();
        let (width, height) = self.size.unwrap_or((0, 0));
        w.u32s(&[version, width, height]);
        match self.camera {
            None => w.u32s(&[0]),
            Some(CameraSpec::Matrix(m)) => {
                w.u32s(&[1]);
                w.pod(m.as_flattened());
            }
            Some(CameraSpec::LookAt { eye, target, up, fov_y, near, far }) => {
                w.u32s(&[2]);
                w.pod(&[eye, target, up].concat());
                w.pod(&[fov_y, near, far]);
            }
        }
        w.u32s(&[self.meshes.len() as u32]);
        for m in &self.meshes {
            let set = m.primitive != FilePrimitive::Triangles;
            w.u32s(&[m.opaque as u32 | if m.surface.is_some() { 2 } else { 0 } | if set { 4 } else { 0 }, m.name.len() as u32]);
            w.0.extend(m.name.as_bytes());
            w.u32s(&[m.positions.len() as u32, m.indices.len() as u32]);
            w.pod(&m.positions);
            w.pod(&m.colors);
            w.pod(&m.indices);
            match &m.primitive {
                FilePrimitive::Triangles => {}
                FilePrimitive::Strands { counts, widths } => {
                    w.u32s(&[1, counts.len() as u32]);
                    w.u32s(counts);
                    w.pod(widths);
                }
                FilePrimitive::Particles { falloff, radii } => {
                    w.u32s(&[2, falloff.code()]);
                    w.pod(radii);
                }
                FilePrimitive::Gaussians { scales, rotations, sh, degree } => {
                    // The block's value: 0 without harmonics, else their degree + 1.
                    w.u32s(&[3, if sh.is_empty() { 0 } else { degree + 1 }]);
                    w.pod(scales);
                    w.pod(rotations);
                    w.pod(sh);
                }
            }
            if let Some(s) = &m.surface {
                w.u32s(&[s.shading.code(), s.two_sided as u32 | (s.cull_back_faces as u32) << 1]);
                w.pod(&[s.specular, s.shininess, s.opacity]);
                w.u32s(&[s.normals.len() as u32]);
                w.pod(&s.normals);
                w.u32s(&[s.uvs.len() as u32]);
                w.pod(&s.uvs);
                match &s.texture {
                    Some(t) => {
                        w.u32s(&[t.height, t.width]);
                        w.pod(&t.texels);
                    }
                    None => w.u32s(&[0, 0]),
                }
            }
        }
        if version >= 2 {
            w.u32s(&[self.lights.len() as u32]);
            for l in &self.lights {
                w.pod(&[l.direction, l.color].concat());
                w.pod(&[l.intensity]);
            }
            w.pod(&self.ambient);
        }
        w.0
    }

    /// Parses a file's bytes; errors say where the file is wrong.
    pub fn parse(data: &[u8]) -> Result<Self> {
        let mut r = Reader { data, at: 0 };
        if r.take(8, "the header")? != MAGIC {
            return Err(invalid!("not an oit scene file (it does not start with OITSCENE)"));
        }
        let version = r.u32("the version")?;
        if !(1..=VERSION).contains(&version) {
            return Err(invalid!("scene file version {version}; this reads versions 1 to {VERSION}"));
        }
        let (w, h) = (r.u32("the size")?, r.u32("the size")?);
        let size = (w > 0 && h > 0).then_some((w, h));
        let camera = match r.u32("the camera kind")? {
            0 => None,
            1 => {
                let m: Vec<f64> = r.array(16, "the camera matrix")?;
                Some(CameraSpec::Matrix(std::array::from_fn(|i| std::array::from_fn(|j| m[4 * i + j]))))
            }
            2 => {
                let v: Vec<f64> = r.array(12, "the look-at camera")?;
                let xyz = |i: usize| [v[i], v[i + 1], v[i + 2]];
                Some(CameraSpec::LookAt { eye: xyz(0), target: xyz(3), up: xyz(6), fov_y: v[9], near: v[10], far: v[11] })
            }
            k => return Err(invalid!("unknown camera kind {k} (0: none, 1: matrix, 2: look-at)")),
        };
        let count = r.u32("the mesh count")?;
        let mut meshes = Vec::new();
        for i in 0..count {
            let m = read_mesh(&mut r).map_err(|e| invalid!("mesh {i}: {e}"))?;
            meshes.push(m);
        }
        let (mut lights, mut ambient) = (Vec::new(), [0.0; 3]);
        if version >= 2 {
            for _ in 0..r.u32("the light count")? {
                let v: Vec<f32> = r.array(7, "a light")?;
                lights.push(Light { direction: [v[0], v[1], v[2]], color: [v[3], v[4], v[5]], intensity: v[6] });
            }
            let a: Vec<f32> = r.array(3, "the ambient term")?;
            ambient = [a[0], a[1], a[2]];
        }
        if r.at != data.len() {
            return Err(invalid!("{} bytes after the last mesh", data.len() - r.at));
        }
        Ok(Self { size, camera, meshes, lights, ambient })
    }
}

fn read_mesh(r: &mut Reader<'_>) -> Result<FileMesh> {
    let flags = r.u32("mesh flags")?;
    let name_len = r.u32("a mesh name")? as usize;
    let name = String::from_utf8_lossy(r.take(name_len, "a mesh name")?).into_owned();
    let n = r.u32("the vertex count")? as usize;
    let m = r.u32("the triangle count")? as usize;
    let positions = r.array(n, "positions")?;
    let colors = r.array(n, "colors")?;
    let indices = r.array(m, "indices")?;
    let primitive = if flags & 4 != 0 { read_primitive(r, n)? } else { FilePrimitive::Triangles };
    let surface = if flags & 2 != 0 { Some(read_surface(r, n)?) } else { None };
    Ok(FileMesh { name, opaque: flags & 1 != 0, positions, colors, indices, primitive, surface })
}

/// A strand or particle set's block: its kind, then the points per strand and the widths, or the
/// falloff and the radii.
fn read_primitive(r: &mut Reader<'_>, n: usize) -> Result<FilePrimitive> {
    let (kind, value) = (r.u32("the primitive kind")?, r.u32("the primitive block")?);
    match kind {
        1 => Ok(FilePrimitive::Strands { counts: r.array(value as usize, "the strand counts")?, widths: r.array(n, "the widths")? }),
        2 => {
            let falloff = match value {
                1 => Falloff::Hard,
                2 => Falloff::Linear,
                3 => Falloff::Gaussian,
                k => return Err(invalid!("unknown falloff {k} (1: hard, 2: linear, 3: gaussian)")),
            };
            Ok(FilePrimitive::Particles { falloff, radii: r.array(n, "the radii")? })
        }
        3 => {
            let (scales, rotations) = (r.array(n, "the scales")?, r.array(n, "the rotations")?);
            if value > 4 {
                return Err(invalid!("spherical harmonics of degree {}: 0 to 3 are read", value - 1));
            }
            let k = if value == 0 { 0 } else { (value * value) as usize };
            Ok(FilePrimitive::Gaussians {
                scales,
                rotations,
                sh: r.array(n.saturating_mul(k), "the harmonics")?,
                degree: value.saturating_sub(1),
            })
        }
        k => Err(invalid!("unknown primitive kind {k} (1: strands, 2: particles, 3: gaussians)")),
    }
}

/// A surface block: shading, sidedness (bit 0 two-sided lighting, bit 1 back faces culled),
/// specular, shininess, opacity, then normals, UVs and texture, each possibly empty.
fn read_surface(r: &mut Reader<'_>, n: usize) -> Result<FileSurface> {
    let shading = match r.u32("the shading")? {
        0 => Shading::Unlit,
        1 => Shading::Flat,
        2 => Shading::Smooth,
        3 => Shading::Hair,
        k => return Err(invalid!("unknown shading {k} (0: unlit, 1: flat, 2: smooth, 3: hair)")),
    };
    let sides = r.u32("two-sidedness")?;
    let m: Vec<f32> = r.array(3, "the material")?;
    let count = |r: &mut Reader<'_>, what: &str| -> Result<usize> {
        match r.u32(what)? as usize {
            c if c == 0 || c == n => Ok(c),
            c => Err(invalid!("{c} {what} for {n} vertices")),
        }
    };
    let k = count(r, "normals")?;
    let normals = r.array(k, "normals")?;
    let k = count(r, "uvs")?;
    let uvs = r.array(k, "uvs")?;
    let (height, width) = (r.u32("the texture height")?, r.u32("the texture width")?);
    let texture = match height > 0 && width > 0 {
        true => Some(FileTexture { width, height, texels: r.array((height as usize).saturating_mul(width as usize), "texels")? }),
        false => None,
    };
    let (two_sided, cull_back_faces) = (sides & 1 != 0, sides & 2 != 0);
    Ok(FileSurface { shading, two_sided, cull_back_faces, specular: m[0], shininess: m[1], opacity: m[2], normals, uvs, texture })
}

impl FileMesh {
    /// The core's mesh of this record, checked as every mesh is.
    pub fn to_mesh(&self) -> Result<Mesh> {
        let mesh = match &self.primitive {
            FilePrimitive::Triangles => Mesh::new(self.positions.clone(), self.indices.clone(), self.colors.clone(), self.opaque),
            FilePrimitive::Strands { counts, widths } => {
                Mesh::strands(self.positions.clone(), counts.clone(), widths.clone(), self.colors.clone(), self.opaque)
            }
            FilePrimitive::Particles { falloff, radii } => {
                Mesh::particles(self.positions.clone(), radii.clone(), self.colors.clone(), self.opaque, *falloff)
            }
            FilePrimitive::Gaussians { scales, rotations, sh, degree } => {
                let opacities = self.colors.iter().map(|c| c[3]).collect();
                let rgb = self.colors.iter().map(|c| [c[0], c[1], c[2]]).collect();
                let (p, s, q) = (self.positions.clone(), scales.clone(), rotations.clone());
                match sh.is_empty() {
                    true => Mesh::gaussians(p, s, q, opacities, rgb),
                    false => Mesh::gaussians_sh(p, s, q, opacities, sh.clone(), *degree),
                }
            }
        }?;
        let Some(s) = &self.surface else { return Ok(mesh) };
        let texture = match &s.texture {
            Some(t) => Some(TextureMap::new(Arc::new(Texture::new(t.width, t.height, t.texels.clone())?))),
            None => None,
        };
        if mesh.primitive != Primitive::Triangles {
            if !s.normals.is_empty() || !s.uvs.is_empty() || texture.is_some() {
                return Err(invalid!("{} carry no normals, UVs or texture", mesh.primitive.name()));
            }
            return mesh.with_primitive_surface(s.shading, s.specular, s.shininess, s.opacity);
        }
        let material = Material {
            shading: s.shading,
            specular: s.specular,
            shininess: s.shininess,
            opacity: s.opacity,
            two_sided: s.two_sided,
            cull_back_faces: s.cull_back_faces,
            texture,
            ..Default::default()
        };
        let normals = (!s.normals.is_empty()).then(|| s.normals.clone());
        let uvs = (!s.uvs.is_empty()).then(|| s.uvs.clone());
        mesh.with_surface(normals, uvs, material)
    }

    /// The record of `mesh`: a surface block where it has more than its vertex colors (a
    /// particle set's falloff goes with its primitive), textures as their linear texels.
    pub fn from_mesh(named: &NamedMesh) -> Self {
        let m = &named.mesh;
        let mat = &m.material;
        let primitive = match &m.primitive {
            Primitive::Triangles => FilePrimitive::Triangles,
            Primitive::Strands { counts, widths } => FilePrimitive::Strands { counts: counts.clone(), widths: widths.clone() },
            Primitive::Particles { radii } => FilePrimitive::Particles { falloff: mat.falloff, radii: radii.clone() },
            Primitive::Gaussians { scales, rotations, sh, degree } => {
                FilePrimitive::Gaussians { scales: scales.clone(), rotations: rotations.clone(), sh: sh.clone(), degree: *degree }
            }
        };
        let surfaced = !mat.is_plain_surface() || !m.normals.is_empty() || !m.uvs.is_empty();
        let surface = surfaced.then(|| FileSurface {
            shading: mat.shading,
            two_sided: mat.two_sided,
            cull_back_faces: mat.cull_back_faces,
            specular: mat.specular,
            shininess: mat.shininess,
            opacity: mat.opacity,
            normals: m.normals.clone(),
            uvs: m.uvs.clone(),
            texture: mat.texture.as_ref().map(|t| FileTexture {
                width: t.image.width,
                height: t.image.height,
                texels: t.image.linear_texels(),
            }),
        });
        FileMesh {
            name: named.name.clone(),
            opaque: m.opaque,
            positions: m.positions.clone(),
            colors: m.colors.clone(),
            indices: m.indices.clone(),
            primitive,
            surface,
        }
    }
}

struct Writer(Vec<u8>);

impl Writer {
    fn u32s(&mut self, v: &[u32]) {
        self.pod(v);
    }

    /// Plain numbers and arrays of them, little-endian (as every supported target stores them).
    fn pod<T: bytemuck::Pod>(&mut self, v: &[T]) {
        self.0.extend(bytemuck::cast_slice(v));
    }
}

struct Reader<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.data.len());
        let end = end.ok_or_else(|| invalid!("file ends inside {what} (at byte {}, {n} bytes needed)", self.at))?;
        let s = &self.data[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn u32(&mut self, what: &str) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().expect("4 bytes")))
    }

    fn array<T: bytemuck::Pod>(&mut self, count: usize, what: &str) -> Result<Vec<T>> {
        let bytes = count.checked_mul(std::mem::size_of::<T>()).ok_or_else(|| invalid!("{what}: count {count} too large"))?;
        Ok(bytemuck::pod_collect_to_vec(self.take(bytes, what)?))
    }
}

#[cfg(test)]
mod tests;
