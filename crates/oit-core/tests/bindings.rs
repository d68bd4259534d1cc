//! Every pipeline's bind-group layouts, declared once in Rust (each method's
//! `MethodInfo::pipelines`, the renderer's `cache::ENGINE_PIPELINES`), against what its WGSL
//! binds, by naga reflection and without a GPU: each resource an entry point uses (naga's
//! per-entry-point usage, through the functions it calls) has an entry in the declared layout
//! at its group and binding, visible to its stage, of the type wgpu checks it against
//! (uniform, read-only or read-write storage, depth or float texture, 2D or 2D array). A layout
//! may hold bindings a shader does not use, as wgpu allows; but every binding of a method's
//! own group (storage buffers, float textures) is declared by some shader that binds it.

use std::collections::{BTreeMap, BTreeSet};

use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};
use oit_core::cache::{Layout, PipelineSpec, ENGINE_PIPELINES};
use oit_core::method::{default_consts, variant_consts};
use oit_core::shader::{compose, Const, VALIDATION_VARIANTS};

/// Every declared pipeline, with who declares it.
fn declared() -> Vec<(&'static str, &'static PipelineSpec)> {
    let mut all: Vec<_> = ENGINE_PIPELINES.iter().map(|p| ("the renderer", p)).collect();
    for m in oit_core::methods() {
        assert!(!m.pipelines.is_empty(), "{} declares no pipelines", m.name);
        all.extend(m.pipelines.iter().flat_map(|t| t.iter()).map(|p| (m.name, p)));
    }
    all
}

/// What a binding is, in the terms wgpu matches a shader's resource to a layout entry by.
#[derive(Debug, PartialEq)]
enum Kind {
    Uniform,
    Storage { read_only: bool },
    Texture { sample: &'static str, dimension: wgpu::TextureViewDimension, multisampled: bool },
    Other(String),
}

fn layout_kind(entry: &wgpu::BindGroupLayoutEntry) -> Kind {
    match entry.ty {
        wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, .. } => Kind::Uniform,
        wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Storage { read_only }, .. } => Kind::Storage { read_only },
        wgpu::BindingType::Texture { sample_type, view_dimension, multisampled } => {
            let sample = match sample_type {
                wgpu::TextureSampleType::Float { .. } => "float",
                wgpu::TextureSampleType::Depth => "depth",
                wgpu::TextureSampleType::Sint => "sint",
                wgpu::TextureSampleType::Uint => "uint",
            };
            Kind::Texture { sample, dimension: view_dimension, multisampled }
        }
        ref other => Kind::Other(format!("{other:?}")),
    }
}

fn shader_kind(module: &naga::Module, var: &naga::GlobalVariable) -> Kind {
    use naga::{AddressSpace, ImageClass, ImageDimension, ScalarKind, StorageAccess};
    match var.space {
        AddressSpace::Uniform => Kind::Uniform,
        // wgpu matches the access exactly: read-only is LOAD, read-write LOAD | STORE.
        AddressSpace::Storage { access } if access == StorageAccess::LOAD => Kind::Storage { read_only: true },
        AddressSpace::Storage { access } if access == StorageAccess::LOAD | StorageAccess::STORE => Kind::Storage { read_only: false },
        AddressSpace::Handle => match module.types[var.ty].inner {
            naga::TypeInner::Image { dim, arrayed, class } => {
                let dimension = match (dim, arrayed) {
                    (ImageDimension::D2, false) => wgpu::TextureViewDimension::D2,
                    (ImageDimension::D2, true) => wgpu::TextureViewDimension::D2Array,
                    _ => return Kind::Other(format!("{dim:?} image (arrayed: {arrayed})")),
                };
                let (sample, multisampled) = match class {
                    ImageClass::Depth { multi } => ("depth", multi),
                    ImageClass::Sampled { kind: ScalarKind::Float, multi } => ("float", multi),
                    ImageClass::Sampled { kind: ScalarKind::Sint, multi } => ("sint", multi),
                    ImageClass::Sampled { kind: ScalarKind::Uint, multi } => ("uint", multi),
                    other => return Kind::Other(format!("{other:?}")),
                };
                Kind::Texture { sample, dimension, multisampled }
            }
            ref other => Kind::Other(format!("{other:?}")),
        },
        other => Kind::Other(format!("{other:?}")),
    }
}

