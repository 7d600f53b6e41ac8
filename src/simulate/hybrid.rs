//! Event-driven integration of a one-contact stick–slip system.
//!
//! Each smooth phase (slip+, slip−, stick) is integrated with DOPRI5 or DOP853 ([`super::method`],
//! [`SolverOptions::method`]). Transitions are zeros of smooth event functions located on the step's continuous extension by the Illinois method to
//! a bracket of a few ulps (physics.md §1.5–1.6, "how the transition time is located exactly"):
//!
//! | phase   | event function            | becomes zero when                      | next phase            |
//! |---------|---------------------------|----------------------------------------|-----------------------|
//! | slip s  | `s·v_rel`                 | the contact stops slipping             | stick, or slip −s if \|f_stick\| > μ_s·N |
//! | stick   | `μ_s·N − f`, `μ_s·N + f`  | static friction reaches its limit (seed eq. 5) | slip −sign(f) |
//! | any     | `N`                       | the contact lifts off                  | error (the model assumes contact) |
//!
//! `v_rel` is the slip velocity of the contact, `f` the friction force on it along +x, `N` the normal
//! force. An event fires on a change from `g > 0` to `g ≤ 0`; besides both ends of a step, `g` is also
//! sampled at interior points of the step (DifferentialEquations.jl's `interp_points`); when the samples
//! of a function have an interior minimum above zero, a golden-section search on the continuous
//! extension looks for a dip below zero between them (across the boundary with the previous step when
//! the minimum sample is there), so a function that dips across zero and back within one step is not
//! missed. The search resolves the minimum's position to 1e-3 of two sample intervals, so a dip
//! narrower than that can still escape. Right after a transition the new
//! phase's event function may start at exactly 0 (a tangential stick→slip departure, physics.md §1.8);
//! it is armed by the first strictly positive value, and if its first sample is already negative the
//! sub-interval is searched for a positive maximum (a departure and a return within one sub-step).
//!
//! In slip, the slip velocity and the switching functions are functions of the state alone: the
//! interior samples and the searches read them from the interpolated state without solving for
//! the contact forces ([`Stats::kinematic_evals`]), bitwise the values the solve gives. The normal
//! force needs the solve, and only its sign matters (lift-off ends the run), so it is sampled inside
//! a step only when the step is not clear of zero: when some right-hand-side evaluation of the step
//! (every stage, the end and the start) or of the step before gave `N ≤ lift_off_margin · N_max`,
//! `N_max` the largest of them ([`SolverOptions::lift_off_margin`], 0.5 by default). Such a step
//! and the one after it sample and search `N` exactly as every step does with
//! `lift_off_margin = 1` (the step before it gives its last interior sample, solved, to the
//! boundary's minimum test). In a clear step, the samples could only have caught a dip of `N`
//! through zero that none of the step's 7 (DOPRI5) or 16 (DOP853) evaluations, at most half
//! (DOPRI5) or 0.27 (DOP853) of the step apart, comes within half its size of: a swing of the
//! force on a time scale the step does not resolve. A dip that the stages see is found as before.

use super::error::{SettingError, SimulationError, StopCause};
use super::method::{Dense, Method, Outcome, Step};
use crate::{Error, Result};

use serde::Serialize;
use std::cell::Cell;

pub use crate::model::stick_slip::{
    Contact, MAX_SWITCHING_SURFACES, Mode, ModelFault, Phase, StickSlipModel, region_of,
};

/// Settings of the event-driven integrator.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverOptions {
    /// Relative tolerance of the local error test.
    pub rtol: f64,
    /// Absolute tolerance of the local error test (in the state's units).
    pub atol: f64,
    /// Largest step, s.
    pub h_max: f64,
    /// Interior points per step at which event functions are sampled (0 = ends only).
    pub event_samples: usize,
    /// In slip, the normal force (the lift-off event) is sampled at the interior points only in a
    /// step where it came within this fraction of its size: some right-hand-side evaluation of the
    /// step or of the step before gave `N ≤ lift_off_margin · N_max`, `N_max` the largest `N` of
    /// those evaluations (0 to 1; 1 samples it in every step).
    pub lift_off_margin: f64,
    /// Largest number of accepted steps before giving up.
    pub max_steps: usize,
    /// Largest number of transitions before giving up (accumulation guard).
    pub max_transitions: usize,
    /// The Runge–Kutta pair of the smooth phases (`"dopri5"` or `"dop853"`).
    pub method: Method,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            rtol: 1e-10,
            atol: 1e-12,
            h_max: f64::INFINITY,
            event_samples: 3,
            lift_off_margin: 0.5,
            max_steps: 20_000_000,
            max_transitions: 1_000_000,
            method: Method::Dopri5,
        }
    }
}

impl SolverOptions {
    /// Checks ranges: tolerances positive and finite, `h_max > 0`.
    pub fn validate(&self) -> Result<()> {
        if !(self.rtol > 0.0 && self.rtol.is_finite() && self.atol > 0.0 && self.atol.is_finite()) {
            return Err(SettingError::Tolerances {
                rtol: self.rtol,
                atol: self.atol,
            }
            .into());
        }
        if self.rtol < 1e-14 {
            let rtol = self.rtol;
            return Err(SettingError::RtolBelowPrecision { rtol }.into());
        }
        if self.h_max.is_nan() || self.h_max <= 0.0 {
            let h_max_s = self.h_max;
            return Err(SettingError::HMax { h_max_s }.into());
        }
        if !(0.0..=1.0).contains(&self.lift_off_margin) {
            let margin = self.lift_off_margin;
            return Err(SettingError::LiftOffMargin { margin }.into());
        }
        Ok(())
    }
}

/// One located transition.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Transition {
    pub t_s: f64,
    pub from: Phase,
    pub to: Phase,
}

/// Counters of one run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Stats {
    pub steps: usize,
    pub rejected: usize,
    pub rhs_evals: usize,
    /// Event-function evaluations that solve for the contact forces, outside the steps' stages:
    /// phase starts, a step's end when its last stage was elsewhere, interior samples in stick and
    /// where the normal force is sampled in slip, the dip search and refinement of a force event,
    /// and the choice of phase after a transition.
    pub event_evals: usize,
    /// Event-function evaluations in slip from the state alone (the slip velocity and the
    /// switching functions, no contact solve): interior samples, dip searches and refinements.
    pub kinematic_evals: usize,
}

