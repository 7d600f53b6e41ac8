//! Freed geometry recovered by the fit (issue 17, point 3). Each test makes a recording with the
//! model from the shipped sample's blade (`data/reversal/blade_true.toml`) with one geometry
//! parameter changed through `ParamId::set` (as the fit frees it), simulated at rtol 1e-10 (tighter
//! than the fit's 1e-7, so no model evaluation reproduces the data bit for bit), written as a DLTdv
//! file through the sample's camera model (15 µm/px, origin (200, 300)) with Gaussian tracking noise
//! of 0.1 px per coordinate (as the sample: data/reversal/README.md). A small job (8 particles × 6
//! iterations, 25 polish iterations, about 115 simulations), starting from the sample's blade file,
//! fits that parameter and the friction offset C with the default objective (the likelihood),
//! bands and solver.
//!
//! Reference: the values the recording was simulated with. Asserted: both parameters within 5 %
//! (the single-recording tests' tolerance, tests/suite/fit_recovery.rs) and the result's `determined`
//! flag set for the geometry parameter (1σ below 10 % of its search range: the recording determines
//! it). The two parameters chosen are those the physics says the recording sees: the head mass,
//! with the head's frequency held, moves the head–link stick–slip cycle, whose fundamental follows
//! √(f_head² + K_link/(4π² M)) (issue 17), and so the low band's line; the preload hd sets the
//! normal force, hence the friction force and the stick–slip. Both come out determined.
//! `cargo test --release --test suite geometry_fit:: -- --nocapture` prints the numbers.

use crate::common;

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use wiperlab::fit::FitOutcome;
use wiperlab::fit::run_fit;
use wiperlab::job::LoadedJob;
use wiperlab::model::{BladeParams, ParamId};

/// The sample's friction offset C (data/reversal/blade_true.toml `[friction] c`), left unchanged.
const C_TRUE: f64 = 0.56;

/// Makes the recording with `id` set to `value` on the sample's blade, fits `id` within `bounds`
/// and C within [0.3, 0.8], prints and checks the recovery; returns the fit and the true blade.
fn recover(id: ParamId, value: f64, bounds: [f64; 2], seed: u64) -> (FitOutcome, BladeParams) {
    let base = common::true_blade();
    let mut truth = base;
    assert!(id.set(&mut truth, value));
    let (sim, t0) =
        common::recording_of(&truth).expect("the changed blade keeps contact over the window");
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let noise = Normal::new(0.0, 0.1).unwrap();
    let case = common::write_case(
        &format!("geometry_{id}"),
        &sim,
        &base,
        &format!("{{\"{id}\": {value}, \"C\": {C_TRUE}}}"),
        &mut || noise.sample(&mut rng),
    );
    let dir = case.path();
    let job = format!(
        r#"name = "geometry"
blade = "blade.toml"
{recording}[fit]
particles = 8
swarm_iterations = 6
polish_iterations = 25
seed = 3
[fit.parameters]
C = [0.3, 0.8]
{id} = [{lo:?}, {hi:?}]
[truth]
json = "truth.json"
keys = {{ {id} = "/{id}", C = "/C" }}
"#,
        recording = common::dltdv_recording("rec_xypts.csv", t0),
        lo = bounds[0],
        hi = bounds[1],
    );
    std::fs::write(dir.join("job.toml"), job).unwrap();
    let loaded = LoadedJob::load(&dir.join("job.toml")).unwrap();
    let out = run_fit(&loaded, false).unwrap();
    let r = &out.result;
    eprintln!(
        "{id}: cost {:.3}, {} evaluations ({} failed)",
        r.cost, r.model_evaluations, r.failed_evaluations
    );
    for p in &r.parameters {
        eprintln!(
            "  {}: fitted {:.6e} ± {:.2e} true {:.6e} rel err {:+.3} %, determined {}",
            p.name,
            p.value,
            p.std_error,
            p.true_value.unwrap(),
            100.0 * p.rel_error.unwrap(),
            p.determined
        );
    }
    for pk in &r.peaks {
        eprintln!(
            "  peak {}: {:.3} vs {:.3} Hz",
            pk.band, pk.model_hz, pk.measured_hz
        );
    }
    for p in &r.parameters {
        let err = p.rel_error.unwrap();
        assert!(err.abs() < 0.05, "{} off by {:+.2} %", p.name, 100.0 * err);
    }
    let fitted = r.parameters.iter().find(|p| p.name == id).unwrap();
    assert!(
        fitted.determined && !r.undetermined.contains(&id),
        "the recording should determine {id}: {:?}",
        r.warnings
    );
    assert_eq!(id.get(&out.best_params), Some(fitted.value));
    (out, truth)
}

/// A head 1.3 times the sample's (0.195 kg instead of 0.15 kg), its 20 Hz held
/// (k0 = M (2π·20 Hz)²); the fitted blade keeps the 20 Hz head in closed form.
#[test]
fn fit_recovers_a_changed_head_mass() {
    let (out, truth) = recover(ParamId::HeadMass, 0.195, [0.1, 0.3], 17);
    assert!(
        (out.best_params.head_freq_hz() - truth.head_freq_hz()).abs() < 1e-9,
        "the fitted blade's head is at {} Hz, not the blade file's {} Hz",
        out.best_params.head_freq_hz(),
        truth.head_freq_hz()
    );
}

/// A preload 1.2 times the sample's (h_d 0.561 mm instead of 0.467 mm), searched over 0.7–1.5×.
#[test]
fn fit_recovers_a_changed_preload() {
    let hd = common::true_blade().hd_m;
    recover(ParamId::Hd, 1.2 * hd, [0.7 * hd, 1.5 * hd], 18);
}