fn reflect(path: &str, consts: &[Const]) -> (naga::Module, ModuleInfo) {
    reflect_source(path, &compose(path, consts))
}

fn reflect_source(path: &str, src: &str) -> (naga::Module, ModuleInfo) {
    let module = naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{path}: {}", e.emit_to_string(src)));
    let info = Validator::new(ValidationFlags::all(), Capabilities::all()).validate(&module).unwrap_or_else(|e| panic!("{path}: {e:?}"));
    (module, info)
}

fn naga_stage(stage: wgpu::ShaderStages) -> naga::ShaderStage {
    match stage {
        wgpu::ShaderStages::VERTEX => naga::ShaderStage::Vertex,
        wgpu::ShaderStages::FRAGMENT => naga::ShaderStage::Fragment,
        _ => naga::ShaderStage::Compute,
    }
}

/// What is wrong with `spec` compiled as `module`: one line per resource an entry point uses
/// that its declared layout lacks or declares otherwise.
fn mismatches(owner: &str, spec: &PipelineSpec, module: &naga::Module, info: &ModuleInfo) -> Vec<String> {
    let mut wrong = Vec::new();
    for (name, stage) in spec.entry_points() {
        let at = format!("{owner}: {} {name} (pipeline {})", spec.shader, spec.entry);
        let Some(index) = module.entry_points.iter().position(|e| e.name == name && e.stage == naga_stage(stage)) else {
            wrong.push(format!("{at}: no {stage:?} entry point {name} in the shader"));
            continue;
        };
        let uses = info.get_entry_point(index);
        for (handle, var) in module.global_variables.iter() {
            let Some(rb) = &var.binding else { continue };
            if uses[handle].is_empty() {
                continue;
            }
            let what = format!("{at}: @group({}) @binding({}) {}", rb.group, rb.binding, var.name.as_deref().unwrap_or("?"));
            let Some(layout) = spec.groups.get(rb.group as usize) else {
                wrong.push(format!("{what}: the pipeline declares only groups 0..{}", spec.groups.len()));
                continue;
            };
            let entries = layout.entries();
            let Some(entry) = entries.iter().find(|e| e.binding == rb.binding) else {
                wrong.push(format!("{what}: {layout:?} has no binding {}", rb.binding));
                continue;
            };
            if let Some(named) = layout.named() {
                let declared = named.iter().find(|(_, b)| *b == rb.binding).map(|(n, _)| *n);
                let name = var.name.as_deref().unwrap_or("?");
                if declared != Some(name) {
                    wrong.push(format!("{what}: {layout:?} names binding {} {declared:?}, the shader '{name}'", rb.binding));
                }
            }
            let (shader, rust) = (shader_kind(module, var), layout_kind(entry));
            if shader != rust {
                wrong.push(format!("{what}: the shader binds {shader:?}, {layout:?} declares {rust:?}"));
            }
            if !entry.visibility.contains(stage) {
                wrong.push(format!("{what}: {layout:?} is not visible to the {stage:?} stage ({:?})", entry.visibility));
            }
        }
    }
    wrong
}

#[test]
fn every_declared_pipeline_binds_what_its_shader_uses() {
    let all = declared();
    assert!(all.len() > 40, "the pipeline tables look truncated: {} pipelines", all.len());
    let variants: Vec<Vec<Const>> =
        std::iter::once(default_consts()).chain(VALIDATION_VARIANTS.iter().map(|v| variant_consts(*v))).collect();
    let mut wrong = BTreeSet::new();
    for consts in &variants {
        let mut modules = BTreeMap::new();
        for (owner, spec) in &all {
            let (module, info) = modules.entry(spec.shader).or_insert_with(|| reflect(spec.shader, consts));
            wrong.extend(mismatches(owner, spec, module, info));
        }
    }
    assert!(wrong.is_empty(), "declared layouts disagree with the shaders:\n{}", wrong.into_iter().collect::<Vec<_>>().join("\n"));
}

