//! What is known about a method before it renders (`MethodInfo` and the facts it holds),
//! its parameters and their validation.

use std::collections::BTreeMap;

use super::frame::{Limits, Method};
use super::params::{check, did_you_mean, ParamInfo, ParamKind, ParamValue, Params};
use crate::cache::PipelineSpec;
use crate::context::GpuContext;
use crate::error::{invalid, Result};

/// Everything known about a method before it renders: what `oit.methods()` reports, what the
/// renderer checks before creating it, and what `oit.memory_bytes` answers. One declaration
/// per method (in its own file) is the only place these facts live.
#[derive(Clone, Copy, Debug)]
pub struct MethodInfo {
    pub name: &'static str,
    pub summary: &'static str,
    pub exact: bool,
    pub bounded_memory: bool,
    pub passes: &'static [&'static str],
    pub params: &'static [ParamInfo],
    /// Adapter features the method needs; checked before it is created.
    pub features: wgpu::Features,
    /// How its image depends on the order geometry is submitted in.
    pub order: Order,
    /// The antialiasing modes it renders (every method has `Frames`).
    pub antialias_modes: &'static [AntialiasMode],
    /// The GPU memory it allocates for a frame.
    pub memory: Memory,
    /// What bounds its error against the exact composite.
    pub error_bound: ErrorBound,
    /// How a frame too large for its bindings or the memory budget is split into screen tiles.
    pub tiling: Tiling,
    /// Whether the method reads the fragment census before it renders (its storage, tiles or
    /// pass count are planned from every pixel's fragment count). Methods that do not get no
    /// census pass unless the caller asks for the counts (`Renderer::set_census`).
    pub census: bool,
    /// Whether, with these parameters, it reads the census although `census` is false
    /// (hybrid's tail = "compact" takes its tail count from it); `never` for the others.
    pub census_when: fn(&Params) -> bool,
    /// The integer parameter the method's speed-accuracy trade moves along (k, nodes, layers,
    /// samples, buckets): what `oit compare` sweeps; None where there is none.
    pub main: Option<&'static str>,
    /// The pipelines it builds, a table per shader file: what it creates them from, and what
    /// tests/bindings.rs checks against each shader's bindings.
    pub pipelines: &'static [&'static [PipelineSpec]],
    pub(crate) create: fn(&GpuContext, &Limits) -> Box<dyn Method>,
}

/// `MethodInfo::census_when` of a method whose parameters never ask for the census.
pub fn never(_: &Params) -> bool {
    false
}

/// How a method's image depends on submission order (docs/methods.md, "Guarantees").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// Bit-identical under any order of meshes, triangles and vertices.
    Bitwise,
    /// Bit-identical, except that fragments at exactly equal depths are taken in submission order.
    BitwiseExceptTies,
    /// Commutative float sums: a reordering changes only the rounding (within twice the float32 bound).
    Rounding,
    /// The image depends on the submission order.
    Submission,
}

impl Order {
    pub fn name(self) -> &'static str {
        match self {
            Order::Bitwise => "bitwise",
            Order::BitwiseExceptTies => "bitwise_except_ties",
            Order::Rounding => "rounding",
            Order::Submission => "submission",
        }
    }

    /// Whether reordering the geometry leaves the image bit for bit the same (away from exact depth ties).
    pub fn independent(self) -> bool {
        matches!(self, Order::Bitwise | Order::BitwiseExceptTies)
    }
}

/// How a frame of several samples a pixel is made (docs/methods.md, "Antialiasing").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AntialiasMode {
    /// One full frame per sample position, averaged: any method, memory of one sample.
    #[default]
    Frames,
    /// One multisampled capture with a sample mask per stored fragment.
    Coverage,
}

impl AntialiasMode {
    pub fn name(self) -> &'static str {
        match self {
            AntialiasMode::Frames => "frames",
            AntialiasMode::Coverage => "coverage",
        }
    }
}

/// Antialiasing by sample frames only (every method).
pub const FRAMES: &[AntialiasMode] = &[AntialiasMode::Frames];

