use pyo3::prelude::*; #[pymodule] fn _oit(_m: &Bound<PyModule>) -> PyResult<()> { Ok(()) }
