//! An engine's frame with oit's transparent pass in it: the engine draws its own opaque
//! picture and depth, oit draws three transparent layers over it with the exact A-buffer
//! (`Renderer::render_into`), straight into the engine's texture, and the example writes it
//! out as a PNG.
//!
//!     make example      (the Makefile's target directory; `cargo run --release -p oit-core
//!                        --example over_opaque [out.png]` also works, building into ./target)
//!
//! The `render_into` call below is the README's Rust block, as it is written there
//! (tests/test_readme.py checks that the two stay the same; `cargo test` and clippy build this).

#[path = "../tests/common/caller.rs"]
mod caller;

use oit_core::{shared_context, Camera, Mesh, Renderer, Scene};

/// A full-screen quad at NDC depth `z` with one straight RGBA color.
fn layer(z: f32, rgba: [f32; 4]) -> Mesh {
    let p = vec![[-0.8, -0.8, z], [0.8, -0.8, z], [0.8, 0.8, z], [-0.8, 0.8, z]];
    Mesh::new(p, vec![[0, 1, 2], [0, 2, 3]], vec![rgba], false).expect("a valid mesh")
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The Vulkan loader's window-system code prints "XDG_RUNTIME_DIR is invalid or not set"
    // without one (headless machines, CI); a private directory keeps it quiet, as the Python
    // package and the viewer do. Nothing is written there.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none_or(|d| !std::path::Path::new(&d).is_dir()) {
        let dir = std::env::temp_dir().join(format!("oit-runtime-{}", std::process::id()));
        if std::fs::create_dir_all(&dir).is_ok() {
            std::env::set_var("XDG_RUNTIME_DIR", dir);
        }
    }
    let path = std::env::args().nth(1).unwrap_or_else(|| "out/over_opaque.png".into());
    let size = (320, 240);
    let gpu = shared_context(None)?;
    // The engine's opaque pass: a grey wall at depth 0.6 over the left two thirds, sky elsewhere.
    let picture = caller::draw_opaque(&gpu, size, wgpu::TextureFormat::Rgba8UnormSrgb, 0.6, [0.5, 0.5, 0.5], 2.0 / 3.0, [0.3, 0.5, 0.8]);
    // oit's transparent layers: red and green in front of the wall, blue behind it.
    let mut scene = Scene::new();
    scene.add_mesh(layer(0.3, [1.0, 0.1, 0.1, 0.5]));
    scene.add_mesh(layer(0.5, [0.1, 1.0, 0.1, 0.4]));
    scene.add_mesh(layer(0.8, [0.1, 0.1, 1.0, 0.6]));
    let camera = Camera::from_rows([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])?;
    let mut renderer = Renderer::new(gpu.clone(), size.0, size.1)?;
    let caller::Picture { color, depth } = picture;
    #[rustfmt::skip]
    let stats = renderer.render_into(&scene, &camera, "abuffer", &[], [0.0; 3],
                                     oit_core::Target { color: &color, depth: Some(&depth), encode_srgb: false })?;
    println!("{}: {} fragments, {:.1} ms on the GPU", stats.method, stats.fragments, stats.gpu_time_ms.unwrap_or(0.0));
    let pixels = caller::read_texture(&gpu, &color, 4);
    if let Some(dir) = std::path::Path::new(&path).parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(std::fs::File::create(&path)?), size.0, size.1);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header()?.write_image_data(&pixels)?;
    println!("wrote {path}");
    Ok(())
}
