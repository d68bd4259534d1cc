//! Every WGSL file parses and validates with naga (no GPU needed), and the structs shared
//! with Rust have the sizes naga computes.

use oit_core::gpu_types::{
    Alloc, CompactNode, CoverageNode, FrameUniform, GpuInstance, GpuLight, GpuSegment, PallBlock, PoolNode, PrimNode, PrimShading,
};
use oit_core::method::{default_consts, variant_consts};
use oit_core::shader::{compose, entry_files, Const, SceneVariant, VALIDATION_VARIANTS};

fn validate(path: &str) -> naga::Module {
    validate_with(path, &default_consts())
}

fn validate_with(path: &str, consts: &[Const]) -> naga::Module {
    let src = compose(path, consts);
    let module = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{path}: {}", e.emit_to_string(&src)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{path}: {e:?}"));
    module
}

#[test]
fn every_shader_validates() {
    let files: Vec<_> = entry_files().collect();
    assert!(files.len() >= 4, "shader list looks truncated: {files:?}");
    for f in files {
        validate(f);
    }
}

/// Every scene variant a pipeline can be specialized to (unlit, lit without textures, the
/// shading-cost knob on an unlit scene) validates too: the `//!if` blocks leave whole shaders.
#[test]
fn every_shader_validates_in_every_scene_variant() {
    for v in VALIDATION_VARIANTS {
        for f in entry_files() {
            validate_with(f, &variant_consts(v));
        }
    }
}

/// hybrid's and hybrid64's tail words and adaptive's insert nodes as 64-bit atomics (ATOMIC64,
/// set per device) validate as well as the 32-bit pairs of the defaults.
#[test]
fn the_64_bit_atomic_variants_validate() {
    let mut consts: Vec<Const> = default_consts().iter().copied().filter(|c| !matches!(c, Const::U32("ATOMIC64", _))).collect();
    consts.push(Const::U32("ATOMIC64", 1));
    for f in ["hybrid.wgsl", "hybrid64.wgsl", "adaptive.wgsl"] {
        let text = compose(f, &consts);
        assert!(text.contains("array<atomic<u64>>"), "{f} with ATOMIC64 keeps 32-bit words");
        validate_with(f, &consts);
    }
}

/// The sorted resolve's keys as 64-bit words (INT64, set per device) validate as well as the
/// pairs of 32-bit words of the defaults.
#[test]
fn the_64_bit_sort_keys_validate() {
    let mut consts: Vec<Const> = default_consts().iter().copied().filter(|c| !matches!(c, Const::U32("INT64", _))).collect();
    consts.push(Const::U32("INT64", 1));
    for f in ["abuffer.wgsl", "sbuffer.wgsl", "pall.wgsl", "abuffer_coverage.wgsl"] {
        let text = compose(f, &consts);
        assert!(text.contains("alias Entry = u64;"), "{f} with INT64 keeps keys of two words");
        validate_with(f, &consts);
    }
}

#[test]
fn an_unlit_variant_has_no_shading_varyings() {
    let unlit = compose("blend.wgsl", &variant_consts(SceneVariant::default()));
    let lit = compose("blend.wgsl", &default_consts());
    let code = ["fn sample_map", "uv_plane_u: vec3<f32>", "fn surface_emission", "(flags & ALPHA_TEST) != 0u"];
    for varying in ["normal: vec3<f32>", "uv: vec2<f32>", "material: u32"].into_iter().chain(code) {
        assert!(!unlit.contains(varying), "the unlit blend shader still has `{varying}`");
        assert!(lit.contains(varying), "the lit blend shader lacks `{varying}`");
    }
}

#[test]
fn a_lit_scene_without_textures_emission_or_alpha_tests_compiles_without_their_code() {
    let lit = SceneVariant { shaded: true, lights: 1, phong: true, ..Default::default() };
    let plain = compose("blend.wgsl", &variant_consts(lit));
    let all = compose("blend.wgsl", &variant_consts(SceneVariant { textured: true, emissive: true, alpha_test: true, ..lit }));
    for code in ["fn sample_map", "uv_plane_u: vec3<f32>", "fn surface_emission", "(flags & ALPHA_TEST) != 0u"] {
        assert!(!plain.contains(code), "a lit scene without them kept `{code}`");
        assert!(all.contains(code), "a textured, emissive, alpha-tested scene lacks `{code}`");
    }
}

