//! `wiperlab.fit`: a fit job run as `wiperlab fit` runs it, interruptible with Ctrl-C.
//!
//! The fit runs on a thread of its own while the calling thread waits without the GIL and looks
//! for signals every [`POLL`]: Python's SIGINT handler (Ctrl-C) raises `KeyboardInterrupt` there,
//! the fit is asked to stop ([`wiperlab::search::interrupt::request_stop`]) and, as on the command
//! line, writes its best-so-far result to `<name>.interrupted.result.toml` before the exception
//! reaches the caller. No signal handler of wiperlab's own is installed, so Python keeps its.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;
use wiperlab::Error;
use wiperlab::job::LoadedJob;
use wiperlab::search::interrupt;

use crate::errors::{guard, panic_error, to_py};

/// How often the waiting thread looks for signals.
const POLL: Duration = Duration::from_millis(50);

/// The claim on the process's one running fit, given up when dropped.
struct Running;

static RUNNING: AtomicBool = AtomicBool::new(false);

impl Running {
    /// The claim, or `RuntimeError` while another thread's fit runs.
    fn claim() -> PyResult<Running> {
        if RUNNING.swap(true, Ordering::SeqCst) {
            return Err(PyRuntimeError::new_err(
                "another wiperlab.fit is running in this process; fits run one at a time \
                 (a Ctrl-C stops every fit of the process)",
            ));
        }
        Ok(Running)
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        RUNNING.store(false, Ordering::SeqCst);
    }
}

/// Runs the job `job` (the docstring is `wiperlab.fit`'s); returns the result as JSON text and the
/// paths of the result file and the report directory.
#[pyfunction]
#[pyo3(signature = (job, progress=true, out_dir=None))]
pub fn fit(
    py: Python<'_>,
    job: PathBuf,
    progress: bool,
    out_dir: Option<PathBuf>,
) -> PyResult<(String, PathBuf, PathBuf)> {
    let loaded = guard(py, move || LoadedJob::load(&job))?;
    let dir = out_dir.unwrap_or_else(|| wiperlab::cli::default_fit_dir(&loaded));
    let report_dir = dir.clone();
    // One fit at a time: the stop flag is the process's.
    let _one = Running::claim()?;
    interrupt::clear_stop();
    let worker = std::thread::Builder::new()
        .name("wiperlab-fit".into())
        .spawn(move || {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                wiperlab::cli::fit_files(&loaded, &dir, progress).and_then(|(result, path)| {
                    let json = serde_json::to_string(&result)
                        .map_err(|e| Error::write("the Python package", "JSON", e))?;
                    Ok((json, path))
                })
            }))
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the fit's thread: {e}")))?;
    let mut signal: Option<PyErr> = None;
    while !worker.is_finished() {
        py.detach(|| std::thread::sleep(POLL));
        if signal.is_none()
            && let Err(e) = py.check_signals()
        {
            interrupt::request_stop();
            signal = Some(e);
        }
    }
    let outcome = worker.join();
    interrupt::clear_stop();
    let outcome = match outcome {
        Ok(Ok(r)) => r,
        Ok(Err(panic)) | Err(panic) => return Err(panic_error(py, panic)),
    };
    match (signal, outcome) {
        // Ctrl-C: KeyboardInterrupt with the command line's message (where the best result is).
        (Some(e), Err(err @ Error::Interrupted { .. }))
            if e.is_instance_of::<PyKeyboardInterrupt>(py) =>
        {
            Err(PyKeyboardInterrupt::new_err(err.to_string()))
        }
        (Some(e), _) => Err(e),
        (None, Ok((json, path))) => Ok((json, path, report_dir)),
        (None, Err(err)) => Err(to_py(py, err)),
    }
}
