//! The last line against panics: every public entry of the module runs under [`guard`], which
//! turns a Rust panic into a `RuntimeError` that names what was being done and says it is a
//! bug, instead of PyO3's `PanicException` (a `BaseException` that `except Exception` misses).
//! The `guarded!` macro wraps each `fn` of a `#[pymethods]` block or a list of `#[pyfunction]`s
//! and records their names (`GUARDED`), which tests/test_load_entry_points.py checks against
//! everything the module exposes.

use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// The panic's own message, when it has one.
pub fn panic_text(payload: &(dyn Any + Send)) -> &str {
    payload.downcast_ref::<&str>().copied().or_else(|| payload.downcast_ref::<String>().map(String::as_str)).unwrap_or("no message")
}

/// The `RuntimeError` for a panic while doing `what`.
pub fn bug(what: &str, payload: &(dyn Any + Send)) -> PyErr {
    PyRuntimeError::new_err(format!(
        "{what} failed on an internal error ({}): this is a bug in oit; please report it with the input that caused it",
        panic_text(payload)
    ))
}

/// Runs `f`; a panic inside becomes [`bug`]`(what)`.
pub fn guard<T>(what: &str, f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|payload| Err(bug(what, &*payload)))
}

/// `guarded! { #[pymethods] impl Type { fns } }` or `guarded! { fns LIST; #[pyfunction] fns }`:
/// the same items with each body run under [`guard`] (`Type.name` or `name` as what was being
/// done), every return type made a `PyResult` (a `Res<T>` converted, a plain `T` wrapped), and
/// the names listed in `Type::GUARDED` or `LIST`.
macro_rules! guarded {
    ($(#[$($a:tt)*])* impl $ty:ident { $($items:tt)* }) => {
        guarded!(@munch [impl $ty; $(#[$($a)*])*] [] [] $($items)*);
    };
    (fns $list:ident; $($items:tt)*) => {
        guarded!(@munch [fns $list] [] [] $($items)*);
    };
    (@munch $head:tt [$($done:tt)*] [$($names:expr),*]
        $(#[$($m:tt)*])* $v:vis fn $name:ident $(<$($lt:lifetime),*>)? ($($args:tt)*) -> PyResult<$t:ty> { $($b:tt)* } $($rest:tt)*) => {
        guarded!(@munch $head [$($done)* $(#[$($m)*])* $v fn $name $(<$($lt),*>)? ($($args)*) -> PyResult<$t> {
            $crate::guard::guard(guarded!(@what $head $name), || -> PyResult<$t> { $($b)* })
        }] [$($names,)* stringify!($name)] $($rest)*);
    };
    (@munch $head:tt [$($done:tt)*] [$($names:expr),*]
        $(#[$($m:tt)*])* $v:vis fn $name:ident $(<$($lt:lifetime),*>)? ($($args:tt)*) -> Res<$t:ty> { $($b:tt)* } $($rest:tt)*) => {
        guarded!(@munch $head [$($done)* $(#[$($m)*])* $v fn $name $(<$($lt),*>)? ($($args)*) -> PyResult<$t> {
            $crate::guard::guard(guarded!(@what $head $name), || -> PyResult<$t> { Ok((|| -> Res<$t> { $($b)* })()?) })
        }] [$($names,)* stringify!($name)] $($rest)*);
    };
    (@munch $head:tt [$($done:tt)*] [$($names:expr),*]
        $(#[$($m:tt)*])* $v:vis fn $name:ident $(<$($lt:lifetime),*>)? ($($args:tt)*) -> $t:ty { $($b:tt)* } $($rest:tt)*) => {
        guarded!(@munch $head [$($done)* $(#[$($m)*])* $v fn $name $(<$($lt),*>)? ($($args)*) -> PyResult<$t> {
            $crate::guard::guard(guarded!(@what $head $name), || -> PyResult<$t> { Ok({ $($b)* }) })
        }] [$($names,)* stringify!($name)] $($rest)*);
    };
    (@munch $head:tt [$($done:tt)*] [$($names:expr),*]
        $(#[$($m:tt)*])* $v:vis fn $name:ident $(<$($lt:lifetime),*>)? ($($args:tt)*) { $($b:tt)* } $($rest:tt)*) => {
        guarded!(@munch $head [$($done)* $(#[$($m)*])* $v fn $name $(<$($lt),*>)? ($($args)*) -> PyResult<()> {
            $crate::guard::guard(guarded!(@what $head $name), || -> PyResult<()> { { $($b)* } Ok(()) })
        }] [$($names,)* stringify!($name)] $($rest)*);
    };
    (@munch [impl $ty:ident; $($a:tt)*] [$($done:tt)*] [$($names:expr),*]) => {
        $($a)* impl $ty { $($done)* }
        impl $ty {
            /// The names of this class's guarded entries (tests/test_load_entry_points.py).
            pub(crate) const GUARDED: &'static [&'static str] = &[$($names),*];
        }
    };
    (@munch [fns $list:ident] [$($done:tt)*] [$($names:expr),*]) => {
        $($done)*
        /// The names of these guarded functions (tests/test_load_entry_points.py).
        pub(crate) const $list: &[&str] = &[$($names),*];
    };
    (@what [impl $ty:ident; $($a:tt)*] $name:ident) => { concat!(stringify!($ty), ".", stringify!($name)) };
    (@what [fns $list:ident] $name:ident) => { stringify!($name) };
}
pub(crate) use guarded;
