//! Method parameters: their declared kinds and ranges, the values given, and their validation
//! (with "did you mean" hints).

use std::collections::BTreeMap;

use crate::error::{invalid, Result};
use crate::shader::Const;

/// A parameter's type, range and default.
#[derive(Clone, Copy, Debug)]
pub enum ParamKind {
    /// Valid values: min, min + step, .., max.
    Int {
        min: i64,
        max: i64,
        default: i64,
        step: i64,
    },
    Float {
        min: f64,
        max: f64,
        default: f64,
    },
    Choice {
        choices: &'static [&'static str],
        default: &'static str,
    },
}

#[derive(Clone, Copy, Debug)]
pub struct ParamInfo {
    pub name: &'static str,
    pub kind: ParamKind,
    pub doc: &'static str,
    /// The shader constant its value compiles into, with the value of its default (what the
    /// shaders are validated with: `method::default_consts`).
    pub compiled: Option<(&'static str, u32)>,
}

/// An integer parameter declared once: its `ParamInfo` (what `MethodInfo::params` lists) and
/// the typed read of its checked value, so that a method names it in one place.
#[derive(Clone, Copy, Debug)]
pub struct IntParam(pub ParamInfo);

impl IntParam {
    pub const fn new(name: &'static str, (min, max, default): (i64, i64, i64), doc: &'static str) -> Self {
        assert!(0 <= min && min <= default && default <= max && max <= u32::MAX as i64, "an integer parameter is a u32 in range");
        Self(ParamInfo { name, kind: ParamKind::Int { min, max, default, step: 1 }, doc, compiled: None })
    }

    /// The same parameter valid only at min, min + step, .., max (its default and max among them).
    pub const fn stepped(self, step: i64) -> Self {
        let ParamKind::Int { min, max, default, .. } = self.0.kind else { unreachable!() };
        assert!(step >= 1 && (default - min) % step == 0 && (max - min) % step == 0, "default and max on the step");
        Self(ParamInfo { kind: ParamKind::Int { min, max, default, step }, ..self.0 })
    }

    /// The same parameter compiled into the shader constant `constant`.
    pub const fn compiled_as(self, constant: &'static str) -> Self {
        let ParamKind::Int { default, .. } = self.0.kind else { unreachable!() };
        Self(ParamInfo { compiled: Some((constant, default as u32)), ..self.0 })
    }

    /// Its value in `params` (checked against its range when they were resolved).
    pub fn of(&self, params: &Params) -> u32 {
        params.int(self.0.name) as u32
    }

    /// Its shader constant with its value in `params`.
    pub fn constant(&self, params: &Params) -> Const {
        let (name, _) = self.0.compiled.expect("a compiled parameter (IntParam::compiled_as)");
        Const::U32(name, self.of(params))
    }
}

/// A number parameter declared once (see `IntParam`).
#[derive(Clone, Copy, Debug)]
pub struct FloatParam(pub ParamInfo);

impl FloatParam {
    pub const fn new(name: &'static str, (min, max, default): (f64, f64, f64), doc: &'static str) -> Self {
        Self(ParamInfo { name, kind: ParamKind::Float { min, max, default }, doc, compiled: None })
    }

    pub fn of(&self, params: &Params) -> f64 {
        params.float(self.0.name)
    }
}

/// A parameter that is one of named choices, declared once with the value each choice stands
/// for: the method reads the value, never the name.
#[derive(Clone, Copy, Debug)]
pub struct ChoiceParam<T: 'static> {
    pub info: ParamInfo,
    values: &'static [T],
    default: usize,
}

impl<T: Copy + PartialEq> ChoiceParam<T> {
    /// `choices[i]` stands for `values[i]`; `choices[default]` is the default.
    pub const fn new(
        name: &'static str,
        choices: &'static [&'static str],
        values: &'static [T],
        default: usize,
        doc: &'static str,
    ) -> Self {
        assert!(choices.len() == values.len() && default < choices.len(), "a value for each choice");
        Self {
            info: ParamInfo { name, kind: ParamKind::Choice { choices, default: choices[default] }, doc, compiled: None },
            values,
            default,
        }
    }

    /// The value of its checked choice in `params`.
    pub fn of(&self, params: &Params) -> T {
        let ParamKind::Choice { choices, .. } = self.info.kind else { unreachable!("made by ChoiceParam::new") };
        let at = choices.iter().position(|c| *c == params.choice(self.info.name));
        self.values[at.expect("resolve_params checked the choice")]
    }

    /// Its value in `params`, or `absent` for a method without it (ktab has no `tail`).
    pub fn or(&self, params: &Params, absent: T) -> T {
        if params.0.contains_key(self.info.name) {
            self.of(params)
        } else {
            absent
        }
    }

    /// Whether `params` choose `value` (false where the method has no such parameter).
    pub fn is(&self, params: &Params, value: T) -> bool {
        params.0.contains_key(self.info.name) && self.of(params) == value
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    Int(i64),
    Float(f64),
    Str(String),
}

