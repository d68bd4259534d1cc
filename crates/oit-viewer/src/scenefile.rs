//! The scene interchange file (`.oitscene`): what `python -m oit view --scene NAME` exports
//! and the viewer reads. The layout is specified in docs/viewer.md; python/oit/scenefile.py
//! writes it and mirrors this file.

use std::path::Path;

use oit_core::{Falloff, Light, Material, Mesh, Primitive, Shading, Texture, TextureMap};

pub const MAGIC: &[u8; 8] = b"OITSCENE";
/// The newest version; a file without surfaces, lights or ambient term is written as 1, one
/// without strands, particles or "hair" shading as 2.
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

/// A mesh and its name, as the core's loader gives them.
pub use oit_core::load::NamedMesh;

/// Meshes in submission order, the camera they come with (if any) and the frame size they
/// are meant for.
#[derive(Clone, Debug, Default)]
pub struct SceneData {
    pub meshes: Vec<NamedMesh>,
    pub camera: Option<CameraSpec>,
    pub size: Option<(u32, u32)>,
    /// Directional lights (none: the headlight) and the ambient term (docs/shading.md).
    pub lights: Vec<Light>,
    pub ambient: [f32; 3],
}

struct Reader<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.data.len());
        let end = end.ok_or_else(|| format!("file ends inside {what} (at byte {}, {n} bytes needed)", self.at))?;
        let s = &self.data[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().unwrap()))
    }
    fn f32s<const N: usize>(&mut self, what: &str) -> Result<[f32; N], String> {
        let b = self.take(4 * N, what)?;
        Ok(std::array::from_fn(|i| f32::from_le_bytes(b[4 * i..4 * i + 4].try_into().unwrap())))
    }
    fn f64s<const N: usize>(&mut self, what: &str) -> Result<[f64; N], String> {
        let b = self.take(8 * N, what)?;
        Ok(std::array::from_fn(|i| f64::from_le_bytes(b[8 * i..8 * i + 8].try_into().unwrap())))
    }
    fn array<T: bytemuck::Pod>(&mut self, count: usize, what: &str) -> Result<Vec<T>, String> {
        let bytes = count.checked_mul(std::mem::size_of::<T>()).ok_or_else(|| format!("{what}: count {count} too large"))?;
        Ok(bytemuck::pod_collect_to_vec(self.take(bytes, what)?))
    }
}

/// Parses a scene file's bytes; errors say where the file is wrong.
pub fn parse(data: &[u8]) -> Result<SceneData, String> {
    let mut r = Reader { data, at: 0 };
    if r.take(8, "the header")? != MAGIC {
        return Err("not an oit scene file (it does not start with OITSCENE)".into());
    }
    let version = r.u32("the version")?;
    if !(1..=VERSION).contains(&version) {
        return Err(format!("scene file version {version}; this viewer reads versions 1 to {VERSION}"));
    }
    let (w, h) = (r.u32("the size")?, r.u32("the size")?);
    let size = (w > 0 && h > 0).then_some((w, h));
    let camera = match r.u32("the camera kind")? {
        0 => None,
        1 => {
            let m: [f64; 16] = r.f64s("the camera matrix")?;
            Some(CameraSpec::Matrix(std::array::from_fn(|i| std::array::from_fn(|j| m[4 * i + j]))))
        }
        2 => {
            let v: [f64; 12] = r.f64s("the look-at camera")?;
            Some(CameraSpec::LookAt {
                eye: [v[0], v[1], v[2]],
                target: [v[3], v[4], v[5]],
                up: [v[6], v[7], v[8]],
                fov_y: v[9],
                near: v[10],
                far: v[11],
            })
        }
        k => return Err(format!("unknown camera kind {k} (0: none, 1: matrix, 2: look-at)")),
    };
    let count = r.u32("the mesh count")?;
    let mut meshes = Vec::new();
    for i in 0..count {
        let flags = r.u32("mesh flags")?;
        let name_len = r.u32("a mesh name")? as usize;
        let name = String::from_utf8_lossy(r.take(name_len, "a mesh name")?).into_owned();
        let n = r.u32("the vertex count")? as usize;
        let m = r.u32("the triangle count")? as usize;
        let positions: Vec<[f32; 3]> = r.array(n, "positions")?;
        let colors: Vec<[f32; 4]> = r.array(n, "colors")?;
        let indices: Vec<[u32; 3]> = r.array(m, "indices")?;
        let opaque = flags & 1 != 0;
        let mut mesh = if flags & 4 != 0 {
            read_primitive(&mut r, positions, colors, opaque, n)
        } else {
            Mesh::new(positions, indices, colors, opaque).map_err(|e| e.to_string())
        }
        .map_err(|e| format!("mesh {i} ('{name}'): {e}"))?;
        if flags & 2 != 0 {
            mesh = read_surface(&mut r, mesh, n).map_err(|e| format!("mesh {i} ('{name}'): {e}"))?;
        }
        meshes.push(NamedMesh::new(if name.is_empty() { format!("mesh {i}") } else { name }, mesh));
    }
    let (mut lights, mut ambient) = (Vec::new(), [0.0; 3]);
    if version >= 2 {
        for _ in 0..r.u32("the light count")? {
            let v: [f32; 7] = r.f32s("a light")?;
            lights.push(Light::new([v[0], v[1], v[2]], [v[3], v[4], v[5]], v[6]).map_err(|e| e.to_string())?);
        }
        ambient = r.f32s("the ambient term")?;
    }
    if r.at != data.len() {
        return Err(format!("{} bytes after the last mesh", data.len() - r.at));
    }
    Ok(SceneData { meshes, camera, size, lights, ambient })
}

