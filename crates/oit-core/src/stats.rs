//! What a frame reports, defined once: [`Stats`], and [`SCHEMA`], the keys a frame's stats have
//! outside Rust, with their Python types and meanings. [`Stats::entries`] gives the values in the
//! schema's order; oit-py converts them without naming a key, `oit._oit.stats_schema()` exports
//! the schema, and tests/test_contract.py holds the Python `Stats` TypedDict and the `.pyi`
//! against it.

use crate::method::{AntialiasMode, Params};

/// Numbers about one frame (see the contract in README and docs/methods.md).
#[derive(Clone, Debug, Default)]
pub struct Stats {
    pub method: String,
    pub params: Params,
    /// Whether the fragment census ran: without it `fragments` and `max_depth_complexity` are 0
    /// and the frame's `depth_complexity` is empty (methods that need no census run none unless
    /// `Renderer::set_census` asks for it).
    pub census: bool,
    /// Transparent fragments that passed the opaque depth test.
    pub fragments: u64,
    pub max_depth_complexity: u32,
    /// GPU memory the method allocated for this frame (its largest tile's; excludes the frame's
    /// own targets).
    pub memory_bytes: u64,
    /// The frame's own targets and readbacks, at the tile size: base color, depth, output,
    /// error bound, census counts, and a coverage-mask frame's per-sample targets.
    pub target_bytes: u64,
    /// The scene's buffers (vertices, indices, materials, textures, the instance table), apart
    /// from the frame's.
    pub scene_bytes: u64,
    /// `scene_bytes` by what uploaded them: meshes (with materials, textures and instance
    /// tables), strand sets, particle sets.
    pub scene_bytes_by_primitive: [u64; 3],
    /// The part of `scene_bytes` that strand and particle corners take: built on the GPU each
    /// frame, not uploaded.
    pub expanded_bytes: u64,
    /// The part of `scene_bytes` that the materials' textures take (the atlas of every image
    /// with its mips, each image once).
    pub texture_bytes: u64,
    pub gpu_time_ms: Option<f64>,
    pub pass_times_ms: Vec<(&'static str, f64)>,
    pub overflow_fragments: u64,
    pub wall_time_ms: f64,
    pub extra: Vec<(&'static str, f64)>,
    /// Samples a pixel (1: no antialiasing).
    pub antialias: u32,
    pub antialias_mode: AntialiasMode,
    /// Screen tiles the frame was rendered in (1: untiled); summed over antialiasing samples.
    pub tiles: u32,
    /// Chunks the transparent geometry was uploaded in (1 unless it passes a binding).
    pub geometry_chunks: u32,
    /// Instances drawn, over every mesh (a mesh added once counts one).
    pub instances: u64,
    /// The most GPU memory the frame allocated at once: the method's largest tile and the
    /// frame's targets and readbacks (`memory_bytes + target_bytes`), within the memory budget
    /// when one is set; the scene's own buffers are `scene_bytes`.
    pub peak_memory_bytes: u64,
    /// The adapter's name.
    pub adapter: String,
    /// The largest value of the frame's error bound, where the method derives one.
    pub error_bound_max: Option<f64>,
}

/// One key of a frame's stats outside Rust: its name, its Python type (as the TypedDict writes
/// it) and what it means.
#[derive(Clone, Copy, Debug)]
pub struct StatKey {
    pub name: &'static str,
    pub ty: &'static str,
    pub doc: &'static str,
}

const fn key(name: &'static str, ty: &'static str, doc: &'static str) -> StatKey {
    StatKey { name, ty, doc }
}

/// Every key, in the order [`Stats::entries`] gives them. `error_bound_max` is present only
/// where the method derives a bound.
pub const SCHEMA: &[StatKey] = &[
    key("method", "str", "the method's name"),
    key("params", "dict[str, Any]", "every parameter, defaults filled in"),
    key("census", "bool", "whether the fragment census ran (render(census=True), or a method that plans from it)"),
    key("fragments", "int | None", "transparent fragments in front of the opaque depth (summed over samples); None without a census"),
    key("max_depth_complexity", "int | None", "the most transparent fragments of a pixel; None without a census"),
    key("memory_bytes", "int", "what the method allocated (oit.memory_bytes gives its formula)"),
    key("target_bytes", "int", "the frame's targets and readbacks as allocated (tile-sized under a small budget)"),
    key("scene_bytes", "int", "the scene's GPU buffers (one copy of each mesh, the instance table), apart from the frame's"),
    key("expanded_bytes", "int", "the part of scene_bytes that strands and particles build on the GPU each frame, not uploaded"),
    key("texture_bytes", "int", "the part of scene_bytes that textures take (each image once, with its mips, 4 bytes a texel)"),
    key(
        "scene_bytes_by_primitive",
        "dict[str, float]",
        "scene_bytes as 'triangles' (meshes, materials, instances), 'strands' and 'particles'",
    ),
    key("gpu_time_ms", "float | None", "the passes' GPU time; None where the adapter has no timestamp queries"),
    key("pass_times_ms", "dict[str, float]", "GPU time per pass; a pass run more than once adds up"),
    key("overflow_fragments", "int", "fragments a bounded structure could not hold"),
    key("wall_time_ms", "float", "the render's wall time, readback included"),
    key("antialias", "int", "samples a pixel (1: no antialiasing)"),
    key("antialias_mode", "str", "'frames' or 'coverage'"),
    key("tiles", "int", "screen tiles the frame was rendered in (1: untiled), summed over antialiasing samples"),
    key("geometry_chunks", "int", "chunks the transparent geometry was uploaded in (1 unless it passes a binding)"),
    key("instances", "int", "instances drawn, over every mesh (a mesh added once counts one)"),
    key("peak_memory_bytes", "int", "memory_bytes + target_bytes: all the frame allocated at once, within memory_budget"),
    key("adapter", "str", "the adapter's name"),
    key("extra", "dict[str, float]", "method-specific figures, each declared with its merge rule (oit._oit.extra_merge_rules())"),
    key("error_bound_max", "float", "the largest of frame.error_bound, where the method derives one"),
];

/// A value of a frame's stats, as [`Stats::entries`] gives it.
#[derive(Clone, Debug, PartialEq)]
pub enum StatValue<'a> {
    Bool(bool),
    Int(Option<u64>),
    Float(Option<f64>),
    Str(&'a str),
    Params(&'a Params),
    /// Named numbers in order; a name that repeats has been added up.
    Numbers(Vec<(&'static str, f64)>),
}

impl Stats {
    /// Every key of [`SCHEMA`] with its value, in its order (`error_bound_max` only where there
    /// is a bound). Without a census, `fragments` and `max_depth_complexity` are None.
    pub fn entries(&self) -> Vec<(&'static str, StatValue<'_>)> {
        use StatValue::*;
        let counted = |v: u64| Int(self.census.then_some(v));
        let mut entries = vec![
            ("method", Str(&self.method)),
            ("params", Params(&self.params)),
            ("census", Bool(self.census)),
            ("fragments", counted(self.fragments)),
            ("max_depth_complexity", counted(self.max_depth_complexity as u64)),
            ("memory_bytes", Int(Some(self.memory_bytes))),
            ("target_bytes", Int(Some(self.target_bytes))),
            ("scene_bytes", Int(Some(self.scene_bytes))),
            ("expanded_bytes", Int(Some(self.expanded_bytes))),
            ("texture_bytes", Int(Some(self.texture_bytes))),
            ("scene_bytes_by_primitive", Numbers(primitive_bytes(self.scene_bytes_by_primitive))),
            ("gpu_time_ms", Float(self.gpu_time_ms)),
            ("pass_times_ms", Numbers(summed(&self.pass_times_ms))),
            ("overflow_fragments", Int(Some(self.overflow_fragments))),
            ("wall_time_ms", Float(Some(self.wall_time_ms))),
            ("antialias", Int(Some(self.antialias as u64))),
            ("antialias_mode", Str(self.antialias_mode.name())),
            ("tiles", Int(Some(self.tiles as u64))),
            ("geometry_chunks", Int(Some(self.geometry_chunks as u64))),
            ("instances", Int(Some(self.instances))),
            ("peak_memory_bytes", Int(Some(self.peak_memory_bytes))),
            ("adapter", Str(&self.adapter)),
            ("extra", Numbers(self.extra.clone())),
        ];
        if let Some(max) = self.error_bound_max {
            entries.push(("error_bound_max", Float(Some(max))));
        }
        entries
    }

    /// What the renderer knows once the frame is whole: the adapter, and the bound's largest
    /// value.
    pub(crate) fn finish(&mut self, adapter: &str, error_bound: Option<&[f32]>) {
        self.adapter = adapter.to_string();
        self.error_bound_max = error_bound.map(|b| b.iter().fold(0.0f64, |m, &v| m.max(v as f64)));
    }
}

/// Bytes by primitive kind as named numbers ("triangles", "strands", "particles").
fn primitive_bytes(b: [u64; 3]) -> Vec<(&'static str, f64)> {
    vec![("triangles", b[0] as f64), ("strands", b[1] as f64), ("particles", b[2] as f64)]
}

/// How a method's extra number combines over the tiles of a frame and over the samples of an
/// antialiased frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Merge {
    /// Counts: they add up.
    Sum,
    /// Choices and flags (auto's largest k, whether it fell back): the largest.
    Max,
    /// Per-pixel means: weighted by each part's pixels (tiles) or equally (samples).
    Mean,
}

/// Every extra number a method reports, with its merge rule: declared once (tests/test_contract.py
/// checks that every method's extras are here).
pub const EXTRAS: &[(&str, Merge)] = &[
    ("tail_fragments", Merge::Sum),
    ("geometry_passes", Merge::Sum),
    ("peeled_fragments", Merge::Sum),
    ("pool_regrown", Merge::Sum),
    ("resolve_sweeps", Merge::Max),
    ("pool_nodes", Merge::Sum),
    ("counted_in_capture", Merge::Max),
    ("auto_k", Merge::Max),
    ("auto_mean_k", Merge::Mean),
    ("auto_slots", Merge::Sum),
    ("auto_predicted_k", Merge::Max),
    ("auto_exact", Merge::Max),
    ("auto_attempts", Merge::Max),
    ("lock_failures", Merge::Sum),
    ("lock_waits", Merge::Sum),
];

/// The merge rule of extra `name` (a count unless declared otherwise).
pub fn merge_rule(name: &str) -> Merge {
    EXTRAS.iter().find(|(n, _)| *n == name).map_or(Merge::Sum, |(_, m)| *m)
}

/// Extra numbers of several parts of a frame (tiles or samples), merged by their rules; each part
/// has a weight (its pixels, or 1 a sample) for the means.
#[derive(Default)]
pub(crate) struct ExtraMerge {
    values: Vec<(&'static str, f64, f64)>,
}

impl ExtraMerge {
    pub fn add(&mut self, extra: &[(&'static str, f64)], weight: f64) {
        for &(name, v) in extra {
            let rule = merge_rule(name);
            let x = if rule == Merge::Mean { v * weight } else { v };
            match self.values.iter_mut().find(|(n, _, _)| *n == name) {
                Some((_, total, w)) => {
                    *total = if rule == Merge::Max { total.max(x) } else { *total + x };
                    *w += weight;
                }
                None => self.values.push((name, x, weight)),
            }
        }
    }

    pub fn finish(self) -> Vec<(&'static str, f64)> {
        self.values.into_iter().map(|(name, v, w)| (name, if merge_rule(name) == Merge::Mean && w > 0.0 { v / w } else { v })).collect()
    }
}

/// Named numbers with repeats added up, in the order of first appearance (a pass that ran more
/// than once: antialiasing samples, auto's attempts).
fn summed(pairs: &[(&'static str, f64)]) -> Vec<(&'static str, f64)> {
    let mut out: Vec<(&'static str, f64)> = Vec::new();
    for &(k, v) in pairs {
        match out.iter_mut().find(|(name, _)| *name == k) {
            Some((_, total)) => *total += v,
            None => out.push((k, v)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_entries_are_the_schema_in_its_order() {
        let mut stats = Stats { error_bound_max: Some(0.5), census: true, ..Default::default() };
        let names: Vec<_> = stats.entries().iter().map(|(k, _)| *k).collect();
        assert_eq!(names, SCHEMA.iter().map(|k| k.name).collect::<Vec<_>>());
        stats.error_bound_max = None;
        assert_eq!(stats.entries().len(), SCHEMA.len() - 1, "no error_bound_max without a bound");
    }

    #[test]
    fn counts_are_unknown_without_a_census_and_repeated_passes_add_up() {
        let stats = Stats { fragments: 7, pass_times_ms: vec![("a", 1.0), ("b", 2.0), ("a", 3.0)], ..Default::default() };
        let entries = stats.entries();
        let get = |name| entries.iter().find(|(k, _)| *k == name).map(|(_, v)| v.clone()).unwrap();
        assert_eq!(get("fragments"), StatValue::Int(None));
        assert_eq!(get("pass_times_ms"), StatValue::Numbers(vec![("a", 4.0), ("b", 2.0)]));
    }

    #[test]
    fn extras_merge_by_their_declared_rules() {
        let mut m = ExtraMerge::default();
        m.add(&[("tail_fragments", 3.0), ("auto_k", 4.0), ("auto_mean_k", 2.0)], 100.0);
        m.add(&[("tail_fragments", 5.0), ("auto_k", 2.0), ("auto_mean_k", 4.0)], 300.0);
        assert_eq!(m.finish(), vec![("tail_fragments", 8.0), ("auto_k", 4.0), ("auto_mean_k", 3.5)]);
        let names: Vec<_> = EXTRAS.iter().map(|(n, _)| *n).collect();
        assert!(names.iter().enumerate().all(|(i, n)| !names[..i].contains(n)), "an extra declared twice");
    }

    #[test]
    fn finishing_takes_the_largest_bound() {
        let mut stats = Stats::default();
        stats.finish("lavapipe", Some(&[0.25, 0.75, 0.5]));
        assert_eq!((stats.adapter.as_str(), stats.error_bound_max), ("lavapipe", Some(0.75)));
        stats.finish("lavapipe", None);
        assert_eq!(stats.error_bound_max, None);
    }
}
