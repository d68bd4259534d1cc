//! Materials, textures, images and samplers: baseColorFactor and baseColorTexture, alphaMode
//! and alphaCutoff, doubleSided, emissiveFactor and emissiveTexture with
//! KHR_materials_emissive_strength, each texture's sampler and KHR_texture_transform. Each
//! glTF image is decoded once (PNG or JPEG, from a bufferView, a file or a data URI) into one
//! shared `Arc<Texture>`, so it is uploaded once however many materials use it.

use std::path::Path;
use std::sync::Arc;

use super::data::{uri_bytes, Store};
use super::json::Obj;
use super::Notes;
use crate::load::{decode_image, fit_texture, LoadError};
use crate::shading::{Material, Sampler, Texture, TextureMap};

/// glTF's alphaMode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Alpha {
    Opaque,
    Mask,
    Blend,
}

/// A glTF material as a primitive draws it.
#[derive(Clone, Debug)]
pub(super) struct DrawnMaterial {
    /// baseColorFactor: multiplies COLOR_0.
    pub factor: [f32; 4],
    pub alpha: Alpha,
    /// Sides, maps, emission and the MASK cutoff; shading is the caller's.
    pub material: Material,
    /// The TEXCOORD set the maps read (None: the material has no map).
    pub uv_set: Option<u64>,
}

/// The document's materials, textures, images and samplers, decoded as primitives ask.
pub(super) struct Looks<'a> {
    materials: Vec<Obj<'a>>,
    textures: Vec<Obj<'a>>,
    images: Vec<Obj<'a>>,
    samplers: Vec<Obj<'a>>,
    dir: &'a Path,
    looks: Vec<Option<DrawnMaterial>>,
    decoded: Vec<Option<Arc<Texture>>>,
    texel_bytes: u64,
}

/// The most bytes of decoded images one file may ask for (each image's own size is bounded by
/// the decoder's limit): 16 images of 8192 x 8192.
const MAX_TEXEL_BYTES: u64 = 4 << 30;

impl<'a> Looks<'a> {
    pub fn new(root: &Obj<'a>, dir: &'a Path) -> Result<Self, String> {
        let (materials, images) = (root.objs("materials")?, root.objs("images")?);
        Ok(Self {
            looks: vec![None; materials.len()],
            decoded: vec![None; images.len()],
            materials,
            textures: root.objs("textures")?,
            images,
            samplers: root.objs("samplers")?,
            dir,
            texel_bytes: 0,
        })
    }

    pub fn count(&self) -> usize {
        self.materials.len()
    }

    /// Material `index` (None: the specification's default, white, OPAQUE and single-sided).
    pub fn look(&mut self, index: Option<usize>, store: &Store<'_>, notes: &mut Notes) -> Result<DrawnMaterial, LoadError> {
        let Some(i) = index else {
            return Ok(DrawnMaterial { factor: [1.0; 4], alpha: Alpha::Opaque, material: sides(false), uv_set: None });
        };
        if let Some(look) = &self.looks[i] {
            return Ok(look.clone());
        }
        let look = self.read(i, store, notes)?;
        self.looks[i] = Some(look.clone());
        Ok(look)
    }

    fn read(&mut self, i: usize, store: &Store<'_>, notes: &mut Notes) -> Result<DrawnMaterial, LoadError> {
        let m = self.materials[i].clone();
        let pbr = m.obj("pbrMetallicRoughness")?;
        let factor = match &pbr {
            Some(p) => p.nums::<4>("baseColorFactor")?.unwrap_or([1.0; 4]),
            None => [1.0; 4],
        };
        let factor = factor.map(|x| x as f32);
        if factor.iter().any(|x| !(0.0..=1.0).contains(x)) {
            return Err(format!("{}.pbrMetallicRoughness.baseColorFactor: {factor:?} is outside [0, 1]", m.at).into());
        }
        let alpha = match m.str("alphaMode")?.unwrap_or("OPAQUE") {
            "OPAQUE" => Alpha::Opaque,
            "MASK" => Alpha::Mask,
            "BLEND" => Alpha::Blend,
            other => return Err(format!("{}.alphaMode: '{other}' is not OPAQUE, MASK or BLEND", m.at).into()),
        };
        let cutoff = m.num("alphaCutoff")?.unwrap_or(0.5);
        if cutoff < 0.0 {
            return Err(format!("{}.alphaCutoff: {cutoff} is below 0", m.at).into());
        }
        let mut material = sides(m.bool("doubleSided")?.unwrap_or(false));
        material.alpha_cutoff = (alpha == Alpha::Mask).then_some(cutoff as f32);
        let base = match pbr.as_ref().map(|p| p.obj("baseColorTexture")).transpose()?.flatten() {
            Some(info) => self.map(&info, store, notes)?,
            None => None,
        };
        let strength = match m.extension("KHR_materials_emissive_strength")? {
            Some(e) => e.num("emissiveStrength")?.unwrap_or(1.0),
            None => 1.0,
        };
        let emissive = m.nums::<3>("emissiveFactor")?.unwrap_or([0.0; 3]).map(|x| (x * strength) as f32);
        if emissive.iter().any(|x| !(*x >= 0.0 && x.is_finite())) {
            return Err(format!("{}: emissiveFactor times emissiveStrength {emissive:?} must be finite and >= 0", m.at).into());
        }
        material.emissive = emissive;
        let glow = match m.obj("emissiveTexture")? {
            Some(info) if emissive != [0.0; 3] => self.map(&info, store, notes)?,
            _ => None,
        };
        let uv_set = match (&base, &glow) {
            (Some((_, b)), Some((_, g))) => {
                if b != g {
                    notes.other_uv_sets += 1;
                }
                Some(*b)
            }
            (Some((_, s)), None) | (None, Some((_, s))) => Some(*s),
            (None, None) => None,
        };
        material.texture = base.map(|(t, _)| t);
        material.emissive_texture = glow.map(|(t, _)| t);
        Ok(DrawnMaterial { factor, alpha, material, uv_set })
    }

