//! What a frame reports, declared once in the table of [`stats_table!`]: each key's field, its
//! Python type, its merge over the samples of an antialiased frame, how it shows outside Rust,
//! and its meaning. The table makes the [`Stats`] struct, [`SCHEMA`], [`Stats::entries`] (the
//! dict Python gets: oit-py converts it without naming a key) and the samples' merge
//! ([`SampleMerge`]). `oit._oit.stats_schema()` exports the schema, and tests/test_contract.py
//! holds the Python `oit.Stats` TypedDict against it. Method-specific numbers (`extra`) merge by
//! the rules of [`EXTRAS`]; one not declared there is a bug, and panics where it is met.

use crate::method::{AntialiasMode, Params};

mod extras;
mod shape;

pub(crate) use extras::ExtraMerge;
pub use extras::{merge_rule, EXTRAS};
use shape::Add;

/// How a number combines over the parts of a frame: a key of [`Stats`] over the samples of an
/// antialiased frame, an extra number over tiles and samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Merge {
    /// Alike in every sample (the scene, the method): the first sample's.
    First,
    /// The whole frame's, set once its samples are merged (wall time, adapter, bound).
    Frame,
    /// Counts: they add up (named numbers: a name that repeats adds up).
    Sum,
    /// Peaks, choices and flags (auto's largest k, whether it fell back): the largest.
    Max,
    /// Per-pixel means: weighted by each part's pixels (tiles) or equally (samples).
    Mean,
    /// Each extra number by its own rule ([`EXTRAS`]).
    ByName,
}

impl Merge {
    pub fn name(self) -> &'static str {
        match self {
            Merge::First => "first",
            Merge::Frame => "frame",
            Merge::Sum => "sum",
            Merge::Max => "max",
            Merge::Mean => "mean",
            Merge::ByName => "by_name",
        }
    }
}

/// One key of a frame's stats outside Rust: its name, its Python type (as the TypedDict writes
/// it), what it means, and how the samples of an antialiased frame merge it.
#[derive(Clone, Copy, Debug)]
pub struct StatKey {
    pub name: &'static str,
    pub ty: &'static str,
    pub doc: &'static str,
    pub merge: Merge,
}

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

