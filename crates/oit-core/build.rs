//! Embeds every WGSL file under `shaders/` (the list `shader::SOURCES` is generated here, not
//! kept by hand): a new shader file is picked up by the next build.

use std::path::{Path, PathBuf};

fn collect(dir: &Path, root: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir).expect("shaders/ is readable").map(|e| e.expect("entry").path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            collect(&p, root, out);
        } else if p.extension().is_some_and(|e| e == "wgsl") {
            out.push(p.strip_prefix(root).expect("under shaders/").to_path_buf());
        }
    }
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let root = manifest.join("../../shaders").canonicalize().expect("shaders/ beside the crates");
    // Relative to the package: clones that share a target directory share this script's last
    // run, and cargo checks relative paths in the clone being built (absolute ones would be the
    // clone that ran it last, whose files may be others).
    println!("cargo::rerun-if-changed=../../shaders");
    // And again whenever cargo is run from another directory (another checkout): a relative path
    // whose files are older than the other checkout's run would not say so.
    println!("cargo::rerun-if-env-changed=PWD");
    let mut files = Vec::new();
    collect(&root, &root, &mut files);
    let mut code = String::from(
        "/// Every WGSL file, embedded at build time, by path relative to `shaders/`.\npub const SOURCES: &[(&str, &str)] = &[\n",
    );
    for f in &files {
        let rel = f.to_str().expect("UTF-8 shader path").replace('\\', "/");
        println!("cargo::rerun-if-changed=../../shaders/{rel}");
        // Relative to the crate being compiled, not this run's absolute path: clones that share
        // a target directory share this file, and each must embed its own shaders.
        code.push_str(&format!("    ({rel:?}, include_str!(concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/../../shaders/{rel}\"))),\n"));
    }
    code.push_str("];\n");
    // Which checkout the list is of: shader.rs refuses to build with another's.
    code.push_str(&format!(
        "/// The package directory this list was made in.\npub const SOURCES_OF: &str = {:?};\n",
        manifest.display().to_string()
    ));
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo")).join("shader_sources.rs");
    std::fs::write(out, code).expect("OUT_DIR is writable");
}