/// One crossing of a switching surface (no change of phase).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Switch {
    pub t_s: f64,
    /// Index of the surface.
    pub surface: usize,
    /// True when the switching function became positive (the region bit was set).
    pub entered: bool,
}

/// Output of [`integrate`]: the state at each requested time, the transitions and the counters.
#[derive(Debug, Clone)]
pub struct Run<const N: usize> {
    pub t_s: Vec<f64>,
    pub y: Vec<[f64; N]>,
    pub phase: Vec<Phase>,
    /// The mode at each requested time: its phase with the stick anchor and the switching region,
    /// what [`StickSlipModel::rhs`] needs to give the contact forces there.
    pub modes: Vec<Mode>,
    pub transitions: Vec<Transition>,
    /// State just after each transition (consistent with the new phase).
    pub transition_states: Vec<[f64; N]>,
    /// Crossings of the model's switching surfaces, in time order.
    pub switches: Vec<Switch>,
    pub stats: Stats,
    /// State and mode at the end time.
    pub y_end: [f64; N],
    pub mode_end: Mode,
}

const NO_EVENT: f64 = f64::INFINITY;

/// Number of event functions: three of the phase, then one per switching surface.
const N_EVENTS: usize = 3 + MAX_SWITCHING_SURFACES;

/// Event-function values in `mode` (`[g0, g1, g2, s0, s1]`, unused = +∞) and the contact forces.
/// `s_i` is switching function `i` signed so that it is positive inside the current region.
fn event_values<M: StickSlipModel<N>, const N: usize>(
    model: &M,
    mode: &Mode,
    t: f64,
    y: &[f64; N],
) -> std::result::Result<([f64; N_EVENTS], Contact), ModelFault> {
    let mut yc = *y;
    model.complete(mode, t, &mut yc)?;
    let mut dy = [0.0; N];
    let c = model.rhs(mode, t, &yc, &mut dy)?;
    Ok((event_values_of(model, mode, t, &yc, c), c))
}

/// The event functions at `(t, yc)` (a state consistent with `mode`) from the contact `c` the
/// right-hand side computed there.
fn event_values_of<M: StickSlipModel<N>, const N: usize>(
    model: &M,
    mode: &Mode,
    t: f64,
    yc: &[f64; N],
    c: Contact,
) -> [f64; N_EVENTS] {
    let mut g = [NO_EVENT; N_EVENTS];
    match mode.phase.slip_dir() {
        Some(s) => {
            g[0] = s * c
                .slip_velocity
                .unwrap_or_else(|| model.slip_velocity(t, yc));
            g[2] = c.normal;
        }
        None => {
            g[0] = c.limit - c.friction;
            g[1] = c.limit + c.friction;
            g[2] = c.normal;
        }
    }
    switching_values(model, mode, t, yc, &mut g);
    g
}

/// The switching functions at `(t, yc)` into `g[3..]`, each signed so that leaving `mode`'s region
/// makes it negative.
fn switching_values<M: StickSlipModel<N>, const N: usize>(
    model: &M,
    mode: &Mode,
    t: f64,
    yc: &[f64; N],
    g: &mut [f64; N_EVENTS],
) {
    for i in 0..model.switching_surfaces().min(MAX_SWITCHING_SURFACES) {
        let si = model.switching_function(i, t, yc);
        g[3 + i] = if mode.region & (1 << i) != 0 { si } else { -si };
    }
}

/// The event functions of a slip `mode` that the state alone gives, at `(t, y)` (made consistent
/// with `mode` first): `g0 = s·v_rel` and the switching functions, bitwise as [`event_values`] gives
/// them; `g2` (the normal force, which needs the contact solve) is NaN: not sampled.
fn kinematic_event_values<M: StickSlipModel<N>, const N: usize>(
    model: &M,
    mode: &Mode,
    s: f64,
    t: f64,
    y: &[f64; N],
) -> std::result::Result<[f64; N_EVENTS], ModelFault> {
    let mut yc = *y;
    model.complete(mode, t, &mut yc)?;
    let mut g = [NO_EVENT; N_EVENTS];
    g[0] = s * model.slip_velocity(t, &yc);
    g[2] = f64::NAN;
    switching_values(model, mode, t, &yc, &mut g);
    Ok(g)
}

/// Whether a step of a slip phase leaves its normal force clear of zero: the smallest `N` of its
/// right-hand-side evaluations and of its two ends, `n_min`, is positive and above `margin` times the
/// largest, `n_max` (NaN is never clear). The interior samples then skip `N`: to be caught by
/// them, `N` would have to fall from above `margin · n_max` to zero and come back between two of
/// those evaluations, a swing larger than everything the step's own stages show.
fn normal_clear(n_min: f64, n_max: f64, margin: f64) -> bool {
    n_min > 0.0 && n_min > margin * n_max
}

/// The smaller of `a` and `b`, NaN when either is (`f64::min` would drop the NaN).
fn min_or_nan(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.min(b)
    }
}

/// Minimum of `g` on `[a, b]` by golden-section search (Kiefer 1953), stopping as soon as a value
/// `<= 0` is seen (that is all the caller needs: a sign change) or the bracket has shrunk to 1e-3 of
/// its start or to a few ulps of `t` (on a bracket of ~1e-13 s at t ≈ 2 s, 1e-3 of it is below the
/// spacing of doubles and the search would never end). Returns `(t_min, g_min, evaluations)`.
fn golden_extremum<F: FnMut(f64) -> std::result::Result<f64, ModelFault>>(
    mut g: F,
    a: f64,
    b: f64,
) -> std::result::Result<(f64, f64, usize), ModelFault> {
    const R: f64 = 0.618_033_988_749_894_8; // (√5 − 1)/2
    let (mut lo, mut hi) = (a, b);
    let mut x1 = hi - R * (hi - lo);
    let mut x2 = lo + R * (hi - lo);
    let mut f1 = g(x1)?;
    let mut f2 = g(x2)?;
    let mut n = 2;
    let width_min = (1e-3 * (b - a)).max(16.0 * f64::EPSILON * a.abs().max(b.abs()));
    while f1 > 0.0 && f2 > 0.0 && (hi - lo) > width_min && n < 100 {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - R * (hi - lo);
            f1 = g(x1)?;
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + R * (hi - lo);
            f2 = g(x2)?;
        }
        n += 1;
    }
    Ok(if f1 <= f2 { (x1, f1, n) } else { (x2, f2, n) })
}

