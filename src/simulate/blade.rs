//! Simulating the blade over a drive window, sampled at given (camera) times.

use super::hybrid::{
    Mode, ModelFault, Phase, SolverOptions, Stats, StickSlipModel, Switch, Transition, integrate,
};
use crate::model::blade::{Blade, BladeParams, Kinematics, LockedBlade, StickForm};
use crate::trace::{PointTrack, Role, Trace};
use crate::{Error, Result};

/// How far into a neck/lip segment (s) the runner looks for a state the tracks and the contact
/// allow the model to start from.
const START_SEARCH_S: f64 = 0.01;

/// A simulated reversal: the observables at each sample time, the transitions and the counters.
/// All vectors have the length of `t_s`.
#[derive(Debug, Clone)]
pub struct BladeSimulation {
    pub t_s: Vec<f64>,
    /// Head horizontal position v (the drive), m.
    pub v_m: Vec<f64>,
    /// Head drop u = l1(1 − cos θ) + l2(1 − cos φ), m (positive down).
    pub u_m: Vec<f64>,
    /// Lip-tip horizontal position v3, m.
    pub v3_m: Vec<f64>,
    /// Neck angle θ from the vertical, rad.
    pub theta_rad: Vec<f64>,
    /// Lip angle φ from the vertical, rad.
    pub phi_rad: Vec<f64>,
    /// Neck rate θ̇, rad/s.
    pub theta_dot_rad_per_s: Vec<f64>,
    /// Lip rate φ̇, rad/s.
    pub phi_dot_rad_per_s: Vec<f64>,
    /// Lip-tip horizontal velocity v̇3 (the slip velocity; 0 in stick), m/s.
    pub v3_dot_m_per_s: Vec<f64>,
    pub phase: Vec<Phase>,
    /// The mode at each sample: the phase with its stick anchor and shoulder region, what
    /// [`contact_forces`] needs to evaluate the model there.
    pub modes: Vec<Mode>,
    pub transitions: Vec<Transition>,
    /// Crossings of the shoulder-contact angle (empty without a shoulder).
    pub switches: Vec<Switch>,
    pub stats: Stats,
    /// Tip link length l1 + l2 (the tip's height below the upright head), m.
    pub reach_m: f64,
}

impl BladeSimulation {
    /// Fills sample `j` from the state `y` (layout `[θ, φ, θ̇, φ̇]`) in `mode`: positions from
    /// `blade`'s kinematics, the slip velocity from `model`, all from one evaluation of the drive
    /// and of each angle's sine and cosine.
    fn observe<M: Observed>(
        &mut self,
        j: usize,
        model: &M,
        blade: &Blade,
        y: &[f64; 4],
        mode: &Mode,
    ) {
        let k = blade.kinematics(self.t_s[j], y);
        self.v_m[j] = k.head_position_m;
        self.u_m[j] = k.head_drop_m;
        self.v3_m[j] = k.tip_position_m;
        self.theta_rad[j] = y[0];
        self.phi_rad[j] = y[1];
        self.theta_dot_rad_per_s[j] = y[2];
        self.phi_dot_rad_per_s[j] = y[3];
        self.v3_dot_m_per_s[j] = model.slip_velocity_from(&k, y);
        self.modes[j] = *mode;
    }

    /// The state `[θ, φ, θ̇, φ̇]` at sample `j`.
    fn state(&self, j: usize) -> [f64; 4] {
        [
            self.theta_rad[j],
            self.phi_rad[j],
            self.theta_dot_rad_per_s[j],
            self.phi_dot_rad_per_s[j],
        ]
    }

    /// |slip speed| `|v̇3|` of every sample in slip (stick samples left out), m/s.
    pub fn slip_speeds(&self) -> Vec<f64> {
        self.phase
            .iter()
            .zip(&self.v3_dot_m_per_s)
            .filter(|(ph, _)| ph.slip_dir().is_some())
            .map(|(_, v)| v.abs())
            .collect()
    }

