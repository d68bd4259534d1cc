//! WGSL sources: `//!include path` directives resolved from the embedded `shaders/` tree,
//! compile-time constants prepended from Rust so that each number lives in one place, and
//! `//!if NAME` / `//!else` / `//!endif` blocks kept or dropped by a constant's value, so that a
//! pipeline compiles only the varyings and code its scene uses (docs/methods.md, "Specialization").

include!(concat!(env!("OUT_DIR"), "/shader_sources.rs"));

// The list of shaders is this checkout's: a target directory shared with another checkout whose
// build script ran last (with other shader files) is refused here rather than missing a shader
// at run time. The remedy: `touch crates/oit-core/build.rs`, then build again.
const _: () = assert!(
    crate::consts::same_str(SOURCES_OF, env!("CARGO_MANIFEST_DIR")),
    "shader list of another checkout: touch crates/oit-core/build.rs"
);

pub use crate::consts::Const;

/// The engine's constants a shader needs when it is validated without a pipeline (tests,
/// tools); the methods' own come from the registry (`method::default_consts`).
pub const ENGINE_CONSTS: &[Const] = &[
    Const::U32("NODES_PER_BINDING", 1 << 20),
    Const::U32("POOL_SPLIT", 4),
    Const::U32("RUN", crate::consts::RUN),
    Const::U32("STEP_BUDGET", 32_768),
    // Whether the sorted resolve pauses after STEP_BUDGET steps (an adapter with a loop limit)
    // or runs each pixel to its end in one dispatch (shaders/common/sweep_passes.wgsl).
    Const::U32("BUDGETED", 1),
    Const::U32("FRAG_STEPS", 0),
    Const::U32("SHADE_STEPS", 0),
    Const::U32("KEYED", 1),
    // What the sorted resolve's units cost in a loop limiter: the adapter's profile sets them
    // (context::DeviceProfile); any count validates.
    Const::U32("SWEEP_LOAD_STEPS", 1),
    Const::U32("SWEEP_LINK_STEPS", 1),
    Const::U32("SWEEP_MERGE_STEPS", 1),
    Const::U32("SWEEP_COMPOSITE_STEPS", 1),
    // Whether a list capture counts its own fragments per pixel (shaders/common/pool.wgsl).
    Const::U32("COUNTING", 0),
    // Whether the device honours @early_depth_test(force) (set by `module`): validated with
    // the shaders' own opaque-depth test.
    Const::U32("EARLY_DEPTH", 0),
    // Whether the device has 64-bit atomic adds, loads and stores (set by `module` where the
    // pipeline's constants do not say): hybrid's
    // tail words are then 64-bit atomics, else pairs of 32-bit ones (shaders/common/tail_words.wgsl),
    // and adaptive's insert reads and writes a node with one atomic, else two.
    Const::U32("ATOMIC64", 0),
    // Whether the device has 64-bit integers (set by `module` where the pipeline's constants do
    // not say): the sorted resolve's keys are then one 64-bit word each (shaders/common/sweep.wgsl).
    Const::U32("INT64", 0),
    // The scene variant (`SceneVariant`): validated shaded, lit and textured, the longest text.
    Const::U32("SHADED", 1),
    Const::U32("LIGHTS", 2),
    Const::U32("TEXTURES", 1),
    Const::U32("SHADING_COST", 0),
    Const::U32("INSTANCED", 1),
    Const::U32("PRIMITIVES", 1),
    Const::U32("SETS_ONLY", 0),
    Const::U32("PHONG", 1),
    Const::U32("FALLOFF", 1),
    Const::U32("EMISSIVE", 1),
    Const::U32("ALPHA_TESTS", 1),
    Const::U32("SPLAT_RAY", 1),
    // Whether `expanded` is writable: the expansion pass of strands and particles only.
    Const::U32("EXPANDING", 0),
];

