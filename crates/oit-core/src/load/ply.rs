//! PLY, ASCII or binary (little or big endian), streamed: every property type, list
//! properties of any count and index type, and every count checked against the bytes the
//! file has before anything is allocated for it. Vertex and face colors with alpha (integer
//! ones are sRGB, float ones linear; a face's color wins over its vertices', and vertices
//! shared by faces of different colors are split), vertex normals; polygons fanned into
//! triangles. A PLY of points only becomes particles in `load_file`; one with the 3DGS
//! properties becomes Gaussian splats (ply/gaussians.rs). The header is ply/header.rs.

mod gaussians;
mod header;

use std::io::Read;
use std::path::Path;

use super::keys::KeyMap;
use super::text::{decimal, whitespace, Text};
use super::{named, srgb_to_linear, LoadError, NamedMesh, DEFAULT_RGB};
use header::{header, Element, Format, PropertyKind, Scalar};

pub fn load_ply(path: &Path) -> Result<NamedMesh, LoadError> {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh").to_string();
    let file = std::fs::File::open(path).map_err(|e| format!("cannot read it ({e})"))?;
    let len = file.metadata().map_err(|e| format!("cannot read it ({e})"))?.len();
    parse(file, len, stem)
}

/// The file's text after the header: its bytes left, values read as the format says.
struct Input<R> {
    text: Text<R>,
    /// The file's length.
    len: u64,
}

fn io(e: std::io::Error) -> String {
    format!("cannot read it ({e})")
}

const CUT_SHORT: &str = "the file ends inside its data (cut short?)";

impl<R: Read> Input<R> {
    fn new(r: R, len: u64) -> Self {
        Self { text: Text::new(r), len }
    }

    /// Bytes from the current one to the end of the file.
    fn left(&self) -> u64 {
        self.len.saturating_sub(self.text.offset())
    }

    fn line(&self) -> usize {
        self.text.line_number
    }

    fn binary(&mut self, s: Scalar, format: Format) -> Result<f64, String> {
        let n = s.size() as usize;
        let bytes = self.text.peek(n).map_err(io)?;
        if bytes.len() < n {
            return Err(CUT_SHORT.into());
        }
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(&bytes[..n]);
        self.text.consume(n);
        if format == Format::Big {
            b[..n].reverse();
        }
        Ok(match s {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(b),
        })
    }

    /// After an item of ASCII data, the rest of its line: words past the header's properties
    /// (some writers add a texture number and more) are not read as the next item.
    fn end_item(&mut self, format: Format) -> Result<(), String> {
        if format == Format::Ascii {
            self.text.line().map_err(io)?;
        }
        Ok(())
    }

    fn ascii(&mut self, s: Scalar) -> Result<f64, String> {
        let w = self.text.word(whitespace).map_err(io)?.ok_or(CUT_SHORT)?;
        let text = std::str::from_utf8(w).unwrap_or("");
        let v = match s {
            Scalar::F32 | Scalar::F64 => decimal(w).or_else(|| text.parse::<f64>().ok()),
            _ => text.parse::<i64>().ok().map(|i| i as f64).or_else(|| text.parse::<f64>().ok()),
        };
        v.ok_or_else(|| format!("'{}' is not a number", String::from_utf8_lossy(&w[..w.len().min(40)])))
    }

    fn value(&mut self, s: Scalar, format: Format) -> Result<f64, String> {
        match format {
            Format::Ascii => self.ascii(s),
            _ => self.binary(s, format),
        }
    }

    /// A list's length, checked against the bytes left.
    fn list_len(&mut self, count: Scalar, item: Scalar, format: Format) -> Result<usize, String> {
        let n = self.value(count, format)?;
        let per = if format == Format::Ascii { 2 } else { item.size() };
        if !(n >= 0.0 && n.fract() == 0.0) || n * per as f64 > self.left() as f64 + 1.0 {
            return Err(format!("a list of {n} values does not fit in the {} bytes left", self.left()));
        }
        Ok(n as usize)
    }
}

/// What the loader keeps of the vertices.
struct Vertices {
    positions: Vec<[f32; 3]>,
    colors: Vec<[f32; 4]>,
    normals: Vec<[f32; 3]>,
}