    /// The simulation as a canonical trace: point `head` at (v, −u), point `tip` at (v3, −(l1+l2)),
    /// in the model's frame (origin at the upright head position, y up).
    pub fn to_trace(&self) -> Trace {
        let n = self.t_s.len();
        Trace {
            t_s: self.t_s.clone(),
            points: vec![
                PointTrack {
                    name: Role::Head.name().into(),
                    x_m: self.v_m.clone(),
                    y_m: self.u_m.iter().map(|u| -u).collect(),
                },
                PointTrack {
                    name: Role::Tip.name().into(),
                    x_m: self.v3_m.clone(),
                    y_m: vec![-self.reach_m; n],
                },
            ],
        }
    }
}

/// The contact forces of a simulation at its samples, N (the length of its `t_s`).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactForces {
    /// Normal force N of the glass on the lip tip (seed eq. 3), N.
    pub normal_n: Vec<f64>,
    /// Friction force f of the glass on the lip tip along +x, N: `−sign(v̇3)·μ_d(|v̇3|)·N` in slip
    /// (seed eq. 4), the force that holds the tip in stick, `|f| ≤ μ_s·N` (seed eq. 5).
    pub friction_n: Vec<f64>,
}

/// The contact forces of `sim`, a simulation of model `kind` with `params` and `stick_form`, at its
/// samples: the model's own right-hand side evaluated in each sample's mode (what the integrator
/// used there). Separate from the simulation so that a fit's runs do not pay for them.
///
/// # Errors
/// [`super::SettingError`] for the neck/lip model (its prescribed head is not kept);
/// [`super::SimulationError`] naming the time and state if the right-hand side fails at a sample.
pub fn contact_forces(
    kind: ModelKind,
    params: &BladeParams,
    stick_form: StickForm,
    sim: &BladeSimulation,
) -> Result<ContactForces> {
    match kind {
        ModelKind::Blade2dof => forces_of(&Blade::new(*params, stick_form), sim),
        ModelKind::Head1dof => forces_of(&LockedBlade::new(*params), sim),
        ModelKind::Necklip => Err(super::SettingError::NecklipContactForces.into()),
    }
}

fn forces_of<M: StickSlipModel<4>>(model: &M, sim: &BladeSimulation) -> Result<ContactForces> {
    let n = sim.t_s.len();
    let mut out = ContactForces {
        normal_n: Vec::with_capacity(n),
        friction_n: Vec::with_capacity(n),
    };
    let mut dy = [0.0; 4];
    for (j, (&t, mode)) in sim.t_s.iter().zip(&sim.modes).enumerate() {
        let y = sim.state(j);
        let c = model
            .rhs(mode, t, &y, &mut dy)
            .map_err(|e| super::error::SimulationError::new(t, e, model.describe(t, &y)))?;
        out.normal_n.push(c.normal);
        out.friction_n.push(c.friction);
    }
    Ok(out)
}

/// The default reversal window `[π/2, 3π/2]/ω`: from the fastest forward point of the drive
/// `v = a(1 − cos ωt)` through the reversal at `π/ω` to the fastest backward point.
pub fn default_window(params: &BladeParams) -> (f64, f64) {
    let w = params.drive_omega_rad_per_s;
    (
        0.5 * std::f64::consts::PI / w,
        1.5 * std::f64::consts::PI / w,
    )
}

crate::names::named_enum! {
    /// Which member of the model hierarchy to simulate.
    #[derive(Default)]
    pub enum ModelKind: "model" {
        /// The 1-DOF head model: neck and lip locked into one link (no neck–lip mode), the head on its
        /// spring ([`LockedBlade`]). Explains a low band only.
        Head1dof => "head1dof",
        /// The neck/lip model on a prescribed head ([`crate::model::necklip::NeckLip`]): the head's
        /// vertical motion is taken from the recording, so the low component is imposed, not modelled.
        /// Explains a high band only.
        Necklip => "necklip",
        /// The full 2-DOF head/neck/lip link model of the seed, eqs. (1)–(5) ([`Blade`]).
        #[default]
        Blade2dof => "blade2dof",
    }
}

impl ModelKind {
    /// Degrees of freedom in slip.
    pub fn dof(self) -> usize {
        match self {
            ModelKind::Head1dof => 1,
            ModelKind::Necklip | ModelKind::Blade2dof => 2,
        }
    }

    /// Whether the model has a neck–lip mode, i.e. can produce a high (hundreds of Hz) band.
    pub fn has_neck_mode(self) -> bool {
        self != ModelKind::Head1dof
    }

