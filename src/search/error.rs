//! What can go wrong in a fit (setting up its problem, the search, the intervals): [`FitError`], each
//! variant with its numbers and names.
//!
//! [`FitError::is_input`] tells the settings a user can fix (exit code 2) from a fit that failed
//! (exit code 1).

use std::sync::Arc;

/// A fit job that cannot be set up, or an optimiser run that failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// The neck/lip model without the recording's head track.
    #[error("the neck/lip model needs the recording's head track")]
    NecklipNeedsHead,
    /// `objective = "likelihood"` where the recording has no likelihood; `why` was recorded when
    /// the problem was built (e.g. a median-averaged band, whose ordinates are not χ²).
    #[error(
        "[fit] objective = \"likelihood\" needs the recording's likelihood: {why}; set objective = \"features\""
    )]
    LikelihoodObjective { why: NoLikelihood },
    /// An exploration's sample count out of range.
    #[error("--samples {samples}: expected 1 to {max} (the Sobol sequence's length per seed)")]
    Samples { samples: usize, max: usize },
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
