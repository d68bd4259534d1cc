use super::*;

fn triangle(opaque: bool) -> FileMesh {
    FileMesh {
        name: "tri".into(),
        opaque,
        positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        colors: vec![[0.5, 0.25, 1.0, 0.4]; 3],
        indices: vec![[0, 1, 2]],
        primitive: FilePrimitive::Triangles,
        surface: None,
    }
}

fn surface() -> FileSurface {
    FileSurface {
        shading: Shading::Smooth,
        two_sided: false,
        cull_back_faces: true,
        specular: 0.5,
        shininess: 48.0,
        opacity: 0.75,
        normals: vec![[0.0, 0.0, 1.0]; 3],
        uvs: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
        // Texels between 8-bit levels: the file keeps them exactly.
        texture: Some(FileTexture { width: 1, height: 2, texels: vec![[0.1234, 0.0, 1.0, 1.0], [0.0, 0.3, 0.7, 0.501]] }),
    }
}

fn version(bytes: &[u8]) -> u32 {
    u32::from_le_bytes(bytes[8..12].try_into().unwrap())
}

#[test]
fn records_round_trip_exactly_and_take_the_oldest_version_that_holds_them() {
    let look = CameraSpec::LookAt { eye: [0.0, 0.0, 3.0], target: [0.0; 3], up: [0.0, 1.0, 0.0], fov_y: 45.0, near: 0.1, far: 10.0 };
    let plain = SceneFile { meshes: vec![triangle(false), triangle(true)], camera: Some(look), size: Some((64, 32)), ..Default::default() };
    let bytes = plain.encode();
    assert_eq!(version(&bytes), 1);
    let back = SceneFile::parse(&bytes).unwrap();
    assert_eq!((back.meshes, back.camera, back.size), (plain.meshes.clone(), Some(look), Some((64, 32))));

    let mut lit = plain.clone();
    lit.meshes[0].surface = Some(surface());
    lit.lights = vec![Light { direction: [0.0, -1.0, -1.0], color: [1.0, 0.5, 0.25], intensity: 0.8 }];
    lit.ambient = [0.1, 0.2, 0.3];
    let bytes = lit.encode();
    assert_eq!(version(&bytes), 2);
    let back = SceneFile::parse(&bytes).unwrap();
    assert_eq!(back.meshes, lit.meshes);
    assert_eq!((back.lights[0].direction, back.lights[0].intensity, back.ambient), ([0.0, -1.0, -1.0], 0.8, [0.1, 0.2, 0.3]));
    assert_eq!(back.encode(), bytes);

    let mut sets = SceneFile::default();
    let strands = FilePrimitive::Strands { counts: vec![3], widths: vec![0.1, 0.2, 0.3] };
    let particles = FilePrimitive::Particles { falloff: Falloff::Gaussian, radii: vec![0.25; 3] };
    for primitive in [strands, particles] {
        sets.meshes.push(FileMesh { indices: vec![], primitive, ..triangle(false) });
    }
    let bytes = sets.encode();
    assert_eq!(version(&bytes), 3);
    assert_eq!(SceneFile::parse(&bytes).unwrap().meshes, sets.meshes);
}

#[test]
fn records_become_checked_meshes_and_back() {
    let mut record = triangle(false);
    record.surface = Some(surface());
    let mesh = record.to_mesh().unwrap();
    assert_eq!((mesh.material.shading, mesh.material.opacity, mesh.material.cull_back_faces), (Shading::Smooth, 0.75, true));
    assert_eq!(mesh.uvs, record.surface.as_ref().unwrap().uvs);
    let again = FileMesh::from_mesh(&NamedMesh::new("tri".into(), mesh));
    assert_eq!(again.surface.as_ref().unwrap().normals, record.surface.as_ref().unwrap().normals);
    assert_eq!(FileMesh::from_mesh(&NamedMesh::new("tri".into(), triangle(true).to_mesh().unwrap())), triangle(true));
    let strands = FileMesh {
        indices: vec![],
        primitive: FilePrimitive::Strands { counts: vec![3], widths: vec![0.1; 3] },
        surface: Some(FileSurface { normals: vec![], uvs: vec![], texture: None, shading: Shading::Hair, ..surface() }),
        ..triangle(false)
    };
    assert_eq!(strands.to_mesh().unwrap().material.shading, Shading::Hair);
    let textured = FileMesh { surface: Some(FileSurface { normals: vec![], uvs: vec![], ..surface() }), ..strands };
    assert!(textured.to_mesh().unwrap_err().to_string().contains("carry no normals, UVs or texture"));
    let past = FileMesh { indices: vec![[0, 1, 7]], ..triangle(false) };
    assert!(past.to_mesh().unwrap_err().to_string().contains("refers past the last vertex"));
}

#[test]
fn bad_files_say_what_is_wrong() {
    let err = |b: &[u8]| SceneFile::parse(b).unwrap_err().to_string();
    assert!(err(b"PLY").contains("ends inside"));
    assert!(err(b"NOTSCENE\x01\0\0\0").contains("not an oit scene"));
    let mut newer = SceneFile::default().encode();
    newer[8] = 9;
    assert!(err(&newer).contains("scene file version 9; this reads versions 1 to 3"));
    let good = SceneFile { meshes: vec![triangle(false)], ..Default::default() }.encode();
    assert!(err(&good[..good.len() - 4]).contains("mesh 0: file ends inside indices"));
    assert!(err(&[good.as_slice(), &[0]].concat()).contains("1 bytes after the last mesh"));
}

/// tests/data/two_quads.oitscene, which Python's and the viewer's tests read too.
#[test]
fn the_shared_scene_file_reads_and_writes_its_bytes() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/two_quads.oitscene");
    let bytes = std::fs::read(path).unwrap();
    let file = SceneFile::parse(&bytes).unwrap();
    let names: Vec<&str> = file.meshes.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["back (opaque)", "red quad", "triangle, α per vertex"]);
    assert_eq!(file.encode(), bytes);
}
