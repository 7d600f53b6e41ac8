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

/// `u` with B doubled: the Stribeck slope −A·B at zero slip speed twice the truth's, where the
/// cost jitters by about a hundred nats (docs/validation.md, "Jitter").
fn b_doubled(p: &wiperlab::search::SpectralProblem, u: &[f64]) -> Vec<f64> {
    let b = p
        .free
        .iter()
        .position(|f| f.name == wiperlab::model::ParamId::B)
        .expect("B is freed");
    let mut steep = u.to_vec();
    steep[b] = p.free[b].u_of(2.0 * p.free[b].value(u[b]));
    steep
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

#[test]
fn the_slow_slip_before_the_reversal_grows_a_rounding_level_step_and_head_y_sees_it() {
    // A step of 1e-13 in A's normalised coordinate changes nothing the integrator can see until
    // the slip slows towards the reversal; there an oscillation grows out of the difference until
    // the neck angles of the two runs part by milliradians (measured on this recording's truth:
    // below 2e-13 rad for the first 8,000 frames, 6e-3 rad by frame 9,035 of 18,869). The cost of
    // tip − head x hardly sees it (a few hundredths of a nat); head y's low band, which sees the
    // squared angle's envelope, does (most of a nat): docs/likelihood.md, "Jitter".
    use wiperlab::search::jitter::RoundingJitter;
    let (one, u) = problem(&[]);
    let (two, _) = problem(&[SignalKind::HeadY]);
    let mut stepped = u.clone();
    stepped[0] += 1e-13;
    let a = one
        .simulate(&one.params_at(&u))
        .expect("the truth simulates");
    let b = one
        .simulate(&one.params_at(&stepped))
        .expect("the stepped truth simulates");
    let parted = |range: std::ops::Range<usize>| {
        range
            .map(|j| (a.theta_rad[j] - b.theta_rad[j]).abs())
            .fold(0.0_f64, f64::max)
    };
    let n = a.theta_rad.len();
    let (early, late) = (parted(0..n / 3), parted(n / 3..n));
    println!("neck angles part by {early:.2e} rad in the first third, {late:.2e} rad later");
    assert!(early < 1e-10, "{early:.2e} rad in the first third");
    assert!(late > 1e-4, "{late:.2e} rad after the first third");
    let j1 = RoundingJitter::at(&one, &u).expect("one signal's jitter");
    let j2 = RoundingJitter::at(&two, &u).expect("two signals' jitter");
    println!(
        "jitter {:.3} nats alone, {:.3} with head y",
        j1.sd_nats, j2.sd_nats
    );
    assert_eq!(j1.costs_nats.len(), 2 * u.len() + 1);
    assert!(j1.sd_nats < 0.1, "one signal: {} nats", j1.sd_nats);
    assert!(
        j2.sd_nats > 5.0 * j1.sd_nats,
        "{} against {}",
        j2.sd_nats,
        j1.sd_nats
    );
}

#[test]
fn the_rounding_widens_the_spread_where_the_slip_is_unstable_and_nowhere_else() {
    // The sandwich's V carries the rounding's draws of the growing oscillation's onset
    // (docs/uncertainty.md, "Jitter"). At this recording's truth tip − head x hardly jitters, so
    // its spread is the tracking noise's; with the Stribeck slope −A·B doubled (B × 2) the cost
    // jitters by about a hundred nats (docs/validation.md, "Jitter"), and the draws widen the
    // spread of some coordinate by more than half again. Factors as measured here: 1.00 and
    // more than 2.
    use wiperlab::search::evidence::at_fit_smoothed;
    let (one, u) = problem(&[]);
    let calm = at_fit_smoothed(&one, &u).expect("the spread at the truth");
    println!("widening at the truth: {:?}", calm.rounding_widening);
    assert!(
        calm.rounding_widening
            .iter()
            .all(|w| (1.0..1.05).contains(w)),
        "{:?}",
        calm.rounding_widening
    );
    let steep = b_doubled(&one, &u);
    let jittery = at_fit_smoothed(&one, &steep).expect("the spread with B doubled");
    println!("widening with B doubled: {:?}", jittery.rounding_widening);
    assert!(
        jittery.rounding_widening.iter().any(|w| *w > 1.5),
        "{:?}",
        jittery.rounding_widening
    );
}

#[test]
fn where_the_response_jitters_the_fisher_steps_grow_until_the_information_is_the_bowls() {
    // A central difference of step h over a response that carries the rounding's draws (variance
    // ε² per component) carries noise of variance ε²/(2h²), which JᵀWJ reads as information
    // (Moré & Wild 2011, ACM TOMS 38:19). With B × 2 (the cost jitters by about a hundred nats
    // at this truth, docs/validation.md, "Jitter") the Fisher 1σ at the fits' own step 3e-3
    // is that noise's: it grows with the step. The sandwich's steps then grow until the noise
    // makes up at most a tenth of each column's information, and the 1σ there is the one the
    // larger step reads. At the truth itself, where tip − head x hardly jitters, no step grows.
    use wiperlab::likelihood::covariance::covariance;
    use wiperlab::search::evidence::{FISHER_STEP_U, at_fit_smoothed};
    let (one, u) = problem(&[]);
    let calm = at_fit_smoothed(&one, &u).expect("the spread at the truth");
    assert!(
        calm.fisher_steps_u.iter().all(|h| *h == FISHER_STEP_U),
        "{:?}",
        calm.fisher_steps_u
    );
    let steep = b_doubled(&one, &u);
    let jittery = at_fit_smoothed(&one, &steep).expect("the spread with B doubled");
    let lik = one.likelihood.as_ref().expect("a likelihood");
    let parts = lik
        .nll(
            &one,
            &one.simulate(&one.params_at(&steep)).expect("simulates"),
        )
        .expect("the NLL");
    let sigma_at =
        |h: f64| covariance(&lik.fisher_with_step(&one, &steep, &parts, h).expect("F")).0;
    let (own, wide) = (sigma_at(FISHER_STEP_U), sigma_at(10.0 * FISHER_STEP_U));
    println!(
        "steps {:?}; Fisher 1σ at 3e-3 {own:?}, at 3e-2 {wide:?}, adapted {:?}",
        jittery.fisher_steps_u, jittery.curvature_sigma_u
    );
    // The noise's signature: a ten-fold step widens some coordinate's 1σ more than three-fold.
    assert!(own.iter().zip(&wide).any(|(a, b)| *b > 3.0 * a));
    assert!(jittery.fisher_steps_u.iter().any(|h| *h > FISHER_STEP_U));
    for (i, (adapted, fixed)) in jittery.curvature_sigma_u.iter().zip(&own).enumerate() {
        assert!(
            *adapted >= *fixed,
            "coordinate {i}: adapted 1σ {adapted:.2e} below the fixed step's {fixed:.2e}"
        );
    }
    assert!(
        jittery
            .curvature_sigma_u
            .iter()
            .zip(&own)
            .any(|(a, f)| *a > 2.0 * f)
    );
}

#[test]
fn a_probe_of_the_jitter_measures_as_the_check_does_and_leaves_its_cache_alone() {
    // The profile reads each step's draw-averaged cost with `RoundingJitter::probe` where the
    // optimum jitters by more than a rise limit (docs/likelihood.md, "Jitter"); the tolerance
    // check and the walk's start read the optimum's check from the problem's cache, which the
    // probes at the steps must not replace. The simulations are deterministic, so a probe and a
    // check at one point give the same costs.
    use std::sync::atomic::Ordering;
    use wiperlab::search::jitter::RoundingJitter;
    let (one, u) = problem(&[]);
    let steep = b_doubled(&one, &u);
    let checked = RoundingJitter::at(&one, &u).expect("the check at the truth");
    let probed = RoundingJitter::probe(&one, &steep).expect("a probe with B doubled");
    let again = RoundingJitter::at(&one, &steep).expect("the check with B doubled");
    assert_eq!(probed, again);
    assert!(probed.sd_nats > 1.0, "{} nats", probed.sd_nats);
    let before = one.evaluations.load(Ordering::Relaxed);
    let _ = RoundingJitter::probe(&one, &u);
    assert_eq!(RoundingJitter::at(&one, &steep), Some(again));
    assert_eq!(
        one.evaluations.load(Ordering::Relaxed) - before,
        2 * u.len() + 1,
        "the probe simulated, the cached check did not"
    );
    assert!(checked.sd_nats < 0.1);
}
