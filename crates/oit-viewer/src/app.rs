//! The application state and its frame loop: settings, meshes, camera, and when to render.
//! The engine renders only when something it depends on changed; the picture on screen is
//! recomposed (CPU) when only the way of showing it changed. The window around it is
//! window.rs; screenshots are screenshot.rs.

use std::sync::Arc;

use eframe::egui::{self, ColorImage, Rect, TextureHandle, TextureId, TextureOptions};
use oit_core::{Antialias, AntialiasMode, Camera, Frame, GpuContext, ParamValue, Renderer, Scene};

use crate::gpu;
use crate::heatmap::{self, ErrorMap};
use crate::native::Native;
use crate::orbit::ViewCamera;
use crate::scenefile::SceneData;
use crate::state::{Compare, MeshControl, Settings, ViewMode, EXACT};

pub use crate::screenshot::ScreenshotJob;

/// Everything one engine render depends on.
#[derive(Clone, Debug, PartialEq)]
struct RenderKey {
    method: String,
    params: Vec<(String, ParamValue)>,
    background: [f32; 3],
    antialias: u32,
    mode: AntialiasMode,
    size: [u32; 2],
    camera: [[f64; 4]; 4],
    scene: u64,
    /// Rendered straight into the texture egui paints (`native.rs`), not read back.
    direct: bool,
}

/// Everything the picture on screen depends on, beyond the frames.
#[derive(Clone, Debug, PartialEq)]
struct ShowKey {
    renders: u64,
    view: ViewMode,
    compare: Compare,
    show_exact: bool,
    split: f32,
    error_scale: f32,
}

pub struct ViewerApp {
    pub settings: Settings,
    pub meshes: Vec<MeshControl>,
    /// The scene file's lights (none: the headlight) and ambient term.
    pub lights: Vec<oit_core::Light>,
    pub ambient: [f32; 3],
    pub camera: ViewCamera,
    pub title: String,
    pub show_panel: bool,
    pub gpu: Result<Arc<GpuContext>, String>,
    renderer: Option<Renderer>,
    scene: Scene,
    /// Bumped whenever the meshes change; the scene is rebuilt from `meshes`.
    scene_rev: u64,
    built_rev: u64,
    pub frame: Option<Frame>,
    exact: Option<Frame>,
    key: Option<RenderKey>,
    exact_key: Option<RenderKey>,
    pub error: Option<ErrorMap>,
    /// `renders` when `error` was computed.
    error_at: Option<u64>,
    pub render_error: Option<String>,
    /// Engine renders so far (the method's and the exact one's).
    pub renders: u64,
    texture: Option<TextureHandle>,
    /// The texture on eframe's device the plain image view is rendered into (None: another
    /// integration, or the tests' app, which read every frame back).
    native: Option<Native>,
    shown: Option<ShowKey>,
    /// Where the picture was last painted, in points.
    pub view_rect: Rect,
    pub screenshot: Option<ScreenshotJob>,
    pub status: String,
}

impl ViewerApp {
    /// The app on eframe's device (`cc.wgpu_render_state`).
    pub fn new(cc: &eframe::CreationContext<'_>, data: SceneData, settings: Settings, title: String) -> Self {
        let mut app = Self::with_gpu(gpu::context(cc.wgpu_render_state.as_ref()), data, settings, title);
        app.native = cc.wgpu_render_state.clone().map(Native::new);
        app
    }

    /// The app on a given engine context (tests build it on their own egui-wgpu device).
    pub fn with_gpu(gpu: Result<Arc<GpuContext>, String>, data: SceneData, settings: Settings, title: String) -> Self {
        let camera = ViewCamera::new(data.camera.as_ref(), &data.meshes);
        let mut settings = settings;
        settings.ambient = data.ambient;
        let meshes = data.meshes.into_iter().map(|m| MeshControl::new(m.name, m.mesh, m.instances)).collect();
        Self {
            settings,
            meshes,
            lights: data.lights,
            ambient: data.ambient,
            camera,
            title,
            show_panel: true,
            gpu,
            renderer: None,
            scene: Scene::new(),
            scene_rev: 1,
            built_rev: 0,
            frame: None,
            exact: None,
            key: None,
            exact_key: None,
            error: None,
            error_at: None,
            render_error: None,
            renders: 0,
            texture: None,
            native: None,
            shown: None,
            view_rect: Rect::NOTHING,
            screenshot: None,
            status: String::new(),
        }
    }

    /// Call after changing `meshes` or `settings.show_opaque`.
    pub fn meshes_changed(&mut self) {
        self.scene_rev += 1;
    }

    pub fn triangle_count(&self) -> usize {
        self.scene.triangle_count()
    }

    /// The exact frame: the method's own when the method is the exact one.
    pub fn exact_frame(&self) -> Option<&Frame> {
        if self.settings.method == EXACT {
            self.frame.as_ref()
        } else {
            self.exact.as_ref()
        }
    }

    fn rebuild_scene(&mut self) {
        if self.built_rev == self.scene_rev {
            return;
        }
        let mut scene = Scene::new();
        for m in self.meshes.iter().filter(|m| m.visible && (self.settings.show_opaque || !m.original.opaque)) {
            let mut mesh = m.mesh();
            if !self.settings.lit {
                mesh.material = Default::default();
            }
            scene.add_placed(mesh, m.instances.clone());
        }
        if !self.settings.headlight {
            for l in &self.lights {
                scene.add_light(*l).expect("at most MAX_LIGHTS lights, as the scene file had");
            }
        }
        scene.set_ambient(self.settings.ambient).expect("a valid ambient term, as the scene file had");
        self.scene = scene;
        self.built_rev = self.scene_rev;
    }

