//! The viewer driven through its UI with egui_kittest, rendered by egui-wgpu and oit-core on
//! one device (lavapipe here). The snapshots in tests/snapshots are checked in; each test
//! also checks the app's numbers against the engine itself, not only against the pictures.
//! Update the pictures with `UPDATE_SNAPSHOTS=1 cargo test --release -p oit-viewer`.

mod common;

use eframe::egui::accesskit::Role;
use eframe::egui::Key;
use egui_kittest::kittest::Queryable;
use egui_kittest::{Harness, SnapshotOptions};
use oit_core::{Camera, Mesh, Renderer};
use oit_viewer::scenefile::{CameraSpec, NamedMesh, SceneData};
use oit_viewer::{Compare, Settings, ViewMode, ViewerApp};

const SIZE: [f32; 2] = [720.0, 440.0];

fn quad(z: f32, offset: f32, rgba: [f32; 4], opaque: bool) -> NamedMesh {
    let s = 0.6;
    let p = |x: f32, y: f32| [x + offset, y + offset * 0.5, z];
    let mesh = Mesh::new(vec![p(-s, -s), p(s, -s), p(s, s), p(-s, s)], vec![[0, 1, 2], [0, 2, 3]], vec![rgba], opaque).unwrap();
    NamedMesh::new(format!("quad z={z}"), mesh)
}

/// Three transparent quads submitted front to back (the worst order for blending) over an
/// opaque one, seen by a perspective camera.
fn scene() -> SceneData {
    SceneData {
        meshes: vec![
            quad(0.3, -0.35, [0.9, 0.2, 0.1, 0.6], false),
            quad(0.0, 0.0, [0.1, 0.8, 0.2, 0.5], false),
            quad(-0.3, 0.35, [0.1, 0.3, 0.9, 0.7], false),
            quad(-0.6, 0.6, [0.25, 0.25, 0.3, 1.0], true),
        ],
        camera: Some(CameraSpec::LookAt { eye: [0.4, 0.3, 3.0], target: [0.0; 3], up: [0.0, 1.0, 0.0], fov_y: 45.0, near: 1.0, far: 5.0 }),
        ..Default::default()
    }
}

/// The app on the test renderer's device, as eframe would run it.
fn harness(method: &str) -> Harness<'static, ViewerApp> {
    harness_of(method, scene())
}

fn harness_of(method: &str, scene: SceneData) -> Harness<'static, ViewerApp> {
    let renderer = common::WgpuRenderer::new();
    let app = ViewerApp::with_gpu(renderer.context(), scene, Settings::new(method), "test scene".into());
    let mut h = Harness::builder()
        .with_size(SIZE)
        .with_pixels_per_point(1.0)
        .renderer(renderer)
        .build_ui_state(|ui, app: &mut ViewerApp| app.show(ui), app);
    h.run();
    h
}

/// Text and widgets render the same on every lavapipe run; the tolerance is kittest's
/// default per-pixel threshold, with a few pixels spare for antialiased text edges. Times
/// ("... ms") change from run to run and are masked.
fn check(h: &mut Harness<'_, ViewerApp>, name: &str) {
    let timings: Vec<_> =
        h.query_all_by(|n| [n.label(), n.value()].into_iter().flatten().any(|l| l.ends_with(" ms"))).map(|n| n.rect()).collect();
    assert!(!timings.is_empty(), "the stats show times");
    // A fixed width: the text's own width changes with the number.
    timings.into_iter().for_each(|r| h.mask(eframe::egui::Rect::from_min_size(r.min, [120.0, r.height()].into())));
    h.snapshot_options(name, &SnapshotOptions::new().max_failed_pixels(16));
}

fn method_of(h: &Harness<'_, ViewerApp>) -> String {
    h.state().frame.as_ref().expect("a frame was rendered").stats.method.clone()
}

#[test]
fn switch_methods_and_move_a_slider() {
    let mut h = harness("hybrid");
    assert_eq!(method_of(&h), "hybrid");
    assert!(h.state().render_error.is_none(), "{:?}", h.state().render_error);

    h.get_by_label("method").click();
    h.run();
    h.get_by_label("abuffer (exact)").click();
    h.run();
    assert_eq!(h.state().settings.method, "abuffer");
    assert_eq!(method_of(&h), "abuffer");

    h.get_by_label("method").click();
    h.run();
    h.get_by_label("hybrid").click();
    h.run();
    assert_eq!(method_of(&h), "hybrid");
    let k = |h: &Harness<'_, ViewerApp>| h.state().frame.as_ref().unwrap().stats.params.int("k");
    assert_eq!(k(&h), 8);
    h.get_by_role_and_label(Role::Slider, "k").focus();
    h.run();
    h.key_press(Key::ArrowLeft);
    h.run();
    assert_eq!(k(&h), 7, "the slider moved and the frame was rendered again with it");
    check(&mut h, "hybrid_k7");
}

#[test]
fn compare_mode_split_and_error_heatmap() {
    let mut h = harness("unsorted");
    assert!(h.state().error.is_none());
    h.get_by_label("split").click();
    h.run();
    assert_eq!(h.state().settings.compare, Compare::Split);
    let e = h.state().error.clone().expect("compare mode measures the error");
    // Front-to-back submission makes over-blending visibly wrong where the quads overlap.
    assert!(e.max > 0.05 && e.mean > 0.0, "unsorted vs abuffer: mean {} max {}", e.mean, e.max);
    check(&mut h, "unsorted_split");

    h.get_by_label("error").click();
    h.run();
    assert_eq!(h.state().settings.view, ViewMode::Error);
    check(&mut h, "unsorted_error");

    h.get_by_label("method").click();
    h.run();
    h.get_by_label("abuffer (exact)").click();
    h.run();
    assert_eq!(h.state().error.as_ref().unwrap().max, 0.0, "the exact method against itself");
}

