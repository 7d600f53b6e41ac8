//! The comparison methods of `wiperlab bench` (src/simulate/timestep.rs) against physics.md §1.7's
//! work–precision table for Leine's block on a belt (computed there independently with SciPy and
//! Leine's semi-implicit scheme): start at the stick→slip point x = 1, ẋ = 0.2 and compare x at
//! t = 3 s (slip) and 6 s (stick) with the exact solution (here: the event-driven integrator at
//! rtol 1e-12, itself checked to ~1e-12 against RK4 + Hénon in tests/suite/stick_slip_benchmarks.rs).

use wiperlab::model::benchmarks::leine_belt as leine;
use wiperlab::simulate::hybrid::{Mode, Phase, SolverOptions, integrate};
use wiperlab::simulate::timestep::{moreau_jean, smoothed};

fn exact_at(times: &[f64]) -> Vec<f64> {
    let opts = SolverOptions {
        rtol: 1e-12,
        atol: 1e-14,
        ..Default::default()
    };
    let mode = Mode {
        phase: Phase::SlipNeg,
        anchor: 0.0,
        region: 0,
    };
    let run = integrate(&leine(), 0.0, [1.0, 0.2], mode, 6.5, times, &opts).unwrap();
    run.y.iter().map(|y| y[0]).collect()
}

/// physics.md §1.7 lists for Leine's semi-implicit Euler DAE scheme: dt = 1e-3: err x(3 s) 4.7e-4,
/// x(6 s) 2.4e-3; dt = 1e-5: 4.7e-6 and 2.4e-5. Our Moreau–Jean variant (continuous part of the law
/// explicit) is not the same scheme, so only the order of magnitude (within 10×) and the first-order
/// convergence (error ÷ 100 ± 3× for dt ÷ 100) are required.
#[test]
fn moreau_jean_first_order_and_published_magnitude() {
    let times = [3.0, 6.0];
    let exact = exact_at(&times);
    let mut errs = Vec::new();
    for (dt, e3, e6) in [(1e-3, 4.7e-4, 2.4e-3), (1e-5, 4.7e-6, 2.4e-5)] {
        let tr = moreau_jean(&leine(), 0.0, 6.5, [1.0, 0.2], dt, &times).unwrap();
        let err3 = (tr.observable_m[0] - exact[0]).abs();
        let err6 = (tr.observable_m[1] - exact[1]).abs();
        eprintln!("dt {dt:e}: err x(3) {err3:.3e} (table {e3:e}), x(6) {err6:.3e} (table {e6:e})");
        assert!(err3 < 10.0 * e3 && err3 > e3 / 10.0, "x(3): {err3}");
        assert!(err6 < 10.0 * e6 && err6 > e6 / 10.0, "x(6): {err6}");
        errs.push((err3, err6));
    }
    for (a, b) in [(errs[0].0, errs[1].0), (errs[0].1, errs[1].1)] {
        let ratio = a / b;
        assert!(ratio > 100.0 / 3.0 && ratio < 300.0, "ratio {ratio}");
    }
}

/// The smoothed law converges to the set-valued one as ε → 0, slowly (physics.md §1.7: the error
/// falls about like ε^(1/2) here, because the departure from stick is tangential).
#[test]
fn smoothed_friction_converges_slowly() {
    let times = [3.0, 6.0];
    let exact = exact_at(&times);
    let mut last = f64::INFINITY;
    for eps in [1e-2, 1e-3, 1e-4] {
        let tr = smoothed(&leine(), eps, 0.0, 6.5, [1.0, 0.2], 1e-10, &times).unwrap();
        let err6 = (tr.observable_m[1] - exact[1]).abs();
        eprintln!(
            "eps {eps:e}: err x(6) {err6:.3e}, {} RHS",
            tr.stats.rhs_evals
        );
        assert!(err6 < last, "{err6} after {last}");
        // Not faster than first order in ε, not slower than ε^(1/4).
        if last.is_finite() {
            let ratio = last / err6;
            assert!(ratio < 12.0 && ratio > 10f64.powf(0.25), "ratio {ratio}");
        }
        last = err6;
    }
}