/// Locates a zero of `g` in `[a, b]` with `g(a) > 0 ≥ g(b)` by the Illinois variant of regula falsi
/// (Dowell & Jarratt, BIT 11 (1971) 168; the method of SUNDIALS CVODE's root finder), with a bisection
/// whenever the bracket fails to halve in three iterations. Returns the right end of the final bracket
/// (where `g ≤ 0`), so that the event has happened at the returned time; the bracket is closed to a
/// few ulps of `t`.
fn illinois_right<F: FnMut(f64) -> std::result::Result<f64, ModelFault>>(
    mut g: F,
    mut a: f64,
    mut b: f64,
    mut fa: f64,
    mut fb: f64,
) -> std::result::Result<f64, ModelFault> {
    let mut side = 0i8;
    let mut width_3_ago = (b - a).abs();
    for it in 0..300 {
        let width = (b - a).abs();
        if width <= 4.0 * f64::EPSILON * a.abs().max(b.abs()) || fb == 0.0 {
            return Ok(b);
        }
        let mut c = if it % 3 == 2 && width > 0.5 * width_3_ago {
            0.5 * (a + b)
        } else {
            (a * fb - b * fa) / (fb - fa)
        };
        if it % 3 == 2 {
            width_3_ago = width;
        }
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        if !(c > lo && c < hi) {
            c = 0.5 * (a + b);
        }
        let fc = g(c)?;
        if fc > 0.0 {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    Ok(b)
}

/// An event of the one-contact system, located on a step's continuous extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    /// In slip: the slip velocity reached zero (the contact may stick or reverse).
    SlipEnds,
    /// In stick: friction reached its static limit, `function` 0 for `μ_s·N − f`, 1 for
    /// `μ_s·N + f` (seed eq. 5).
    StaticLimit { function: usize },
    /// The normal force reached zero (the contact lifts off; always ends the run with an error).
    LiftOff,
    /// Switching surface `index` of the model was crossed (same phase, other branch).
    Surface { index: usize },
}

impl Event {
    /// The event of event function `k` in a phase that is slip (`slipping`) or stick.
    fn of_function(k: usize, slipping: bool) -> Event {
        match k {
            0 if slipping => Event::SlipEnds,
            0 | 1 => Event::StaticLimit { function: k },
            2 => Event::LiftOff,
            i => Event::Surface { index: i - 3 },
        }
    }

    /// The index of the event function.
    fn function(self) -> usize {
        match self {
            Event::SlipEnds => 0,
            Event::StaticLimit { function } => function,
            Event::LiftOff => 2,
            Event::Surface { index } => 3 + index,
        }
    }
}

/// Why [`HybridSolver::step`] returned (after diffsol's `OdeSolverStopReason`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum StopReason {
    /// An accepted step of the current phase ended at `t_s`, with no event in it.
    InternalStep { t_s: f64 },
    /// `event` was located at `t_s` and handled: the phase (or the region) changes there.
    Event { t_s: f64, event: Event },
    /// The stop time `t_s` was reached.
    StopTime { t_s: f64 },
}

/// One accepted step as the outputs see it: its continuous extension on `[t0, t1]` in `mode`;
/// `y1` is the step's exact end state when it ended without an event at `t1`.
struct Segment<const N: usize> {
    t1: f64,
    dense: Dense<N>,
    y1: Option<[f64; N]>,
    mode: Mode,
}

/// The event-driven integrator, one step at a time: [`HybridSolver::step`] advances to the next
/// accepted step, located event or the stop time and says which ([`StopReason`]). The state at
/// any time up to [`HybridSolver::settled_s`] is final (a later step can locate an event no earlier
/// than that, see the module docs on the dip search) and is read with
/// [`HybridSolver::state_at`].
pub struct HybridSolver<'m, M: StickSlipModel<N>, const N: usize> {
    model: &'m M,
    opts: SolverOptions,
    t_end: f64,
    span: f64,
    t: f64,
    y: [f64; N],
    mode: Mode,
    h: f64,
    /// Set after an event: the next step starts a phase (derivative and event values anew).
    phase_start: bool,
    /// The last attempt was rejected (the next accepted step does not grow the step size).
    rejected_last: bool,
    f: [f64; N],
    g_prev: [f64; N_EVENTS],
    /// The previous accepted step of this phase: its continuous extension and its last interior
    /// event sample, so that a minimum of the samples at a step boundary is searched too.
    prev: Option<(Dense<N>, f64, [f64; N_EVENTS])>,
    /// The last right-hand-side call of the last attempt: its time, state and contact. When it
    /// was at the accepted step's end (the FSAL stage), the event functions there read its contact
    /// instead of solving the model again (bitwise the same values).
    last_rhs: Option<(f64, [f64; N], Contact)>,
    /// The smallest and largest normal force of the last attempt's right-hand-side calls (NaN
    /// when one was not a number).
    stage_normal: (f64, f64),
    /// The previous accepted step of this phase left its normal force clear of zero
    /// ([`normal_clear`]), and sampled only the kinematic event functions inside.
    prev_normal_clear: bool,
    settled: f64,
    segments: Vec<Segment<N>>,
    quick_transitions: usize,
    last_transition_t: f64,
    /// Transitions, the states just after them, switching-surface crossings and counters so far.
    pub transitions: Vec<Transition>,
    pub transition_states: Vec<[f64; N]>,
    pub switches: Vec<Switch>,
    pub stats: Stats,
}

