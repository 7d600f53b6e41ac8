//! The fit recovers known parameters from a recording the model produced (at a tighter tolerance
//! than the fit uses, so the data are not bit-identical to any model evaluation), written as a
//! DLTdv file through the same camera model as the shipped sample (15 µm/px, origin (200, 300)).

use crate::common;

use wiperlab::fit::{FitWarning, run_fit};
use wiperlab::job::LoadedJob;
use wiperlab::model::{BladeParams, FrictionLaw};
use wiperlab::simulate::failure::FailureCause;

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
    let (sim, t0) = common::recording_of(&truth).unwrap();
    let case = common::write_case(
        "fit_recovery",
        &sim,
        &base,
        &format!("{{\"C\": {c_true}, \"k1\": {k1_true}}}"),
        &mut || 0.0,
    );
    let dir = case.path();
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
}

/// Counts add up across candidates and the bootstrap, and the failure warning fires: the preload
/// h_d is freed down to 0.2 of its value, where the contact lifts off (tests/suite/hard_cases.rs: at half
/// the sample's preload the normal force reaches zero inside the window), so a large share of the
/// evaluations fail. Two candidates and a polish-only bootstrap run on the same recording. The
/// feature cost keeps the job's evaluations to its swarm, polishes and curvature: with the
/// likelihood, each fit and replicate also settles its optimum (about 50 more evaluations each, all
/// succeeding), which brought the chosen model's failed share from above to 5 % (13 of 237), below
/// the tenth at which the warning fires.
#[test]
fn evaluation_and_failure_counts_add_up_and_failures_are_reported() {
    let truth = common::true_blade();
    let (sim, t0) = common::recording_of(&truth).unwrap();
    let tmp = common::temp_dir("fit_counts");
    let dir = tmp.path();
    common::write_dltdv(&dir.join("rec_xypts.csv"), &sim, &mut || 0.0);
    std::fs::write(dir.join("blade.toml"), toml::to_string(&truth).unwrap()).unwrap();
    let hd = truth.hd_m;
    let job = format!(
        r#"name = "counts"
blade = "blade.toml"
{recording}[fit]
particles = 6
swarm_iterations = 3
polish_iterations = 6
models = ["head1dof", "blade2dof"]
objective = "features"
[fit.parameters]
C = [0.3, 0.8]
hd = [{lo}, {hi}]
[fit.uncertainty]
bootstrap = 2
full_refit = false
polish_iterations = 4
"#,
        recording = common::dltdv_recording("rec_xypts.csv", t0),
        lo = 0.2 * hd,
        hi = 1.2 * hd,
    );
    std::fs::write(dir.join("job.toml"), job).unwrap();
    let loaded = LoadedJob::load(&dir.join("job.toml")).unwrap();
    let r = run_fit(&loaded, false).unwrap().result;
    let trials = &r.model_trials;
    assert_eq!(trials.len(), 2);
    let evals: usize = trials.iter().map(|t| t.model_evaluations).sum();
    let failed: usize = trials.iter().map(|t| t.failed_evaluations).sum();
    eprintln!(
        "evaluations {evals} ({failed} failed); per trial {:?}; warnings {:?}",
        trials
            .iter()
            .map(|t| (t.model_evaluations, t.failed_evaluations))
            .collect::<Vec<_>>(),
        r.warnings
    );
    assert_eq!(r.model_evaluations, evals);
    assert_eq!(r.failed_evaluations, failed);
    for t in trials {
        assert!(t.failed_evaluations <= t.model_evaluations);
        // Each restart's history ends at no more evaluations than the trial counted.
        let last = r.history.iter().map(|h| h.evaluations).max().unwrap_or(0);
        if t.chosen {
            assert!(last <= t.model_evaluations);
        }
    }
    assert!(failed > 0, "no evaluation failed down to 0.2 h_d");
    // The warning counts the chosen model's evaluations, bootstrap replicates included, by
    // cause: here the lip tip leaving the glass.
    let chosen = trials.iter().find(|t| t.chosen).unwrap();
    assert!(
        r.warnings.iter().any(|w| matches!(
            w,
            FitWarning::FailedEvaluations { failed, evaluations, causes, first }
                if *failed == chosen.failed_evaluations
                    && *evaluations == chosen.model_evaluations
                    && causes.get(&FailureCause::ContactLoss).is_some_and(|n| *n > 0)
                    && causes.values().sum::<usize>() == *failed
                    && first.as_deref().is_some_and(|f| f.contains("contact lost"))
        )),
        "{:?}",
        r.warnings
    );
    assert_eq!(r.first_failure.is_some(), chosen.failed_evaluations > 0);
}