/// A strand or particle set (flags bit 2, version 3): its kind, then the points per strand and
/// the widths, or the falloff and the radii.
fn read_primitive(r: &mut Reader<'_>, points: Vec<[f32; 3]>, colors: Vec<[f32; 4]>, opaque: bool, n: usize) -> Result<Mesh, String> {
    let (kind, value) = (r.u32("the primitive kind")?, r.u32("the primitive block")?);
    match kind {
        1 => {
            let counts: Vec<u32> = r.array(value as usize, "the strand counts")?;
            let widths: Vec<f32> = r.array(n, "the widths")?;
            Mesh::strands(points, counts, widths, colors, opaque).map_err(|e| e.to_string())
        }
        2 => {
            let falloff = match value {
                1 => Falloff::Hard,
                2 => Falloff::Linear,
                3 => Falloff::Gaussian,
                k => return Err(format!("unknown falloff {k} (1: hard, 2: linear, 3: gaussian)")),
            };
            let radii: Vec<f32> = r.array(n, "the radii")?;
            Mesh::particles(points, radii, colors, opaque, falloff).map_err(|e| e.to_string())
        }
        k => Err(format!("unknown primitive kind {k} (1: strands, 2: particles)")),
    }
}

/// A mesh's surface (flags bit 1): shading, two-sidedness, specular, shininess, opacity, then
/// optional normals, UVs and texture. A strand or particle set's has none of those three.
fn read_surface(r: &mut Reader<'_>, mesh: Mesh, n: usize) -> Result<Mesh, String> {
    let shading = match r.u32("the shading")? {
        0 => Shading::Unlit,
        1 => Shading::Flat,
        2 => Shading::Smooth,
        3 => Shading::Hair,
        k => return Err(format!("unknown shading {k} (0: unlit, 1: flat, 2: smooth, 3: hair)")),
    };
    // The sidedness word: bit 0 two-sided lighting, bit 1 back faces culled.
    let sides = r.u32("two-sidedness")?;
    let (two_sided, cull_back_faces) = (sides & 1 != 0, sides & 2 != 0);
    let [specular, shininess, opacity] = r.f32s("the material")?;
    let count = |r: &mut Reader<'_>, what: &str| -> Result<usize, String> {
        match r.u32(what)? as usize {
            0 => Ok(0),
            c if c == n => Ok(c),
            c => Err(format!("{c} {what} for {n} vertices")),
        }
    };
    let k = count(r, "normals")?;
    let normals: Option<Vec<[f32; 3]>> = (k > 0).then(|| r.array(k, "normals")).transpose()?;
    let k = count(r, "uvs")?;
    let uvs: Option<Vec<[f32; 2]>> = (k > 0).then(|| r.array(k, "uvs")).transpose()?;
    let (h, w) = (r.u32("the texture height")?, r.u32("the texture width")?);
    let texture = if h > 0 && w > 0 {
        let texels = r.array((h as usize).saturating_mul(w as usize), "texels")?;
        Some(TextureMap::new(std::sync::Arc::new(Texture::new(w, h, texels).map_err(|e| e.to_string())?)))
    } else {
        None
    };
    if mesh.primitive != Primitive::Triangles {
        if normals.is_some() || uvs.is_some() || texture.is_some() {
            return Err(format!("{} carry no normals, UVs or texture", mesh.primitive.name()));
        }
        return mesh.with_primitive_surface(shading, specular, shininess, opacity).map_err(|e| e.to_string());
    }
    let material = Material { shading, specular, shininess, opacity, two_sided, cull_back_faces, texture, ..Default::default() };
    mesh.with_surface(normals, uvs, material).map_err(|e| e.to_string())
}