impl<'m, M: StickSlipModel<N>, const N: usize> HybridSolver<'m, M, N> {
    /// A solver at `(t0, y0)` in `mode0` (made consistent with it) that will stop at `t_end`.
    ///
    /// # Errors
    /// [`SettingError`] for invalid options or `t_end ≤ t0`; a simulation error when `y0` cannot
    /// be made consistent with `mode0`.
    pub fn new(
        model: &'m M,
        t0: f64,
        y0: [f64; N],
        mode0: Mode,
        t_end: f64,
        opts: &SolverOptions,
    ) -> Result<Self> {
        opts.validate()?;
        if t_end <= t0 {
            let (t0_s, t_end_s) = (t0, t_end);
            return Err(SettingError::Window { t0_s, t_end_s }.into());
        }
        if model.switching_surfaces() > MAX_SWITCHING_SURFACES {
            return Err(SettingError::SwitchingSurfaces {
                declared: model.switching_surfaces(),
                max: MAX_SWITCHING_SURFACES,
            }
            .into());
        }
        let mut y = y0;
        let mut mode = mode0;
        model
            .complete(&mode, t0, &mut y)
            .map_err(|e| SimulationError::new(t0, e, model.describe(t0, &y)))?;
        mode.region = region_of(model, t0, &y);
        let span = t_end - t0;
        Ok(HybridSolver {
            model,
            opts: *opts,
            t_end,
            span,
            t: t0,
            y,
            mode,
            h: (1e-6 * span).min(opts.h_max),
            phase_start: true,
            rejected_last: false,
            f: [0.0; N],
            g_prev: [NO_EVENT; N_EVENTS],
            prev: None,
            last_rhs: None,
            stage_normal: (f64::NAN, f64::NAN),
            prev_normal_clear: false,
            settled: t0,
            segments: Vec::new(),
            quick_transitions: 0,
            last_transition_t: f64::NEG_INFINITY,
            transitions: Vec::new(),
            transition_states: Vec::new(),
            switches: Vec::new(),
            stats: Stats::default(),
        })
    }

    /// Current time, state and mode (at the end of the last step or at the last event).
    pub fn current(&self) -> (f64, [f64; N], Mode) {
        (self.t, self.y, self.mode)
    }

    /// Up to this time the solution is final: no later step can place an event before it.
    pub fn settled_s(&self) -> f64 {
        self.settled
    }

    /// The state at `t` and the phase there, made consistent with that phase. `t` lies between
    /// the settled time before the last [`HybridSolver::step`] and [`HybridSolver::settled_s`], and
    /// does not go back before an earlier read: read every time you need after each step.
    ///
    /// # Errors
    /// The model's fault when the state cannot be completed (see [`StickSlipModel::complete`]).
    pub fn state_at(&mut self, t: f64) -> Result<([f64; N], Phase)> {
        self.state_and_mode_at(t).map(|(y, mode)| (y, mode.phase))
    }

    /// [`HybridSolver::state_at`] with the whole mode there (phase, stick anchor, region).
    ///
    /// # Errors
    /// As [`HybridSolver::state_at`].
    pub fn state_and_mode_at(&mut self, t: f64) -> Result<([f64; N], Mode)> {
        while self.segments.len() > 1 && self.segments[0].t1 < t {
            self.segments.remove(0);
        }
        let (mut y, mode) = match self.segments.first() {
            Some(s) if t <= s.t1 => (
                match s.y1 {
                    Some(y1) if t == s.t1 => y1,
                    _ => s.dense.eval(t),
                },
                s.mode,
            ),
            _ => (self.y, self.mode),
        };
        self.model
            .complete(&mode, t, &mut y)
            .map_err(|e| self.fail(t, &y, e.into()))?;
        Ok((y, mode))
    }

    fn fail(&self, t: f64, y: &[f64; N], cause: StopCause) -> Error {
        SimulationError::new(t, cause, self.model.describe(t, y)).into()
    }

    /// Advances to the next accepted step, located event or the stop time.
    ///
    /// # Errors
    /// A simulation error naming the time and state when the contact lifts off (N ≤ 0), the slip
    /// system is singular (Painlevé), the step size collapses, or the step/transition budget runs out.
    pub fn step(&mut self) -> Result<StopReason> {
        // Steps that ended before the settled time are no longer read (outputs up to it were
        // read after the last step): keep the list short and its storage reused.
        let settled = self.settled;
        self.segments.retain(|s| s.t1 >= settled);
        if self.phase_start {
            self.begin_phase()?;
        }
        loop {
            if self.t >= self.t_end {
                self.settled = self.t_end;
                return Ok(StopReason::StopTime { t_s: self.t });
            }
            if self.stats.steps >= self.opts.max_steps {
                return Err(self.fail(
                    self.t,
                    &self.y,
                    StopCause::StepBudget {
                        max_steps: self.opts.max_steps,
                    },
                ));
            }
            // The accepted step is finished where the attempt made it, not moved out of it.
            let finished = self.attempt(|solver, a, last| {
                solver.stats.steps += 1;
                let t_new = if last {
                    solver.t_end
                } else {
                    solver.t + solver.h
                };
                match solver.locate(a, t_new)? {
                    None => Ok(solver.accept(a, t_new)),
                    Some((k, te)) => solver.handle_event(a, k, te, t_new),
                }
            })?;
            if let Some(reason) = finished {
                return reason;
            }
        }
    }

    /// The derivative and event values at the start of a phase; contact must hold there.
    fn begin_phase(&mut self) -> Result<()> {
        let (model, mode, t, y) = (self.model, self.mode, self.t, self.y);
        model
            .rhs(&mode, t, &y, &mut self.f)
            .map_err(|e| self.fail(t, &y, e.into()))?;
        self.stats.rhs_evals += 1;
        let (g, c0) = event_values(model, &mode, t, &y).map_err(|e| self.fail(t, &y, e.into()))?;
        self.stats.event_evals += 1;
        if c0.normal <= 0.0 {
            return Err(self.fail(
                t,
                &y,
                StopCause::ContactLost {
                    phase: None,
                    normal_n: c0.normal,
                },
            ));
        }
        self.g_prev = g;
        self.prev = None;
        self.prev_normal_clear = true;
        self.phase_start = false;
        Ok(())
    }

