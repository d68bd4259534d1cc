//! The one loader behind every entry point (`oit.Scene.from_file`, `python -m oit render` and
//! `compare`, the viewer, the bench): OBJ with MTL, glTF/GLB, PLY and STL to meshes with their
//! materials, and the file's cameras. A file is followed as it is written (docs/loading.md
//! lists what each format brings); `viewing_alpha` is the one convenience the command line
//! and the viewer add on top.

mod gltf;
mod keys;
mod mtl;
mod obj;
mod ply;
mod stl;
mod text;

use std::path::Path;

use glam::DVec3;

use crate::error::{invalid, OitError, Result};
use crate::scene::{Instance, Mesh, Scene};
pub(crate) use crate::shading::srgb_to_linear;
use crate::shading::{Material, Shading, Texture, TextureMap};

/// The alpha every mesh gets when nothing in a file is transparent (the command line and the
/// viewer; `Scene.from_file` keeps the file's).
pub const VIEWING_ALPHA: f32 = 0.4;
/// Color of meshes whose file gives none: light gray, linear.
pub const DEFAULT_RGB: [f32; 3] = [0.8, 0.8, 0.8];
/// The ambient term a loaded scene gets (docs/shading.md): the lights are the headlight.
pub const AMBIENT: [f32; 3] = [0.1; 3];
/// The largest side of a loaded image: larger ones are downscaled, keeping their aspect, with
/// a warning (the side every adapter can sample).
pub const MAX_TEXTURE_SIZE: u32 = Texture::MAX_SIZE;
/// The extensions `load_file` reads, as its messages list them.
pub const FORMATS: &str = ".obj (with .mtl), .gltf, .glb, .ply and .stl";

/// A mesh of a file under its name, drawn once for each of its instances (a glTF mesh that
/// several nodes use; one identity instance elsewhere).
#[derive(Clone, Debug)]
pub struct NamedMesh {
    pub name: String,
    pub mesh: Mesh,
    pub instances: Vec<Instance>,
}

impl NamedMesh {
    /// A mesh drawn once, where its vertices are.
    pub fn new(name: String, mesh: Mesh) -> Self {
        Self { name, mesh, instances: vec![Instance::IDENTITY] }
    }
}

/// How a file camera projects; `far` is the file's or, where it gives none (glTF's infinite
/// perspective), one past the scene's farthest corner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// `yfov` in radians; `aspect` the file's width / height, if it gives one.
    Perspective { yfov: f64, aspect: Option<f64>, near: f64, far: f64 },
    /// Half the view's width and height.
    Orthographic { xmag: f64, ymag: f64, near: f64, far: f64 },
}

/// A camera of the file: world to camera (looking down -z, y up) and its projection.
#[derive(Clone, Debug)]
pub struct FileCamera {
    pub name: String,
    /// Row-major (`p_camera = view @ [x, y, z, 1]`).
    pub view: [[f64; 4]; 4],
    pub projection: Projection,
}

/// What a surface is shaded with where the file does not say (it never says in these
/// formats): smooth with the file's normals (computed where it has none), a little specular.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    pub shading: Shading,
    pub specular: f32,
    /// The radius of a point cloud's particles (a PLY of points only); None: 1/200 of its
    /// box's diagonal.
    pub point_radius: Option<f32>,
}

impl Default for Surface {
    fn default() -> Self {
        Self { shading: Shading::Smooth, specular: 0.25, point_radius: None }
    }
}

/// Everything a file holds, in the file's order, and what of it is not drawn.
#[derive(Clone, Debug, Default)]
pub struct LoadedFile {
    pub meshes: Vec<NamedMesh>,
    pub cameras: Vec<FileCamera>,
    /// One sentence a feature the file uses and oit does not draw, with how many objects use it
    /// ("2 animations are not drawn: oit shows the base pose"); each feature said once.
    pub warnings: Vec<String>,
}

/// Why a format's loader refused a file: `load_file` prefixes the file's path.
#[derive(Clone, Debug, PartialEq)]
pub enum LoadError {
    /// The file breaks its format's rules: the message names the object and the rule.
    Invalid(String),
    /// A file it refers to (a buffer, an image, a material library) is not there: the message
    /// names it and the object that refers to it.
    NotFound(String),
}

impl From<String> for LoadError {
    fn from(e: String) -> Self {
        Self::Invalid(e)
    }
}

impl From<&str> for LoadError {
    fn from(e: &str) -> Self {
        Self::Invalid(e.to_string())
    }
}

