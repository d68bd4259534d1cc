//! Gaussian splats on the GPU (lavapipe in CI) against the float64 reference: a mixed scene of
//! splats and triangle meshes, under perspective, through the exact A-buffer (docs/methods.md,
//! "Gaussian splats").

use glam::{DQuat, DVec3};
use oit_core::{reference, shared_context, Camera, Mesh, Renderer, Scene};

const SIZE: u32 = 96;

/// Looking at the origin from (0.4, 0.6, 3), 50 degrees, depth 0.1 .. 20 to [0, 1].
fn camera() -> Camera {
    let view = glam::dcamera::rh::view::look_at_mat4(DVec3::new(0.4, 0.6, 3.0), DVec3::ZERO, DVec3::Y);
    let proj = glam::dcamera::rh::proj::directx::perspective(50f64.to_radians(), 1.0, 0.1, 20.0);
    let m = (proj * view).transpose().to_cols_array_2d();
    Camera::from_rows(m).unwrap()
}

/// A deterministic number in [0, 1) from `i` (a hash; no random generator needed).
fn unit(i: u32) -> f32 {
    let mut x = i.wrapping_mul(0x9e37_79b9) ^ 0x85eb_ca6b;
    x ^= x >> 15;
    x = x.wrapping_mul(0x2c1b_3c6d);
    x ^= x >> 12;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

/// Splats of every size and orientation among a transparent triangle crossing them and an
/// opaque floor behind; their colors spherical harmonics of `sh` degree where given.
fn scene(sh: Option<u32>) -> Scene {
    let mut scene = Scene::new();
    let floor = vec![[-3.0, -1.0, -3.0], [3.0, -1.0, -3.0], [3.0, -1.0, 2.0], [-3.0, -1.0, 2.0]];
    scene.add_mesh(Mesh::new(floor, vec![[0, 2, 1], [0, 3, 2]], vec![[0.3, 0.35, 0.4, 1.0]], true).unwrap());
    let n = 40;
    let (mut means, mut scales, mut rotations, mut opacities, mut colors) = (vec![], vec![], vec![], vec![], vec![]);
    for i in 0..n {
        let r = |k: u32| unit(17 * i + k);
        means.push([2.0 * r(0) - 1.0, 1.6 * r(1) - 0.8, 1.4 * r(2) - 0.9]);
        scales.push([0.02 + 0.25 * r(3), 0.02 + 0.12 * r(4), 0.005 + 0.1 * r(5)]);
        let axis = DVec3::new(r(6) as f64 - 0.5, r(7) as f64 - 0.5, r(8) as f64 - 0.5).normalize();
        let q = DQuat::from_axis_angle(axis, 6.0 * r(9) as f64);
        rotations.push([q.w as f32, q.x as f32, q.y as f32, q.z as f32]);
        opacities.push(0.1 + 0.9 * r(10));
        colors.push([r(11), r(12), r(13)]);
    }
    match sh {
        None => _ = scene.add_gaussians(means, scales, rotations, opacities, colors).unwrap(),
        Some(degree) => {
            let k = ((degree + 1) * (degree + 1)) as usize;
            let sh = (0..n as usize * k).map(|j| [0, 1, 2].map(|c| unit(9000 + 3 * j as u32 + c) - 0.5)).collect();
            let m = Mesh::gaussians_sh(means, scales, rotations, opacities, sh, degree).unwrap();
            // Twice: in place and rotated, scaled and tinted (the view direction and the tint
            // go through the instance).
            let turn = glam::DMat4::from_rotation_y(0.7) * glam::DMat4::from_scale(DVec3::new(1.0, 0.6, 1.2));
            let rows = |m: glam::DMat4| m.transpose().to_cols_array_2d();
            let instances = vec![oit_core::Instance::IDENTITY, oit_core::Instance::from_rows(rows(turn), [0.9, 0.7, 1.0, 0.8]).unwrap()];
            scene.add_placed(m, instances);
        }
    }
    let sheet = vec![[-1.2, -0.9, 0.3], [1.1, -0.7, -0.6], [0.0, 1.0, 0.0]];
    scene.add_mesh(Mesh::new(sheet, vec![[0, 1, 2]], vec![[0.9, 0.2, 0.1, 0.45]], false).unwrap());
    scene
}

#[test]
fn abuffer_equals_the_reference_on_splats_mixed_with_meshes() {
    check(&scene(None), "splats");
}

#[test]
fn abuffer_equals_the_reference_on_instanced_splats_of_every_harmonic_degree() {
    for degree in 0..=3 {
        check(&scene(Some(degree)), &format!("degree {degree}"));
    }
}

fn check(scene: &Scene, what: &str) {
    let ctx = shared_context(None).expect("a GPU adapter (lavapipe in CI)");
    let mut r = Renderer::new(ctx, SIZE, SIZE).unwrap();
    let f = r.render(scene, &camera(), "abuffer", &[], [1.0; 3]).unwrap();
    let want = reference(scene, &camera(), SIZE, SIZE, [1.0; 3]).unwrap();
    let mut errors: Vec<f64> = Vec::new();
    let mut ambiguous = 0;
    for p in 0..(SIZE * SIZE) as usize {
        if want.ambiguous[p] {
            ambiguous += 1;
            continue;
        }
        let e = (0..4).map(|c| (f.image[4 * p + c] as f64 - want.image[4 * p + c]).abs()).fold(0.0, f64::max);
        errors.push(e);
    }
    errors.sort_by(f64::total_cmp);
    let max = *errors.last().unwrap();
    let p99 = errors[errors.len() * 99 / 100];
    println!("{what}: {} pixels compared, {ambiguous} ambiguous, max error {max:.2e}, p99 {p99:.2e}", errors.len());
    assert!(want.depth_complexity.iter().any(|&d| d >= 4), "the splats overlap");
    // Float rounding: float32 footprints, exp and blending over a few layers.
    assert!(max < 1e-4 && p99 < 3e-5, "max {max:.2e}, p99 {p99:.2e}");
}