/// Parameters after validation, every declared one present (defaults filled in).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Params(pub BTreeMap<&'static str, ParamValue>);

impl Params {
    pub fn int(&self, name: &str) -> i64 {
        match self.0.get(name) {
            Some(ParamValue::Int(v)) => *v,
            other => panic!("parameter '{name}' is not an int: {other:?}"),
        }
    }
    pub fn float(&self, name: &str) -> f64 {
        match self.0.get(name) {
            Some(ParamValue::Float(v)) => *v,
            Some(ParamValue::Int(v)) => *v as f64,
            other => panic!("parameter '{name}' is not a float: {other:?}"),
        }
    }
    pub fn choice(&self, name: &str) -> &str {
        match self.0.get(name) {
            Some(ParamValue::Str(v)) => v,
            other => panic!("parameter '{name}' is not a choice: {other:?}"),
        }
    }
}

/// Levenshtein distance, for "did you mean" hints.
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + (ca != *cb) as usize).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

pub(crate) fn did_you_mean<'a>(name: &str, options: impl Iterator<Item = &'a str>) -> String {
    let lower = name.to_lowercase();
    options
        .map(|o| (distance(&lower, o), o))
        .filter(|(d, _)| *d <= 2)
        .min()
        .map(|(_, o)| format!(" (did you mean '{o}'?)"))
        .unwrap_or_default()
}

pub(crate) fn check(method: &str, info: &ParamInfo, value: &ParamValue) -> Result<ParamValue> {
    let name = info.name;
    match (info.kind, value) {
        (ParamKind::Int { min, max, step, .. }, ParamValue::Int(v)) => {
            if *v < min || *v > max {
                return Err(invalid!("{method}: {name} = {v} is out of range; use {min} <= {name} <= {max}"));
            }
            if (*v - min) % step != 0 {
                let valid: Vec<String> = (min..=max).step_by(step as usize).map(|x| x.to_string()).collect();
                return Err(invalid!("{method}: {name} = {v} is not a valid count; use one of {}", valid.join(", ")));
            }
            Ok(ParamValue::Int(*v))
        }
        (ParamKind::Float { min, max, .. }, ParamValue::Float(_) | ParamValue::Int(_)) => {
            let v = match value {
                ParamValue::Float(f) => *f,
                ParamValue::Int(i) => *i as f64,
                ParamValue::Str(_) => unreachable!(),
            };
            if !v.is_finite() || v < min || v > max {
                return Err(invalid!("{method}: {name} = {v} is out of range; use {min} <= {name} <= {max}"));
            }
            Ok(ParamValue::Float(v))
        }
        (ParamKind::Choice { choices, .. }, ParamValue::Str(s)) => {
            if !choices.contains(&s.as_str()) {
                return Err(invalid!("{method}: {name} = '{s}' is not one of: {}", choices.join(", ")));
            }
            Ok(ParamValue::Str(s.clone()))
        }
        (kind, v) => {
            let got = match v {
                ParamValue::Int(i) => format!("the integer {i}"),
                ParamValue::Float(f) => format!("the number {f}"),
                ParamValue::Str(s) => format!("the string '{s}'"),
            };
            let want = match kind {
                ParamKind::Int { min, max, .. } => format!("an integer in [{min}, {max}]"),
                ParamKind::Float { min, max, .. } => format!("a number in [{min}, {max}]"),
                ParamKind::Choice { choices, .. } => format!("one of {}", choices.join(", ")),
            };
            Err(invalid!("{method}: {name} must be {want}, got {got}"))
        }
    }
}

impl ChoiceParam<u32> {
    /// The same parameter compiled into the shader constant `constant` (its value's number).
    pub const fn compiled_as(self, constant: &'static str) -> Self {
        Self { info: ParamInfo { compiled: Some((constant, self.values[self.default])), ..self.info }, ..self }
    }

    /// Its shader constant with its value in `params` (`absent` for a method without it).
    pub fn constant_or(&self, params: &Params, absent: u32) -> Const {
        let (name, _) = self.info.compiled.expect("a compiled parameter (ChoiceParam::compiled_as)");
        Const::U32(name, self.or(params, absent))
    }
}
