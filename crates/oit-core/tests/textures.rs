//! Textures on the GPU (lavapipe in CI) against the float64 reference: a receding, textured
//! floor seen at a grazing angle, so that one frame spans magnification and a dozen mip levels,
//! under every sampler (wrap modes, nearest and linear filters and mips, a UV transform), with
//! an emissive texture and an alpha cutoff; and one image shared by two materials, uploaded once.

use std::sync::Arc;

use glam::DVec3;
use oit_core::shading::{Filter, Sampler, TextureMap, Wrap};
use oit_core::{reference, shared_context, Camera, Material, Mesh, Renderer, Scene, Shading, Texture};

const SIZE: u32 = 48;

/// A 32 x 16 image of random texels (a fixed generator), alpha between 0.3 and 1.
fn image(seed: u64) -> Arc<Texture> {
    let mut x = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    let rgba: Vec<u8> = (0..32 * 16 * 4)
        .map(|i| {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let v = (x >> 33) as u8;
            if i % 4 == 3 {
                77 + v % 179
            } else {
                v
            }
        })
        .collect();
    Arc::new(Texture::from_rgba8(32, 16, rgba, true).unwrap())
}

/// A floor of 20 x 20 units at y = 0 with UVs repeating `repeat` times across it.
fn floor(material: Material, repeat: f32) -> Mesh {
    let p = vec![[-10.0, 0.0, -18.0], [10.0, 0.0, -18.0], [10.0, 0.0, 2.0], [-10.0, 0.0, 2.0]];
    let uv = vec![[0.0, 0.0], [repeat, 0.0], [repeat, repeat], [0.0, repeat]];
    let mesh = Mesh::new(p, vec![[0, 2, 1], [0, 3, 2]], vec![[0.9, 0.8, 0.7, 0.9]], false).unwrap();
    mesh.with_surface(None, Some(uv), material).unwrap()
}

fn camera() -> Camera {
    let view = glam::dcamera::rh::view::look_at_mat4(DVec3::new(0.3, 1.0, 2.5), DVec3::new(0.0, 0.0, -6.0), DVec3::Y);
    let proj = glam::dcamera::rh::proj::directx::perspective(50f64.to_radians(), 1.0, 0.5, 40.0);
    Camera::from_rows((proj * view).transpose().to_cols_array_2d()).unwrap()
}

/// Every pixel the reference does not call ambiguous within float32 shading plus the change of
/// the reference image over a thousandth of a pixel (docs/shading.md, "Accuracy").
fn assert_agrees(scene: &Scene, label: &str) {
    let want = reference(scene, &camera(), SIZE, SIZE, [1.0; 3]).unwrap();
    let mut r = Renderer::new(shared_context(None).expect("a GPU adapter (lavapipe in CI)"), SIZE, SIZE).unwrap();
    let at = |img: &[f64], x: i64, y: i64, c: usize| {
        img[4 * (y.clamp(0, SIZE as i64 - 1) * SIZE as i64 + x.clamp(0, SIZE as i64 - 1)) as usize + c]
    };
    for method in ["abuffer", "compact_abuffer", "depth_peeling"] {
        let got = r.render(scene, &camera(), method, &[], [1.0; 3]).unwrap();
        let mut checked = 0;
        for y in 0..SIZE as i64 {
            for x in 0..SIZE as i64 {
                let k = (y * SIZE as i64 + x) as usize;
                if want.ambiguous[k] {
                    continue;
                }
                checked += 1;
                for c in 0..3 {
                    let w = at(&want.image, x, y, c);
                    let step = [(1, 0), (-1, 0), (0, 1), (0, -1)]
                        .iter()
                        .map(|(dx, dy)| (at(&want.image, x + dx, y + dy, c) - w).abs())
                        .fold(0.0, f64::max);
                    let err = (got.image[4 * k + c] as f64 - w).abs();
                    assert!(
                        err <= 4e-6 + 1e-3 * step,
                        "{label}, {method}: pixel ({x}, {y}) channel {c}: {} against {w}",
                        got.image[4 * k + c]
                    );
                }
            }
        }
        assert!(checked as f64 > 0.85 * (SIZE * SIZE) as f64, "{label}: only {checked} pixels unambiguous");
    }
}

#[test]
fn every_sampler_filters_as_the_reference_does() {
    let rotated = [[0.8, -0.6, 0.25], [0.6, 0.8, -0.5]];
    let samplers = [
        ("trilinear, repeat", Sampler::default(), oit_core::shading::UV_IDENTITY),
        (
            "nearest, nearest mips, clamp, transformed",
            Sampler {
                wrap_u: Wrap::ClampToEdge,
                wrap_v: Wrap::MirroredRepeat,
                mag: Filter::Nearest,
                min: Filter::Nearest,
                mipmap: Some(Filter::Nearest),
            },
            rotated,
        ),
        (
            "bilinear without mips, mirrored",
            Sampler { wrap_u: Wrap::MirroredRepeat, wrap_v: Wrap::Repeat, mag: Filter::Linear, min: Filter::Linear, mipmap: None },
            oit_core::shading::UV_IDENTITY,
        ),
        (
            "nearest within levels, linear between",
            Sampler { mag: Filter::Nearest, min: Filter::Nearest, mipmap: Some(Filter::Linear), ..Sampler::default() },
            rotated,
        ),
    ];
    for (label, sampler, transform) in samplers {
        let map = TextureMap { image: image(1), sampler, transform };
        let mut scene = Scene::new();
        scene.add_mesh(floor(Material { texture: Some(map), ..Default::default() }, 6.0));
        assert_agrees(&scene, label);
    }
}

#[test]
fn emission_and_alpha_cutoffs_shade_as_the_reference_does() {
    let lit = Material {
        shading: Shading::Smooth,
        specular: 0.3,
        texture: Some(TextureMap::new(image(2))),
        emissive: [0.6, 0.3, 0.1],
        emissive_texture: Some(TextureMap::new(image(3))),
        ..Default::default()
    };
    let mut scene = Scene::new();
    scene.add_mesh(floor(lit, 4.0));
    assert_agrees(&scene, "emissive");
    let masked = Material { texture: Some(TextureMap::new(image(4))), alpha_cutoff: Some(0.6), ..Default::default() };
    let mut scene = Scene::new();
    scene.add_mesh(floor(masked, 3.0));
    assert_agrees(&scene, "alpha cutoff");
}

#[test]
fn an_image_two_materials_use_is_uploaded_once() {
    let shared = image(5);
    let bytes = shared.bytes();
    let mut scene = Scene::new();
    for repeat in [2.0, 5.0] {
        scene.add_mesh(floor(Material { texture: Some(TextureMap::new(shared.clone())), ..Default::default() }, repeat));
    }
    let mut r = Renderer::new(shared_context(None).expect("a GPU adapter (lavapipe in CI)"), 8, 8).unwrap();
    let stats = r.render(&scene, &camera(), "abuffer", &[], [1.0; 3]).unwrap().stats;
    // 32 x 16 with its mips (683 texels) fits a 32 x 32 atlas layer: 4 KiB, not twice that.
    assert_eq!(bytes, 4 * 683);
    assert_eq!(stats.texture_bytes, 4 * 32 * 32);
}
