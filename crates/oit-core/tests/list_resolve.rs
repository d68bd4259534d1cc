//! The list methods' sorted resolve under its two strategies (method::resolve_plan::
//! ResolveStrategy): the plain one (no loop limit: every pixel finished in the first dispatch)
//! gives the budgeted one's bits, on scenes whose deepest pixel the plain one can finish within
//! llvmpipe's loop limit. With OIT_FINGERPRINTS=path set, each list method's image on those
//! scenes is also hashed into that file, so that two builds can be compared bit for bit.

use oit_core::context::DeviceProfile;
use oit_core::method::default_consts;
use oit_core::shader::{compose, Const};
use oit_core::{shared_context, Antialias, AntialiasMode, Camera, GpuContext, Mesh, Renderer, Scene};
use std::sync::Arc;

fn identity() -> Camera {
    Camera::from_rows([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]).unwrap()
}

/// `n` pseudo-random triangles around the frame's center (a fixed LCG), every fourth at the depth
/// of the one before it with the same color, so that equal keys reach the tie order.
// 6.283 and 2.094 are any angles, not TAU and TAU / 3: the fingerprints were taken with them.
#[allow(clippy::approx_constant)]
fn deep_scene(n: usize, seed: u64) -> Scene {
    let mut s = seed;
    let mut next = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((s >> 33) as f32) / (1u64 << 31) as f32
    };
    let mut scene = Scene::new();
    let mut last = (0.5f32, [0.5f32, 0.5, 0.5, 0.5]);
    for i in 0..n {
        let (z, c) = if i % 4 == 3 { last } else { (0.05 + 0.9 * next(), [next(), next(), next(), 0.05 + 0.3 * next()]) };
        last = (z, c);
        let (cx, cy) = (0.3 * (next() - 0.5), 0.3 * (next() - 0.5));
        let r = 0.6 + next();
        let a = next() * 6.283;
        let p: Vec<[f32; 3]> = (0..3).map(|k| a + k as f32 * 2.094).map(|t| [cx + r * t.cos(), cy + r * t.sin(), z]).collect();
        scene.add_mesh(Mesh::new(p, vec![[0, 1, 2]], vec![c], false).unwrap());
    }
    scene
}

fn fingerprint(image: &[f32]) -> u64 {
    image.iter().fold(0xcbf29ce484222325u64, |h, v| (h ^ v.to_bits() as u64).wrapping_mul(0x100000001b3))
}

const LISTED: &[&str] = &["abuffer", "pall", "sbuffer", "compact_abuffer", "adaptive_lists", "mlab_lists", "adaptive", "mlab"];

#[test]
fn fingerprints_of_the_list_methods() {
    let Ok(path) = std::env::var("OIT_FINGERPRINTS") else { return };
    let gpu = shared_context(None).expect("a GPU adapter (lavapipe in CI)");
    let mut out = String::new();
    for (label, scene, w, h) in
        [("shallow", deep_scene(12, 1), 16, 12), ("mid", deep_scene(260, 3), 12, 10), ("deep", deep_scene(700, 7), 24, 20)]
    {
        let mut r = Renderer::new(gpu.clone(), w, h).unwrap();
        for name in LISTED {
            let line = match r.render(&scene, &identity(), name, &[], [0.2, 0.3, 0.4]) {
                Ok(f) => format!("{label} {name} {:016x} max_dc={}\n", fingerprint(&f.image), f.stats.max_depth_complexity),
                Err(e) => format!("{label} {name} error {e}\n"),
            };
            out.push_str(&line);
        }
        let f = r
            .render_antialiased(
                &scene,
                &identity(),
                "abuffer",
                &[],
                [0.2, 0.3, 0.4],
                Antialias { samples: 4, mode: AntialiasMode::Coverage },
            )
            .unwrap();
        out.push_str(&format!("{label} abuffer-coverage {:016x}\n", fingerprint(&f.image)));
    }
    std::fs::write(path, out).unwrap();
}

/// The exact methods, whose resolve sweeps their sorted lists.
const SWEPT: &[&str] = &["abuffer", "pall", "sbuffer", "compact_abuffer"];

fn scenes() -> [(&'static str, Scene, u32, u32); 3] {
    [("shallow", deep_scene(12, 1), 16, 12), ("mid", deep_scene(260, 3), 12, 10), ("deep", deep_scene(700, 7), 24, 20)]
}

fn resolve_sweeps(f: &oit_core::Frame) -> f64 {
    f.stats.extra.iter().find(|(k, _)| *k == "resolve_sweeps").map_or(f64::NAN, |(_, v)| *v)
}

#[test]
fn the_plain_resolve_validates() {
    let mut consts: Vec<Const> = default_consts().iter().copied().filter(|c| !matches!(c, Const::U32("BUDGETED", _))).collect();
    consts.push(Const::U32("BUDGETED", 0));
    for path in ["abuffer.wgsl", "abuffer_coverage.wgsl", "pall.wgsl", "sbuffer.wgsl", "compact_abuffer.wgsl"] {
        let src = compose(path, &consts);
        assert!(!src.contains("steps < STEP_BUDGET"), "{path}: the plain resolve keeps a budget");
        let module = naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{path}: {}", e.emit_to_string(&src)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{path}: {e:?}"));
    }
}

#[test]
fn the_plain_resolve_gives_the_budgeted_ones_bits() {
    let budgeted = shared_context(None).expect("a GPU adapter (lavapipe in CI)");
    if budgeted.profile.loop_limit.is_none() {
        return; // the adapter runs the plain resolve already: nothing to compare it with
    }
    let plain = Arc::new(GpuContext::new(None).unwrap().with_profile(DeviceProfile::UNLIMITED));
    // Past one run only (the shallow scene's pixels never leave cs_sort under either strategy).
    for (label, scene, w, h) in scenes().into_iter().skip(1) {
        let mut a = Renderer::new(budgeted.clone(), w, h).unwrap();
        let mut b = Renderer::new(plain.clone(), w, h).unwrap();
        for name in SWEPT {
            let fa = a.render(&scene, &identity(), name, &[], [0.2, 0.3, 0.4]).unwrap();
            let fb = b.render(&scene, &identity(), name, &[], [0.2, 0.3, 0.4]).unwrap();
            assert!(fa.image.iter().zip(&fb.image).all(|(x, y)| x.to_bits() == y.to_bits()), "{label} {name}: the images differ");
            // One dispatch of cs_sort finishes every pixel of the plain resolve.
            assert_eq!(resolve_sweeps(&fb), 1.0, "{label} {name}");
            if label == "deep" {
                assert!(resolve_sweeps(&fa) > 1.0, "{label} {name}: the budgeted resolve should resume its deep pixels");
            }
        }
        let coverage = |r: &mut Renderer| {
            r.render_antialiased(
                &scene,
                &identity(),
                "abuffer",
                &[],
                [0.2, 0.3, 0.4],
                Antialias { samples: 4, mode: AntialiasMode::Coverage },
            )
            .unwrap()
            .image
        };
        let (ia, ib) = (coverage(&mut a), coverage(&mut b));
        assert!(ia.iter().zip(&ib).all(|(x, y)| x.to_bits() == y.to_bits()), "{label} abuffer coverage: the images differ");
    }
}
