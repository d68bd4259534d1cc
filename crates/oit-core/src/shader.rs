//! WGSL sources: `//!include path` directives resolved from the embedded `shaders/` tree,
//! and compile-time constants prepended from Rust so that each number lives in one place.

/// Every WGSL file, embedded at build time, by path relative to `shaders/`.
pub const SOURCES: &[(&str, &str)] = &[
    ("common/scene.wgsl", include_str!("../../../shaders/common/scene.wgsl")),
    ("common/targets.wgsl", include_str!("../../../shaders/common/targets.wgsl")),
    ("common/fullscreen.wgsl", include_str!("../../../shaders/common/fullscreen.wgsl")),
    ("common/pool.wgsl", include_str!("../../../shaders/common/pool.wgsl")),
    ("common/nodes.wgsl", include_str!("../../../shaders/common/nodes.wgsl")),
    ("common/select.wgsl", include_str!("../../../shaders/common/select.wgsl")),
    ("common/sweep.wgsl", include_str!("../../../shaders/common/sweep.wgsl")),
    ("common/list_cursor.wgsl", include_str!("../../../shaders/common/list_cursor.wgsl")),
    ("common/setup.wgsl", include_str!("../../../shaders/common/setup.wgsl")),
    ("common/submission.wgsl", include_str!("../../../shaders/common/submission.wgsl")),
    ("opaque.wgsl", include_str!("../../../shaders/opaque.wgsl")),
    ("census.wgsl", include_str!("../../../shaders/census.wgsl")),
    ("blend.wgsl", include_str!("../../../shaders/blend.wgsl")),
    ("common/fixed.wgsl", include_str!("../../../shaders/common/fixed.wgsl")),
    ("common/alpha8.wgsl", include_str!("../../../shaders/common/alpha8.wgsl")),
    ("abuffer.wgsl", include_str!("../../../shaders/abuffer.wgsl")),
    ("hybrid.wgsl", include_str!("../../../shaders/hybrid.wgsl")),
    ("weighted.wgsl", include_str!("../../../shaders/weighted.wgsl")),
    ("adaptive.wgsl", include_str!("../../../shaders/adaptive.wgsl")),
    ("pall.wgsl", include_str!("../../../shaders/pall.wgsl")),
    ("compact_abuffer.wgsl", include_str!("../../../shaders/compact_abuffer.wgsl")),
    ("sbuffer.wgsl", include_str!("../../../shaders/sbuffer.wgsl")),
    ("scan.wgsl", include_str!("../../../shaders/scan.wgsl")),
    ("peel.wgsl", include_str!("../../../shaders/peel.wgsl")),
    ("screen_door.wgsl", include_str!("../../../shaders/screen_door.wgsl")),
    ("stochastic.wgsl", include_str!("../../../shaders/stochastic.wgsl")),
    ("mlab.wgsl", include_str!("../../../shaders/mlab.wgsl")),
    ("bucket_peeling.wgsl", include_str!("../../../shaders/bucket_peeling.wgsl")),
    ("hybrid64.wgsl", include_str!("../../../shaders/hybrid64.wgsl")),
    ("auto_estimate.wgsl", include_str!("../../../shaders/auto_estimate.wgsl")),
    ("common/targets_samples.wgsl", include_str!("../../../shaders/common/targets_samples.wgsl")),
    ("census_samples.wgsl", include_str!("../../../shaders/census_samples.wgsl")),
    ("abuffer_coverage.wgsl", include_str!("../../../shaders/abuffer_coverage.wgsl")),
];

/// A compile-time constant injected in front of a shader.
#[derive(Clone, Copy, Debug)]
pub enum Const {
    U32(&'static str, u32),
    F32(&'static str, f32),
}

/// Constants a shader needs when it is validated without a pipeline (tests, tools).
pub const DEFAULT_CONSTS: &[Const] = &[
    Const::U32("NODES_PER_BINDING", 1 << 20),
    Const::U32("BATCH", 32),
    Const::U32("K", 8),
    Const::U32("PER_PIXEL", 0),
    Const::U32("TAIL", 1),
    Const::U32("WEIGHT", 10),
    Const::U32("NODES", 8),
    Const::U32("NODES_PLUS_ONE", 9),
    Const::U32("DUAL", 1),
    Const::U32("SAMPLES", 8),
    Const::U32("LAYERS", 4),
    Const::U32("LAYERS_PLUS_ONE", 5),
    Const::U32("BUCKETS", 32),
    Const::F32("CORE_SCALE", 2147483648.0),
    Const::F32("TAIL_SCALE", 16777216.0),
];

fn source(path: &str) -> &'static str {
    SOURCES.iter().find(|(p, _)| *p == path).map(|(_, s)| *s).unwrap_or_else(|| panic!("shader '{path}' is not in shader::SOURCES"))
}

fn expand(path: &str, out: &mut String, seen: &mut Vec<String>) {
    if seen.iter().any(|s| s == path) {
        return;
    }
    seen.push(path.to_string());
    for line in source(path).lines() {
        match line.trim().strip_prefix("//!include ") {
            Some(inc) => expand(inc.trim(), out, seen),
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
}

/// The full WGSL text of `path` with its includes and the given constants.
pub fn compose(path: &str, consts: &[Const]) -> String {
    let mut out = String::new();
    for c in consts {
        match c {
            Const::U32(name, v) => out.push_str(&format!("const {name}: u32 = {v}u;\n")),
            Const::F32(name, v) => out.push_str(&format!("const {name}: f32 = {v:?};\n")),
        }
    }
    expand(path, &mut out, &mut Vec::new());
    out
}

/// Top-level shader files (not the `common/` helpers).
pub fn entry_files() -> impl Iterator<Item = &'static str> {
    SOURCES.iter().map(|(p, _)| *p).filter(|p| !p.starts_with("common/"))
}

pub(crate) fn module(device: &wgpu::Device, path: &str, consts: &[Const]) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(path),
        source: wgpu::ShaderSource::Wgsl(compose(path, consts).into()),
    })
}
