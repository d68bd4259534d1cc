//! The glTF loader on documents written here (doc.rs), one feature a test, and a fuzz run
//! (fuzz.rs) that feeds it broken versions of them and asserts it never panics.

mod doc;
mod fuzz;

use std::sync::Arc;

use serde_json::json;

use super::*;
use crate::load::{load_file, Surface};
use crate::shading::{Falloff, Filter, Wrap};
use doc::{base64, dir, png, push, Doc};

const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// The z of each triangle's normal (counter-clockwise seen from +z: positive).
fn facing(m: &crate::scene::Mesh) -> Vec<f32> {
    m.indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| glam::Vec3::from(m.positions[i as usize]));
            (b - a).cross(c - a).z
        })
        .collect()
}

#[test]
fn strips_keep_their_winding_and_fans_turn_about_the_first_vertex() {
    let mut d = Doc::new();
    // A strip of three triangles up y, every one counter-clockwise seen from +z.
    let strip: [[f32; 3]; 5] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 2.0, 0.0]];
    let s = d.mesh(&strip, json!({"mode": 5}));
    d.node(json!({"mesh": s}));
    let fan: [[f32; 3]; 5] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 1.0, 0.0]];
    let f = d.mesh(&fan, json!({"mode": 6}));
    d.node(json!({"mesh": f}));
    let file = d.load().unwrap();
    let (s, f) = (&file.meshes[0].mesh, &file.meshes[1].mesh);
    assert_eq!(s.indices, [[0, 1, 2], [1, 3, 2], [2, 3, 4]]);
    assert_eq!(f.indices, [[1, 2, 0], [2, 3, 0], [3, 4, 0]]);
    assert!(facing(s).iter().chain(&facing(f)).all(|&z| z > 0.0));
    // Repeated vertices (a strip's restart) make no triangle.
    let mut d = Doc::new();
    let ix = d.indices(&[0, 1, 2, 2, 3, 3, 4]);
    let s = d.mesh(&strip, json!({"mode": 5, "indices": ix}));
    d.node(json!({"mesh": s}));
    assert_eq!(d.load().unwrap().meshes[0].mesh.indices.len(), 1);
}

#[test]
fn lines_are_strands_and_points_particles_sized_by_the_scene() {
    let mut d = Doc::new();
    let square: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [3.0, 4.0, 0.0], [0.0, 4.0, 0.0]];
    // LINES 0-1, 1-2 chain into one polyline; 3-0 starts another.
    let ix = d.indices(&[0, 1, 1, 2, 3, 0]);
    let lines = d.mesh(&square, json!({"mode": 1, "indices": ix}));
    let lines_loop = d.mesh(&square, json!({"mode": 2}));
    let strip = d.mesh(&square, json!({"mode": 3}));
    let points = d.mesh(&square, json!({"mode": 0}));
    for m in [lines, lines_loop, strip, points] {
        d.node(json!({"mesh": m}));
    }
    let file = d.load().unwrap();
    let strands = |k: usize| match &file.meshes[k].mesh.primitive {
        Primitive::Strands { counts, widths } => (counts.clone(), widths[0]),
        p => panic!("{p:?}"),
    };
    // The scene's box is 3 x 4: its diagonal 5.
    assert_eq!(strands(0).0, [3, 2]);
    assert!((strands(0).1 - 5.0 / 500.0).abs() < 1e-7);
    assert_eq!(strands(1).0, [5]);
    assert_eq!(file.meshes[1].mesh.positions[4], square[0], "a loop comes back to its first point");
    assert_eq!(strands(2).0, [4]);
    let Primitive::Particles { radii } = &file.meshes[3].mesh.primitive else { panic!() };
    assert!(radii.len() == 4 && (radii[0] - 5.0 / 200.0).abs() < 1e-7);
    assert_eq!(file.meshes[3].mesh.material.falloff, Falloff::Hard);
    let sized = from_bytes(&d.glb(), &dir(), Some(0.5)).unwrap();
    assert!(matches!(&sized.meshes[3].mesh.primitive, Primitive::Particles { radii } if radii[0] == 0.5));
    // An odd count of LINES (a validator warning, not an error): the last vertex is not drawn,
    // and the warning names the accessor and the rule.
    let mut d = Doc::new();
    let m = d.mesh(&TRI, json!({"mode": 1}));
    d.node(json!({"mesh": m}));
    let file = d.load().unwrap();
    assert!(matches!(&file.meshes[0].mesh.primitive, Primitive::Strands { .. }) && file.meshes[0].mesh.positions.len() == 2);
    assert!(file.warnings.iter().any(|w| w.contains("accessors[0]: count 3 is not a multiple of 2 for LINES")), "{:?}", file.warnings);
}

