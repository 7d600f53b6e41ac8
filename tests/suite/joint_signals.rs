//! Several tracked signals read together (`[fit.likelihood] joint_signals`, docs/likelihood.md,
//! "Several signals"): on the shipped recording, at its truth, head y read with tip − head x
//! narrows every parameter's curvature interval, and the goodness-of-fit test, which reads the
//! fit's own signal, does not change.
//!
//! Why it must narrow: the information of two signals' joint law is at least that of one of them
//! (the Fisher information of a marginal is bounded by the joint's; Lehmann & Casella 1998,
//! *Theory of Point Estimation*, §2.5), so each diagonal of `F⁻¹` can only shrink. The size of the
//! gain is the one the whitened response gives; that response is checked against the trace
//! formula of the complex-Wishart information in `src/search/evidence/joint.rs`'s unit tests.
//! Reference values: the true A, B, C, k1 of `data/reversal/truth.json` (/params), from the
//! independent implementation that made the recording. About 2 s.

use crate::common;

use wiperlab::job::{Candidate, LoadedJob, NoiseSpectrum};
use wiperlab::search::evidence::curvature_at;
use wiperlab::search::problem_for;
use wiperlab::spectrum::features::SignalKind;

/// `data/reversal/truth.json` /params: A, B (s/m), C, k1 (N·m/rad).
const TRUTH: [f64; 4] = [0.88, 69.74712740275162, 0.56, 0.029748408887917077];

/// The shipped job's blade2dof problem with the joint signals `joint` and white noise, and the
/// truth in its normalised coordinates.
fn problem(joint: &[SignalKind]) -> (wiperlab::search::SpectralProblem, Vec<f64>) {
    let mut job = LoadedJob::load(&common::root().join("fits/reversal.toml")).expect("job");
    job.job.fit.likelihood.noise = NoiseSpectrum::White;
    job.job.fit.likelihood.joint_signals = joint.to_vec();
    let p = problem_for(&job, "blade2dof".parse::<Candidate>().unwrap()).expect("problem");
    let u = p.free.iter().zip(TRUTH).map(|(f, v)| f.u_of(v)).collect();
    (p, u)
}

#[test]
fn head_y_read_with_the_signal_narrows_every_curvature_interval_at_the_truth() {
    let (one, u) = problem(&[]);
    let (two, _) = problem(&[SignalKind::HeadY]);
    let (s1, _) = curvature_at(&one, &u).expect("one signal's curvature");
    let (s2, _) = curvature_at(&two, &u).expect("two signals' curvature");
    println!("1σ (normalised), one signal {s1:?}, with head y {s2:?}");
    for (i, (a, b)) in s1.iter().zip(&s2).enumerate() {
        assert!(
            b.is_finite() && *b > 0.0 && b < a,
            "parameter {i}: 1σ {b} with head y, {a} without"
        );
    }
    // The joint likelihood's NLL is its own (the matrices' law), the goodness of fit the signal's.
    let sim = one
        .simulate(&one.params_at(&u))
        .expect("the truth simulates");
    let (l1, l2) = (
        one.likelihood.as_ref().expect("a likelihood"),
        two.likelihood.as_ref().expect("a likelihood"),
    );
    assert_eq!(
        l2.signals(&two),
        vec![SignalKind::TipRelX, SignalKind::HeadY]
    );
    let (g1, g2) = (
        l1.goodness_of_fit(&one, &sim).expect("test"),
        l2.goodness_of_fit(&two, &sim).expect("test"),
    );
    assert_eq!(g1.excess_nll_nats, g2.excess_nll_nats);
    assert_ne!(
        l1.excess_nll(&one, &sim).unwrap(),
        l2.excess_nll(&two, &sim).unwrap()
    );
}

#[test]
fn a_band_too_short_for_the_cross_spectra_falls_back_to_the_one_signal_and_says_so() {
    // The low band at nperseg 16384 keeps one segment of the recording's 18,869 frames: ν = 2
    // (Percival & Walden 1993, §6.17: one Hann segment has 2 degrees of freedom), ν/2 = 1, fewer
    // than the 2 × 2 cross-spectral matrix of two signals needs (complex Wishart with n ≥ p).
    let mut job = LoadedJob::load(&common::root().join("fits/reversal.toml")).expect("job");
    job.job.spectrum.bands[0].nperseg = 16384;
    job.job.fit.likelihood.joint_signals = vec![SignalKind::HeadY];
    let p = problem_for(&job, "blade2dof".parse::<Candidate>().unwrap()).expect("problem");
    let lik = p.likelihood.as_ref().expect("the one signal's likelihood");
    assert_eq!(lik.signals(&p), vec![SignalKind::TipRelX]);
    match &lik.joint_dropped {
        Some(wiperlab::estimate::warning::JointDropped {
            n_segments,
            half_dof,
            signals,
        }) => {
            assert_eq!((*n_segments, *signals), (1, 2));
            assert!((half_dof - 1.0).abs() < 1e-12, "ν/2 = {half_dof}");
        }
        other => panic!("expected joint_signals_dropped, got {other:?}"),
    }
}