impl LoadError {
    fn at(self, path: &Path) -> OitError {
        match self {
            Self::Invalid(e) => invalid!("{}: {e}", path.display()),
            Self::NotFound(e) => OitError::NotFound(format!("{}: {e}", path.display())),
        }
    }
}

/// Reads `path` by its extension. Bad files are `InvalidInput` naming the file and the fault.
pub fn load_file(path: &Path, surface: Surface) -> Result<LoadedFile> {
    if !path.is_file() {
        return Err(OitError::NotFound(format!("no such file: {}: check the path", path.display())));
    }
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_lowercase();
    let fail = |e: LoadError| e.at(path);
    let mut file = match ext.as_str() {
        "obj" => obj::read(path, surface.point_radius).map_err(fail)?,
        "ply" => LoadedFile { meshes: vec![ply::load_ply(path).map_err(fail)?], ..Default::default() },
        "stl" => LoadedFile { meshes: stl::read(path).map_err(fail)?, ..Default::default() },
        "gltf" | "glb" => gltf::load_with(path, surface.point_radius).map_err(fail)?,
        _ => return Err(invalid!("{}: unknown file type '.{ext}': oit reads {FORMATS}", path.display())),
    };
    let points = |m: &Mesh| m.indices.is_empty() && !m.positions.is_empty() && m.primitive == crate::primitive::Primitive::Triangles;
    if ext == "ply" && file.meshes.iter().all(|m| points(&m.mesh)) {
        // A point cloud: hard discs facing the eye, one a point.
        for m in &mut file.meshes {
            m.mesh = points_as_particles(std::mem::take(&mut m.mesh), surface.point_radius).map_err(|e| fail(e.to_string().into()))?;
        }
        return Ok(file);
    }
    let drawn = |m: &NamedMesh| !m.mesh.indices.is_empty() || m.mesh.primitive != crate::primitive::Primitive::Triangles;
    if !file.meshes.iter().any(drawn) {
        return Err(invalid!(
            "{} has nothing to draw: no triangles, lines or points (oit draws triangle meshes, lines as strands and points as particles)",
            path.display()
        ));
    }
    file.meshes.retain(drawn);
    for m in &mut file.meshes {
        if m.mesh.primitive == crate::primitive::Primitive::Triangles {
            restyle(&mut m.mesh, surface).map_err(|e| invalid!("{}: '{}': {e}", path.display(), m.name))?;
        }
    }
    Ok(file)
}

/// A mesh of points only as a particle set of hard discs of `radius` (None: 1/200 of the
/// points' box diagonal, or 1 where the points coincide), its colors kept.
fn points_as_particles(mesh: Mesh, radius: Option<f32>) -> Result<Mesh> {
    let radius = radius.unwrap_or_else(|| {
        let b = crate::scene::placed_bounds(std::iter::once((&mesh, &[crate::scene::Instance::IDENTITY][..])));
        let diagonal = b.map_or(0.0, |(lo, hi)| (hi - lo).length()) as f32;
        if diagonal > 0.0 {
            diagonal / 200.0
        } else {
            1.0
        }
    });
    Mesh::particles(mesh.positions, vec![radius], mesh.colors, mesh.opaque, crate::shading::Falloff::Hard)
}

/// Applies `surface` to a loaded mesh, keeping what the file gave (normals, UVs, texture,
/// sidedness); flat and unlit shading drop the normals.
fn restyle(mesh: &mut Mesh, surface: Surface) -> Result<()> {
    let normals = (surface.shading == Shading::Smooth && !mesh.normals.is_empty()).then(|| std::mem::take(&mut mesh.normals));
    let uvs = (!mesh.uvs.is_empty()).then(|| std::mem::take(&mut mesh.uvs));
    let material = Material { shading: surface.shading, specular: surface.specular, ..std::mem::take(&mut mesh.material) };
    *mesh = std::mem::take(mesh).with_surface(normals, uvs, material)?;
    Ok(())
}

/// Whether a mesh blends: not opaque, and some vertex alpha, texel alpha or its opacity lies
/// strictly between 0 and 1 (alpha-tested surfaces, 0 or 1 everywhere, do not).
pub fn blends(mesh: &Mesh) -> bool {
    let partial = |a: f32| a > 0.0 && a < 1.0;
    let texture = mesh.material.texture.as_ref().is_some_and(|t| t.image.has_partial_alpha());
    let tested = mesh.material.alpha_cutoff.is_some();
    !mesh.opaque && !tested && (partial(mesh.material.opacity) || texture || mesh.colors.iter().any(|c| partial(c[3])))
}

