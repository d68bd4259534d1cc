//! MTL, the material libraries an OBJ names: `Kd` and `map_Kd` (sRGB), the dissolve `d`, `Tr`
//! and `map_d` as alpha, each material under its `newmtl` name. A library that is not there
//! is a warning of the OBJ; an image a library names that is not there is `NotFound` naming
//! it and the library's line.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::text::{number, rest, words, Lines};
use super::{decode_image, fit_texture, texture_map, LoadError};
use crate::shading::TextureMap;

/// A material of a library: what oit reads of it.
#[derive(Default)]
pub struct Mtl {
    pub rgb: Option<[f32; 3]>,
    pub dissolve: Option<f32>,
    pub tr: Option<f32>,
    /// (image, the MTL file and line naming it).
    pub map_kd: Option<(PathBuf, String)>,
    pub map_d: Option<(PathBuf, String)>,
}

impl Mtl {
    /// The rule of docs/loading.md: `d` wins; `Tr` alone is 1 - d, except `Tr 1`, which
    /// MeshLab and several exporters write meaning opaque, and which would otherwise hide
    /// the mesh.
    pub fn alpha(&self) -> f32 {
        let a = match (self.dissolve, self.tr) {
            (Some(d), _) => d,
            (None, Some(t)) if t >= 1.0 => 1.0,
            (None, Some(t)) => 1.0 - t,
            (None, None) => 1.0,
        };
        a.clamp(0.0, 1.0)
    }
}

/// The materials of an OBJ's libraries by name, and the libraries it names that are not there.
#[derive(Default)]
pub struct Materials {
    pub by_name: HashMap<String, Mtl>,
    pub missing: Vec<String>,
}

impl Materials {
    /// `mtllib a.mtl [b.mtl ...]`: the whole text as one name first (names may hold spaces).
    pub fn library(&mut self, names: &str, line: usize, dir: &Path) -> Result<(), LoadError> {
        if names.is_empty() {
            return Ok(());
        }
        let whole = dir.join(names.replace('\\', "/"));
        let files: Vec<String> =
            if whole.is_file() { vec![names.to_string()] } else { names.split_whitespace().map(str::to_string).collect() };
        for name in files {
            let file = dir.join(name.replace('\\', "/"));
            if !file.is_file() {
                // OBJ files are often shared without their .mtl: drawn gray, as other viewers do.
                self.missing.push(format!("'{name}' (line {line})"));
                continue;
            }
            let label = file.file_name().map_or(name.clone(), |n| n.to_string_lossy().into_owned());
            self.read(&file, &label)?;
        }
        Ok(())
    }