    /// Whether the model explains the low (head) component; the neck/lip model imposes it.
    pub fn has_head_mode(self) -> bool {
        self != ModelKind::Necklip
    }
}

/// Simulates the blade model `kind` from the quasi-static slip equilibrium at `window.0` to
/// `window.1`, recording the state at `sample_times` (ascending, inside the window).
///
/// # Errors
/// As [`simulate_blade`].
pub fn simulate_model(
    kind: ModelKind,
    params: &BladeParams,
    window: (f64, f64),
    sample_times: &[f64],
    opts: &SolverOptions,
    stick_form: StickForm,
) -> Result<BladeSimulation> {
    match kind {
        ModelKind::Necklip => Err(super::SettingError::NecklipWithoutHead.into()),
        ModelKind::Blade2dof => simulate_blade(params, window, sample_times, opts, stick_form),
        ModelKind::Head1dof => {
            params.validate()?;
            let model = LockedBlade::new(*params);
            let y0 = model
                .slip_equilibrium(window.0)
                .map_err(|e| crate::simulate::SimulationError::at_start(window.0, e))?;
            run_to_simulation(&model, &model.blade, y0, params, window, sample_times, opts)
        }
    }
}

/// Simulates the neck/lip model on the prescribed head `head`.
///
/// The model cannot pass the blade's flip at the reversal (its head-height constraint degenerates
/// at upright, [`crate::model::necklip`]), so with a lean track the window is cut into the segments
/// of [`PrescribedHead::segments`](crate::model::necklip::PrescribedHead::segments) (guard
/// [`FLIP_GUARD_OF_REACH`](crate::model::necklip::FLIP_GUARD_OF_REACH) of the reach). The first
/// segment starts from the full model's quasi-static slip equilibrium (the constraint's Baumgarte
/// term pulls the head height onto `head`): the window is meant to start in steady slip, and the
/// recorded angles there need not balance the model's stiffnesses (starting from them gave a
/// negative normal force away from the true blade). A segment after the flip starts from the
/// state the tracks give
/// ([`NeckLip::state_from_tracks`](crate::model::necklip::NeckLip::state_from_tracks)), in stick or
/// slip as the tip's speed and the friction limit say. Samples outside the segments hold NaN
/// positions and angles (the drive `v` is known) and the phase of the segment before, so the
/// spectra skip them.
///
/// # Errors
/// As [`simulate_blade`]; [`super::SimulationError`] too when the lean stays inside the guard over the
/// whole window.
pub fn simulate_necklip(
    params: &BladeParams,
    head: &crate::model::necklip::PrescribedHead,
    window: (f64, f64),
    sample_times: &[f64],
    opts: &SolverOptions,
) -> Result<BladeSimulation> {
    use crate::model::necklip::{FLIP_GUARD_OF_REACH, NeckLip};
    params.validate()?;
    let model = NeckLip::new(*params, head.clone());
    let reach = params.l1_m + params.l2_m;
    let segments = head.segments(window, FLIP_GUARD_OF_REACH * reach);
    if segments.is_empty() {
        return Err(super::error::SimulationError::new(
            window.0,
            super::error::StopCause::NoSegment {
                guard_m: FLIP_GUARD_OF_REACH * reach,
            },
            "no segment",
        )
        .into());
    }
    let n = sample_times.len();
    let drive_dir = |t: f64| {
        if model.blade.drive(t).1 >= 0.0 {
            Phase::SlipPos
        } else {
            Phase::SlipNeg
        }
    };
    let mut sim = unsimulated(&model.blade, sample_times, drive_dir(window.0), reach);
    for (i, &(a0, b)) in segments.iter().enumerate() {
        let mut a = a0;
        let fail = |e: ModelFault| -> Error {
            super::error::SimulationError::new(
                a0,
                e,
                format!("start of neck/lip segment {} ({a0:.6}–{b:.6} s)", i + 1),
            )
            .into()
        };
        let (y0, mode0) = if i == 0 {
            (
                model.blade.slip_equilibrium(a).map_err(fail)?,
                Mode::new(drive_dir(a), 0.0),
            )
        } else {
            let (start, t_start) =
                first_consistent_start(&model, (a, b), sample_times).map_err(fail)?;
            a = t_start;
            start
        };
        let lo = sample_times.partition_point(|&t| t < a);
        let hi = sample_times.partition_point(|&t| t <= b);
        let run = integrate(&model, a, y0, mode0, b, &sample_times[lo..hi], opts)?;
        for (k, j) in (lo..hi).enumerate() {
            sim.observe(j, &model, &model.blade, &run.y[k], &run.modes[k]);
        }
        sim.phase[lo..hi].copy_from_slice(&run.phase);
        let last = run.phase.last().copied().unwrap_or(mode0.phase);
        let next = segments
            .get(i + 1)
            .map_or(n, |s| sample_times.partition_point(|&t| t < s.0));
        sim.phase[hi..next].fill(last);
        sim.transitions.extend(run.transitions);
        sim.switches.extend(run.switches);
        sim.stats.steps += run.stats.steps;
        sim.stats.rejected += run.stats.rejected;
        sim.stats.rhs_evals += run.stats.rhs_evals;
        sim.stats.event_evals += run.stats.event_evals;
        sim.stats.kinematic_evals += run.stats.kinematic_evals;
    }
    Ok(sim)
}

