//! GPU tests (lavapipe in CI): the A-buffer against hand-computed stacks and the f64
//! reference, and the blend methods where they must agree with it.

use oit_core::{reference, shared_context, Camera, Mesh, Renderer, Scene};

/// A full-screen quad at NDC depth `z` (identity camera) with one straight RGBA color.
fn quad(z: f32, rgba: [f32; 4], opaque: bool) -> Mesh {
    let p = vec![[-1.0, -1.0, z], [1.0, -1.0, z], [1.0, 1.0, z], [-1.0, 1.0, z]];
    Mesh::new(p, vec![[0, 1, 2], [0, 2, 3]], vec![rgba], opaque).unwrap()
}

fn identity() -> Camera {
    Camera::from_rows([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]).unwrap()
}

fn renderer(w: u32, h: u32) -> Renderer {
    Renderer::new(shared_context(None).expect("a GPU adapter (lavapipe in CI)"), w, h).unwrap()
}

#[test]
fn abuffer_matches_hand_computed_stack() {
    let layers = [(0.7, [1.0, 0.0, 0.0, 0.5]), (0.2, [0.0, 1.0, 0.0, 0.25]), (0.5, [0.0, 0.0, 1.0, 0.8])];
    let mut scene = Scene::new();
    for (z, c) in layers {
        scene.add_mesh(quad(z, c, false));
    }
    let bg = [1.0, 1.0, 1.0];
    // Front to back: green (z 0.2), blue (0.5), red (0.7).
    let mut sorted = layers.to_vec();
    sorted.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
    let (mut c, mut t) = ([0.0f64; 3], 1.0f64);
    for (_, rgba) in &sorted {
        for i in 0..3 {
            c[i] += t * rgba[3] as f64 * rgba[i] as f64;
        }
        t *= 1.0 - rgba[3] as f64;
    }
    let want = [c[0] + t * bg[0] as f64, c[1] + t * bg[1] as f64, c[2] + t * bg[2] as f64, 1.0 - t];
    let mut r = renderer(8, 6);
    let f = r.render(&scene, &identity(), "abuffer", &[], bg).unwrap();
    assert_eq!(f.stats.max_depth_complexity, 3);
    assert_eq!(f.stats.fragments, 3 * 8 * 6);
    for px in f.image.chunks(4) {
        for i in 0..4 {
            assert!((px[i] as f64 - want[i]).abs() < 1e-6, "{px:?} vs {want:?}");
        }
    }
}

#[test]
fn opaque_occludes_and_unsorted_agrees_when_submitted_back_to_front() {
    let mut scene = Scene::new();
    scene.add_mesh(quad(0.9, [0.2, 0.3, 0.4, 1.0], true));
    scene.add_mesh(quad(0.95, [1.0, 0.0, 0.0, 0.5], false)); // hidden behind the opaque quad
    scene.add_mesh(quad(0.6, [0.0, 1.0, 0.0, 0.5], false));
    scene.add_mesh(quad(0.3, [0.0, 0.0, 1.0, 0.5], false));
    let mut r = renderer(4, 4);
    let a = r.render(&scene, &identity(), "abuffer", &[], [0.0; 3]).unwrap();
    let u = r.render(&scene, &identity(), "unsorted", &[], [0.0; 3]).unwrap();
    let want = reference(&scene, &identity(), 4, 4, [0.0; 3]).unwrap();
    assert_eq!(a.stats.max_depth_complexity, 2);
    for i in 0..a.image.len() {
        assert!((a.image[i] as f64 - want.image[i]).abs() < 1e-6, "abuffer {i}: {} vs {}", a.image[i], want.image[i]);
        assert!((u.image[i] as f64 - want.image[i]).abs() < 1e-6, "unsorted {i}: {} vs {}", u.image[i], want.image[i]);
    }
}