    /// One attempt of size `h` (cut to the stop time): `finish` of the accepted step and whether
    /// it is the last one, or `None` after a rejection (the step size is reduced).
    fn attempt<R>(
        &mut self,
        finish: impl FnOnce(&mut Self, &Step<N>, bool) -> R,
    ) -> Result<Option<R>> {
        self.h = self.h.min(self.opts.h_max);
        let last = self.t + self.h >= self.t_end;
        if last {
            self.h = self.t_end - self.t;
        }
        if self.h <= 4.0 * f64::EPSILON * self.t.abs().max(1.0) * 16.0 {
            return Err(self.fail(
                self.t,
                &self.y,
                StopCause::StepSizeCollapse {
                    h_s: self.h,
                    phase: Some(self.mode.phase),
                },
            ));
        }
        let (model, mode) = (self.model, self.mode);
        let mut evals = 0;
        let mut last_rhs = None;
        let (mut n_min, mut n_max) = (f64::INFINITY, f64::NEG_INFINITY);
        // Only calls at the step's end can serve the end's event functions (`end_event_values`):
        // keep those, not a copy of every stage.
        let t_step_end = self.t + self.h;
        let mut rhs = |tt: f64, yy: &[f64; N], dy: &mut [f64; N]| {
            evals += 1;
            let c = model.rhs(&mode, tt, yy, dy)?;
            if tt == t_step_end {
                last_rhs = Some((tt, *yy, c));
            }
            n_min = min_or_nan(n_min, c.normal);
            n_max = n_max.max(c.normal);
            Ok::<(), ModelFault>(())
        };
        let method = self.opts.method;
        let outcome = method.attempt(
            &mut rhs,
            self.t,
            &self.y,
            &self.f,
            self.h,
            self.opts.rtol,
            self.opts.atol,
        );
        self.stats.rhs_evals += evals;
        self.last_rhs = last_rhs;
        self.stage_normal = (n_min, n_max);
        match outcome {
            // The right-hand side failed inside the step, or the error estimate or state is not
            // finite (e.g. near a singular constraint): shrink, so the collapse check ends the run.
            Err(_) => {}
            Ok(Outcome::Rejected { err }) if !err.is_finite() => {}
            Ok(Outcome::Rejected { err }) => {
                self.stats.rejected += 1;
                self.rejected_last = true;
                self.h = method.next_step(self.h, err).min(self.h * 0.9);
                return Ok(None);
            }
            Ok(Outcome::Accepted(a)) => return Ok(Some(finish(self, &a, last))),
        }
        self.stats.rejected += 1;
        self.rejected_last = true;
        self.h *= 0.25;
        Ok(None)
    }

    /// The earliest event in the accepted step `a` ending at `t_new`: its function and its time.
    /// The event functions are sampled at `event_samples` interior points and the end; a crossing
    /// is refined by the Illinois method, a dip between samples found by golden-section search.
    /// In slip the slip velocity and the switching functions are read from the state alone, and
    /// the normal force is sampled inside only in a step that is not clear of zero
    /// ([`normal_clear`]) or that follows one; there, its samples and searches are those of sampling
    /// it in every step.
    fn locate(&mut self, a: &Step<N>, t_new: f64) -> Result<Option<(usize, f64)>> {
        let (model, mode, t, h) = (self.model, self.mode, self.t, self.h);
        let m = self.opts.event_samples;
        let slip = mode.phase.slip_dir();
        let mut found: Option<(usize, f64)> = None;
        let mut ta = t;
        let mut ga = self.g_prev;
        // The sample before `ta` (for the minimum test): the previous step's last interior sample.
        let (mut tb, mut gb) = self
            .prev
            .map_or((f64::NAN, [f64::NAN; N_EVENTS]), |(_, tp, gp)| (tp, gp));
        let prev = self.prev;
        let dense = a.dense;
        let (solves, kinematic) = (Cell::new(0), Cell::new(0));
        let (g_end, clear) = self.slip_end(a, t_new, &ga, &solves);
        if slip.is_some() && !clear && gb[2].is_nan() {
            gb = self.solved_prev_sample(gb)?;
        }
        // State on [previous step, this step] from the continuous extensions.
        let y_at = |tt: f64| match prev {
            Some((pd, _, _)) if tt < t => pd.eval(tt),
            _ => dense.eval(tt),
        };
        // Event function `k` at `tt` for the searches; in slip all but the normal force from the
        // state alone.
        let g_at = |k: usize, tt: f64| {
            let yy = y_at(tt);
            match slip {
                Some(s) if k != 2 => {
                    kinematic.set(kinematic.get() + 1);
                    kinematic_event_values(model, &mode, s, tt, &yy).map(|g| g[k])
                }
                _ => {
                    solves.set(solves.get() + 1);
                    event_values(model, &mode, tt, &yy).map(|(g, _)| g[k])
                }
            }
        };
        for j in 1..=m + 1 {
            let at_end = j == m + 1;
            let tj = if at_end {
                t_new
            } else {
                t + h * j as f64 / (m + 1) as f64
            };
            let yj = if at_end { a.y_new } else { dense.eval(tj) };
            let gj = match (at_end, g_end, slip) {
                (true, Some(g), _) => g,
                (false, _, Some(s)) if clear => {
                    kinematic.set(kinematic.get() + 1);
                    kinematic_event_values(model, &mode, s, tj, &yj)
                        .map_err(|e| self.fail(tj, &yj, e.into()))?
                }
                _ => match self.end_event_values(at_end, tj, &yj) {
                    Some(g) => g,
                    None => {
                        solves.set(solves.get() + 1);
                        event_values(model, &mode, tj, &yj)
                            .map_err(|e| self.fail(tj, &yj, e.into()))?
                            .0
                    }
                },
            };
            // In a clear step the normal force has no interior samples: nothing to test.
            for k in (0..N_EVENTS).filter(|&k| !(clear && k == 2)) {
                let bracket = if k >= 3 {
                    // A switching surface: fires on leaving the current region, also when the
                    // function leaves exactly 0 on the wrong side (a graze right after a switch).
                    (ga[k] >= 0.0 && gj[k] < 0.0).then_some((ta, tj, ga[k], gj[k]))
                } else if ga[k] > 0.0 && gj[k] <= 0.0 {
                    Some((ta, tj, ga[k], gj[k]))
                } else if ga[k] == 0.0 && j == 1 && gj[k] < 0.0 {
                    // Just after a transition the function starts at 0; if it is already negative
                    // at the first sample it may have risen and fallen back in between (a slip that
                    // reverses again within the first sub-step): look for a positive maximum.
                    let (tm, gm, _) = golden_extremum(|tt| g_at(k, tt).map(|g| -g), ta, tj)
                        .map_err(|e| self.fail(tj, &yj, e.into()))?;
                    (-gm > 0.0).then_some((tm, tj, -gm, gj[k]))
                } else if gb[k] > 0.0
                    && ga[k] > 0.0
                    && gj[k] > 0.0
                    && ga[k].is_finite()
                    && ga[k] <= gb[k]
                    && ga[k] <= gj[k]
                {
                    // The samples have an interior minimum above zero: the function may dip
                    // across zero and back between samples. Find the minimum.
                    let (tm, gm, _) = golden_extremum(|tt| g_at(k, tt), tb, tj)
                        .map_err(|e| self.fail(tj, &yj, e.into()))?;
                    (gm <= 0.0).then_some((tb, tm, gb[k], gm))
                } else {
                    None
                };
                if let Some((lo, hi, glo, ghi)) = bracket {
                    let tk = illinois_right(|tt| g_at(k, tt), lo, hi, glo, ghi)
                        .map_err(|e| self.fail(tj, &yj, e.into()))?;
                    if found.is_none_or(|(_, te)| tk < te) {
                        found = Some((k, tk));
                    }
                }
            }
            if found.is_some() {
                break;
            }
            tb = ta;
            gb = ga;
            ta = tj;
            ga = gj;
        }
        self.stats.event_evals += solves.get();
        self.stats.kinematic_evals += kinematic.get();
        if found.is_none() {
            self.g_prev = ga;
            self.prev = Some((dense, tb, gb));
            self.prev_normal_clear = clear;
        }
        Ok(found)
    }

