//! The fit's result file: every field survives a TOML round trip, and results written before a
//! field existed still load.

use wiperlab::fit::result::*;
use wiperlab::job::SpectrumSection;
use wiperlab::model::ParamId;

fn sample_parameter() -> FittedParam {
    FittedParam {
        name: ParamId::K1,
        value: 0.03,
        lower: 0.005,
        upper: 0.15,
        std_error: 0.001,
        fisher_std_error: None,
        rounding_widening: None,
        determined: true,
        true_value: Some(0.029),
        rel_error: Some(0.03 / 0.029 - 1.0),
        interval: Some(Interval {
            lo: 0.028,
            hi: 0.032,
            level: 0.68,
            method: IntervalMethod::Profile {
                rise_limit_nats: 0.125,
            },
            widened_from: None,
            range_95: None,
        }),
    }
}

fn sample_peak() -> PeakComparison {
    PeakComparison {
        band: "low".into(),
        measured_hz: 49.0,
        model_hz: 49.5,
        rel_diff: 0.5 / 49.0,
        measured_level: 1e-9,
        model_level: 2e-9,
        target_range_hz: None,
        measured_line: None,
        model_line: None,
    }
}

fn sample_trial() -> ModelTrial {
    ModelTrial {
        model: "head1dof@exponential_viscous".parse().unwrap(),
        parameters: vec![ParamId::K0],
        cost: 3.0,
        wall_time_s: 0.1,
        model_evaluations: 5,
        failed_evaluations: 0,
        chosen: false,
        reason: "cost 3.0 > 1.5".into(),
        not_distinguishable: false,
        evidence: Some(TrialEvidence {
            log_likelihood_nats: -12.5,
            spectral_nll_nats: vec![10.0, 2.5],
            time_nll_nats: None,
            residual_rms_m: 1e-5,
            n_effective: 40.0,
            effective_parameters: Some(1.2),
            tic: Some(25.4),
            delta_tic: Some(3.2),
            aic: 27.0,
            bic: 28.7,
            delta_aic: 4.0,
            delta_bic: 2.1,
            lrt: Some(RatioTest {
                against: "head1dof".parse().unwrap(),
                statistic: 0.5,
                df: 2,
                p_value: 0.78,
            }),
        }),
        friction: Some(wiperlab::model::FrictionLaw::ExponentialViscous {
            a: 0.8,
            b_s_per_m: 70.0,
            c: 0.56,
            d_s_per_m: 0.36,
        }),
    }
}

