//! Opening what the command line names: scene files (`.oitscene`) and meshes (OBJ, PLY,
//! STL, glTF/GLB). Mesh files carry no camera; the viewer fits one.

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3};
use oit_core::{Material, Mesh, Shading};

use crate::scenefile::{self, NamedMesh, SceneData};

/// Alpha of mesh files that say nothing about transparency (as `python -m oit render`).
pub const DEFAULT_ALPHA: f32 = 0.4;
/// Color of mesh files without colors: light gray, linear.
const DEFAULT_RGB: [f32; 3] = [0.8, 0.8, 0.8];

/// Everything the command line names, in order: meshes concatenate, the first scene file's
/// camera and size win. `alpha` overrides every transparent mesh's alpha when given.
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
    if !path.is_file() {
        return Err(format!("no such file: {}", path.display()));
    }
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_lowercase();
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh").to_string();
    let err = |e: String| format!("{}: {e}", path.display());
    let mut scene = match ext.as_str() {
        "oitscene" => scenefile::read(path)?,
        "obj" => meshes_only(obj(path).map_err(err)?),
        "ply" => meshes_only(vec![ply(path, &stem).map_err(err)?]),
        "stl" => meshes_only(vec![stl(path, &stem).map_err(err)?]),
        "gltf" | "glb" => meshes_only(gltf_meshes(path).map_err(err)?),
        _ => {
            return Err(format!(
                "{}: unknown file type '.{ext}'; the viewer opens .oitscene, .obj, .ply, .stl, .gltf and .glb",
                path.display()
            ))
        }
    };
    if scene.meshes.iter().all(|m| m.mesh.indices.is_empty()) {
        return Err(format!("{} has no triangles", path.display()));
    }
    if let Some(a) = alpha {
        for m in scene.meshes.iter_mut().filter(|m| !m.mesh.opaque) {
            m.mesh.colors.iter_mut().for_each(|c| c[3] = a);
        }
    }
    Ok(scene)
}

/// Meshes from a mesh file, lit as `python -m oit render` lights them: smooth shading with
/// computed normals, a little specular, the headlight and a dim ambient term (docs/shading.md).
fn meshes_only(meshes: Vec<NamedMesh>) -> SceneData {
    let lit = |m: NamedMesh| {
        let material = Material { shading: Shading::Smooth, specular: 0.25, ..Default::default() };
        NamedMesh { name: m.name, mesh: m.mesh.with_surface(None, None, material).expect("a valid material") }
    };
    SceneData { meshes: meshes.into_iter().map(lit).collect(), ambient: [0.1; 3], ..Default::default() }
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn named(name: String, positions: Vec<[f32; 3]>, indices: Vec<[u32; 3]>, colors: Vec<[f32; 4]>) -> Result<NamedMesh, String> {
    let mesh = Mesh::new(positions, indices, colors, false).map_err(|e| format!("'{name}': {e}"))?;
    Ok(NamedMesh { name, mesh })
}

/// Vertex colors (`v x y z r g b`, read as sRGB) or the material's diffuse and dissolve.
fn obj(path: &Path) -> Result<Vec<NamedMesh>, String> {
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let (models, materials) = tobj::load_obj(path, &options).map_err(|e| e.to_string())?;
    let materials = materials.unwrap_or_default();
    let mut out = Vec::new();
    for (i, model) in models.into_iter().enumerate() {
        let m = model.mesh;
        let positions: Vec<[f32; 3]> = m.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        let indices: Vec<[u32; 3]> = m.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        let material = m.material_id.and_then(|id| materials.get(id));
        let colors = if m.vertex_color.len() == m.positions.len() && !m.vertex_color.is_empty() {
            m.vertex_color
                .chunks_exact(3)
                .map(|c| [srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2]), DEFAULT_ALPHA])
                .collect()
        } else {
            let rgb = material.and_then(|mt| mt.diffuse).map(|d| d.map(srgb_to_linear)).unwrap_or(DEFAULT_RGB);
            let a = material.and_then(|mt| mt.dissolve).filter(|&d| d < 1.0).unwrap_or(DEFAULT_ALPHA);
            vec![[rgb[0], rgb[1], rgb[2], a.clamp(0.0, 1.0)]]
        };
        let name = if model.name.is_empty() { format!("object {i}") } else { model.name };
        if !indices.is_empty() {
            out.push(named(name, positions, indices, colors)?);
        }
    }
    Ok(out)
}

