//! Every WGSL file parses and validates with naga (no GPU needed), and the structs shared
//! with Rust have the sizes naga computes.

use oit_core::gpu_types::{Alloc, CompactNode, CoverageNode, FrameUniform, PallBlock, PoolNode, PrimNode, PrimShading};
use oit_core::shader::{compose, entry_files, DEFAULT_CONSTS};

fn validate(path: &str) -> naga::Module {
    let src = compose(path, DEFAULT_CONSTS);
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
    assert_eq!(struct_size(&m, "Node") as usize, std::mem::size_of::<PoolNode>());
    assert_eq!(struct_size(&m, "Alloc") as usize, std::mem::size_of::<Alloc>());
    let m = validate("adaptive.wgsl");
    assert_eq!(struct_size(&m, "Node") as usize, std::mem::size_of::<PrimNode>());
    let m = validate("compact_abuffer.wgsl");
    assert_eq!(struct_size(&m, "Node") as usize, std::mem::size_of::<CompactNode>());
    assert_eq!(struct_size(&m, "PrimShading") as usize, std::mem::size_of::<PrimShading>());
    let m = validate("abuffer_coverage.wgsl");
    assert_eq!(struct_size(&m, "Node") as usize, std::mem::size_of::<CoverageNode>());
    let m = validate("pall.wgsl");
    assert_eq!(struct_size(&m, "Block") as usize, std::mem::size_of::<PallBlock>());
}
