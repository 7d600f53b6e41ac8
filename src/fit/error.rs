//! What can go wrong in the fit stage: [`FitError`], each variant with its numbers and names.
//!
//! [`FitError::is_input`] tells the settings a user can fix (exit code 2) from a fit that failed
//! (exit code 1).

use std::path::PathBuf;
use std::sync::Arc;

use crate::model::TrackError;

/// A fit job that cannot be set up, or an optimiser run that failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
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
    /// The neck/lip model without the recording's head track.
    #[error("the neck/lip model needs the recording's head track")]
    NecklipNeedsHead,
    /// A band of `[spectrum]` without a target in `[targets]`.
    #[error("[targets] gives no target for band '{band}'")]
    NoTarget { band: String },
    /// Neither a recording nor targets.
    #[error("the job gives neither [recording] nor [targets]")]
    NothingToFit,
    /// The shoulder candidate without its bounds.
    #[error("the shoulder candidate needs [fit.shoulder] bounds")]
    ShoulderBounds,
    /// `objective = "likelihood"` where the recording has no likelihood; `why` was recorded when
    /// the problem was built (e.g. a median-averaged band, whose ordinates are not χ²).
    #[error(
        "[fit] objective = \"likelihood\" needs the recording's likelihood: {why}; set objective = \"features\""
    )]
    LikelihoodObjective { why: NoLikelihood },
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
    /// An exploration's sample count out of range.
    #[error("--samples {samples}: expected 1 to {max} (the Sobol sequence's length per seed)")]
    Samples { samples: usize, max: usize },
    /// `init`: a value that cannot be written as TOML.
    #[error("init: cannot write a TOML value: {0}")]
    TomlValue(#[source] toml::ser::Error),
    /// `init`: a recording path that is not UTF-8 (a job file is UTF-8).
    #[error("init: the recording's path is not UTF-8")]
    PathNotUtf8 { path: std::path::PathBuf },
    /// `init`: the job template does not render.
    #[error("init: the job template does not render: {0}")]
    Template(#[source] minijinja::Error),
    /// The SIGINT/SIGTERM handler cannot be installed.
    #[error("cannot install the interrupt handler: {0}")]
    SignalHandler(#[source] ctrlc::Error),
    /// The optimiser (argmin) failed.
    #[error("fit failed: {0}")]
    Optimiser(argmin::core::Error),
    /// Interrupted before any optimiser iteration finished: no point to report.
    #[error("fit failed: interrupted before the first iteration")]
    InterruptedEarly,
    /// No optimiser run at all (no restarts).
    #[error("fit failed: no optimiser run")]
    NoRun,
    /// A nested candidate's local search without a single start point.
    #[error("fit failed: no start for the nested search")]
    NoNestedStart,
    /// The particle swarm finished without a best particle.
    #[error("fit failed: particle swarm returned no particle")]
    NoParticle,
    /// The bootstrap cannot estimate the measurement noise of recording `label` (empty: the only
    /// one) from the noise floor `floor` (PSD units).
    #[error(
        "fit failed: bootstrap: cannot estimate the measurement noise{} (floor {floor:e}); no intervals",
        if label.is_empty() { String::new() } else { format!(" of recording '{label}'") }
    )]
    NoNoise { label: String, floor: f64 },
    /// The bootstrap's noise distribution cannot be built for standard deviation `sigma`.
    #[error("fit failed: noise N(0, {sigma:e}): {source}")]
    NoiseDistribution {
        sigma: f64,
        #[source]
        source: rand_distr::NormalError,
    },
    /// A Laplace interval where the recording has no likelihood (`why`, as recorded).
    #[error("fit failed: no likelihood: {why}")]
    NoLikelihood { why: NoLikelihood },
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

/// Why a problem has no recording likelihood (kept with the problem; an error only where the
/// likelihood is needed).
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum NoLikelihood {
    /// The problem is being built; its likelihood comes next.
    #[error("not built yet")]
    NotBuilt,
    /// A target job compares peaks with target ranges: there is no measurement noise.
    #[error("a target job has no measurement noise")]
    TargetJob,
    /// The recording's likelihood could not be computed.
    #[error(transparent)]
    Recording(Arc<crate::Error>),
}

/// Why a fitted candidate has no likelihood at its optimum (then its spread comes from the cost's
/// curvature).
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum NoEvidence {
    /// The fit was interrupted before the optimum's likelihood was read.
    #[error("interrupted")]
    Interrupted,
    /// The likelihood at the optimum (or its settling) failed, e.g. a target job's.
    #[error(transparent)]
    Failed(Arc<crate::Error>),
}

impl FitError {
    /// True for errors in the job, the flags or the recording's tracks (exit code 2); false for a
    /// fit that failed.
    pub fn is_input(&self) -> bool {
        !matches!(
            self,
            FitError::Optimiser(_)
                | FitError::InterruptedEarly
                | FitError::NoRun
                | FitError::NoParticle
                | FitError::NoNestedStart
                | FitError::NoNoise { .. }
                | FitError::NoiseDistribution { .. }
                | FitError::NoLikelihood { .. }
        )
    }
}

impl From<FitError> for crate::Error {
    fn from(e: FitError) -> Self {
        let input = e.is_input();
        crate::Error::stage(e, input)
    }
}

impl FitError {
    /// The fit stage's error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&FitError> {
        e.stage_error()
    }
}