fn sample() -> FitResult {
    FitResult {
        job: "j".into(),
        recording: "r.csv".into(),
        wiperlab_version: "0.1.0".into(),
        model: "blade2dof".parse().unwrap(),
        cost: 1.5,
        parameters: vec![sample_parameter()],
        peaks: vec![sample_peak()],
        undetermined: vec![],
        correlation: vec![vec![f64::NAN]],
        spread_source: SpreadSource::Sandwich,
        swarm_iterations: 1,
        polish_iterations: 2,
        model_evaluations: 3,
        failed_evaluations: 0,
        first_failure: None,
        wall_time_s: 0.5,
        threads: 2,
        solver_rtol: 1e-8,
        solver_atol: 1e-10,
        transitions_in_best_model: 10,
        model_trials: vec![sample_trial()],
        warnings: vec![
            wiperlab::fit::FitWarning::Undetermined {
                parameter: ParamId::K1,
            },
            wiperlab::fit::FitWarning::Text { text: "w".into() },
            wiperlab::fit::FitWarning::FlatterThanCurvature(
                wiperlab::likelihood::secant::FlatAxisReport {
                    parameter: ParamId::C,
                    rise_nats: 0.11,
                    quadratic_nats: 12.5,
                    stretch: 10.0,
                },
            ),
            wiperlab::fit::FitWarning::TruthMoreLikely {
                fit_cost_nats: 38.3,
                truth_cost_nats: 35.9,
                ridge_nats: Some(31.1),
                model: Some("blade2dof+shoulder".parse().expect("a model name")),
            },
        ]
        .into(),
        input_sha256: "ab".into(),
        settings: "name = \"j\"\n".into(),
        target_job: true,
        spectrum: Some(SpectrumSection::default()),
        fit_settings: Some(
            toml::from_str("[parameters]\nk1 = [0.005, 0.15]\n").expect("fit section"),
        ),
        fitted_at: Some("2026-11-22T10:00:00.5Z".parse().expect("RFC 3339 time")),
        data_files: vec!["psd_low.csv".into()],
        modes: vec![],
        interrupted: false,
        goodness_of_fit: Some(wiperlab::likelihood::GoodnessOfFit {
            excess_nll_nats: 78.3,
            replicate_mean_nats: 75.7,
            replicate_sd_nats: 7.8,
            replicates: 999,
            p_value: 0.354,
        }),
        tolerance_check: Some(wiperlab::fit::tolerance::ToleranceCheck::of(
            vec![wiperlab::fit::tolerance::TolerancePoint {
                rtol: 1e-8,
                atol: 1e-10,
                cost_nats: 78.3,
                transitions: 160,
            }],
            vec!["rtol 1e-10: too many steps".into()],
        )),
        tracking_noise: None,
        drive: None,
        truth_cost: Some(35.9),
        truth_segment: Some(wiperlab::fit::truth::TruthSegment {
            rise_nats: vec![5.0, 31.1, -2.0],
            ridge_nats: 31.1,
        }),
        truth_tolerance: Some(wiperlab::fit::tolerance::ToleranceCheck::of(
            [(1e-8, 35.9, 160), (1e-9, 36.4, 158), (1e-10, 35.2, 160)]
                .map(
                    |(rtol, cost_nats, transitions)| wiperlab::fit::tolerance::TolerancePoint {
                        rtol,
                        atol: rtol / 100.0,
                        cost_nats,
                        transitions,
                    },
                )
                .to_vec(),
            Vec::new(),
        )),
        truth_model: Some("blade2dof+shoulder".parse().expect("a model name")),
        truth_model_cost: Some(38.3),
        friction_curve: None,
        posterior: None,
        priors: Some(wiperlab::likelihood::prior::PriorsReport {
            nats_at_fit: 0.6,
            parameters: vec![wiperlab::likelihood::prior::ParamPriorReport {
                name: ParamId::ThetaC,
                prior: wiperlab::job::ParamPrior::Normal {
                    mean: 0.08,
                    sd: 0.01,
                },
                prior_interval: [0.07, 0.09],
                value: 0.085,
                interval: Some([0.08, 0.09]),
                z: 0.5,
            }],
            friction_curve: Some(wiperlab::likelihood::prior::RigCurveReport {
                file: "rig.csv".into(),
                points: vec![wiperlab::likelihood::prior::RigPointReport {
                    speed_m_per_s: 0.075,
                    coefficient: 0.17,
                    sd: 0.008,
                    mu_d_fit: 0.18,
                    z: 1.25,
                }],
            }),
        }),
        history: vec![HistoryPoint {
            stage: SearchStage::Swarm,
            restart: 1,
            iteration: 0,
            best_cost: 2.0,
            evaluations: 3,
        }],
    }
}

#[test]
fn toml_round_trip_keeps_every_field_nan_included() {
    let r = sample();
    let back: FitResult = toml::from_str(&r.to_toml().unwrap()).unwrap();
    assert!(back.correlation[0][0].is_nan());
    let mut a = r.clone();
    let mut b = back;
    a.correlation.clear();
    b.correlation.clear();
    assert_eq!(a, b);
}

#[test]
fn results_without_the_new_fields_still_load() {
    // A result as written before `model`, `interval`, `model_trials`, `warnings`,
    // `input_sha256` and `settings` existed.
    let mut t: toml::Table = toml::from_str(&sample().to_toml().unwrap()).unwrap();
    for k in [
        "model",
        "model_trials",
        "warnings",
        "warning_details",
        "input_sha256",
        "settings",
        "target_job",
        "spectrum",
        "fit_settings",
        "fitted_at",
        "data_files",
    ] {
        assert!(t.remove(k).is_some(), "{k}");
    }
    t["parameters"].as_array_mut().unwrap()[0]
        .as_table_mut()
        .unwrap()
        .remove("interval")
        .unwrap();
    let r: FitResult = toml::from_str(&toml::to_string(&t).unwrap()).unwrap();
    assert_eq!(r.model.to_string(), "blade2dof");
    assert!(r.model_trials.is_empty() && r.warnings.is_empty());
    assert!(r.input_sha256.is_empty() && r.settings.is_empty());
    assert_eq!(r.parameters[0].interval, None);
    assert!(!r.target_job && r.spectrum.is_none() && r.fit_settings.is_none());
    assert_eq!(r.fitted_at, None);
}