    /// In slip, the event functions at the accepted step `a`'s end `t_new` (the last stage's, or
    /// a contact solve counted in `solves`; `None` on a fault, which the sampling loop meets where
    /// it always did) and whether the step's normal force, with `g_start` at its start, stays
    /// clear of zero ([`normal_clear`]) after a step that was clear too. They come first because
    /// the end's normal force decides the interior sampling. Outside slip `(None, false)`.
    fn slip_end(
        &mut self,
        a: &Step<N>,
        t_new: f64,
        g_start: &[f64; N_EVENTS],
        solves: &Cell<usize>,
    ) -> (Option<[f64; N_EVENTS]>, bool) {
        if self.mode.phase.slip_dir().is_none() {
            return (None, false);
        }
        let g_end = self.end_event_values(true, t_new, &a.y_new).or_else(|| {
            solves.set(solves.get() + 1);
            event_values(self.model, &self.mode, t_new, &a.y_new)
                .ok()
                .map(|(g, _)| g)
        });
        let clear = self.prev_normal_clear
            && g_end.is_some_and(|ge| {
                let (lo, hi) = self.stage_normal;
                normal_clear(
                    min_or_nan(min_or_nan(lo, g_start[2]), ge[2]),
                    hi.max(g_start[2]).max(ge[2]),
                    self.opts.lift_off_margin,
                )
            });
        (g_end, clear)
    }

    /// The previous step's last interior sample with the contact solved, when that step sampled
    /// only the kinematic functions inside (`gb`'s normal force NaN): for the minimum test at this
    /// step's start. `gb` itself without a previous step.
    fn solved_prev_sample(&mut self, gb: [f64; N_EVENTS]) -> Result<[f64; N_EVENTS]> {
        let Some((pd, tp, _)) = self.prev else {
            return Ok(gb);
        };
        let yb = pd.eval(tp);
        self.stats.event_evals += 1;
        Ok(event_values(self.model, &self.mode, tp, &yb)
            .map_err(|e| self.fail(tp, &yb, e.into()))?
            .0)
    }

    /// The event functions at the accepted step's end `(t_end, y_end)` from the attempt's last
    /// right-hand-side call, when that call was at exactly this time and state and the state is
    /// already consistent with the mode (`complete` leaves it bitwise unchanged): the same function
    /// of the same arguments as [`event_values`] there, without solving the model again. `None`
    /// otherwise (`at_end` false, the last stage elsewhere, or a state `complete` changes).
    fn end_event_values(
        &mut self,
        at_end: bool,
        t_end: f64,
        y_end: &[f64; N],
    ) -> Option<[f64; N_EVENTS]> {
        if !at_end {
            return None;
        }
        let (tt, yy, c) = self.last_rhs.take()?;
        if tt != t_end || yy != *y_end {
            return None;
        }
        let mut yc = yy;
        self.model.complete(&self.mode, tt, &mut yc).ok()?;
        (yc == yy).then(|| event_values_of(self.model, &self.mode, tt, &yc, c))
    }

    /// Takes the accepted step without an event.
    fn accept(&mut self, a: &Step<N>, t_new: f64) -> StopReason {
        self.segments.push(Segment {
            t1: t_new,
            dense: a.dense,
            y1: Some(a.y_new),
            mode: self.mode,
        });
        // A later step looks back no earlier than this step's last interior sample.
        self.settled = self.prev.map_or(self.t, |(_, tb, _)| tb);
        self.t = t_new;
        self.y = a.y_new;
        self.f = a.f_new;
        self.h = self
            .opts
            .method
            .next_step_after(self.h, a.err, self.rejected_last);
        self.rejected_last = false;
        if self.t >= self.t_end {
            self.settled = self.t_end;
            StopReason::StopTime { t_s: self.t }
        } else {
            StopReason::InternalStep { t_s: t_new }
        }
    }

    /// Ends the step at event `k` located at `te` (possibly in the previous step: a dip at the
    /// boundary), and starts the phase that follows it.
    fn handle_event(&mut self, a: &Step<N>, k: usize, te: f64, t_new: f64) -> Result<StopReason> {
        let t_start = self.t;
        let mut ye = if te >= t_new {
            a.y_new
        } else if te < t_start {
            self.prev.map_or(a.dense.eval(te), |(pd, _, _)| pd.eval(te))
        } else {
            a.dense.eval(te)
        };
        // The solution now ends at `te`: cut the segments there (a dip found at the boundary with
        // the previous step lies before this step, which is then dropped).
        if te >= t_start {
            self.segments.push(Segment {
                t1: te,
                dense: a.dense,
                y1: None,
                mode: self.mode,
            });
        }
        if let Some(s) = self.segments.last_mut()
            && s.t1 > te
        {
            s.t1 = te;
            s.y1 = None;
        }
        self.settled = te;
        self.model
            .complete(&self.mode, te, &mut ye)
            .map_err(|e| self.fail(te, &ye, e.into()))?;
        let event = Event::of_function(k, self.mode.phase.slip_dir().is_some());
        self.phase_start = true;
        self.t = te;
        match event {
            Event::Surface { index } => {
                // Same phase, the other branch of the right-hand side.
                self.mode.region ^= 1 << index;
                self.switches.push(Switch {
                    t_s: te,
                    surface: index,
                    entered: self.mode.region & (1 << index) != 0,
                });
                self.y = ye;
            }
            Event::LiftOff => {
                let (_, c) = event_values(self.model, &self.mode, te, &ye)
                    .map_err(|e| self.fail(te, &ye, e.into()))?;
                return Err(self.fail(
                    te,
                    &ye,
                    StopCause::ContactLost {
                        phase: Some(self.mode.phase),
                        normal_n: c.normal,
                    },
                ));
            }
            Event::SlipEnds | Event::StaticLimit { .. } => {
                self.transition(event.function(), te, ye)?
            }
        }
        self.h = self.h.max(1e-12 * self.span);
        Ok(StopReason::Event { t_s: te, event })
    }