#[test]
fn gpu_instancing_places_each_instance_under_the_node() {
    let mut d = Doc::new();
    let m = d.mesh(&TRI, json!({}));
    let t = d.floats("VEC3", &[0.0, 0.0, 0.0, 10.0, 0.0, 0.0, 20.0, 0.0, 0.0]);
    let s = d.floats("VEC3", &[1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 1.0, 1.0, 1.0]);
    d.json["extensionsUsed"] = json!(["EXT_mesh_gpu_instancing"]);
    d.node(json!({"mesh": m, "translation": [0, 0, 5],
                  "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": t, "SCALE": s, "_ID": 0}}}}));
    let file = d.load().unwrap();
    assert!(file.warnings.is_empty(), "{:?}", file.warnings);
    let at: Vec<[f64; 3]> = file.meshes[0].instances.iter().map(|i| i.apply([1.0, 0.0, 0.0]).to_array()).collect();
    assert_eq!(at, [[1.0, 0.0, 5.0], [12.0, 0.0, 5.0], [21.0, 0.0, 5.0]]);
    // Attributes of different lengths are refused.
    let short = d.floats("VEC3", &[1.0, 1.0, 1.0]);
    d.json["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] = json!(short);
    assert!(d.error().contains("has 1 instances but"), "{}", d.error());
}

