//! The bytes behind a glTF document: the GLB container, buffers (the GLB's binary chunk, files
//! next to the document, data URIs), bufferViews and accessors of every component type, with
//! `normalized`, `byteStride`, accessors without a bufferView (zeros) and sparse accessors.
//! Every offset, stride and count is checked against the bytes it reads before anything is
//! allocated, so a count the file cannot hold is refused, never allocated.

use std::borrow::Cow;
use std::cell::Cell;
use std::path::Path;

use super::json::Obj;
use crate::load::LoadError;

/// The most elements an accessor without a bufferView may have: its zeros take no bytes in
/// the file, so this bounds what a file of a few bytes can make the loader allocate.
pub(super) const MAX_ZEROS: u64 = 1 << 24;

/// A GLB's JSON and binary chunks, or a .gltf's JSON.
pub(super) struct Container<'a> {
    pub json: &'a [u8],
    pub bin: Option<&'a [u8]>,
}

const JSON_CHUNK: u32 = 0x4E4F_534A;
const BIN_CHUNK: u32 = 0x004E_4942;

fn word(bytes: &[u8], at: usize) -> Option<u32> {
    bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Splits a GLB (by its magic, whatever the extension) into its chunks; anything else is JSON.
pub(super) fn container(bytes: &[u8]) -> Result<Container<'_>, String> {
    let bad = |why: String| format!("not a readable glTF file: {why}");
    if !bytes.starts_with(b"glTF") {
        let json = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        return Ok(Container { json, bin: None });
    }
    let (Some(version), Some(length)) = (word(bytes, 4), word(bytes, 8)) else {
        return Err(bad(format!("the GLB header needs 12 bytes, the file has {}", bytes.len())));
    };
    if version != 2 {
        return Err(bad(format!("GLB version {version}: oit reads glTF 2.0")));
    }
    if length as usize > bytes.len() {
        return Err(bad(format!("its GLB header says {length} bytes but the file has {}", bytes.len())));
    }
    let bytes = &bytes[..length as usize];
    let (mut json, mut bin) = (None, None);
    let mut at = 12;
    let mut k = 0;
    while at < bytes.len() {
        let (Some(len), Some(kind)) = (word(bytes, at), word(bytes, at + 4)) else {
            return Err(bad(format!("GLB chunk {k} has a cut header at byte {at}")));
        };
        let start = at + 8;
        let Some(data) = bytes.get(start..start.saturating_add(len as usize)) else {
            return Err(bad(format!("GLB chunk {k} says {len} bytes but {} remain", bytes.len() - start)));
        };
        match (k, kind) {
            // Some exporters pad the JSON with zeros rather than spaces.
            (0, JSON_CHUNK) => json = Some(&data[..data.len() - data.iter().rev().take_while(|&&b| b == 0).count()]),
            (0, _) => return Err(bad(format!("the first GLB chunk is of type {kind:#010x}, not JSON"))),
            (_, BIN_CHUNK) if bin.is_none() => bin = Some(data),
            _ => {} // Chunks of other types are skipped, as the specification asks.
        }
        at = start + len as usize;
        k += 1;
    }
    let json = json.ok_or_else(|| bad("the GLB has no JSON chunk".to_string()))?;
    Ok(Container { json, bin })
}

/// Standard or URL-safe base64, padding optional, whitespace skipped.
fn base64(text: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    let (mut acc, mut bits) = (0u32, 0);
    for c in text.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            b' ' | b'\n' | b'\r' | b'\t' => continue,
            _ => return None,
        };
        acc = acc << 6 | v as u32;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// `%XX` escapes decoded (a URI's file name); None where one is broken.
