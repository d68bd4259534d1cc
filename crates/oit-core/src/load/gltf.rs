//! glTF 2.0 and GLB through the gltf crate's importer (buffers and images decoded): every
//! triangle primitive of the default scene (or of every scene), uploaded once and drawn as an
//! instance under each node's world transform that uses its mesh, with COLOR_0 times
//! baseColorFactor, baseColorTexture (sRGB) on its TEXCOORD set, normals, alphaMode
//! (OPAQUE, the default, gives an opaque mesh; MASK alpha 0 or 1 at alphaCutoff; BLEND
//! transparent) and doubleSided (true: lit on both sides; false: back faces culled); the
//! cameras of the node tree.

use std::path::Path;

use glam::{DMat4, DVec3};
use gltf::material::AlphaMode;

use super::{bounds, named, FileCamera, LoadedFile, NamedMesh, Projection};
use crate::scene::Instance;
use crate::shading::{Material, Texture, TextureMap};

pub fn load(path: &Path) -> Result<LoadedFile, String> {
    let (doc, buffers, images) = gltf::import(path).map_err(|e| format!("not a readable glTF file ({e})"))?;
    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => doc.nodes().collect(),
    };
    // Depth first, children after their parent, in file order.
    let mut stack: Vec<(gltf::Node, DMat4)> = roots.into_iter().rev().map(|n| (n, DMat4::IDENTITY)).collect();
    let mut out = LoadedFile::default();
    let mut cameras = Vec::new();
    // (mesh, primitive) to its place in `out.meshes`.
    let mut seen: std::collections::HashMap<(usize, usize), usize> = std::collections::HashMap::new();
    while let Some((node, parent)) = stack.pop() {
        let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(|x| x as f64)));
        let world = parent * local;
        stack.extend(node.children().collect::<Vec<_>>().into_iter().rev().map(|c| (c, world)));
        if let Some(camera) = node.camera() {
            cameras.push((camera, world, node.name().map(str::to_string)));
        }
        let Some(mesh) = node.mesh() else { continue };
        for (p, prim) in mesh.primitives().enumerate() {
            if prim.mode() != gltf::mesh::Mode::Triangles {
                continue;
            }
            let label = mesh.name().or(node.name()).map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
            let name = if p > 0 { format!("{label} #{p}") } else { label };
            let instance = placement(&world)?;
            if let Some(&at) = seen.get(&(mesh.index(), p)) {
                // A mesh another node drew already: one more instance of the same upload.
                out.meshes[at].instances.push(instance);
            } else if let Some(mut m) = primitive(&prim, &buffers, &images, name)? {
                m.instances = vec![instance];
                seen.insert((mesh.index(), p), out.meshes.len());
                out.meshes.push(m);
            }
        }
    }
    // A file without triangles is refused after loading; its cameras need no far plane then.
    let (lo, hi) = bounds(&out.meshes).unwrap_or((DVec3::ZERO, DVec3::ZERO));
    for (i, (camera, world, node_name)) in cameras.into_iter().enumerate() {
        let name = camera.name().map(str::to_string).or(node_name).unwrap_or_else(|| format!("camera {i}"));
        out.cameras.push(file_camera(&camera, &world, name, lo, hi)?);
    }
    Ok(out)
}

/// A node's world transform as an instance (glTF transforms are affine; the last row is
/// taken as (0, 0, 0, 1) whatever rounding left there).
fn placement(world: &DMat4) -> Result<Instance, String> {
    let mut rows = world.transpose().to_cols_array_2d();
    rows[3] = [0.0, 0.0, 0.0, 1.0];
    Instance::from_rows(rows, [1.0; 4]).map_err(|e| format!("a node's transform: {e}"))
}

