//! One mapping from the core's `OitError` to Python exceptions: `ValueError` for bad input,
//! `FileNotFoundError`, `MemoryError` for budgets, `RuntimeError` for the device.

use pyo3::exceptions::{PyFileNotFoundError, PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::PyErr;

use oit_core::OitError;

pub(crate) struct Error(pub OitError);

impl From<OitError> for Error {
    fn from(e: OitError) -> Self {
        Self(e)
    }
}

impl From<Error> for PyErr {
    fn from(Error(e): Error) -> PyErr {
        let msg = e.to_string();
        match e {
            OitError::InvalidInput(_) => PyValueError::new_err(msg),
            OitError::NotFound(_) => PyFileNotFoundError::new_err(msg),
            OitError::OutOfMemory(_) => PyMemoryError::new_err(msg),
            OitError::NoAdapter(_) | OitError::Unsupported(_) | OitError::Device(_) => PyRuntimeError::new_err(msg),
        }
    }
}

/// A core result, converted on its way to Python.
pub(crate) type Res<T> = Result<T, Error>;
