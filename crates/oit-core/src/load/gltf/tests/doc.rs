//! A glTF document grown call by call, as the tests write them, and its packings (GLB, PNG
//! images, base64 data URIs).

use std::path::PathBuf;

use serde_json::{json, Value};

use crate::load::gltf::from_bytes;
use crate::load::{LoadError, LoadedFile};

/// A glTF document grown call by call, with one binary buffer.
pub(super) struct Doc {
    pub json: Value,
    pub bin: Vec<u8>,
}

pub(super) fn push(array: &mut Value, item: Value) -> usize {
    let a = array.as_array_mut().unwrap();
    a.push(item);
    a.len() - 1
}

impl Doc {
    pub fn new() -> Self {
        let json = json!({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                          "materials": [], "accessors": [], "bufferViews": [], "buffers": [{"byteLength": 0}]});
        Self { json, bin: Vec::new() }
    }

    pub fn view(&mut self, data: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": data.len()});
        self.bin.extend_from_slice(data);
        self.json["buffers"][0]["byteLength"] = json!(self.bin.len());
        push(&mut self.json["bufferViews"], v)
    }

    pub fn accessor(&mut self, a: Value) -> usize {
        push(&mut self.json["accessors"], a)
    }

    pub fn floats(&mut self, kind: &str, data: &[f32]) -> usize {
        let comps = match kind {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            _ => 4,
        };
        let view = self.view(bytemuck::cast_slice(data));
        self.accessor(json!({"bufferView": view, "componentType": 5126, "count": data.len() / comps, "type": kind}))
    }

    pub fn indices(&mut self, data: &[u32]) -> usize {
        let view = self.view(bytemuck::cast_slice(data));
        self.accessor(json!({"bufferView": view, "componentType": 5125, "count": data.len(), "type": "SCALAR"}))
    }

    /// A mesh of one primitive with POSITION `positions` (and `extra` merged into it).
    pub fn mesh(&mut self, positions: &[[f32; 3]], extra: Value) -> usize {
        let pos = self.floats("VEC3", positions.as_flattened());
        let mut prim = json!({"attributes": {"POSITION": pos}});
        if let Value::Object(e) = extra {
            for (k, v) in e {
                if k == "attributes" {
                    for (a, i) in v.as_object().unwrap() {
                        prim["attributes"][a] = i.clone();
                    }
                } else {
                    prim[k] = v;
                }
            }
        }
        push(&mut self.json["meshes"], json!({"primitives": [prim]}))
    }

    pub fn node(&mut self, n: Value) -> usize {
        let i = push(&mut self.json["nodes"], n);
        push(&mut self.json["scenes"][0]["nodes"], json!(i));
        i
    }

    pub fn material(&mut self, m: Value) -> usize {
        push(&mut self.json["materials"], m)
    }

    /// A PNG of `w` x `h` texels of one color, as an image in a bufferView and its texture.
    pub fn texture(&mut self, w: u32, h: u32, rgba: [u8; 4], sampler: Option<Value>) -> usize {
        let view = self.view(&png(w, h, rgba));
        let image = push(
            self.json.as_object_mut().unwrap().entry("images").or_insert(json!([])),
            json!({"bufferView": view, "mimeType": "image/png"}),
        );
        let mut t = json!({"source": image});
        if let Some(s) = sampler {
            t["sampler"] = json!(push(self.json.as_object_mut().unwrap().entry("samplers").or_insert(json!([])), s));
        }
        push(self.json.as_object_mut().unwrap().entry("textures").or_insert(json!([])), t)
    }

    pub fn glb(&self) -> Vec<u8> {
        glb(&self.json, &self.bin)
    }

    pub fn load(&self) -> Result<LoadedFile, LoadError> {
        from_bytes(&self.glb(), &dir(), None)
    }

    pub fn error(&self) -> String {
        match self.load() {
            Err(LoadError::Invalid(e)) => e,
            other => panic!("expected a refusal, got {other:?}"),
        }
    }
}

pub(super) fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut text = serde_json::to_vec(json).unwrap();
    text.resize(text.len().next_multiple_of(4), b' ');
    let mut blob = bin.to_vec();
    blob.resize(blob.len().next_multiple_of(4), 0);
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + text.len() + 8 + blob.len()) as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&text);
    out.extend((blob.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(&blob);
    out
}

pub(super) fn png(w: u32, h: u32, rgba: [u8; 4]) -> Vec<u8> {
    let image = image::RgbaImage::from_pixel(w, h, image::Rgba(rgba));
    let mut out = std::io::Cursor::new(Vec::new());
    image.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

pub(super) fn base64(data: &[u8]) -> String {
    const T: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    data.chunks(3)
        .flat_map(|c| {
            let n = c.iter().enumerate().fold(0u32, |n, (i, &b)| n | (b as u32) << (16 - 8 * i));
            (0..4).map(move |i| if i <= c.len() { T[(n >> (18 - 6 * i) & 63) as usize] as char } else { '=' })
        })
        .collect()
}

pub(super) fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("oit-core-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}