/// What a scene's geometry passes compile for (`//!if` blocks and loop bounds in
/// common/scene.wgsl and common/shading.wgsl): whether any mesh has a surface (normals, UVs
/// and the material as varyings), the light count, whether any mesh is textured, and the
/// shading-cost knob's extra light evaluations, and whether any mesh is drawn other than once
/// in place (instances: the transform, color factor and drawn index from the instance table),
/// whether any set is strands or particles (common/primitives.wgsl), and whether every chunk is
/// one (`sets_only`: no triangle meshes, so corners are pulled from the expansion alone and the
/// mesh side of the vertex shader and triangle setup is not compiled).
/// An unlit scene's pipelines carry the vertex color alone, as they did before shading existed,
/// and a scene without instances no transform.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SceneVariant {
    pub shaded: bool,
    pub lights: u32,
    pub textured: bool,
    pub shading_cost: u32,
    pub instanced: bool,
    pub primitives: bool,
    pub sets_only: bool,
    /// Whether any surface shades flat or smooth (Blinn-Phong): without one, a shaded scene
    /// (strands shaded as hair, say) compiles without the light loop that llvmpipe would run,
    /// masked, for every fragment.
    pub phong: bool,
    /// Whether any particle set fades its alpha towards its rim (a falloff): without one, the
    /// falloff's code is not compiled.
    pub falloff: bool,
    /// Whether any material gives off light (an emissive color), and whether any tests its
    /// alpha against a cutoff (glTF's MASK): without one, that code is not compiled.
    pub emissive: bool,
    pub alpha_test: bool,
    /// Whether any splat set takes its fragments' depth along the pixel's ray
    /// (`SplatDepth::Ray`): without one, that code and its varyings are not compiled.
    pub splat_ray: bool,
}

impl SceneVariant {
    pub fn consts(&self) -> [Const; 13] {
        [
            Const::U32("SHADED", self.shaded as u32),
            Const::U32("LIGHTS", if self.shaded { self.lights } else { 0 }),
            Const::U32("TEXTURES", (self.shaded && self.textured) as u32),
            Const::U32("SHADING_COST", self.shading_cost),
            Const::U32("INSTANCED", self.instanced as u32),
            Const::U32("PRIMITIVES", self.primitives as u32),
            Const::U32("SETS_ONLY", (self.primitives && self.sets_only) as u32),
            Const::U32("PHONG", (self.shaded && self.phong) as u32),
            Const::U32("FALLOFF", (self.shaded && self.primitives && self.falloff) as u32),
            Const::U32("EMISSIVE", (self.shaded && self.emissive) as u32),
            Const::U32("ALPHA_TESTS", (self.shaded && self.alpha_test) as u32),
            Const::U32("SPLAT_RAY", (self.shaded && self.primitives && self.falloff && self.splat_ray) as u32),
            // Only shaders/expand.wgsl writes the corners (its own //!define).
            Const::U32("EXPANDING", 0),
        ]
    }
}

/// Scene variants besides the defaults' that tests validate every shader in: unlit, lit
/// without textures, the shading-cost knob on an unlit scene, an unlit instanced scene, and
/// unlit strands or particles beside meshes, and lit strands or particles alone (shaded as hair,
/// without the Blinn-Phong code).
pub const VALIDATION_VARIANTS: [SceneVariant; 6] = [
    UNLIT,
    SceneVariant { shaded: true, lights: 1, ..UNLIT },
    SceneVariant { shading_cost: 3, ..UNLIT },
    SceneVariant { instanced: true, ..UNLIT },
    SceneVariant { primitives: true, ..UNLIT },
    SceneVariant { shaded: true, lights: 1, primitives: true, sets_only: true, phong: false, falloff: false, ..UNLIT },
];

/// An unlit scene of meshes (PHONG and FALLOFF count only where a scene is shaded).
const UNLIT: SceneVariant = SceneVariant {
    shaded: false,
    lights: 0,
    textured: false,
    shading_cost: 0,
    instanced: false,
    primitives: false,
    sets_only: false,
    phong: true,
    falloff: true,
    emissive: false,
    alpha_test: false,
    splat_ray: false,
};

/// `base` with `variant`'s constants in place of those of the same names.
pub fn with_variant(base: &[Const], variant: SceneVariant) -> Vec<Const> {
    let own = variant.consts();
    let mut consts: Vec<Const> = base.iter().copied().filter(|c| !own.iter().any(|o| o.name() == c.name())).collect();
    consts.extend(own);
    consts
}

fn source(path: &str) -> &'static str {
    SOURCES.iter().find(|(p, _)| *p == path).map(|(_, s)| *s).unwrap_or_else(|| panic!("shader '{path}' is not in shader::SOURCES"))
}

/// Lines of `path` and its includes, with `//!if` blocks resolved against `consts`.
fn expand(path: &str, consts: &[Const], out: &mut String, seen: &mut Vec<String>) {
    if seen.iter().any(|s| s == path) {
        return;
    }
    seen.push(path.to_string());
    expand_lines(path, source(path), consts, out, seen);
}

/// `text` (as if it were the file `path`) with its directives resolved: for tests of the
/// directives themselves.
pub fn expand_text(path: &str, text: &str, consts: &[Const]) -> String {
    let mut out = String::new();
    expand_lines(path, text, consts, &mut out, &mut vec![path.to_string()]);
    out
}

