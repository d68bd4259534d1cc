//! Opening what the command line names: scene files (`.oitscene`) and meshes through the
//! core's loader (`oit_core::load`: OBJ, PLY, STL, glTF/GLB), the one `oit.Scene.from_file`
//! and `python -m oit render` use. Mesh files keep their materials and instances; the view is
//! the file's first perspective camera, else fitted.

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3};
use oit_core::load::{self as core_load, Surface, AMBIENT};

use crate::scenefile::{self, SceneData};

/// Everything the command line names, in order: meshes concatenate, the first scene file's
/// camera and size win. `alpha` makes every mesh transparent at that alpha; without it, mesh
/// files where nothing is transparent are drawn at the loader's VIEWING_ALPHA (and it says
/// so on stderr).
pub fn load_all(paths: &[PathBuf], alpha: Option<f32>) -> Result<SceneData, String> {
    let mut out = SceneData::default();
    for path in paths {
        let mut part = load(path, alpha)?;
        out.camera = out.camera.or(part.camera);
        out.size = out.size.or(part.size);
        if out.lights.is_empty() && out.ambient == [0.0; 3] {
            (out.lights, out.ambient) = (part.lights, part.ambient);
        }
        out.meshes.append(&mut part.meshes);
    }
    if out.meshes.is_empty() {
        return Err("nothing to show: the files hold no triangles".into());
    }
    Ok(out)
}

pub fn load(path: &Path, alpha: Option<f32>) -> Result<SceneData, String> {
    if let Some(a) = alpha.filter(|a| !(0.0..=1.0).contains(a)) {
        return Err(format!("--alpha {a} is outside [0, 1]"));
    }
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_lowercase();
    if ext == "oitscene" {
        if !path.is_file() {
            return Err(format!("no such file: {}", path.display()));
        }
        let mut scene = scenefile::read(path)?;
        if let Some(a) = alpha {
            core_load::set_alpha(&mut scene.meshes, a).map_err(|e| e.to_string())?;
        }
        return Ok(scene);
    }
    // The loader never panics on any bytes; should it all the same, say it is a bug, not crash.
    let read = std::panic::catch_unwind(|| core_load::load_file(path, Surface::default())).map_err(|payload| {
        let msg = payload.downcast_ref::<&str>().copied().or_else(|| payload.downcast_ref::<String>().map(String::as_str));
        format!(
            "loading {} failed on an internal error ({}): this is a bug in oit; please report it with the file",
            path.display(),
            msg.unwrap_or("no message")
        )
    })?;
    let mut file = read.map_err(|e| {
        let e = e.to_string();
        if e.contains("unknown file type") {
            format!("{e} (and the viewer .oitscene)")
        } else {
            e
        }
    })?;
    // What the file has that the viewer does not draw, a line each (as the command line says it).
    for w in &file.warnings {
        eprintln!("oit-viewer: warning: {}: {w}", path.display());
    }
    if let Some(note) = core_load::viewing_alpha(&mut file.meshes, alpha).map_err(|e| e.to_string())? {
        eprintln!("oit-viewer: {}: {note}", path.display());
    }
    let camera = file.cameras.first().and_then(|c| file_camera(c, &file.meshes));
    if !file.cameras.is_empty() && camera.is_none() {
        eprintln!("oit-viewer: {}: the file's first camera is orthographic; the view is fitted instead", path.display());
    }
    Ok(SceneData { meshes: file.meshes, ambient: AMBIENT, camera, ..Default::default() })
}

