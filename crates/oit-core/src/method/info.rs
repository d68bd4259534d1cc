//! What is known about a method before it renders (`MethodInfo` and the facts it holds),
//! its parameters and their validation.

use std::collections::BTreeMap;

use super::frame::{Limits, Method};
use super::params::{check, did_you_mean, ParamInfo, ParamKind, ParamValue, Params};
use crate::cache::PipelineSpec;
use crate::context::GpuContext;
use crate::error::{invalid, Result};
use crate::shader::Const;

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
    /// The shader constants its pipelines take besides its parameters' (`ParamInfo::compiled`)
    /// and the scene's, at the values its shaders are validated with (`method::default_consts`).
    pub constants: &'static [Const],
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

/// Bytes linear in at most one integer parameter: `base + per · param`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Linear {
    pub base: u64,
    pub per: u64,
    pub param: Option<&'static str>,
}

impl Linear {
    /// `base` bytes whatever the parameters.
    pub const fn bytes(base: u64) -> Self {
        Self { base, per: 0, param: None }
    }

    /// `per` bytes for each unit of the integer parameter `param`, plus `base`.
    pub const fn per(param: super::params::IntParam, per: u64, base: u64) -> Self {
        Self { base, per, param: Some(param.0.name) }
    }

    pub fn at(&self, params: &Params) -> u64 {
        self.base + self.param.map_or(0, |p| self.per * params.int(p).max(0) as u64)
    }

    /// The expression as the formula shows it: `20`, `8·k + 24`.
    fn text(&self) -> String {
        match self.param {
            None => self.base.to_string(),
            Some(p) if self.base == 0 => format!("{}·{p}", self.per),
            Some(p) => format!("{}·{p} + {}", self.per, self.base),
        }
    }
}

/// Bytes a frame of `W·H` pixels allocates: `W·H·per_pixel + fixed`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameBytes {
    pub per_pixel: Linear,
    pub fixed: u64,
}

impl FrameBytes {
    pub fn at(&self, pixels: u64, params: &Params) -> u64 {
        pixels * self.per_pixel.at(params) + self.fixed
    }

    fn text(&self) -> String {
        let per_pixel = match (self.per_pixel.param, self.per_pixel.base) {
            (None, 0) if self.fixed > 0 => return self.fixed.to_string(),
            (None, 0) => return "0".to_string(),
            (None, _) => format!("W·H·{}", self.per_pixel.text()),
            (Some(_), _) => format!("W·H·({})", self.per_pixel.text()),
        };
        if self.fixed > 0 {
            format!("{per_pixel} + {}", self.fixed)
        } else {
            per_pixel
        }
    }
}

impl FrameBytes {
    /// The bytes of `buffers` together, and `fixed` more (counters, say): what a method
    /// declares its memory as where it is its buffers (their parameters must agree).
    pub const fn of(buffers: &[Buffer], fixed: u64) -> Self {
        let mut out = FrameBytes { per_pixel: Linear::bytes(0), fixed };
        let mut i = 0;
        while i < buffers.len() {
            let b = buffers[i].bytes;
            let param = match (out.per_pixel.param, b.per_pixel.param) {
                (Some(a), Some(c)) => {
                    assert!(crate::consts::same_str(a, c), "buffers of one method grow with one parameter");
                    Some(a)
                }
                (a, None) => a,
                (None, c) => c,
            };
            out.per_pixel = Linear { base: out.per_pixel.base + b.per_pixel.base, per: out.per_pixel.per + b.per_pixel.per, param };
            out.fixed += b.fixed;
            i += 1;
        }
        out
    }
}

/// One buffer of a method's own storage group, declared once: its binding's name (as its WGSL
/// declares it) and its bytes, from which the buffer is made (`buffer_sizes`) and the method's
/// memory declared (`FrameBytes::of`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Buffer {
    pub name: &'static str,
    pub bytes: FrameBytes,
}

impl Buffer {
    /// `per_pixel` bytes for each pixel of the tile.
    pub const fn per_pixel(name: &'static str, per_pixel: Linear) -> Self {
        Self { name, bytes: FrameBytes { per_pixel, fixed: 0 } }
    }
}