fn percent_decode(text: &str) -> Option<Vec<u8>> {
    let b = text.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = std::str::from_utf8(b.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    Some(out)
}

/// The bytes a URI names: a data URI's payload, or a file relative to the document's folder.
/// `what` is the object that refers to it (`buffers[0]`, `images[2]`).
pub(super) fn uri_bytes(uri: &str, dir: &Path, what: &str) -> Result<Vec<u8>, LoadError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((head, payload)) = rest.split_once(',') else {
            return Err(format!("{what}: the data URI has no ',' before its data").into());
        };
        let data = if head.ends_with(";base64") { base64(payload) } else { percent_decode(payload) };
        return data.ok_or_else(|| format!("{what}: the data URI's data is not valid base64").into());
    }
    if uri.contains("://") {
        return Err(format!("{what}: uri '{uri}' is not a file next to the document or a data: URI (oit reads no network)").into());
    }
    let name =
        percent_decode(uri).and_then(|b| String::from_utf8(b).ok()).ok_or_else(|| format!("{what}: uri '{uri}' has a broken %-escape"))?;
    let file = dir.join(&name);
    if file.exists() && !file.is_file() {
        return Err(format!("{what}: uri '{uri}' is not a file ({})", file.display()).into());
    }
    std::fs::read(&file).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => LoadError::NotFound(format!("{what} refers to '{name}', which is not there ({})", file.display())),
        _ => LoadError::Invalid(format!("{what}: cannot read '{}' ({e})", file.display())),
    })
}

/// Each buffer's bytes, cut to its byteLength. A buffer with no data (no uri and not the GLB's
/// binary chunk; the specification leaves its bytes undefined) reads as zeros up to
/// ZERO_BUFFER_BYTES (the loader says so); past that it is None, refused when something reads it.
/// The most bytes a buffer without data is read as zeros for.
const ZERO_BUFFER_BYTES: u64 = 1 << 24;

pub(super) fn buffers<'a>(list: &[Obj<'_>], bin: Option<&'a [u8]>, dir: &Path) -> Result<Vec<Option<Cow<'a, [u8]>>>, LoadError> {
    let mut out = Vec::with_capacity(list.len());
    for (i, b) in list.iter().enumerate() {
        let length = b.uint("byteLength")?.ok_or_else(|| format!("{}: the required field 'byteLength' is missing", b.at))?;
        let data: Option<Cow<'a, [u8]>> = match b.str("uri")? {
            Some(uri) => Some(Cow::Owned(uri_bytes(uri, dir, &b.at)?)),
            None if i == 0 => bin.map(Cow::Borrowed),
            None => None,
        };
        let data = match data {
            Some(d) if (d.len() as u64) < length => {
                return Err(format!("{}: byteLength is {length} but its data holds {} bytes", b.at, d.len()).into());
            }
            Some(Cow::Borrowed(d)) => Some(Cow::Borrowed(&d[..length as usize])),
            Some(Cow::Owned(mut d)) => {
                d.truncate(length as usize);
                Some(Cow::Owned(d))
            }
            None if length <= ZERO_BUFFER_BYTES => Some(Cow::Owned(vec![0; length as usize])),
            None => None,
        };
        out.push(data);
    }
    Ok(out)
}

/// A bufferView, checked to lie inside its buffer.
pub(super) struct View {
    buffer: usize,
    offset: usize,
    length: usize,
    stride: Option<usize>,
}

/// A glTF component type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Component {
    I8,
    U8,
    I16,
    U16,
    U32,
    F32,
}

impl Component {
    fn from_code(code: u32) -> Option<Self> {
        Some(match code {
            5120 => Self::I8,
            5121 => Self::U8,
            5122 => Self::I16,
            5123 => Self::U16,
            5125 => Self::U32,
            5126 => Self::F32,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::U32 | Self::F32 => 4,
        }
    }
}

/// Everything the accessors read from.
pub(super) struct Store<'a> {
    buffers: Vec<Option<Cow<'a, [u8]>>>,
    views: Vec<View>,
    accessors: Vec<Obj<'a>>,
    /// Bytes the loader may still decode (`charge`).
    budget: Cell<u64>,
}

/// What a file may make the loader decode: this many bytes, plus BUDGET_RATIO times its own
/// size (its JSON and buffers). Reading one accessor from many primitives, or placing one mesh
/// on many nodes and instances, spends it; a file of a few kilobytes cannot ask for gigabytes.
const BUDGET_BASE: u64 = 256 << 20;
const BUDGET_RATIO: u64 = 32;

/// An accessor, checked: its elements lie inside its bufferView (or it has none: zeros).
pub(super) struct Accessor<'s> {
    pub at: String,
    pub count: usize,
    pub component: Component,
    pub normalized: bool,
    pub kind: &'static str,
    comps: usize,
    /// The first element's bytes onwards, and the step between elements.
    data: Option<(&'s [u8], usize)>,
    sparse: Option<Obj<'s>>,
}

