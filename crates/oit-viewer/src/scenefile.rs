//! The scene interchange file (`.oitscene`): what `python -m oit view --scene NAME` exports
//! and the viewer reads. The layout is specified in docs/viewer.md; python/oit/scenefile.py
//! writes it and mirrors this file.

use std::path::Path;

use oit_core::Mesh;

pub const MAGIC: &[u8; 8] = b"OITSCENE";
pub const VERSION: u32 = 1;

/// A camera as a scene file stores it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraSpec {
    /// View-projection, row-major (`clip = M @ [x, y, z, 1]`), wgpu clip space, made for
    /// the file's size (its aspect ratio).
    Matrix([[f64; 4]; 4]),
    /// A right-handed perspective camera; `fov_y` in degrees.
    LookAt { eye: [f64; 3], target: [f64; 3], up: [f64; 3], fov_y: f64, near: f64, far: f64 },
}

#[derive(Clone, Debug)]
pub struct NamedMesh {
    pub name: String,
    pub mesh: Mesh,
}

/// Meshes in submission order, the camera they come with (if any) and the frame size they
/// are meant for.
#[derive(Clone, Debug, Default)]
pub struct SceneData {
    pub meshes: Vec<NamedMesh>,
    pub camera: Option<CameraSpec>,
    pub size: Option<(u32, u32)>,
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
    if version != VERSION {
        return Err(format!("scene file version {version}; this viewer reads version {VERSION}"));
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
        let mesh = Mesh::new(positions, indices, colors, flags & 1 != 0).map_err(|e| format!("mesh {i} ('{name}'): {e}"))?;
        meshes.push(NamedMesh { name: if name.is_empty() { format!("mesh {i}") } else { name }, mesh });
    }
    if r.at != data.len() {
        return Err(format!("{} bytes after the last mesh", data.len() - r.at));
    }
    Ok(SceneData { meshes, camera, size })
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
    u32s(&mut out, &[VERSION, w, h]);
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
        u32s(&mut out, &[m.mesh.opaque as u32, m.name.len() as u32]);
        out.extend(m.name.as_bytes());
        u32s(&mut out, &[m.mesh.positions.len() as u32, m.mesh.indices.len() as u32]);
        out.extend(bytemuck::cast_slice(&m.mesh.positions));
        out.extend(bytemuck::cast_slice(&m.mesh.colors));
        out.extend(bytemuck::cast_slice(&m.mesh.indices));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle(opaque: bool) -> NamedMesh {
        let mesh =
            Mesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]], vec![[0.5, 0.25, 1.0, 0.4]], opaque).unwrap();
        NamedMesh { name: "tri".into(), mesh }
    }

    #[test]
    fn round_trip() {
        let look = CameraSpec::LookAt { eye: [0.0, 0.0, 3.0], target: [0.0; 3], up: [0.0, 1.0, 0.0], fov_y: 45.0, near: 0.1, far: 10.0 };
        let mut identity = [[0.0; 4]; 4];
        (0..4).for_each(|i| identity[i][i] = 1.0);
        for camera in [None, Some(look), Some(CameraSpec::Matrix(identity))] {
            let scene = SceneData { meshes: vec![triangle(false), triangle(true)], camera, size: Some((64, 32)) };
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