/// `len` bytes of PLY as one mesh named `name` (points only where it has no faces).
fn parse(r: impl Read, len: u64, name: String) -> Result<NamedMesh, LoadError> {
    let mut input = Input::new(r, len);
    let (format, elements) = header(&mut input.text)?;
    let at = |input: &Input<_>, what: &str, i: u64, e: String| match format {
        Format::Ascii => format!("line {}: {what} {i}: {e}", input.line()),
        _ => format!("{what} {i}: {e}"),
    };
    // Every element's items must fit in what is left: a count is never trusted on its own.
    let need: u128 = elements.iter().map(|e| e.count as u128 * e.min_bytes(format) as u128).sum();
    if need > input.left() as u128 {
        let e = elements.iter().max_by_key(|e| e.count as u128 * e.min_bytes(format) as u128).map_or("", |e| e.name.as_str());
        return Err(format!(
            "the header's counts need at least {need} bytes of data, the file has {} (a wrong count in 'element {e}'?)",
            input.left()
        )
        .into());
    }
    let vertex_count = elements.iter().find(|e| e.name == "vertex").map_or(0, |e| e.count);
    if vertex_count > u32::MAX as u64 - 1 {
        return Err(format!("{vertex_count} vertices are more than a mesh holds ({})", u32::MAX - 1).into());
    }
    let mut vertices = None;
    let mut splats: Option<gaussians::Splats> = None;
    let mut indices: Vec<[u32; 3]> = Vec::new();
    // The color of each triangle, where faces have colors.
    let mut face_colors: Vec<[f32; 4]> = Vec::new();
    let mut values = vec![0f64; 0];
    let mut list = Vec::new();
    for e in &elements {
        let props = &e.props;
        // A vertex may have alpha alone (gray RGB); a face's color needs its RGB.
        let color = |e: &Element| {
            let rgb = [["red", "r", "diffuse_red"], ["green", "g", "diffuse_green"], ["blue", "b", "diffuse_blue"]].map(|n| e.find(&n));
            let alpha = e.find(&["alpha", "a"]);
            let has_rgb = rgb.iter().all(Option::is_some);
            (has_rgb || (alpha.is_some() && e.name == "vertex")).then_some((rgb, alpha))
        };
        values.resize(props.len(), 0.0);
        let layout = (e.name == "vertex" && splats.is_none()).then(|| gaussians::SplatLayout::find(e)).flatten();
        if let Some(layout) = layout {
            let mut out = gaussians::Splats::default();
            for i in 0..e.count {
                read_item(&mut input, e, format, &mut values, &mut list).map_err(|m| at(&input, "vertex", i, m))?;
                layout.push(&values, &mut out);
            }
            splats = Some(out);
        } else if e.name == "vertex" && vertices.is_none() {
            let xyz = ["x", "y", "z"].map(|n| e.find(&[n]));
            let [Some(x), Some(y), Some(z)] = xyz else { return Err("vertices need x, y and z".into()) };
            let normal = ["nx", "ny", "nz"].map(|n| e.find(&[n]));
            let color = color(e);
            let n = e.count as usize;
            let mut v = Vertices {
                positions: Vec::with_capacity(n),
                colors: Vec::with_capacity(if color.is_some() { n } else { 0 }),
                normals: Vec::with_capacity(if normal.iter().all(Option::is_some) { n } else { 0 }),
            };
            for i in 0..e.count {
                read_item(&mut input, e, format, &mut values, &mut list).map_err(|m| at(&input, "vertex", i, m))?;
                v.positions.push([values[x] as f32, values[y] as f32, values[z] as f32]);
                if let Some((rgb, alpha)) = color {
                    v.colors.push(to_color(e, &values, rgb, alpha));
                }
                if let [Some(a), Some(b), Some(c)] = normal {
                    v.normals.push([values[a] as f32, values[b] as f32, values[c] as f32]);
                }
            }
            vertices = Some(v);
        } else if e.name == "face" {
            let list_at =
                props.iter().position(|(n, k)| matches!(k, PropertyKind::List { .. }) && (n == "vertex_indices" || n == "vertex_index"));
            let list_at = list_at.or_else(|| props.iter().position(|(_, k)| matches!(k, PropertyKind::List { .. })));
            let Some(list_at) = list_at else { return Err("faces need a 'vertex_indices' list".into()) };
            let color = color(e);
            indices.reserve(e.count as usize);
            for i in 0..e.count {
                list.clear();
                read_face(&mut input, e, format, &mut values, &mut list, list_at).map_err(|m| at(&input, "face", i, m))?;
                if let Some(&bad) = list.iter().find(|&&k| !(k >= 0.0 && k < vertex_count as f64 && k.fract() == 0.0)) {
                    return Err(at(&input, "face", i, format!("vertex index {bad} is past the {vertex_count} vertices")).into());
                }
                // A fan triangulates convex polygons.
                let before = indices.len();
                for k in 2..list.len() {
                    indices.push([list[0] as u32, list[k - 1] as u32, list[k] as u32]);
                }
                if let Some((rgb, alpha)) = color {
                    let c = to_color(e, &values, rgb, alpha);
                    face_colors.extend(std::iter::repeat_n(c, indices.len() - before));
                }
            }
        } else {
            for i in 0..e.count {
                read_item(&mut input, e, format, &mut values, &mut list).map_err(|m| at(&input, &e.name, i, m))?;
            }
        }
    }
    if let Some(s) = splats {
        let mesh = match s.sh.is_empty() {
            true => crate::scene::Mesh::gaussians(s.means, s.scales, s.rotations, s.opacities, s.colors),
            false => crate::scene::Mesh::gaussians_sh(s.means, s.scales, s.rotations, s.opacities, s.sh, s.degree),
        };
        let mesh = mesh.map_err(|e| format!("'{name}': {e}"))?;
        return Ok(super::NamedMesh::new(name, mesh));
    }
    let Some(mut v) = vertices else { return Err("no 'vertex' element".into()) };
    if !face_colors.is_empty() {
        split_by_face_color(&mut v, &mut indices, &face_colors);
    }
    drop(face_colors);
    let opaque = v.colors.iter().all(|c| c[3] >= 1.0);
    let colors = if v.colors.is_empty() { vec![[DEFAULT_RGB[0], DEFAULT_RGB[1], DEFAULT_RGB[2], 1.0]] } else { v.colors };
    let mut mesh = named(name, v.positions, indices, colors, opaque)?;
    let usable = |n: &[f32; 3]| n.iter().all(|x| x.is_finite()) && n.iter().any(|&x| x != 0.0);
    if !v.normals.is_empty() && v.normals.iter().all(usable) && !mesh.mesh.indices.is_empty() {
        mesh.mesh.normals = v.normals;
    }
    Ok(mesh)
}

