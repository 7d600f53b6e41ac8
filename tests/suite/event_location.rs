//! Event location of the hybrid integrator: convergence order of transition times, dips across zero
//! within one step, and the slip direction after tangential stick→slip departures (physics.md §1.8).

use crate::common;

use wiperlab::model::benchmarks::{CoulombBelt, seed_law_belt};
use wiperlab::model::{Blade, BladeParams, StickForm};
use wiperlab::simulate::Method;
use wiperlab::simulate::blade::default_window;
use wiperlab::simulate::hybrid::{
    Contact, Mode, ModelFault, Phase, SolverOptions, StickSlipModel, integrate,
};

/// Forward slip from the start of a run.
const SLIP_POS: Mode = Mode {
    phase: Phase::SlipPos,
    anchor: 0.0,
    region: 0,
};

/// Fixed steps of size `h` with `method`: tolerances so loose that every step is accepted,
/// `h_max = h`.
fn fixed_step(h: f64, method: Method) -> SolverOptions {
    SolverOptions {
        rtol: 1e6,
        atol: 1e6,
        h_max: h,
        method,
        ..Default::default()
    }
}

/// Undamped Coulomb belt of physics.md §3.1 (m = 1, k = 4π², v_b = 0.1, F_s = 1, F_k = 0.6) started
/// in stick at x = 0: the first departure is at t_d = x_s/v_b = 10 s·F_s/k (stick is exact), the first
/// stick onset at t_d + t_slip with the closed-form t_slip. Returns the error of that onset time.
fn onset_error(opts: &SolverOptions) -> f64 {
    let case = CoulombBelt::ONE_HZ;
    let (belt, vb) = (case.belt(), case.v_belt_m_per_s);
    let t_onset = case.first_stick_onset_s();
    let mode = Mode {
        phase: Phase::Stick,
        anchor: 0.0,
        region: 0,
    };
    let run = integrate(&belt, 0.0, [0.0, vb], mode, t_onset + 0.05, &[], opts).unwrap();
    let tr = run
        .transitions
        .iter()
        .find(|tr| tr.to == Phase::Stick)
        .expect("stick onset");
    tr.t_s - t_onset
}

/// The transition-time error falls at the integrator's order: with fixed steps h, DOPRI5's steps are
/// 5th-order and its continuous extension (CONTD5) 4th-order; the slip→stick time is located on the
/// continuous extension, so it converges at order 4 (asserted within [3.5, 5.5] for h from T/25 to
/// T/200, T ≈ 1 s the undamped period).
#[test]
fn transition_time_error_falls_at_integrator_order() {
    let hs = [0.04, 0.02, 0.01, 0.005];
    let errs: Vec<f64> = hs
        .iter()
        .map(|&h| onset_error(&fixed_step(h, Method::Dopri5)).abs())
        .collect();
    for w in 0..hs.len() - 1 {
        let order = (errs[w] / errs[w + 1]).log2();
        eprintln!(
            "h = {}: err {:.3e}, observed order {order:.2}",
            hs[w], errs[w]
        );
    }
    for w in 0..hs.len() - 1 {
        let order = (errs[w] / errs[w + 1]).log2();
        assert!(
            order > 3.5 && order < 5.5,
            "order {order} between h = {} and {}",
            hs[w],
            hs[w + 1]
        );
    }
    assert!((errs[2] / errs[3]).log2() > 4.5);
    // With adaptive steps the error follows the tolerance, with either method.
    for method in Method::ALL.iter().copied() {
        for (rtol, bound) in [(1e-6, 1e-5), (1e-9, 1e-8), (1e-12, 1e-11)] {
            let e = onset_error(&SolverOptions {
                rtol,
                atol: rtol * 1e-2,
                method,
                ..Default::default()
            })
            .abs();
            eprintln!("{method} rtol {rtol:e}: onset error {e:.3e}");
            assert!(e < bound, "{method} rtol {rtol}: {e}");
        }
    }
}

/// DOP853's continuous extension is 7th-order (Hairer–Nørsett–Wanner §II.10), i.e. its local error
/// is O(h⁸), the order of the steps' global error: the slip→stick time located on it converges at
/// order ≈ 8 with fixed steps (asserted within [7, 9] for h from T/5 to T/20; smaller steps reach
/// rounding).
#[test]
fn dop853_transition_time_error_falls_at_order_eight() {
    let hs = [0.2, 0.1, 0.05];
    let errs: Vec<f64> = hs
        .iter()
        .map(|&h| onset_error(&fixed_step(h, Method::Dop853)).abs())
        .collect();
    for w in 0..hs.len() - 1 {
        let order = (errs[w] / errs[w + 1]).log2();
        eprintln!(
            "h = {}: err {:.3e}, observed order {order:.2}",
            hs[w], errs[w]
        );
        assert!(
            order > 7.0 && order < 9.0,
            "order {order} between h = {} and {}",
            hs[w],
            hs[w + 1]
        );
    }
}

