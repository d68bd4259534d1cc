//! The loader on small files written here: what each format brings, and bad files refused.

use std::path::PathBuf;

use super::*;

fn tmp(name: &str, data: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("oit-core-load-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, data).unwrap();
    p
}

fn load(p: &Path) -> Result<LoadedFile> {
    load_file(p, Surface::default())
}

#[test]
fn obj_dissolve_is_alpha_and_tr_its_complement() {
    tmp("two.mtl", b"newmtl glass\nKd 1 0 0\nd 0.25\nnewmtl wall\nKd 0 0 1\nTr 0.75\nnewmtl solid\nKd 0 1 0\n");
    let obj = "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
               o a\nusemtl glass\nf 1 2 3 4\no b\nusemtl wall\nf 1 2 3\no c\nusemtl solid\nf 1 3 4\n";
    let f = load(&tmp("two.obj", obj.as_bytes())).unwrap();
    let m: Vec<&Mesh> = f.meshes.iter().map(|m| &m.mesh).collect();
    assert_eq!(m.iter().map(|m| m.triangle_count()).collect::<Vec<_>>(), [2, 1, 1]);
    assert_eq!(m[0].colors[0], [1.0, 0.0, 0.0, 0.25]);
    assert!((m[1].colors[0][3] - 0.25).abs() < 1e-6 && !m[1].opaque);
    assert!(m[2].opaque && m[2].colors[0][3] == 1.0);
    assert!(blends(m[0]) && !blends(m[2]));
}

#[test]
fn viewing_alpha_applies_only_when_nothing_blends() {
    let p = tmp("quad.obj", b"o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    let mut f = load(&p).unwrap();
    assert!(f.meshes[0].mesh.opaque, "an OBJ without a dissolve is opaque, as written");
    assert!(viewing_alpha(&mut f.meshes, None).unwrap().unwrap().contains("alpha 0.4"));
    assert!(f.meshes[0].mesh.colors.iter().all(|c| c[3] == VIEWING_ALPHA) && !f.meshes[0].mesh.opaque);
    let mut f = load(&p).unwrap();
    assert_eq!(viewing_alpha(&mut f.meshes, Some(0.25)).unwrap(), None);
    assert!(f.meshes[0].mesh.colors.iter().all(|c| c[3] == 0.25));
    assert!(viewing_alpha(&mut f.meshes, Some(1.5)).is_err());
    // A file that blends keeps its alphas.
    tmp("glass.mtl", b"newmtl glass\nd 0.25\n");
    let mut f = load(&tmp("glass.obj", b"mtllib glass.mtl\nusemtl glass\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")).unwrap();
    assert_eq!(viewing_alpha(&mut f.meshes, None).unwrap(), None);
    assert_eq!(f.meshes[0].mesh.colors[0][3], 0.25);
}

fn tmp_path(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("oit-core-load-{}", std::process::id())).join(name)
}

#[test]
fn ply_ascii_with_rgba_vertex_colors() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0 255 0 0 128\n1 0 0 255 0 0 128\n0 1 0 255 0 0 128\n3 0 1 2\n";
    let f = load(&tmp("tri.ply", text.as_bytes())).unwrap();
    let m = &f.meshes[0].mesh;
    assert_eq!(m.colors[0][..3], [1.0, 0.0, 0.0]);
    assert!((m.colors[0][3] - 128.0 / 255.0).abs() < 1e-6 && !m.opaque);
}

