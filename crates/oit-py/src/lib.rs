//! Thin PyO3 layer over oit-core: array conversion, GIL release during GPU and reference
//! work, and one mapping from `OitError` to Python exceptions (error.rs). The public API is
//! `python/oit`; this module (`oit._oit`) is private.

use pyo3::prelude::*;

mod convert;
mod error;
mod guard;
mod info;
mod load;
mod primitives;
mod reference;
mod renderer;
mod scene;
mod scenefile;
mod surface;

use guard::guarded;

guarded! { fns GUARDED;

/// Panics on purpose, under the guard: tests/test_load_entry_points.py proves it arrives as a
/// RuntimeError, not as PanicException.
#[pyfunction]
fn _panic_for_test() -> PyResult<()> {
    panic!("a panic on purpose (oit._oit._panic_for_test)")
}
}

#[pymodule]
fn _oit(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<scene::Scene>()?;
    m.add_class::<renderer::Renderer>()?;
    m.add_function(wrap_pyfunction!(info::methods, m)?)?;
    m.add_function(wrap_pyfunction!(reference::reference, m)?)?;
    m.add_function(wrap_pyfunction!(reference::view_direction, m)?)?;
    m.add_function(wrap_pyfunction!(info::memory_bytes, m)?)?;
    m.add_function(wrap_pyfunction!(info::constants, m)?)?;
    m.add_function(wrap_pyfunction!(info::surface_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(info::stats_schema, m)?)?;
    m.add_function(wrap_pyfunction!(info::extra_merge_rules, m)?)?;
    m.add_function(wrap_pyfunction!(load::load_file, m)?)?;
    m.add_function(wrap_pyfunction!(scenefile::encode_scene, m)?)?;
    m.add_function(wrap_pyfunction!(scenefile::decode_scene, m)?)?;
    m.add_function(wrap_pyfunction!(scenefile::scene_file_format, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    let classes = [("Scene", scene::Scene::GUARDED), ("Renderer", renderer::Renderer::GUARDED)];
    let mut guarded: Vec<String> = classes.iter().flat_map(|(c, names)| names.iter().map(move |n| format!("{c}.{n}"))).collect();
    let functions = [info::GUARDED, reference::GUARDED, load::GUARDED, scenefile::GUARDED, GUARDED];
    guarded.extend(functions.iter().flat_map(|names| names.iter()).map(|n| n.to_string()));
    m.add("_GUARDED", guarded)?;
    Ok(())
}