/// A probe whose slip velocity is `(t − t1)(t − t2)`, prescribed through `v̇ = 2t − t1 − t2`, and
/// which can never stick (the holding force, 10, exceeds the limit, 1): it must reverse at t1 and again
/// at t2.
struct Dip {
    t1: f64,
    t2: f64,
}

impl StickSlipModel<1> for Dip {
    fn rhs(
        &self,
        mode: &Mode,
        t: f64,
        _y: &[f64; 1],
        dy: &mut [f64; 1],
    ) -> Result<Contact, ModelFault> {
        dy[0] = 2.0 * t - self.t1 - self.t2;
        // Holding the contact would need a force opposing its acceleration, 10× the limit.
        Ok(Contact {
            normal: 1.0,
            friction: if mode.phase == Phase::Stick {
                -10.0 * dy[0].signum()
            } else {
                0.0
            },
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

#[test]
fn dip_across_zero_within_one_step_is_not_missed() {
    // Steps of 0.25 s (every step accepted) against a dip of width 0.01 s: both crossings lie in one
    // step, and in one quarter-step sub-interval (event_samples = 3), so neither end nor sample of the
    // step sees a negative value. Steps start at 2e-6 s and grow tenfold up to 0.25 s, so their
    // boundaries fall near 0.222 + 0.25 i: the third dip's sampled minimum is a step boundary.
    for (t1, t2, method) in [(0.61, 0.62), (0.5001, 0.5102), (0.7, 0.7005)]
        .into_iter()
        .flat_map(|(a, b)| Method::ALL.iter().map(move |&m| (a, b, m)))
    {
        let dip = Dip { t1, t2 };
        let opts = fixed_step(0.25, method);
        let mode = SLIP_POS;
        let run = integrate(&dip, 0.0, [t1 * t2], mode, 2.0, &[], &opts).unwrap();
        let times: Vec<(f64, Phase)> = run.transitions.iter().map(|tr| (tr.t_s, tr.to)).collect();
        eprintln!(
            "{method} dip ({t1}, {t2}): {times:?}, {} steps",
            run.stats.steps
        );
        assert_eq!(run.transitions.len(), 2, "{times:?}");
        assert_eq!(run.transitions[0].to, Phase::SlipNeg);
        assert_eq!(run.transitions[1].to, Phase::SlipPos);
        // The velocity is a quadratic, integrated exactly by either method and its continuous
        // extension, so the times are exact up to rounding (the analytic roots t1, t2).
        assert!((run.transitions[0].t_s - t1).abs() < 1e-12);
        assert!((run.transitions[1].t_s - t2).abs() < 1e-12);
    }
}

/// Tangential departures: in the seed law and Leine's law μ_s = μ_d(0⁺), so at stick→slip the slip
/// acceleration of the consistent branch is 0 (physics.md §1.8). The chosen direction must be the one
/// in which the contact then actually slips: s·v_rel ≥ 0 throughout every slip phase.
#[test]
fn tangential_departures_take_the_consistent_direction() {
    // Belt with the seed law (physics.md §3.4): every departure is slip− (γ < 0), and γ < 0 at
    // output samples inside every slip phase.
    let belt = seed_law_belt(3.0);
    let times: Vec<f64> = (0..30_000).map(|i| i as f64 * 1e-3).collect();
    let mode = Mode {
        phase: Phase::Stick,
        anchor: 0.0,
        region: 0,
    };
    let run = integrate(
        &belt,
        0.0,
        [0.0, 0.2],
        mode,
        30.0,
        &times,
        &SolverOptions::default(),
    )
    .unwrap();
    assert!(run.transitions.len() >= 5);
    for tr in &run.transitions {
        assert!(tr.to != Phase::SlipPos, "{tr:?}");
    }
    let mut slip_samples = 0;
    for (y, ph) in run.y.iter().zip(&run.phase) {
        if let Some(s) = ph.slip_dir() {
            assert!(s * (y[1] - 0.2) >= 0.0, "slip {ph} with γ = {}", y[1] - 0.2);
            slip_samples += 1;
        }
    }
    assert!(slip_samples > 10_000);

    // The blade (default sample parameters), with either method: over the reversal window, every
    // slip phase moves the tip in its own direction (v̇3 sampled at 100 kHz, allowing 1e-9 m/s of
    // rounding).
    let params: BladeParams = common::true_blade();
    let (t0, t1) = default_window(&params);
    let n = ((t1 - t0) * 1e5) as usize;
    let times: Vec<f64> = (0..n).map(|i| t0 + i as f64 * 1e-5).collect();
    let blade = Blade::new(params, StickForm::Reduced);
    let y0 = blade.slip_equilibrium(t0).unwrap();
    let mode = SLIP_POS;
    for method in Method::ALL.iter().copied() {
        let opts = SolverOptions {
            method,
            ..SolverOptions::default()
        };
        let run = integrate(&blade, t0, y0, mode, t1, &times, &opts).unwrap();
        let departures = run
            .transitions
            .iter()
            .filter(|tr| tr.from == Phase::Stick)
            .count();
        eprintln!(
            "blade ({method}): {} transitions, {departures} departures",
            run.transitions.len()
        );
        assert!(departures >= 3, "{departures} departures");
        let mut checked = 0;
        for ((t, y), ph) in run.t_s.iter().zip(&run.y).zip(&run.phase) {
            if let Some(s) = ph.slip_dir() {
                let v = blade.tip_velocity(*t, y);
                assert!(
                    s * v >= -1e-9,
                    "{method} t = {t}: {ph} with tip velocity {v}"
                );
                checked += 1;
            }
        }
        assert!(checked > n / 10, "{method}: {checked} slip samples");
    }
}

/// The step API: on the Coulomb belt (physics.md §3.1) started in stick, the first event is the
/// static limit at the closed-form departure time t_d = 10 s·F_s/k (stick is exact), then the slip
/// ends at the closed-form stick onset; every event the solver reports is a transition it records,
/// the settled time never goes back, and the last reason is the stop time.
#[test]
fn step_reports_why_it_stopped() {
    use wiperlab::simulate::hybrid::{Event, HybridSolver, StopReason};
    let case = CoulombBelt::ONE_HZ;
    let (belt, vb) = (case.belt(), case.v_belt_m_per_s);
    let t_onset = case.first_stick_onset_s();
    let mode = Mode {
        phase: Phase::Stick,
        anchor: 0.0,
        region: 0,
    };
    let opts = SolverOptions::default();
    let t_end = t_onset + 0.05;
    let mut solver = HybridSolver::new(&belt, 0.0, [0.0, vb], mode, t_end, &opts).unwrap();
    let (mut events, mut steps, mut settled) = (Vec::new(), 0, 0.0);
    let last = loop {
        let reason = solver.step().unwrap();
        assert!(solver.settled_s() >= settled);
        settled = solver.settled_s();
        match reason {
            StopReason::InternalStep { .. } => steps += 1,
            StopReason::Event { t_s, event } => events.push((t_s, event)),
            StopReason::StopTime { .. } => break reason,
        }
    };
    assert_eq!(last, StopReason::StopTime { t_s: t_end });
    assert!(steps > 10, "{steps} internal steps");
    assert_eq!(events.len(), solver.transitions.len());
    let (t_dep, e0) = events[0];
    assert!(matches!(e0, Event::StaticLimit { .. }), "{e0:?}");
    assert!(
        (t_dep - 10.0 / (4.0 * std::f64::consts::PI.powi(2))).abs() < 1e-9,
        "{t_dep}"
    );
    let (t_stick, e1) = events[1];
    assert_eq!(e1, Event::SlipEnds);
    assert!((t_stick - t_onset).abs() < 1e-6, "{t_stick} vs {t_onset}");
    // The solver's run equals integrate's.
    let run = integrate(&belt, 0.0, [0.0, vb], mode, t_end, &[], &opts).unwrap();
    let times: Vec<f64> = run.transitions.iter().map(|t| t.t_s).collect();
    let stepped: Vec<f64> = events.iter().map(|e| e.0).collect();
    assert_eq!(times, stepped);
}

/// In slip the normal force is sampled inside a step only near lift-off (`lift_off_margin`, 0.5 by
/// default): on the true blade and on the seed experiment's blade with its shoulder (switching
/// surface), over the reversal window with either method, the transitions, the shoulder crossings
/// and the end state are bitwise those of sampling it in every step (`lift_off_margin = 1`), with
/// under a third of the contact solves for events.
#[test]
fn sampling_the_normal_force_near_lift_off_only_keeps_every_event() {
    let shoulder: BladeParams = toml::from_str(
        &std::fs::read_to_string(common::root().join("data/paper/seed_experiment_blade.toml"))
            .expect("read seed_experiment_blade.toml"),
    )
    .expect("parse");
    for (name, params) in [("true blade", common::true_blade()), ("shoulder", shoulder)] {
        let (t0, t1) = default_window(&params);
        let blade = Blade::new(params, StickForm::Reduced);
        let y0 = blade.slip_equilibrium(t0).unwrap();
        let mode = SLIP_POS;
        for method in Method::ALL.iter().copied() {
            let opts = |lift_off_margin| SolverOptions {
                rtol: 1e-6,
                atol: 1e-8,
                method,
                lift_off_margin,
                ..SolverOptions::default()
            };
            let near = integrate(&blade, t0, y0, mode, t1, &[], &opts(0.5)).unwrap();
            let every = integrate(&blade, t0, y0, mode, t1, &[], &opts(1.0)).unwrap();
            eprintln!(
                "{name} ({method}): {} transitions, {} switches; {:?} against {:?}",
                near.transitions.len(),
                near.switches.len(),
                near.stats,
                every.stats
            );
            assert!(near.transitions.len() > 50, "{name} {method}");
            assert_eq!(near.transitions, every.transitions, "{name} {method}");
            assert_eq!(near.switches, every.switches, "{name} {method}");
            assert_eq!(near.y_end, every.y_end, "{name} {method}");
            assert_eq!(near.stats.steps, every.stats.steps, "{name} {method}");
            assert!(
                3 * near.stats.event_evals < every.stats.event_evals,
                "{name} {method}"
            );
        }
    }
}
