//! How a texture is sampled: glTF's wrap modes and filters, and the bits the shaders read.

use crate::error::{invalid, Result};

/// How a texture coordinate outside [0, 1] is brought back (glTF's `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    #[default]
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

impl Wrap {
    /// glTF's code (10497, 33648, 33071).
    pub fn from_gltf(code: u32) -> Result<Self> {
        match code {
            10497 => Ok(Self::Repeat),
            33648 => Ok(Self::MirroredRepeat),
            33071 => Ok(Self::ClampToEdge),
            _ => Err(invalid!("wrap mode {code} is not 10497 (REPEAT), 33648 (MIRRORED_REPEAT) or 33071 (CLAMP_TO_EDGE)")),
        }
    }

    /// Texel `i` of a row of `n` brought into [0, n), as Vulkan's addressing does.
    pub fn texel(self, i: i64, n: i64) -> i64 {
        match self {
            Self::Repeat => i.rem_euclid(n),
            Self::ClampToEdge => i.clamp(0, n - 1),
            Self::MirroredRepeat => {
                let m = i.rem_euclid(2 * n);
                if m < n {
                    m
                } else {
                    2 * n - 1 - m
                }
            }
        }
    }

    fn code(self) -> u32 {
        self as u32
    }
}

/// Nearest or linear filtering (within a level, or between levels).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    Nearest,
    #[default]
    Linear,
}

/// How a texture is filtered and wrapped: glTF's sampler. The default (a glTF texture without a
/// sampler, and `Scene.add_mesh`'s textures) is repeat wrap and trilinear filtering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampler {
    pub wrap_u: Wrap,
    pub wrap_v: Wrap,
    /// Where a texel covers more than a pixel (level 0).
    pub mag: Filter,
    /// Where a pixel covers more than a texel, within the level chosen.
    pub min: Filter,
    /// Between mip levels; None samples level 0 only.
    pub mipmap: Option<Filter>,
}

impl Default for Sampler {
    fn default() -> Self {
        Self { wrap_u: Wrap::Repeat, wrap_v: Wrap::Repeat, mag: Filter::Linear, min: Filter::Linear, mipmap: Some(Filter::Linear) }
    }
}

impl Sampler {
    /// From glTF's codes: magFilter 9728 NEAREST / 9729 LINEAR; minFilter those or
    /// 9984..9987 (NEAREST_MIPMAP_NEAREST, LINEAR_MIPMAP_NEAREST, NEAREST_MIPMAP_LINEAR,
    /// LINEAR_MIPMAP_LINEAR); an absent filter is linear (with linear mips).
    pub fn from_gltf(mag: Option<u32>, min: Option<u32>, wrap_s: u32, wrap_t: u32) -> Result<Self> {
        use Filter::{Linear, Nearest};
        let mag = match mag {
            None | Some(9729) => Linear,
            Some(9728) => Nearest,
            Some(c) => return Err(invalid!("magFilter {c} is not 9728 (NEAREST) or 9729 (LINEAR)")),
        };
        let (min, mipmap) = match min {
            None => (Linear, Some(Linear)),
            Some(9728) => (Nearest, None),
            Some(9729) => (Linear, None),
            Some(9984) => (Nearest, Some(Nearest)),
            Some(9985) => (Linear, Some(Nearest)),
            Some(9986) => (Nearest, Some(Linear)),
            Some(9987) => (Linear, Some(Linear)),
            Some(c) => return Err(invalid!("minFilter {c} is not one of 9728, 9729, 9984, 9985, 9986, 9987")),
        };
        Ok(Self { wrap_u: Wrap::from_gltf(wrap_s)?, wrap_v: Wrap::from_gltf(wrap_t)?, mag, min, mipmap })
    }

    /// The bits the shaders read (`SAMPLER_*` in shaders/common/shading.wgsl): wrap u in bits
    /// 0-1, wrap v in 2-3, mag linear bit 4, min linear bit 5, mips on bit 6, linear mips bit 7.
    pub fn bits(&self) -> u32 {
        self.wrap_u.code()
            | self.wrap_v.code() << 2
            | u32::from(self.mag == Filter::Linear) << 4
            | u32::from(self.min == Filter::Linear) << 5
            | u32::from(self.mipmap.is_some()) << 6
            | u32::from(self.mipmap == Some(Filter::Linear)) << 7
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_modes_address_texels_as_vulkan_does() {
        let row = |w: Wrap| (-4..6).map(|i| w.texel(i, 3)).collect::<Vec<_>>();
        assert_eq!(row(Wrap::Repeat), [2, 0, 1, 2, 0, 1, 2, 0, 1, 2]);
        assert_eq!(row(Wrap::ClampToEdge), [0, 0, 0, 0, 0, 1, 2, 2, 2, 2]);
        assert_eq!(row(Wrap::MirroredRepeat), [2, 2, 1, 0, 0, 1, 2, 2, 1, 0]);
    }
}
