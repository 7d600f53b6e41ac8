//! Why a simulation stopped: [`SimulationError`], the time, the readable state and the typed
//! cause, each carrying its numbers.

use super::hybrid::Phase;
use crate::model::stick_slip::ModelFault;

/// The cause of a stopped simulation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StopCause {
    /// The model could not be evaluated (Painlevé singularity, singular system, no equilibrium).
    #[error("{0}")]
    Model(#[from] ModelFault),
    /// The lip tip left the glass: the normal force fell to `normal_n` ≤ 0 (in `phase`, when known).
    #[error(
        "contact lost{}: normal force N fell to {normal_n:.6e} N (the model assumes the lip tip stays on the glass)",
        phase.map(|p| format!(" in {p}")).unwrap_or_default()
    )]
    ContactLost { phase: Option<Phase>, normal_n: f64 },
    /// The adaptive step fell below the resolution of the time, `h_s`, in `phase`.
    #[error("step size collapsed to {h_s:.3e} s{}", phase.map(|p| format!(" in {p}")).unwrap_or_default())]
    StepSizeCollapse { h_s: f64, phase: Option<Phase> },
    /// More steps than [`super::SolverOptions::max_steps`].
    #[error("step budget of {max_steps} steps exhausted")]
    StepBudget { max_steps: usize },
    /// More phase transitions than [`super::SolverOptions::max_transitions`].
    #[error("more than {max_transitions} transitions")]
    TooManyTransitions { max_transitions: usize },
    /// Transitions accumulate at a point (Zeno): `count` within 1e-12 s of each other.
    #[error(
        "transitions accumulate (more than {count} within 1e-12 s of each other): a Zeno point; the event-driven method cannot pass it"
    )]
    Zeno { count: usize },
    /// The neck/lip model has no segment to run on: the recorded lean stays within `guard_m` of
    /// upright over the whole window.
    #[error(
        "the recorded lean stays within {guard_m:.3e} m of upright over the whole window: nothing for the neck/lip model to run on"
    )]
    NoSegment { guard_m: f64 },
}

/// A simulation that stopped at `t_s` (simulated time, s) in `state` (a readable snapshot).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("simulation stopped at t = {t_s:.9} s: {cause} (state: {state})")]
pub struct SimulationError {
    pub t_s: f64,
    pub cause: StopCause,
    pub state: String,
}

impl SimulationError {
    /// A stop at `t_s` in `state` for `cause`.
    pub fn new(t_s: f64, cause: impl Into<StopCause>, state: impl Into<String>) -> Self {
        SimulationError {
            t_s,
            cause: cause.into(),
            state: state.into(),
        }
    }

    /// A model fault while finding the initial equilibrium at `t_s`.
    pub fn at_start(t_s: f64, fault: ModelFault) -> Self {
        SimulationError::new(t_s, fault, "initial equilibrium")
    }
}

impl From<SimulationError> for crate::Error {
    fn from(e: SimulationError) -> Self {
        crate::Error::stage(e, false)
    }
}

impl SimulationError {
    /// The simulate stage's error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&SimulationError> {
        e.stage_error()
    }
}