/// Friction laws as candidates (`[fit] laws`) on a recording the exponential law made: the
/// default model fitted with each law (`blade2dof@exponential`, `blade2dof@exponential_viscous`,
/// D freed in its default [0, 2] s/m beside the job's C and k1). The viscous law contains the
/// exponential one at D = 0, where its search starts, so its fit ends no less likely; the truth has
/// D = 0, so the extra parameter cannot buy a TIC lower by more than 2 except by chance (for a
/// likelihood-ratio statistic on one degree of freedom, well under 1 % of recordings), and the
/// exponential law, with fewer parameters, is reported with its curve.
#[test]
fn a_law_the_recording_does_not_need_is_not_chosen() {
    let base: BladeParams = common::true_blade();
    let (sim, t0) = common::recording_of(&base).unwrap();
    let case = common::write_case("fit_laws", &sim, &base, "{}", &mut || 0.0);
    let dir = case.path();
    let job = format!(
        r#"name = "laws"
blade = "blade.toml"
{recording}[fit]
particles = 8
swarm_iterations = 6
polish_iterations = 25
seed = 3
laws = ["exponential_viscous", "exponential"]
[fit.parameters]
C = [0.3, 0.8]
k1 = [0.01, 0.05]
"#,
        recording = common::dltdv_recording("rec_xypts.csv", t0),
    );
    std::fs::write(dir.join("job.toml"), job).unwrap();
    let loaded = LoadedJob::load(&dir.join("job.toml")).unwrap();
    let out = run_fit(&loaded, false).unwrap();
    let r = &out.result;
    let names: Vec<String> = r.model_trials.iter().map(|t| t.model.name()).collect();
    assert_eq!(
        names,
        ["blade2dof@exponential", "blade2dof@exponential_viscous"]
    );
    let (exp, visc) = (&r.model_trials[0], &r.model_trials[1]);
    for t in &r.model_trials {
        eprintln!(
            "{}: cost {:.4}, ΔTIC {:?}, {:?}; {}",
            t.model,
            t.cost,
            t.evidence.as_ref().and_then(|e| e.delta_tic),
            t.friction,
            t.reason
        );
    }
    use wiperlab::model::ParamId;
    assert_eq!(exp.parameters, [ParamId::C, ParamId::K1]);
    assert_eq!(visc.parameters, [ParamId::C, ParamId::D, ParamId::K1]);
    assert!(matches!(
        exp.friction,
        Some(FrictionLaw::Exponential { .. })
    ));
    assert!(matches!(
        visc.friction,
        Some(FrictionLaw::ExponentialViscous { d_s_per_m, .. }) if (0.0..=2.0).contains(&d_s_per_m)
    ));
    assert!(visc.cost <= exp.cost + 1e-9, "{} > {}", visc.cost, exp.cost);
    assert!(exp.chosen && !visc.chosen);
    assert_eq!(r.model.name(), "blade2dof@exponential");
    let lrt = visc.evidence.as_ref().and_then(|e| e.lrt.as_ref()).unwrap();
    assert_eq!((lrt.against, lrt.df), (exp.model, 1));
    let curve = r.friction_curve.as_ref().expect("the chosen law's curve");
    assert!(matches!(curve.fitted_law, FrictionLaw::Exponential { .. }));
}
