//! WGSL sources: `//!include path` directives resolved from the embedded `shaders/` tree,
//! and compile-time constants prepended from Rust so that each number lives in one place.

include!(concat!(env!("OUT_DIR"), "/shader_sources.rs"));

pub use crate::consts::Const;

/// Constants a shader needs when it is validated without a pipeline (tests, tools).
pub const DEFAULT_CONSTS: &[Const] = &[
    Const::U32("NODES_PER_BINDING", 1 << 20),
    Const::U32("POOL_SPLIT", 4),
    Const::U32("BATCH", 32),
    Const::U32("RUN", 32),
    Const::U32("STEP_BUDGET", 32_768),
    Const::U32("FRAG_STEPS", 0),
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

/// The full WGSL text of `path` with its includes, the shared constants (`consts::SHARED`) and
/// the given ones.
pub fn compose(path: &str, consts: &[Const]) -> String {
    let mut out = String::new();
    for c in crate::consts::SHARED.iter().chain(consts) {
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

/// The attribute that asks for the depth test before a storage-writing fragment shader; it is
/// dropped where the device lacks SHADER_EARLY_DEPTH_TEST (those shaders test the opaque
/// depth themselves first, so only the time changes).
const EARLY_DEPTH_TEST: &str = " @early_depth_test(force)";

pub(crate) fn module(device: &wgpu::Device, path: &str, consts: &[Const]) -> wgpu::ShaderModule {
    let mut text = compose(path, consts);
    if !device.features().contains(wgpu::Features::SHADER_EARLY_DEPTH_TEST) {
        text = text.replace(EARLY_DEPTH_TEST, "");
    }
    device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(path), source: wgpu::ShaderSource::Wgsl(text.into()) })
}