/// A model whose state has the blade's layout `[θ, φ, θ̇, φ̇]`, observed through the blade's
/// kinematics.
trait Observed: StickSlipModel<4> {
    /// [`StickSlipModel::slip_velocity`] at the state `y` whose kinematics are `k` (bitwise).
    fn slip_velocity_from(&self, k: &Kinematics, y: &[f64; 4]) -> f64;
}

impl Observed for Blade {
    fn slip_velocity_from(&self, k: &Kinematics, y: &[f64; 4]) -> f64 {
        self.tip_velocity_from(k.head_speed_m_per_s, k.cos, y)
    }
}

impl Observed for LockedBlade {
    fn slip_velocity_from(&self, k: &Kinematics, y: &[f64; 4]) -> f64 {
        self.tip_velocity_from(k.head_speed_m_per_s, k.cos[0], y[2])
    }
}

impl Observed for crate::model::necklip::NeckLip {
    fn slip_velocity_from(&self, k: &Kinematics, y: &[f64; 4]) -> f64 {
        self.blade.tip_velocity_from(k.head_speed_m_per_s, k.cos, y)
    }
}

/// A simulation before any sample was observed: the drive `v` at every sample, NaN positions,
/// angles, rates and forces, every sample in `phase`.
fn unsimulated(blade: &Blade, sample_times: &[f64], phase: Phase, reach_m: f64) -> BladeSimulation {
    let mut sim = unobserved(sample_times, phase, reach_m);
    sim.v_m = sample_times.iter().map(|&t| blade.drive(t).0).collect();
    sim
}

/// A simulation before any sample was observed: NaN drive, positions, angles, rates and forces,
/// every sample in `phase` (for a run that observes every sample).
fn unobserved(sample_times: &[f64], phase: Phase, reach_m: f64) -> BladeSimulation {
    let n = sample_times.len();
    BladeSimulation {
        t_s: sample_times.to_vec(),
        v_m: vec![f64::NAN; n],
        u_m: vec![f64::NAN; n],
        v3_m: vec![f64::NAN; n],
        theta_rad: vec![f64::NAN; n],
        phi_rad: vec![f64::NAN; n],
        theta_dot_rad_per_s: vec![f64::NAN; n],
        phi_dot_rad_per_s: vec![f64::NAN; n],
        v3_dot_m_per_s: vec![f64::NAN; n],
        phase: vec![phase; n],
        modes: vec![Mode::new(phase, 0.0); n],
        transitions: Vec::new(),
        switches: Vec::new(),
        stats: Stats::default(),
        reach_m,
    }
}

/// The first sample (up to [`START_SEARCH_S`] into the segment `(a, b)`) where the tracks give a
/// state the neck/lip model can start from, and its time: right after the flip slip can be
/// Painlevé-singular with the head height prescribed, and static friction may not yet hold the tip.
///
/// # Errors
/// [`ModelFault::NoConsistentStart`] with the last attempt's fault when no sample in the search
/// span gives a start.
fn first_consistent_start(
    model: &crate::model::necklip::NeckLip,
    (a, b): (f64, f64),
    sample_times: &[f64],
) -> std::result::Result<(([f64; 4], Mode), f64), ModelFault> {
    let dt = sample_times.get(1).map_or(1e-4, |t1| t1 - sample_times[0]);
    let limit = (a + START_SEARCH_S).min(b);
    let mut ts = a;
    loop {
        let attempt = model
            .state_from_tracks(ts)
            .and_then(|(y, dir)| start_from_tracks(model, ts, y, dir));
        match attempt {
            Ok(s) => return Ok((s, ts)),
            Err(e) if ts + dt > limit => {
                return Err(ModelFault::NoConsistentStart {
                    search_s: START_SEARCH_S,
                    last: Box::new(e),
                });
            }
            Err(_) => ts += dt,
        }
    }
}

