//! Hard cases for the event-driven simulator (issue 5): each either simulates correctly, checked
//! against an independent number, or stops with `Error::Simulation` naming the time and state. None
//! may panic or return NaN.

use crate::common;

use wiperlab::model::belt::Belt;
use wiperlab::model::benchmarks::{CoulombBelt, seed_law_belt};
use wiperlab::model::{Blade, BladeParams, FrictionLaw, StickForm};
use wiperlab::simulate::belt::limit_cycle;
use wiperlab::simulate::blade::{BladeSimulation, default_window, simulate_blade};
use wiperlab::simulate::hybrid::{Mode, Phase, SolverOptions, integrate};

fn sample_params() -> BladeParams {
    common::true_blade()
}

fn tight() -> SolverOptions {
    SolverOptions {
        rtol: 1e-12,
        atol: 1e-14,
        ..Default::default()
    }
}

/// The drive-phase window `[π − d, π + d]/ω` around the reversal.
fn reversal_window(params: &BladeParams, d: f64) -> (f64, f64) {
    let w = params.drive_omega_rad_per_s;
    let pi = std::f64::consts::PI;
    ((pi - d) / w, (pi + d) / w)
}

fn window_times((t0, t1): (f64, f64), rate_hz: f64) -> Vec<f64> {
    let n = ((t1 - t0) * rate_hz) as usize;
    (0..n).map(|i| t0 + i as f64 / rate_hz).collect()
}

fn all_finite(sim: &BladeSimulation) -> bool {
    sim.theta_rad
        .iter()
        .chain(&sim.phi_rad)
        .chain(&sim.v3_m)
        .chain(&sim.u_m)
        .all(|x| x.is_finite())
}

/// Largest difference between matched transition times of two runs (same count and phases).
fn transition_gap(a: &BladeSimulation, b: &BladeSimulation) -> f64 {
    assert_eq!(
        a.transitions.len(),
        b.transitions.len(),
        "transition counts"
    );
    a.transitions
        .iter()
        .zip(&b.transitions)
        .map(|(x, y)| {
            assert_eq!((x.from, x.to), (y.from, y.to));
            (x.t_s - y.t_s).abs()
        })
        .fold(0.0, f64::max)
}

/// Closed-form Coulomb belt period (physics.md §3.1) with N = 1.
fn coulomb_period(mass_kg: f64, k_n_per_m: f64, v_belt_m_per_s: f64, mu_s: f64, mu_k: f64) -> f64 {
    coulomb(mass_kg, k_n_per_m, v_belt_m_per_s, mu_s, mu_k)
        .closed_form()
        .period_s()
}

fn coulomb(mass_kg: f64, k_n_per_m: f64, v_belt_m_per_s: f64, mu_s: f64, mu_k: f64) -> CoulombBelt {
    CoulombBelt {
        mass_kg,
        k_n_per_m,
        v_belt_m_per_s,
        mu_s,
        mu_k,
    }
}

fn expect_simulation_error(
    r: wiperlab::Result<BladeSimulation>,
    window: (f64, f64),
) -> (f64, String) {
    match r {
        Err(e) if wiperlab::simulate::SimulationError::of(&e).is_some() => {
            let wiperlab::simulate::SimulationError { t_s, cause, state } =
                wiperlab::simulate::SimulationError::of(&e).unwrap().clone();
            let message = cause.to_string();
            eprintln!("stopped at t = {t_s}: {message}; state: {state}");
            assert!(
                t_s.is_finite() && t_s >= window.0 && t_s <= window.1,
                "t_s {t_s}"
            );
            assert!(state.contains("θ =") && state.contains("v3 ="), "{state}");
            (t_s, message)
        }
        Err(e) => panic!("expected Error::Simulation, got {e}"),
        Ok(s) => panic!(
            "expected Error::Simulation, got {} transitions",
            s.transitions.len()
        ),
    }
}

