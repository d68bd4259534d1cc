//! Typed errors of the engine; the Python layer maps each kind to one exception once.

/// Every failure the engine reports. Messages say what went wrong and what to do.
#[derive(Debug, thiserror::Error)]
pub enum OitError {
    /// Bad input from the caller (maps to `ValueError`).
    #[error("{0}")]
    InvalidInput(String),
    /// No usable GPU adapter (maps to `RuntimeError`).
    #[error("{0}")]
    NoAdapter(String),
    /// The adapter lacks a feature or limit the method needs (maps to `RuntimeError`).
    #[error("{0}")]
    Unsupported(String),
    /// A budget or device limit is exceeded (maps to `MemoryError`).
    #[error("{0}")]
    OutOfMemory(String),
    /// The device failed during work (maps to `RuntimeError`).
    #[error("{0}")]
    Device(String),
    /// A file, or one that a file refers to, is not there (maps to `FileNotFoundError`).
    #[error("{0}")]
    NotFound(String),
}

pub type Result<T> = std::result::Result<T, OitError>;

/// Shorthand for an [`OitError::InvalidInput`] with a formatted message.
macro_rules! invalid {
    ($($arg:tt)*) => { $crate::error::OitError::InvalidInput(format!($($arg)*)) };
}
pub(crate) use invalid;
