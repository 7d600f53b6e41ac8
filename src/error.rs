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
    /// An output path that is the input file itself (the input is never overwritten).
    #[error(
        "output {} is the input file {}: choose another output path (the input is never overwritten)",
        output.display(),
        input.display()
    )]
    SameFile { input: PathBuf, output: PathBuf },
    /// Values could not be written as `format` (CSV, JSON, TOML) for `target` (a file name, or
    /// where the text goes, e.g. "stdout").
    #[error("writing {format} ({target}): {source}")]
    Write {
        target: String,
        format: &'static str,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// A later stage's typed error (`spectrum::SpectrumError`, `simulate::SimulationError`, ...),
    /// kept as that type: each stage's error type gives `of(&Error)` to read it back. The error
    /// module names no later stage, so the stages depend on it and not the other way round.
    /// `input`: caused by the user's settings (exit code 2), else by the data or the numerics.
    #[error("{source}")]
    Stage {
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
        input: bool,
    },
    /// SIGINT or SIGTERM stopped the work; `written` is the interrupted result, when one was
    /// written (never over a complete result).
    #[error("interrupted{}", written.as_ref().map(|p| format!("; the best result so far is in {}", p.display())).unwrap_or_default())]
    Interrupted { written: Option<PathBuf> },
}

impl Error {
    /// True for errors caused by the user's input (files, jobs, flags): the CLI exits with code 2.
    pub fn is_input_error(&self) -> bool {
        match self {
            Error::Io { .. }
            | Error::Parse { .. }
            | Error::Input { .. }
            | Error::SameFile { .. } => true,
            Error::Stage { input, .. } => *input,
            _ => false,
        }
    }

    /// The process exit code for this error: 2 for bad input, 130 for an interrupt (128 + SIGINT),
    /// 1 for a computation that failed.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Interrupted { .. } => 130,
            e if e.is_input_error() => 2,
            _ => 1,
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

    /// A later stage's typed error `e` (see [`Error::Stage`]).
    pub fn stage<E: std::error::Error + Send + Sync + 'static>(e: E, input: bool) -> Self {
        Error::Stage {
            source: Box::new(e),
            input,
        }
    }

    /// The later stage's error of type `E` inside, if this is one.
    pub fn stage_error<E: std::error::Error + 'static>(&self) -> Option<&E> {
        match self {
            Error::Stage { source, .. } => source.downcast_ref::<E>(),
            _ => None,
        }
    }

    /// Shorthand for [`Error::Write`]: `source` failed writing `format` for `target`.
    pub fn write<E>(target: impl std::fmt::Display, format: &'static str, source: E) -> Self
    where
        E: std::error::Error + Send + Sync + 'static,
    {
        Error::Write {
            target: target.to_string(),
            format,
            source: Box::new(source),
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
