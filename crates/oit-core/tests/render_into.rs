//! Frames into a caller's texture (`Renderer::render_into`): oit's transparent pass over an
//! opaque picture and depth the caller drew itself equals the frame of the same scene with that
//! opaque geometry as its own mesh.

mod common;

use common::caller;
use oit_core::{shared_context, Camera, Mesh, Renderer, Scene, Target};

fn quad(x: (f32, f32), z: f32, rgba: [f32; 4], opaque: bool) -> Mesh {
    let p = vec![[x.0, -1.0, z], [x.1, -1.0, z], [x.1, 1.0, z], [x.0, 1.0, z]];
    Mesh::new(p, vec![[0, 1, 2], [0, 2, 3]], vec![rgba], opaque).unwrap()
}

fn identity() -> Camera {
    Camera::from_rows([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]).unwrap()
}

fn transparent() -> Scene {
    let mut scene = Scene::new();
    scene.add_mesh(quad((-1.0, 1.0), 0.3, [1.0, 0.2, 0.1, 0.5], false));
    scene.add_mesh(quad((-1.0, 1.0), 0.8, [0.1, 0.3, 1.0, 0.6], false));
    scene
}

#[test]
fn the_transparent_pass_over_a_callers_picture_equals_the_frame_with_its_opaque_mesh() {
    let gpu = shared_context(None).expect("a GPU adapter (lavapipe in CI)");
    let size = (64, 48);
    let (wall, sky) = ([0.5f32, 0.4, 0.3], [0.2f32, 0.6, 0.9]);
    // The caller's wall covers the left half at depth 0.6, over its sky.
    let picture = caller::draw_opaque(&gpu, size, wgpu::TextureFormat::Rgba32Float, 0.6, wall, 0.5, sky.map(f64::from));
    let mut r = Renderer::new(gpu.clone(), size.0, size.1).unwrap();
    for method in ["abuffer", "unsorted", "hybrid"] {
        let stats = r
            .render_into(
                &transparent(),
                &identity(),
                method,
                &[],
                [0.0; 3],
                Target { color: &picture.color, depth: Some(&picture.depth), encode_srgb: false },
            )
            .unwrap();
        assert_eq!(stats.method, method);
        let got: Vec<f32> = bytemuck::pod_collect_to_vec(&caller::read_texture(&gpu, &picture.color, 16));
        // The same frame with the wall as an opaque mesh and the sky as the background.
        let mut scene = transparent();
        scene.add_mesh(quad((-1.0, 0.0), 0.6, [wall[0], wall[1], wall[2], 1.0], true));
        let want = r.render(&scene, &identity(), method, &[], sky).unwrap().image;
        for (i, (g, w)) in got.chunks(4).zip(want.chunks(4)).enumerate() {
            for c in 0..3 {
                assert!((g[c] - w[c]).abs() <= 1e-6, "{method}: pixel {i} channel {c}: {} against {}", g[c], w[c]);
            }
        }
        // Behind the wall the far layer is hidden; beside it both layers are over the sky.
        let (left, right) = (&got[(10 * size.0 as usize + 5) * 4..][..3], &got[(10 * size.0 as usize + 60) * 4..][..3]);
        assert!(left != right, "{method}: the caller's depth hid nothing");
        // Draw the caller's picture again for the next method (render_into wrote over it).
        let again = caller::draw_opaque(&gpu, size, wgpu::TextureFormat::Rgba32Float, 0.6, wall, 0.5, sky.map(f64::from));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_texture(again.color.as_image_copy(), picture.color.as_image_copy(), picture.color.size());
        gpu.queue.submit([enc.finish()]);
    }
}

/// The error `render_into` refuses `target` with, at the renderer's `size`.
fn refusal(gpu: &std::sync::Arc<oit_core::GpuContext>, size: (u32, u32), target: Target<'_>) -> String {
    let mut r = Renderer::new(gpu.clone(), size.0, size.1).unwrap();
    r.render_into(&transparent(), &identity(), "abuffer", &[], [0.0; 3], target).unwrap_err().to_string()
}

#[test]
fn a_target_of_another_size_or_a_wrong_depth_is_refused_by_name() {
    let gpu = shared_context(None).expect("a GPU adapter (lavapipe in CI)");
    let picture = caller::draw_opaque(&gpu, (32, 16), wgpu::TextureFormat::Rgba8Unorm, 0.5, [1.0; 3], 1.0, [0.0; 3]);
    let e = refusal(&gpu, (64, 48), Target { color: &picture.color, depth: None, encode_srgb: false });
    assert!(e.contains("make them the same size"), "{e}");
    let e = refusal(&gpu, (32, 16), Target { color: &picture.color, depth: Some(&picture.color), encode_srgb: false });
    assert!(e.contains("must be Depth32Float"), "{e}");
    // A budget below the frame's targets, which render_into keeps frame-sized, before any work.
    let mut r = Renderer::new(gpu.clone(), 32, 16).unwrap();
    r.set_memory_budget(Some(4096)).unwrap();
    let e = r
        .render_into(
            &transparent(),
            &identity(),
            "abuffer",
            &[],
            [0.0; 3],
            Target { color: &picture.color, depth: Some(&picture.depth), encode_srgb: false },
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("render_into draws into frame-sized targets"), "{e}");
}
