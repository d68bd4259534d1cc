//! The extra numbers methods report (`Stats::extra`), each declared once with how tiles and
//! samples merge it; one not declared is a bug in its method, and panics where it is met.

use super::Merge;

/// Every extra number a method reports, with its merge rule (`Sum`, `Max` or `Mean`): declared
/// once (tests/test_contract.py checks that every method's extras are here).
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
    ("auto_moments", Merge::Max),
    ("lock_failures", Merge::Sum),
    ("lock_waits", Merge::Sum),
];

/// The merge rule of extra `name`, None where [`EXTRAS`] does not declare it.
pub fn merge_rule(name: &str) -> Option<Merge> {
    EXTRAS.iter().find(|(n, _)| *n == name).map(|(_, m)| *m)
}

/// The merge rule of an extra a method reported: one not in [`EXTRAS`] is a bug in that method,
/// and panics (the binding reports a panic as a bug).
pub(super) fn declared_rule(name: &str) -> Merge {
    merge_rule(name).unwrap_or_else(|| panic!("extra number '{name}' has no merge rule: declare it in stats::EXTRAS"))
}

/// Extra numbers of several parts of a frame (tiles or samples), merged by their rules; each part
/// has a weight (its pixels, or 1 a sample) for the means.
#[derive(Default)]
pub(crate) struct ExtraMerge {
    values: Vec<(&'static str, Merge, f64, f64)>,
}

impl ExtraMerge {
    pub fn add(&mut self, extra: &[(&'static str, f64)], weight: f64) {
        for &(name, v) in extra {
            let rule = declared_rule(name);
            let x = if rule == Merge::Mean { v * weight } else { v };
            match self.values.iter_mut().find(|(n, ..)| *n == name) {
                Some((_, _, total, w)) => {
                    *total = if rule == Merge::Max { total.max(x) } else { *total + x };
                    *w += weight;
                }
                None => self.values.push((name, rule, x, weight)),
            }
        }
    }

    pub fn finish(self) -> Vec<(&'static str, f64)> {
        self.values.into_iter().map(|(name, rule, v, w)| (name, if rule == Merge::Mean && w > 0.0 { v / w } else { v })).collect()
    }
}
