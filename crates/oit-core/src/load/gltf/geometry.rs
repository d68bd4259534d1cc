//! A mesh primitive to a drawable mesh: TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN as
//! triangles (a strip's odd triangles turned to keep its winding), POINTS as particles and
//! LINES, LINE_STRIP and LINE_LOOP as strands, with COLOR_0 times baseColorFactor, NORMAL and
//! the TEXCOORD set the material's maps read. Quantized attributes (KHR_mesh_quantization) are
//! read as the accessor says.

use super::data::{Accessor, Store};
use super::json::Obj;
use super::material::{Alpha, Looks};
use super::Notes;
use crate::load::{named, LoadError, NamedMesh};
use crate::scene::Mesh;
use crate::shading::Falloff;

/// The primitive modes, by code.
const MODES: [&str; 7] = ["POINTS", "LINES", "LINE_LOOP", "LINE_STRIP", "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"];

/// The primitive as a mesh (None when it has no POSITION: nothing to draw). Strands get width
/// 1 and particles radius 1 here; the caller sizes them once the scene's box is known.
pub(super) fn primitive(
    prim: &Obj<'_>,
    store: &Store<'_>,
    looks: &mut Looks<'_>,
    notes: &mut Notes,
    name: String,
) -> Result<Option<NamedMesh>, LoadError> {
    let attrs = prim.obj("attributes")?.ok_or_else(|| format!("{}: the required field 'attributes' is missing", prim.at))?;
    let n_acc = store.accessor_count();
    if !prim.array("targets")?.is_empty() {
        notes.morphed += 1;
    }
    let Some(pos) = attrs.index("POSITION", n_acc, "accessors")? else {
        notes.positionless += 1;
        return Ok(None);
    };
    let code = prim.uint_or("mode", 4)?;
    let mode = *MODES.get(code as usize).ok_or_else(|| format!("{}.mode: {code} is not a primitive mode (0 to 6)", prim.at))?;
    let pos = store.accessor(pos)?;
    let positions = pos.floats::<3>(store)?;
    if let Some(k) = positions.iter().position(|p| p.iter().any(|x| !x.is_finite())) {
        return Err(format!("{}: POSITION element {k} is {:?}, not finite", pos.at, positions[k]).into());
    }
    let n = positions.len();
    let attribute = |key: &str| -> Result<Option<Accessor<'_>>, String> {
        let Some(i) = attrs.index(key, n_acc, "accessors")? else { return Ok(None) };
        let a = store.accessor(i)?;
        if a.count != n {
            return Err(format!("{}.{key}: {} has {} elements but POSITION ({}) has {n}", attrs.at, a.at, a.count, pos.at));
        }
        Ok(Some(a))
    };
    // The vertex order the mode reads, and the accessor that gives it (for messages).
    let (order, source) = match prim.index("indices", n_acc, "accessors")? {
        Some(i) => {
            let a = store.accessor(i)?;
            let ix = a.uints(store)?;
            if let Some(k) = ix.iter().position(|&v| v as usize >= n) {
                return Err(format!("{}: index {} at {k} is past POSITION's {n} vertices", a.at, ix[k]).into());
            }
            (ix, a.at)
        }
        None => {
            store.charge(n as u64 * 16, &pos.at)?;
            ((0..n as u32).collect(), pos.at.clone())
        }
    };
    let look = looks.look(prim.index("material", looks.count(), "materials")?, store, notes)?;
    let mut colors: Vec<[f32; 4]> = match attribute("COLOR_0")? {
        Some(c) if c.components() == 3 => c.floats::<3>(store)?.into_iter().map(|[r, g, b]| [r, g, b, 1.0]).collect(),
        Some(c) => c.floats::<4>(store).map_err(|_| format!("{}: COLOR_0 is {}, not VEC3 or VEC4", c.at, c.kind))?,
        None => vec![[1.0; 4]],
    };
    for c in &mut colors {
        for (x, f) in c.iter_mut().zip(look.factor) {
            *x = (*x * f).clamp(0.0, 1.0);
        }
        if look.alpha == Alpha::Opaque {
            c[3] = 1.0;
        }
    }
    let opaque = look.alpha == Alpha::Opaque;
    let count = order.len();
    // A count the mode does not use whole is a warning in the validator, not an error: the
    // leftover vertices are not drawn, and the loader says so.
    let mut leftover = |what: &str| notes.leftover.push(format!("{source}: count {count} {what} for {mode}"));
    let pick = |v: &[[f32; 4]], at: &[u32]| if v.len() == 1 { v.to_vec() } else { at.iter().map(|&i| v[i as usize]).collect() };
    match mode {
        "POINTS" => {
            let centers = order.iter().map(|&i| positions[i as usize]).collect();
            let mesh =
                Mesh::particles(centers, vec![1.0], pick(&colors, &order), opaque, Falloff::Hard).map_err(|e| format!("'{name}': {e}"))?;
            return Ok(Some(NamedMesh::new(name, mesh)));
        }
        "LINES" | "LINE_STRIP" | "LINE_LOOP" => {
            let strands: Vec<Vec<u32>> = match mode {
                "LINES" => {
                    if count % 2 != 0 {
                        leftover("is not a multiple of 2");
                    }
                    // Segments that share their ends are chained into one polyline.
                    let mut out: Vec<Vec<u32>> = Vec::new();
                    for s in order.chunks_exact(2) {
                        match out.last_mut() {
                            Some(last) if last.last() == Some(&s[0]) => last.push(s[1]),
                            _ => out.push(s.to_vec()),
                        }
                    }
                    out
                }
                _ if count < 2 => {
                    leftover("is less than 2");
                    return Ok(None);
                }
                "LINE_STRIP" => vec![order],
                _ => {
                    let mut ring = order;
                    ring.push(ring[0]);
                    vec![ring]
                }
            };
            let counts = strands.iter().map(|s| s.len() as u32).collect();
            let flat: Vec<u32> = strands.concat();
            let points = flat.iter().map(|&i| positions[i as usize]).collect();
            let mesh = Mesh::strands(points, counts, vec![1.0], pick(&colors, &flat), opaque).map_err(|e| format!("'{name}': {e}"))?;
            return Ok(Some(NamedMesh::new(name, mesh)));
        }
        _ => {}
    }
    let triangles: Vec<[u32; 3]> = match mode {
        "TRIANGLES" => {
            if count % 3 != 0 {
                leftover("is not a multiple of 3");
            }
            order.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
        }
        _ if count < 3 => {
            leftover("is less than 3");
            return Ok(None);
        }
        // The specification's order: triangle i is (v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]);
        // repeated vertices (a strip's restarts) make no triangle.
        "TRIANGLE_STRIP" => (0..count - 2).map(|i| [order[i], order[i + 1 + i % 2], order[i + 2 - i % 2]]).filter(proper).collect(),
        _ => (0..count - 2).map(|i| [order[i + 1], order[i + 2], order[0]]).filter(proper).collect(),
    };
    let mut mesh = named(name, positions, triangles, colors, opaque)?;
    if let Some(a) = attribute("NORMAL")? {
        // Zero or broken normals (some exporters write them) are recomputed instead.
        let normals = a.floats::<3>(store)?;
        if normals.iter().all(|v| v.iter().all(|x| x.is_finite()) && v.iter().any(|&x| x != 0.0)) {
            mesh.mesh.normals = normals;
        }
    }
    let mut material = look.material;
    if let Some(set) = look.uv_set {
        match attribute(&format!("TEXCOORD_{set}"))? {
            Some(a) => mesh.mesh.uvs = a.floats::<2>(store)?,
            // Maps without UVs cannot be placed: drawn without them, as other viewers do.
            None => {
                material.texture = None;
                material.emissive_texture = None;
            }
        }
    }
    mesh.mesh.material = material;
    Ok(Some(mesh))
}

/// A triangle of three different vertices.
fn proper(t: &[u32; 3]) -> bool {
    t[0] != t[1] && t[1] != t[2] && t[0] != t[2]
}