/// `name: Type, "Python type", Merge, shape, "meaning";` a row, in the order Python's dict has
/// them. The shape (a function of [`shape`]) says how the value shows outside Rust.
macro_rules! stats_table {
    ($(#[$attr:meta])* pub struct $name:ident {
        $($(#[doc = $rdoc:literal])* $field:ident: $ty:ty, $py:literal, $merge:ident, $shape:ident, $doc:literal;)*
    }) => {
        $(#[$attr])*
        pub struct $name {
            $($(#[doc = $rdoc])* #[doc = concat!("\n\nOutside Rust: `", $py, "`, ", $doc, ".")] pub $field: $ty,)*
        }

        /// Every key, in the order [`Stats::entries`] gives them.
        pub const SCHEMA: &[StatKey] =
            &[$(StatKey { name: stringify!($field), ty: $py, doc: $doc, merge: Merge::$merge },)*];

        impl $name {
            /// Every key of [`SCHEMA`] that has a value, with it, in its order
            /// (`error_bound_max` only where there is a bound).
            pub fn entries(&self) -> Vec<(&'static str, StatValue<'_>)> {
                let mut out = Vec::with_capacity(SCHEMA.len());
                $(if let Some(v) = shape::$shape(self, &self.$field) {
                    out.push((stringify!($field), v));
                })*
                out
            }

            /// Merges the stats of a later sample into this one's, key by key by its rule (the
            /// extra numbers are [`SampleMerge`]'s).
            fn merge_sample(&mut self, later: Stats) {
                $(merge_key!($merge, self.$field, later.$field);)*
            }
        }
    };
}

/// One key's merge: `First`, `Frame` and `ByName` keys keep what they have (`Mean` is for
/// extras only).
macro_rules! merge_key {
    (Sum, $a:expr, $b:expr) => {
        Add::add(&mut $a, $b)
    };
    (Max, $a:expr, $b:expr) => {
        $a = $a.max($b)
    };
    (First, $a:expr, $b:expr) => {};
    (Frame, $a:expr, $b:expr) => {};
    (ByName, $a:expr, $b:expr) => {};
}

stats_table! {
    /// Numbers about one frame (see the contract in README and docs/methods.md).
    #[derive(Clone, Debug, Default)]
    pub struct Stats {
        method: String, "str", First, plain, "the method's name";
        params: Params, "dict[str, Any]", First, plain, "every parameter, defaults filled in";
        /// Whether the fragment census ran: without it `fragments` and `max_depth_complexity`
        /// are unknown and the frame's `depth_complexity` is empty (methods that need no census
        /// run none unless `Renderer::set_census` asks for it).
        census: bool, "bool", First, plain,
            "whether the fragment census ran (render(census=True), or a method that plans from it)";
        /// Transparent fragments that passed the opaque depth test.
        fragments: u64, "int | None", Sum, counted,
            "transparent fragments in front of the opaque depth (summed over samples); None without a census";
        max_depth_complexity: u32, "int | None", Max, counted,
            "the most transparent fragments of a pixel; None without a census";
        /// GPU memory the method allocated for this frame (its largest tile's; excludes the
        /// frame's own targets).
        memory_bytes: u64, "int", Max, plain, "what the method allocated (oit.memory_bytes gives its formula)";
        /// The frame's own targets and readbacks, at the tile size: base color, depth, output,
        /// error bound, census counts, and a coverage-mask frame's per-sample targets.
        target_bytes: u64, "int", First, plain,
            "the frame's targets and readbacks as allocated (tile-sized under a small budget)";
        /// The scene's buffers (vertices, indices, materials, textures, the instance table).
        scene_bytes: u64, "int", First, plain,
            "the scene's GPU buffers (one copy of each mesh, the instance table), apart from the frame's";
        /// Strand and particle corners: built on the GPU each frame, not uploaded.
        expanded_bytes: u64, "int", First, plain,
            "the part of scene_bytes that strands and particles build on the GPU each frame, not uploaded";
        /// The atlas of every image with its mips, each image once.
        texture_bytes: u64, "int", First, plain,
            "the part of scene_bytes that textures take (each image once, with its mips, 4 bytes a texel)";
        /// By what uploaded them: meshes (with materials, textures and instance tables), strand
        /// sets, particle sets, splat sets.
        scene_bytes_by_primitive: [u64; 4], "dict[str, float]", First, by_primitive,
            "scene_bytes by kind: 'triangles' (and instances), 'strands', 'particles', 'gaussians'";
        gpu_time_ms: Option<f64>, "float | None", Sum, plain,
            "the passes' GPU time; None where the adapter has no timestamp queries";
        pass_times_ms: Vec<(&'static str, f64)>, "dict[str, float]", Sum, summed,
            "GPU time per pass; a pass run more than once adds up";
        overflow_fragments: u64, "int", Sum, plain, "fragments a bounded structure could not hold";
        wall_time_ms: f64, "float", Frame, plain, "the render's wall time, readback included";
        antialias: u32, "int", Frame, plain, "samples a pixel (1: no antialiasing)";
        antialias_mode: AntialiasMode, "str", Frame, plain, "'frames' or 'coverage'";
        tiles: u32, "int", Sum, plain,
            "screen tiles the frame was rendered in (1: untiled), summed over antialiasing samples";
        geometry_chunks: u32, "int", First, plain,
            "chunks the transparent geometry was uploaded in (1 unless it passes a binding)";
        instances: u64, "int", First, plain, "instances drawn, over every mesh (a mesh added once counts one)";
        /// The most GPU memory the frame allocated at once: the method's largest tile and the
        /// frame's targets and readbacks (`memory_bytes + target_bytes`); the scene's own
        /// buffers are `scene_bytes`.
        peak_memory_bytes: u64, "int", Max, plain,
            "memory_bytes + target_bytes: all the frame allocated at once, within memory_budget";
        adapter: String, "str", Frame, plain, "the adapter's name";
        extra: Vec<(&'static str, f64)>, "dict[str, float]", ByName, declared,
            "method-specific figures, each declared with its merge rule (oit._oit.extra_merge_rules())";
        error_bound_max: Option<f64>, "float", Frame, if_some,
            "the largest of frame.error_bound, where the method derives one";
    }
}

impl Stats {
    /// What the renderer knows once the frame is whole: the adapter, and the bound's largest
    /// value.
    pub(crate) fn finish(&mut self, adapter: &str, error_bound: Option<&[f32]>) {
        self.adapter = adapter.to_string();
        self.error_bound_max = error_bound.map(|b| b.iter().fold(0.0f64, |m, &v| m.max(v as f64)));
    }
}

/// The stats of an antialiased frame's samples, merged by each key's rule ([`SCHEMA`]); the
/// `Frame` keys are the caller's to set afterwards.
#[derive(Default)]
pub(crate) struct SampleMerge {
    stats: Option<Stats>,
    extra: ExtraMerge,
}

impl SampleMerge {
    pub fn add(&mut self, sample: Stats) {
        self.extra.add(&sample.extra, 1.0);
        match &mut self.stats {
            Some(first) => first.merge_sample(sample),
            None => self.stats = Some(sample),
        }
    }

    pub fn finish(self) -> Stats {
        let mut stats = self.stats.unwrap_or_default();
        stats.extra = self.extra.finish();
        stats
    }
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
        assert!(EXTRAS.iter().all(|(_, m)| matches!(m, Merge::Sum | Merge::Max | Merge::Mean)));
    }

    #[test]
    #[should_panic(expected = "extra number 'made_up' has no merge rule: declare it in stats::EXTRAS")]
    fn an_undeclared_extra_is_refused_when_merged() {
        ExtraMerge::default().add(&[("tail_fragments", 1.0), ("made_up", 2.0)], 1.0);
    }

    #[test]
    #[should_panic(expected = "extra number 'made_up' has no merge rule")]
    fn an_undeclared_extra_is_refused_on_its_way_out() {
        Stats { extra: vec![("made_up", 2.0)], ..Default::default() }.entries();
    }

    #[test]
    fn samples_merge_by_each_keys_rule() {
        let sample = |i: u32| Stats {
            method: "hybrid".into(),
            census: true,
            fragments: 10 * i as u64,
            max_depth_complexity: 4 - i,
            memory_bytes: 100 * i as u64,
            target_bytes: 7 + i as u64,
            gpu_time_ms: Some(i as f64),
            pass_times_ms: vec![("capture", 1.0), ("resolve", i as f64)],
            overflow_fragments: i as u64,
            tiles: 2,
            instances: 3,
            peak_memory_bytes: 50 * i as u64,
            wall_time_ms: 9.0,
            extra: vec![("tail_fragments", i as f64), ("auto_mean_k", 2.0 * i as f64)],
            ..Default::default()
        };
        let mut m = SampleMerge::default();
        (1..=3).for_each(|i| m.add(sample(i)));
        let s = m.finish();
        assert_eq!((s.method.as_str(), s.census, s.fragments, s.max_depth_complexity), ("hybrid", true, 60, 3));
        assert_eq!((s.memory_bytes, s.target_bytes, s.overflow_fragments, s.tiles, s.instances), (300, 8, 6, 6, 3));
        assert_eq!((s.gpu_time_ms, s.peak_memory_bytes, s.wall_time_ms), (Some(6.0), 150, 9.0));
        assert_eq!(s.pass_times_ms.len(), 6);
        assert_eq!(s.extra, vec![("tail_fragments", 6.0), ("auto_mean_k", 4.0)]);
        let mut untimed = SampleMerge::default();
        [sample(1), Stats { gpu_time_ms: None, ..sample(2) }].into_iter().for_each(|s| untimed.add(s));
        assert_eq!(untimed.finish().gpu_time_ms, None, "unknown where a sample's is");
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