#[test]
fn frames_look_pipelines_up_and_never_build_them_twice() {
    // Every method once, then every method again on another renderer of the same device: the
    // second round finds each pipeline in the device's cache.
    let mut scene = Scene::new();
    scene.add_mesh(quad(0.3, [1.0, 0.0, 0.0, 0.5], false));
    scene.add_mesh(quad(0.6, [0.0, 0.0, 1.0, 0.5], false));
    // A device of its own: other tests' frames build pipelines in the shared device's cache.
    let ctx = std::sync::Arc::new(oit_core::GpuContext::new(None).expect("a GPU adapter (lavapipe in CI)"));
    let names: Vec<&str> = oit_core::methods().iter().filter(|m| ctx.features.contains(m.features)).map(|m| m.name).collect();
    let mut first = Renderer::new(ctx.clone(), 8, 8).unwrap();
    for name in &names {
        first.render(&scene, &identity(), name, &[], [1.0; 3]).unwrap();
    }
    let built = ctx.cache.pipelines();
    let mut second = Renderer::new(ctx.clone(), 6, 4).unwrap();
    for name in &names {
        second.render(&scene, &identity(), name, &[], [1.0; 3]).unwrap();
    }
    assert_eq!(ctx.cache.pipelines(), built, "a frame built a pipeline that an earlier frame had built");
}

/// Overlapping triangles at many depths, some behind an opaque quad: the census counts the
/// same fragments by blending into its count target as by atomics, and the method that plans
/// from it (abuffer) renders the same image either way.
#[test]
fn census_by_blending_counts_what_atomics_count() {
    let mut scene = Scene::new();
    scene.add_mesh(quad(0.55, [0.2, 0.2, 0.2, 1.0], true));
    for i in 0..24u32 {
        let (x, y, z) = ((i % 5) as f32 * 0.3 - 0.6, (i % 7) as f32 * 0.2 - 0.6, 0.05 + 0.037 * i as f32);
        let p = vec![[x - 0.7, y - 0.5, z], [x + 0.6, y - 0.4, z + 0.01], [x, y + 0.8, z - 0.01]];
        scene.add_mesh(Mesh::new(p, vec![[0, 1, 2]], vec![[0.9, 0.4, 0.1, 0.3]], false).unwrap());
    }
    let mut r = renderer(40, 30);
    r.set_census(true);
    let blended = r.render(&scene, &identity(), "unsorted", &[], [1.0; 3]).unwrap();
    r.set_atomic_census(true);
    let atomic = r.render(&scene, &identity(), "unsorted", &[], [1.0; 3]).unwrap();
    assert!(blended.stats.census && atomic.stats.census);
    assert!(blended.stats.fragments > 0 && blended.stats.max_depth_complexity > 3);
    assert_eq!(blended.depth_complexity, atomic.depth_complexity);
    assert_eq!(blended.stats.fragments, atomic.stats.fragments);
    let exact_atomic = r.render(&scene, &identity(), "abuffer", &[], [1.0; 3]).unwrap();
    r.set_atomic_census(false);
    let exact_blended = r.render(&scene, &identity(), "abuffer", &[], [1.0; 3]).unwrap();
    assert_eq!(exact_atomic.image, exact_blended.image);
    assert_eq!(exact_atomic.depth_complexity, blended.depth_complexity);
}

/// A device like `shared_context`'s without 64-bit atomics: hybrid's tail words and adaptive's
/// nodes are then pairs of 32-bit atomics (shaders/common/tail_words.wgsl, shaders/adaptive.wgsl).
fn context_without_int64() -> std::sync::Arc<oit_core::GpuContext> {
    let full = shared_context(None).expect("a GPU adapter (lavapipe in CI)");
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY),
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
    let adapter = adapters.into_iter().find(|a| a.get_info().name == full.info.name).expect("the shared context's adapter");
    let int64 = wgpu::Features::SHADER_INT64 | wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX | wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS;
    let features = full.features - int64;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("oit without int64"),
        required_features: features,
        required_limits: adapter.limits(),
        ..Default::default()
    }))
    .expect("a device");
    std::sync::Arc::new(oit_core::GpuContext::from_device(device, queue, adapter.get_info()))
}

