//! DOP853 against DOPRI5 on the shipped true blade (`data/reversal/blade_true.toml`), both run
//! here in the same process, DOPRI5 being the independent reference:
//! - where DOP853's right-hand-side evaluations go on the whole default window at rtol 1e-10, as
//!   `wiperlab simulate` runs it (outputs at 10 kHz): 11 per attempt, 4 more per accepted step (its
//!   end's derivative and the three stages of the 7th-order dense output), one per phase start;
//!   and that it needs fewer evaluations than DOPRI5 (docs/validation.md, "DOP853 against
//!   DOPRI5", explains why the ratio is 0.69 and not 0.5);
//! - the transitions of 20 ms of stick–slip from the blade's first stick onset at rtol 1e-10: the
//!   same sequence with both methods, at the same times within a bound set by the tolerance.

use crate::common;

use wiperlab::bench::blade_burst_start;
use wiperlab::model::{Blade, StickForm};
use wiperlab::simulate::Method;
use wiperlab::simulate::blade::{default_window, simulate_blade};
use wiperlab::simulate::hybrid::{Mode, Phase, SolverOptions, integrate};

fn opts(rtol: f64, method: Method) -> SolverOptions {
    SolverOptions {
        rtol,
        atol: rtol * 1e-2,
        method,
        ..SolverOptions::default()
    }
}

#[test]
fn dop853_evaluations_on_the_whole_window_add_up_and_undercut_dopri5() {
    let p = common::true_blade();
    let win = default_window(&p);
    // The `simulate` command's outputs: 10 kHz over the window.
    let n = ((win.1 - win.0) * 1e4).floor() as usize + 1;
    let times: Vec<f64> = (0..n).map(|k| win.0 + k as f64 / 1e4).collect();
    let run = |m| simulate_blade(&p, win, &times, &opts(1e-10, m), StickForm::Reduced).unwrap();
    let (d5, d8) = (run(Method::Dopri5), run(Method::Dop853));
    let (s5, s8) = (d5.stats, d8.stats);
    eprintln!(
        "rtol 1e-10: DOPRI5 {s5:?}, {} transitions",
        d5.transitions.len()
    );
    eprintln!(
        "rtol 1e-10: DOP853 {s8:?}, {} transitions",
        d8.transitions.len()
    );
    // Every evaluation accounted for (Hairer, Nørsett & Wanner §II.10: 12 stages, the first the
    // previous step's end derivative, 3 dense-output stages): phase starts are the window's start
    // and one per transition (this blade has no switching surface).
    let phase_starts = 1 + d8.transitions.len();
    assert_eq!(
        s8.rhs_evals,
        15 * s8.steps + 11 * s8.rejected + phase_starts,
        "DOP853 {s8:?}"
    );
    assert_eq!(
        s5.rhs_evals,
        6 * (s5.steps + s5.rejected) + 1 + d5.transitions.len(),
        "DOPRI5 {s5:?}"
    );
    // Fewer evaluations than DOPRI5 (measured 0.69; 0.8 leaves room for the first stick onset,
    // which moves with the integration error and changes the burst's length by a few cycles).
    let ratio = s8.rhs_evals as f64 / s5.rhs_evals as f64;
    assert!(ratio < 0.8, "DOP853/DOPRI5 evaluations {ratio:.3}");
    // Its steps: fewer than a third of DOPRI5's.
    assert!(3 * s8.steps < s5.steps, "{} against {}", s8.steps, s5.steps);
}

#[test]
fn dop853_and_dopri5_place_the_bursts_transitions_alike() {
    let p = common::true_blade();
    let (ta, ya, anchor) = blade_burst_start(&p).unwrap();
    let blade = Blade::new(p, StickForm::Reduced);
    let mode = Mode {
        phase: Phase::Stick,
        anchor,
        region: 0,
    };
    let rtol = 1e-10;
    let run = |m| integrate(&blade, ta, ya, mode, ta + 0.02, &[], &opts(rtol, m)).unwrap();
    let (r5, r8) = (run(Method::Dopri5), run(Method::Dop853));
    assert!(
        r5.transitions.len() > 20,
        "{} transitions",
        r5.transitions.len()
    );
    assert_eq!(r5.transitions.len(), r8.transitions.len());
    let mut worst: f64 = 0.0;
    for (a, b) in r5.transitions.iter().zip(&r8.transitions) {
        assert_eq!((a.from, a.to), (b.from, b.to), "at {} s", a.t_s);
        worst = worst.max((a.t_s - b.t_s).abs());
    }
    eprintln!(
        "20 ms burst, rtol {rtol:e}: {} transitions, worst |Δt| DOP853 − DOPRI5 {worst:.2e} s",
        r5.transitions.len()
    );
    // Each method's transition error at this rtol is of order rtol·(burst length) and below
    // (docs/validation.md: 6.0e-13 s and 1.3e-12 s against an rtol 1e-13 run); allow ten times
    // rtol times the 20 ms burst, summed over both methods.
    let bound = 2.0 * 10.0 * rtol * 0.02;
    assert!(worst < bound, "worst |Δt| {worst:e} s against {bound:e} s");
}