/// A method's own group (its storage buffers or float textures) binds nothing that no shader
/// declares: a binding there that no shader has means the Rust and WGSL sides disagree on
/// the group's shape. Shared groups (scene, targets) may hold what a shader leaves out.
#[test]
fn every_binding_of_a_method_group_is_declared_by_a_shader() {
    let mut declared_at: BTreeMap<(String, usize), BTreeSet<u32>> = BTreeMap::new();
    let mut wanted: BTreeMap<(String, usize), Vec<u32>> = BTreeMap::new();
    let mut modules = BTreeMap::new();
    for (_, spec) in declared() {
        for (g, layout) in spec.groups.iter().enumerate() {
            if !matches!(layout, Layout::Storage(_) | Layout::Textures(_)) {
                continue;
            }
            let key = (format!("{layout:?}"), g);
            // A binding named "_" is bound for the group's shape, and no shader of it reads it.
            let named = layout.named().expect("a method's own group is bound by name");
            wanted.insert(key.clone(), named.iter().filter(|(n, _)| *n != "_").map(|(_, b)| *b).collect());
            let (module, _) = modules.entry(spec.shader).or_insert_with(|| reflect(spec.shader, &default_consts()));
            let bound = module.global_variables.iter().filter_map(|(_, v)| v.binding.as_ref()).filter(|b| b.group as usize == g);
            declared_at.entry(key).or_default().extend(bound.map(|b| b.binding));
        }
    }
    for (key, bindings) in wanted {
        let missing: Vec<u32> = bindings.into_iter().filter(|b| !declared_at[&key].contains(b)).collect();
        assert!(missing.is_empty(), "{} at group {}: no shader that binds it declares bindings {missing:?}", key.0, key.1);
    }
}

/// A binding or struct written the same way in two files belongs in one shared include
/// (shaders/common/), so that the files cannot drift apart.
#[test]
fn no_binding_or_struct_is_written_twice() {
    let mut seen: BTreeMap<String, &str> = BTreeMap::new();
    for (path, src) in oit_core::shader::SOURCES {
        let lines: Vec<&str> = src.lines().map(|l| l.split("//").next().unwrap_or("").trim()).filter(|l| !l.is_empty()).collect();
        for (i, line) in lines.iter().enumerate() {
            let decl = if line.starts_with("@group(") {
                line.to_string()
            } else if line.starts_with("struct ") {
                let end = lines[i..].iter().position(|l| *l == "}").map_or(lines.len(), |e| i + e + 1);
                lines[i..end].join(" ")
            } else {
                continue;
            };
            if let Some(first) = seen.insert(decl.clone(), path) {
                panic!("{first} and {path} both declare `{decl}`: move it to a shared include under shaders/common/");
            }
        }
    }
}

/// Two bindings of one type swapped in a shader (`ktab` and `vis` of hybrid.wgsl, both
/// `array<atomic<u32>>`) bind the wrong buffers with every type check passing: the names catch
/// it, without a GPU.
#[test]
fn swapping_two_bindings_of_one_type_is_caught_by_name() {
    let owner = oit_core::methods().iter().find(|m| m.name == "hybrid").expect("hybrid is registered");
    let spec = owner.pipelines.iter().flat_map(|t| t.iter()).find(|p| p.entry == "fs_store").expect("hybrid's store pass");
    let src = compose(spec.shader, &default_consts());
    let (ktab, vis) = ("@group(2) @binding(0) var<storage, read_write> ktab", "@group(2) @binding(1) var<storage, read_write> vis");
    assert!(src.contains(ktab) && src.contains(vis), "hybrid.wgsl's declarations moved: update this test");
    let (module, info) = reflect_source(spec.shader, &src);
    assert!(mismatches("hybrid", spec, &module, &info).is_empty(), "the shader as written agrees with its declaration");
    // The binding numbers trade places (hybrid.wgsl declares `vis` twice, by its variant).
    let swapped = src.replace(ktab, &ktab.replace("binding(0)", "binding(1)")).replace(vis, &vis.replace("binding(1)", "binding(0)"));
    let (module, info) = reflect_source(spec.shader, &swapped);
    let wrong = mismatches("hybrid", spec, &module, &info);
    // The store pass reads ktab (vis only later passes): it is named where vis is declared.
    assert!(wrong.iter().any(|w| w.contains("names binding 1 Some(\"vis\"), the shader 'ktab'")), "the swap went unseen: {wrong:?}");
}
