//! The side panel: method and parameters (from `oit_core::methods()`, so a new method shows
//! up by itself), view and compare modes, background, meshes, and the frame's numbers. It
//! changes nothing itself: it returns the `Action`s the user asked for.

use eframe::egui::{self, RichText};
use oit_core::{Frame, MethodInfo, ParamInfo, ParamKind, ParamValue};

use crate::heatmap::ErrorMap;
use crate::state::{Action, Compare, MeshControl, Settings, ViewMode, EXACT};

/// What the side panel shows.
pub struct PanelData<'a> {
    pub title: &'a str,
    /// The adapter's name, when there is a device.
    pub adapter: Option<&'a str>,
    pub settings: &'a Settings,
    pub meshes: &'a [MeshControl],
    /// The scene's own lights (0: the headlight).
    pub lights: usize,
    pub camera_at_home: bool,
    pub status: &'a str,
    pub frame: Option<&'a Frame>,
    pub triangles: usize,
    pub error: Option<&'a ErrorMap>,
}

/// Draws the panel and returns what the user asked for. The widgets edit a copy of the
/// settings, so that widgets further down show a change in the frame it was made.
pub fn side_panel(ui: &mut egui::Ui, p: &PanelData<'_>) -> Vec<Action> {
    let mut s = p.settings.clone();
    let mut out = Vec::new();
    ui.heading(p.title);
    if let Some(name) = p.adapter {
        ui.label(RichText::new(name).small().weak());
    }
    ui.separator();
    method_section(ui, &mut s, &mut out);
    ui.separator();
    view_section(ui, &mut s, p, &mut out);
    ui.separator();
    stats_section(ui, &s, p);
    ui.separator();
    lighting_section(ui, &mut s, p.lights, &mut out);
    ui.separator();
    meshes_section(ui, &mut s, p.meshes, &mut out);
    out
}

/// Shading on or off, the scene's lights or the headlight, a grey ambient term (docs/shading.md).
fn lighting_section(ui: &mut egui::Ui, s: &mut Settings, lights: usize, out: &mut Vec<Action>) {
    if ui.checkbox(&mut s.lit, "lit (off: vertex colors only)").changed() {
        out.push(Action::SetLit(s.lit));
    }
    if lights > 0 {
        let text = format!("headlight instead of the scene's {lights} light{}", if lights == 1 { "" } else { "s" });
        if ui.checkbox(&mut s.headlight, text).changed() {
            out.push(Action::SetHeadlight(s.headlight));
        }
    }
    let mut grey = s.ambient.iter().sum::<f32>() / 3.0;
    if ui.add(egui::Slider::new(&mut grey, 0.0..=1.0).text("ambient")).changed() {
        out.push(Action::SetAmbient(grey));
    }
}

fn method_section(ui: &mut egui::Ui, s: &mut Settings, out: &mut Vec<Action>) {
    let mut changed = false;
    egui::ComboBox::from_label("method").selected_text(s.method.clone()).show_ui(ui, |ui| {
        for m in oit_core::methods() {
            let text = if m.exact { format!("{} (exact)", m.name) } else { m.name.to_string() };
            changed |= ui.selectable_value(&mut s.method, m.name.to_string(), text).on_hover_text(m.summary).changed();
        }
    });
    if changed {
        out.push(Action::SetMethod(s.method.clone()));
    }
    let Some(info) = oit_core::methods().iter().find(|m| m.name == s.method) else { return };
    ui.label(RichText::new(info.summary).small());
    for p in info.params {
        let mut value = s.method_params(info.name).into_iter().find(|(k, _)| k == p.name).map(|(_, v)| v);
        let Some(v) = value.as_mut() else { continue };
        if param_widget(ui, info, p, v) {
            s.set_param(p.name, v.clone());
            out.push(Action::SetParam(p.name.to_string(), v.clone()));
        }
    }
}

