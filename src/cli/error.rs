//! What can go wrong with the command line itself: [`CliError`], naming the flag as typed.

use crate::model::modes::ModesError;
use crate::names::significant;
use crate::spectrum::SpectrumError;
use std::path::PathBuf;

/// A flag the command cannot use, or a command-level failure. Input errors (exit code 2) unless
/// [`CliError::is_input`] says otherwise.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CliError {
    /// A list flag with the wrong number of values.
    #[error("{flag}: expected {expected} (got {got} values)")]
    ValueCount {
        flag: &'static str,
        expected: &'static str,
        got: usize,
    },
    /// `--window T0,T1` not ordered or not finite.
    #[error(
        "--window {},{}: expected T0 < T1, both finite, in s",
        significant(*t0_s, 6),
        significant(*t1_s, 6)
    )]
    Window { t0_s: f64, t1_s: f64 },
    /// A rate that must be positive and finite.
    #[error("{flag} must be > 0 (got {})", significant(*value, 6))]
    NotPositive { flag: &'static str, value: f64 },
    /// A tolerance that must be positive and finite.
    #[error("{flag} {}: expected a positive, finite tolerance", significant(*value, 6))]
    Tolerance { flag: &'static str, value: f64 },
    /// Welch settings given by `--noverlap`/`--nfft` that do not fit the segment.
    #[error("Welch settings (--noverlap, --nfft): {0}")]
    Welch(SpectrumError),
    /// A `--signal` that names no point (pair) of the trace; `reason` lists the trace's points
    /// (from [`crate::spectrum::SignalExpr::resolve`]).
    #[error("--signal {given}: {reason}")]
    Signal {
        given: String,
        reason: crate::spectrum::signal::SignalError,
    },
    /// `--nperseg` outside 8 ..= the record's samples.
    #[error("--nperseg {nperseg}: expected 8 <= nperseg <= the record's {samples} samples")]
    Nperseg { nperseg: usize, samples: usize },
    /// A `--band` (as typed) outside [0, Nyquist] or empty; `fs_hz` is the record's sample rate.
    #[error(
        "--band {text}: expected 0 <= LO < HI <= {} Hz (the Nyquist frequency, half the {} Hz \
         sample rate)",
        significant(fs_hz / 2.0, 6),
        significant(*fs_hz, 6)
    )]
    Band { text: String, fs_hz: f64 },
    /// A `--band HI:LO` (as typed) whose ends are swapped; `swapped` is it the right way round.
    #[error("--band {text}: LO and HI are swapped: did you mean --band {swapped}?")]
    BandSwapped { text: String, swapped: String },
    /// `init -o` naming an existing file.
    #[error("-o {}: the file exists; init never overwrites a job (choose another -o)", path.display())]
    OutputExists { path: PathBuf },
    /// `campaign task --index` past the campaign's recordings.
    #[error("campaign task: --index {index} is beyond the campaign's {count} recordings")]
    IndexBeyond { index: usize, count: usize },
    /// Some of a campaign's recordings failed (exit code 1).
    #[error(
        "fit failed: {failed} of {total} recordings failed (the others' results are written; reasons above and in `campaign collect`)"
    )]
    RecordingsFailed { failed: usize, total: usize },
    /// The running executable's path is unknown (the Slurm script calls it).
    #[error("campaign slurm: cannot find this executable: {0}")]
    CurrentExe(#[source] std::io::Error),
    /// `--speeds` outside what the blade can reach.
    #[error("--speeds: {0}")]
    Speeds(ModesError),
    /// The modes of the blade in `path` cannot be computed (exit code 1).
    #[error("{}: {source}", path.display())]
    Modes {
        path: PathBuf,
        #[source]
        source: ModesError,
    },
    /// `bench --blade` with no file.
    #[error("bench: --blade needs at least one file")]
    NoBladeFile,
}

impl CliError {
    /// True for errors in the flags (exit code 2); false for work that failed.
    pub fn is_input(&self) -> bool {
        !matches!(
            self,
            CliError::RecordingsFailed { .. } | CliError::Modes { .. }
        )
    }
}

impl From<CliError> for crate::Error {
    fn from(e: CliError) -> Self {
        let input = e.is_input();
        crate::Error::stage(e, input)
    }
}
