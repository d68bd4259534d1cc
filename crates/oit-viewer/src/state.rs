//! Plain data under the whole viewer: what the user chose (`Settings`), the meshes as loaded
//! (`MeshControl`), and what the panel and the view ask for (`Action`), which `ViewerApp`
//! applies. The panel and the view read these and never reach the app itself.

use std::collections::BTreeMap;

use oit_core::{Mesh, ParamValue};

/// The method compare mode and the error view measure against.
pub const EXACT: &str = "abuffer";

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewMode {
    Image,
    Complexity,
    Error,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    Off,
    Split,
    Toggle,
}

/// What the user chose: plain data that the panel shows and asks to change with `Action`s.
#[derive(Clone, Debug)]
pub struct Settings {
    pub method: String,
    /// Every method's parameters, defaults filled in, kept when switching methods.
    pub params: BTreeMap<String, Vec<(String, ParamValue)>>,
    /// Linear RGB.
    pub background: [f32; 3],
    pub show_opaque: bool,
    pub view: ViewMode,
    pub compare: Compare,
    /// Toggle mode: showing the exact frame.
    pub show_exact: bool,
    /// Split mode: where the exact half starts, as a fraction of the width.
    pub split: f32,
    /// Error at the top of the heatmap's colormap.
    pub error_scale: f32,
    /// Render at this fraction of the view's pixels (software adapters are slow).
    pub render_scale: f32,
    /// Samples a pixel (oit_core::antialias::SAMPLE_COUNTS).
    pub antialias: u32,
    /// Coverage masks instead of sample frames (abuffer at 4 samples).
    pub coverage: bool,
    /// Shading (docs/shading.md): off draws every mesh unlit (its vertex colors); `headlight`
    /// replaces the scene's lights with the one along the view; the ambient term, linear RGB.
    pub lit: bool,
    pub headlight: bool,
    pub ambient: [f32; 3],
}

impl Settings {
    pub fn new(method: &str) -> Self {
        let params = oit_core::methods()
            .iter()
            .map(|m| {
                let p = m.resolve_params(&[]).expect("defaults are valid");
                (m.name.to_string(), p.0.into_iter().map(|(k, v)| (k.to_string(), v)).collect())
            })
            .collect();
        Self {
            method: method.to_string(),
            params,
            background: [1.0; 3],
            show_opaque: true,
            view: ViewMode::Image,
            compare: Compare::Off,
            show_exact: false,
            split: 0.5,
            error_scale: 0.1,
            render_scale: 1.0,
            antialias: 1,
            coverage: false,
            lit: true,
            headlight: false,
            ambient: [0.0; 3],
        }
    }

    pub fn method_params(&self, method: &str) -> Vec<(String, ParamValue)> {
        self.params.get(method).cloned().unwrap_or_default()
    }

    /// Sets one parameter of the current method.
    pub fn set_param(&mut self, name: &str, value: ParamValue) {
        let list = self.params.entry(self.method.clone()).or_default();
        match list.iter_mut().find(|(k, _)| k == name) {
            Some(slot) => slot.1 = value,
            None => list.push((name.to_string(), value)),
        }
    }

    pub fn needs_exact(&self) -> bool {
        self.compare != Compare::Off || self.view == ViewMode::Error
    }
}

/// One mesh as loaded, and what the user does to it.
#[derive(Clone, Debug)]
pub struct MeshControl {
    pub name: String,
    pub original: Mesh,
    /// Where the file draws it (one identity instance unless a glTF mesh is shared by nodes).
    pub instances: Vec<oit_core::Instance>,
    pub visible: bool,
    /// The mesh's alpha when all its vertices share one, else a factor on its alphas.
    pub alpha: f32,
    pub uniform_alpha: bool,
}

impl MeshControl {
    pub fn new(name: String, mesh: Mesh, instances: Vec<oit_core::Instance>) -> Self {
        let first = mesh.colors.first().map_or(1.0, |c| c[3]);
        let uniform_alpha = mesh.colors.iter().all(|c| c[3] == first);
        let alpha = if uniform_alpha { first } else { 1.0 };
        Self { name, original: mesh, instances, visible: true, alpha, uniform_alpha }
    }

    /// The mesh with the user's alpha applied.
    pub fn mesh(&self) -> Mesh {
        let mut m = self.original.clone();
        if !m.opaque {
            let (a, uniform) = (self.alpha, self.uniform_alpha);
            m.colors.iter_mut().for_each(|c| c[3] = if uniform { a } else { (c[3] * a).clamp(0.0, 1.0) });
        }
        m
    }
}

/// What the side panel and the view ask for, in the order they were asked; `ViewerApp::apply`
/// carries them out.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    SetMethod(String),
    /// A parameter of the current method.
    SetParam(String, ParamValue),
    SetView(ViewMode),
    SetCompare(Compare),
    SetShowExact(bool),
    /// `Space`: flips between the method's and the exact frame, in toggle mode only.
    FlipExact,
    SetSplit(f32),
    SetErrorScale(f32),
    SetBackground([f32; 3]),
    SetAntialias(u32),
    SetCoverage(bool),
    SetRenderScale(f32),
    SetShowOpaque(bool),
    SetLit(bool),
    SetHeadlight(bool),
    /// A grey ambient term.
    SetAmbient(f32),
    /// Mesh `index`: visible or not.
    SetMeshVisible(usize, bool),
    /// Mesh `index`: its alpha (or the factor on its alphas).
    SetMeshAlpha(usize, f32),
    /// A drag of (dx, dy) points around the pivot.
    Orbit {
        dx: f64,
        dy: f64,
    },
    /// A drag of (dx, dy) points over a view `height` points tall, moving the pivot.
    Pan {
        dx: f64,
        dy: f64,
        height: f64,
    },
    /// Scroll by points; positive moves closer.
    Zoom(f64),
    ResetView,
    /// A screenshot of the window into the working directory.
    Screenshot,
    TogglePanel,
}
