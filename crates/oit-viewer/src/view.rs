//! The central view: mouse and keyboard camera controls, rendering at the view's pixel size,
//! the picture, its colormap legend, and messages.

use eframe::egui::{self, Align2, Color32, FontId, Key, PointerButton, Pos2, Rect, Sense, Stroke, StrokeKind, Vec2};

use crate::app::{Compare, ViewMode, ViewerApp};
use crate::heatmap::colormap;

/// Frame size in pixels for a view of `rect` points.
pub fn render_size(rect: Rect, pixels_per_point: f32, scale: f32, max: u32) -> [u32; 2] {
    let px = rect.size() * pixels_per_point * scale;
    [(px.x.floor() as u32).clamp(1, max), (px.y.floor() as u32).clamp(1, max)]
}

pub fn central(ui: &mut egui::Ui, app: &mut ViewerApp) {
    let rect = ui.available_rect_before_wrap();
    let response = ui.allocate_rect(rect, Sense::click_and_drag());
    camera_input(ui, app, &response);
    let ppp = ui.ctx().pixels_per_point();
    // Whole pixels, starting on a pixel: at scale 1 the picture maps 1:1 onto the screen.
    let origin = (rect.min.to_vec2() * ppp).ceil() / ppp;
    let inner = Rect::from_min_max(origin.to_pos2(), rect.max);
    let max = app.gpu.as_ref().map_or(8192, |g| g.limits.max_texture_dimension_2d);
    let size = render_size(inner, ppp, app.settings.render_scale, max);
    if inner.width() >= 1.0 && inner.height() >= 1.0 && app.update_frames(size) {
        ui.ctx().request_repaint(); // the side panel shows the new stats next frame
    }
    let painter = ui.painter_at(rect);
    let shown = Vec2::new(size[0] as f32, size[1] as f32) / (ppp * app.settings.render_scale);
    let image_rect = Rect::from_min_size(inner.min, shown);
    app.view_rect = image_rect;
    if let Some(tex) = app.texture(ui.ctx()) {
        let uv = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
        painter.image(tex.id(), image_rect, uv, Color32::WHITE);
    }
    overlay(&painter, image_rect, app);
}

fn camera_input(ui: &egui::Ui, app: &mut ViewerApp, response: &egui::Response) {
    let delta = response.drag_delta();
    let shift = ui.input(|i| i.modifiers.shift);
    if delta != Vec2::ZERO {
        let (dx, dy) = (delta.x as f64, delta.y as f64);
        if response.dragged_by(PointerButton::Primary) && !shift {
            app.camera.moved().rotate(dx, dy);
        } else if response.dragged() {
            app.camera.moved().pan(dx, dy, response.rect.height() as f64);
        }
    }
    if response.hovered() {
        let (scroll, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        if scroll != 0.0 {
            app.camera.moved().zoom(scroll as f64);
        }
        if pinch != 1.0 {
            app.camera.moved().zoom((pinch as f64).ln() / 0.002);
        }
    }
    if response.double_clicked() {
        app.camera.reset();
    }
}

/// R resets the view, Space flips between the method and the exact frame (toggle mode),
/// Tab hides the side panel.
pub fn shortcuts(ctx: &egui::Context, app: &mut ViewerApp) {
    ctx.input_mut(|i| {
        if i.consume_key(egui::Modifiers::NONE, Key::R) {
            app.camera.reset();
        }
        if i.consume_key(egui::Modifiers::NONE, Key::Space) && app.settings.compare == Compare::Toggle {
            app.settings.show_exact = !app.settings.show_exact;
        }
        if i.consume_key(egui::Modifiers::NONE, Key::Tab) {
            app.show_panel = !app.show_panel;
        }
    });
}

/// Labels over the picture: what each part shows, the colormap legend, errors.
fn overlay(painter: &egui::Painter, rect: Rect, app: &ViewerApp) {
    let s = &app.settings;
    let font = FontId::proportional(13.0);
    let label = |pos: Pos2, anchor: Align2, text: &str| {
        let galley = painter.layout_no_wrap(text.to_string(), font.clone(), Color32::WHITE);
        let r = anchor.anchor_size(pos, galley.size()).expand(3.0);
        painter.rect_filled(r, 3.0, Color32::from_black_alpha(150));
        painter.galley(r.min + Vec2::splat(3.0), galley, Color32::WHITE);
    };
    let exact_available = app.exact_frame().is_some();
    match (s.view, s.compare) {
        (ViewMode::Error, _) => label(rect.left_top() + Vec2::splat(8.0), Align2::LEFT_TOP, &format!("|{} − abuffer|", s.method)),
        (_, Compare::Split) if exact_available => {
            label(rect.left_top() + Vec2::splat(8.0), Align2::LEFT_TOP, &s.method);
            let x = rect.left() + rect.width() * s.split.clamp(0.0, 1.0);
            label(Pos2::new(x + 8.0, rect.top() + 8.0), Align2::LEFT_TOP, "abuffer (exact)");
        }
        (_, Compare::Toggle) => {
            let which = if s.show_exact { "abuffer (exact)" } else { s.method.as_str() };
            label(rect.left_top() + Vec2::splat(8.0), Align2::LEFT_TOP, &format!("{which} — Space toggles"));
        }
        _ => {}
    }
    let legend = match (s.view, app.frame.as_ref()) {
        (ViewMode::Complexity, Some(f)) => {
            Some(("fragments / pixel".to_string(), "0".to_string(), f.stats.max_depth_complexity.to_string()))
        }
        (ViewMode::Error, Some(_)) => Some(("max |Δ| of linear RGB".to_string(), "0".to_string(), format!("≥ {}", s.error_scale))),
        _ => None,
    };
    if let Some((title, lo, hi)) = legend {
        let bar = Rect::from_min_size(rect.left_bottom() + Vec2::new(12.0, -30.0), Vec2::new(160.0, 10.0));
        let steps = 32;
        for k in 0..steps {
            let x0 = bar.left() + bar.width() * k as f32 / steps as f32;
            let r = Rect::from_min_max(Pos2::new(x0, bar.top()), Pos2::new(x0 + bar.width() / steps as f32 + 0.5, bar.bottom()));
            painter.rect_filled(r, 0.0, colormap(k as f32 / (steps - 1) as f32));
        }
        painter.rect_stroke(bar, 0.0, Stroke::new(1.0, Color32::WHITE), StrokeKind::Outside);
        label(bar.left_top() - Vec2::new(0.0, 4.0), Align2::LEFT_BOTTOM, &title);
        label(bar.left_bottom() + Vec2::new(0.0, 4.0), Align2::LEFT_TOP, &lo);
        label(bar.right_bottom() + Vec2::new(0.0, 4.0), Align2::RIGHT_TOP, &hi);
    }
    if let Some(e) = &app.render_error {
        let galley = painter.layout(e.clone(), FontId::proportional(14.0), Color32::WHITE, (rect.width() - 40.0).max(100.0));
        let r = Align2::CENTER_CENTER.anchor_size(rect.center(), galley.size()).expand(8.0);
        painter.rect_filled(r, 4.0, Color32::from_rgb(140, 30, 30));
        painter.galley(r.min + Vec2::splat(8.0), galley, Color32::WHITE);
    }
}