/// One item into `values` (lists read and dropped).
fn read_item<R: Read>(input: &mut Input<R>, e: &Element, format: Format, values: &mut [f64], list: &mut Vec<f64>) -> Result<(), String> {
    read_face(input, e, format, values, list, usize::MAX)
}

/// An item: its list property `list_at` into `list` (none past the properties), its other
/// lists read and dropped, its scalars into `values`.
fn read_face<R: Read>(
    input: &mut Input<R>,
    e: &Element,
    format: Format,
    values: &mut [f64],
    list: &mut Vec<f64>,
    list_at: usize,
) -> Result<(), String> {
    let mut other = Vec::new();
    for (k, (_, kind)) in e.props.iter().enumerate() {
        match *kind {
            PropertyKind::Scalar(s) => values[k] = input.value(s, format)?,
            PropertyKind::List { count, item } => {
                let n = input.list_len(count, item, format)?;
                let into = if k == list_at { &mut *list } else { &mut other };
                into.clear();
                for _ in 0..n {
                    into.push(input.value(item, format)?);
                }
            }
        }
    }
    input.end_item(format)
}

/// Straight linear RGBA of an item: integer channels are sRGB scaled by their type's largest
/// value (alpha linear), float channels linear; missing RGB is the default gray.
fn to_color(e: &Element, values: &[f64], rgb: [Option<usize>; 3], alpha: Option<usize>) -> [f32; 4] {
    let channel = |i: usize, srgb: bool| {
        let s = e.scalar(i);
        let x = match s.unit() {
            Some(u) => (values[i] / u) as f32,
            None => values[i] as f32,
        };
        let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
        if srgb && s.unit().is_some() {
            srgb_to_linear(x)
        } else {
            x
        }
    };
    let c = match rgb {
        [Some(r), Some(g), Some(b)] => [channel(r, true), channel(g, true), channel(b, true)],
        _ => DEFAULT_RGB,
    };
    [c[0], c[1], c[2], alpha.map_or(1.0, |a| channel(a, false))]
}

/// Gives each triangle its face's color: a vertex takes the color of the first face that uses
/// it, and a face of another color gets a copy of it.
fn split_by_face_color(v: &mut Vertices, indices: &mut [[u32; 3]], face_colors: &[[f32; 4]]) {
    const FREE: u32 = u32::MAX;
    let n = v.positions.len();
    let mut owner = vec![FREE; n];
    let mut copies: KeyMap<(u32, [u32; 4]), u32> = KeyMap::default();
    let base_colors = std::mem::take(&mut v.colors);
    let mut colors: Vec<[f32; 4]> = Vec::with_capacity(n);
    colors.extend((0..n).map(|i| base_colors.get(i).copied().unwrap_or([DEFAULT_RGB[0], DEFAULT_RGB[1], DEFAULT_RGB[2], 1.0])));
    drop(base_colors);
    for (t, tri) in indices.iter_mut().enumerate() {
        let c = face_colors[t];
        for i in tri.iter_mut() {
            let k = *i as usize;
            if owner[k] == FREE {
                owner[k] = t as u32;
                colors[k] = c;
            } else if colors[k] != c {
                let key = (*i, c.map(f32::to_bits));
                let next = v.positions.len() as u32;
                let copy = *copies.entry(key).or_insert(next);
                if copy == next {
                    v.positions.push(v.positions[k]);
                    colors.push(c);
                    if !v.normals.is_empty() {
                        v.normals.push(v.normals[k]);
                    }
                }
                *i = copy;
            }
        }
    }
    v.colors = colors;
}
