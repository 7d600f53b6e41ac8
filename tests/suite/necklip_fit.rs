//! The neck/lip model as a fit candidate on the shipped recording (data/reversal/): it runs across
//! the blade's flip, leaves the flip's guard out of the measured spectra, and is never chosen for a
//! job with a low band, which it imposes from the head track instead of explaining.

use crate::common;

use wiperlab::fit::run_fit;
use wiperlab::job::LoadedJob;
use wiperlab::simulate::blade::ModelKind;

/// The main job's bands (fits/reversal.toml).
const MAIN_JOB_BANDS: &[(&str, [f64; 2], usize)] =
    &[("low", [30.0, 300.0], 4096), ("high", [500.0, 5000.0], 512)];

#[test]
fn necklip_is_fitted_but_not_chosen_for_a_low_band() {
    let root = common::root();
    let tmp = common::temp_dir("necklip_fit");
    let dir = tmp.path();
    // The main job's recording and bands (fits/reversal.toml) on the true blade, with a tiny
    // optimiser budget and the swarm's looser tolerance (rtol 1e-6): this checks the plumbing, not
    // the fitted values (docs/model-choice.md, "Which model the scene needs"). Here blade2dof also has the
    // lower cost, so what shows the rule is the reason.
    let job = format!(
        r#"name = "necklip_fit"
blade = "{root}/data/reversal/blade_true.toml"

{recording}
{spectrum}
[solver]
rtol = 1e-6
atol = 1e-8

[fit]
particles = 2
swarm_iterations = 0
polish_iterations = 2
seed = 1
models = ["necklip", "blade2dof"]

[fit.parameters]
k1 = [0.005, 0.15]
"#,
        root = root.display(),
        recording = common::sample_recording(),
        spectrum = common::spectrum_bands(MAIN_JOB_BANDS),
    );
    let path = dir.join("job.toml");
    std::fs::write(&path, job).unwrap();
    let job = LoadedJob::load(&path).unwrap();
    let out = run_fit(&job, false).unwrap();
    let trials = &out.result.model_trials;
    assert_eq!(trials.len(), 2);
    let nl = trials
        .iter()
        .find(|t| t.model.kind == ModelKind::Necklip)
        .unwrap();
    eprintln!(
        "necklip: cost {:.4}, {} runs, {:.1} s; {}",
        nl.cost, nl.model_evaluations, nl.wall_time_s, nl.reason
    );
    for t in trials {
        eprintln!(
            "{}: cost {:.4}, {} runs; {}",
            t.model, t.cost, t.model_evaluations, t.reason
        );
    }
    // It produced a model (a cost below the failure value 1e9) …
    assert!(nl.cost < 1e8, "every neck/lip run failed: cost {}", nl.cost);
    // … but the low band disqualifies it, whatever its cost.
    assert!(!nl.chosen);
    assert!(nl.reason.contains("imposes band 'low'"), "{}", nl.reason);
    assert_eq!(out.result.model.kind, ModelKind::Blade2dof);
    assert!(!out.result.model.shoulder);
}