impl<'a> Store<'a> {
    /// The store over `buffers`; `json_bytes` is the size of the document's JSON (for the budget).
    pub fn new(buffers: Vec<Option<Cow<'a, [u8]>>>, views: &[Obj<'_>], accessors: Vec<Obj<'a>>, json_bytes: usize) -> Result<Self, String> {
        let views = views
            .iter()
            .map(|v| {
                let buffer = v.required_index("buffer", buffers.len(), "buffers")?;
                let offset = v.uint_or("byteOffset", 0)?;
                let length = v.uint("byteLength")?.ok_or_else(|| format!("{}: the required field 'byteLength' is missing", v.at))?;
                let stride = v.uint("byteStride")?;
                if let Some(s) = stride {
                    if !(4..=252).contains(&s) || s % 4 != 0 {
                        return Err(format!("{}: byteStride {s} is not a multiple of 4 in [4, 252]", v.at));
                    }
                }
                if let Some(data) = &buffers[buffer] {
                    if offset.checked_add(length).is_none_or(|end| end > data.len() as u64) {
                        return Err(format!(
                            "{}: bytes {offset} to {} lie past the end of buffers[{buffer}] ({} bytes)",
                            v.at,
                            offset as u128 + length as u128,
                            data.len()
                        ));
                    }
                }
                Ok(View { buffer, offset: offset as usize, length: length as usize, stride: stride.map(|s| s as usize) })
            })
            .collect::<Result<_, String>>()?;
        let held: u64 = buffers.iter().flatten().map(|b| b.len() as u64).sum::<u64>() + json_bytes as u64;
        Ok(Self { buffers, views, accessors, budget: Cell::new(BUDGET_BASE + BUDGET_RATIO * held) })
    }

    /// Spends `bytes` of the decoding budget on `what`, or refuses the file.
    pub fn charge(&self, bytes: u64, what: &str) -> Result<(), String> {
        let left = self.budget.get();
        if bytes > left {
            return Err(format!(
                "{what} would take the decoded data past {BUDGET_BASE} bytes plus {BUDGET_RATIO} times the file's size: \
                 the file asks for far more than it holds"
            ));
        }
        self.budget.set(left - bytes);
        Ok(())
    }

    pub fn accessor_count(&self) -> usize {
        self.accessors.len()
    }

    /// The bytes of bufferView `v`.
    pub fn view_bytes(&self, v: usize, what: &str) -> Result<&[u8], String> {
        let view = self.views.get(v).ok_or_else(|| format!("{what}: bufferViews[{v}] does not exist"))?;
        let data = self.buffers[view.buffer]
            .as_deref()
            .ok_or_else(|| format!("buffers[{}] has no data (no uri, and not the GLB's binary chunk), yet {what} reads it", view.buffer))?;
        Ok(&data[view.offset..view.offset + view.length])
    }

    fn view_count(&self) -> usize {
        self.views.len()
    }

    /// Accessor `i`, its sizes checked.
    pub fn accessor(&self, i: usize) -> Result<Accessor<'_>, String> {
        let a = &self.accessors[i];
        let at = a.at.clone();
        let code = a.code("componentType")?.ok_or_else(|| format!("{at}: the required field 'componentType' is missing"))?;
        let component = Component::from_code(code)
            .ok_or_else(|| format!("{at}: componentType {code} is not one of 5120, 5121, 5122, 5123, 5125, 5126"))?;
        let kind = a.str("type")?.ok_or_else(|| format!("{at}: the required field 'type' is missing"))?;
        let (kind, comps) = match kind {
            "SCALAR" => ("SCALAR", 1),
            "VEC2" => ("VEC2", 2),
            "VEC3" => ("VEC3", 3),
            "VEC4" => ("VEC4", 4),
            "MAT2" => ("MAT2", 4),
            "MAT3" => ("MAT3", 9),
            "MAT4" => ("MAT4", 16),
            t => return Err(format!("{at}: type '{t}' is not SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4")),
        };
        let count = a.uint("count")?.ok_or_else(|| format!("{at}: the required field 'count' is missing"))?;
        if count == 0 {
            return Err(format!("{at}: count is 0; an accessor has at least one element"));
        }
        let normalized = a.bool("normalized")?.unwrap_or(false);
        let element = (comps * component.size()) as u64;
        let data = match a.index("bufferView", self.view_count(), "bufferViews")? {
            Some(v) => {
                let bytes = self.view_bytes(v, &at)?;
                let stride = self.views[v].stride.unwrap_or(element as usize) as u64;
                if stride < element {
                    return Err(format!("{at}: bufferViews[{v}].byteStride {stride} is less than the element's {element} bytes"));
                }
                let offset = a.uint_or("byteOffset", 0)?;
                let need = (count as u128 - 1) * stride as u128 + element as u128 + offset as u128;
                if need > bytes.len() as u128 {
                    return Err(format!(
                        "{at}: count {count} of {element}-byte elements {stride} bytes apart from byteOffset {offset} needs {need} bytes, \
                         but bufferViews[{v}] has {}",
                        bytes.len()
                    ));
                }
                Some((&bytes[offset as usize..], stride as usize))
            }
            None if count > MAX_ZEROS => {
                return Err(format!("{at}: count {count} without a bufferView is past the {MAX_ZEROS} elements oit makes of zeros"));
            }
            None => None,
        };
        Ok(Accessor { at, count: count as usize, component, normalized, kind, comps, data, sparse: a.obj("sparse")? })
    }
}

