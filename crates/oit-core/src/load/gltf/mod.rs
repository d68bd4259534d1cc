//! glTF 2.0 and GLB, read from the specification rather than through an importer: the JSON is
//! checked value by value (`json`), buffers, bufferViews and accessors are resolved with every
//! size checked against the bytes it reads (`data`), the node tree is walked once with a visited
//! set (`nodes`), materials and textures are decoded once each (`material`) and each primitive
//! becomes a mesh, a strand set or a particle set (`geometry`). No input makes it panic, loop
//! or allocate more than the file holds; what breaks the specification is refused naming the
//! object and the rule, and what oit does not draw is said once in `LoadedFile::warnings`.
//!
//! Each (mesh, primitive) is uploaded once and drawn as an instance under the world transform
//! of every node that uses it (times each EXT_mesh_gpu_instancing instance). Lines are strands
//! 1/500 of the scene's box diagonal wide; points are hard particles 1/200 of it in radius
//! (or `Surface::point_radius`).

mod data;
mod geometry;
mod json;
mod material;
mod nodes;

use std::collections::{BTreeSet, HashMap};
use std::path::Path;

use glam::{DMat4, DVec3};
use serde_json::Value;

use self::json::Obj;
use super::{bounds, FileCamera, LoadError, LoadedFile, Projection};
use crate::primitive::Primitive;
use crate::scene::Instance;

/// The extensions oit reads; a file that requires another is refused.
pub const EXTENSIONS: [&str; 4] =
    ["KHR_mesh_quantization", "KHR_texture_transform", "KHR_materials_emissive_strength", "EXT_mesh_gpu_instancing"];
/// A strand's width as a fraction of the scene's box diagonal.
pub const LINE_WIDTH: f32 = 1.0 / 500.0;
/// A point's particle radius as a fraction of the scene's box diagonal.
pub const POINT_RADIUS: f32 = 1.0 / 200.0;

/// What the file uses that oit does not draw, counted as the loader meets it.
#[derive(Default)]
pub(super) struct Notes {
    morphed: usize,
    positionless: usize,
    sourceless: BTreeSet<usize>,
    downscaled: usize,
    other_uv_sets: usize,
    /// Primitives whose vertex count their mode does not use whole, described.
    pub(super) leftover: Vec<String>,
}

/// "1 animation" / "2 animations".
fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// Reads a glTF or GLB file; points become particles of `point_radius` (None: 1/200 of the
/// scene's box diagonal).
pub fn load_with(path: &Path, point_radius: Option<f32>) -> Result<LoadedFile, LoadError> {
    let bytes = std::fs::read(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => LoadError::NotFound("no such file: check the path".to_string()),
        _ => LoadError::Invalid(format!("cannot read the file ({e})")),
    })?;
    from_bytes(&bytes, path.parent().unwrap_or(Path::new(".")), point_radius)
}