#[test]
fn texture_transform_sampler_and_shared_images() {
    let mut d = Doc::new();
    let sampler = json!({"wrapS": 33071, "wrapT": 33648, "magFilter": 9728, "minFilter": 9984});
    let tex = d.texture(2, 2, [255, 0, 0, 255], Some(sampler));
    let uv0 = d.floats("VEC2", &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    let uv1 = d.floats("VEC2", &[0.5, 0.5, 1.0, 0.5, 0.5, 1.0]);
    let transform = json!({"offset": [0.5, 0.25], "rotation": std::f64::consts::FRAC_PI_2, "scale": [2.0, 3.0], "texCoord": 1});
    let a = d.material(
        json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": tex, "extensions": {"KHR_texture_transform": transform}}}}),
    );
    let b = d.material(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": tex}}}));
    let ma = d.mesh(&TRI, json!({"material": a, "attributes": {"TEXCOORD_0": uv0, "TEXCOORD_1": uv1}}));
    let mb = d.mesh(&TRI, json!({"material": b, "attributes": {"TEXCOORD_0": uv0}}));
    d.node(json!({"mesh": ma}));
    d.node(json!({"mesh": mb}));
    let file = d.load().unwrap();
    let (ta, tb) = (file.meshes[0].mesh.material.texture.as_ref().unwrap(), file.meshes[1].mesh.material.texture.as_ref().unwrap());
    assert!(Arc::ptr_eq(&ta.image, &tb.image), "one image, one texture");
    assert_eq!(file.meshes[0].mesh.uvs[0], [0.5, 0.5], "the transform's texCoord picks TEXCOORD_1");
    let t = ta.transform;
    let expect = [[0.0, 3.0, 0.5], [-2.0, 0.0, 0.25]];
    assert!(t.iter().flatten().zip(expect.iter().flatten()).all(|(x, y)| (x - y).abs() < 1e-6), "{t:?}");
    assert_eq!((ta.sampler.wrap_u, ta.sampler.wrap_v), (Wrap::ClampToEdge, Wrap::MirroredRepeat));
    assert_eq!((ta.sampler.mag, ta.sampler.min, ta.sampler.mipmap), (Filter::Nearest, Filter::Nearest, Some(Filter::Nearest)));
    assert_eq!(tb.sampler, ta.sampler);
    assert_eq!(tb.transform, crate::shading::UV_IDENTITY);
}

#[test]
fn emissive_factor_strength_and_texture() {
    let mut d = Doc::new();
    let tex = d.texture(1, 1, [255, 255, 255, 255], None);
    let uv = d.floats("VEC2", &[0.0; 6]);
    let m = d.material(json!({"emissiveFactor": [1.0, 0.5, 0.0], "emissiveTexture": {"index": tex},
                              "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}}));
    let mesh = d.mesh(&TRI, json!({"material": m, "attributes": {"TEXCOORD_0": uv}}));
    d.node(json!({"mesh": mesh}));
    let file = d.load().unwrap();
    let mat = &file.meshes[0].mesh.material;
    assert_eq!(mat.emissive, [4.0, 2.0, 0.0]);
    assert!(mat.emissive_texture.is_some() && mat.texture.is_none());
    assert_eq!(file.meshes[0].mesh.uvs.len(), 3);
}

#[test]
fn alpha_modes_and_colors() {
    let mut d = Doc::new();
    let colors = d.view(&[255, 0, 0, 128, 0, 255, 0, 128, 0, 0, 255, 128]);
    let c = d.accessor(json!({"bufferView": colors, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"}));
    let mask = d.material(json!({"alphaMode": "MASK", "alphaCutoff": 0.25, "doubleSided": true}));
    let opaque = d.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.5]}}));
    let blend = d.material(json!({"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1, 1, 0.5]}}));
    for m in [mask, opaque, blend] {
        let mesh = d.mesh(&TRI, json!({"material": m, "attributes": {"COLOR_0": c}}));
        d.node(json!({"mesh": mesh}));
    }
    let file = d.load().unwrap();
    let m: Vec<&crate::scene::Mesh> = file.meshes.iter().map(|m| &m.mesh).collect();
    assert_eq!(m[0].material.alpha_cutoff, Some(0.25));
    assert!(!m[0].opaque && m[0].material.two_sided && (m[0].colors[0][3] - 128.0 / 255.0).abs() < 1e-6);
    assert!(m[1].opaque && m[1].colors[0] == [1.0, 0.0, 0.0, 1.0] && m[1].material.cull_back_faces);
    assert!(!m[2].opaque && m[2].material.alpha_cutoff.is_none());
    assert!((m[2].colors[0][0] - 0.5).abs() < 1e-6 && (m[2].colors[0][3] - 64.0 / 255.0).abs() < 1e-6);
}

#[test]
fn accessors_without_a_buffer_view_are_zeros_with_sparse_values_on_top() {
    let mut d = Doc::new();
    let ix = d.view(bytemuck::cast_slice(&[1u16, 2]));
    let values = d.view(bytemuck::cast_slice(&[1.0f32, 0.0, 0.0, 0.0, 1.0, 0.0]));
    let pos = d.accessor(json!({"componentType": 5126, "count": 3, "type": "VEC3",
        "sparse": {"count": 2, "indices": {"bufferView": ix, "componentType": 5123}, "values": {"bufferView": values}}}));
    // Sparse values over a bufferView's: the second vertex moved up.
    let base = d.floats("VEC3", TRI.as_flattened());
    let up = d.view(bytemuck::cast_slice(&[1u8]));
    let moved = d.view(bytemuck::cast_slice(&[1.0f32, 0.0, 2.0]));
    d.json["accessors"][base]["sparse"] =
        json!({"count": 1, "indices": {"bufferView": up, "componentType": 5121}, "values": {"bufferView": moved}});
    let zeros = d.accessor(json!({"componentType": 5126, "count": 3, "type": "VEC3"}));
    for p in [pos, base, zeros] {
        push(&mut d.json["meshes"], json!({"primitives": [{"attributes": {"POSITION": p}}]}));
        let m = d.json["meshes"].as_array().unwrap().len() - 1;
        d.node(json!({"mesh": m}));
    }
    let file = d.load().unwrap();
    assert_eq!(file.meshes[0].mesh.positions, TRI);
    assert_eq!(file.meshes[1].mesh.positions, [[0.0, 0.0, 0.0], [1.0, 0.0, 2.0], [0.0, 1.0, 0.0]]);
    assert_eq!(file.meshes[2].mesh.positions, [[0.0; 3]; 3]);
    // A sparse index past the count is refused.
    let far = d.view(bytemuck::cast_slice(&[7u8]));
    d.json["accessors"][base]["sparse"]["indices"]["bufferView"] = json!(far);
    assert!(d.error().contains("index 7 at 0 is past the accessor's 3 elements"), "{}", d.error());
}

#[test]
fn quantized_positions_and_integers_written_as_floats() {
    let mut d = Doc::new();
    let view = d.view(bytemuck::cast_slice(&[0i16, 0, 0, 0, 32767, 0, 0, 0, 0, 32767, 0, 0]));
    d.json["bufferViews"][view]["byteStride"] = json!(8);
    let pos = d.accessor(json!({"bufferView": view, "componentType": 5122, "normalized": true, "count": 3.0, "type": "VEC3"}));
    let raw = d.view(&[0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0]);
    let ints = d.accessor(json!({"bufferView": raw, "componentType": 5121, "count": 3, "type": "VEC3", "byteOffset": 0}));
    d.json["bufferViews"][raw]["byteStride"] = json!(4);
    d.json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    d.json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    for p in [pos, ints] {
        push(&mut d.json["meshes"], json!({"primitives": [{"attributes": {"POSITION": p}, "extras": [1, 2]}], "extras": "anything"}));
        let m = d.json["meshes"].as_array().unwrap().len() - 1;
        d.node(json!({"mesh": m as f64, "extras": 3}));
    }
    let file = d.load().unwrap();
    assert_eq!(file.meshes[0].mesh.positions, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(file.meshes[1].mesh.positions, [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
}

#[test]
fn images_from_data_uris_in_a_glb_and_textures_without_source() {
    let mut d = Doc::new();
    let uri = format!("data:image/png;base64,{}", base64(&png(1, 1, [0, 0, 255, 255])));
    d.json["images"] = json!([{"uri": uri}]);
    d.json["textures"] = json!([{"source": 0}, {}]);
    let uv = d.floats("VEC2", &[0.0; 6]);
    let with = d.material(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}));
    let without = d.material(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}}));
    for m in [with, without] {
        let mesh = d.mesh(&TRI, json!({"material": m, "attributes": {"TEXCOORD_0": uv}}));
        d.node(json!({"mesh": mesh}));
    }
    let file = d.load().unwrap();
    let t = file.meshes[0].mesh.material.texture.as_ref().unwrap();
    assert_eq!((t.image.width, t.image.height, t.image.srgb), (1, 1, true));
    assert!(file.meshes[1].mesh.material.texture.is_none());
    assert_eq!(file.warnings, ["1 texture has no image oit reads ('source'): drawn untextured"]);
    // An image with no fields, used: refused naming it (the gltf crate panicked here).
    d.json["images"] = json!([{}]);
    assert!(d.error().starts_with("images[0] has neither a uri nor a bufferView"), "{}", d.error());
}

#[test]
fn images_past_the_largest_texture_are_downscaled_with_a_warning() {
    let mut d = Doc::new();
    let tex = d.texture(8200, 4, [9, 9, 9, 255], None);
    let uv = d.floats("VEC2", &[0.0; 6]);
    let m = d.material(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": tex}}}));
    let mesh = d.mesh(&TRI, json!({"material": m, "attributes": {"TEXCOORD_0": uv}}));
    d.node(json!({"mesh": mesh}));
    let file = d.load().unwrap();
    let t = &file.meshes[0].mesh.material.texture.as_ref().unwrap().image;
    assert_eq!((t.width, t.height), (8192, 4));
    assert_eq!(file.warnings, ["1 image larger than 8192 texels a side is downscaled to fit"]);
}

#[test]
fn animations_skins_and_morph_targets_are_said_once() {
    let mut d = Doc::new();
    let m = d.mesh(&TRI, json!({"targets": [{"POSITION": 0}]}));
    d.node(json!({"mesh": m}));
    // A channel with no target node, which oit never reads anyway.
    d.json["animations"] = json!([{"channels": [{"sampler": 0, "target": {"path": "translation"}}], "samplers": []}, {}]);
    d.json["skins"] = json!([{"joints": [0]}]);
    d.json["extensionsUsed"] = json!(["KHR_materials_clearcoat", "KHR_texture_transform"]);
    let file = d.load().unwrap();
    assert_eq!(
        file.warnings,
        [
            "1 extension oit does not read is ignored: KHR_materials_clearcoat",
            "2 animations are not drawn: oit shows the base pose",
            "1 skin is not applied: oit shows the meshes where their nodes place them",
            "1 primitive has morph targets: oit shows the base shape",
        ]
    );
}

#[test]
fn node_cycles_and_second_parents_are_refused_naming_the_node() {
    let mut d = Doc::new();
    let m = d.mesh(&TRI, json!({}));
    d.node(json!({"mesh": m, "children": [1]}));
    d.json["nodes"] = json!([{"mesh": m, "children": [1]}, {"children": [2]}, {"children": [1]}]);
    assert_eq!(d.error(), "nodes[1] has two parents, nodes[0] and nodes[2]: a node has at most one parent");
    d.json["nodes"] = json!([{"mesh": m}, {"children": [2]}, {"children": [1]}]);
    d.json["scenes"] = json!([{"nodes": [0]}]);
    assert_eq!(d.error(), "nodes[1] is its own ancestor: the nodes' children form a cycle");
    d.json["nodes"] = json!([{"mesh": m, "children": [0]}]);
    assert_eq!(d.error(), "nodes[0] is its own child: a node tree has no cycles");
    d.json["nodes"] = json!([{"mesh": m, "children": [1]}, {"mesh": m}]);
    d.json["scenes"] = json!([{"nodes": [0, 1]}]);
    assert!(d.error().contains("scenes[0].nodes lists nodes[1], a child of nodes[0]"), "{}", d.error());
}

#[test]
fn a_missing_bin_is_not_found_naming_it() {
    let dir = dir();
    let json = r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"gone%20away.bin","byteLength":36}]}"#;
    let path = dir.join("lonely.gltf");
    std::fs::write(&path, json).unwrap();
    let e = load_with(&path, None).unwrap_err();
    let LoadError::NotFound(msg) = &e else { panic!("{e:?}") };
    assert!(msg.starts_with("buffers[0] refers to 'gone away.bin', which is not there"), "{msg}");
    let e = load_file(&path, Surface::default()).unwrap_err();
    assert!(matches!(e, crate::OitError::NotFound(_)) && e.to_string().contains("lonely.gltf"), "{e}");
}

#[test]
fn rules_the_specification_states_are_named() {
    let mut d = Doc::new();
    let pos = d.floats("VEC3", &[0.0; 15]);
    push(&mut d.json["meshes"], json!({"primitives": [{"attributes": {"POSITION": pos}}]}));
    d.node(json!({"mesh": 0}));
    // A count TRIANGLES does not use whole is a validator warning: the leftover is not drawn.
    let file = d.load().unwrap();
    assert_eq!(file.meshes[0].mesh.indices.len(), 1);
    assert!(file.warnings.iter().any(|w| w.contains("accessors[0]: count 5 is not a multiple of 3 for TRIANGLES")), "{:?}", file.warnings);
    d.json["accessors"][0]["count"] = json!(4_000_000_000u64);
    assert!(d.error().starts_with("accessors[0]: count 4000000000 of 12-byte elements"), "{}", d.error());
    d.json["accessors"][0]["count"] = json!(3);
    let ix = d.indices(&[0, 1, 9]);
    d.json["meshes"][0]["primitives"][0]["indices"] = json!(ix);
    assert_eq!(d.error(), "accessors[1]: index 9 at 2 is past POSITION's 3 vertices");
    d.json["meshes"][0]["primitives"][0]["indices"] = json!(7);
    assert_eq!(d.error(), "meshes[0].primitives[0].indices: accessors[7] does not exist (the file has 2 accessors)");
    d.json["meshes"][0]["primitives"][0].as_object_mut().unwrap().remove("indices");
    d.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression", "KHR_texture_transform"]);
    assert!(d.error().starts_with("extensionsRequired lists KHR_draco_mesh_compression, which oit does not read"), "{}", d.error());
    d.json.as_object_mut().unwrap().remove("extensionsRequired");
    d.json["accessors"][0]["componentType"] = json!("float");
    assert_eq!(d.error(), "accessors[0].componentType: expected a non-negative integer, got a string (\"float\")");
    d.json["asset"]["version"] = json!("1.0");
    assert_eq!(d.error(), "asset.version is '1.0': oit reads glTF 2.0");
    let e = from_bytes(b"glTF\x02\0\0\0garbage", &dir(), None).unwrap_err();
    assert!(matches!(&e, LoadError::Invalid(m) if m.starts_with("not a readable glTF file")), "{e:?}");
}

#[test]
fn a_small_file_cannot_ask_for_gigabytes() {
    // 10 000 instances of a mesh of 20 000 primitives: 2e8 placements from 150 KB.
    let mut d = Doc::new();
    let m = d.mesh(&TRI, json!({}));
    let prim = d.json["meshes"][m]["primitives"][0].clone();
    d.json["meshes"][m]["primitives"] = Value::Array(vec![prim; 20_000]);
    let t = d.floats("VEC3", &vec![0.0; 30_000]);
    d.node(json!({"mesh": m, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": t}}}}));
    assert!(d.error().starts_with("nodes[0] would take the decoded data past"), "{}", d.error());
}

#[test]
fn gltf_with_data_uri_buffer_through_load_file() {
    let mut d = Doc::new();
    let m = d.mesh(&TRI, json!({}));
    d.node(json!({"mesh": m, "name": "tri"}));
    d.json["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{}", base64(&d.bin)));
    let path = dir().join("uri.gltf");
    std::fs::write(&path, serde_json::to_vec(&d.json).unwrap()).unwrap();
    let file = load_file(&path, Surface::default()).unwrap();
    assert_eq!(file.meshes[0].name, "tri");
    assert_eq!(file.meshes[0].mesh.normals.len(), 3, "smooth shading computed the normals");
}