/// Near-Painlevé: μ_s = 7.2 (5× the sample's), a head 100× heavier and a 10× preload. The slip
/// equations lose their unique solution (the determinant of the (θ̈, φ̈, N) system with friction
/// changes sign against the frictionless one); the run must stop there with that diagnostic.
#[test]
fn near_painleve_stops_with_diagnostic() {
    let mut p = sample_params();
    p.head_mass_kg *= 100.0;
    p.hd_m *= 10.0;
    p.friction = FrictionLaw::Exponential {
        a: 4.4,
        b_s_per_m: 69.7,
        c: 2.8,
    };
    let w = default_window(&p);
    let times = window_times(w, 20e3);
    let r = simulate_blade(&p, w, &times, &tight(), StickForm::Reduced);
    let (_, message) = expect_simulation_error(r, w);
    assert!(message.contains("Painlevé"), "{message}");
}

/// Very many transitions per millisecond: a Coulomb belt with a 20 µs slip period gives about 100
/// transitions per ms; 2000 of them must keep the closed-form period (physics.md §3.1) to 1e-9, and
/// a transition budget that is too small must stop the run with a diagnostic.
#[test]
fn accumulation_of_transitions_keeps_period_and_budget() {
    let m = 1e-6;
    let k = m * (2.0 * std::f64::consts::PI * 5e4).powi(2);
    let belt = coulomb(m, k, 10.0, 1.0, 0.6).belt();
    let period = coulomb_period(m, k, 10.0, 1.0, 0.6);
    let t_end = 1000.0 * period;
    let cyc = limit_cycle(&belt, 0.0, t_end, &tight()).unwrap().unwrap();
    let per_ms = cyc.transitions as f64 / (t_end * 1e3);
    eprintln!(
        "T = {period:.6e} s, {} transitions ({per_ms:.0} per ms), rel err {:.2e}",
        cyc.transitions,
        (cyc.period_s - period).abs() / period
    );
    assert!(per_ms > 50.0);
    assert!((cyc.period_s - period).abs() < 1e-9 * period);
    let small = SolverOptions {
        max_transitions: 100,
        ..tight()
    };
    match limit_cycle(&belt, 0.0, t_end, &small) {
        Err(e) if wiperlab::simulate::SimulationError::of(&e).is_some() => {
            let wiperlab::simulate::SimulationError { t_s, cause, .. } =
                wiperlab::simulate::SimulationError::of(&e).unwrap().clone();
            let message = cause.to_string();
            assert!(message.contains("more than 100 transitions"), "{message}");
            assert_eq!(
                cause,
                wiperlab::simulate::StopCause::TooManyTransitions {
                    max_transitions: 100
                }
            );
            assert!(t_s > 0.0 && t_s < t_end);
        }
        other => panic!("expected a budget error, got {other:?}"),
    }
}

/// A neck 100× stiffer (stick mode ~10× faster), over the drive phase π ± 0.1 around the reversal:
/// the drift-free and the Baumgarte stick forms are two independent formulations of stick and must
/// give the same transitions (measured: 277 transitions, agreeing to ~1e-12 s).
#[test]
fn stiff_neck_simulates_and_stick_forms_agree() {
    let mut p = sample_params();
    p.k1_nm_per_rad *= 100.0;
    let w = reversal_window(&p, 0.1);
    let times = window_times(w, 20e3);
    let a = simulate_blade(&p, w, &times, &tight(), StickForm::Reduced).unwrap();
    let b = simulate_blade(
        &p,
        w,
        &times,
        &tight(),
        StickForm::Baumgarte { omega_b_per_s: 1e4 },
    )
    .unwrap();
    assert!(all_finite(&a) && all_finite(&b));
    let gap = transition_gap(&a, &b);
    eprintln!(
        "stiff neck: {} transitions, gap {gap:.2e} s",
        a.transitions.len()
    );
    assert!(!a.transitions.is_empty());
    assert!(gap < 1e-9, "gap {gap}");
}

