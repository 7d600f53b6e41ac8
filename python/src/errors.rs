//! wiperlab's errors as Python exceptions, and the guard that keeps panics out of Python.
//!
//! The exception classes live in `wiperlab/errors.py` (so that a parse error is both a
//! `wiperlab.WiperlabError` and a `ValueError`); this module picks the class for each
//! [`wiperlab::Error`] and keeps the library's message, the same text the CLI prints.

use pyo3::call::PyCallArgs;
use pyo3::exceptions::{
    PyFileNotFoundError, PyKeyboardInterrupt, PyOSError, PyPermissionError, PyValueError,
};
use pyo3::prelude::*;
use wiperlab::Error;

/// The `wiperlab.errors` class named `name`, raised with `args`.
fn raise<'py>(py: Python<'py>, name: &str, args: impl PyCallArgs<'py>) -> PyErr {
    let class = py.import("wiperlab.errors").and_then(|m| m.getattr(name));
    match class {
        Ok(class) => match class.call1(args) {
            Ok(exc) => PyErr::from_value(exc),
            Err(e) => e,
        },
        Err(e) => e,
    }
}

/// The Python exception for `e`:
///
/// * a file that does not exist: `FileNotFoundError` (errno, message, file name); one that may not
///   be read or written: `PermissionError`; another I/O failure: `OSError`;
/// * a value in a file that is not what was expected: `wiperlab.ParseError(path, line, column)`;
/// * a tracking export that cannot be imported: `wiperlab.RecordingError`;
/// * a simulation that fails numerically: `wiperlab.SimulationError`;
/// * a fit that fails: `wiperlab.FitError`;
/// * any other bad input (a file, a job, a setting, samples a spectrum cannot use):
///   `wiperlab.InputError`, a `ValueError`;
/// * an interrupt: `KeyboardInterrupt`;
/// * anything else: `wiperlab.WiperlabError`.
pub fn to_py(py: Python<'_>, e: Error) -> PyErr {
    to_py_as(py, e, "InputError")
}

/// As [`to_py`], with `input_class` (a `wiperlab.errors` class) for other bad input: a reader of
/// recordings says `RecordingError` for a file it cannot import.
pub fn to_py_as(py: Python<'_>, e: Error, input_class: &str) -> PyErr {
    let message = e.to_string();
    match &e {
        Error::Io { path, source, .. } => {
            let errno = source.raw_os_error().unwrap_or(0);
            let file = path.display().to_string();
            match source.kind() {
                std::io::ErrorKind::NotFound => {
                    PyFileNotFoundError::new_err((errno, message, file))
                }
                std::io::ErrorKind::PermissionDenied => {
                    PyPermissionError::new_err((errno, message, file))
                }
                _ => PyOSError::new_err((errno, message, file)),
            }
        }
        Error::Parse {
            path, line, column, ..
        } => raise(
            py,
            "ParseError",
            (message, path.display().to_string(), *line, *column),
        ),
        Error::Interrupted { .. } => PyKeyboardInterrupt::new_err(message),
        _ if e.stage_error::<wiperlab::import::ImportError>().is_some() => {
            raise(py, "RecordingError", (message,))
        }
        _ if e
            .stage_error::<wiperlab::simulate::SimulationError>()
            .is_some() =>
        {
            raise(py, "SimulationError", (message,))
        }
        _ if e.stage_error::<wiperlab::fit::FitError>().is_some()
            || e.stage_error::<wiperlab::job::JobError>().is_some()
            || e.stage_error::<wiperlab::likelihood::MeasureError>()
                .is_some()
            || e.stage_error::<wiperlab::likelihood::LikelihoodError>()
                .is_some() =>
        {
            raise(py, "FitError", (message,))
        }
        // A spectrum that cannot be made from the samples given (too short, a NaN) is as much a
        // bad argument as a setting out of range.
        _ if e.is_input_error()
            || e.stage_error::<wiperlab::spectrum::SpectrumError>()
                .is_some() =>
        {
            raise(py, input_class, (message,))
        }
        _ => raise(py, "WiperlabError", (message,)),
    }
}

/// `wiperlab.InputError` with `message` (a bad value the binding itself finds, e.g. in a blade's
/// parameters).
pub fn input_error(py: Python<'_>, message: impl Into<String>) -> PyErr {
    raise(py, "InputError", (message.into(),))
}

/// A bad argument of a Python call (an unknown option name, a wrong shape): `ValueError`.
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// Runs `work` without the GIL and turns its error into the matching exception, and a panic into
/// `wiperlab.WiperlabError` naming it as a bug, so that no panic reaches Python.
pub fn guard<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> wiperlab::Result<T> + Send,
{
    guard_as(py, "InputError", work)
}

/// As [`guard`], with [`to_py_as`]'s `input_class`.
pub fn guard_as<T, F>(py: Python<'_>, input_class: &str, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> wiperlab::Result<T> + Send,
{
    let outcome = py.detach(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(work)));
    match outcome {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(to_py_as(py, e, input_class)),
        Err(panic) => Err(panic_error(py, panic)),
    }
}

/// `wiperlab.WiperlabError` for a panic's payload.
pub fn panic_error(py: Python<'_>, panic: Box<dyn std::any::Any + Send>) -> PyErr {
    let what = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into());
    raise(
        py,
        "WiperlabError",
        (format!(
            "internal error in wiperlab (a bug: please report it with the call that caused it): {what}"
        ),),
    )
}
