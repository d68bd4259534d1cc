//! The scene interchange file (`.oitscene`) as the viewer reads it: the core's codec
//! (`oit_core::scenefile`, which Python's `oit.scenefile` calls too), each mesh record made a
//! checked core mesh. The layout is specified in docs/viewer.md.

use std::path::Path;

use oit_core::scenefile::{FileMesh, SceneFile};
use oit_core::Light;

pub use oit_core::scenefile::{CameraSpec, MAGIC, VERSION};

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

/// Parses a scene file's bytes; errors say where the file is wrong.
pub fn parse(data: &[u8]) -> Result<SceneData, String> {
    let file = SceneFile::parse(data).map_err(|e| e.to_string())?;
    let mut meshes = Vec::with_capacity(file.meshes.len());
    for (i, m) in file.meshes.iter().enumerate() {
        let mesh = m.to_mesh().map_err(|e| format!("mesh {i} ('{}'): {e}", m.name))?;
        meshes.push(NamedMesh::new(if m.name.is_empty() { format!("mesh {i}") } else { m.name.clone() }, mesh));
    }
    let lights = file.lights.iter().map(|l| Light::new(l.direction, l.color, l.intensity).map_err(|e| e.to_string()));
    Ok(SceneData { meshes, camera: file.camera, size: file.size, lights: lights.collect::<Result<_, _>>()?, ambient: file.ambient })
}

pub fn read(path: &Path) -> Result<SceneData, String> {
    let data = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse(&data).map_err(|e| format!("{}: {e}", path.display()))
}

/// The file's bytes (the viewer only reads scene files; tests write them with this).
pub fn encode(scene: &SceneData) -> Vec<u8> {
    let meshes = scene.meshes.iter().map(FileMesh::from_mesh).collect();
    SceneFile { size: scene.size, camera: scene.camera, meshes, lights: scene.lights.clone(), ambient: scene.ambient }.encode()
}

#[cfg(test)]
mod tests {
    use super::*;
    use oit_core::{Falloff, Material, Mesh, Shading, Texture, TextureMap};

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