    /// A phase transition at `te` from the state `ye`: the next phase, checked against the
    /// transition budget and against accumulation (Zeno).
    fn transition(&mut self, k: usize, te: f64, mut ye: [f64; N]) -> Result<()> {
        let from = self.mode.phase;
        let new_mode = decide_after_event(self.model, &self.mode, k, te, &mut ye)
            .map_err(|e| self.fail(te, &ye, e.into()))?;
        self.stats.event_evals += 1;
        self.transitions.push(Transition {
            t_s: te,
            from,
            to: new_mode.phase,
        });
        self.transition_states.push(ye);
        if self.transitions.len() > self.opts.max_transitions {
            return Err(self.fail(
                te,
                &ye,
                StopCause::TooManyTransitions {
                    max_transitions: self.opts.max_transitions,
                },
            ));
        }
        if te - self.last_transition_t <= 1e-12 * te.abs().max(1.0) {
            self.quick_transitions += 1;
            if self.quick_transitions > 50 {
                return Err(self.fail(te, &ye, StopCause::Zeno { count: 50 }));
            }
        } else {
            self.quick_transitions = 0;
        }
        self.last_transition_t = te;
        self.y = ye;
        self.mode = new_mode;
        Ok(())
    }
}

/// Integrates `model` from `(t0, y0)` in `mode0` to `t_end`, recording the state at `out_times`
/// (sorted ascending, inside `[t0, t_end]`), every transition, and counters: a loop over
/// [`HybridSolver::step`] that reads each output time once the solution has settled past it.
///
/// # Errors
/// As [`HybridSolver::new`] and [`HybridSolver::step`].
pub fn integrate<M: StickSlipModel<N>, const N: usize>(
    model: &M,
    t0: f64,
    y0: [f64; N],
    mode0: Mode,
    t_end: f64,
    out_times: &[f64],
    opts: &SolverOptions,
) -> Result<Run<N>> {
    let mut solver = HybridSolver::new(model, t0, y0, mode0, t_end, opts)?;
    let mut run = Run {
        t_s: Vec::with_capacity(out_times.len()),
        y: Vec::with_capacity(out_times.len()),
        phase: Vec::with_capacity(out_times.len()),
        modes: Vec::with_capacity(out_times.len()),
        transitions: Vec::new(),
        transition_states: Vec::new(),
        switches: Vec::new(),
        stats: Stats::default(),
        y_end: y0,
        mode_end: mode0,
    };
    let mut next_out = out_times.partition_point(|&to| to < t0);
    // Outputs at exactly t0: the consistent start state.
    let (_, y_start, mode_start) = solver.current();
    while next_out < out_times.len() && out_times[next_out] <= t0 {
        run.t_s.push(out_times[next_out]);
        run.y.push(y_start);
        run.phase.push(mode_start.phase);
        run.modes.push(mode_start);
        next_out += 1;
    }
    loop {
        let reason = solver.step()?;
        while next_out < out_times.len() && out_times[next_out] <= solver.settled_s() {
            let to = out_times[next_out];
            let (yo, mode) = solver.state_and_mode_at(to)?;
            run.t_s.push(to);
            run.y.push(yo);
            run.phase.push(mode.phase);
            run.modes.push(mode);
            next_out += 1;
        }
        if let StopReason::StopTime { .. } = reason {
            break;
        }
    }
    let (_, y_end, mode_end) = solver.current();
    run.transitions = solver.transitions;
    run.transition_states = solver.transition_states;
    run.switches = solver.switches;
    run.stats = solver.stats;
    run.y_end = y_end;
    run.mode_end = mode_end;
    Ok(run)
}