/// A sparse accessor's element indices and the bytes of their values.
type Sparse<'s> = (Vec<u32>, &'s [u8]);

/// Reads `N`-component elements as f32 (normalized integers mapped to [0, 1] or [-1, 1]).
fn gather<const N: usize>(src: &[u8], stride: usize, component: Component, normalized: bool, out: &mut [[f32; N]]) {
    fn each<const N: usize, const S: usize>(src: &[u8], stride: usize, out: &mut [[f32; N]], f: impl Fn([u8; S]) -> f32) {
        for (i, o) in out.iter_mut().enumerate() {
            let e = &src[i * stride..i * stride + N * S];
            for (c, x) in o.iter_mut().enumerate() {
                *x = f(std::array::from_fn(|k| e[c * S + k]));
            }
        }
    }
    use Component::*;
    let n = normalized;
    match component {
        F32 if stride == 4 * N && cfg!(target_endian = "little") => {
            let bytes = &src[..out.len() * 4 * N];
            bytemuck::cast_slice_mut::<f32, u8>(out.as_flattened_mut()).copy_from_slice(bytes);
        }
        F32 => each(src, stride, out, f32::from_le_bytes),
        U8 if n => each(src, stride, out, |b: [u8; 1]| b[0] as f32 / 255.0),
        U8 => each(src, stride, out, |b: [u8; 1]| b[0] as f32),
        I8 if n => each(src, stride, out, |b: [u8; 1]| (b[0] as i8 as f32 / 127.0).max(-1.0)),
        I8 => each(src, stride, out, |b: [u8; 1]| b[0] as i8 as f32),
        U16 if n => each(src, stride, out, |b| u16::from_le_bytes(b) as f32 / 65535.0),
        U16 => each(src, stride, out, |b| u16::from_le_bytes(b) as f32),
        I16 if n => each(src, stride, out, |b| (i16::from_le_bytes(b) as f32 / 32767.0).max(-1.0)),
        I16 => each(src, stride, out, |b| i16::from_le_bytes(b) as f32),
        U32 => each(src, stride, out, |b| u32::from_le_bytes(b) as f32),
    }
}

/// Reads unsigned integer scalars.
fn gather_u32(src: &[u8], stride: usize, component: Component, out: &mut [u32]) {
    fn each<const S: usize>(src: &[u8], stride: usize, out: &mut [u32], f: impl Fn([u8; S]) -> u32) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = f(std::array::from_fn(|k| src[i * stride + k]));
        }
    }
    match component {
        Component::U8 => each(src, stride, out, |b: [u8; 1]| b[0] as u32),
        Component::U16 => each(src, stride, out, |b| u16::from_le_bytes(b) as u32),
        _ => each(src, stride, out, u32::from_le_bytes),
    }
}

