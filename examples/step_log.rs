//! One line per step of the event-driven integrator on the true blade's default window
//! (`data/reversal/blade_true.toml`; arguments rtol, method, atol, default atol = rtol/100, and
//! the solver's `lift_off_margin`, default 0.5): end time, step size, accepted steps,
//! rejected attempts and right-hand-side evaluations since the last line, why the step ended and
//! the phase it ran in; the totals on stderr. Where the evaluations go by part of the window
//! (docs/validation.md, "DOP853 against DOPRI5"):
//!
//! ```sh
//! cargo run --release --example step_log -- 1e-10 dop853 > steps.txt
//! ```
use wiperlab::model::{BladeParams, StickForm, blade::Blade};
use wiperlab::simulate::blade::default_window;
use wiperlab::simulate::hybrid::{HybridSolver, Mode, StopReason};
use wiperlab::simulate::{Method, Phase, SolverOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rtol: f64 = args.get(1).map_or(1e-10, |a| a.parse().expect("rtol"));
    let method = match args.get(2).map(String::as_str) {
        Some("dopri5") => Method::Dopri5,
        _ => Method::Dop853,
    };
    let text = std::fs::read_to_string("data/reversal/blade_true.toml").unwrap();
    let p: BladeParams = toml::from_str(&text).unwrap();
    let blade = Blade::new(p, StickForm::Reduced);
    let (t0, t1) = default_window(&p);
    let y0 = blade.slip_equilibrium(t0).unwrap();
    let s0 = if blade.drive(t0).1 >= 0.0 {
        Phase::SlipPos
    } else {
        Phase::SlipNeg
    };
    let opts = SolverOptions {
        rtol,
        atol: args
            .get(3)
            .map_or(rtol / 100.0, |a| a.parse().expect("atol")),
        method,
        lift_off_margin: args
            .get(4)
            .map_or(0.5, |a| a.parse().expect("lift_off_margin")),
        ..SolverOptions::default()
    };
    let mut s = HybridSolver::new(&blade, t0, y0, Mode::new(s0, 0.0), t1, &opts).unwrap();
    let mut t_prev = t0;
    let mut prev = s.stats;
    loop {
        let (_, _, mode) = s.current();
        let r = s.step().unwrap();
        let st = s.stats;
        let (t, kind) = match r {
            StopReason::InternalStep { t_s } => (t_s, "step"),
            StopReason::Event { t_s, .. } => (t_s, "event"),
            StopReason::StopTime { t_s } => (t_s, "stop"),
        };
        println!(
            "{t:.12} {:.6e} {} {} {} {} {:?}",
            t - t_prev,
            st.steps - prev.steps,
            st.rejected - prev.rejected,
            st.rhs_evals - prev.rhs_evals,
            kind,
            mode.phase
        );
        t_prev = t;
        prev = st;
        if kind == "stop" {
            break;
        }
    }
    eprintln!("{:?}", s.stats);
}
