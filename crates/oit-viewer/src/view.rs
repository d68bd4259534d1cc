//! The central view: its layout at the view's pixel size, mouse and keyboard controls (as
//! `Action`s for the app), the picture, its colormap legend, and messages.

use eframe::egui::{self, Align2, Color32, FontId, Key, PointerButton, Pos2, Rect, Sense, Stroke, StrokeKind, Vec2};
use oit_core::Frame;

use crate::heatmap::colormap;
use crate::state::{Action, Compare, Settings, ViewMode};

/// Frame size in pixels for a view of `rect` points.
pub fn render_size(rect: Rect, pixels_per_point: f32, scale: f32, max: u32) -> [u32; 2] {
    let px = rect.size() * pixels_per_point * scale;
    [(px.x.floor() as u32).clamp(1, max), (px.y.floor() as u32).clamp(1, max)]
}

/// Where the picture goes this frame: the view, and the frame's size and place in it.
#[derive(Clone, Copy, Debug)]
pub struct Layout {
    /// The whole view, in points.
    pub rect: Rect,
    /// The view from its first whole pixel.
    pub inner: Rect,
    /// The frame to render, in pixels.
    pub size: [u32; 2],
    /// Where the frame is painted, in points.
    pub image: Rect,
}

impl Layout {
    /// Whether the view has room for a frame.
    pub fn has_area(&self) -> bool {
        self.inner.width() >= 1.0 && self.inner.height() >= 1.0
    }
}

/// Takes the rest of `ui` for the view; frames are rendered at `render_scale` of its pixels,
/// at most `max` a side.
pub fn layout(ui: &mut egui::Ui, render_scale: f32, max: u32) -> (egui::Response, Layout) {
    let rect = ui.available_rect_before_wrap();
    let response = ui.allocate_rect(rect, Sense::click_and_drag());
    let ppp = ui.ctx().pixels_per_point();
    // Whole pixels, starting on a pixel: at scale 1 the picture maps 1:1 onto the screen.
    let origin = (rect.min.to_vec2() * ppp).ceil() / ppp;
    let inner = Rect::from_min_max(origin.to_pos2(), rect.max);
    let size = render_size(inner, ppp, render_scale, max);
    let shown = Vec2::new(size[0] as f32, size[1] as f32) / (ppp * render_scale);
    (response, Layout { rect, inner, size, image: Rect::from_min_size(inner.min, shown) })
}

/// Paints the frame's `texture` and the labels over it.
pub fn paint(ui: &egui::Ui, layout: &Layout, texture: Option<egui::TextureId>, overlay: &Overlay<'_>) {
    let painter = ui.painter_at(layout.rect);
    if let Some(tex) = texture {
        let uv = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
        painter.image(tex, layout.image, uv, Color32::WHITE);
    }
    paint_overlay(&painter, layout.image, overlay);
}

/// Mouse over the view: drag orbits, shift-drag or another button pans, scroll and pinch
/// zoom, double-click resets.
pub fn camera_input(ui: &egui::Ui, response: &egui::Response) -> Vec<Action> {
    let mut out = Vec::new();
    let delta = response.drag_delta();
    let shift = ui.input(|i| i.modifiers.shift);
    if delta != Vec2::ZERO {
        let (dx, dy) = (delta.x as f64, delta.y as f64);
        if response.dragged_by(PointerButton::Primary) && !shift {
            out.push(Action::Orbit { dx, dy });
        } else if response.dragged() {
            out.push(Action::Pan { dx, dy, height: response.rect.height() as f64 });
        }
    }
    if response.hovered() {
        let (scroll, pinch) = ui.input(|i| (i.smooth_scroll_delta.y, i.zoom_delta()));
        if scroll != 0.0 {
            out.push(Action::Zoom(scroll as f64));
        }
        if pinch != 1.0 {
            out.push(Action::Zoom((pinch as f64).ln() / 0.002));
        }
    }
    if response.double_clicked() {
        out.push(Action::ResetView);
    }
    out
}

/// R resets the view, Space flips between the method and the exact frame (toggle mode),
/// Tab hides the side panel.
pub fn shortcuts(ctx: &egui::Context) -> Vec<Action> {
    let mut out = Vec::new();
    ctx.input_mut(|i| {
        if i.consume_key(egui::Modifiers::NONE, Key::R) {
            out.push(Action::ResetView);
        }
        if i.consume_key(egui::Modifiers::NONE, Key::Space) {
            out.push(Action::FlipExact);
        }
        if i.consume_key(egui::Modifiers::NONE, Key::Tab) {
            out.push(Action::TogglePanel);
        }
    });
    out
}

/// What the labels over the picture show.
pub struct Overlay<'a> {
    pub settings: &'a Settings,
    pub frame: Option<&'a Frame>,
    pub exact_available: bool,
    pub render_error: Option<&'a str>,
}

/// Labels over the picture: what each part shows, the colormap legend, errors.
fn paint_overlay(painter: &egui::Painter, rect: Rect, o: &Overlay<'_>) {
    let s = o.settings;
    let font = FontId::proportional(13.0);
    let label = |pos: Pos2, anchor: Align2, text: &str| {
        let galley = painter.layout_no_wrap(text.to_string(), font.clone(), Color32::WHITE);
        let r = anchor.anchor_size(pos, galley.size()).expand(3.0);
        painter.rect_filled(r, 3.0, Color32::from_black_alpha(150));
        painter.galley(r.min + Vec2::splat(3.0), galley, Color32::WHITE);
    };
    match (s.view, s.compare) {
        (ViewMode::Error, _) => label(rect.left_top() + Vec2::splat(8.0), Align2::LEFT_TOP, &format!("|{} − abuffer|", s.method)),
        (_, Compare::Split) if o.exact_available => {
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
    let legend = match (s.view, o.frame) {
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
    if let Some(e) = o.render_error {
        let galley = painter.layout(e.to_string(), FontId::proportional(14.0), Color32::WHITE, (rect.width() - 40.0).max(100.0));
        let r = Align2::CENTER_CENTER.anchor_size(rect.center(), galley.size()).expand(8.0);
        painter.rect_filled(r, 4.0, Color32::from_rgb(140, 30, 30));
        painter.galley(r.min + Vec2::splat(8.0), galley, Color32::WHITE);
    }
}
