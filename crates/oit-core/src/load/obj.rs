//! OBJ with its MTL: one mesh per object and material; the diffuse color `Kd` and texture
//! `map_Kd` (sRGB), the dissolve `d` (or `Tr` = 1 - d) and dissolve texture `map_d` as alpha,
//! vertex colors (`v x y z r g b`, sRGB), normals and UVs.

use std::path::Path;

use super::{named, srgb_to_linear, texture_map, NamedMesh, DEFAULT_RGB};
use crate::shading::{Material, TextureMap};

pub fn load(path: &Path) -> Result<Vec<NamedMesh>, String> {
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let (models, materials) = tobj::load_obj(path, &options).map_err(|e| format!("not a readable OBJ file ({e})"))?;
    // A missing or broken MTL leaves the meshes gray, as other viewers do.
    let materials = materials.unwrap_or_default();
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    for (i, model) in models.into_iter().enumerate() {
        let m = model.mesh;
        let positions: Vec<[f32; 3]> = m.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        let indices: Vec<[u32; 3]> = m.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        if indices.is_empty() {
            continue;
        }
        let material = m.material_id.and_then(|id| materials.get(id));
        let (rgb, alpha) = material.map_or((DEFAULT_RGB, 1.0), |mt| {
            let d = mt.dissolve.or_else(|| mt.unknown_param.get("Tr").and_then(|t| t.trim().parse::<f32>().ok()).map(|t| 1.0 - t));
            (mt.diffuse.map_or(DEFAULT_RGB, |d| d.map(srgb_to_linear)), d.unwrap_or(1.0).clamp(0.0, 1.0))
        });
        let colors = if !m.vertex_color.is_empty() && m.vertex_color.len() == m.positions.len() {
            m.vertex_color.chunks_exact(3).map(|c| [srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2]), alpha]).collect()
        } else {
            vec![[rgb[0], rgb[1], rgb[2], alpha]]
        };
        let texture = match material {
            Some(mt) if !m.texcoords.is_empty() => texture(dir, mt.diffuse_texture.as_deref(), mt.dissolve_texture.as_deref())?,
            _ => None,
        };
        let opaque = alpha == 1.0 && material.is_none_or(|mt| mt.dissolve_texture.is_none());
        let name = if model.name.is_empty() { format!("object {i}") } else { model.name };
        let mut mesh = named(name, positions, indices, colors, opaque)?;
        if m.normals.len() == m.positions.len() {
            mesh.mesh.normals = m.normals.chunks_exact(3).map(|n| [n[0], n[1], n[2]]).collect();
            // Zero normals (some exporters write them) are recomputed instead.
            if mesh.mesh.normals.iter().any(|n| n.iter().all(|&x| x == 0.0) || n.iter().any(|x| !x.is_finite())) {
                mesh.mesh.normals.clear();
            }
        }
        if m.texcoords.len() / 2 == mesh.mesh.positions.len() && texture.is_some() {
            // OBJ's v points up the image; the texture's row 0 is v = 0.
            mesh.mesh.uvs = m.texcoords.chunks_exact(2).map(|t| [t[0], 1.0 - t[1]]).collect();
        }
        mesh.mesh.material = Material { texture: texture.filter(|_| !mesh.mesh.uvs.is_empty()), ..Default::default() };
        out.push(mesh);
    }
    Ok(out)
}

/// `map_Kd` times `map_d` (whose first channel is the alpha), either optional.
fn texture(dir: &Path, diffuse: Option<&str>, dissolve: Option<&str>) -> Result<Option<TextureMap>, String> {
    let read = |name: &str| {
        let file = dir.join(name.trim());
        image::open(&file).map(|i| i.to_rgba8()).map_err(|e| format!("texture {}: {e}", file.display()))
    };
    let mask = dissolve.map(read).transpose()?;
    let mut image = match (diffuse, &mask) {
        (Some(d), _) => read(d)?,
        (None, Some(m)) => image::RgbaImage::from_pixel(m.width(), m.height(), image::Rgba([255; 4])),
        (None, None) => return Ok(None),
    };
    if let Some(mask) = mask {
        let (w, h) = (image.width(), image.height());
        let mask = image::imageops::resize(&mask, w, h, image::imageops::FilterType::Triangle);
        image.pixels_mut().zip(mask.pixels()).for_each(|(p, m)| p[3] = m[0]);
    }
    texture_map(image.width(), image.height(), image.into_raw()).map(Some)
}
