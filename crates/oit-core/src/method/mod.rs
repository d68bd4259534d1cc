//! The method trait, the registry of names, and parameter validation.
//! Adding a method: one file here, its WGSL, one line in `REGISTRY`, and its tests.

mod abuffer;
mod adaptive;
mod auto;
mod blend;
mod bucket_peeling;
mod compact_abuffer;
pub mod hybrid;
mod hybrid64;
pub(crate) mod lists;
mod mlab;
mod pall;
pub mod peel;
mod sbuffer;
mod screen_door;
mod stochastic;
pub mod weighted;

use std::collections::BTreeMap;

use crate::context::GpuContext;
use crate::error::{invalid, Result};
use crate::scene::Camera;
use crate::targets::{SampleTargets, Targets};
use crate::timer::PassTimer;
use crate::upload::GpuScene;

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

/// What `oit.methods()` reports about a method.
#[derive(Clone, Copy, Debug)]
pub struct MethodInfo {
    pub name: &'static str,
    pub summary: &'static str,
    pub exact: bool,
    pub bounded_memory: bool,
    pub passes: &'static [&'static str],
    pub params: &'static [ParamInfo],
    create: fn(&GpuContext, &Limits) -> Box<dyn Method>,
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

const REGISTRY: &[MethodInfo] = &[
    abuffer::INFO,
    blend::UNSORTED,
    blend::SORTED,
    blend::ADDITIVE,
    blend::FILTER,
    hybrid::HYBRID,
    hybrid::KTAB,
    hybrid64::INFO,
    weighted::WAVG,
    weighted::WSUM,
    weighted::WBOIT,
    adaptive::INFO,
    pall::INFO,
    compact_abuffer::INFO,
    sbuffer::INFO,
    peel::DEPTH_PEELING,
    peel::DUAL_DEPTH_PEELING,
    screen_door::INFO,
    stochastic::INFO,
    mlab::INFO,
    bucket_peeling::INFO,
    auto::INFO,
];

pub fn methods() -> &'static [MethodInfo] {
    REGISTRY
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

fn did_you_mean<'a>(name: &str, options: impl Iterator<Item = &'a str>) -> String {
    let lower = name.to_lowercase();
    options
        .map(|o| (distance(&lower, o), o))
        .filter(|(d, _)| *d <= 2)
        .min()
        .map(|(_, o)| format!(" (did you mean '{o}'?)"))
        .unwrap_or_default()
}

pub fn lookup(name: &str) -> Result<&'static MethodInfo> {
    REGISTRY.iter().find(|m| m.name == name).ok_or_else(|| {
        let names: Vec<&str> = REGISTRY.iter().map(|m| m.name).collect();
        invalid!("unknown method '{name}'{}; valid methods: {}", did_you_mean(name, names.iter().copied()), names.join(", "))
    })
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

/// Limits a method sizes its buffers by: the adapter's, or lower ones a caller asks for
/// (tests use a small binding limit to exercise buffer splitting on small scenes).
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    pub max_binding_bytes: u64,
}

/// Everything a method needs to record one frame. The opaque pass and the census have run;
/// the method writes its final image into `targets.out`.
pub(crate) struct FrameCtx<'a> {
    pub gpu: &'a GpuContext,
    pub scene: &'a GpuScene,
    pub camera: &'a Camera,
    pub targets: &'a Targets,
    pub targets_layout: &'a wgpu::BindGroupLayout,
    pub scene_layout: &'a wgpu::BindGroupLayout,
    pub timer: &'a mut PassTimer,
    pub params: &'a Params,
    /// Transparent fragments per pixel (row-major), from this frame's census.
    pub depth_complexity: &'a [u32],
    /// Largest transparent fragment count of a pixel, from this frame's census.
    pub max_depth_complexity: u32,
    /// Transparent fragments of the frame, from the census.
    pub fragments: u64,
    /// The frame uniform (`gpu_types::FrameUniform`), for methods that set its `seed`.
    pub frame_uniform: &'a wgpu::Buffer,
    /// Limits to size buffers by (the adapter's, or lower ones the caller asked for).
    pub limits: Limits,
    /// A coverage-mask frame's per-sample targets (only methods that take coverage masks
    /// see one); `targets_layout` is then their layout.
    pub coverage: Option<&'a SampleTargets>,
}

impl<'a> FrameCtx<'a> {
    /// Group 1 of storage-writing and resolve passes: the frame's targets, or the per-sample
    /// ones of a coverage-mask frame.
    pub fn targets_group(&self) -> &'a wgpu::BindGroup {
        self.coverage.map_or(&self.targets.group, |c| &c.group)
    }

    /// The depth attachment geometry passes draw against (read-only).
    pub fn raster_depth(&self) -> &'a wgpu::TextureView {
        self.coverage.map_or(&self.targets.depth, |c| &c.raster_depth)
    }
}

impl FrameCtx<'_> {
    /// The same frame for another method's parameters (methods that delegate, e.g. auto).
    pub fn with_params<'b>(&'b mut self, params: &'b Params) -> FrameCtx<'b> {
        FrameCtx {
            gpu: self.gpu,
            scene: self.scene,
            camera: self.camera,
            targets: self.targets,
            targets_layout: self.targets_layout,
            scene_layout: self.scene_layout,
            timer: &mut *self.timer,
            params,
            depth_complexity: self.depth_complexity,
            max_depth_complexity: self.max_depth_complexity,
            fragments: self.fragments,
            frame_uniform: self.frame_uniform,
            limits: self.limits,
            coverage: self.coverage,
        }
    }

    /// Refuses a frame whose per-pixel buffer of `bytes_per_pixel` would pass one storage
    /// binding, naming the largest frame that fits.
    pub fn check_per_pixel(&self, what: &str, bytes_per_pixel: u64) -> Result<()> {
        check_per_pixel(self.limits.max_binding_bytes, self.targets.width, self.targets.height, what, bytes_per_pixel)
    }
}

/// See [`FrameCtx::check_per_pixel`].
pub(crate) fn check_per_pixel(limit: u64, width: u32, height: u32, what: &str, bytes_per_pixel: u64) -> Result<()> {
    let pixels = width as u64 * height as u64;
    if pixels * bytes_per_pixel <= limit {
        return Ok(());
    }
    let fits = limit / bytes_per_pixel.max(1);
    let side = (fits as f64).sqrt() as u64;
    Err(crate::error::OitError::OutOfMemory(format!(
        "{what} needs {} bytes at {width} x {height}, past the {limit}-byte storage binding limit: render at most \
         {fits} pixels (e.g. {side} x {side})",
        pixels * bytes_per_pixel
    )))
}

/// What a method reports about its frame, beyond what the renderer measures.
#[derive(Debug, Default)]
pub struct MethodReport {
    /// GPU memory the method itself allocated (buffers kept for this frame).
    pub memory_bytes: u64,
    /// Fragments a bounded structure could not hold.
    pub overflow_fragments: u64,
    /// Method-specific numbers (e.g. how often the node pool grew).
    pub extra: Vec<(&'static str, f64)>,
    /// Whether the method wrote a per-pixel error bound into `targets.bound`.
    pub error_bound: bool,
}

pub(crate) trait Method: Send {
    fn render(&mut self, cx: &mut FrameCtx<'_>) -> Result<MethodReport>;
}