    /// Renders what changed at `size` pixels; returns whether anything was rendered.
    pub fn update_frames(&mut self, size: [u32; 2]) -> bool {
        let gpu = match &self.gpu {
            Ok(g) => g.clone(),
            Err(e) => {
                self.render_error = Some(e.clone());
                return false;
            }
        };
        self.rebuild_scene();
        let rows = self.camera.rows(size[0] as f64 / size[1] as f64);
        let key = RenderKey {
            method: self.settings.method.clone(),
            params: self.settings.method_params(&self.settings.method),
            background: self.settings.background,
            antialias: self.settings.antialias,
            mode: if self.settings.coverage { AntialiasMode::Coverage } else { AntialiasMode::Frames },
            size,
            camera: rows,
            scene: self.scene_rev,
            direct: self.native.is_some()
                && self.settings.view == ViewMode::Image
                && !self.settings.needs_exact()
                && self.settings.antialias <= 1,
        };
        // The exact frame at the same samples, as sample frames (exact at every sample).
        let exact_key = RenderKey { method: EXACT.into(), params: vec![], mode: AntialiasMode::Frames, direct: false, ..key.clone() };
        let want_exact = self.settings.needs_exact() && self.settings.method != EXACT;
        let stale = self.key.as_ref() != Some(&key);
        let exact_stale = want_exact && self.exact_key.as_ref() != Some(&exact_key);
        if !stale && !exact_stale {
            self.refresh_error();
            return false;
        }
        if self.renderer.as_ref().map(|r| r.size()) != Some((size[0], size[1])) {
            self.renderer = None; // free the old targets first
            match Renderer::new(gpu, size[0], size[1]) {
                Ok(mut r) => {
                    // The panel shows fragments and depth complexity for every method.
                    r.set_census(true);
                    self.renderer = Some(r);
                }
                Err(e) => {
                    self.render_error = Some(e.to_string());
                    return false;
                }
            }
        }
        let renderer = self.renderer.as_mut().expect("created above");
        let camera = match Camera::from_rows(rows) {
            Ok(c) => c,
            Err(e) => {
                self.render_error = Some(e.to_string());
                return false;
            }
        };
        let (scene, native) = (&self.scene, &mut self.native);
        let mut run = |k: &RenderKey| match native.as_mut().filter(|_| k.direct) {
            Some(n) => n.render(renderer, scene, &camera, &k.method, &k.params, k.background),
            None => renderer.render_antialiased(
                scene,
                &camera,
                &k.method,
                &k.params,
                k.background,
                Antialias { samples: k.antialias, mode: k.mode },
            ),
        };
        if stale {
            self.key = Some(key.clone());
            self.renders += 1;
            match run(&key) {
                Ok(f) => {
                    self.frame = Some(f);
                    self.render_error = None;
                }
                Err(e) => {
                    self.frame = None;
                    self.render_error = Some(format!("{}: {e}", key.method));
                }
            }
        }
        if exact_stale {
            self.exact_key = Some(exact_key.clone());
            self.renders += 1;
            match run(&exact_key) {
                Ok(f) => self.exact = Some(f),
                Err(e) => {
                    self.exact = None;
                    self.render_error = Some(format!("{EXACT}: {e}"));
                }
            }
        }
        self.refresh_error();
        true
    }

    /// The error map of the current frames, computed once per pair (compare and error modes).
    fn refresh_error(&mut self) {
        if !self.settings.needs_exact() || self.error_at == Some(self.renders) {
            return;
        }
        self.error_at = Some(self.renders);
        self.error = match (self.frame.as_ref(), self.exact_frame()) {
            (Some(f), Some(x)) if f.image.len() == x.image.len() => Some(ErrorMap::new(&f.image, &x.image)),
            _ => None,
        };
    }

    /// The picture for the current frames and settings.
    fn compose(&self) -> Option<ColorImage> {
        let f = self.frame.as_ref()?;
        let s = &self.settings;
        let picture = |fr: &Frame| match s.view {
            ViewMode::Complexity => heatmap::complexity_image(fr.width, fr.height, &fr.depth_complexity, fr.stats.max_depth_complexity),
            _ => heatmap::color_image(fr.width, fr.height, &fr.image),
        };
        if s.view == ViewMode::Error {
            return self.error.as_ref().map(|e| e.image(f.width, f.height, s.error_scale));
        }
        let exact = self.exact_frame().filter(|x| x.image.len() == f.image.len());
        Some(match (s.compare, exact) {
            (Compare::Split, Some(x)) => heatmap::split(&picture(f), &picture(x), s.split),
            (Compare::Toggle, Some(x)) if s.show_exact => picture(x),
            _ => picture(f),
        })
    }

    /// The texture to paint: the one the frame was rendered into, or the picture uploaded when
    /// it changed.
    pub fn texture(&mut self, ctx: &egui::Context) -> Option<TextureId> {
        if self.key.as_ref().is_some_and(|k| k.direct) && self.frame.is_some() {
            return self.native.as_ref().and_then(Native::texture_id);
        }
        let s = &self.settings;
        let key = ShowKey {
            renders: self.renders,
            view: s.view,
            compare: s.compare,
            show_exact: s.show_exact,
            split: s.split,
            error_scale: s.error_scale,
        };
        if self.shown.as_ref() != Some(&key) || self.texture.is_none() {
            self.shown = Some(key);
            match self.compose() {
                Some(img) => match &mut self.texture {
                    Some(t) => t.set(img, TextureOptions::NEAREST),
                    None => self.texture = Some(ctx.load_texture("oit-frame", img, TextureOptions::NEAREST)),
                },
                None => self.texture = None,
            }
        }
        self.texture.as_ref().map(TextureHandle::id)
    }
}