/// The GPU memory a method allocates for one frame (`stats["memory_bytes"]`).
#[derive(Clone, Copy, Debug)]
pub enum Memory {
    /// Fixed by the frame size and the parameters: `bytes(pixels, params)`; `formula` is its text.
    Frame { formula: &'static str, bytes: fn(u64, &Params) -> u64 },
    /// Grows with the scene (its fragments or triangles); `formula` is its text.
    Scene { formula: &'static str },
    /// Chosen per frame as per-pixel slots (auto): `bytes(pixels, slots)` once the slots are known.
    Slots { formula: &'static str, bytes: fn(u64, u64) -> u64 },
}

impl Memory {
    pub fn formula(&self) -> &'static str {
        match self {
            Memory::Frame { formula, .. } | Memory::Scene { formula } | Memory::Slots { formula, .. } => formula,
        }
    }

    pub fn kind(&self) -> &'static str {
        match self {
            Memory::Frame { .. } => "frame",
            Memory::Scene { .. } => "scene",
            Memory::Slots { .. } => "slots",
        }
    }
}

/// How the renderer plans a method's screen tiles (tiles.rs, docs/methods.md "Tiles").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tiling {
    /// By its memory formula (`Memory::Frame`): bytes grow with the tile's pixels (render
    /// targets of its own included: like the frame's, they are the tile's size).
    Formula,
    /// From the census: `per_pixel` bytes a pixel and `per_fragment` bytes a stored fragment
    /// (a node of its pool), the pool spread over `lists::POOL_BINDINGS` bindings, and
    /// `per_triangle` bytes of each transparent triangle, whatever the tile.
    Storage { per_pixel: u64, per_fragment: u64, per_triangle: u64 },
}

impl Tiling {
    pub fn name(self) -> &'static str {
        match self {
            Tiling::Formula => "formula",
            Tiling::Storage { .. } => "census",
        }
    }
}

/// What bounds a method's error against the exact composite.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorBound {
    /// Exact: float32 compositing only, about (n + 2)·2⁻²³ for n layers.
    Exact,
    /// A per-pixel bound written with the frame (`frame.error_bound`).
    PerPixel,
    /// No per-pixel bound is derived (docs/methods.md says what the method does wrong).
    None,
}

impl ErrorBound {
    pub fn name(self) -> &'static str {
        match self {
            ErrorBound::Exact => "exact",
            ErrorBound::PerPixel => "per_pixel",
            ErrorBound::None => "none",
        }
    }
}

/// The names of `features` (wgpu's flag names, e.g. SHADER_INT64).
pub fn feature_names(features: wgpu::Features) -> Vec<&'static str> {
    features.iter_names().map(|(n, _)| n).collect()
}

impl MethodInfo {
    /// Checks names, types and ranges of `given` and fills in defaults.
    pub fn resolve_params(&self, given: &[(String, ParamValue)]) -> Result<Params> {
        let mut out = BTreeMap::new();
        for (name, value) in given {
            let info = self.params.iter().find(|p| p.name == name).ok_or_else(|| {
                let valid: Vec<&str> = self.params.iter().map(|p| p.name).collect();
                invalid!(
                    "method '{}' has no parameter '{name}'{}; its parameters: {}",
                    self.name,
                    did_you_mean(name, valid.iter().copied()),
                    if valid.is_empty() { "none".to_string() } else { valid.join(", ") }
                )
            })?;
            let v = check(self.name, info, value)?;
            out.insert(info.name, v);
        }
        for p in self.params {
            out.entry(p.name).or_insert_with(|| match p.kind {
                ParamKind::Int { default, .. } => ParamValue::Int(default),
                ParamKind::Float { default, .. } => ParamValue::Float(default),
                ParamKind::Choice { default, .. } => ParamValue::Str(default.to_string()),
            });
        }
        Ok(Params(out))
    }

    /// Bytes the method allocates at `pixels` pixels with `params`: None when that grows with
    /// the scene, or (auto) when it depends on the slots chosen per frame and `slots` is None.
    pub fn memory_bytes(&self, pixels: u64, params: &Params, slots: Option<u64>) -> Option<u64> {
        match self.memory {
            Memory::Frame { bytes, .. } => Some(bytes(pixels, params)),
            Memory::Scene { .. } => None,
            Memory::Slots { bytes, .. } => slots.map(|s| bytes(pixels, s)),
        }
    }

    /// Whether a frame with `params` runs the census before the method (besides the caller's asking).
    pub fn needs_census(&self, params: &Params) -> bool {
        self.census || (self.census_when)(params)
    }

    pub(crate) fn instantiate(&self, gpu: &GpuContext, limits: &Limits) -> Box<dyn Method> {
        (self.create)(gpu, limits)
    }
}