fn ply(path: &Path, name: &str) -> Result<NamedMesh, String> {
    use ply_rs_bw::ply::Property as P;
    let mut file = std::io::BufReader::new(std::fs::File::open(path).map_err(|e| e.to_string())?);
    let parser = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
    let ply = parser.read_ply(&mut file).map_err(|e| e.to_string())?;
    let scalar = |p: Option<&P>| -> Option<f64> {
        Some(match p? {
            P::Char(v) => *v as f64,
            P::UChar(v) => *v as f64,
            P::Short(v) => *v as f64,
            P::UShort(v) => *v as f64,
            P::Int(v) => *v as f64,
            P::UInt(v) => *v as f64,
            P::Float(v) => *v as f64,
            P::Double(v) => *v,
            _ => return None,
        })
    };
    let vertices = ply.payload.get("vertex").ok_or("no 'vertex' element")?;
    let mut positions = Vec::with_capacity(vertices.len());
    let mut colors = Vec::with_capacity(vertices.len());
    for v in vertices {
        let xyz = ["x", "y", "z"].map(|k| scalar(v.get(k)));
        let [Some(x), Some(y), Some(z)] = xyz else { return Err("vertices need x, y and z".into()) };
        positions.push([x as f32, y as f32, z as f32]);
        // 8-bit colors are sRGB; float colors are taken as linear.
        let unit = |k: &str| match v.get(k) {
            Some(P::UChar(c)) => Some(*c as f32 / 255.0),
            p => scalar(p).map(|c| c as f32),
        };
        let rgb = ["red", "green", "blue"].map(unit);
        let c = match rgb {
            [Some(r), Some(g), Some(b)] if matches!(v.get("red"), Some(P::UChar(_))) => [r, g, b].map(srgb_to_linear),
            [Some(r), Some(g), Some(b)] => [r, g, b],
            _ => DEFAULT_RGB,
        };
        let a = unit("alpha").unwrap_or(DEFAULT_ALPHA);
        colors.push([c[0], c[1], c[2], a].map(|x| x.clamp(0.0, 1.0)));
    }
    let faces = ply.payload.get("face").map(Vec::as_slice).unwrap_or_default();
    let mut indices = Vec::with_capacity(faces.len());
    for f in faces {
        let list: Vec<i64> = match f.get("vertex_indices").or_else(|| f.get("vertex_index")) {
            Some(P::ListInt(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(P::ListUInt(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(P::ListShort(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(P::ListUShort(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(P::ListChar(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(P::ListUChar(l)) => l.iter().map(|&i| i as i64).collect(),
            _ => return Err("faces need a 'vertex_indices' list".into()),
        };
        if list.iter().any(|&i| i < 0 || i as usize >= positions.len()) {
            return Err(format!("a face refers to a vertex outside [0, {})", positions.len()));
        }
        // A fan triangulates convex polygons.
        for k in 1..list.len().saturating_sub(1) {
            indices.push([list[0] as u32, list[k] as u32, list[k + 1] as u32]);
        }
    }
    named(name.to_string(), positions, indices, colors)
}

fn stl(path: &Path, name: &str) -> Result<NamedMesh, String> {
    let mut file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mesh = stl_io::read_stl(&mut file).map_err(|e| e.to_string())?;
    let positions = mesh.vertices.iter().map(|v| v.0).collect();
    let indices = mesh.faces.iter().map(|f| f.vertices.map(|i| i as u32)).collect();
    let [r, g, b] = DEFAULT_RGB;
    named(name.to_string(), positions, indices, vec![[r, g, b, DEFAULT_ALPHA]])
}

/// Buffers of a glTF: the GLB blob, files beside it, or base64 data URIs.
fn gltf_buffers(doc: &gltf::Gltf, path: &Path) -> Result<Vec<Vec<u8>>, String> {
    doc.buffers()
        .map(|b| match b.source() {
            gltf::buffer::Source::Bin => doc.blob.clone().ok_or_else(|| "the GLB has no binary chunk".to_string()),
            gltf::buffer::Source::Uri(uri) => match uri.strip_prefix("data:") {
                Some(rest) => rest.split_once(";base64,").map(|(_, d)| base64(d)).ok_or("only base64 data URIs are read")?,
                None => {
                    let file = path.parent().unwrap_or(Path::new(".")).join(uri);
                    std::fs::read(&file).map_err(|e| format!("buffer {}: {e}", file.display()))
                }
            },
        })
        .collect()
}

fn base64(text: &str) -> Result<Vec<u8>, String> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => Some(c - b'A'),
        b'a'..=b'z' => Some(c - b'a' + 26),
        b'0'..=b'9' => Some(c - b'0' + 52),
        b'+' | b'-' => Some(62),
        b'/' | b'_' => Some(63),
        _ => None,
    };
    let digits: Vec<u8> = text
        .bytes()
        .filter(|&c| c != b'=' && !c.is_ascii_whitespace())
        .map(value)
        .collect::<Option<_>>()
        .ok_or("a data URI is not valid base64")?;
    let mut out = Vec::with_capacity(digits.len() * 3 / 4);
    for chunk in digits.chunks(4) {
        let n = chunk.iter().enumerate().fold(0u32, |n, (i, &d)| n | (d as u32) << (18 - 6 * i));
        out.extend(&n.to_be_bytes()[1..chunk.len()]);
    }
    Ok(out)
}

/// Every triangle primitive of the default scene (or all scenes), placed by its node's
/// transform. Colors: COLOR_0 times the base color factor; both are linear in glTF.
fn gltf_meshes(path: &Path) -> Result<Vec<NamedMesh>, String> {
    let doc = gltf::Gltf::open(path).map_err(|e| e.to_string())?;
    let buffers = gltf_buffers(&doc, path)?;
    let mut out = Vec::new();
    let mut stack: Vec<(gltf::Node, DMat4)> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().map(|n| (n, DMat4::IDENTITY)).collect(),
        None => doc.nodes().map(|n| (n, DMat4::IDENTITY)).collect(),
    };
    while let Some((node, parent)) = stack.pop() {
        let m = node.transform().matrix();
        let world = parent * DMat4::from_cols_array_2d(&m.map(|c| c.map(|x| x as f64)));
        stack.extend(node.children().map(|c| (c, world)));
        let Some(mesh) = node.mesh() else { continue };
        for (p, prim) in mesh.primitives().enumerate() {
            if prim.mode() != gltf::mesh::Mode::Triangles {
                continue;
            }
            let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let Some(pos) = reader.read_positions() else { continue };
            let positions: Vec<[f32; 3]> =
                pos.map(|v| world.transform_point3(DVec3::from_array(v.map(|x| x as f64))).as_vec3().to_array()).collect();
            let flat: Vec<u32> = match reader.read_indices() {
                Some(ix) => ix.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            };
            let indices = flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
            let material = prim.material();
            let factor = material.pbr_metallic_roughness().base_color_factor();
            let blend = material.alpha_mode() == gltf::material::AlphaMode::Blend;
            let colors: Vec<[f32; 4]> = match reader.read_colors(0) {
                Some(c) => c.into_rgba_f32().map(|c| std::array::from_fn(|i| c[i] * factor[i])).collect(),
                None => vec![factor],
            };
            let colors = colors
                .into_iter()
                .map(|c| [c[0], c[1], c[2], if blend { c[3] } else { DEFAULT_ALPHA }].map(|x| x.clamp(0.0, 1.0)))
                .collect();
            let name = format!("{}{}", mesh.name().or(node.name()).unwrap_or("mesh"), if p > 0 { format!(" #{p}") } else { String::new() });
            out.push(named(name, positions, indices, colors)?);
        }
    }
    Ok(out)
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
    fn obj_with_a_quad_and_alpha_override() {
        let p = tmp("quad.obj", b"o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
        let s = load(&p, Some(0.25)).unwrap();
        assert_eq!(s.meshes.len(), 1);
        assert_eq!(s.meshes[0].mesh.indices.len(), 2);
        assert!(s.meshes[0].mesh.colors.iter().all(|c| c[3] == 0.25));
        assert_eq!(load(&p, None).unwrap().meshes[0].mesh.colors[0], [0.8, 0.8, 0.8, DEFAULT_ALPHA]);
    }

    #[test]
    fn ply_ascii_with_colors() {
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                    property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n\
                    element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                    0 0 0 255 0 0 128\n1 0 0 255 0 0 128\n0 1 0 255 0 0 128\n3 0 1 2\n";
        let s = load(&tmp("tri.ply", text.as_bytes()), None).unwrap();
        let c = s.meshes[0].mesh.colors[0];
        assert_eq!(c[..3], [1.0, 0.0, 0.0]);
        assert!((c[3] - 128.0 / 255.0).abs() < 1e-6);
    }

    #[test]
    fn stl_binary() {
        let mut data = vec![0u8; 80];
        data.extend(1u32.to_le_bytes());
        for v in [[0.0f32, 0.0, 1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            v.iter().for_each(|x| data.extend(x.to_le_bytes()));
        }
        data.extend([0, 0]);
        let s = load(&tmp("tri.stl", &data), None).unwrap();
        assert_eq!(s.meshes[0].mesh.indices.len(), 1);
    }

    #[test]
    fn gltf_with_a_data_uri_and_a_node_transform() {
        let mut bin = Vec::new();
        [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].iter().flatten().for_each(|x| bin.extend(x.to_le_bytes()));
        let b64 = {
            const T: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
            bin.chunks(3)
                .flat_map(|c| {
                    let n = c.iter().enumerate().fold(0u32, |n, (i, &b)| n | (b as u32) << (16 - 8 * i));
                    (0..4).map(move |i| if i <= c.len() { T[(n >> (18 - 6 * i) & 63) as usize] as char } else { '=' })
                })
                .collect::<String>()
        };
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
            "nodes":[{{"mesh":0,"translation":[0,0,2]}}],
            "meshes":[{{"name":"tri","primitives":[{{"attributes":{{"POSITION":0}},"material":0}}]}}],
            "materials":[{{"alphaMode":"BLEND","pbrMetallicRoughness":{{"baseColorFactor":[1,0.5,0,0.3]}}}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}}],
            "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{b64}"}}]}}"#
        );
        let s = load(&tmp("tri.gltf", json.as_bytes()), None).unwrap();
        let m = &s.meshes[0].mesh;
        assert_eq!(m.positions[1], [1.0, 0.0, 2.0]);
        assert_eq!(m.colors[0], [1.0, 0.5, 0.0, 0.3]);
    }

    #[test]
    fn unknown_extension_names_the_formats() {
        let e = load(&tmp("x.fbx", b""), None).unwrap_err();
        assert!(e.contains(".oitscene, .obj, .ply, .stl, .gltf and .glb"), "{e}");
    }
}