#[test]
fn words_are_the_same_in_64_bit_atomics_and_32_bit_pairs() {
    let full = shared_context(None).expect("a GPU adapter (lavapipe in CI)");
    if !full.features.contains(wgpu::Features::SHADER_INT64_ATOMIC_ALL_OPS) {
        eprintln!("skipped: the adapter has no 64-bit atomic adds, so there is nothing to compare the pairs with");
        return;
    }
    // 40 layers of varied colors and alphas: with k = 4 most go to the tail, and their green
    // sums carry between the packed words many times.
    let mut scene = Scene::new();
    for i in 0..40u32 {
        let f = i as f32;
        let rgba = [(f * 0.37).fract(), (f * 0.61 + 0.2).fract(), (f * 0.83 + 0.5).fract(), 0.05 + (f * 0.29).fract() * 0.9];
        scene.add_mesh(quad(0.1 + 0.02 * f, rgba, false));
    }
    let mut wide = Renderer::new(full, 8, 8).unwrap();
    let mut pairs = Renderer::new(context_without_int64(), 8, 8).unwrap();
    for (method, k) in [("hybrid", 4), ("hybrid", 1), ("ktab", 4)] {
        let params = [("k".to_string(), oit_core::ParamValue::Int(k))];
        let a = wide.render(&scene, &identity(), method, &params, [1.0; 3]).unwrap();
        let b = pairs.render(&scene, &identity(), method, &params, [1.0; 3]).unwrap();
        assert_eq!(a.stats.overflow_fragments, (40 - k as u64) * 64, "{method} k = {k}");
        assert_eq!(a.stats.overflow_fragments, b.stats.overflow_fragments, "{method} k = {k}");
        assert_eq!(a.image, b.image, "{method} k = {k}: the two tails differ");
        assert_eq!(a.error_bound, b.error_bound, "{method} k = {k}");
    }
    // adaptive's insert reads and writes a node as one 64-bit atomic or as two 32-bit ones.
    for nodes in [4, 8] {
        let params = [("nodes".to_string(), oit_core::ParamValue::Int(nodes))];
        let a = wide.render(&scene, &identity(), "adaptive", &params, [1.0; 3]).unwrap();
        let b = pairs.render(&scene, &identity(), "adaptive", &params, [1.0; 3]).unwrap();
        assert_eq!(a.stats.overflow_fragments, 0, "adaptive, {nodes} nodes: lock failures");
        assert_eq!(a.image, b.image, "adaptive, {nodes} nodes: the two node forms differ");
    }
}

/// The executor reads what a tile leaves (its pixels, its error bound, its pass times and the
/// method's counters) after one wait: hybrid, ktab and hybrid64, which once waited for their
/// counter, the pass times, the image and the bound apart, now wait once a frame; abuffer, which
/// counts its fragments in its capture once a frame has sized its pool, waits for that count
/// (it plans the resolve) and for the tile.
#[test]
fn a_frame_waits_for_the_gpu_once_where_its_method_allows() {
    let ctx = std::sync::Arc::new(oit_core::GpuContext::new(None).expect("a GPU adapter (lavapipe in CI)"));
    let mut scene = Scene::new();
    for (z, c) in [(0.7, [1.0, 0.0, 0.0, 0.5]), (0.2, [0.0, 1.0, 0.0, 0.25]), (0.5, [0.0, 0.0, 1.0, 0.8])] {
        scene.add_mesh(quad(z, c, false));
    }
    let mut r = Renderer::new(ctx.clone(), 8, 6).unwrap();
    let mut waits = |name: &str| {
        r.render(&scene, &identity(), name, &[], [1.0; 3]).unwrap(); // pipelines, pools
        let before = ctx.waits();
        r.render(&scene, &identity(), name, &[], [1.0; 3]).unwrap();
        ctx.waits() - before
    };
    for name in ["hybrid", "ktab", "hybrid64", "wboit", "bucket_peeling"] {
        if oit_core::method::lookup(name).is_ok_and(|m| ctx.features.contains(m.features)) {
            assert_eq!(waits(name), 1, "{name}");
        }
    }
    assert_eq!(waits("abuffer"), 2);
}