/// Chooses the phase after event `k` of `mode` at `(t, y)`, and makes `y` consistent with it.
fn decide_after_event<M: StickSlipModel<N>, const N: usize>(
    model: &M,
    mode: &Mode,
    k: usize,
    t: f64,
    y: &mut [f64; N],
) -> std::result::Result<Mode, ModelFault> {
    match mode.phase.slip_dir() {
        Some(s) => {
            // Slip velocity reached zero: stick if static friction can hold the contact (seed eq. 5),
            // otherwise the slip reverses directly (physics.md §1.8, "slip reversal without sticking").
            let anchor = model.contact_position(t, y);
            let mut ys = *y;
            model.enter_stick(t, &mut ys, anchor);
            let stick = Mode {
                phase: Phase::Stick,
                anchor,
                region: mode.region,
            };
            model.complete(&stick, t, &mut ys)?;
            let mut dy = [0.0; N];
            let c = model.rhs(&stick, t, &ys, &mut dy)?;
            if c.friction.abs() <= c.limit {
                *y = ys;
                Ok(stick)
            } else {
                // The force needed to hold exceeds the limit: slip opposite to that force.
                let s_new = -c.friction.signum();
                let s_new = if s_new == 0.0 { -s } else { s_new };
                *y = ys;
                Ok(Mode {
                    phase: Phase::slip(s_new),
                    anchor: 0.0,
                    region: mode.region,
                })
            }
        }
        None => {
            // Static friction reached +limit (k = 0) or −limit (k = 1): slip against it.
            let s_new = if k == 0 { -1.0 } else { 1.0 };
            Ok(Mode {
                phase: Phase::slip(s_new),
                anchor: 0.0,
                region: mode.region,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A contact that slips forward for ever (slip velocity `1 + t`, state `[v]`) under a normal
    /// force `N(t) = 1 − depth·exp(−((t − t_dip)/width)²)` that does not act back on it.
    struct Probe {
        t_dip: f64,
        width: f64,
        depth: f64,
    }

    impl Probe {
        fn normal(&self, t: f64) -> f64 {
            1.0 - self.depth * (-((t - self.t_dip) / self.width).powi(2)).exp()
        }
    }

    impl StickSlipModel<1> for Probe {
        fn rhs(
            &self,
            _mode: &Mode,
            t: f64,
            _y: &[f64; 1],
            dy: &mut [f64; 1],
        ) -> std::result::Result<Contact, ModelFault> {
            dy[0] = 1.0;
            Ok(Contact {
                normal: self.normal(t),
                friction: 0.0,
                limit: 1.0,
                slip_velocity: None,
            })
        }
        fn slip_velocity(&self, _t: f64, y: &[f64; 1]) -> f64 {
            y[0]
        }
        fn contact_position(&self, _t: f64, _y: &[f64; 1]) -> f64 {
            0.0
        }
        fn enter_stick(&self, _t: f64, y: &mut [f64; 1], _anchor: f64) {
            y[0] = 0.0;
        }
        fn describe(&self, _t: f64, y: &[f64; 1]) -> String {
            format!("v = {}", y[0])
        }
    }

    /// Steps of at most `h` s that are all accepted (the slip velocity is linear in t, which either
    /// method integrates exactly).
    fn fixed_step(h: f64, method: Method, lift_off_margin: f64) -> SolverOptions {
        SolverOptions {
            rtol: 1e6,
            atol: 1e6,
            h_max: h,
            method,
            lift_off_margin,
            ..SolverOptions::default()
        }
    }

    const SLIP: Mode = Mode {
        phase: Phase::SlipPos,
        anchor: 0.0,
        region: 0,
    };

    /// With the normal force constant, no step comes near lift-off: the interior samples read the
    /// slip velocity from the state, and the contact is solved only at the phase's start (and at
    /// the last step's end if its last stage fell elsewhere). With `lift_off_margin = 1` every
    /// interior sample solves it.
    #[test]
    fn slip_far_from_lift_off_samples_without_contact_solves() {
        let probe = Probe {
            t_dip: 0.0,
            width: 1.0,
            depth: 0.0,
        };
        for method in Method::ALL.iter().copied() {
            let stats = |margin: f64| {
                let opts = fixed_step(0.25, method, margin);
                integrate(&probe, 0.0, [1.0], SLIP, 4.0, &[], &opts)
                    .unwrap()
                    .stats
            };
            let st = stats(0.5);
            assert!(st.steps >= 16, "{method}: {st:?}");
            assert!(st.event_evals <= 2, "{method}: {st:?}");
            assert!(st.kinematic_evals >= 3 * st.steps, "{method}: {st:?}");
            let all = stats(1.0);
            assert_eq!(all.steps, st.steps);
            assert!(all.event_evals >= 3 * st.steps, "{method}: {all:?}");
        }
    }

    /// A dip of the normal force below zero around 0.3 of one step, 0.05 step wide: N is positive
    /// at both ends of the step and at its three interior samples, so only the dip search finds
    /// it; the stages near 0.3 of the step see N < 0, so the step samples N inside. The run stops
    /// with the contact lost where N first reaches 0, t_dip − width·√(ln 1.5) in closed form.
    #[test]
    fn normal_force_dip_between_samples_seen_by_the_stages_is_found() {
        let h = 0.25;
        for method in Method::ALL.iter().copied() {
            let flat = Probe {
                t_dip: 0.0,
                width: 1.0,
                depth: 0.0,
            };
            let opts = fixed_step(h, method, 0.5);
            // The step boundaries of the run (the probe's normal force does not change them).
            let mut solver = HybridSolver::new(&flat, 0.0, [1.0], SLIP, 4.0, &opts).unwrap();
            let mut ends = Vec::new();
            while let StopReason::InternalStep { t_s } = solver.step().unwrap() {
                ends.push(t_s);
            }
            let (ta, tb) = ends
                .windows(2)
                .map(|w| (w[0], w[1]))
                .find(|&(a, b)| a > 1.0 && b - a == h)
                .expect("a full step after 1 s");
            let probe = Probe {
                t_dip: ta + 0.3 * h,
                width: 0.05 * h,
                depth: 1.5,
            };
            for i in 0..=4 {
                let n = probe.normal(ta + 0.25 * h * i as f64);
                assert!(n > 0.4, "{method}: sample {i} sees N = {n}");
            }
            let e = integrate(&probe, 0.0, [1.0], SLIP, 4.0, &[], &opts).unwrap_err();
            let e = SimulationError::of(&e).expect("a simulation error");
            assert!(
                matches!(e.cause, StopCause::ContactLost { .. }),
                "{method}: {e}"
            );
            let t_lift = probe.t_dip - probe.width * 1.5f64.ln().sqrt();
            assert!(
                (e.t_s - t_lift).abs() < 1e-12 && tb > e.t_s,
                "{method}: stopped at {} s, N first 0 at {t_lift} s",
                e.t_s
            );
        }
    }

    /// The bracket the dip search met in a neck/lip run near the flip (t ≈ 1.9906 s, 7.6e-14 s wide):
    /// without the ulp floor the search would cycle forever between two adjacent doubles.
    #[test]
    fn golden_search_ends_on_a_bracket_narrower_than_a_thousand_ulps() {
        let (a, b) = (1.990_639_444_323_852_6, 1.990_639_444_323_928_6);
        let mid = 0.5 * (a + b);
        let (t, g, n) = golden_extremum(|t| Ok(1.0 + (t - mid).abs()), a, b).unwrap();
        assert!(n < 100, "{n} evaluations");
        assert!((a..=b).contains(&t) && g >= 1.0);
    }

    /// On an ordinary bracket the search still narrows to 1e-3 of it: the minimum of (t − 0.3)² on
    /// [0, 1] is found within 1e-3.
    #[test]
    fn golden_search_finds_a_parabolas_minimum() {
        let (t, _, n) = golden_extremum(|t| Ok(1.0 + (t - 0.3) * (t - 0.3)), 0.0, 1.0).unwrap();
        assert!((t - 0.3).abs() < 1e-3, "t = {t}");
        assert!(n < 30, "{n} evaluations");
    }
}
