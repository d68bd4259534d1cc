//! The fuzz run: broken versions of a small document (fixed seed, a few seconds), as GLB and as
//! .gltf text; the loader never panics.

use std::path::Path;
use std::time::{Duration, Instant};

use serde_json::{json, Value};

use super::doc::{base64, dir, glb, push, Doc};
use super::TRI;
use crate::load::gltf::from_bytes;

/// A small GLB using most of what the loader reads, for the fuzz run.
fn fuzz_seed() -> Doc {
    let mut d = Doc::new();
    let tex = d.texture(2, 2, [10, 200, 30, 128], Some(json!({"wrapS": 33071})));
    let uv = d.floats("VEC2", &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    let col = d.floats("VEC4", &[1.0; 12]);
    let ix = d.indices(&[0, 1, 2]);
    let mat = d.material(json!({"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": tex,
        "extensions": {"KHR_texture_transform": {"scale": [2, 2]}}}}, "emissiveFactor": [1, 0, 0]}));
    let m = d.mesh(&TRI, json!({"material": mat, "indices": ix, "attributes": {"TEXCOORD_0": uv, "COLOR_0": col}}));
    let lines = d.mesh(&TRI, json!({"mode": 2}));
    let t = d.floats("VEC3", &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
    let sx = d.view(&[1]);
    let sv = d.view(bytemuck::cast_slice(&[5.0f32, 5.0, 5.0]));
    d.json["accessors"][t]["sparse"] =
        json!({"count": 1, "indices": {"bufferView": sx, "componentType": 5121}, "values": {"bufferView": sv}});
    let child = push(&mut d.json["nodes"], json!({"mesh": lines, "rotation": [0, 0, 0.6, 0.8]}));
    d.node(json!({"mesh": m, "children": [child], "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": t}}}}));
    d.json["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]);
    d.node(json!({"camera": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1]}));
    d.json["animations"] = json!([{}]);
    d.json["extensionsUsed"] = json!(["EXT_mesh_gpu_instancing", "KHR_texture_transform"]);
    d
}

/// A fixed-seed xorshift generator.
struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// A random place in the JSON tree: an object and one of its keys, or an array and an index.
fn mutate_json(v: &mut Value, rng: &mut XorShift) {
    let odd = [
        json!(null),
        json!(-1),
        json!(1.5),
        json!(4_294_967_295u64),
        json!(1e300),
        json!("x"),
        json!([]),
        json!({}),
        json!(true),
        json!([0, 0]),
    ];
    let mut at = v;
    loop {
        let stop = rng.below(4) == 0;
        match at {
            Value::Object(map) if !map.is_empty() => {
                let key = map.keys().nth(rng.below(map.len())).cloned().unwrap();
                if stop || !(map[&key].is_object() || map[&key].is_array()) {
                    match rng.below(4) {
                        0 => {
                            map.remove(&key);
                        }
                        1 if key == "count" || key == "byteLength" || key == "byteOffset" => {
                            map[&key] = json!(1u64 << (20 + rng.below(40)))
                        }
                        _ => map[&key] = odd[rng.below(odd.len())].clone(),
                    }
                    return;
                }
                at = map.get_mut(&key).unwrap();
            }
            Value::Array(a) if !a.is_empty() => {
                let i = rng.below(a.len());
                if stop || !(a[i].is_object() || a[i].is_array()) {
                    a[i] = odd[rng.below(odd.len())].clone();
                    return;
                }
                at = &mut a[i];
            }
            _ => return,
        }
    }
}

/// The document as .gltf text, its buffer a data URI.
fn gltf_text(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json = json.clone();
    if let Some(b) = json.pointer_mut("/buffers/0").and_then(Value::as_object_mut) {
        b.insert("uri".into(), json!(format!("data:application/octet-stream;base64,{}", base64(bin))));
    }
    serde_json::to_vec(&json).unwrap()
}

/// One broken version of `seed`, as GLB or as .gltf text, and how it was broken.
fn fuzz_case(seed: &Doc, rng: &mut XorShift) -> (Vec<u8>, &'static str) {
    let pack = if rng.below(2) == 0 { glb } else { gltf_text };
    let base = pack(&seed.json, &seed.bin);
    match rng.below(6) {
        0 => (base[..rng.below(base.len())].to_vec(), "truncated"),
        1 => {
            let mut b = base;
            for _ in 0..1 + rng.below(8) {
                let i = rng.below(b.len());
                b[i] ^= 1 << rng.below(8);
            }
            (b, "bit flips")
        }
        2 => {
            let mut b = base;
            let i = rng.below(b.len());
            b[i] = rng.next() as u8;
            (b, "byte replaced")
        }
        3 | 4 => {
            let mut json = seed.json.clone();
            for _ in 0..1 + rng.below(3) {
                mutate_json(&mut json, rng);
            }
            (pack(&json, &seed.bin), "JSON mutated")
        }
        _ => {
            let mut json = seed.json.clone();
            let n = json["nodes"].as_array().unwrap().len();
            let (a, b) = (rng.below(n), rng.below(n));
            json["nodes"][a]["children"] = json!([b]);
            (pack(&json, &seed.bin), "nodes relinked")
        }
    }
}

#[test]
fn fuzzed_files_never_panic() {
    let seed = fuzz_seed();
    from_bytes(&seed.glb(), &dir(), None).expect("the seed loads");
    from_bytes(&gltf_text(&seed.json, &seed.bin), &dir(), None).expect("the seed loads as .gltf");
    let mut rng = XorShift(0x5eed_0172);
    let start = Instant::now();
    let (mut cases, mut loaded) = (0, 0);
    let mut slowest = Duration::ZERO;
    while start.elapsed() < Duration::from_secs(3) && cases < 30_000 {
        let (bytes, how) = fuzz_case(&seed, &mut rng);
        let t = Instant::now();
        let result = std::panic::catch_unwind(|| from_bytes(&bytes, Path::new("/nonexistent"), None));
        slowest = slowest.max(t.elapsed());
        let Ok(result) = result else { panic!("case {cases} ({how}) panicked; its bytes: {}", base64(&bytes)) };
        loaded += result.is_ok() as usize;
        cases += 1;
    }
    eprintln!("{cases} fuzzed files, {loaded} loaded, the slowest in {slowest:?}");
    assert!(cases > 100, "only {cases} cases ran");
    // The mutations reach past the container: some files still load, most are refused.
    assert!(loaded > cases / 50 && loaded < cases / 2, "{loaded} of {cases} loaded");
    assert!(slowest < Duration::from_secs(1), "a case took {slowest:?}");
}