fn expand_lines(path: &str, text: &str, consts: &[Const], out: &mut String, seen: &mut Vec<String>) {
    // One entry per open `//!if`: whether its current branch is kept, and whether it is at `else`.
    let mut open: Vec<(bool, bool)> = Vec::new();
    let live = |open: &[(bool, bool)]| open.iter().all(|(keep, _)| *keep);
    for (n, line) in text.lines().enumerate() {
        let directive = line.trim();
        if let Some(name) = directive.strip_prefix("//!if ") {
            open.push((condition(name.trim(), consts, path, n), false));
        } else if directive == "//!else" {
            match open.last_mut() {
                Some(top) if !top.1 => *top = (!top.0, true),
                _ => panic!("{path}:{}: //!else without its //!if", n + 1),
            }
        } else if directive == "//!endif" {
            open.pop().unwrap_or_else(|| panic!("{path}:{}: //!endif without its //!if", n + 1));
        } else if !live(&open) {
            continue;
        } else if let Some(inc) = directive.strip_prefix("//!include ") {
            expand(inc.trim(), consts, out, seen);
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    assert!(open.is_empty(), "{path}: an //!if is never closed by //!endif");
}

/// `NAME` (or `!NAME`): whether the u32 constant NAME is nonzero (or zero). A name no constant
/// defines is a mistake in the caller, never taken as false.
fn condition(expr: &str, consts: &[Const], path: &str, line: usize) -> bool {
    let (negate, name) = match expr.strip_prefix('!') {
        Some(rest) => (true, rest.trim()),
        None => (false, expr),
    };
    let value = crate::consts::SHARED.iter().chain(consts).rev().find_map(|c| match c {
        Const::U32(n, v) if *n == name => Some(*v != 0),
        _ => None,
    });
    let value = value.unwrap_or_else(|| panic!("{path}:{}: //!if {name}: no u32 constant {name} is given", line + 1));
    value != negate
}

/// The full WGSL text of `path` with its includes, the shared constants (`consts::SHARED`) and
/// the given ones.
pub fn compose(path: &str, consts: &[Const]) -> String {
    let mut out = String::new();
    let consts = &with_defines(path, consts);
    for c in crate::consts::SHARED.iter().chain(consts) {
        match c {
            Const::U32(name, v) => out.push_str(&format!("const {name}: u32 = {v}u;\n")),
            Const::F32(name, v) => out.push_str(&format!("const {name}: f32 = {v:?};\n")),
        }
    }
    expand(path, consts, &mut out, &mut Vec::new());
    out
}

/// `consts` with the values a top-level file sets for itself (`//!define NAME value` lines, u32)
/// in place of the given ones: what only that file's pipelines compile with.
fn with_defines(path: &str, consts: &[Const]) -> Vec<Const> {
    let own: Vec<(&'static str, u32)> = source(path)
        .lines()
        .filter_map(|l| l.trim().strip_prefix("//!define "))
        .map(|d| {
            let (name, value) = d.trim().split_once(' ').unwrap_or_else(|| panic!("{path}: //!define NAME value, got '{d}'"));
            let value = value.trim().parse().unwrap_or_else(|_| panic!("{path}: //!define {name}: '{value}' is not a u32"));
            (name, value)
        })
        .collect();
    let mut out: Vec<Const> = consts.iter().copied().filter(|c| !own.iter().any(|(n, _)| *n == c.name())).collect();
    out.extend(own.iter().map(|&(n, v)| Const::U32(n, v)));
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
    let early = device.features().contains(wgpu::Features::SHADER_EARLY_DEPTH_TEST);
    let mut all = consts.to_vec();
    all.push(Const::U32("EARLY_DEPTH", early as u32));
    // The device's 64-bit atomics, unless the pipeline asks for the 32-bit form itself.
    if !consts.iter().any(|c| matches!(c, Const::U32("ATOMIC64", _))) {
        let atomic64 = device.features().contains(wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS);
        all.push(Const::U32("ATOMIC64", atomic64 as u32));
    }
    if !consts.iter().any(|c| matches!(c, Const::U32("INT64", _))) {
        all.push(Const::U32("INT64", device.features().contains(wgpu::Features::SHADER_INT64) as u32));
    }
    let mut text = compose(path, &all);
    if !early {
        text = text.replace(EARLY_DEPTH_TEST, "");
    }
    device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(path), source: wgpu::ShaderSource::Wgsl(text.into()) })
}
