//! What is known about a method before it renders (`MethodInfo` and the facts it holds),
//! its parameters and their validation.

use std::collections::BTreeMap;

use super::{Limits, Method};
use crate::context::GpuContext;
use crate::error::{invalid, OitError, Result};

/// A parameter's type, range and default.
#[derive(Clone, Copy, Debug)]
pub enum ParamKind {
    Int { min: i64, max: i64, default: i64 },
    Float { min: f64, max: f64, default: f64 },
    Choice { choices: &'static [&'static str], default: &'static str },
}

#[derive(Clone, Copy, Debug)]
pub struct ParamInfo {
    pub name: &'static str,
    pub kind: ParamKind,
    pub doc: &'static str,
}

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
    pub(crate) create: fn(&GpuContext, &Limits) -> Box<dyn Method>,
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

#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    Int(i64),
    Float(f64),
    Str(String),
}

/// Parameters after validation, every declared one present (defaults filled in).
#[derive(Clone, Debug, Default)]
pub struct Params(pub BTreeMap<&'static str, ParamValue>);

impl Params {
    pub fn int(&self, name: &str) -> i64 {
        match self.0.get(name) {
            Some(ParamValue::Int(v)) => *v,
            other => panic!("parameter '{name}' is not an int: {other:?}"),
        }
    }
    pub fn float(&self, name: &str) -> f64 {
        match self.0.get(name) {
            Some(ParamValue::Float(v)) => *v,
            Some(ParamValue::Int(v)) => *v as f64,
            other => panic!("parameter '{name}' is not a float: {other:?}"),
        }
    }
    pub fn choice(&self, name: &str) -> &str {
        match self.0.get(name) {
            Some(ParamValue::Str(v)) => v,
            other => panic!("parameter '{name}' is not a choice: {other:?}"),
        }
    }
}

/// Levenshtein distance, for "did you mean" hints.
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + (ca != *cb) as usize).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

pub(crate) fn did_you_mean<'a>(name: &str, options: impl Iterator<Item = &'a str>) -> String {
    let lower = name.to_lowercase();
    options
        .map(|o| (distance(&lower, o), o))
        .filter(|(d, _)| *d <= 2)
        .min()
        .map(|(_, o)| format!(" (did you mean '{o}'?)"))
        .unwrap_or_default()
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

    /// Refuses an adapter that lacks a feature the method needs, naming it.
    pub fn check_features(&self, gpu: &GpuContext) -> Result<()> {
        let missing = self.features - gpu.features;
        if missing.is_empty() {
            return Ok(());
        }
        let works: Vec<&str> = super::methods().iter().filter(|m| gpu.features.contains(m.features)).map(|m| m.name).collect();
        Err(OitError::Unsupported(format!(
            "adapter '{}' lacks {} which '{}' needs; these methods work on it: {}",
            gpu.info.name,
            feature_names(missing).join(" and "),
            self.name,
            works.join(", ")
        )))
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

    pub(crate) fn instantiate(&self, gpu: &GpuContext, limits: &Limits) -> Box<dyn Method> {
        (self.create)(gpu, limits)
    }
}

fn check(method: &str, info: &ParamInfo, value: &ParamValue) -> Result<ParamValue> {
    let name = info.name;
    match (info.kind, value) {
        (ParamKind::Int { min, max, .. }, ParamValue::Int(v)) => {
            if *v < min || *v > max {
                return Err(invalid!("{method}: {name} = {v} is out of range; use {min} <= {name} <= {max}"));
            }
            Ok(ParamValue::Int(*v))
        }
        (ParamKind::Float { min, max, .. }, ParamValue::Float(_) | ParamValue::Int(_)) => {
            let v = match value {
                ParamValue::Float(f) => *f,
                ParamValue::Int(i) => *i as f64,
                ParamValue::Str(_) => unreachable!(),
            };
            if !v.is_finite() || v < min || v > max {
                return Err(invalid!("{method}: {name} = {v} is out of range; use {min} <= {name} <= {max}"));
            }
            Ok(ParamValue::Float(v))
        }
        (ParamKind::Choice { choices, .. }, ParamValue::Str(s)) => {
            if !choices.contains(&s.as_str()) {
                return Err(invalid!("{method}: {name} = '{s}' is not one of: {}", choices.join(", ")));
            }
            Ok(ParamValue::Str(s.clone()))
        }
        (kind, v) => {
            let got = match v {
                ParamValue::Int(i) => format!("the integer {i}"),
                ParamValue::Float(f) => format!("the number {f}"),
                ParamValue::Str(s) => format!("the string '{s}'"),
            };
            let want = match kind {
                ParamKind::Int { min, max, .. } => format!("an integer in [{min}, {max}]"),
                ParamKind::Float { min, max, .. } => format!("a number in [{min}, {max}]"),
                ParamKind::Choice { choices, .. } => format!("one of {}", choices.join(", ")),
            };
            Err(invalid!("{method}: {name} must be {want}, got {got}"))
        }
    }
}
