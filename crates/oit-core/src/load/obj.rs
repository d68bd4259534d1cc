//! OBJ with its MTL, read line by line as exporters write them (docs/loading.md): one mesh per
//! object (`o`/`g`) and material (`usemtl`; an empty one is no material); faces fanned into
//! triangles, `l` lines as strands and `p` points as particles; vertex colors
//! (`v x y z r g b`, sRGB), normals and UVs; `Kd` and `map_Kd` (sRGB), the dissolve `d`,
//! `Tr` and `map_d` as alpha. Errors name the line (`line 12: face index 9 is past the 8
//! vertices`); a missing `.mtl` is a warning (the meshes drawn gray), a missing image its MTL
//! names is `NotFound` naming it and the MTL line.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::keys::{key3, KeyMap};
use super::mtl::{load_texture, Materials, Mtl};
use super::text::{number, rest, short, words, Lines};
use super::{named, srgb_to_linear, LoadError, LoadedFile, NamedMesh, DEFAULT_RGB, MAX_TEXTURE_SIZE};
use crate::scene::Mesh;
use crate::shading::{Falloff, Material, TextureMap};

/// A strand's width and a particle's radius (where `Surface::point_radius` gives none), as
/// fractions of the diagonal of the box around the file's vertices.
pub const LINE_WIDTH_OF_DIAGONAL: f32 = 1.0 / 500.0;
pub const POINT_RADIUS_OF_DIAGONAL: f32 = 1.0 / 200.0;

const NONE: u32 = u32::MAX;

/// The file's meshes and warnings; `point_radius` sizes `p` points (None: 1/200 of the box
/// diagonal).
pub fn read(path: &Path, point_radius: Option<f32>) -> Result<LoadedFile, LoadError> {
    let file = std::fs::File::open(path).map_err(|e| LoadError::Invalid(format!("cannot read it ({e})")))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut obj = ObjFile::default();
    let mut lines = Lines::new(file);
    while let Some((number, line)) = lines.next().map_err(|e| LoadError::Invalid(format!("cannot read it ({e})")))? {
        obj.statement(line, number, dir)?;
    }
    obj.finish_group();
    obj.build(point_radius)
}

/// A run of statements under one object name and material.
#[derive(Default)]
struct Group {
    name: String,
    material: Option<String>,
    /// (position, uv, normal) of each of its vertices, NONE where absent.
    keys: Vec<[u32; 3]>,
    lookup: KeyMap<(u64, u32), u32>,
    triangles: Vec<[u32; 3]>,
    /// Positions (file indices) of its `l` lines and points of its `p` statements.
    line_points: Vec<u32>,
    line_counts: Vec<u32>,
    points: Vec<u32>,
}

impl Group {
    fn is_empty(&self) -> bool {
        self.triangles.is_empty() && self.line_counts.is_empty() && self.points.is_empty()
    }
}

#[derive(Default)]
struct ObjFile {
    positions: Vec<[f32; 3]>,
    /// Vertex colors (sRGB), NaN for vertices written without one; empty while none has one.
    colors: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    normals: Vec<[f32; 3]>,
    group: Group,
    groups: Vec<Group>,
    materials: Materials,
    corners: Vec<[u32; 3]>,
    /// For faces of positions alone: (group, its vertex) of each position.
    slot: Vec<(u32, u32)>,
    group_id: u32,
    short_faces: usize,
    short_lines: usize,
    /// Texture coordinate and normal indices past what the file defines: left out.
    dangling: [usize; 2],
}

impl ObjFile {
    fn statement(&mut self, line: &[u8], at: usize, dir: &Path) -> Result<(), LoadError> {
        if words(line).next() == Some(b"mtllib") {
            return self.materials.library(&rest(line), at, dir);
        }
        self.geometry(line).map_err(|e| LoadError::Invalid(format!("line {at}: {e}")))
    }