/// A file's perspective camera as the viewer's look-at: its eye, its view direction with the
/// orbit's pivot where that direction passes nearest the scene's center, its up, field of view
/// and planes. (An orthographic camera has no look-at: the view is fitted.)
fn file_camera(c: &core_load::FileCamera, meshes: &[core_load::NamedMesh]) -> Option<scenefile::CameraSpec> {
    let core_load::Projection::Perspective { yfov, near, far, .. } = c.projection else { return None };
    let inv = DMat4::from_cols_array_2d(&c.view).transpose().inverse();
    let eye = inv.transform_point3(DVec3::ZERO);
    let forward = inv.transform_vector3(DVec3::NEG_Z).normalize_or_zero();
    let up = inv.transform_vector3(DVec3::Y).normalize_or_zero();
    if forward == DVec3::ZERO || up == DVec3::ZERO {
        return None;
    }
    let (center, _) = crate::orbit::bounds(meshes);
    let reach = (center - eye).dot(forward).max(2.0 * near);
    let target = eye + forward * reach;
    Some(scenefile::CameraSpec::LookAt {
        eye: eye.to_array(),
        target: target.to_array(),
        up: up.to_array(),
        fov_y: yfov.to_degrees(),
        near,
        far,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str, data: &[u8]) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("oit-viewer-load-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, data).unwrap();
        p
    }

    #[test]
    fn a_3dgs_ply_opens_as_splats_with_its_own_opacities() {
        let props =
            ["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"];
        let mut text = String::from("ply\nformat ascii 1.0\nelement vertex 2\n");
        props.iter().for_each(|p| text += &format!("property float {p}\n"));
        text += "end_header\n0 0 0 0.5 0 -0.5 0 -2 -2 -3 1 0 0 0\n0.5 0 -1 0 0 0 -1 -1 -2 -2 1 0 0 0\n";
        let s = load(&tmp("splats.ply", text.as_bytes()), None).unwrap();
        assert_eq!(s.meshes.len(), 1);
        let m = &s.meshes[0].mesh;
        assert!(matches!(m.primitive, oit_core::Primitive::Gaussians { .. }), "{:?}", m.primitive);
        // The logits' sigmoids, not the viewing alpha: the splats blend.
        let want = [0.5, 1.0 / (1.0 + 1f32.exp())];
        m.colors.iter().zip(want).for_each(|(c, w)| assert!((c[3] - w).abs() < 1e-6, "{c:?}"));
    }

    #[test]
    fn obj_with_a_quad_and_alpha_override() {
        let p = tmp("quad.obj", b"o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
        let s = load(&p, Some(0.25)).unwrap();
        assert_eq!(s.meshes.len(), 1);
        assert_eq!(s.meshes[0].mesh.indices.len(), 2);
        assert!(s.meshes[0].mesh.colors.iter().all(|c| c[3] == 0.25));
        // Nothing in the file is transparent: drawn at the viewing alpha.
        let c = load(&p, None).unwrap().meshes[0].mesh.colors[0];
        assert_eq!(c, [0.8, 0.8, 0.8, core_load::VIEWING_ALPHA]);
    }

    #[test]
    fn an_opaque_gltf_material_stays_opaque_beside_a_blended_one() {
        // One triangle (base64 positions), drawn by an OPAQUE (default) and a BLEND material.
        let json = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],
            "nodes":[{"mesh":0},{"mesh":1,"translation":[0,0,-1]}],
            "meshes":[{"name":"box","primitives":[{"attributes":{"POSITION":0},"material":0}]},
                      {"name":"panel","primitives":[{"attributes":{"POSITION":0},"material":1}]}],
            "materials":[{"pbrMetallicRoughness":{"baseColorFactor":[1,0,0,1]}},
                         {"alphaMode":"BLEND","pbrMetallicRoughness":{"baseColorFactor":[0,0,1,0.5]}}],
            "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
            "bufferViews":[{"buffer":0,"byteLength":36}],
            "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]}"#;
        let s = load(&tmp("two.gltf", json.as_bytes()), None).unwrap();
        let (box_, panel) = (&s.meshes[0].mesh, &s.meshes[1].mesh);
        assert!(box_.opaque && box_.colors.iter().all(|c| *c == [1.0, 0.0, 0.0, 1.0]));
        assert!(box_.material.cull_back_faces && !box_.material.two_sided);
        assert!(!panel.opaque && panel.colors.iter().all(|c| *c == [0.0, 0.0, 1.0, 0.5]));
        // The panel's node moves it: its instance, over the file's vertices.
        assert_eq!(panel.positions[0], [0.0, 0.0, 0.0]);
        assert_eq!(s.meshes[1].instances[0].apply(panel.positions[0]).to_array(), [0.0, 0.0, -1.0]);
    }

    #[test]
    fn a_gltf_camera_is_the_view() {
        // The triangle, and a camera 10 in front of it looking down -z.
        let json = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],
            "nodes":[{"mesh":0},{"camera":0,"translation":[0.5,0,10]}],
            "cameras":[{"type":"perspective","perspective":{"yfov":0.6,"znear":0.5,"zfar":50}}],
            "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
            "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
            "bufferViews":[{"buffer":0,"byteLength":36}],
            "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]}"#;
        let s = load(&tmp("cam.gltf", json.as_bytes()), None).unwrap();
        let Some(scenefile::CameraSpec::LookAt { eye, target, up, fov_y, near, far }) = s.camera else { panic!("{:?}", s.camera) };
        assert_eq!(eye, [0.5, 0.0, 10.0]);
        assert!((target[2] - 0.0).abs() < 1e-9 && (target[0] - 0.5).abs() < 1e-9, "{target:?}");
        assert_eq!(up, [0.0, 1.0, 0.0]);
        assert!((fov_y - 0.6f64.to_degrees()).abs() < 1e-4 && (near - 0.5).abs() < 1e-6 && (far - 50.0).abs() < 1e-4);
    }

    #[test]
    fn unknown_extension_names_the_formats() {
        let e = load(&tmp("x.fbx", b""), None).unwrap_err();
        assert!(e.contains(core_load::FORMATS) && e.contains(".oitscene"), "{e}");
    }
}
