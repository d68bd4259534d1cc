//! The application state and its frame loop: settings, meshes, camera, and when to render.
//! The engine renders only when something it depends on changed; the picture on screen is
//! recomposed (CPU) when only the way of showing it changed.

use std::path::PathBuf;
use std::sync::Arc;

use eframe::egui::{self, Color32, ColorImage, Rect, TextureHandle, TextureId, TextureOptions};
use oit_core::{AntialiasMode, Camera, Frame, GpuContext, ParamValue, Renderer, Scene};

use crate::heatmap::{self, ErrorMap};
use crate::native::Native;
use crate::orbit::ViewCamera;
use crate::scenefile::SceneData;
use crate::state::{Action, Compare, MeshControl, Settings, ViewMode, EXACT};
use crate::{gpu, panels, screenshot, view};

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

/// `--screenshot`: after `frames` frames, grab the window, save it, and maybe quit.
#[derive(Clone, Debug)]
pub struct ScreenshotJob {
    pub path: PathBuf,
    pub frames: u32,
    pub crop_view: bool,
    pub exit: bool,
    requested: bool,
}

impl ScreenshotJob {
    pub fn new(path: PathBuf, frames: u32, crop_view: bool, exit: bool) -> Self {
        Self { path, frames, crop_view, exit, requested: false }
    }
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
            None => renderer.render_antialiased(scene, &camera, &k.method, &k.params, k.background, k.antialias, k.mode),
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

    /// Saves the window picture of a finished screenshot request.
    fn take_screenshot(&mut self, ctx: &egui::Context) {
        let Some(job) = self.screenshot.as_mut() else { return };
        let events = ctx.input(|i| i.raw.events.clone());
        for e in events {
            let egui::Event::Screenshot { image, .. } = e else { continue };
            if let Some(err) = self.render_error.as_ref().filter(|_| job.exit) {
                // A picture of the error banner is no screenshot: fail as the command line does.
                eprintln!("oit-viewer: error: {err}");
                std::process::exit(1);
            }
            let ppp = ctx.pixels_per_point();
            let img = if job.crop_view { image.region(&self.view_rect, Some(ppp)) } else { (*image).clone() };
            let result = screenshot::write_png(&job.path, &img);
            let ok = result.is_ok();
            let job = self.screenshot.take().expect("checked above");
            match result {
                Ok(()) => {
                    self.status = format!("saved {}", job.path.display());
                    println!("oit-viewer: wrote {} ({} x {})", job.path.display(), img.width(), img.height());
                }
                Err(e) => {
                    self.status = format!("screenshot failed: {e}");
                    eprintln!("oit-viewer: {}", self.status);
                }
            }
            if job.exit {
                if !ok {
                    std::process::exit(1);
                }
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
            return;
        }
        if job.frames > 0 {
            job.frames -= 1;
        } else if !job.requested {
            job.requested = true;
            ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(Default::default()));
        }
        ctx.request_repaint();
    }

    /// A screenshot of the window into the working directory, named by the time.
    pub fn request_screenshot(&mut self) {
        let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
        self.screenshot = Some(ScreenshotJob::new(PathBuf::from(format!("oit-viewer-{secs}.png")), 0, false, false));
    }
}

impl ViewerApp {
    /// Carries out what the panel and the view asked for, in order.
    pub fn apply(&mut self, actions: impl IntoIterator<Item = Action>) {
        for action in actions {
            let s = &mut self.settings;
            match action {
                Action::SetMethod(m) => s.method = m,
                Action::SetParam(name, value) => s.set_param(&name, value),
                Action::SetView(v) => s.view = v,
                Action::SetCompare(c) => s.compare = c,
                Action::SetShowExact(b) => s.show_exact = b,
                Action::FlipExact => {
                    if s.compare == Compare::Toggle {
                        s.show_exact = !s.show_exact;
                    }
                }
                Action::SetSplit(x) => s.split = x,
                Action::SetErrorScale(x) => s.error_scale = x,
                Action::SetBackground(rgb) => s.background = rgb,
                Action::SetAntialias(n) => s.antialias = n,
                Action::SetCoverage(b) => s.coverage = b,
                Action::SetRenderScale(x) => s.render_scale = x,
                Action::SetShowOpaque(b) => {
                    s.show_opaque = b;
                    self.meshes_changed();
                }
                Action::SetLit(b) => {
                    s.lit = b;
                    self.meshes_changed();
                }
                Action::SetHeadlight(b) => {
                    s.headlight = b;
                    self.meshes_changed();
                }
                Action::SetAmbient(g) => {
                    s.ambient = [g.clamp(0.0, 1.0); 3];
                    self.meshes_changed();
                }
                Action::SetMeshVisible(i, b) => {
                    if let Some(m) = self.meshes.get_mut(i) {
                        m.visible = b;
                        self.meshes_changed();
                    }
                }
                Action::SetMeshAlpha(i, a) => {
                    if let Some(m) = self.meshes.get_mut(i) {
                        m.alpha = a;
                        self.meshes_changed();
                    }
                }
                Action::Orbit { dx, dy } => self.camera.moved().rotate(dx, dy),
                Action::Pan { dx, dy, height } => self.camera.moved().pan(dx, dy, height),
                Action::Zoom(amount) => self.camera.moved().zoom(amount),
                Action::ResetView => self.camera.reset(),
                Action::Screenshot => self.request_screenshot(),
                Action::TogglePanel => self.show_panel = !self.show_panel,
            }
        }
    }

    /// What the side panel shows.
    fn panel_data(&self) -> panels::PanelData<'_> {
        panels::PanelData {
            title: &self.title,
            adapter: self.gpu.as_ref().ok().map(|g| g.info.name.as_str()),
            settings: &self.settings,
            meshes: &self.meshes,
            lights: self.lights.len(),
            camera_at_home: self.camera.is_home(),
            status: &self.status,
            frame: self.frame.as_ref(),
            triangles: self.triangle_count(),
            error: self.error.as_ref(),
        }
    }

    /// The central view: camera input, rendering at the view's pixel size, the picture.
    fn central(&mut self, ui: &mut egui::Ui) {
        let max = self.gpu.as_ref().map_or(8192, |g| g.limits.max_texture_dimension_2d);
        let (response, layout) = view::layout(ui, self.settings.render_scale, max);
        let actions = view::camera_input(ui, &response);
        self.apply(actions);
        if layout.has_area() && self.update_frames(layout.size) {
            ui.ctx().request_repaint(); // the side panel shows the new stats next frame
        }
        self.view_rect = layout.image;
        let texture = self.texture(ui.ctx());
        let overlay = view::Overlay {
            settings: &self.settings,
            frame: self.frame.as_ref(),
            exact_available: self.exact_frame().is_some(),
            render_error: self.render_error.as_deref(),
        };
        view::paint(ui, &layout, texture, &overlay);
    }

    /// One frame of the whole window.
    pub fn show(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        self.take_screenshot(&ctx);
        if self.show_panel {
            egui::Panel::left("settings").default_size(290.0).resizable(true).show(ui, |ui| {
                let actions = egui::ScrollArea::vertical().show(ui, |ui| panels::side_panel(ui, &self.panel_data())).inner;
                self.apply(actions);
            });
        }
        egui::CentralPanel::no_frame().show(ui, |ui| self.central(ui));
        if !ctx.egui_wants_keyboard_input() {
            self.apply(view::shortcuts(&ctx));
        }
    }
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.show(ui);
    }

    fn clear_color(&self, _visuals: &egui::Visuals) -> [f32; 4] {
        let c = Color32::from_gray(40);
        egui::Rgba::from(c).to_array()
    }
}
