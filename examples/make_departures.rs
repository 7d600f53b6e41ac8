//! Writes recordings whose tracking noise departs from the likelihood's white default:
//! `data/departures/`.
//!
//! The shipped sample's true blade (`data/reversal/blade_true.toml`) over its default reversal
//! window, simulated at rtol 1e-10, atol 1e-12 (tighter than any fit, so no model evaluation
//! reproduces it bit for bit), 10,000 frames/s, written as a DLTdv8 `xypts.csv` through the shipped
//! sample's camera model (15 µm per pixel, origin (200, 300) px, y down; point 1 the head, point 2
//! the lip tip). Each coordinate gets its own tracking noise of marginal standard deviation 0.1 px:
//!
//! - `ar1_rho06_xypts.csv`: AR(1) noise with lag-one correlation ρ = 0.6 (a tracker that
//!   correlates neighbouring frames), drawn by the recursion `e_t = ρ e_{t−1} + √(1 − ρ²)·σ·z_t`
//!   from a stationary start (written here, not with the library's noise model under test);
//! - `white_xypts.csv`: white noise, the same σ, another seed (the control);
//! - `viscous_white_xypts.csv`: white noise of the same σ (a third seed) on a blade whose friction
//!   law departs from the exponential one: `exponential_viscous` with the true A, B, C and a
//!   viscous term D|v| that is 8 % of μ_d at the median slip speed of this recording's own slipping
//!   samples (D solved by fixed-point iteration: the median moves with D).
//!
//! Run from the crate root: `cargo run --release --example make_departures`. Also writes
//! `truth.json` (the friction law and k1 of data/reversal/truth.json, the viscous recording's law
//! under `friction_viscous`, and the noise of each file).

#[path = "common/recording.rs"]
mod recording;

use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::path::Path;
use wiperlab::model::friction_curve::percentile;
use wiperlab::model::{BladeParams, FrictionLaw};
use wiperlab::simulate::blade::BladeSimulation;

const NOISE_PX: f64 = 0.1;

/// The viscous term's share of μ_d at the median slip speed.
const VISCOUS_SHARE: f64 = 0.08;

/// The median |slip speed| over the slipping samples of `sim`, m/s.
fn median_slip_speed(sim: &BladeSimulation) -> f64 {
    let mut v = sim.slip_speeds();
    v.sort_by(f64::total_cmp);
    percentile(&v, 50.0)
}

/// The true blade `p` with the viscous law whose D·v_med is [`VISCOUS_SHARE`] of μ_d(v_med) at
/// the median slip speed v_med of its own simulation: D = s/(1 − s)·(A e^(−B v_med) + C)/v_med,
/// iterated from the exponential blade's median until D moves by less than 0.1 % (the median itself
/// wanders by about 1e-4 from one D to the next: which samples slip moves with the stick–slip
/// timing). The blade, its simulation, its first frame's time and v_med.
fn viscous_blade(p: &BladeParams) -> (BladeParams, BladeSimulation, f64, f64) {
    let (a, b, c) = friction(p);
    let (mut sim, _) = recording::simulate_window(p).expect("simulate the true blade");
    let mut d = 0.0;
    for _ in 0..50 {
        let v_med = median_slip_speed(&sim);
        let next = VISCOUS_SHARE / (1.0 - VISCOUS_SHARE) * (a * (-b * v_med).exp() + c) / v_med;
        let mut q = *p;
        q.friction = FrictionLaw::ExponentialViscous {
            a,
            b_s_per_m: b,
            c,
            d_s_per_m: next,
        };
        let (next_sim, t0) = recording::simulate_window(&q).expect("simulate the viscous blade");
        if (next - d).abs() < 1e-3 * next {
            let v_med = median_slip_speed(&next_sim);
            return (q, next_sim, t0, v_med);
        }
        (sim, d) = (next_sim, next);
    }
    panic!("D did not settle in 50 iterations (last {d})");
}