/// A slider for small integer and float ranges, a number field for wide ones (seeds, "0 =
/// all layers"), a list for choices. Returns whether the value changed.
fn param_widget(ui: &mut egui::Ui, method: &MethodInfo, p: &ParamInfo, v: &mut ParamValue) -> bool {
    let changed = match (p.kind, v) {
        (ParamKind::Int { min, max, step, .. }, ParamValue::Int(x)) if max - min <= 4096 => {
            let slider = egui::Slider::new(x, min..=max).text(p.name).logarithmic(max >= 64 && min >= 0);
            ui.add(slider.step_by(step as f64)).changed()
        }
        (ParamKind::Int { min, max, .. }, ParamValue::Int(x)) => {
            ui.horizontal(|ui| {
                let r = ui.add(egui::DragValue::new(x).range(min..=max));
                let label = ui.label(p.name);
                r.labelled_by(label.id).changed()
            })
            .inner
        }
        (ParamKind::Float { min, max, .. }, ParamValue::Float(x)) => ui.add(egui::Slider::new(x, min..=max).text(p.name)).changed(),
        (ParamKind::Choice { choices, .. }, ParamValue::Str(x)) => {
            let mut changed = false;
            egui::ComboBox::from_label(p.name).selected_text(x.clone()).show_ui(ui, |ui| {
                for c in choices {
                    changed |= ui.selectable_value(x, c.to_string(), *c).changed();
                }
            });
            changed
        }
        (_, v) => {
            ui.label(format!("{}.{} = {v:?}", method.name, p.name));
            false
        }
    };
    if !p.doc.is_empty() {
        ui.label(RichText::new(p.doc).small().weak());
    }
    changed
}

fn view_section(ui: &mut egui::Ui, s: &mut Settings, p: &PanelData<'_>, out: &mut Vec<Action>) {
    let old = s.clone();
    ui.horizontal(|ui| {
        ui.label("show");
        ui.selectable_value(&mut s.view, ViewMode::Image, "image");
        ui.selectable_value(&mut s.view, ViewMode::Complexity, "depth complexity");
        ui.selectable_value(&mut s.view, ViewMode::Error, "error");
    });
    ui.horizontal(|ui| {
        ui.label(format!("compare with {EXACT}"));
        ui.selectable_value(&mut s.compare, Compare::Off, "off");
        ui.selectable_value(&mut s.compare, Compare::Split, "split");
        ui.selectable_value(&mut s.compare, Compare::Toggle, "toggle");
    });
    match s.compare {
        Compare::Split => {
            ui.add(egui::Slider::new(&mut s.split, 0.0..=1.0).text("split"));
        }
        Compare::Toggle => {
            ui.checkbox(&mut s.show_exact, "show the exact frame (Space)");
        }
        Compare::Off => {}
    }
    if s.view == ViewMode::Error {
        ui.add(egui::Slider::new(&mut s.error_scale, 0.001..=1.0).logarithmic(true).text("error scale"));
    }
    ui.horizontal(|ui| {
        ui.color_edit_button_rgb(&mut s.background);
        ui.label("background");
    });
    ui.horizontal(|ui| {
        egui::ComboBox::from_label("samples a pixel").selected_text(s.antialias.to_string()).show_ui(ui, |ui| {
            for n in oit_core::antialias::SAMPLE_COUNTS {
                ui.selectable_value(&mut s.antialias, n, n.to_string());
            }
        });
    })
    .response
    .on_hover_text("antialiasing: one frame per sample position, averaged");
    let coverage_ok = oit_core::coverage_methods().contains(&s.method.as_str()) && s.antialias == oit_core::COVERAGE_SAMPLES;
    s.coverage &= coverage_ok;
    ui.add_enabled(coverage_ok, egui::Checkbox::new(&mut s.coverage, "coverage masks"))
        .on_hover_text("abuffer at 4 samples: one multisampled capture, a sample mask per fragment")
        .on_disabled_hover_text("abuffer at 4 samples only");
    ui.add(egui::Slider::new(&mut s.render_scale, 0.25..=1.0).text("render scale"))
        .on_hover_text("render at a fraction of the view's pixels: faster on software adapters");
    ui.horizontal(|ui| {
        if ui.add_enabled(!p.camera_at_home, egui::Button::new("reset view")).on_hover_text("R, or double-click the view").clicked() {
            out.push(Action::ResetView);
        }
        if ui.button("screenshot").on_hover_text("saves the window as oit-viewer-<time>.png here").clicked() {
            out.push(Action::Screenshot);
        }
    });
    if !p.status.is_empty() {
        ui.label(RichText::new(p.status).small());
    }
    changes(&old, s, out);
}