impl Accessor<'_> {
    fn expect(&self, kinds: &[&str]) -> Result<(), String> {
        if kinds.contains(&self.kind) {
            Ok(())
        } else {
            Err(format!("{}: type {} where {} is needed", self.at, self.kind, kinds.join(" or ")))
        }
    }

    /// The number of components an element has (2 for VEC2 ...).
    pub fn components(&self) -> usize {
        self.comps
    }

    /// The elements as `N` floats each (the type must have `N` components and be a vector or
    /// scalar), the sparse substitution applied.
    pub fn floats<const N: usize>(&self, store: &Store<'_>) -> Result<Vec<[f32; N]>, String> {
        let kinds: &[&str] = match N {
            1 => &["SCALAR"],
            2 => &["VEC2"],
            3 => &["VEC3"],
            _ => &["VEC4"],
        };
        self.expect(kinds)?;
        store.charge(self.count as u64 * 4 * N as u64, &self.at)?;
        let mut out = vec![[0.0f32; N]; self.count];
        if let Some((src, stride)) = self.data {
            gather(src, stride, self.component, self.normalized, &mut out);
        }
        if let Some((indices, values)) = self.sparse(store)? {
            let mut v = vec![[0.0f32; N]; indices.len()];
            gather(values, N * self.component.size(), self.component, self.normalized, &mut v);
            indices.iter().zip(v).for_each(|(&i, x)| out[i as usize] = x);
        }
        Ok(out)
    }

    /// The elements as unsigned integers (indices): SCALAR of 5121, 5123 or 5125.
    pub fn uints(&self, store: &Store<'_>) -> Result<Vec<u32>, String> {
        self.expect(&["SCALAR"])?;
        if !matches!(self.component, Component::U8 | Component::U16 | Component::U32) || self.normalized {
            return Err(format!("{}: indices must be unsigned bytes, shorts or ints (5121, 5123, 5125), not normalized", self.at));
        }
        // Triangles made of them take three times as much again (a strip's one index a triangle).
        store.charge(self.count as u64 * 16, &self.at)?;
        let mut out = vec![0u32; self.count];
        if let Some((src, stride)) = self.data {
            gather_u32(src, stride, self.component, &mut out);
        }
        if let Some((indices, values)) = self.sparse(store)? {
            let mut v = vec![0u32; indices.len()];
            gather_u32(values, self.component.size(), self.component, &mut v);
            indices.iter().zip(v).for_each(|(&i, x)| out[i as usize] = x);
        }
        Ok(out)
    }

    /// The sparse substitution: the element indices (checked below `count`) and the bytes of
    /// their tightly packed values.
    fn sparse<'s>(&self, store: &'s Store<'_>) -> Result<Option<Sparse<'s>>, String> {
        let Some(s) = &self.sparse else { return Ok(None) };
        let count = s.uint("count")?.ok_or_else(|| format!("{}: the required field 'count' is missing", s.at))?;
        if count == 0 || count > self.count as u64 {
            return Err(format!("{}: count {count} is not in [1, {}] (the accessor's count)", s.at, self.count));
        }
        let part = |key: &str| s.obj(key)?.ok_or_else(|| format!("{}: the required field '{key}' is missing", s.at));
        let (ix, vals) = (part("indices")?, part("values")?);
        let read = |o: &Obj<'_>, size: usize| -> Result<&'s [u8], String> {
            let v = o.required_index("bufferView", store.view_count(), "bufferViews")?;
            let bytes = store.view_bytes(v, &o.at)?;
            let offset = o.uint_or("byteOffset", 0)?;
            let need = offset as u128 + count as u128 * size as u128;
            if need > bytes.len() as u128 {
                return Err(format!(
                    "{}: {count} values of {size} bytes from byteOffset {offset} need {need} bytes, bufferViews[{v}] has {}",
                    o.at,
                    bytes.len()
                ));
            }
            Ok(&bytes[offset as usize..need as usize])
        };
        let code = ix.code("componentType")?.ok_or_else(|| format!("{}: the required field 'componentType' is missing", ix.at))?;
        let component = match Component::from_code(code) {
            Some(c @ (Component::U8 | Component::U16 | Component::U32)) => c,
            _ => return Err(format!("{}: componentType {code} is not 5121, 5123 or 5125", ix.at)),
        };
        let mut indices = vec![0u32; count as usize];
        gather_u32(read(&ix, component.size())?, component.size(), component, &mut indices);
        if let Some(k) = indices.iter().position(|&i| i as usize >= self.count) {
            return Err(format!("{}: index {} at {k} is past the accessor's {} elements", ix.at, indices[k], self.count));
        }
        if let Some(k) = indices.windows(2).position(|w| w[0] >= w[1]) {
            return Err(format!("{}: indices must increase strictly, but {} follows {} at {}", ix.at, indices[k + 1], indices[k], k + 1));
        }
        let values = read(&vals, self.comps * self.component.size())?;
        Ok(Some((indices, values)))
    }
}
