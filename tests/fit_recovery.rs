//! The fit recovers known parameters from a recording the model produced (at a tighter tolerance
//! than the fit uses, so the data are not bit-identical to any model evaluation), written as a
//! DLTdv file through the same camera model as the shipped sample (15 µm/px, origin (200, 300)).

mod common;

use wiperlab::fit::job::LoadedJob;
use wiperlab::fit::run_fit;
use wiperlab::model::{BladeParams, FrictionLaw, StickForm};
use wiperlab::simulate::SolverOptions;
use wiperlab::simulate::blade::{default_window, simulate_blade};

#[test]
fn fit_recovers_friction_c_and_neck_stiffness() {
    let base: BladeParams = common::true_blade();
    // Known parameters: the sample's, with C and k1 moved off the sample's values.
    let (c_true, k1_true) = (0.5, 0.026);
    let mut truth = base;
    truth.k1_nm_per_rad = k1_true;
    if let FrictionLaw::Exponential { c, .. } = &mut truth.friction {
        *c = c_true;
    }
    let (t0, t1) = default_window(&truth);
    let fps = 1e4;
    let n = ((t1 - t0) * fps) as usize;
    let times: Vec<f64> = (0..n).map(|k| t0 + k as f64 / fps).collect();
    let sim = simulate_blade(
        &truth,
        (t0, *times.last().unwrap()),
        &times,
        &SolverOptions {
            rtol: 1e-10,
            atol: 1e-12,
            ..SolverOptions::default()
        },
        StickForm::Reduced,
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!("wiperlab_fit_recovery_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    common::write_dltdv(&dir.join("rec_xypts.csv"), &sim, &mut || 0.0);
    std::fs::write(dir.join("blade.toml"), toml::to_string(&base).unwrap()).unwrap();
    std::fs::write(
        dir.join("truth.json"),
        format!("{{\"C\": {c_true}, \"k1\": {k1_true}}}"),
    )
    .unwrap();
    let job = format!(
        r#"name = "recovery"
blade = "blade.toml"
{recording}[fit]
particles = 8
swarm_iterations = 6
polish_iterations = 25
seed = 3
[fit.parameters]
C = [0.3, 0.8]
k1 = [0.01, 0.05]
[truth]
json = "truth.json"
keys = {{ C = "/C", k1 = "/k1" }}
"#,
        recording = common::dltdv_recording("rec_xypts.csv", t0),
    );
    std::fs::write(dir.join("job.toml"), job).unwrap();
    let loaded = LoadedJob::load(&dir.join("job.toml")).unwrap();
    let out = run_fit(&loaded, false).unwrap();
    for p in &out.result.parameters {
        eprintln!(
            "{}: fitted {:.6} true {:.6} rel err {:+.3}%",
            p.name,
            p.value,
            p.true_value.unwrap(),
            100.0 * p.rel_error.unwrap()
        );
    }
    for pk in &out.result.peaks {
        eprintln!(
            "peak {}: {:.3} vs {:.3} Hz",
            pk.band, pk.model_hz, pk.measured_hz
        );
        assert!(pk.rel_diff.abs() < 0.01);
    }
    for p in &out.result.parameters {
        assert!(
            p.rel_error.unwrap().abs() < 0.05,
            "{} off by {}",
            p.name,
            p.rel_error.unwrap()
        );
    }
    // The result carries the blade's modes at the fitted parameters: one stick mode and the two
    // slip modes at each of the window's three speeds (model::modes::WINDOW_SPEED_FRACTIONS).
    assert_eq!(out.result.modes.len(), 7, "{:?}", out.result.warnings);
    assert!(
        out.result
            .modes
            .iter()
            .all(|m| m.freq_hz.is_finite() && m.freq_hz > 0.0)
    );
    std::fs::remove_dir_all(&dir).ok();
}