/// The actions that take the view section's settings from `old` to `new`.
fn changes(old: &Settings, new: &Settings, out: &mut Vec<Action>) {
    let mut push = |differ: bool, action: Action| {
        if differ {
            out.push(action);
        }
    };
    push(old.view != new.view, Action::SetView(new.view));
    push(old.compare != new.compare, Action::SetCompare(new.compare));
    push(old.split != new.split, Action::SetSplit(new.split));
    push(old.show_exact != new.show_exact, Action::SetShowExact(new.show_exact));
    push(old.error_scale != new.error_scale, Action::SetErrorScale(new.error_scale));
    push(old.background != new.background, Action::SetBackground(new.background));
    push(old.antialias != new.antialias, Action::SetAntialias(new.antialias));
    push(old.coverage != new.coverage, Action::SetCoverage(new.coverage));
    push(old.render_scale != new.render_scale, Action::SetRenderScale(new.render_scale));
}

fn mib(bytes: u64) -> String {
    format!("{:.2} MiB", bytes as f64 / (1u64 << 20) as f64)
}

fn stats_section(ui: &mut egui::Ui, s: &Settings, p: &PanelData<'_>) {
    let Some(f) = p.frame else {
        ui.label("no frame yet");
        return;
    };
    let st = &f.stats;
    egui::Grid::new("stats").num_columns(2).striped(true).show(ui, |ui| {
        let mut row = |k: &str, v: String| {
            ui.label(k);
            ui.label(v);
            ui.end_row();
        };
        row("frame", format!("{} x {}, {} triangles", f.width, f.height, p.triangles));
        row("GPU time", st.gpu_time_ms.map_or("n/a (no timestamp queries)".into(), |t| format!("{t:.2} ms")));
        row("wall time", format!("{:.1} ms", st.wall_time_ms));
        row("fragments", st.fragments.to_string());
        row("max depth complexity", st.max_depth_complexity.to_string());
        row("memory (method)", mib(st.memory_bytes));
        row("memory (targets, scene)", format!("{}, {}", mib(st.target_bytes), mib(st.scene_bytes)));
        row("overflow fragments", st.overflow_fragments.to_string());
        for (k, v) in &st.extra {
            row(k, format!("{v}"));
        }
        if let Some(e) = p.error.filter(|_| s.needs_exact()) {
            row("mean error", format!("{:.5}", e.mean));
            row("max error", format!("{:.5}", e.max));
        }
    });
    if !st.pass_times_ms.is_empty() {
        egui::CollapsingHeader::new("pass times").show(ui, |ui| {
            for (name, t) in &st.pass_times_ms {
                ui.label(format!("{name}: {t:.3} ms"));
            }
        });
    }
}

fn meshes_section(ui: &mut egui::Ui, s: &mut Settings, meshes: &[MeshControl], out: &mut Vec<Action>) {
    if meshes.iter().any(|m| m.original.opaque) && ui.checkbox(&mut s.show_opaque, "show opaque geometry").changed() {
        out.push(Action::SetShowOpaque(s.show_opaque));
    }
    egui::CollapsingHeader::new(format!("meshes ({})", meshes.len())).default_open(meshes.len() <= 8).show(ui, |ui| {
        for (i, m) in meshes.iter().enumerate() {
            ui.push_id(i, |ui| {
                let label = if m.original.opaque { format!("{} (opaque)", m.name) } else { m.name.clone() };
                let mut visible = m.visible;
                if ui.checkbox(&mut visible, label).changed() {
                    out.push(Action::SetMeshVisible(i, visible));
                }
                if !m.original.opaque {
                    let text = if m.uniform_alpha { "alpha" } else { "alpha ×" };
                    let mut alpha = m.alpha;
                    if ui.add(egui::Slider::new(&mut alpha, 0.0..=1.0).text(text)).changed() {
                        out.push(Action::SetMeshAlpha(i, alpha));
                    }
                }
            });
        }
    });
}
