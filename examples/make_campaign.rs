//! Writes the shipped example campaign's model-made recordings: `data/campaign/`.
//!
//! Six recordings of one blade (`data/reversal/blade_true.toml`): three sweep speeds (drive
//! angular frequency 0.8, 1 and 1.25 times the sample's) by two rubber compounds (friction law
//! offsets C = 0.56, the sample's, and C = 0.50; A and B as the sample's). Each is simulated at
//! rtol 1e-10 (tighter than any fit uses, so no model evaluation reproduces it bit for bit) over
//! the model's default reversal window (drive phase π/2 to 3π/2), 10,000 fps, and written as a DLTdv8 `xypts.csv` through
//! the shipped sample's camera model (15 µm per pixel, origin (200, 300) px, y down; point 1 the
//! head, point 2 the lip tip) with Gaussian tracking noise of 0.1 px (seeded).
//!
//! Run from the crate root: `cargo run --release --example make_campaign`. Writes the recordings,
//! `conditions.csv` (per recording: t0_s, drive_omega_rad_per_s and the condition labels) and
//! `truth.csv` (the true C and k1 of each recording).

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write as _;
use std::path::Path;
use wiperlab::model::{BladeParams, FrictionLaw, StickForm};
use wiperlab::simulate::SolverOptions;
use wiperlab::simulate::blade::{BladeSimulation, default_window, simulate_blade};

/// Metres per pixel and the pixel origin of the sample's camera (data/reversal/README.md).
const M_PER_PX: f64 = 1.5e-5;
const ORIGIN_PX: (f64, f64) = (200.0, 300.0);
/// The camera's horizontal origin on the model's x axis, m (the sample's `a`).
const X_ORIGIN_M: f64 = 0.1;
const FPS: f64 = 10_000.0;
const NOISE_PX: f64 = 0.1;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base: BladeParams = toml::from_str(
        &std::fs::read_to_string(root.join("data/reversal/blade_true.toml"))
            .expect("read data/reversal/blade_true.toml"),
    )
    .expect("parse blade_true.toml");
    let out = root.join("data/campaign");
    std::fs::create_dir_all(&out).expect("create data/campaign");
    let mut conditions =
        String::from("recording,t0_s,drive_omega_rad_per_s,compound,sweep,repeat\n");
    let mut truth = String::from("recording,C,k1\n");
    let noise = Normal::new(0.0, NOISE_PX).expect("noise level");
    let mut seed = 20_261_122u64;
    for (compound, c) in [("soft", 0.56), ("hard", 0.50)] {
        for (sweep, factor) in [("slow", 0.8), ("normal", 1.0), ("fast", 1.25)] {
            let mut p = base;
            p.drive_omega_rad_per_s *= factor;
            if let FrictionLaw::Exponential { c: ci, .. } = &mut p.friction {
                *ci = c;
            }
            let (t0, t1) = default_window(&p);
            let n = ((t1 - t0) * FPS) as usize;
            let times: Vec<f64> = (0..n).map(|k| t0 + k as f64 / FPS).collect();
            let opts = SolverOptions {
                rtol: 1e-10,
                atol: 1e-12,
                ..SolverOptions::default()
            };
            let window = (t0, *times.last().expect("frames"));
            let sim = simulate_blade(&p, window, &times, &opts, StickForm::Reduced)
                .unwrap_or_else(|e| panic!("{compound} {sweep}: {e}"));
            let name = format!("{compound}_{sweep}_xypts.csv");
            seed += 1;
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
            let mut draw = || noise.sample(&mut rng);
            std::fs::write(out.join(&name), dltdv_text(&sim, &mut draw)).expect("write recording");
            let _ = writeln!(
                conditions,
                "{name},{t0:?},{:?},{compound},{sweep},1",
                p.drive_omega_rad_per_s
            );
            let _ = writeln!(truth, "{name},{c:?},{:?}", p.k1_nm_per_rad);
            println!("{name}: {} frames from t0 = {t0:.6} s", sim.t_s.len());
        }
    }
    std::fs::write(out.join("conditions.csv"), conditions).expect("write conditions.csv");
    std::fs::write(out.join("truth.csv"), truth).expect("write truth.csv");
}

/// The simulation as DLTdv8 `xypts.csv` text: `x_px = X0 + (x − a)/S`, `y_px = Y0 − y/S` (y down)
/// for the head (x = v, y = −u) and the lip tip (x = v3, y = −reach, the glass), `%.4f`.
fn dltdv_text(sim: &BladeSimulation, noise_px: &mut dyn FnMut() -> f64) -> String {
    let mut csv = String::from("pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y\n");
    let px_x = |x: f64| ORIGIN_PX.0 + (x - X_ORIGIN_M) / M_PER_PX;
    let px_y = |y: f64| ORIGIN_PX.1 - y / M_PER_PX;
    for i in 0..sim.t_s.len() {
        let _ = writeln!(
            csv,
            "{:.4},{:.4},{:.4},{:.4}",
            px_x(sim.v_m[i]) + noise_px(),
            px_y(-sim.u_m[i]) + noise_px(),
            px_x(sim.v3_m[i]) + noise_px(),
            px_y(-sim.reach_m) + noise_px()
        );
    }
    csv
}
