//! Shoulder contact: a piecewise neck stiffness located as a switching event.
//!
//! - The integrator's switching surfaces against the closed-form period of a bilinear oscillator.
//! - The blade with a shoulder whose two stiffnesses are equal against the blade without one.
//! - A shoulder the neck never reaches changes nothing.

use crate::common;

use wiperlab::model::{BladeParams, Shoulder, StickForm};
use wiperlab::simulate::blade::simulate_blade;
use wiperlab::simulate::hybrid::{
    Contact, Mode, ModelFault, Phase, SolverOptions, StickSlipModel, integrate,
};

/// A frictionless mass on a bilinear spring: force −k1·x for |x| ≤ x_c, −sign x·[k1 x_c + k2(|x| − x_c)]
/// beyond. It is declared as slipping against a belt far faster than it ever moves, so the phase never
/// changes and only the switching surface |x| = x_c is exercised.
struct Bilinear {
    m: f64,
    k1: f64,
    k2: f64,
    xc: f64,
}

impl StickSlipModel<2> for Bilinear {
    fn rhs(
        &self,
        mode: &Mode,
        _t: f64,
        y: &[f64; 2],
        dy: &mut [f64; 2],
    ) -> Result<Contact, ModelFault> {
        let x = y[0];
        let force = if mode.region & 1 != 0 {
            -x.signum() * (self.k1 * self.xc + self.k2 * (x.abs() - self.xc))
        } else {
            -self.k1 * x
        };
        dy[0] = y[1];
        dy[1] = force / self.m;
        Ok(Contact {
            normal: 1.0,
            friction: 0.0,
            limit: 0.0,
            slip_velocity: None,
        })
    }
    fn slip_velocity(&self, _t: f64, y: &[f64; 2]) -> f64 {
        y[1] - 1e6
    }
    fn contact_position(&self, _t: f64, y: &[f64; 2]) -> f64 {
        y[0]
    }
    fn enter_stick(&self, _t: f64, _y: &mut [f64; 2], _anchor: f64) {}
    fn describe(&self, _t: f64, y: &[f64; 2]) -> String {
        format!("x = {}, v = {}", y[0], y[1])
    }
    fn switching_surfaces(&self) -> usize {
        1
    }
    fn switching_function(&self, _i: usize, _t: f64, y: &[f64; 2]) -> f64 {
        y[0].abs() - self.xc
    }
}

#[test]
fn bilinear_oscillator_switch_times_match_the_closed_form() {
    // Closed form (piecewise harmonic motion, derived here): start at x = 0 with speed V0 in the soft
    // region. Soft: x = (V0/ω1) sin ω1 t reaches x_c at t1 = asin(x_c ω1/V0)/ω1 with speed
    // Vc = V0 cos(ω1 t1). Stiff: about the equilibrium x* = x_c − k1 x_c/k2 of that branch,
    // z = x − x* = R sin(ω2 τ + ψ), z(0) = k1 x_c/k2, ż(0) = Vc, ψ = atan2(z(0) ω2, Vc); it returns to
    // x_c after τ2 = (π − 2ψ)/ω2. Switches then alternate: τ2 in contact, 2·t1 free.
    let (m, k1, k2, xc, v0) = (1.0, 1.0, 25.0, 0.5, 1.0);
    let model = Bilinear { m, k1, k2, xc };
    let (w1, w2) = ((k1 / m).sqrt(), (k2 / m).sqrt());
    let t1 = (xc * w1 / v0).asin() / w1;
    let vc = v0 * (w1 * t1).cos();
    let psi = (k1 * xc / k2 * w2).atan2(vc);
    let tau2 = (std::f64::consts::PI - 2.0 * psi) / w2;
    let opts = SolverOptions {
        rtol: 1e-12,
        atol: 1e-14,
        ..SolverOptions::default()
    };
    let run = integrate(
        &model,
        0.0,
        [0.0, v0],
        Mode::new(Phase::SlipNeg, 0.0),
        20.0,
        &[],
        &opts,
    )
    .unwrap();
    assert!(run.switches.len() >= 8, "{} switches", run.switches.len());
    assert!(
        (run.switches[0].t_s - t1).abs() < 1e-9 * t1,
        "first switch {} vs {t1}",
        run.switches[0].t_s
    );
    assert!(run.switches[0].entered && !run.switches[1].entered);
    for (i, w) in run.switches.windows(2).enumerate() {
        let want = if i % 2 == 0 { tau2 } else { 2.0 * t1 };
        let got = w[1].t_s - w[0].t_s;
        assert!(
            (got - want).abs() < 1e-9 * want,
            "interval {i}: {got} s against the closed form {want} s"
        );
    }
}

