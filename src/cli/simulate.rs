//! `wiperlab simulate`: the blade model over its reversal window.

use super::CliError;
use crate::job::{parse_toml, read_text};
use crate::model::{BladeParams, StickForm};
use crate::names::named_enum;
use crate::simulate::blade::{ModelKind, contact_forces, default_window, simulate_model};
use crate::simulate::{Method, SolverOptions};
use crate::{Error, Result};
use std::path::PathBuf;

named_enum! {
    /// How the stick phase is integrated ([`StickForm`]).
    pub enum StickChoice: "stick form" {
        /// Drift-free reduced form.
        Reduced => "reduced",
        /// All coordinates with Baumgarte stabilisation at ω_B = [`BAUMGARTE_OMEGA_PER_S`].
        Baumgarte => "baumgarte",
    }
}

named_enum! {
    /// The models `simulate` runs on their own ([`ModelKind`] without the necklip model, which
    /// needs a recorded head and runs only inside a fit).
    pub enum SimulatedModel: "model" {
        /// [`ModelKind::Blade2dof`].
        Blade2dof => "blade2dof",
        /// [`ModelKind::Head1dof`].
        Head1dof => "head1dof",
    }
}

impl From<SimulatedModel> for ModelKind {
    fn from(m: SimulatedModel) -> ModelKind {
        match m {
            SimulatedModel::Blade2dof => ModelKind::Blade2dof,
            SimulatedModel::Head1dof => ModelKind::Head1dof,
        }
    }
}

/// Baumgarte's ω_B for `--stick baumgarte`, 1/s: fast against the blade's highest mode
/// (≈ 1.2 kHz in stick, 2π·1.2e3 ≈ 7.5e3 /s), so the constraint error decays within a period.
pub const BAUMGARTE_OMEGA_PER_S: f64 = 1e4;

/// The `simulate` command's settings.
pub(super) struct SimulateArgs {
    pub params: PathBuf,
    pub window: Option<Vec<f64>>,
    pub fps: f64,
    pub rtol: f64,
    pub atol: f64,
    pub method: Method,
    pub stick: StickChoice,
    pub model: SimulatedModel,
    pub out_dir: Option<PathBuf>,
}

/// Simulates, writes the trace and figures, and prints the solver's statistics.
pub(super) fn run(a: SimulateArgs) -> Result<()> {
    let p: BladeParams = parse_toml(&a.params, &read_text(&a.params)?)?;
    p.validate()
        .map_err(|m| Error::input(&a.params, m.to_string()))?;
    let win = match a.window.as_deref() {
        Some(&[t0, t1]) => (t0, t1),
        Some(w) => {
            return Err(CliError::ValueCount {
                flag: "--window",
                expected: "T0,T1 in s, e.g. 1.83,1.85",
                got: w.len(),
            }
            .into());
        }
        None => default_window(&p),
    };
    if !(win.0.is_finite() && win.1.is_finite() && win.0 < win.1) {
        let (t0_s, t1_s) = win;
        return Err(CliError::Window { t0_s, t1_s }.into());
    }
    if !(a.fps > 0.0 && a.fps.is_finite()) {
        let (flag, value) = ("--fps", a.fps);
        return Err(CliError::NotPositive { flag, value }.into());
    }
    for (flag, value) in [("--rtol", a.rtol), ("--atol", a.atol)] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(CliError::Tolerance { flag, value }.into());
        }
    }
    let n = ((win.1 - win.0) * a.fps).floor() as usize + 1;
    let times: Vec<f64> = (0..n).map(|k| win.0 + k as f64 / a.fps).collect();
    let form = match a.stick {
        StickChoice::Baumgarte => StickForm::Baumgarte {
            omega_b_per_s: BAUMGARTE_OMEGA_PER_S,
        },
        StickChoice::Reduced => StickForm::Reduced,
    };
    let opts = SolverOptions {
        rtol: a.rtol,
        atol: a.atol,
        method: a.method,
        ..SolverOptions::default()
    };
    let t = std::time::Instant::now();
    let sim = simulate_model(a.model.into(), &p, win, &times, &opts, form)?;
    let forces = contact_forces(a.model.into(), &p, form, &sim)?;
    let wall = t.elapsed().as_secs_f64();
    let dir = a
        .out_dir
        .unwrap_or_else(|| super::default_report_dir(&a.params, "simulate"));
    crate::io::create_dir(&dir)?;
    crate::report::figures::write_simulation(&dir, &sim, &forces)?;
    println!(
        "simulated {:.4}..{:.4} s with {} in {wall:.3} s: {} transitions, {} steps ({} rejected), {} RHS evaluations; outputs in {}",
        win.0,
        win.1,
        a.method,
        sim.transitions.len(),
        sim.stats.steps,
        sim.stats.rejected,
        sim.stats.rhs_evals,
        dir.display()
    );
    Ok(())
}
