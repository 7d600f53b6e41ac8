//! The crate's error type.
//!
//! Every error that comes from bad *input* (a file, a job, a command-line value) names the file and,
//! where there is one, the line, column and field, and what was expected. The CLI maps those to exit
//! code 2 ([`Error::is_input_error`]); numerical failures (a simulation that loses contact, a singular
//! slip system) exit with 1 and name the time and state.

use std::path::{Path, PathBuf};

/// Result alias used across wiperlab.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in wiperlab.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be opened, read or written.
    #[error("{}: {action}: {source}", path.display())]
    Io {
        path: PathBuf,
        action: &'static str,
        #[source]
        source: std::io::Error,
    },
    /// A value in a file is not what was expected. `line` and `column` are 1-based; `column` 0 means
    /// the whole line.
    #[error("{}:{line}:{column}: {message}", path.display())]
    Parse {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    /// A file as a whole is not usable (unknown format, no data rows, a required point missing).
    #[error("{}: {message}", path.display())]
    Input { path: PathBuf, message: String },
    /// A setting (command-line flag or job field) is out of range or inconsistent.
    #[error("{0}")]
    Config(String),
    /// The simulation could not continue: the simulated time, a readable snapshot of the state and
    /// the typed cause.
    #[error(transparent)]
    Simulation(#[from] crate::simulate::SimulationError),
    /// A spectral estimate could not be made (settings or samples), with its numbers.
    #[error(transparent)]
    Spectrum(#[from] crate::spectrum::SpectrumError),
    /// A numerical routine was given data it cannot work on (too short a record, all NaN, ...).
    #[error("{0}")]
    Numerics(String),
    /// The optimiser failed.
    #[error("fit failed: {0}")]
    Fit(String),
}

impl Error {
    /// True for errors caused by the user's input (files, jobs, flags): the CLI exits with code 2.
    pub fn is_input_error(&self) -> bool {
        match self {
            Error::Io { .. } | Error::Parse { .. } | Error::Input { .. } | Error::Config(_) => true,
            Error::Spectrum(e) => e.is_setting(),
            _ => false,
        }
    }

    /// Shorthand for [`Error::Parse`].
    pub fn parse(path: &Path, line: usize, column: usize, message: impl Into<String>) -> Self {
        Error::Parse {
            path: path.to_path_buf(),
            line,
            column,
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::Input`].
    pub fn input(path: &Path, message: impl Into<String>) -> Self {
        Error::Input {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::Io`].
    pub fn io(path: &Path, action: &'static str, source: std::io::Error) -> Self {
        Error::Io {
            path: path.to_path_buf(),
            action,
            source,
        }
    }
}
