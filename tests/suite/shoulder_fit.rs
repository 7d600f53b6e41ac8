//! Shoulder contact recovered by the fit: a recording the model made with a piecewise neck stiffness
//! (at a tighter tolerance than the fit uses), written as a DLTdv file through the shipped sample's
//! camera model (15 µm/px, origin (200, 300)), fitted with and without the shoulder. The shoulder
//! candidate must win on AIC and recover k1_contact within 5 % (issue 6, "Done when"). The opposite
//! case, a recording made without a shoulder, is the main job (tests/suite/cli.rs asserts `blade2dof` wins).

use crate::common;

use wiperlab::fit::run_fit;
use wiperlab::job::LoadedJob;
use wiperlab::model::{BladeParams, Shoulder};

#[test]
fn fit_prefers_and_recovers_the_shoulder() {
    prefers_and_recovers_the_shoulder(
        "shoulder_fit",
        // The swarms at rtol 1e-6 as the main job's (fits/reversal.toml); the polish and everything
        // reported at [solver]'s 1e-8.
        "particles = 10\nswarm_iterations = 8\npolish_iterations = 40\nswarm_rtol = 1e-6\n",
    );
}

/// The same with the CMA-ES search (`[fit.search] method = "cmaes"`), which also ends at least as
/// likely as the truth (the result's shortfall is at most its 0.1-nat tolerance). About 45 CPU-s
/// for a search that is not the default, so it runs on request:
/// `cargo test --release --test suite shoulder_fit:: -- --include-ignored`.
#[test]
#[ignore = "CMA-ES is not the default search; run with --include-ignored"]
fn the_cmaes_search_prefers_and_recovers_the_shoulder() {
    let out = prefers_and_recovers_the_shoulder(
        "shoulder_fit_cmaes",
        "polish_iterations = 40\n[fit.search]\nmethod = \"cmaes\"\nmax_evaluations = 600\n",
    );
    let truth = out.result.truth_cost.expect("the truth's cost");
    assert!(
        out.result.cost - truth <= wiperlab::fit::SHORTFALL_TOLERANCE_NATS,
        "cost {:.3} nats, the truth's {truth:.3}",
        out.result.cost
    );
    for t in &out.result.model_trials {
        assert!(t.reason.contains("CMA-ES: "), "{}", t.reason);
        assert!(t.model_evaluations > 0);
    }
}

/// Fits a recording made with a shoulder by `blade2dof` and `blade2dof+shoulder` with the search
/// settings `search` (lines of `[fit]`, and tables after it), asserts that the shoulder is chosen
/// and k1_contact recovered within 5 %, and returns the fit.
fn prefers_and_recovers_the_shoulder(name: &str, search: &str) -> wiperlab::fit::FitOutcome {
    let base: BladeParams = common::true_blade();
    // Known parameters: a free neck 4x softer than the sample's, touching the shoulder at 0.06 rad
    // (|θ| reaches ~0.12-0.15 rad in slip, data/reversal/clean_10kfps.csv.gz) with k1_contact = 0.03.
    let (k1_free, theta_c, k1c) = (0.0075, 0.06, 0.03);
    let mut truth = base;
    truth.k1_nm_per_rad = k1_free;
    truth.shoulder = Some(Shoulder {
        contact_angle_rad: theta_c,
        k1_contact_nm_per_rad: k1c,
    });
    let (sim, t0) = common::recording_of(&truth).unwrap();
    assert!(
        !sim.switches.is_empty(),
        "the recording should touch the shoulder"
    );
    let case = common::write_case(
        name,
        &sim,
        &base,
        &format!("{{\"k1\": {k1_free}, \"k1c\": {k1c}, \"theta_c\": {theta_c}}}"),
        &mut || 0.0,
    );
    let dir = case.path();
    let job = format!(
        r#"name = "shoulder"
blade = "blade.toml"
{recording}[solver]                 # as the main job (fits/reversal.toml)
rtol = 1e-8
atol = 1e-10
[fit]
seed = 3
models = ["blade2dof", "blade2dof+shoulder"]
{search}[fit.shoulder]
k1c = [0.01, 0.06]
theta_c = [0.03, 0.1]
[fit.parameters]
k1 = [0.002, 0.05]
[truth]
json = "truth.json"
keys = {{ k1 = "/k1", k1c = "/k1c", theta_c = "/theta_c" }}
"#,
        recording = common::dltdv_recording("rec_xypts.csv", t0),
    );
    std::fs::write(dir.join("job.toml"), job).unwrap();
    let loaded = LoadedJob::load(&dir.join("job.toml")).unwrap();
    let out = run_fit(&loaded, false).unwrap();
    for t in &out.result.model_trials {
        eprintln!(
            "{}: cost {:.4}, {} evaluations, {:.1} s; {}",
            t.model, t.cost, t.model_evaluations, t.wall_time_s, t.reason
        );
    }
    for p in &out.result.parameters {
        eprintln!(
            "{}: fitted {:.6} true {:.6} rel err {:+.3}%",
            p.name,
            p.value,
            p.true_value.unwrap(),
            100.0 * p.rel_error.unwrap()
        );
    }
    assert_eq!(
        out.result.model,
        wiperlab::job::Candidate {
            kind: wiperlab::simulate::blade::ModelKind::Blade2dof,
            shoulder: true,
            law: None,
        }
    );
    // The shoulder is chosen only after one more batch of the model without it ran
    // (`confirm_the_smaller`), whose reason says so.
    let smaller = out
        .result
        .model_trials
        .iter()
        .find(|t| !t.model.shoulder)
        .expect("blade2dof's trial");
    assert!(
        smaller.reason.contains("was chosen over it, so restarts"),
        "{}",
        smaller.reason
    );
    let k1c_fit = out
        .result
        .parameters
        .iter()
        .find(|p| p.name == wiperlab::model::ParamId::K1c)
        .expect("k1c fitted");
    assert!(
        k1c_fit.rel_error.unwrap().abs() < 0.05,
        "k1_contact off by {:+.2} %",
        100.0 * k1c_fit.rel_error.unwrap()
    );
    out
}
