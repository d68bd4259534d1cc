//! The glTF JSON read by hand: every value checked for its type and range before use, and
//! named by its path (`accessors[3].count`) when it is wrong. Integers may be written `1.0`
//! (the validator allows it); `null` reads as absent; unknown fields and `extras` are ignored.

use serde_json::{Map, Value};

/// An object of the document and where it is (`meshes[0].primitives[1]`).
#[derive(Clone, Debug)]
pub(super) struct Obj<'a> {
    pub at: String,
    pub map: &'a Map<String, Value>,
}

/// A value's JSON type, for messages.
fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// A non-negative integer (written `3` or `3.0`) up to 2^53.
fn as_uint(v: &Value) -> Option<u64> {
    v.as_u64().or_else(|| v.as_f64().filter(|x| *x >= 0.0 && x.fract() == 0.0 && *x <= 9_007_199_254_740_992.0).map(|x| x as u64))
}

impl<'a> Obj<'a> {
    pub fn root(value: &'a Value) -> Result<Self, String> {
        match value {
            Value::Object(map) => Ok(Self { at: String::new(), map }),
            v => Err(format!("the glTF JSON is {}, not an object", kind(v))),
        }
    }

    fn path(&self, key: &str) -> String {
        if self.at.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.at)
        }
    }

    pub fn get(&self, key: &str) -> Option<&'a Value> {
        self.map.get(key).filter(|v| !v.is_null())
    }

    fn wrong(&self, key: &str, want: &str, v: &Value) -> String {
        let shown = v.to_string();
        let shown =
            if shown.len() > 40 { format!("{}...", &shown[..shown.char_indices().nth(37).map_or(shown.len(), |c| c.0)]) } else { shown };
        format!("{}: expected {want}, got {} ({shown})", self.path(key), kind(v))
    }

    pub fn uint(&self, key: &str) -> Result<Option<u64>, String> {
        self.get(key).map(|v| as_uint(v).ok_or_else(|| self.wrong(key, "a non-negative integer", v))).transpose()
    }

    pub fn uint_or(&self, key: &str, default: u64) -> Result<u64, String> {
        Ok(self.uint(key)?.unwrap_or(default))
    }

    /// A code such as a component type or a filter (a non-negative integer below 2^32).
    pub fn code(&self, key: &str) -> Result<Option<u32>, String> {
        match self.uint(key)? {
            Some(c) => u32::try_from(c).map(Some).map_err(|_| format!("{}: {c} is not a glTF code", self.path(key))),
            None => Ok(None),
        }
    }

    /// An index into the document's array `target` of `len` objects.
    pub fn index(&self, key: &str, len: usize, target: &str) -> Result<Option<usize>, String> {
        let Some(i) = self.uint(key)? else { return Ok(None) };
        check_index(&self.path(key), i, len, target).map(Some)
    }

    pub fn required_index(&self, key: &str, len: usize, target: &str) -> Result<usize, String> {
        self.index(key, len, target)?.ok_or_else(|| format!("{}: the required field '{key}' is missing", self.name()))
    }

    /// The object's own name in messages (`accessors[3]`, or "the glTF JSON" at the root).
    pub fn name(&self) -> &str {
        if self.at.is_empty() {
            "the glTF JSON"
        } else {
            &self.at
        }
    }

    pub fn num(&self, key: &str) -> Result<Option<f64>, String> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => v.as_f64().filter(|x| x.is_finite()).map(Some).ok_or_else(|| self.wrong(key, "a number", v)),
        }
    }

    pub fn nums<const N: usize>(&self, key: &str) -> Result<Option<[f64; N]>, String> {
        let Some(v) = self.get(key) else { return Ok(None) };
        let want = format!("an array of {N} numbers");
        let items = v.as_array().filter(|a| a.len() == N).ok_or_else(|| self.wrong(key, &want, v))?;
        let mut out = [0.0; N];
        for (o, x) in out.iter_mut().zip(items) {
            *o = x.as_f64().filter(|x| x.is_finite()).ok_or_else(|| self.wrong(key, &want, v))?;
        }
        Ok(Some(out))
    }

    pub fn str(&self, key: &str) -> Result<Option<&'a str>, String> {
        self.get(key).map(|v| v.as_str().ok_or_else(|| self.wrong(key, "a string", v))).transpose()
    }

    pub fn bool(&self, key: &str) -> Result<Option<bool>, String> {
        self.get(key).map(|v| v.as_bool().ok_or_else(|| self.wrong(key, "true or false", v))).transpose()
    }

    pub fn obj(&self, key: &str) -> Result<Option<Obj<'a>>, String> {
        match self.get(key) {
            None => Ok(None),
            Some(Value::Object(map)) => Ok(Some(Obj { at: self.path(key), map })),
            Some(v) => Err(self.wrong(key, "an object", v)),
        }
    }

    /// The array `key` (missing: empty).
    pub fn array(&self, key: &str) -> Result<&'a [Value], String> {
        match self.get(key) {
            None => Ok(&[]),
            Some(Value::Array(a)) => Ok(a),
            Some(v) => Err(self.wrong(key, "an array", v)),
        }
    }

    /// The array `key` of objects, each named `key[i]`.
    pub fn objs(&self, key: &str) -> Result<Vec<Obj<'a>>, String> {
        let base = self.path(key);
        self.array(key)?
            .iter()
            .enumerate()
            .map(|(i, v)| match v {
                Value::Object(map) => Ok(Obj { at: format!("{base}[{i}]"), map }),
                v => Err(format!("{base}[{i}]: expected an object, got {}", kind(v))),
            })
            .collect()
    }

    /// The array `key` of indices into `target` (`len` objects).
    pub fn indices(&self, key: &str, len: usize, target: &str) -> Result<Vec<usize>, String> {
        let base = self.path(key);
        self.array(key)?
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let at = format!("{base}[{i}]");
                let n = as_uint(v).ok_or_else(|| format!("{at}: expected a non-negative integer, got {}", kind(v)))?;
                check_index(&at, n, len, target)
            })
            .collect()
    }

    /// The extension `name` of this object, if it has it.
    pub fn extension(&self, name: &str) -> Result<Option<Obj<'a>>, String> {
        match self.obj("extensions")? {
            Some(e) => e.obj(name),
            None => Ok(None),
        }
    }
}

fn check_index(at: &str, i: u64, len: usize, target: &str) -> Result<usize, String> {
    if i < len as u64 {
        Ok(i as usize)
    } else {
        Err(format!("{at}: {target}[{i}] does not exist (the file has {len} {target})"))
    }
}