    fn read(&mut self, file: &Path, label: &str) -> Result<(), LoadError> {
        let at = |n: usize| move |e: String| LoadError::Invalid(format!("{label}, line {n}: {e}"));
        let f = std::fs::File::open(file).map_err(|e| LoadError::Invalid(format!("cannot read {label} ({e})")))?;
        let dir = file.parent().unwrap_or(Path::new("."));
        let mut lines = Lines::new(f);
        let mut current: Option<String> = None;
        while let Some((n, line)) = lines.next().map_err(|e| LoadError::Invalid(format!("cannot read {label} ({e})")))? {
            let mut t = words(line);
            let Some(key) = t.next() else { continue };
            if key == b"newmtl" {
                let name = rest(line);
                self.by_name.insert(name.clone(), Mtl::default());
                current = Some(name);
                continue;
            }
            let Some(m) = current.as_ref().and_then(|c| self.by_name.get_mut(c)) else { continue };
            match key {
                b"Kd" => {
                    let r = t.next();
                    if r == Some(b"spectral") || r == Some(b"xyz") {
                        continue;
                    }
                    let r = number(r, "Kd's red").map_err(at(n))?;
                    let (g, b) = match (t.next(), t.next()) {
                        (Some(g), Some(b)) => (number(Some(g), "Kd's green").map_err(at(n))?, number(Some(b), "Kd's blue").map_err(at(n))?),
                        _ => (r, r),
                    };
                    m.rgb = Some([r, g, b]);
                }
                b"d" => {
                    let v = t.find(|x| *x != b"-halo");
                    m.dissolve = Some(number(v, "d").map_err(at(n))?);
                }
                b"Tr" => m.tr = Some(number(t.next(), "Tr").map_err(at(n))?),
                b"map_Kd" | b"map_d" => {
                    let name = map_file(t);
                    if name.is_empty() {
                        continue;
                    }
                    let entry = (dir.join(name.replace('\\', "/")), format!("{label}, line {n}"));
                    if key == b"map_Kd" {
                        m.map_kd = Some(entry);
                    } else {
                        m.map_d = Some(entry);
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }
}

/// The file name of a `map_*` statement after its options (`-s 1 1 1`, `-bm 0.5`, ...).
fn map_file<'a>(mut t: impl Iterator<Item = &'a [u8]>) -> String {
    let mut words = Vec::new();
    while let Some(w) = t.next() {
        let args = match w {
            b"-blendu" | b"-blendv" | b"-cc" | b"-clamp" | b"-imfchan" | b"-bm" | b"-boost" | b"-texres" | b"-type" => 1,
            b"-mm" => 2,
            b"-o" | b"-s" | b"-t" => 3,
            _ if words.is_empty() && w.starts_with(b"-") && w.len() > 1 && !w[1].is_ascii_digit() => 0,
            _ => {
                words.push(String::from_utf8_lossy(w).into_owned());
                continue;
            }
        };
        // -o/-s/-t take one to three numbers.
        let mut left = args;
        let mut peek = Vec::new();
        while left > 0 {
            let Some(x) = t.next() else { break };
            if args == 3 && left < 3 && std::str::from_utf8(x).ok().and_then(|s| s.parse::<f32>().ok()).is_none() {
                peek.push(String::from_utf8_lossy(x).into_owned());
                break;
            }
            left -= 1;
        }
        words.extend(peek);
    }
    words.join(" ")
}

/// `map_Kd` times `map_d` (whose first channel is the alpha), either optional, and whether it
/// was downscaled to MAX_TEXTURE_SIZE.
pub fn load_texture(
    diffuse: Option<&(PathBuf, String)>,
    dissolve: Option<&(PathBuf, String)>,
) -> Result<(Option<TextureMap>, bool), LoadError> {
    let read = |(file, at): &(PathBuf, String)| -> Result<image::RgbaImage, LoadError> {
        if !file.is_file() {
            return Err(LoadError::NotFound(format!("{at}: the image {} is not there", file.display())));
        }
        let unreadable = |e: String| LoadError::Invalid(format!("{at}: the image {} is not readable ({e})", file.display()));
        let bytes = std::fs::read(file).map_err(|e| unreadable(e.to_string()))?;
        decode_image(&bytes).map_err(unreadable)
    };
    let mask = dissolve.map(read).transpose()?;
    let mut image = match (diffuse, &mask) {
        (Some(d), _) => read(d)?,
        (None, Some(m)) => image::RgbaImage::from_pixel(m.width(), m.height(), image::Rgba([255; 4])),
        (None, None) => return Ok((None, false)),
    };
    if let Some(mask) = mask {
        let (w, h) = (image.width(), image.height());
        let mask = image::imageops::resize(&mask, w, h, image::imageops::FilterType::Triangle);
        image.pixels_mut().zip(mask.pixels()).for_each(|(p, m)| p[3] = m[0]);
    }
    let (image, large) = fit_texture(image);
    let at = diffuse.or(dissolve).map_or(String::new(), |x| x.1.clone());
    let map = texture_map(image.width(), image.height(), image.into_raw()).map_err(|e| format!("{at}: {e}"))?;
    Ok((Some(map), large))
}
