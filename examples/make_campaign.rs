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

#[path = "common/recording.rs"]
mod recording;

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write as _;
use std::path::Path;
use wiperlab::model::FrictionLaw;

const NOISE_PX: f64 = 0.1;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = recording::true_blade(root);
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
            let (sim, t0) = recording::simulate_window(&p)
                .unwrap_or_else(|e| panic!("{compound} {sweep}: {e}"));
            let name = format!("{compound}_{sweep}_xypts.csv");
            seed += 1;
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
            let text = recording::dltdv_text(&sim, |_, _| noise.sample(&mut rng));
            std::fs::write(out.join(&name), text).expect("write recording");
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