fn true_params() -> BladeParams {
    common::true_blade()
}

fn opts() -> SolverOptions {
    SolverOptions {
        rtol: 1e-10,
        atol: 1e-12,
        ..SolverOptions::default()
    }
}

#[test]
fn equal_stiffnesses_reproduce_the_blade_without_a_shoulder() {
    // The neck angle runs between −0.12 and +0.15 rad in this window (data/reversal/clean_10kfps.csv.gz),
    // so a contact angle of 0.08 rad is crossed; with k1_contact = k1 the moment has no kink and the
    // only difference is that steps restart at each crossing.
    let p = true_params();
    let mut ps = p;
    ps.shoulder = Some(Shoulder {
        contact_angle_rad: 0.08,
        k1_contact_nm_per_rad: p.k1_nm_per_rad,
    });
    let times: Vec<f64> = (0..=2000).map(|k| 1.70 + k as f64 * 1e-4).collect();
    let a = simulate_blade(&p, (1.70, 1.90), &times, &opts(), StickForm::Reduced).unwrap();
    let b = simulate_blade(&ps, (1.70, 1.90), &times, &opts(), StickForm::Reduced).unwrap();
    assert!(
        !b.switches.is_empty(),
        "the contact angle should be crossed"
    );
    assert!(a.switches.is_empty());
    // Compare before stick–slip starts (t < 1.80 s), where the slip is stable and trajectories
    // agree to the integration tolerance (tests/suite/model.rs shows onset after 1.80 s is truncation-seeded).
    let n = times.iter().position(|&t| t >= 1.80).unwrap();
    let worst = (0..n)
        .map(|i| (a.theta_rad[i] - b.theta_rad[i]).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-8, "θ differs by {worst} rad");
}

#[test]
fn a_shoulder_never_reached_changes_nothing() {
    let p = true_params();
    let mut ps = p;
    ps.shoulder = Some(Shoulder {
        contact_angle_rad: 1.0,
        k1_contact_nm_per_rad: 30.0 * p.k1_nm_per_rad,
    });
    let times: Vec<f64> = (0..=500).map(|k| 1.82 + k as f64 * 1e-4).collect();
    let a = simulate_blade(&p, (1.82, 1.87), &times, &opts(), StickForm::Reduced).unwrap();
    let b = simulate_blade(&ps, (1.82, 1.87), &times, &opts(), StickForm::Reduced).unwrap();
    assert!(b.switches.is_empty());
    assert_eq!(a.theta_rad, b.theta_rad);
    assert_eq!(a.transitions.len(), b.transitions.len());
}

/// The fit's shoulder only stiffens the neck: on the main job's `blade2dof+shoulder` candidate a
/// point with `k1c` below `k1` gets the failed cost without a simulation (the evaluation counter
/// does not move), and the same point with `k1c` above `k1`, or equal (the shoulder that changes
/// nothing, where the nested search starts), is simulated and scored.
#[test]
fn the_fits_shoulder_never_softens_the_neck() {
    use std::sync::atomic::Ordering;
    use wiperlab::model::ParamId;
    use wiperlab::search::{FAILED_COST, problem_for};
    let job = wiperlab::job::LoadedJob::load(&common::root().join("fits/reversal.toml"))
        .expect("the shipped job loads");
    let p = problem_for(&job, "blade2dof+shoulder".parse().unwrap()).expect("problem");
    // The sample's true blade (data/reversal/truth.json) with a contact angle of 0.1 rad.
    let value = |id: ParamId, k1c: f64| match id {
        ParamId::A => 0.88,
        ParamId::B => 69.74712740275162,
        ParamId::C => 0.56,
        ParamId::K1 => 0.029748408887917077,
        ParamId::K1c => k1c,
        ParamId::ThetaC => 0.1,
        other => panic!("unexpected free parameter {other:?}"),
    };
    let at = |k1c: f64| -> Vec<f64> { p.free.iter().map(|f| f.u_of(value(f.name, k1c))).collect() };
    let runs = || p.evaluations.load(Ordering::Relaxed);
    let before = runs();
    assert_eq!(p.cost_at(&at(0.015)), FAILED_COST);
    assert_eq!(runs(), before, "a softening shoulder is not simulated");
    for k1c in [0.029748408887917077, 0.06] {
        let c = p.cost_at(&at(k1c));
        assert!(c.is_finite() && c < FAILED_COST, "k1c {k1c}: {c}");
    }
    assert_eq!(runs(), before + 2);
}