/// `n` samples of stationary AR(1) noise of marginal standard deviation `sigma` and lag-one
/// correlation `rho`.
fn ar1(n: usize, sigma: f64, rho: f64, rng: &mut rand::rngs::StdRng) -> Vec<f64> {
    let z0: f64 = StandardNormal.sample(rng);
    let mut e = sigma * z0;
    let mut out = vec![e];
    for _ in 1..n {
        let z: f64 = StandardNormal.sample(rng);
        e = rho * e + (1.0 - rho * rho).sqrt() * sigma * z;
        out.push(e);
    }
    out
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let p = recording::true_blade(root);
    let out = root.join("data/departures");
    std::fs::create_dir_all(&out).expect("create data/departures");
    let (sim, t0) = recording::simulate_window(&p).expect("simulate the true blade");
    let n = sim.t_s.len();
    let mut files = Vec::new();
    for (name, rho, seed) in [
        ("ar1_rho06_xypts.csv", 0.6, 20_261_125u64),
        ("white_xypts.csv", 0.0, 20_261_126u64),
    ] {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let noise: [Vec<f64>; 4] = std::array::from_fn(|_| ar1(n, NOISE_PX, rho, &mut rng));
        let text = recording::dltdv_text(&sim, |c, i| noise[c][i]);
        std::fs::write(out.join(name), text).expect("write recording");
        files.push(format!(
            "    \"{name}\": {{ \"noise\": \"ar1\", \"sigma_px\": {NOISE_PX}, \"rho\": {rho} }}"
        ));
        println!("{name}: {n} frames from t0 = {t0:?} s, noise 0.1 px, rho {rho}");
    }
    let (q, sim, t0_viscous, v_med) = viscous_blade(&p);
    assert_eq!(t0_viscous, t0, "the same window");
    let law = q.friction;
    let name = "viscous_white_xypts.csv";
    let mut rng = rand::rngs::StdRng::seed_from_u64(20_261_127);
    let noise: [Vec<f64>; 4] = std::array::from_fn(|_| ar1(sim.t_s.len(), NOISE_PX, 0.0, &mut rng));
    std::fs::write(
        out.join(name),
        recording::dltdv_text(&sim, |c, i| noise[c][i]),
    )
    .expect("write recording");
    files.push(format!(
        "    \"{name}\": {{ \"noise\": \"ar1\", \"sigma_px\": {NOISE_PX}, \"rho\": 0.0, \"friction\": \"friction_viscous\" }}"
    ));
    println!(
        "{name}: {} frames, law {law:?}: D·v = {:.1} % of μ_d at the median slip speed {v_med:.6} m/s",
        sim.t_s.len(),
        100.0
            * (law.mu_slip(v_med)
                - FrictionLaw::Exponential {
                    a: friction(&p).0,
                    b_s_per_m: friction(&p).1,
                    c: friction(&p).2
                }
                .mu_slip(v_med))
            / law.mu_slip(v_med)
    );
    let friction_viscous = serde_json::to_string(&law).expect("the law as JSON");
    let truth = format!(
        "{{\n  \"t0_s\": {t0:?},\n  \"params\": {{ \"A\": {:?}, \"B\": {:?}, \"C\": {:?}, \"k1\": {:?} }},\n  \"friction_viscous\": {friction_viscous},\n  \"files\": {{\n{}\n  }}\n}}\n",
        friction(&p).0,
        friction(&p).1,
        friction(&p).2,
        p.k1_nm_per_rad,
        files.join(",\n")
    );
    std::fs::write(out.join("truth.json"), truth).expect("write truth.json");
}

/// The exponential law's (A, B, C).
fn friction(p: &BladeParams) -> (f64, f64, f64) {
    match p.friction {
        wiperlab::model::FrictionLaw::Exponential { a, b_s_per_m, c } => (a, b_s_per_m, c),
        other => panic!("blade_true.toml has an exponential friction law, not {other:?}"),
    }
}
