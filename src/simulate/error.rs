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

/// Solver or simulation settings that cannot be run: the user's `[solver]` table or flags, or a
/// call the model does not support. Always an input error (exit code 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SettingError {
    /// Tolerances not positive and finite.
    #[error("solver: rtol and atol must be positive and finite (got rtol = {rtol}, atol = {atol})")]
    Tolerances { rtol: f64, atol: f64 },
    /// A relative tolerance below double precision.
    #[error("solver: rtol = {rtol} is below what double precision can deliver (use >= 1e-14)")]
    RtolBelowPrecision { rtol: f64 },
    /// A maximum step that is not positive.
    #[error("solver: h_max must be > 0 (got {h_max_s})")]
    HMax { h_max_s: f64 },
    /// A lift-off margin outside [0, 1].
    #[error("solver: lift_off_margin must be between 0 and 1 (got {margin})")]
    LiftOffMargin { margin: f64 },
    /// An empty or reversed window.
    #[error("simulation window must have t_end > t0 (got {t0_s} .. {t_end_s})")]
    Window { t0_s: f64, t_end_s: f64 },
    /// A model with more switching surfaces than the integrator tracks.
    #[error("model declares {declared} switching surfaces; at most {max} are supported")]
    SwitchingSurfaces { declared: usize, max: usize },
    /// A fixed time step that is not positive and finite.
    #[error("time step must be > 0 (got {h_s})")]
    TimeStep { h_s: f64 },
    /// The neck/lip model run without its prescribed head motion.
    #[error("the neck/lip model needs a prescribed head motion: use simulate_necklip")]
    NecklipWithoutHead,
    /// Contact forces asked of the neck/lip model, whose prescribed head is not kept.
    #[error("contact forces of the neck/lip model need its prescribed head: not available")]
    NecklipContactForces,
}

impl From<SettingError> for crate::Error {
    fn from(e: SettingError) -> Self {
        crate::Error::stage(e, true)
    }
}

impl SettingError {
    /// The simulate stage's setting error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&SettingError> {
        e.stage_error()
    }
}
