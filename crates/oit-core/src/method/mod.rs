//! The method trait, the registry of names, and parameter validation.
//! Adding a method: its file here (its declaration and passes), its WGSL, its line in
//! `registry!` below, and its numpy model (python/oit/models.py): docs/methods.md, "Adding a
//! method".

mod accum;
mod frame;
mod info;
mod ktab;
mod list_pipelines;
pub(crate) mod lists;
mod params;
mod pixel_lock;
mod pool;
mod resolve_plan;

/// The registry: each method's module, declared here once with the methods it registers, in
/// the order `oit.methods()` lists them.
macro_rules! registry {
    ($($module:ident: [$($info:ident),+]),+ $(,)?) => {
        $(mod $module;)+
        const REGISTRY: &[MethodInfo] = &[$($($module::$info),+),+];
    };
}

registry! {
    abuffer: [INFO],
    blend: [UNSORTED, SORTED, ADDITIVE, FILTER],
    hybrid: [HYBRID, KTAB],
    hybrid64: [INFO],
    weighted: [WAVG, WSUM, WBOIT],
    adaptive: [INFO],
    adaptive_lists: [INFO],
    pall: [INFO],
    compact_abuffer: [INFO],
    sbuffer: [INFO],
    peel: [DEPTH_PEELING, DUAL_DEPTH_PEELING],
    screen_door: [INFO],
    stochastic: [INFO],
    mlab: [INFO],
    mlab_lists: [INFO],
    mboit: [INFO],
    wavelet: [INFO],
    bucket_peeling: [INFO],
    auto: [INFO],
}

pub(crate) use frame::{check_per_pixel, FrameCtx, Limits, Method, Outcome};
pub use frame::{MethodReport, Tally};
pub use info::*;
pub use params::{ParamInfo, ParamKind, ParamValue, Params};

use crate::context::GpuContext;
use crate::error::{invalid, OitError, Result};
use crate::shader::{self, Const, SceneVariant};
use params::did_you_mean;

pub fn methods() -> &'static [MethodInfo] {
    REGISTRY
}

/// Every constant the shaders take, at the values they are validated with (tests, tools): the
/// engine's (`shader::ENGINE_CONSTS`), then each registered method's compiled parameters at
/// their defaults and its other constants (`MethodInfo::constants`), the first of a name kept.
pub fn default_consts() -> Vec<Const> {
    let mut out: Vec<Const> = shader::ENGINE_CONSTS.to_vec();
    for m in REGISTRY {
        let compiled = m.params.iter().filter_map(|p| p.compiled).map(|(n, v)| Const::U32(n, v));
        for c in compiled.chain(m.constants.iter().copied()) {
            if !out.iter().any(|o| o.name() == c.name()) {
                out.push(c);
            }
        }
    }
    out
}

/// `default_consts` compiled for the scene variant `variant`.
pub fn variant_consts(variant: SceneVariant) -> Vec<Const> {
    shader::with_variant(&default_consts(), variant)
}

pub fn lookup(name: &str) -> Result<&'static MethodInfo> {
    REGISTRY.iter().find(|m| m.name == name).ok_or_else(|| {
        let names: Vec<&str> = REGISTRY.iter().map(|m| m.name).collect();
        invalid!("unknown method '{name}'{}; valid methods: {}", did_you_mean(name, names.iter().copied()), names.join(", "))
    })
}

/// GPU bytes `name` allocates for a `width` x `height` frame with `params` (the formula of its
/// `MethodInfo::memory`): None when that grows with the scene, or for auto without `slots`.
pub fn memory_bytes(name: &str, width: u32, height: u32, params: &[(String, ParamValue)], slots: Option<u64>) -> Result<Option<u64>> {
    let info = lookup(name)?;
    if slots.is_some() && !matches!(info.memory, Memory::Slots { .. }) {
        return Err(invalid!("'{name}' has no per-pixel slots; `slots` is for methods that choose them per frame (auto)"));
    }
    let params = info.resolve_params(params)?;
    Ok(info.memory_bytes(width as u64 * height as u64, &params, slots))
}

/// Refuses an adapter that lacks a feature `info`'s method needs, naming the features and the
/// methods that work on it.
pub fn check_features(info: &MethodInfo, gpu: &GpuContext) -> Result<()> {
    let missing = info.features - gpu.features;
    if missing.is_empty() {
        return Ok(());
    }
    let works: Vec<&str> = methods().iter().filter(|m| gpu.features.contains(m.features)).map(|m| m.name).collect();
    Err(OitError::Unsupported(format!(
        "adapter '{}' lacks {} which '{}' needs; these methods work on it: {}",
        gpu.info.name,
        feature_names(missing).join(" and "),
        info.name,
        works.join(", ")
    )))
}
