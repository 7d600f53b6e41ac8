//! DOP853's error estimate against the true local error of its 8th-order step, in the quiet slip of
//! the true blade's default window (`data/reversal/blade_true.toml`; docs/validation.md, "DOP853
//! against DOPRI5"). At each time the state comes from an rtol 1e-12 run; each trial step `h` is
//! compared with 40 DOP853 steps of `h/40` from the same state. Both columns are in units of the
//! error test at rtol 1e-10, atol 1e-12 (≤ 1 accepts): `estimate` is Hairer's norm (`dop853.f`),
//! `true` the largest component of |y_h − y_ref| / (atol + rtol·|y|).
//!
//! ```sh
//! cargo run --release --example error_estimate
//! ```
use wiperlab::model::stick_slip::StickSlipModel;
use wiperlab::model::{BladeParams, StickForm, blade::Blade};
use wiperlab::simulate::blade::default_window;
use wiperlab::simulate::hybrid::{HybridSolver, Mode, StopReason};
use wiperlab::simulate::{Method, Phase, SolverOptions, dop853};

const RTOL: f64 = 1e-10;
const ATOL: f64 = 1e-12;

fn main() {
    let text = std::fs::read_to_string("data/reversal/blade_true.toml").unwrap();
    let p: BladeParams = toml::from_str(&text).unwrap();
    let blade = Blade::new(p, StickForm::Reduced);
    let (t0, t1) = default_window(&p);
    let y0 = blade.slip_equilibrium(t0).unwrap();
    let opts = SolverOptions {
        rtol: 1e-12,
        atol: 1e-14,
        method: Method::Dop853,
        ..SolverOptions::default()
    };
    let mode = Mode::new(Phase::SlipPos, 0.0);
    let mut solver = HybridSolver::new(&blade, t0, y0, mode, t1, &opts).unwrap();
    let times = [1.2, 1.4, 1.6, 1.7];
    let mut next = 0;
    println!("t_s      h_s      estimate   true");
    while next < times.len() {
        let reason = solver.step().unwrap();
        while next < times.len() && times[next] <= solver.settled_s() {
            let t = times[next];
            let (y, m) = solver.state_and_mode_at(t).unwrap();
            assert_eq!(m.phase, Phase::SlipPos, "quiet slip at {t} s");
            compare(&blade, &m, t, &y);
            next += 1;
        }
        if let StopReason::StopTime { .. } = reason {
            break;
        }
    }
}

/// One DOP853 step of size `h` from `(t, y)`: the new state and the error norm.
fn trial(blade: &Blade, mode: &Mode, t: f64, y: &[f64; 4], h: f64) -> ([f64; 4], f64) {
    let mut rhs =
        |tt: f64, yy: &[f64; 4], dy: &mut [f64; 4]| blade.rhs(mode, tt, yy, dy).map(|_| ());
    let mut f0 = [0.0; 4];
    rhs(t, y, &mut f0).unwrap();
    let a = dop853::attempt(&mut rhs, t, y, &f0, h, RTOL, ATOL).unwrap();
    (a.y_new, a.err)
}

/// One line per trial step size at `(t, y)`.
fn compare(blade: &Blade, mode: &Mode, t: f64, y: &[f64; 4]) {
    for h in [5e-5, 1e-4, 2e-4, 3e-4, 4e-4] {
        let (y_h, estimate) = trial(blade, mode, t, y, h);
        let mut y_ref = *y;
        for k in 0..40 {
            y_ref = trial(blade, mode, t + k as f64 * h / 40.0, &y_ref, h / 40.0).0;
        }
        let true_err = (0..4)
            .map(|i| (y_h[i] - y_ref[i]).abs() / (ATOL + RTOL * y[i].abs()))
            .fold(0.0, f64::max);
        println!("{t:.2}  {h:.1e}  {estimate:.2e}   {true_err:.2e}");
    }
}