/// Makes every mesh transparent at `alpha` (vertex alpha; textures keep theirs).
pub fn set_alpha(meshes: &mut [NamedMesh], alpha: f32) -> Result<()> {
    if !(0.0..=1.0).contains(&alpha) {
        return Err(invalid!("alpha {alpha} is outside [0, 1]"));
    }
    for m in meshes {
        m.mesh.opaque = false;
        m.mesh.colors.iter_mut().for_each(|c| c[3] = alpha);
    }
    Ok(())
}

/// The command line's and the viewer's alpha: `alpha` for every mesh when given; otherwise,
/// when nothing in the file blends, VIEWING_ALPHA for every mesh, and the sentence saying so.
pub fn viewing_alpha(meshes: &mut [NamedMesh], alpha: Option<f32>) -> Result<Option<String>> {
    if let Some(a) = alpha {
        set_alpha(meshes, a)?;
        return Ok(None);
    }
    if meshes.iter().any(|m| blends(&m.mesh)) {
        return Ok(None);
    }
    set_alpha(meshes, VIEWING_ALPHA)?;
    Ok(Some(format!("nothing in the file is transparent: every mesh is drawn at alpha {VIEWING_ALPHA} (--alpha A sets another)")))
}

impl LoadedFile {
    /// The meshes as a scene, in file order, with the loader's ambient term.
    pub fn scene(&self) -> Scene {
        let mut scene = Scene::new();
        for m in &self.meshes {
            scene.add_placed(m.mesh.clone(), m.instances.clone());
        }
        scene.set_ambient(AMBIENT).expect("a valid ambient term");
        scene
    }
}

/// A validated mesh (colors clamped to [0, 1]) under its name.
pub(crate) fn named(
    name: String,
    positions: Vec<[f32; 3]>,
    indices: Vec<[u32; 3]>,
    colors: Vec<[f32; 4]>,
    opaque: bool,
) -> std::result::Result<NamedMesh, String> {
    let colors = colors.into_iter().map(|c| c.map(|x| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) })).collect();
    let mesh = Mesh::new(positions, indices, colors, opaque).map_err(|e| format!("'{name}': {e}"))?;
    Ok(NamedMesh::new(name, mesh))
}

/// An 8-bit sRGB color image (linear alpha), 4 bytes a texel row-major, as a texture with the
/// default sampler (repeat wrap, trilinear).
pub(crate) fn texture_map(width: u32, height: u32, rgba: Vec<u8>) -> std::result::Result<TextureMap, String> {
    let image = Texture::from_rgba8(width, height, rgba, true).map_err(|e| e.to_string())?;
    Ok(TextureMap::new(std::sync::Arc::new(image)))
}

/// A PNG or JPEG to 8-bit RGBA, with the decoder's allocation bounded (1 GiB); a decoder that
/// panics on a broken image is an error, not a crash. Every format's images come through here.
pub(crate) fn decode_image(bytes: &[u8]) -> std::result::Result<image::RgbaImage, String> {
    let run = || -> std::result::Result<image::RgbaImage, String> {
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format().map_err(|e| e.to_string())?;
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(1 << 30);
        reader.limits(limits);
        Ok(reader.decode().map_err(|e| format!("not an image oit reads (PNG or JPEG): {e}"))?.into_rgba8())
    };
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)).unwrap_or_else(|_| Err("the image decoder failed on it".to_string()))
}

/// `image` scaled to fit MAX_TEXTURE_SIZE a side, keeping its aspect, and whether it had to be.
pub(crate) fn fit_texture(image: image::RgbaImage) -> (image::RgbaImage, bool) {
    let (w, h) = (image.width(), image.height());
    if w.max(h) <= MAX_TEXTURE_SIZE {
        return (image, false);
    }
    let scale = MAX_TEXTURE_SIZE as f64 / w.max(h) as f64;
    let side = |x: u32| ((x as f64 * scale).round() as u32).clamp(1, MAX_TEXTURE_SIZE);
    (image::imageops::resize(&image, side(w), side(h), image::imageops::FilterType::Triangle), true)
}

/// The box around every mesh's instances (file cameras without a far plane, the viewer's fit);
/// None when nothing is drawn.
pub fn bounds(meshes: &[NamedMesh]) -> Option<(DVec3, DVec3)> {
    crate::scene::placed_bounds(meshes.iter().map(|m| (&m.mesh, m.instances.as_slice())))
}

#[cfg(test)]
mod formats_tests;
#[cfg(test)]
mod tests;