/// A glTF or GLB held in memory; files it refers to are looked up in `dir`.
pub fn from_bytes(bytes: &[u8], dir: &Path, point_radius: Option<f32>) -> Result<LoadedFile, LoadError> {
    let container = data::container(bytes)?;
    let value: Value = serde_json::from_slice(container.json).map_err(|e| format!("not a readable glTF file: its JSON is broken ({e})"))?;
    let root = Obj::root(&value).map_err(|e| format!("not a readable glTF file: {e}"))?;
    check_asset(&root)?;
    let mut warnings = extensions(&root)?;
    let buffer_list = root.objs("buffers")?;
    let dataless = buffer_list
        .iter()
        .enumerate()
        .filter(|(i, b)| b.str("uri").ok().flatten().is_none() && !(*i == 0 && container.bin.is_some()))
        .count();
    if dataless > 0 {
        warnings.push(format!(
            "{} no data (no uri, and not the GLB's binary chunk): read as zeros",
            count(dataless, "buffer has", "buffers have")
        ));
    }
    let buffers = data::buffers(&buffer_list, container.bin, dir)?;
    let store = data::Store::new(buffers, &root.objs("bufferViews")?, root.objs("accessors")?, container.json.len())?;
    let mut looks = material::Looks::new(&root, dir)?;
    let (nodes, meshes, scenes) = (root.objs("nodes")?, root.objs("meshes")?, root.objs("scenes")?);
    let cameras = root.objs("cameras")?;
    let mut notes = Notes::default();
    let mut out = LoadedFile::default();
    let mut placed_cameras = Vec::new();
    // (mesh, primitive) to its place in `out.meshes`; None where it draws nothing.
    let mut seen: HashMap<(usize, usize), Option<usize>> = HashMap::new();
    for (i, world) in nodes::walk(&root, &nodes, &scenes)? {
        let node = &nodes[i];
        if let Some(c) = node.index("camera", cameras.len(), "cameras")? {
            placed_cameras.push((c, world, node.str("name")?));
        }
        let Some(m) = node.index("mesh", meshes.len(), "meshes")? else { continue };
        let placements = nodes::instances(node, world, &store)?.iter().map(|w| placement(w, &node.at)).collect::<Result<Vec<_>, _>>()?;
        let mesh = &meshes[m];
        let primitives = mesh.objs("primitives")?;
        store.charge((placements.len() * primitives.len() * std::mem::size_of::<Instance>()) as u64, &node.at)?;
        let label = [mesh.str("name")?, node.str("name")?]
            .into_iter()
            .flatten()
            .find(|s| !s.is_empty())
            .map_or_else(|| format!("mesh {m}"), str::to_string);
        for (p, prim) in primitives.iter().enumerate() {
            let at = match seen.get(&(m, p)) {
                Some(at) => *at,
                None => {
                    let name = if p > 0 { format!("{label} #{p}") } else { label.clone() };
                    let built = geometry::primitive(prim, &store, &mut looks, &mut notes, name)?;
                    let at = built.map(|mut b| {
                        b.instances.clear();
                        out.meshes.push(b);
                        out.meshes.len() - 1
                    });
                    seen.insert((m, p), at);
                    at
                }
            };
            if let Some(at) = at {
                out.meshes[at].instances.extend_from_slice(&placements);
            }
        }
    }
    if out.meshes.is_empty() && !meshes.is_empty() {
        // No scene places a mesh (a file of meshes without nodes, say): each is drawn once
        // where its vertices are, as a viewer of such a file shows it.
        let mut drawn = 0;
        for (m, mesh) in meshes.iter().enumerate() {
            let label = mesh.str("name")?.filter(|s| !s.is_empty()).map_or_else(|| format!("mesh {m}"), str::to_string);
            for (p, prim) in mesh.objs("primitives")?.iter().enumerate() {
                let name = if p > 0 { format!("{label} #{p}") } else { label.clone() };
                if let Some(mut b) = geometry::primitive(prim, &store, &mut looks, &mut notes, name)? {
                    b.instances = vec![Instance::IDENTITY];
                    out.meshes.push(b);
                    drawn += 1;
                }
            }
        }
        if drawn > 0 {
            warnings.push(format!(
                "no scene places any of the file's {}: each is drawn once where its vertices are",
                count(meshes.len(), "mesh", "meshes")
            ));
        }
    }
    size_points_and_lines(&mut out, point_radius);
    let (lo, hi) = bounds(&out.meshes).unwrap_or((DVec3::ZERO, DVec3::ZERO));
    for (k, (c, world, node_name)) in placed_cameras.into_iter().enumerate() {
        let name = [cameras[c].str("name")?, node_name]
            .into_iter()
            .flatten()
            .find(|s| !s.is_empty())
            .map_or_else(|| format!("camera {k}"), str::to_string);
        out.cameras.push(file_camera(&cameras[c], &world, name, lo, hi)?);
    }
    warnings.extend(notes_to_warnings(&root, &notes)?);
    out.warnings = warnings;
    Ok(out)
}

