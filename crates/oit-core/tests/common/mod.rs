//! Helpers shared by the GPU tests and the examples.
pub mod caller;
