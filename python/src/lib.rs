//! `wiperlab._wiperlab`: the compiled half of the `wiperlab` Python package (PyO3 + NumPy).
//!
//! Each function converts its Python arguments, runs the wiperlab library with the GIL released
//! and converts the result back; the library does all the work. Errors become the exceptions of
//! `wiperlab.errors` ([`errors::to_py`]), and a panic inside the library becomes
//! `wiperlab.WiperlabError` instead of reaching Python ([`errors::guard`]).

use pyo3::prelude::*;

mod errors;
mod fit;
mod model;
mod recording;
mod spectrum;

/// The extension module.
#[pymodule]
fn _wiperlab(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(spectrum::welch, m)?)?;
    m.add_function(wrap_pyfunction!(spectrum::find_peaks_in_band, m)?)?;
    m.add_function(wrap_pyfunction!(recording::read_recording, m)?)?;
    m.add_function(wrap_pyfunction!(model::blade_from_toml, m)?)?;
    m.add_function(wrap_pyfunction!(model::blade_check, m)?)?;
    m.add_function(wrap_pyfunction!(model::blade_default_window, m)?)?;
    m.add_function(wrap_pyfunction!(model::modes, m)?)?;
    m.add_function(wrap_pyfunction!(model::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(check_panic_guard, m)?)?;
    Ok(())
}

/// Panics inside [`errors::guard`], as a bug in the library would: the test suite checks that
/// Python gets `wiperlab.WiperlabError` and the process goes on.
#[pyfunction]
#[pyo3(name = "_check_panic_guard")]
fn check_panic_guard(py: Python<'_>) -> PyResult<()> {
    errors::guard(py, || -> wiperlab::Result<()> {
        panic!("the panic of _check_panic_guard")
    })
}