/// `asset.version` must be 2.x (and `minVersion`, if given, at most 2.0).
fn check_asset(root: &Obj<'_>) -> Result<(), String> {
    let asset = root.obj("asset")?.ok_or("not a readable glTF file: it has no 'asset' (a glTF 2.0 file says its version there)")?;
    let version = asset.str("version")?.ok_or("asset: the required field 'version' is missing")?;
    if version.split('.').next() != Some("2") {
        return Err(format!("asset.version is '{version}': oit reads glTF 2.0"));
    }
    if let Some(min) = asset.str("minVersion")? {
        if min != "2.0" {
            return Err(format!("asset.minVersion is '{min}': oit reads glTF 2.0"));
        }
    }
    Ok(())
}

/// Refuses required extensions oit lacks; names the used ones it ignores.
fn extensions(root: &Obj<'_>) -> Result<Vec<String>, String> {
    let names = |key: &str| -> Result<Vec<&str>, String> {
        root.array(key)?.iter().map(|v| v.as_str().ok_or_else(|| format!("{key}: expected an array of extension names"))).collect()
    };
    let missing: Vec<&str> = names("extensionsRequired")?.into_iter().filter(|e| !EXTENSIONS.contains(e)).collect();
    if !missing.is_empty() {
        return Err(format!(
            "extensionsRequired lists {}, which oit does not read (it reads {})",
            missing.join(", "),
            EXTENSIONS.join(", ")
        ));
    }
    let ignored: BTreeSet<&str> = names("extensionsUsed")?.into_iter().filter(|e| !EXTENSIONS.contains(e)).collect();
    Ok(if ignored.is_empty() {
        Vec::new()
    } else {
        let list: Vec<&str> = ignored.into_iter().collect();
        vec![format!(
            "{} oit does not read {} ignored: {}",
            count(list.len(), "extension", "extensions"),
            if list.len() == 1 { "is" } else { "are" },
            list.join(", ")
        )]
    })
}

fn notes_to_warnings(root: &Obj<'_>, notes: &Notes) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let animations = root.array("animations")?.len();
    if animations > 0 {
        out.push(format!("{} not drawn: oit shows the base pose", count(animations, "animation is", "animations are")));
    }
    let skins = root.array("skins")?.len();
    if skins > 0 {
        out.push(format!("{} not applied: oit shows the meshes where their nodes place them", count(skins, "skin is", "skins are")));
    }
    if notes.morphed > 0 {
        out.push(format!("{} morph targets: oit shows the base shape", count(notes.morphed, "primitive has", "primitives have")));
    }
    if !notes.sourceless.is_empty() {
        let n = notes.sourceless.len();
        out.push(format!("{} no image oit reads ('source'): drawn untextured", count(n, "texture has", "textures have")));
    }
    if let Some(first) = notes.leftover.first() {
        out.push(format!(
            "{} a vertex count the mode does not use whole ({first}{}): the leftover vertices are not drawn",
            count(notes.leftover.len(), "primitive has", "primitives have"),
            if notes.leftover.len() > 1 { ", ..." } else { "" }
        ));
    }
    if notes.downscaled > 0 {
        let n = notes.downscaled;
        let verb = if n == 1 { "is" } else { "are" };
        out.push(format!("{} larger than {} texels a side {verb} downscaled to fit", count(n, "image", "images"), super::MAX_TEXTURE_SIZE));
    }
    if notes.other_uv_sets > 0 {
        let n = notes.other_uv_sets;
        out.push(format!(
            "{} an emissive map on another TEXCOORD set than the base color's: read on the base color's set",
            count(n, "material has", "materials have")
        ));
    }
    if notes.positionless > 0 {
        out.push(format!("{} no POSITION: not drawn", count(notes.positionless, "primitive has", "primitives have")));
    }
    Ok(out)
}

