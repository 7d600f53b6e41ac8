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
//! - `white_xypts.csv`: white noise, the same σ, another seed (the control).
//!
//! Run from the crate root: `cargo run --release --example make_departures`. Also writes
//! `truth.json` (the friction law and k1 of data/reversal/truth.json, and the noise of each file).

#[path = "common/recording.rs"]
mod recording;

use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use std::path::Path;
use wiperlab::model::BladeParams;

const NOISE_PX: f64 = 0.1;

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
    let truth = format!(
        "{{\n  \"t0_s\": {t0:?},\n  \"params\": {{ \"A\": {:?}, \"B\": {:?}, \"C\": {:?}, \"k1\": {:?} }},\n  \"files\": {{\n{}\n  }}\n}}\n",
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