/// The mode a neck/lip segment starts in from the tracks, and its state: stick when the tip's speed
/// from the tracks is below what they resolve (1 mm/s, or 5 % of the drive's speed) and static
/// friction can hold the tip there (seed eq. 5; the velocity is then made consistent with stick),
/// else slip along the tip's velocity. Right after the flip the tip is usually held while the head
/// passes over it, and slip there can be Painlevé-singular with the head height prescribed.
fn start_from_tracks(
    model: &crate::model::necklip::NeckLip,
    t: f64,
    y: [f64; 4],
    dir: f64,
) -> std::result::Result<([f64; 4], Mode), ModelFault> {
    use crate::simulate::hybrid::StickSlipModel;
    let mut dy = [0.0; 4];
    let tip_speed = model.slip_velocity(t, &y).abs();
    if tip_speed < 1e-3_f64.max(0.05 * model.blade.drive(t).1.abs()) {
        let anchor = model.contact_position(t, &y);
        let mut ys = y;
        model.enter_stick(t, &mut ys, anchor);
        let stick = Mode::new(Phase::Stick, anchor);
        if let Ok(c) = model.rhs(&stick, t, &ys, &mut dy)
            && c.normal > 0.0
            && c.friction.abs() <= c.limit
        {
            return Ok((ys, stick));
        }
    }
    let slip = Mode::new(Phase::slip(dir), 0.0);
    let c = model.rhs(&slip, t, &y, &mut dy)?;
    if c.normal > 0.0 {
        Ok((y, slip))
    } else {
        Err(ModelFault::ContactLost { normal_n: c.normal })
    }
}

/// Simulates the blade from the quasi-static slip equilibrium at `window.0` to `window.1`, recording
/// the state at `sample_times` (ascending, inside the window).
///
/// # Errors
/// [`crate::model::ParamError`] / [`super::SettingError`] for invalid parameters or options; [`super::SimulationError`] (time and state named)
/// on contact loss, a singular slip system, a step-size collapse or an exhausted budget.
pub fn simulate_blade(
    params: &BladeParams,
    window: (f64, f64),
    sample_times: &[f64],
    opts: &SolverOptions,
    stick_form: StickForm,
) -> Result<BladeSimulation> {
    params.validate()?;
    let blade = Blade::new(*params, stick_form);
    let t0 = window.0;
    let y0 = blade
        .slip_equilibrium(t0)
        .map_err(|e| crate::simulate::SimulationError::at_start(t0, e))?;
    run_to_simulation(&blade, &blade, y0, params, window, sample_times, opts)
}

/// Integrates `model` (whose state has the blade's layout `[θ, φ, θ̇, φ̇]`) from `y0` and turns the run
/// into observables with `blade`'s kinematics.
fn run_to_simulation<M: Observed>(
    model: &M,
    blade: &Blade,
    y0: [f64; 4],
    params: &BladeParams,
    window: (f64, f64),
    sample_times: &[f64],
    opts: &SolverOptions,
) -> Result<BladeSimulation> {
    let (t0, t1) = window;
    let s0 = if blade.drive(t0).1 >= 0.0 {
        Phase::SlipPos
    } else {
        Phase::SlipNeg
    };
    let run = integrate(model, t0, y0, Mode::new(s0, 0.0), t1, sample_times, opts)?;
    let mut sim = unobserved(&run.t_s, s0, params.l1_m + params.l2_m);
    for (j, (y, mode)) in run.y.iter().zip(&run.modes).enumerate() {
        sim.observe(j, model, blade, y, mode);
    }
    sim.phase = run.phase;
    sim.transitions = run.transitions;
    sim.switches = run.switches;
    sim.stats = run.stats;
    Ok(sim)
}
