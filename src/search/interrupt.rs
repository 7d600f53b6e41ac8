//! Stopping a fit on SIGINT or SIGTERM: the signal sets a flag; the cost function then refuses to
//! simulate (argmin ends the running search with an error), the search keeps the best point its
//! observer saw, and the fit assembles what it has, marked interrupted.

use std::sync::atomic::{AtomicBool, Ordering};

static STOP: AtomicBool = AtomicBool::new(false);

/// Asks every running fit to stop as soon as it can.
pub fn request_stop() {
    STOP.store(true, Ordering::SeqCst);
}

/// Withdraws a stop request, so that the next fit in the same process runs (the Python package
/// calls it before each fit; the command line runs one fit per process and never needs it).
pub fn clear_stop() {
    STOP.store(false, Ordering::SeqCst);
}

/// Whether a stop was requested.
pub fn stop_requested() -> bool {
    STOP.load(Ordering::Relaxed)
}

/// Routes SIGINT and SIGTERM (Ctrl-C, `kill`) to [`request_stop`]. Installing it twice is harmless.
///
/// # Errors
/// [`super::FitError::SignalHandler`] when the handler cannot be installed.
pub fn install_signal_handler() -> crate::Result<()> {
    match ctrlc::set_handler(request_stop) {
        Ok(()) | Err(ctrlc::Error::MultipleHandlers) => Ok(()),
        Err(e) => Err(super::FitError::SignalHandler(e).into()),
    }
}