#[test]
fn depth_complexity_view_and_toggle() {
    let mut h = harness("wavg");
    h.get_by_label("depth complexity").click();
    h.run();
    let f = h.state().frame.as_ref().unwrap();
    assert_eq!(f.stats.max_depth_complexity, 3);
    h.get_by_label("toggle").click();
    h.run();
    h.key_press(Key::Space);
    h.run();
    assert!(h.state().settings.show_exact);
    check(&mut h, "complexity_toggle_exact");
}

#[test]
fn renders_only_when_something_changed() {
    let mut h = harness("wsum");
    let n = h.state().renders;
    h.run_steps(5);
    assert_eq!(h.state().renders, n, "idle frames do not render");
    h.state_mut().settings.background = [0.0, 0.0, 0.0];
    h.run();
    assert_eq!(h.state().renders, n + 1);
    // A mouse drag over the view orbits the camera, and the frame follows.
    let from = h.state().view_rect.center();
    let to = from + eframe::egui::vec2(60.0, 20.0);
    h.hover_at(from);
    h.drag_at(from);
    h.run();
    h.hover_at(to);
    h.run();
    h.drop_at(to);
    h.run();
    assert!(!h.state().camera.is_home(), "the drag moved the camera");
    assert!(h.state().renders > n + 1);
    h.key_press(Key::R); // reset view
    h.run();
    assert!(h.state().camera.is_home());
}

/// On eframe's device the viewer's frame is the engine's frame: the same scene, camera and
/// size rendered by a Renderer of its own (oit_core::shared_context) gives the same image.
#[test]
fn the_frame_is_the_engines_frame() {
    let h = harness("abuffer");
    let own = engines_frame(&h, scene());
    assert_eq!(own.stats.fragments, h.state().frame.as_ref().unwrap().stats.fragments);
}

/// `data` rendered by a Renderer of its own at the app's camera and frame size, checked equal
/// to the app's frame.
fn engines_frame(h: &Harness<'_, ViewerApp>, data: SceneData) -> oit_core::Frame {
    let app = h.state();
    let f = app.frame.as_ref().unwrap();
    let camera = Camera::from_rows(app.camera.rows(f.width as f64 / f.height as f64)).unwrap();
    let mut own_scene = oit_core::Scene::new();
    data.meshes.into_iter().for_each(|m| {
        own_scene.add_mesh(m.mesh);
    });
    let gpu = oit_core::shared_context(None).unwrap();
    let mut r = Renderer::new(gpu, f.width, f.height).unwrap();
    let own = r.render(&own_scene, &camera, "abuffer", &[], [1.0; 3]).unwrap();
    let diff = own.image.iter().zip(&f.image).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(diff < 1e-6, "max difference {diff}");
    own
}

/// The samples box and the coverage checkbox reach the engine: 4 samples with coverage masks
/// on abuffer, then coverage unchecks itself when the method cannot take it.
#[test]
fn antialiasing_from_the_panel() {
    let mut h = harness("abuffer");
    h.state_mut().settings.antialias = 4;
    h.run();
    assert_eq!(h.state().frame.as_ref().unwrap().stats.antialias_mode, oit_core::AntialiasMode::Frames);
    h.get_by_label("coverage masks").click();
    h.run();
    let stats = &h.state().frame.as_ref().unwrap().stats;
    assert_eq!((stats.antialias, stats.antialias_mode), (4, oit_core::AntialiasMode::Coverage));
    h.state_mut().settings.method = "hybrid".into();
    h.run();
    let stats = &h.state().frame.as_ref().unwrap().stats;
    assert_eq!((stats.method.as_str(), stats.antialias, stats.antialias_mode), ("hybrid", 4, oit_core::AntialiasMode::Frames));
    assert!(!h.state().settings.coverage);
}

/// Strands and particles (the GPU builds their triangles) show in the viewer as the engine
/// draws them, mixed with meshes.
#[test]
fn the_viewer_draws_strands_and_particles() {
    let strand = |x: f32| [[x, -0.6, 0.1], [x + 0.1, 0.0, 0.0], [x, 0.6, -0.1]];
    let points: Vec<[f32; 3]> = [-0.4f32, 0.0, 0.4].iter().flat_map(|&x| strand(x)).collect();
    let strands = Mesh::strands(points, vec![3; 3], vec![0.08], vec![[0.8, 0.5, 0.2, 0.6]], false)
        .and_then(|m| m.with_primitive_surface(oit_core::Shading::Hair, 0.3, 32.0, 1.0))
        .unwrap();
    let particles =
        Mesh::particles(vec![[0.3, 0.3, 0.2], [-0.3, -0.2, 0.3]], vec![0.2], vec![[0.2, 0.4, 0.9, 0.5]], false, oit_core::Falloff::Linear)
            .unwrap();
    let mut data = scene();
    data.meshes.truncate(1);
    data.meshes.push(NamedMesh::new("strands".into(), strands));
    data.meshes.push(NamedMesh::new("particles".into(), particles));
    let h = harness_of("abuffer", data.clone());
    let own = engines_frame(&h, data);
    assert!(own.stats.scene_bytes_by_primitive[1] > 0 && own.stats.scene_bytes_by_primitive[2] > 0);
    assert_eq!(h.state().triangle_count(), 2 + 2 * 6 + 2 * 2);
}