/// Each of `buffers` with its bytes for a tile of `pixels` pixels and `params`: what
/// `StorageGroup::ensure` makes.
pub fn buffer_sizes(buffers: &[Buffer], pixels: u64, params: &Params) -> Vec<(&'static str, u64)> {
    buffers.iter().map(|b| (b.name, b.bytes.at(pixels, params))).collect()
}

/// What a method stores that grows with the scene: bytes a pixel, a stored fragment (a node
/// of its pool, spread over `lists::POOL_BINDINGS` bindings) and a transparent triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneBytes {
    pub per_pixel: u64,
    pub per_fragment: u64,
    pub per_triangle: u64,
}

impl SceneBytes {
    fn text(&self) -> String {
        let mut t = format!("{} B/fragment + {} B/pixel", self.per_fragment, self.per_pixel);
        if self.per_triangle > 0 {
            t += &format!(" + {} B/triangle", self.per_triangle);
        }
        t
    }
}

/// The GPU memory a method allocates for one frame (`stats["memory_bytes"]`), declared once:
/// its formula's text, `oit.memory_bytes` and the tiling are derived from it.
#[derive(Clone, Copy, Debug)]
pub enum Memory {
    /// Fixed by the frame size and the parameters.
    Frame(FrameBytes),
    /// Fixed by the frame size and the parameters, where the parameters choose between sets of
    /// buffers (hybrid's tails): `bytes(pixels, params)` in code, `formula` its text.
    Computed { formula: &'static str, bytes: fn(u64, &Params) -> u64 },
    /// Grows with the scene (its fragments or triangles); `note` says what more the text should.
    Scene { storage: SceneBytes, note: &'static str },
    /// Chosen per frame as per-pixel slots (auto): `bytes(pixels, slots)` once the slots are
    /// known; its tiles are planned from `storage` (what its exact fallback keeps).
    Slots { formula: &'static str, bytes: fn(u64, u64) -> u64, storage: SceneBytes },
}

impl Memory {
    pub fn formula(&self) -> String {
        match self {
            Memory::Frame(f) => f.text(),
            Memory::Computed { formula, .. } | Memory::Slots { formula, .. } => formula.to_string(),
            Memory::Scene { storage, note: "" } => storage.text(),
            Memory::Scene { storage, note } => format!("{} {note}", storage.text()),
        }
    }

    pub fn kind(&self) -> &'static str {
        match self {
            Memory::Frame(_) | Memory::Computed { .. } => "frame",
            Memory::Scene { .. } => "scene",
            Memory::Slots { .. } => "slots",
        }
    }

    /// How the renderer plans the method's screen tiles.
    pub fn tiling(&self) -> Tiling {
        match *self {
            Memory::Frame(_) | Memory::Computed { .. } => Tiling::Formula,
            Memory::Scene { storage, .. } | Memory::Slots { storage, .. } => {
                Tiling::Storage { per_pixel: storage.per_pixel, per_fragment: storage.per_fragment, per_triangle: storage.per_triangle }
            }
        }
    }
}

/// How the renderer plans a method's screen tiles (tiles.rs, docs/methods.md "Tiles"), from
/// its `Memory`.
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
            Memory::Frame(f) => Some(f.at(pixels, params)),
            Memory::Computed { bytes, .. } => Some(bytes(pixels, params)),
            Memory::Scene { .. } => None,
            Memory::Slots { bytes, .. } => slots.map(|s| bytes(pixels, s)),
        }
    }

    /// How the renderer plans its screen tiles (from its `memory`).
    pub fn tiling(&self) -> Tiling {
        self.memory.tiling()
    }

    /// Whether a frame with `params` runs the census before the method (besides the caller's asking).
    pub fn needs_census(&self, params: &Params) -> bool {
        self.census || (self.census_when)(params)
    }

    pub(crate) fn instantiate(&self, gpu: &GpuContext, limits: &Limits) -> Box<dyn Method> {
        (self.create)(gpu, limits)
    }
}
