//! One frame of the window: the side panel, the central view, the keyboard, and the actions
//! they ask for carried out on the app.

use eframe::egui::{self, Color32};

use crate::state::{Action, Compare};
use crate::{panels, view, ViewerApp};

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