/// Strands get their width and particles their radius from the scene's box diagonal (1 where
/// the scene is a point).
fn size_points_and_lines(out: &mut LoadedFile, point_radius: Option<f32>) {
    if out.meshes.iter().all(|m| m.mesh.primitive == Primitive::Triangles) {
        return;
    }
    let diagonal = bounds(&out.meshes).map_or(0.0, |(lo, hi)| (hi - lo).length()) as f32;
    let size = |fraction: f32| if diagonal > 0.0 && diagonal.is_finite() { diagonal * fraction } else { 1.0 };
    for m in &mut out.meshes {
        match &mut m.mesh.primitive {
            Primitive::Strands { widths, .. } => widths.fill(size(LINE_WIDTH)),
            Primitive::Particles { radii } => radii.fill(point_radius.unwrap_or_else(|| size(POINT_RADIUS))),
            Primitive::Triangles | Primitive::Gaussians { .. } => {}
        }
    }
}

/// A world transform as an instance (glTF transforms are affine; the last row is taken as
/// (0, 0, 0, 1) whatever rounding left there).
fn placement(world: &DMat4, at: &str) -> Result<Instance, String> {
    let mut rows = world.transpose().to_cols_array_2d();
    rows[3] = [0.0, 0.0, 0.0, 1.0];
    Instance::from_rows(rows, [1.0; 4]).map_err(|e| format!("{at}: its world transform: {e}"))
}

fn file_camera(camera: &Obj<'_>, world: &DMat4, name: String, lo: DVec3, hi: DVec3) -> Result<FileCamera, String> {
    // Cameras ignore scale (the specification); the view is the inverse of the node's rigid part.
    let (_, rotation, translation) = world.to_scale_rotation_translation();
    let view = DMat4::from_rotation_translation(rotation, translation).inverse();
    let farthest = (0..8)
        .map(|i| DVec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][i >> 1 & 1], [lo.z, hi.z][i >> 2]))
        .map(|c| (c - translation).length())
        .fold(0.0, f64::max);
    let at = &camera.at;
    let need = |o: &Obj<'_>, key: &str| o.num(key)?.ok_or_else(|| format!("{}: the required field '{key}' is missing", o.at));
    let projection = match camera.str("type")? {
        Some("perspective") => {
            let p = camera.obj("perspective")?.ok_or_else(|| format!("{at}: a perspective camera needs 'perspective'"))?;
            let near = need(&p, "znear")?;
            // Past the scene's farthest corner (twice the near plane where nothing is drawn).
            let far = p.num("zfar")?.unwrap_or((farthest * 1.01 + near).max(2.0 * near));
            Projection::Perspective { yfov: need(&p, "yfov")?, aspect: p.num("aspectRatio")?, near, far }
        }
        Some("orthographic") => {
            let o = camera.obj("orthographic")?.ok_or_else(|| format!("{at}: an orthographic camera needs 'orthographic'"))?;
            Projection::Orthographic { xmag: need(&o, "xmag")?, ymag: need(&o, "ymag")?, near: need(&o, "znear")?, far: need(&o, "zfar")? }
        }
        t => return Err(format!("{at}.type: {t:?} is not 'perspective' or 'orthographic'")),
    };
    let ok = match projection {
        Projection::Perspective { yfov, near, far, aspect } => {
            yfov > 0.0 && yfov < std::f64::consts::PI && near > 0.0 && far > near && aspect.is_none_or(|a| a > 0.0)
        }
        Projection::Orthographic { xmag, ymag, near, far } => xmag != 0.0 && ymag != 0.0 && far != near,
    };
    if !ok || !view.is_finite() {
        return Err(format!("{at} ('{name}') has an invalid projection {projection:?}"));
    }
    Ok(FileCamera { name, view: view.transpose().to_cols_array_2d(), projection })
}

#[cfg(test)]
mod tests;
