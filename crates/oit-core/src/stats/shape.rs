//! How each field of the stats table shows outside Rust (the table's shape column: None leaves its
//! key out) and how a `Sum` field adds up over samples.

use super::extras::declared_rule;
use super::{StatValue, Stats};

/// A value as it is.
pub(super) fn plain<'a, T: Plain>(_: &Stats, v: &'a T) -> Option<StatValue<'a>> {
    Some(v.plain())
}

/// A count the census makes: None without one.
pub(super) fn counted<'a, T: Plain>(s: &Stats, v: &'a T) -> Option<StatValue<'a>> {
    Some(if s.census { v.plain() } else { StatValue::Int(None) })
}

/// Present only with a value.
pub(super) fn if_some(_: &Stats, v: &Option<f64>) -> Option<StatValue<'static>> {
    v.map(|v| StatValue::Float(Some(v)))
}

/// Bytes by primitive kind as named numbers.
pub(super) fn by_primitive(_: &Stats, b: &[u64; 4]) -> Option<StatValue<'static>> {
    let names = ["triangles", "strands", "particles", "gaussians"];
    Some(StatValue::Numbers(names.iter().zip(b).map(|(&n, &v)| (n, v as f64)).collect()))
}

/// Named numbers with repeats added up, in the order of first appearance (a pass that ran
/// more than once: antialiasing samples, auto's attempts).
pub(super) fn summed(_: &Stats, pairs: &[(&'static str, f64)]) -> Option<StatValue<'static>> {
    let mut out: Vec<(&'static str, f64)> = Vec::new();
    for &(k, v) in pairs {
        match out.iter_mut().find(|(name, _)| *name == k) {
            Some((_, total)) => *total += v,
            None => out.push((k, v)),
        }
    }
    Some(StatValue::Numbers(out))
}

/// Extra numbers, each declared in `EXTRAS` (an undeclared one panics: a method's bug).
pub(super) fn declared(_: &Stats, pairs: &[(&'static str, f64)]) -> Option<StatValue<'static>> {
    pairs.iter().for_each(|(name, _)| _ = declared_rule(name));
    Some(StatValue::Numbers(pairs.to_vec()))
}

/// A field's value as a plain [`StatValue`].
pub(super) trait Plain {
    fn plain(&self) -> StatValue<'_>;
}

impl Plain for String {
    fn plain(&self) -> StatValue<'_> {
        StatValue::Str(self)
    }
}

impl Plain for crate::method::Params {
    fn plain(&self) -> StatValue<'_> {
        StatValue::Params(self)
    }
}

impl Plain for bool {
    fn plain(&self) -> StatValue<'_> {
        StatValue::Bool(*self)
    }
}

impl Plain for u64 {
    fn plain(&self) -> StatValue<'_> {
        StatValue::Int(Some(*self))
    }
}

impl Plain for u32 {
    fn plain(&self) -> StatValue<'_> {
        StatValue::Int(Some(*self as u64))
    }
}

impl Plain for f64 {
    fn plain(&self) -> StatValue<'_> {
        StatValue::Float(Some(*self))
    }
}

impl Plain for Option<f64> {
    fn plain(&self) -> StatValue<'_> {
        StatValue::Float(*self)
    }
}

impl Plain for crate::method::AntialiasMode {
    fn plain(&self) -> StatValue<'_> {
        StatValue::Str(self.name())
    }
}

/// The `Sum` merge of a field's type.
pub(super) trait Add {
    fn add(&mut self, other: Self);
}

impl Add for u64 {
    fn add(&mut self, other: Self) {
        *self += other;
    }
}

impl Add for u32 {
    fn add(&mut self, other: Self) {
        *self += other;
    }
}

/// Unknown (None) where any part's is.
impl Add for Option<f64> {
    fn add(&mut self, other: Self) {
        *self = self.zip(other).map(|(a, b)| a + b);
    }
}

/// Named numbers: the later part's follow (`shape::summed` adds up the repeats).
impl Add for Vec<(&'static str, f64)> {
    fn add(&mut self, other: Self) {
        self.extend(other);
    }
}
