//! Simulating the blade over a drive window, sampled at given (camera) times.

use super::hybrid::{Mode, Phase, SolverOptions, Stats, Switch, Transition, integrate};
use crate::model::blade::{Blade, BladeParams, LockedBlade, StickForm};
use crate::trace::{PointTrack, Trace};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

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
    pub theta_rad: Vec<f64>,
    pub phi_rad: Vec<f64>,
    pub phase: Vec<Phase>,
    pub transitions: Vec<Transition>,
    /// Crossings of the shoulder-contact angle (empty without a shoulder).
    pub switches: Vec<Switch>,
    pub stats: Stats,
    /// Tip link length l1 + l2 (the tip's height below the upright head), m.
    pub reach_m: f64,
}

impl BladeSimulation {
    /// The simulation as a canonical trace: point `head` at (v, −u), point `tip` at (v3, −(l1+l2)),
    /// in the model's frame (origin at the upright head position, y up).
    pub fn to_trace(&self) -> Trace {
        let n = self.t_s.len();
        Trace {
            t_s: self.t_s.clone(),
            points: vec![
                PointTrack {
                    name: "head".into(),
                    x_m: self.v_m.clone(),
                    y_m: self.u_m.iter().map(|u| -u).collect(),
                },
                PointTrack {
                    name: "tip".into(),
                    x_m: self.v3_m.clone(),
                    y_m: vec![-self.reach_m; n],
                },
            ],
        }
    }
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

/// Which member of the model hierarchy to simulate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// The 1-DOF head model: neck and lip locked into one link (no neck–lip mode), the head on its
    /// spring ([`LockedBlade`]). Explains a low band only.
    Head1dof,
    /// The neck/lip model on a prescribed head ([`crate::model::necklip::NeckLip`]): the head's
    /// vertical motion is taken from the recording, so the low component is imposed, not modelled.
    /// Explains a high band only.
    Necklip,
    /// The full 2-DOF head/neck/lip link model of the seed, eqs. (1)–(5) ([`Blade`]).
    #[default]
    Blade2dof,
}

impl ModelKind {
    /// Every kind, smallest first.
    pub const ALL: [ModelKind; 3] = [
        ModelKind::Head1dof,
        ModelKind::Necklip,
        ModelKind::Blade2dof,
    ];

    /// Name used in job files and reports.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Head1dof => "head1dof",
            ModelKind::Necklip => "necklip",
            ModelKind::Blade2dof => "blade2dof",
        }
    }

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
        ModelKind::Necklip => Err(Error::Config(
            "the neck/lip model needs a prescribed head motion: use simulate_necklip".into(),
        )),
        ModelKind::Blade2dof => simulate_blade(params, window, sample_times, opts, stick_form),
        ModelKind::Head1dof => {
            params.validate().map_err(Error::Config)?;
            let model = LockedBlade::new(*params);
            let y0 = model
                .slip_equilibrium(window.0)
                .map_err(|e| Error::Simulation {
                    t_s: window.0,
                    message: e.to_string(),
                    state: "initial equilibrium".into(),
                })?;
            run_to_simulation(&model, &model.blade, y0, params, window, sample_times, opts)
        }
    }
}

/// Simulates the neck/lip model on the prescribed head `head` from the full model's quasi-static
/// slip equilibrium at `window.0` (the constraint's Baumgarte term pulls the head height onto `head`).
///
/// # Errors
/// As [`simulate_blade`].
pub fn simulate_necklip(
    params: &BladeParams,
    head: &crate::model::necklip::PrescribedHead,
    window: (f64, f64),
    sample_times: &[f64],
    opts: &SolverOptions,
) -> Result<BladeSimulation> {
    params.validate().map_err(Error::Config)?;
    let model = crate::model::necklip::NeckLip::new(*params, head.clone());
    let y0 = model
        .blade
        .slip_equilibrium(window.0)
        .map_err(|e| Error::Simulation {
            t_s: window.0,
            message: e.to_string(),
            state: "initial equilibrium".into(),
        })?;
    run_to_simulation(&model, &model.blade, y0, params, window, sample_times, opts)
}

/// Simulates the blade from the quasi-static slip equilibrium at `window.0` to `window.1`, recording
/// the state at `sample_times` (ascending, inside the window).
///
/// # Errors
/// [`Error::Config`] for invalid parameters or options; [`Error::Simulation`] (time and state named)
/// on contact loss, a singular slip system, a step-size collapse or an exhausted budget.
pub fn simulate_blade(
    params: &BladeParams,
    window: (f64, f64),
    sample_times: &[f64],
    opts: &SolverOptions,
    stick_form: StickForm,
) -> Result<BladeSimulation> {
    params.validate().map_err(Error::Config)?;
    let blade = Blade::new(*params, stick_form);
    let t0 = window.0;
    let y0 = blade.slip_equilibrium(t0).map_err(|e| Error::Simulation {
        t_s: t0,
        message: e.to_string(),
        state: "initial equilibrium".into(),
    })?;
    run_to_simulation(&blade, &blade, y0, params, window, sample_times, opts)
}

/// Integrates `model` (whose state has the blade's layout `[θ, φ, θ̇, φ̇]`) from `y0` and turns the run
/// into observables with `blade`'s kinematics.
fn run_to_simulation<M: crate::simulate::hybrid::StickSlipModel<4>>(
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
    let n = run.t_s.len();
    let mut sim = BladeSimulation {
        t_s: run.t_s,
        v_m: Vec::with_capacity(n),
        u_m: Vec::with_capacity(n),
        v3_m: Vec::with_capacity(n),
        theta_rad: Vec::with_capacity(n),
        phi_rad: Vec::with_capacity(n),
        phase: run.phase,
        transitions: run.transitions,
        switches: run.switches,
        stats: run.stats,
        reach_m: params.l1_m + params.l2_m,
    };
    for (t, y) in sim.t_s.iter().zip(&run.y) {
        sim.v_m.push(blade.drive(*t).0);
        sim.u_m.push(blade.head_drop(y));
        sim.v3_m.push(blade.tip_position(*t, y));
        sim.theta_rad.push(y[0]);
        sim.phi_rad.push(y[1]);
    }
    Ok(sim)
}