    /// A textureInfo: the shared image, its sampler and UV transform, and its TEXCOORD set;
    /// None for a texture without an image oit reads.
    fn map(&mut self, info: &Obj<'_>, store: &Store<'_>, notes: &mut Notes) -> Result<Option<(TextureMap, u64)>, LoadError> {
        let t = info.required_index("index", self.textures.len(), "textures")?;
        let texture = self.textures[t].clone();
        let Some(source) = texture.index("source", self.images.len(), "images")? else {
            notes.sourceless.insert(t);
            return Ok(None);
        };
        let sampler = match texture.index("sampler", self.samplers.len(), "samplers")? {
            Some(s) => {
                let o = &self.samplers[s];
                let wrap = |key| o.code(key).map(|c| c.unwrap_or(10497));
                Sampler::from_gltf(o.code("magFilter")?, o.code("minFilter")?, wrap("wrapS")?, wrap("wrapT")?)
                    .map_err(|e| format!("{}: {e}", o.at))?
            }
            None => Sampler::default(),
        };
        let image = self.image(source, store, notes)?;
        let mut set = info.uint_or("texCoord", 0)?;
        let mut map = TextureMap::new(image);
        map.sampler = sampler;
        if let Some(x) = info.extension("KHR_texture_transform")? {
            let [ox, oy] = x.nums::<2>("offset")?.unwrap_or([0.0; 2]);
            let [sx, sy] = x.nums::<2>("scale")?.unwrap_or([1.0; 2]);
            let r = x.num("rotation")?.unwrap_or(0.0);
            let (sin, cos) = r.sin_cos();
            // Translation times rotation times scale, as the extension defines them.
            map.transform = [[cos * sx, sin * sy, ox], [-sin * sx, cos * sy, oy]].map(|row| row.map(|v| v as f32));
            if map.transform.iter().flatten().any(|v| !v.is_finite()) {
                return Err(format!("{}: the UV transform {:?} is not finite", x.at, map.transform).into());
            }
            set = x.uint("texCoord")?.unwrap_or(set);
        }
        Ok(Some((map, set)))
    }

    /// Image `i`, decoded once.
    fn image(&mut self, i: usize, store: &Store<'_>, notes: &mut Notes) -> Result<Arc<Texture>, LoadError> {
        if let Some(t) = &self.decoded[i] {
            return Ok(t.clone());
        }
        let o = self.images[i].clone();
        let owned;
        let bytes: &[u8] = match (o.str("uri")?, o.index("bufferView", usize::MAX, "bufferViews")?) {
            (Some(uri), _) => {
                owned = uri_bytes(uri, self.dir, &o.at)?;
                &owned
            }
            (None, Some(v)) => store.view_bytes(v, &o.at)?,
            (None, None) => return Err(format!("{} has neither a uri nor a bufferView: an image needs one", o.at).into()),
        };
        let image = decode_image(bytes).map_err(|e| format!("{}: {e}", o.at))?;
        self.texel_bytes += image.as_raw().len() as u64;
        if self.texel_bytes > MAX_TEXEL_BYTES {
            return Err(format!(
                "{}: the images decoded so far take {} bytes, past the {MAX_TEXEL_BYTES} oit decodes from one file",
                o.at, self.texel_bytes
            )
            .into());
        }
        let (image, downscaled) = fit_texture(image);
        notes.downscaled += downscaled as usize;
        let texture =
            Arc::new(Texture::from_rgba8(image.width(), image.height(), image.into_raw(), true).map_err(|e| format!("{}: {e}", o.at))?);
        self.decoded[i] = Some(texture.clone());
        Ok(texture)
    }
}

/// The default material with glTF's sidedness: `doubleSided` lights both sides, else back
/// faces are culled.
fn sides(double: bool) -> Material {
    Material { two_sided: double, cull_back_faces: !double, ..Default::default() }
}