#[test]
fn stl_binary_is_gray_and_opaque() {
    let mut data = vec![0u8; 80];
    data.extend(1u32.to_le_bytes());
    for v in [[0.0f32, 0.0, 1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        v.iter().for_each(|x| data.extend(x.to_le_bytes()));
    }
    data.extend([0, 0]);
    let f = load(&tmp("tri.stl", &data)).unwrap();
    assert_eq!(f.meshes[0].mesh.indices.len(), 1);
    assert!(f.meshes[0].mesh.opaque);
}

/// A glTF with its buffer as a base64 data URI: `json` gets `{B64}` replaced by the buffer.
fn gltf_file(name: &str, bin: &[u8], json: &str) -> PathBuf {
    const T: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let b64: String = bin
        .chunks(3)
        .flat_map(|c| {
            let n = c.iter().enumerate().fold(0u32, |n, (i, &b)| n | (b as u32) << (16 - 8 * i));
            (0..4).map(move |i| if i <= c.len() { T[(n >> (18 - 6 * i) & 63) as usize] as char } else { '=' })
        })
        .collect();
    tmp(name, json.replace("{B64}", &b64).as_bytes())
}

#[test]
fn gltf_nodes_materials_sides_and_cameras() {
    let mut bin = Vec::new();
    [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].iter().flatten().for_each(|x| bin.extend(x.to_le_bytes()));
    let json = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,2]}],
        "nodes":[{"mesh":0,"translation":[0,0,2],"children":[1]},{"mesh":1,"scale":[2,2,2]},
                 {"camera":0,"translation":[0,0,10]}],
        "cameras":[{"type":"perspective","perspective":{"yfov":0.8,"znear":0.1}}],
        "meshes":[{"name":"tri","primitives":[{"attributes":{"POSITION":0},"material":0}]},
                  {"name":"plain","primitives":[{"attributes":{"POSITION":0}}]}],
        "materials":[{"alphaMode":"BLEND","doubleSided":true,"pbrMetallicRoughness":{"baseColorFactor":[1,0.5,0,0.3]}}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,{B64}"}]}"#;
    let f = load(&gltf_file("tri.gltf", &bin, json)).unwrap();
    let (a, b) = (&f.meshes[0].mesh, &f.meshes[1].mesh);
    // Vertices stay as the file has them; each node's world transform is the mesh's instance.
    let world = |m: usize, v: usize| f.meshes[m].instances[0].apply(f.meshes[m].mesh.positions[v]).to_array();
    assert_eq!(a.positions[1], [1.0, 0.0, 0.0]);
    assert_eq!(world(0, 1), [1.0, 0.0, 2.0]);
    assert_eq!(a.colors[0], [1.0, 0.5, 0.0, 0.3]);
    assert!(!a.opaque && a.material.two_sided && !a.material.cull_back_faces);
    // The child composes its parent's translation with its own scale; no material is the
    // spec's default: white, OPAQUE, single-sided.
    assert_eq!(world(1, 1), [2.0, 0.0, 2.0]);
    assert!(b.opaque && b.colors[0] == [1.0; 4] && b.material.cull_back_faces && !b.material.two_sided);
    assert_eq!(f.cameras.len(), 1);
    let Projection::Perspective { yfov, aspect, near, far } = f.cameras[0].projection else { panic!() };
    // No zfar: the far plane lies just past the farthest corner of the scene, (2, 2, 2).
    assert!((yfov - 0.8).abs() < 1e-6 && aspect.is_none() && (near - 0.1).abs() < 1e-6);
    assert!(far > 72f64.sqrt() && far < 72f64.sqrt() * 1.1, "{far}");
    assert_eq!(f.cameras[0].view[2][3], -10.0);
}

#[test]
fn bad_files_say_what_to_do() {
    let e = load(&tmp("x.fbx", b"")).unwrap_err().to_string();
    assert!(e.contains(FORMATS), "{e}");
    let e = load(&tmp_path("missing.obj")).unwrap_err().to_string();
    assert!(e.contains("no such file"), "{e}");
    let e = load(&tmp("bad.glb", b"glTF\x02\0\0\0garbage")).unwrap_err().to_string();
    assert!(e.contains("not a readable glTF"), "{e}");
    let e = load(&tmp("bad.ply", b"ply\nformat ascii 1.0\nelement vertex 1\nend_header\nx\n")).unwrap_err().to_string();
    assert!(e.contains("bad.ply"), "{e}");
    let e = load(&tmp("empty.obj", b"# no vertices\no nothing\n")).unwrap_err().to_string();
    assert!(e.contains("no triangles"), "{e}");
    // Vertices alone are a point cloud, as a PLY of points is.
    let cloud = load(&tmp("cloud.obj", b"v 0 0 0\nv 1 0 0\n")).unwrap();
    assert!(matches!(cloud.meshes[0].mesh.primitive, crate::primitive::Primitive::Particles { .. }));
}