    fn geometry(&mut self, line: &[u8]) -> Result<(), String> {
        let mut t = words(line);
        let Some(key) = t.next() else { return Ok(()) };
        match key {
            b"v" => {
                let p = [number(t.next(), "x")?, number(t.next(), "y")?, number(t.next(), "z")?];
                // x y z [w] or x y z r g b.
                let rest: Vec<&[u8]> = t.take(4).collect();
                if rest.len() >= 3 {
                    if self.colors.len() < self.positions.len() {
                        self.colors.resize(self.positions.len(), [f32::NAN; 3]);
                    }
                    let c = [number(Some(rest[0]), "red")?, number(Some(rest[1]), "green")?, number(Some(rest[2]), "blue")?];
                    self.colors.push(c);
                } else if !self.colors.is_empty() {
                    self.colors.push([f32::NAN; 3]);
                }
                self.positions.push(p);
            }
            b"vt" => {
                let u = number(t.next(), "u")?;
                let v = if let Some(v) = t.next() { number(Some(v), "v")? } else { 0.0 };
                self.uvs.push([u, v]);
            }
            b"vn" => self.normals.push([number(t.next(), "x")?, number(t.next(), "y")?, number(t.next(), "z")?]),
            b"f" | b"fo" => {
                self.corners.clear();
                for c in t {
                    let key = self.corner(c, "face")?;
                    self.corners.push(key);
                }
                if self.corners.len() < 3 {
                    self.short_faces += 1;
                    return Ok(());
                }
                let g = &mut self.group;
                let mut local = [0u32; 3];
                for (k, key) in self.corners.iter().enumerate() {
                    let next = g.keys.len() as u32;
                    let i = if key[1] == NONE && key[2] == NONE {
                        // A position alone: its slot in the file-wide table, tagged by group.
                        let v = key[0] as usize;
                        if self.slot.len() <= v {
                            self.slot.resize(self.positions.len(), (NONE, NONE));
                        }
                        let (group, i) = self.slot[v];
                        if group == self.group_id {
                            i
                        } else {
                            self.slot[v] = (self.group_id, next);
                            next
                        }
                    } else {
                        *g.lookup.entry(key3(*key)).or_insert(next)
                    };
                    if i == next {
                        g.keys.push(*key);
                    }
                    // A fan: (0, k - 1, k).
                    match k {
                        0 => local[0] = i,
                        1 => local[2] = i,
                        _ => {
                            local[1] = local[2];
                            local[2] = i;
                            g.triangles.push(local);
                        }
                    }
                }
            }
            b"l" => {
                let before = self.group.line_points.len();
                for c in t {
                    let v = self.corner(c, "line")?[0];
                    self.group.line_points.push(v);
                }
                let n = self.group.line_points.len() - before;
                if n < 2 {
                    self.group.line_points.truncate(before);
                    self.short_lines += 1;
                } else {
                    self.group.line_counts.push(n as u32);
                }
            }
            b"p" => {
                for c in t {
                    let v = self.corner(c, "point")?[0];
                    self.group.points.push(v);
                }
            }
            b"o" | b"g" => {
                self.finish_group();
                self.group.name = rest(line);
            }
            b"usemtl" => {
                let name = rest(line);
                let name = (!name.is_empty()).then_some(name);
                if name != self.group.material {
                    self.finish_group();
                    self.group.material = name;
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// `v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based or negative (from the end), as 0-based
    /// indices (NONE where absent).
    /// A texture coordinate or normal index past what the file defines (some exporters write
    /// `f 1/1/1` with no `vt` lines) leaves that attribute absent, counted for a warning; a
    /// vertex index past the vertices is an error.
    fn corner(&mut self, token: &[u8], statement: &str) -> Result<[u32; 3], String> {
        let mut parts = token.split(|&b| b == b'/');
        let mut out = [NONE; 3];
        let counts = [(self.positions.len(), "vertices"), (self.uvs.len(), "texture coordinates"), (self.normals.len(), "normals")];
        for (k, (n, what)) in counts.into_iter().enumerate() {
            match parts.next() {
                Some([]) if k > 0 => {}
                None if k > 0 => {}
                Some(p) if k > 0 => match index(p, n, statement, what) {
                    Ok(i) => out[k] = i,
                    Err(_) => self.dangling[k - 1] += 1,
                },
                Some(p) => out[k] = index(p, n, statement, what)?,
                None => unreachable!("split yields at least one part"),
            }
        }
        Ok(out)
    }

    fn finish_group(&mut self) {
        if self.group.is_empty() {
            return;
        }
        let next = Group { name: self.group.name.clone(), material: self.group.material.clone(), ..Default::default() };
        let mut done = std::mem::replace(&mut self.group, next);
        done.lookup = KeyMap::default();
        self.group_id += 1;
        self.groups.push(done);
    }

    fn build(self, point_radius: Option<f32>) -> Result<LoadedFile, LoadError> {
        let mut out = LoadedFile::default();
        let diagonal = diagonal(&self.positions);
        let mut textures: HashMap<(Option<PathBuf>, Option<PathBuf>), Option<TextureMap>> = HashMap::new();
        let mut unknown = std::collections::BTreeSet::new();
        let mut downscaled = 0;
        for (i, g) in self.groups.iter().enumerate() {
            let mtl = g.material.as_ref().and_then(|name| {
                let m = self.materials.by_name.get(name);
                if m.is_none() {
                    unknown.insert(name.clone());
                }
                m
            });
            let rgb = mtl.and_then(|m| m.rgb).map_or(DEFAULT_RGB, |c| c.map(srgb_to_linear));
            let alpha = mtl.map_or(1.0, Mtl::alpha);
            let opaque = alpha == 1.0 && mtl.is_none_or(|m| m.map_d.is_none());
            let name = if g.name.is_empty() { format!("object {i}") } else { g.name.clone() };
            let several = [!g.triangles.is_empty(), !g.line_counts.is_empty(), !g.points.is_empty()].iter().filter(|&&x| x).count() > 1;
            let color_of = |v: u32| -> Option<[f32; 4]> {
                let c = self.colors.get(v as usize)?;
                (!c[0].is_nan()).then(|| [srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2]), alpha])
            };
            let colors_of = |vs: &mut dyn Iterator<Item = u32>| -> Vec<[f32; 4]> {
                let colors: Option<Vec<[f32; 4]>> = if self.colors.is_empty() { None } else { vs.map(color_of).collect() };
                colors.unwrap_or_else(|| vec![[rgb[0], rgb[1], rgb[2], alpha]])
            };
            if !g.triangles.is_empty() {
                let positions = g.keys.iter().map(|k| self.positions[k[0] as usize]).collect();
                let colors = colors_of(&mut g.keys.iter().map(|k| k[0]));
                let mut mesh = named(name.clone(), positions, g.triangles.clone(), colors, opaque)?;
                if g.keys.iter().all(|k| k[2] != NONE) {
                    let normals: Vec<[f32; 3]> = g.keys.iter().map(|k| self.normals[k[2] as usize]).collect();
                    // Zero normals (some exporters write them) are recomputed instead.
                    if !normals.iter().any(|n| n.iter().all(|&x| x == 0.0)) {
                        mesh.mesh.normals = normals;
                    }
                }
                let mut texture = None;
                if let Some(m) = mtl.filter(|m| m.map_kd.is_some() || m.map_d.is_some()) {
                    if g.keys.iter().all(|k| k[1] != NONE) {
                        let key = (m.map_kd.as_ref().map(|x| x.0.clone()), m.map_d.as_ref().map(|x| x.0.clone()));
                        texture = match textures.get(&key) {
                            Some(t) => t.clone(),
                            None => {
                                let (t, small) = load_texture(m.map_kd.as_ref(), m.map_d.as_ref())?;
                                downscaled += small as usize;
                                textures.insert(key, t.clone());
                                t
                            }
                        };
                    }
                }
                if texture.is_some() {
                    // OBJ's v points up the image; the texture's row 0 is v = 0.
                    mesh.mesh.uvs = g.keys.iter().map(|k| self.uvs[k[1] as usize]).map(|t| [t[0], 1.0 - t[1]]).collect();
                }
                mesh.mesh.material = Material { texture, ..Default::default() };
                out.meshes.push(mesh);
            }
            if !g.line_counts.is_empty() {
                let positions = g.line_points.iter().map(|&v| self.positions[v as usize]).collect();
                let colors = colors_of(&mut g.line_points.iter().copied());
                let width = diagonal.map_or(1.0, |d| d * LINE_WIDTH_OF_DIAGONAL);
                let mesh =
                    Mesh::strands(positions, g.line_counts.clone(), vec![width], colors, opaque).map_err(|e| format!("'{name}': {e}"))?;
                out.meshes.push(NamedMesh::new(if several { format!("{name} (lines)") } else { name.clone() }, mesh));
            }
            if !g.points.is_empty() {
                let positions = g.points.iter().map(|&v| self.positions[v as usize]).collect();
                let colors = colors_of(&mut g.points.iter().copied());
                let radius = point_radius.unwrap_or_else(|| diagonal.map_or(1.0, |d| d * POINT_RADIUS_OF_DIAGONAL));
                let mesh = Mesh::particles(positions, vec![radius], colors, opaque, Falloff::Hard).map_err(|e| format!("'{name}': {e}"))?;
                out.meshes.push(NamedMesh::new(if several { format!("{name} (points)") } else { name }, mesh));
            }
        }
        if out.meshes.is_empty() && !self.positions.is_empty() {
            // Vertices and nothing drawn from them: a point cloud, as a PLY of points only is.
            let colors = if self.colors.len() == self.positions.len() && self.colors.iter().all(|c| !c[0].is_nan()) {
                self.colors.iter().map(|c| [srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2]), 1.0]).collect()
            } else {
                vec![[DEFAULT_RGB[0], DEFAULT_RGB[1], DEFAULT_RGB[2], 1.0]]
            };
            let radius = point_radius.unwrap_or_else(|| diagonal.map_or(1.0, |d| d * POINT_RADIUS_OF_DIAGONAL));
            let name = self.groups.first().map(|g| g.name.clone()).filter(|n| !n.is_empty()).unwrap_or_else(|| "points".into());
            let mesh =
                Mesh::particles(self.positions.clone(), vec![radius], colors, true, Falloff::Hard).map_err(|e| format!("'{name}': {e}"))?;
            out.meshes.push(NamedMesh::new(name, mesh));
        }
        if !self.materials.missing.is_empty() {
            out.warnings.push(format!(
                "the material librar{} {} named by mtllib {} not there: its meshes are drawn gray",
                if self.materials.missing.len() == 1 { "y" } else { "ies" },
                self.materials.missing.join(", "),
                if self.materials.missing.len() == 1 { "is" } else { "are" }
            ));
        }
        if !unknown.is_empty() && self.materials.missing.is_empty() {
            let names: Vec<String> = unknown.iter().map(|n| format!("'{n}'")).collect();
            out.warnings.push(format!(
                "{} material{} named by usemtl {} in no .mtl file ({}): drawn gray",
                unknown.len(),
                if unknown.len() == 1 { "" } else { "s" },
                if unknown.len() == 1 { "is" } else { "are" },
                names.join(", ")
            ));
        }
        if self.short_faces > 0 {
            out.warnings.push(format!("{} faces with fewer than 3 vertices are not drawn", self.short_faces));
        }
        for (n, what) in self.dangling.iter().zip(["texture coordinate", "normal"]) {
            if *n > 0 {
                out.warnings.push(format!("{n} {what} indices refer past the file's {what}s: those corners have none"));
            }
        }
        if self.short_lines > 0 {
            out.warnings.push(format!("{} lines (l) with fewer than 2 points are not drawn", self.short_lines));
        }
        if downscaled > 0 {
            out.warnings.push(format!("{downscaled} textures are larger than {MAX_TEXTURE_SIZE} texels a side: downscaled to fit"));
        }
        Ok(out)
    }
}

/// A 0-based index from a 1-based or negative (-1: the last) OBJ index.
fn index(token: &[u8], n: usize, statement: &str, what: &str) -> Result<u32, String> {
    let s = std::str::from_utf8(token).ok();
    let Some(i) = s.and_then(|s| s.parse::<i64>().ok()) else {
        return Err(format!("'{}' is not an index", short(&String::from_utf8_lossy(token))));
    };
    let k = match i {
        0 => return Err(format!("{statement} index 0 is not an index into the {n} {what}: OBJ counts from 1")),
        i if i > 0 && i as u64 <= n as u64 => i - 1,
        i if i < 0 && i.unsigned_abs() <= n as u64 => n as i64 + i,
        i if i > 0 => return Err(format!("{statement} index {i} is past the {n} {what}")),
        i => return Err(format!("{statement} index {i} reaches before the first of the {n} {what}")),
    };
    Ok(k as u32)
}

/// The diagonal of the box around the positions, where it is finite and > 0.
fn diagonal(positions: &[[f32; 3]]) -> Option<f32> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] as f64);
            hi[k] = hi[k].max(p[k] as f64);
        }
    }
    let d = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt() as f32;
    (d.is_finite() && d > 0.0).then_some(d)
}
