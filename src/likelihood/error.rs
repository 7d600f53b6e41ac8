//! What can go wrong measuring a recording (or reading a target job's targets) for the likelihood
//! and the cost: [`MeasureError`], each variant with its numbers and names; and why a measurement
//! has no head motion ([`NoHeadTrack`]). Every variant is an input error (exit code 2).

use std::path::PathBuf;

use crate::model::TrackError;

/// A recording or a target job that cannot be measured as the job asks.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeasureError {
    /// No frame rate given and none readable from the time column.
    #[error("cannot tell the recording's frame rate: give recording.import.fps_hz")]
    NoFrameRate { median_rate_hz: f64 },
    /// Frame times that are not uniform at `fs_hz`: one step is `step_s`.
    #[error(
        "the recording's frame times are not uniform at {} Hz (step {} found); resample it first",
        crate::names::significant(*fs_hz, 6),
        crate::names::quantity(*step_s, "s")
    )]
    NonUniformFrames { fs_hz: f64, step_s: f64 },
    /// The neck/lip model without the recording's head and tip tracks; `reason` is why the
    /// measurement has no head motion (recorded when it was measured).
    #[error("the neck/lip model needs the recording's head and tip tracks: {reason}")]
    NecklipNeedsTracks { reason: NoHeadTrack },
    /// A band of `[spectrum]` without a target in `[targets]`.
    #[error("[targets] gives no target for band '{band}'")]
    NoTarget { band: String },
    /// Neither a recording nor targets.
    #[error("the job gives neither [recording] nor [targets]")]
    NothingToFit,
    /// Negative weights of the time-domain terms.
    #[error("[fit.weights] freq_speed and trace must be >= 0 (got {freq_speed} and {trace})")]
    NegativeWeights { freq_speed: f64, trace: f64 },
    /// A frequency-against-speed term with no ridge point in the measurement.
    #[error(
        "[fit.weights] freq_speed: the measured {signal} has no spectrogram ridge point in {band_hz:?} Hz with SNR >= {min_snr}; nothing to fit"
    )]
    NoRidgePoint {
        signal: &'static str,
        band_hz: (f64, f64),
        min_snr: f64,
    },
    /// Frequency against tip speed on a trace without a `tip` point.
    #[error(
        "frequency against tip speed needs a tracked point with role 'tip' (map it in [recording.import.points])"
    )]
    NoTip,
}

/// Why a measurement gives the neck/lip model no prescribed head motion (kept with the
/// measurement, and reported only when a neck/lip candidate needs it).
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum NoHeadTrack {
    /// The recording has no points with the roles head and tip.
    #[error("{}: the recording has no 'head' and 'tip' points", path.display())]
    NoPoints { path: PathBuf },
    /// The head and tip tracks cannot be smoothed.
    #[error("{}: {source}", path.display())]
    Track {
        path: PathBuf,
        #[source]
        source: TrackError,
    },
    /// A target job: no recording at all.
    #[error("a target job has no recording")]
    TargetJob,
}

impl From<MeasureError> for crate::Error {
    fn from(e: MeasureError) -> Self {
        crate::Error::stage(e, true)
    }
}

impl MeasureError {
    /// The measurement's error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&MeasureError> {
        e.stage_error()
    }
}