#[test]
fn strands_shaded_as_hair_alone_compile_without_the_blinn_phong_loop_or_a_falloff() {
    let hair = SceneVariant { shaded: true, lights: 1, primitives: true, sets_only: true, ..Default::default() };
    let phong = SceneVariant { phong: true, ..hair };
    let without = compose("blend.wgsl", &variant_consts(hair));
    let with = compose("blend.wgsl", &variant_consts(phong));
    assert!(without.contains("fn hair("), "the hair shading is missing");
    assert!(!without.contains("dot(n, h)"), "a scene without flat or smooth surfaces kept the Blinn-Phong loop");
    assert!(with.contains("dot(n, h)"), "a scene with flat or smooth surfaces lost the Blinn-Phong loop");
    // Nor with a particle falloff, where no set has one.
    let falloff = compose("blend.wgsl", &variant_consts(SceneVariant { falloff: true, ..hair }));
    assert!(!without.contains("* falloff("), "a scene without a falloff kept its code");
    assert!(falloff.contains("* falloff("), "a scene with a falloff lost its code");
}

#[test]
#[should_panic(expected = "no u32 constant NOT_A_CONSTANT")]
fn an_if_on_an_unknown_constant_is_refused() {
    oit_core::shader::expand_text("t.wgsl", "//!if NOT_A_CONSTANT\nx\n//!endif\n", &[]);
}

fn struct_size(module: &naga::Module, name: &str) -> u32 {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, _) = module.types.iter().find(|(_, t)| t.name.as_deref() == Some(name)).unwrap_or_else(|| panic!("no struct {name}"));
    layouter[handle].size
}

#[test]
fn layout_sizes() {
    let m = validate("abuffer.wgsl");
    assert_eq!(struct_size(&m, "FrameUniform") as usize, std::mem::size_of::<FrameUniform>());
    assert_eq!(struct_size(&m, "Light") as usize, std::mem::size_of::<GpuLight>());
    assert_eq!(struct_size(&m, "Node") as usize, std::mem::size_of::<PoolNode>());
    assert_eq!(struct_size(&m, "Alloc") as usize, std::mem::size_of::<Alloc>());
    assert_eq!(struct_size(&m, "Instance") as usize, std::mem::size_of::<GpuInstance>());
    let m = validate("adaptive_lists.wgsl");
    assert_eq!(struct_size(&m, "Node") as usize, std::mem::size_of::<PrimNode>());
    let m = validate("compact_abuffer.wgsl");
    assert_eq!(struct_size(&m, "Node") as usize, std::mem::size_of::<CompactNode>());
    assert_eq!(struct_size(&m, "PrimShading") as usize, std::mem::size_of::<PrimShading>());
    let m = validate("abuffer_coverage.wgsl");
    assert_eq!(struct_size(&m, "Node") as usize, std::mem::size_of::<CoverageNode>());
    let m = validate("pall.wgsl");
    assert_eq!(struct_size(&m, "Block") as usize, std::mem::size_of::<PallBlock>());
    assert_eq!(struct_size(&m, "Segment") as usize, std::mem::size_of::<GpuSegment>());
}

/// The value naga evaluates for the global constant `name` of `module`.
fn naga_constant(module: &naga::Module, name: &str) -> Option<naga::Literal> {
    let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name))?;
    match module.global_expressions[c.init] {
        naga::Expression::Literal(l) => Some(l),
        ref e => panic!("constant {name} is not a literal: {e:?}"),
    }
}

#[test]
fn shared_constants_reach_every_shader_with_the_rust_values() {
    use oit_core::consts::SHARED;
    use oit_core::shader::{Const, SOURCES};
    for path in entry_files() {
        let m = validate(path);
        for c in SHARED {
            let (name, want) = match *c {
                Const::U32(n, v) => (n, naga::Literal::U32(v)),
                Const::F32(n, v) => (n, naga::Literal::F32(v)),
            };
            assert_eq!(naga_constant(&m, name), Some(want), "{path}: {name}");
        }
    }
    // Defined once: no WGSL file declares a shared constant of its own.
    for (path, src) in SOURCES {
        for c in SHARED {
            let name = c.name();
            assert!(!src.contains(&format!("const {name}:")), "{path} defines {name}, which consts.rs owns");
        }
    }
}

/// A file's own `//!define` sets a constant for its pipelines alone: the expansion pass writes
/// the corners that every other shader only reads.
#[test]
fn a_define_sets_a_constant_for_its_file_alone() {
    let variant = variant_consts(SceneVariant { primitives: true, ..Default::default() });
    let expand = compose("expand.wgsl", &variant);
    assert!(expand.contains("const EXPANDING: u32 = 1u;") && !expand.contains("const EXPANDING: u32 = 0u;"));
    assert!(expand.contains("var<storage, read_write> expanded"));
    let blend = compose("blend.wgsl", &variant);
    assert!(blend.contains("const EXPANDING: u32 = 0u;") && blend.contains("var<storage, read> expanded"));
}