pub fn read(path: &Path) -> Result<SceneData, String> {
    let data = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse(&data).map_err(|e| format!("{}: {e}", path.display()))
}

/// The file's bytes (the viewer only reads scene files; tests write them with this).
pub fn encode(scene: &SceneData) -> Vec<u8> {
    let mut out = Vec::new();
    let u32s = |out: &mut Vec<u8>, v: &[u32]| v.iter().for_each(|x| out.extend(x.to_le_bytes()));
    let f64s = |out: &mut Vec<u8>, v: &[f64]| v.iter().for_each(|x| out.extend(x.to_le_bytes()));
    out.extend(MAGIC);
    let (w, h) = scene.size.unwrap_or((0, 0));
    // A particle set's falloff is in its primitive block, not its surface.
    let surfaced = |m: &Mesh| !m.material.is_plain_surface() || !m.normals.is_empty() || !m.uvs.is_empty();
    let newest = |m: &Mesh| m.primitive != Primitive::Triangles || m.material.shading == Shading::Hair;
    let version = if scene.meshes.iter().any(|m| newest(&m.mesh)) {
        VERSION
    } else if scene.lights.is_empty() && scene.ambient == [0.0; 3] && !scene.meshes.iter().any(|m| surfaced(&m.mesh)) {
        1
    } else {
        2
    };
    u32s(&mut out, &[version, w, h]);
    match scene.camera {
        None => u32s(&mut out, &[0]),
        Some(CameraSpec::Matrix(m)) => {
            u32s(&mut out, &[1]);
            f64s(&mut out, m.as_flattened());
        }
        Some(CameraSpec::LookAt { eye, target, up, fov_y, near, far }) => {
            u32s(&mut out, &[2]);
            f64s(&mut out, &[eye, target, up].concat());
            f64s(&mut out, &[fov_y, near, far]);
        }
    }
    u32s(&mut out, &[scene.meshes.len() as u32]);
    for m in &scene.meshes {
        let surface = surfaced(&m.mesh);
        let set = m.mesh.primitive != Primitive::Triangles;
        u32s(&mut out, &[m.mesh.opaque as u32 | if surface { 2 } else { 0 } | if set { 4 } else { 0 }, m.name.len() as u32]);
        out.extend(m.name.as_bytes());
        u32s(&mut out, &[m.mesh.positions.len() as u32, m.mesh.indices.len() as u32]);
        out.extend(bytemuck::cast_slice(&m.mesh.positions));
        out.extend(bytemuck::cast_slice(&m.mesh.colors));
        out.extend(bytemuck::cast_slice(&m.mesh.indices));
        match &m.mesh.primitive {
            Primitive::Triangles => {}
            Primitive::Strands { counts, widths } => {
                u32s(&mut out, &[1, counts.len() as u32]);
                u32s(&mut out, counts);
                out.extend(bytemuck::cast_slice(widths));
            }
            Primitive::Particles { radii } => {
                u32s(&mut out, &[2, m.mesh.material.falloff.code()]);
                out.extend(bytemuck::cast_slice(radii));
            }
        }
        if surface {
            let mat = &m.mesh.material;
            u32s(&mut out, &[mat.shading.code(), mat.two_sided as u32 | (mat.cull_back_faces as u32) << 1]);
            out.extend(bytemuck::cast_slice(&[mat.specular, mat.shininess, mat.opacity]));
            u32s(&mut out, &[m.mesh.normals.len() as u32]);
            out.extend(bytemuck::cast_slice(&m.mesh.normals));
            u32s(&mut out, &[m.mesh.uvs.len() as u32]);
            out.extend(bytemuck::cast_slice(&m.mesh.uvs));
            match &mat.texture {
                Some(t) => {
                    u32s(&mut out, &[t.image.height, t.image.width]);
                    out.extend(bytemuck::cast_slice(&t.image.linear_texels()));
                }
                None => u32s(&mut out, &[0, 0]),
            }
        }
    }
    if version >= 2 {
        u32s(&mut out, &[scene.lights.len() as u32]);
        for l in &scene.lights {
            out.extend(bytemuck::cast_slice(&[l.direction, l.color].concat()));
            out.extend(l.intensity.to_le_bytes());
        }
        out.extend(bytemuck::cast_slice(&scene.ambient));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strands_and_particles_round_trip_as_version_3() {
        let strands = Mesh::strands(vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]], vec![3], vec![0.1, 0.2, 0.3], vec![[0.5; 4]], false)
            .and_then(|m| m.with_primitive_surface(Shading::Hair, 0.3, 48.0, 0.9))
            .unwrap();
        let particles = Mesh::particles(vec![[0.0; 3], [0.0, 1.0, 0.0]], vec![0.25], vec![[1.0; 4]], true, Falloff::Gaussian).unwrap();
        let scene = SceneData {
            meshes: vec![NamedMesh::new("hair".into(), strands.clone()), NamedMesh::new("smoke".into(), particles.clone())],
            ..Default::default()
        };
        let bytes = encode(&scene);
        assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 3);
        let back = parse(&bytes).unwrap();
        assert_eq!(back.meshes[0].mesh.primitive, strands.primitive);
        assert_eq!(back.meshes[0].mesh.material.shading, Shading::Hair);
        assert_eq!(back.meshes[0].mesh.material.opacity, 0.9);
        assert_eq!(back.meshes[1].mesh.primitive, particles.primitive);
        assert_eq!(back.meshes[1].mesh.material.falloff, Falloff::Gaussian);
        assert!(back.meshes[1].mesh.opaque);
        assert!(parse(&bytes[..bytes.len() - 3]).unwrap_err().contains("file ends"));
    }

    fn triangle(opaque: bool) -> NamedMesh {
        let mesh =
            Mesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]], vec![[0.5, 0.25, 1.0, 0.4]], opaque).unwrap();
        NamedMesh::new("tri".into(), mesh)
    }

    #[test]
    fn round_trip() {
        let look = CameraSpec::LookAt { eye: [0.0, 0.0, 3.0], target: [0.0; 3], up: [0.0, 1.0, 0.0], fov_y: 45.0, near: 0.1, far: 10.0 };
        let mut identity = [[0.0; 4]; 4];
        (0..4).for_each(|i| identity[i][i] = 1.0);
        for camera in [None, Some(look), Some(CameraSpec::Matrix(identity))] {
            let scene = SceneData { meshes: vec![triangle(false), triangle(true)], camera, size: Some((64, 32)), ..Default::default() };
            let back = parse(&encode(&scene)).unwrap();
            assert_eq!(back.camera, camera);
            assert_eq!(back.size, Some((64, 32)));
            assert_eq!(back.meshes.len(), 2);
            assert!(back.meshes[1].mesh.opaque && !back.meshes[0].mesh.opaque);
            assert_eq!(back.meshes[0].mesh.colors, scene.meshes[0].mesh.colors);
            assert_eq!(back.meshes[0].mesh.indices, vec![[0, 1, 2]]);
        }
    }

    /// tests/data/two_quads.oitscene, which tests/test_viewer.py (`test_shared_scene_file`)
    /// reads too and checks against the same values; Python wrote it, and so does `encode`.
    #[test]
    fn the_shared_scene_file() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/two_quads.oitscene");
        let bytes = std::fs::read(&path).unwrap();
        let scene = read(&path).unwrap();
        assert_eq!(scene.size, Some((64, 48)));
        let look = CameraSpec::LookAt { eye: [0.5, 0.25, 4.0], target: [0.0; 3], up: [0.0, 1.0, 0.0], fov_y: 45.0, near: 1.0, far: 10.0 };
        assert_eq!(scene.camera, Some(look));
        let names: Vec<&str> = scene.meshes.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["back (opaque)", "red quad", "triangle, α per vertex"]);
        let [back, quad, tri] = [0, 1, 2].map(|i| &scene.meshes[i].mesh);
        assert_eq!((back.opaque, quad.opaque, tri.opaque), (true, false, false));
        assert_eq!(back.positions, [[-1.0, -1.0, -0.5], [1.0, -1.0, -0.5], [1.0, 1.0, -0.5], [-1.0, 1.0, -0.5]]);
        assert_eq!(back.colors, [[0.5, 0.5, 0.5, 1.0]; 4]);
        assert_eq!(back.indices, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(quad.positions, [[-0.25, -0.5, 0.0], [0.75, -0.5, 0.0], [0.75, 0.5, 0.0], [-0.25, 0.5, 0.0]]);
        assert_eq!(quad.colors, [[1.0, 0.25, 0.125, 0.5]; 4]);
        assert_eq!(quad.indices, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(tri.positions, [[-0.75, -0.25, 0.25], [0.25, -0.25, 0.25], [-0.25, 0.75, 0.25]]);
        assert_eq!(tri.colors, [[1.0, 0.0, 0.0, 0.25], [0.0, 1.0, 0.0, 0.5], [0.0, 0.0, 1.0, 0.75]]);
        assert_eq!(tri.indices, [[0, 1, 2]]);
        assert!(encode(&scene) == bytes, "the viewer writes the file's bytes back");
    }

    #[test]
    fn surfaces_and_lights_round_trip_as_version_2() {
        let mut lit = triangle(false);
        let material = Material { shading: Shading::Smooth, specular: 0.5, opacity: 0.75, ..Default::default() };
        let texture = Texture::new(1, 2, vec![[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.5]]).unwrap();
        lit.mesh = lit.mesh.with_surface(None, Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), material).unwrap();
        lit.mesh.material.texture = Some(TextureMap::new(std::sync::Arc::new(texture)));
        let light = Light::new([0.0, -1.0, -1.0], [1.0, 0.5, 0.25], 0.8).unwrap();
        let scene = SceneData { meshes: vec![lit, triangle(true)], lights: vec![light], ambient: [0.1, 0.2, 0.3], ..Default::default() };
        let bytes = encode(&scene);
        assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 2);
        let back = parse(&bytes).unwrap();
        let (m, plain) = (&back.meshes[0].mesh, &back.meshes[1].mesh);
        assert_eq!((m.material.shading, m.material.specular, m.material.opacity), (Shading::Smooth, 0.5, 0.75));
        assert_eq!(m.normals, scene.meshes[0].mesh.normals);
        let texels = |m: &Mesh| m.material.texture.as_ref().unwrap().image.levels()[0].texels.clone();
        assert_eq!(texels(m), texels(&scene.meshes[0].mesh));
        assert_eq!(texels(m)[1], [0, 0, 255, 128]);
        assert!(plain.material.is_plain() && plain.opaque);
        assert_eq!((back.lights[0].direction, back.lights[0].intensity, back.ambient), ([0.0, -1.0, -1.0], 0.8, [0.1, 0.2, 0.3]));
        assert_eq!(encode(&back), bytes);
    }

    #[test]
    fn bad_files_say_what_is_wrong() {
        assert!(parse(b"PLY").unwrap_err().contains("ends inside"));
        assert!(parse(b"NOTSCENE\x01\0\0\0").unwrap_err().contains("not an oit scene"));
        let mut good = encode(&SceneData { meshes: vec![triangle(false)], ..Default::default() });
        good.truncate(good.len() - 4);
        assert!(parse(&good).unwrap_err().contains("indices"));
        let mut bad_index = encode(&SceneData { meshes: vec![triangle(false)], ..Default::default() });
        let n = bad_index.len();
        bad_index[n - 4..].copy_from_slice(&7u32.to_le_bytes());
        assert!(parse(&bad_index).unwrap_err().contains("refers past the last vertex"));
    }
}