fn primitive(
    prim: &gltf::Primitive<'_>,
    buffers: &[gltf::buffer::Data],
    images: &[gltf::image::Data],
    name: String,
) -> Result<Option<NamedMesh>, String> {
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| d.0.as_slice()));
    let Some(pos) = reader.read_positions() else { return Ok(None) };
    let positions: Vec<[f32; 3]> = pos.collect();
    let flat: Vec<u32> = match reader.read_indices() {
        Some(ix) => ix.into_u32().collect(),
        None => (0..positions.len() as u32).collect(),
    };
    // A mirroring node's front faces are clockwise: its instance says so (`Instance::mirrors`).
    let indices = flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let material = prim.material();
    let pbr = material.pbr_metallic_roughness();
    let factor = pbr.base_color_factor();
    let mut colors: Vec<[f32; 4]> = match reader.read_colors(0) {
        Some(c) => c.into_rgba_f32().map(|c| std::array::from_fn(|i| c[i] * factor[i])).collect(),
        None => vec![factor],
    };
    let mode = material.alpha_mode();
    let cutoff = material.alpha_cutoff().unwrap_or(0.5);
    let info = pbr.base_color_texture();
    let uvs: Option<Vec<[f32; 2]>> = info.as_ref().and_then(|t| reader.read_tex_coords(t.tex_coord())).map(|t| t.into_f32().collect());
    let texture = match (&info, &uvs) {
        (Some(t), Some(_)) => Some(TextureMap::new(std::sync::Arc::new(texture(&images[t.texture().source().index()])?))),
        _ => None,
    };
    if mode == AlphaMode::Opaque {
        colors.iter_mut().for_each(|c| c[3] = 1.0);
    }
    let alpha_cutoff = (mode == AlphaMode::Mask).then_some(cutoff);
    let mut mesh = named(name, positions, indices, colors, mode == AlphaMode::Opaque)?;
    if let Some(normals) = reader.read_normals() {
        // Zero normals (some exporters write them) are recomputed; instances carry the rest.
        let normals: Vec<[f32; 3]> =
            normals.map(|n| DVec3::from_array(n.map(|x| x as f64)).normalize_or_zero().as_vec3().to_array()).collect();
        if normals.len() == mesh.mesh.positions.len() && normals.iter().all(|n| n != &[0.0; 3]) {
            mesh.mesh.normals = normals;
        }
    }
    if texture.is_some() {
        mesh.mesh.uvs = uvs.unwrap_or_default();
    }
    let double = material.double_sided();
    mesh.mesh.material = Material { two_sided: double, cull_back_faces: !double, texture, alpha_cutoff, ..Default::default() };
    Ok(Some(mesh))
}

/// A decoded image to an 8-bit sRGB texture: 16-bit and float channels rounded to 8 bits;
/// gray ones spread to RGB; alpha 1 where there is none.
fn texture(image: &gltf::image::Data) -> Result<Texture, String> {
    use gltf::image::Format as F;
    let (channels, bytes) = match image.format {
        F::R8 => (1, 1),
        F::R8G8 => (2, 1),
        F::R8G8B8 => (3, 1),
        F::R8G8B8A8 => (4, 1),
        F::R16 => (1, 2),
        F::R16G16 => (2, 2),
        F::R16G16B16 => (3, 2),
        F::R16G16B16A16 => (4, 2),
        F::R32G32B32FLOAT => (3, 4),
        F::R32G32B32A32FLOAT => (4, 4),
    };
    let value = |b: &[u8]| -> u8 {
        match bytes {
            1 => b[0],
            2 => (u16::from_le_bytes([b[0], b[1]]) as f32 / 257.0).round() as u8,
            _ => (f32::from_le_bytes([b[0], b[1], b[2], b[3]]).clamp(0.0, 1.0) * 255.0).round() as u8,
        }
    };
    let rgba = image
        .pixels
        .chunks_exact(channels * bytes)
        .flat_map(|p| {
            let c = |i: usize| value(&p[i * bytes..(i + 1) * bytes]);
            let a = match channels {
                2 => c(1),
                4 => c(3),
                _ => 255,
            };
            if channels >= 3 {
                [c(0), c(1), c(2), a]
            } else {
                [c(0), c(0), c(0), a]
            }
        })
        .collect();
    Texture::from_rgba8(image.width, image.height, rgba, true).map_err(|e| e.to_string())
}

fn file_camera(camera: &gltf::Camera<'_>, world: &DMat4, name: String, lo: DVec3, hi: DVec3) -> Result<FileCamera, String> {
    // Cameras ignore scale (the spec); the view is the inverse of the node's rigid part.
    let (_, rotation, translation) = world.to_scale_rotation_translation();
    let view = DMat4::from_rotation_translation(rotation, translation).inverse();
    let eye = translation;
    let farthest = (0..8)
        .map(|i| DVec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][i >> 1 & 1], [lo.z, hi.z][i >> 2]))
        .map(|c| (c - eye).length())
        .fold(0.0, f64::max);
    let projection = match camera.projection() {
        gltf::camera::Projection::Perspective(p) => {
            let near = p.znear() as f64;
            let far = p.zfar().map_or(farthest * 1.01 + near, |f| f as f64);
            Projection::Perspective { yfov: p.yfov() as f64, aspect: p.aspect_ratio().map(|a| a as f64), near, far }
        }
        gltf::camera::Projection::Orthographic(o) => {
            Projection::Orthographic { xmag: o.xmag() as f64, ymag: o.ymag() as f64, near: o.znear() as f64, far: o.zfar() as f64 }
        }
    };
    let ok = match projection {
        Projection::Perspective { yfov, near, far, .. } => yfov > 0.0 && yfov < std::f64::consts::PI && near > 0.0 && far > near,
        Projection::Orthographic { xmag, ymag, near, far } => xmag != 0.0 && ymag != 0.0 && far != near,
    };
    if !ok || !view.is_finite() {
        return Err(format!("camera '{name}' has an invalid projection {projection:?}"));
    }
    Ok(FileCamera { name, view: view.transpose().to_cols_array_2d(), projection })
}
