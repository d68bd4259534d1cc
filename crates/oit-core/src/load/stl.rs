//! STL, gray and opaque: binary (80-byte header, a count, 50 bytes a facet; a header that
//! starts with "solid" is still binary when the size is 84 + 50 n) or ASCII, every `solid`
//! block a mesh of its own, a bare `solid` header included. Vertices that coincide are
//! shared, so smooth shading has neighbours to average.

use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use super::keys::{key3, KeyMap};
use super::text::{control, number, Text};
use super::{named, LoadError, NamedMesh, DEFAULT_RGB};

/// The file's solids, one mesh each, in file order (empty solids left out).
pub fn read(path: &Path) -> Result<Vec<NamedMesh>, LoadError> {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh").to_string();
    let file = std::fs::File::open(path).map_err(|e| format!("cannot read it ({e})"))?;
    let len = file.metadata().map_err(|e| format!("cannot read it ({e})"))?.len();
    parse(file, len, &stem)
}

/// `len` bytes of STL, meshes named after their solid (or `stem`).
pub fn parse<R: Read + Seek>(r: R, len: u64, stem: &str) -> Result<Vec<NamedMesh>, LoadError> {
    let io = |e: std::io::Error| LoadError::Invalid(format!("cannot read it ({e})"));
    let mut r = BufReader::with_capacity(1 << 16, r);
    let mut head = Vec::with_capacity(84);
    r.by_ref().take(84).read_to_end(&mut head).map_err(io)?;
    let count = head.get(80..84).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as u64);
    let binary_size = count.map(|n| 84 + 50 * n);
    if binary_size == Some(len) {
        return binary(r, count.unwrap_or(0), stem);
    }
    let text = head.iter().position(|b| !b.is_ascii_whitespace()).is_some_and(|i| head[i..].starts_with(b"solid"));
    if text {
        r.seek(SeekFrom::Start(0)).map_err(io)?;
        return match ascii(&mut r, stem) {
            // A binary file whose header starts with "solid" and that has bytes past its facets.
            Err(e) if binary_size.is_some_and(|n| n <= len) => {
                r.seek(SeekFrom::Start(84)).map_err(io)?;
                binary(r, count.unwrap_or(0), stem).map_err(|_| e)
            }
            result => result,
        };
    }
    match binary_size {
        None => Err("not an STL file: shorter than a binary STL's 84-byte header and no 'solid' to start an ASCII one".into()),
        Some(n) if n > len => {
            Err(format!("a binary STL of {} facets takes {n} bytes, the file has {len} (cut short?)", count.unwrap_or(0)).into())
        }
        Some(_) => binary(r, count.unwrap_or(0), stem),
    }
}

/// `n` facets of 50 bytes (the caller checked the file holds them).
fn binary(mut r: impl Read, n: u64, stem: &str) -> Result<Vec<NamedMesh>, LoadError> {
    let mut solid = Solid::new(stem.to_string(), n as usize);
    let mut facet = [0u8; 50];
    for f in 0..n {
        r.read_exact(&mut facet).map_err(|e| format!("facet {f}: cannot read it ({e})"))?;
        let mut corners = [[0f32; 3]; 3];
        for (k, c) in corners.iter_mut().enumerate() {
            for (a, x) in c.iter_mut().enumerate() {
                let o = 12 + 12 * k + 4 * a;
                *x = f32::from_le_bytes([facet[o], facet[o + 1], facet[o + 2], facet[o + 3]]);
            }
        }
        if corners.iter().flatten().any(|x| !x.is_finite()) {
            return Err(format!("facet {f}: a vertex is not finite: {corners:?}").into());
        }
        solid.triangle(corners);
    }
    Ok(solid.mesh()?.into_iter().collect())
}

fn ascii(r: impl Read, stem: &str) -> Result<Vec<NamedMesh>, LoadError> {
    let mut out = Vec::new();
    let mut words = Text::new(r);
    let mut solid: Option<Solid> = None;
    let mut polygon: Vec<[f32; 3]> = Vec::new();
    let io = |e: std::io::Error| format!("cannot read it ({e})");
    while let Some(key) = words.word(control).map_err(io)? {
        match key {
            b"solid" => {
                if let Some(s) = solid.take() {
                    out.extend(s.mesh()?);
                }
                let name = String::from_utf8_lossy(words.line().map_err(io)?.unwrap_or_default().trim_ascii()).into_owned();
                solid = Some(Solid::new(if name.is_empty() { stem.to_string() } else { name }, 0));
            }
            b"facet" | b"outer" | b"loop" => polygon.clear(),
            // The facet's normal: oit computes its own.
            b"normal" => {
                for _ in 0..3 {
                    words.word(control).map_err(io)?;
                }
            }
            b"vertex" => {
                let mut v = [0f32; 3];
                for (k, x) in v.iter_mut().enumerate() {
                    let line = words.line_number;
                    *x = number(words.word(control).map_err(io)?, ["x", "y", "z"][k]).map_err(|e| format!("line {line}: {e}"))?;
                }
                polygon.push(v);
            }
            b"endloop" | b"endfacet" => {
                let s = solid.get_or_insert_with(|| Solid::new(stem.to_string(), 0));
                // A loop of more than three vertices is a polygon: fanned.
                for k in 2..polygon.len() {
                    s.triangle([polygon[0], polygon[k - 1], polygon[k]]);
                }
                polygon.clear();
            }
            b"endsolid" => {
                words.line().map_err(io)?;
                if let Some(s) = solid.take() {
                    out.extend(s.mesh()?);
                }
            }
            other => {
                let word: String = String::from_utf8_lossy(other).chars().take(20).collect();
                let line = words.line_number;
                return Err(format!(
                    "line {line}: '{word}' is not an ASCII STL keyword (solid, facet normal, outer loop, vertex, endloop, endfacet, endsolid)"
                )
                .into());
            }
        }
    }
    if let Some(s) = solid {
        out.extend(s.mesh()?);
    }
    Ok(out)
}

/// A solid's triangles with coinciding vertices shared.
struct Solid {
    name: String,
    positions: Vec<[f32; 3]>,
    indices: Vec<[u32; 3]>,
    lookup: KeyMap<(u64, u32), u32>,
}

impl Solid {
    fn new(name: String, facets: usize) -> Self {
        let mut lookup = KeyMap::default();
        lookup.reserve(facets / 2);
        Self { name, positions: Vec::with_capacity(facets / 2), indices: Vec::with_capacity(facets), lookup }
    }

    fn triangle(&mut self, corners: [[f32; 3]; 3]) {
        let t = corners.map(|p| {
            // -0 and 0 are one vertex.
            let key = p.map(|x| if x == 0.0 { 0 } else { x.to_bits() });
            let next = self.positions.len() as u32;
            let i = *self.lookup.entry(key3(key)).or_insert(next);
            if i == next {
                self.positions.push(p);
            }
            i
        });
        self.indices.push(t);
    }

    fn mesh(self) -> Result<Option<NamedMesh>, String> {
        if self.indices.is_empty() {
            return Ok(None);
        }
        let [r, g, b] = DEFAULT_RGB;
        drop(self.lookup);
        named(self.name, self.positions, self.indices, vec![[r, g, b, 1.0]], true).map(Some)
    }
}
