//! The hybrid (event-driven) integrator on stick–slip oscillators with known solutions.
//! Reference values: physics.md §3.1 (closed form, derived again below), §0.4 table (rows computed
//! independently with SciPy DOP853/Radau/LSODA agreeing to ~1e-10; quoted to 7–8 digits).

use wiperlab::model::FrictionLaw;
use wiperlab::model::belt::Belt;
use wiperlab::simulate::SolverOptions;

fn tight() -> SolverOptions {
    SolverOptions {
        rtol: 1e-12,
        atol: 1e-14,
        ..Default::default()
    }
}

/// Closed form of physics.md §3.1 for m ẍ + k x = F_f, Coulomb friction F_s > F_k, belt speed v_b:
/// t_slip = (2/ω)(π − atan(ωΔ/v_b)), t_stick = 2(F_s − F_k)/(k v_b), x_e = (2F_k − F_s)/k.
fn coulomb_closed_form(m: f64, k: f64, vb: f64, fs: f64, fk: f64) -> (f64, f64, f64) {
    let w = (k / m).sqrt();
    let delta = (fs - fk) / k;
    let t_slip = 2.0 / w * (std::f64::consts::PI - (w * delta / vb).atan());
    let t_stick = 2.0 * (fs - fk) / (k * vb);
    (t_slip, t_stick, (2.0 * fk - fs) / k)
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn undamped_coulomb_belt_matches_closed_form_to_1e8() {
    for (m, k, vb) in [
        (1.0, 4.0 * std::f64::consts::PI.powi(2), 0.1),
        (1.0, 1.0, 0.2),
    ] {
        let (fs, fk) = (1.0, 0.6);
        let belt = Belt {
            mass_kg: m,
            k_n_per_m: k,
            c_ns_per_m: 0.0,
            v_belt_m_per_s: vb,
            normal_n: 1.0,
            law: FrictionLaw::Coulomb { mu_s: fs, mu_k: fk },
        };
        let (t_slip, t_stick, x_e) = coulomb_closed_form(m, k, vb, fs, fk);
        let period = t_slip + t_stick;
        let cyc = belt
            .limit_cycle(0.0, 4.5 * period, &tight())
            .unwrap()
            .expect("stick-slip cycle");
        eprintln!(
            "k = {k}: T = {:.12} (closed form {period:.12}), rel err {:.2e}",
            cyc.period_s,
            rel(cyc.period_s, period)
        );
        assert!(rel(cyc.period_s, period) < 1e-8);
        assert!(rel(cyc.t_slip_s, t_slip) < 1e-8);
        assert!(rel(cyc.t_stick_s, t_stick) < 1e-8);
        assert!((cyc.x_stick_onset_m - x_e).abs() < 1e-9 * x_e.abs().max(1e-3));
    }
    // The closed form itself against the physics.md §0.4 table (7 digits): T = 1.0221888 s and
    // 8.0688879 s.
    let (a, b, _) = coulomb_closed_form(1.0, 4.0 * std::f64::consts::PI.powi(2), 0.1, 1.0, 0.6);
    assert!((a + b - 1.0221888).abs() < 1e-7);
    let (a, b, _) = coulomb_closed_form(1.0, 1.0, 0.2, 1.0, 0.6);
    assert!((a + b - 8.0688879).abs() < 1e-7);
}

#[test]
fn damped_coulomb_belt_matches_semi_analytic_table() {
    // physics.md §0.4 row 3: ζ = 0.05, v_b = 0.05: t_slip 0.7581836, t_stick 0.3128486, T 1.0710322.
    let k = 4.0 * std::f64::consts::PI.powi(2);
    let c = 2.0 * 0.05 * k.sqrt();
    let belt = Belt {
        mass_kg: 1.0,
        k_n_per_m: k,
        c_ns_per_m: c,
        v_belt_m_per_s: 0.05,
        normal_n: 1.0,
        law: FrictionLaw::Coulomb {
            mu_s: 1.0,
            mu_k: 0.6,
        },
    };
    let cyc = belt.limit_cycle(0.0, 5.0, &tight()).unwrap().unwrap();
    assert!((cyc.t_slip_s - 0.7581836).abs() < 1e-6, "{}", cyc.t_slip_s);
    assert!(
        (cyc.t_stick_s - 0.3128486).abs() < 1e-6,
        "{}",
        cyc.t_stick_s
    );
    assert!((cyc.period_s - 1.0710322).abs() < 1e-6);
    // Negative case, same row with v_b = 0.1: no stick–slip cycle, the mass decays to sliding.
    let fast = Belt {
        v_belt_m_per_s: 0.1,
        ..belt
    };
    assert!(fast.limit_cycle(0.0, 20.0, &tight()).unwrap().is_none());
}

#[test]
fn leine_block_on_belt_matches_reference() {
    // physics.md §3.3 / §0.4: m = k = F_s = 1, δ = 3 s/m, v_dr = 0.2: t_slip 4.2959995,
    // t_stick 7.7050318, T 12.0010313.
    let belt = Belt {
        mass_kg: 1.0,
        k_n_per_m: 1.0,
        c_ns_per_m: 0.0,
        v_belt_m_per_s: 0.2,
        normal_n: 1.0,
        law: FrictionLaw::Leine {
            mu_s: 1.0,
            delta_s_per_m: 3.0,
        },
    };
    let cyc = belt.limit_cycle(0.0, 40.0, &tight()).unwrap().unwrap();
    eprintln!("Leine: {cyc:?}");
    assert!((cyc.t_slip_s - 4.2959995).abs() < 1e-6);
    assert!((cyc.t_stick_s - 7.7050318).abs() < 1e-6);
    assert!((cyc.period_s - 12.0010313).abs() < 1e-6);
    assert!((cyc.x_stick_onset_m - -0.5410064).abs() < 1e-6);
}

#[test]
fn seed_friction_law_in_belt_oscillator() {
    // physics.md §3.4: m = k = N = 1, A = C = 0.5, B = 3 s/m, v_dr = 0.2: t_slip 4.5590598,
    // t_stick 4.9039561, T 9.4630159, x_e 0.0192088.
    let belt = Belt {
        mass_kg: 1.0,
        k_n_per_m: 1.0,
        c_ns_per_m: 0.0,
        v_belt_m_per_s: 0.2,
        normal_n: 1.0,
        law: FrictionLaw::Exponential {
            a: 0.5,
            b_s_per_m: 3.0,
            c: 0.5,
        },
    };
    let cyc = belt.limit_cycle(0.0, 30.0, &tight()).unwrap().unwrap();
    assert!((cyc.t_slip_s - 4.5590598).abs() < 1e-6);
    assert!((cyc.t_stick_s - 4.9039561).abs() < 1e-6);
    assert!((cyc.period_s - 9.4630159).abs() < 1e-6);
    assert!((cyc.x_stick_onset_m - 0.0192088).abs() < 1e-6);
    // B → ∞ tends to Coulomb with F_s = 1, F_k = 0.5 (C): closed form.
    let (a, b, _) = coulomb_closed_form(1.0, 1.0, 0.2, 1.0, 0.5);
    let steep = Belt {
        law: FrictionLaw::Exponential {
            a: 0.5,
            b_s_per_m: 1e5,
            c: 0.5,
        },
        ..belt
    };
    let cyc = steep
        .limit_cycle(0.0, 3.5 * (a + b), &tight())
        .unwrap()
        .unwrap();
    eprintln!("B=1e5: T = {} vs Coulomb {}", cyc.period_s, a + b);
    assert!(rel(cyc.period_s, a + b) < 1e-3);
}