/// Near-zero damping: a belt with c = 1e-12 must keep the undamped closed-form period (the damping
/// changes it by O(c)); the blade with all dampers at 1e-6 of their values must run over the drive
/// phase π ± 0.1, finite, with both stick forms agreeing. (Over the full window the undamped blade's
/// lip motion grows until the tip lifts off; see `lift_off_*` for that diagnostic.)
#[test]
fn near_zero_damping() {
    let k = 4.0 * std::f64::consts::PI.powi(2);
    let belt = Belt {
        c_ns_per_m: 1e-12,
        ..coulomb(1.0, k, 0.1, 1.0, 0.6).belt()
    };
    let period = coulomb_period(1.0, k, 0.1, 1.0, 0.6);
    let cyc = limit_cycle(&belt, 0.0, 5.0, &tight()).unwrap().unwrap();
    assert!((cyc.period_s - period).abs() < 1e-9 * period);

    let mut p = sample_params();
    p.c0_ns_per_m *= 1e-6;
    p.c1_nms_per_rad *= 1e-6;
    p.c2_nms_per_rad *= 1e-6;
    let w = reversal_window(&p, 0.1);
    let times = window_times(w, 20e3);
    let a = simulate_blade(&p, w, &times, &tight(), StickForm::Reduced).unwrap();
    let b = simulate_blade(
        &p,
        w,
        &times,
        &tight(),
        StickForm::Baumgarte { omega_b_per_s: 1e4 },
    )
    .unwrap();
    assert!(all_finite(&a) && all_finite(&b));
    let gap = transition_gap(&a, &b);
    eprintln!(
        "undamped blade: {} transitions, gap {gap:.2e} s",
        a.transitions.len()
    );
    assert!(gap < 1e-9, "gap {gap}");
}

/// B → ∞: the seed law A e^{−B|v|} + C tends to Coulomb with F_s = A + C, F_k = C, whose period has
/// the closed form of physics.md §3.1. The error must fall steadily (≈ 1/B) and be < 1e-4 at B = 1e6.
#[test]
fn seed_law_converges_to_coulomb_as_b_grows() {
    let t_coulomb = coulomb_period(1.0, 1.0, 0.2, 1.0, 0.5);
    let mut last = f64::INFINITY;
    for b in [1e2, 1e3, 1e4, 1e5, 1e6] {
        let belt = seed_law_belt(b);
        let cyc = limit_cycle(&belt, 0.0, 3.5 * t_coulomb, &tight())
            .unwrap()
            .unwrap();
        let err = (cyc.period_s - t_coulomb).abs() / t_coulomb;
        eprintln!(
            "B = {b:e}: T = {:.12}, rel err vs Coulomb {err:.3e}",
            cyc.period_s
        );
        assert!(err < 0.5 * last, "B = {b}: {err} after {last}");
        last = err;
    }
    assert!(last < 1e-4);
}

/// Lift-off: with half the sample's preload the normal force falls to 0 after the reversal. The run must stop
/// with "contact lost" at the time N crosses 0: integrating to just before that time (independently
/// evaluating the slip dynamics there) gives a normal force close to 0 compared with the preload.
#[test]
fn lift_off_stops_where_normal_force_vanishes() {
    let mut p = sample_params();
    p.hd_m *= 0.5;
    let w = default_window(&p);
    let times = window_times(w, 20e3);
    let r = simulate_blade(&p, w, &times, &tight(), StickForm::Reduced);
    let (t_lift, message) = expect_simulation_error(r, w);
    assert!(message.contains("contact lost"), "{message}");
    let blade = Blade::new(p, StickForm::Reduced);
    let y0 = blade.slip_equilibrium(w.0).unwrap();
    let run = integrate(
        &blade,
        w.0,
        y0,
        Mode {
            phase: Phase::SlipPos,
            anchor: 0.0,
            region: 0,
        },
        t_lift - 1e-9,
        &[],
        &tight(),
    )
    .unwrap();
    let y = run.y_end;
    let n = match run.mode_end.phase.slip_dir() {
        Some(s) => blade.slip_dynamics(s, t_lift - 1e-9, &y).unwrap().normal_n,
        None => {
            blade
                .stick_dynamics(t_lift - 1e-9, &y, run.mode_end.anchor, 0.0)
                .unwrap()
                .normal_n
        }
    };
    eprintln!(
        "N just before lift-off: {n:.3e} N (preload {:.3e} N)",
        p.preload_n()
    );
    assert!(n >= 0.0 && n < 1e-3 * p.preload_n(), "N = {n}");
}
