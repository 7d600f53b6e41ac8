//! The likelihood of `wiperlab::likelihood` against processes whose spectra are known in
//! closed form: Gaussian white noise (one-sided PSD `2σ²/fs`) and a Gaussian AR(1) process
//! `x_t = a·x_{t−1} + e_t` (PSD `2σ_e²/(fs·(1 − 2a·cos ω + a²))`, ω = 2πf/fs; Priestley 1981,
//! *Spectral Analysis and Time Series*, §4.12), both run through our Welch estimator.
//!
//! Monte-Carlo tolerances are stated in standard errors computed from the samples themselves;
//! every check would fail for the naive alternative it names (ν = 2K without the overlap
//! correction, bins treated as independent).

use rand::SeedableRng;
use rand::rngs::StdRng;
use rand_distr::{Distribution, Normal};
use wiperlab::likelihood::{
    Evidence, LINE_FALSE_ALARM, LikelihoodError, Side, WelchLikelihood, band_has_line,
    bin_correlation, demeaned_residuals, effective_sample_size, gaussian_nll, interior_bin,
    likelihood_ratio_test, tracking_noise_sigma, welch_dof,
};
use wiperlab::spectrum::{Scaling, WelchConfig, WelchPlan, Window};

const FS_HZ: f64 = 1000.0;
const NPERSEG: usize = 256;
/// 16 segment lengths: K = 31 half-overlapping segments.
const N_SAMPLES: usize = 16 * NPERSEG;

fn white(seed: u64, sigma: f64, n: usize) -> Vec<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    let d = Normal::new(0.0, sigma).unwrap();
    (0..n).map(|_| d.sample(&mut rng)).collect()
}

/// AR(1) started from its stationary law N(0, σ_e²/(1 − a²)).
fn ar1(seed: u64, a: f64, sigma_e: f64, n: usize) -> Vec<f64> {
    let e = white(seed, sigma_e, n);
    let mut x = Vec::with_capacity(n);
    let mut prev = e[0] / (1.0 - a * a).sqrt();
    x.push(prev);
    for ei in &e[1..] {
        prev = a * prev + ei;
        x.push(prev);
    }
    x
}

fn ar1_psd(f_hz: f64, a: f64, sigma_e: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI * f_hz / FS_HZ;
    2.0 * sigma_e * sigma_e / (FS_HZ * (1.0 - 2.0 * a * w.cos() + a * a))
}

/// Indices of the bins away from 0 and Nyquist.
fn interior(cfg: &WelchConfig, freq: &[f64]) -> Vec<usize> {
    (0..freq.len())
        .filter(|&k| interior_bin(freq[k], FS_HZ, cfg))
        .collect()
}

/// Mean, variance and their standard errors of independent samples `v` (the variance's from the
/// fourth central moment, `Var s² ≈ (μ₄ − σ⁴)/n`).
fn moments(v: &[f64]) -> (f64, f64, f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let m4 = v.iter().map(|x| (x - mean).powi(4)).sum::<f64>() / n;
    (mean, var, (var / n).sqrt(), ((m4 - var * var) / n).sqrt())
}

/// Ratios P̂/S of every 4th interior bin (bins ≥ 3 apart are uncorrelated for the Hann window, by
/// the cross-window of [`bin_correlation`], so the samples are independent) over `seeds`
/// realisations of `signal`.
fn ratios(
    cfg: &WelchConfig,
    seeds: u64,
    signal: impl Fn(u64) -> Vec<f64>,
    psd: impl Fn(f64) -> f64,
) -> Vec<f64> {
    let mut plan = WelchPlan::new(*cfg).unwrap();
    let mut out = Vec::new();
    for seed in 0..seeds {
        let p = plan.process(&signal(seed), FS_HZ).unwrap();
        for k in interior(cfg, &p.freq_hz).into_iter().step_by(4) {
            out.push(p.density[k] / psd(p.freq_hz[k]));
        }
    }
    out
}

#[test]
fn dof_closed_forms() {
    // Periodic Hann, 50 % overlap: over the overlapping half Σ h_t h_{t+N/2} = Σ sin²cos² = N/16,
    // Σ h² = 3N/8, so c = (1/6)² and ν = 2K/(1 + 2(1 − 1/K)/36) = 36K²/(19K − 1) (hand
    // derivation; the value Percival & Walden 1993, §6.17, give for this taper and overlap).
    for k in [1usize, 2, 7, 31] {
        let nu = welch_dof(&WelchConfig::new(NPERSEG), k).unwrap();
        let kf = k as f64;
        let want = 36.0 * kf * kf / (19.0 * kf - 1.0);
        assert!(
            (nu - want).abs() < 1e-9 * want,
            "K = {k}: ν = {nu}, want {want}"
        );
    }
    // No overlap: K independent periodograms, ν = 2K exactly (Welch 1967), for any window.
    for w in Window::ALL {
        let cfg = WelchConfig::new(NPERSEG)
            .with_window(w)
            .with_noverlap(0)
            .unwrap();
        assert!((welch_dof(&cfg, 9).unwrap() - 18.0).abs() < 1e-12, "{w}");
    }
    // Hann without overlap or padding: r(j) = |W(j)/W(0)|² with W the DFT of h² = 3/8 − cos/2 +
    // cos(2·)/8, i.e. r = 1, 4/9, 1/36, 0 (hand derivation).
    let cfg = WelchConfig::new(NPERSEG).with_noverlap(0).unwrap();
    let r = bin_correlation(&cfg, 5, 4).unwrap();
    for (got, want) in r.iter().zip([1.0, 4.0 / 9.0, 1.0 / 36.0, 0.0]) {
        assert!((got - want).abs() < 1e-12, "r = {r:?}");
    }
}

#[test]
fn welch_ordinates_have_the_mean_and_variance_of_chi2_nu_over_nu() {
    let sigma = 0.7;
    let (a, sigma_e) = (0.5, 1.3);
    // SciPy's default 50 % overlap (K = 31) and 75 % overlap (K = 61), where neighbouring
    // segments share more and ν falls much further below 2K.
    for (noverlap, k_want) in [(NPERSEG / 2, 31), (3 * NPERSEG / 4, 61)] {
        let cfg = WelchConfig::new(NPERSEG).with_noverlap(noverlap).unwrap();
        let k = cfg.n_segments(N_SAMPLES);
        assert_eq!(k, k_want);
        let nu = welch_dof(&cfg, k).unwrap();
        for (name, v) in [
            (
                "white",
                ratios(
                    &cfg,
                    200,
                    |s| white(s, sigma, N_SAMPLES),
                    |_| white_ordinate(sigma, &cfg),
                ),
            ),
            (
                "AR(1)",
                ratios(
                    &cfg,
                    200,
                    |s| ar1(1000 + s, a, sigma_e, N_SAMPLES),
                    |f| ar1_psd(f, a, sigma_e),
                ),
            ),
        ] {
            let (mean, var, se_mean, se_var) = moments(&v);
            let what = format!("{name}, noverlap {noverlap}, K {k}, ν {nu:.2}");
            eprintln!(
                "{what}: mean P̂/S {mean:.4} ± {se_mean:.4}, Var {var:.5} ± {se_var:.5}, 2/ν {:.5} ({} ordinates)",
                2.0 / nu,
                v.len()
            );
            assert!(
                (mean - 1.0).abs() < 4.0 * se_mean,
                "{what}: mean P̂/S = {mean} ± {se_mean} over {} ordinates",
                v.len()
            );
            assert!(
                (var - 2.0 / nu).abs() < 4.0 * se_var,
                "{what}: Var P̂/S = {var} ± {se_var}, 2/ν = {}",
                2.0 / nu
            );
            if noverlap > NPERSEG / 2 {
                // ν = 2K (independent segments) predicts a variance this Monte Carlo rejects.
                let naive = 2.0 / (2.0 * k as f64);
                assert!(
                    (var - naive).abs() > 4.0 * se_var,
                    "{what}: {var} vs naive {naive}"
                );
            }
        }
    }
}

/// The variance of a band's sum of ordinates is `M·(2/ν)·φ`, and adjacent ordinates correlate as
/// `r(1)`.
#[test]
fn band_sums_and_neighbours_follow_the_bin_correlation() {
    let cfg = WelchConfig::new(NPERSEG);
    let sigma = 1.0;
    let s = white_ordinate(sigma, &cfg);
    let mut plan = WelchPlan::new(cfg).unwrap();
    let (mut sums, mut pairs) = (Vec::new(), Vec::new());
    let mut bins = Vec::new();
    let seeds = 400;
    for seed in 0..seeds {
        let p = plan
            .process(&white(50_000 + seed, sigma, N_SAMPLES), FS_HZ)
            .unwrap();
        bins = interior(&cfg, &p.freq_hz);
        sums.push(bins.iter().map(|&k| p.density[k] / s).sum::<f64>());
        for &k in bins.iter().step_by(4) {
            pairs.push((p.density[k] / s, p.density[k + 1] / s));
        }
    }
    let wl = WelchLikelihood::new(&cfg, cfg.n_segments(N_SAMPLES), bins.len()).unwrap();
    let m = bins.len() as f64;
    let (_, var, _, _) = moments(&sums);
    let ratio = var / (m * 2.0 / wl.dof);
    let se = wl.bin_factor * (2.0 / (seeds as f64 - 1.0)).sqrt();
    eprintln!(
        "band of {m} bins: Var(sum)/(M·2/ν) = {ratio:.3} ± {se:.3}, φ = {:.3}",
        wl.bin_factor
    );
    // The sum over ~120 bins is near Gaussian: Var s² / s⁴ ≈ 2/(n − 1).
    assert!(
        (ratio - wl.bin_factor).abs() < 3.5 * se,
        "Var(band sum)/(M·2/ν) = {ratio}, φ = {} ± {se}",
        wl.bin_factor
    );
    assert!(
        (ratio - 1.0).abs() > 3.5 * se,
        "bins treated as independent: {ratio}"
    );
    // Pearson correlation of neighbours, pooled over independent pairs; SE ≈ (1 − r²)/√n.
    let n = pairs.len() as f64;
    let (ma, mb) = pairs
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let cov = pairs.iter().map(|p| (p.0 - ma) * (p.1 - mb)).sum::<f64>();
    let va = pairs.iter().map(|p| (p.0 - ma).powi(2)).sum::<f64>();
    let vb = pairs.iter().map(|p| (p.1 - mb).powi(2)).sum::<f64>();
    let r1 = cov / (va * vb).sqrt();
    let want = bin_correlation(&cfg, cfg.n_segments(N_SAMPLES), 2).unwrap()[1];
    eprintln!("neighbour correlation {r1:.3} over {n} pairs, predicted r(1) = {want:.3}");
    assert!(
        (r1 - want).abs() < 4.0 * (1.0 - want * want) / n.sqrt(),
        "neighbour correlation {r1}, predicted {want}"
    );
}

/// Golden-section minimum of `f` on `[lo, hi]`.
fn argmin(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    while hi - lo > 1e-10 {
        let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if f(x1) < f(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    0.5 * (lo + hi)
}

/// Fitting a scale `c` of the true AR(1) spectrum: the NLL is minimised at `mean(P̂/S)` (its
/// derivative in closed form), and over seeds the error `ĉ − 1` has the spread its curvature states.
#[test]
fn whittle_nll_of_a_scale_is_minimised_at_the_truth_within_its_standard_error() {
    let cfg = WelchConfig::new(NPERSEG);
    let (a, sigma_e) = (0.5, 1.0);
    let mut plan = WelchPlan::new(cfg).unwrap();
    let mut z = Vec::new();
    let seeds = 400;
    for seed in 0..seeds {
        let p = plan
            .process(&ar1(7_000 + seed, a, sigma_e, N_SAMPLES), FS_HZ)
            .unwrap();
        let bins = interior(&cfg, &p.freq_hz);
        let measured: Vec<f64> = bins.iter().map(|&k| p.density[k]).collect();
        let truth: Vec<f64> = bins
            .iter()
            .map(|&k| ar1_psd(p.freq_hz[k], a, sigma_e))
            .collect();
        let wl = WelchLikelihood::new(&cfg, p.n_segments, bins.len()).unwrap();
        let nll = |c: f64| {
            let model: Vec<f64> = truth.iter().map(|s| c * s).collect();
            wl.nll(&measured, &model).unwrap()
        };
        let c_hat = argmin(nll, 0.5, 2.0);
        // d/dc Σ α(ln cS + P̂/(cS)) = 0  ⇔  c = mean(P̂/S).
        let closed =
            measured.iter().zip(&truth).map(|(p, s)| p / s).sum::<f64>() / bins.len() as f64;
        assert!((c_hat - closed).abs() < 1e-6, "{c_hat} vs {closed}");
        let h = 1e-3;
        let curv = (nll(c_hat + h) - 2.0 * nll(c_hat) + nll(c_hat - h)) / (h * h);
        z.push((c_hat - 1.0) * curv.sqrt());
    }
    let n = z.len() as f64;
    let (mean, var, _, _) = moments(&z);
    let within2 = z.iter().filter(|v| v.abs() < 2.0).count() as f64 / n;
    eprintln!(
        "scale fit over {n} seeds: mean z {mean:.3}, Var z {var:.3}, |z| < 2 in {within2:.3}"
    );
    assert!(mean.abs() < 4.0 / n.sqrt(), "mean z = {mean}");
    // Var z = 1 ± 4·√(2/n) (z near Gaussian); without φ it would be ≈ φ ≈ 1.9.
    assert!((var - 1.0).abs() < 4.0 * (2.0 / n).sqrt(), "Var z = {var}");
    // Binomial band of the 2σ coverage, ±3 SE.
    assert!(
        (within2 - 0.9545).abs() < 3.0 * (0.9545 * 0.0455 / n).sqrt(),
        "|z| < 2 in {within2}"
    );
}

#[test]
fn white_noise_ordinate_matches_the_welch_level_of_white_noise_in_either_scaling() {
    // Density: checked through every ratio above. Spectrum scaling, Hann: 2σ²·(3N/8)/(N/2)² =
    // 3σ²/N (Σh = N/2, Σh² = 3N/8); the Welch mean over interior bins agrees to MC error.
    let sigma = 2.0;
    let cfg = WelchConfig::new(NPERSEG).with_scaling(Scaling::Spectrum);
    let want = 3.0 * sigma * sigma / NPERSEG as f64;
    assert!((white_ordinate(sigma, &cfg) - want).abs() < 1e-12 * want);
    let v = ratios(&cfg, 50, |s| white(90_000 + s, sigma, N_SAMPLES), |_| want);
    let (mean, _, se, _) = moments(&v);
    assert!((mean - 1.0).abs() < 4.0 * se, "{mean} ± {se}");
}

#[test]
fn tracking_noise_is_recovered_beside_a_smooth_motion() {
    // σ = 0.02 on a 3 Hz sine of amplitude 1 sampled at 1 kHz (Δ² of the sine ≤ 3.6e-4 ≪ σ).
    let sigma = 0.02;
    let e = white(123, sigma, 20_000);
    let x: Vec<f64> = e
        .iter()
        .enumerate()
        .map(|(i, v)| (2.0 * std::f64::consts::PI * 3.0 * i as f64 / FS_HZ).sin() + v)
        .collect();
    let s = tracking_noise_sigma(&x).unwrap();
    assert!((s / sigma - 1.0).abs() < 0.03, "σ̂ = {s}");
    assert_eq!(
        tracking_noise_sigma(&[1.0; 5]),
        Err(LikelihoodError::TooFewSamples { samples: 3, min: 8 })
    );
    assert!(matches!(
        tracking_noise_sigma(&[1.0; 50]),
        Err(LikelihoodError::InvalidSigma { .. })
    ));
}

#[test]
fn lrt_p_values_match_closed_forms_and_tables() {
    use statrs::function::erf::erfc;
    let ev = |nll: f64, k: usize| Evidence {
        nll,
        k,
        n_effective: 100.0,
        effective_parameters: None,
    };
    // df = 1: P(χ²₁ ≥ x) = P(|N(0,1)| ≥ √x) = erfc(√(x/2)).
    for x in [0.1, 1.0, 2.5, 3.841458820694124, 10.0, 30.0] {
        let t = likelihood_ratio_test(&ev(10.0 + x / 2.0, 3), &ev(10.0, 4)).unwrap();
        assert!((t.statistic - x).abs() < 1e-12);
        let want = erfc((x / 2.0).sqrt());
        assert!(
            (t.p_value - want).abs() < 1e-10 * want.max(1e-300),
            "x {x}: {} vs {want}",
            t.p_value
        );
    }
    // scipy.stats.chi2.ppf(0.95, 1) = 3.841458820694124 → p = 0.05.
    let t = likelihood_ratio_test(&ev(11.920729410347062, 1), &ev(10.0, 2)).unwrap();
    assert!((t.p_value - 0.05).abs() < 1e-12);
    // df = 2: P(χ²₂ ≥ x) = e^{−x/2}.
    for x in [0.5, 4.0, 9.210340371976184] {
        let t = likelihood_ratio_test(&ev(5.0 + x / 2.0, 4), &ev(5.0, 6)).unwrap();
        assert_eq!(t.df, 2);
        assert!((t.p_value - (-x / 2.0).exp()).abs() < 1e-12);
    }
    // A larger model that fitted worse: the statistic is negative, the p-value 1.
    let t = likelihood_ratio_test(&ev(5.0, 4), &ev(6.0, 5)).unwrap();
    assert_eq!((t.statistic, t.p_value), (-2.0, 1.0));
    assert_eq!(
        likelihood_ratio_test(&ev(5.0, 4), &ev(4.0, 4)),
        Err(LikelihoodError::NotNested {
            k_smaller: 4,
            k_larger: 4
        })
    );
    assert!(matches!(
        likelihood_ratio_test(&ev(f64::NAN, 4), &ev(4.0, 5)),
        Err(LikelihoodError::NonFinite { index: 0, .. })
    ));
    // AIC = 2k + 2·NLL, BIC = k ln n + 2·NLL.
    let e = ev(7.5, 3);
    assert_eq!(e.aic(), 21.0);
    assert!((e.bic() - (3.0 * 100f64.ln() + 15.0)).abs() < 1e-12);
    assert_eq!(e.log_likelihood(), -7.5);
}

#[test]
fn gaussian_nll_closed_form_and_calibration() {
    use statrs::distribution::{Continuous, Normal as SNormal};
    let sigma = 0.4;
    let e = [0.1, -0.5, 0.3, 0.0, 1.2];
    let want: f64 = -e
        .iter()
        .map(|x| SNormal::new(0.0, sigma).unwrap().ln_pdf(*x))
        .sum::<f64>();
    let got = gaussian_nll(&e, sigma, e.len() as f64).unwrap();
    assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    // Weighed by n_eff/n.
    assert!((gaussian_nll(&e, sigma, 2.0).unwrap() - want * 2.0 / 5.0).abs() < 1e-12);
    // On N(0, σ) residuals the mean NLL per sample is the Gaussian's entropy ½ln(2πeσ²); the
    // per-sample NLL has variance ½ (that of χ²₁/2).
    let n = 100_000;
    let r = white(4242, sigma, n);
    let per = gaussian_nll(&r, sigma, n as f64).unwrap() / n as f64;
    let entropy = 0.5 * (2.0 * std::f64::consts::PI * std::f64::consts::E * sigma * sigma).ln();
    assert!(
        (per - entropy).abs() < 4.0 * (0.5 / n as f64).sqrt(),
        "{per} vs {entropy}"
    );
    // Errors carry their numbers.
    assert_eq!(
        gaussian_nll(&e, 0.0, 5.0),
        Err(LikelihoodError::InvalidSigma { sigma: 0.0 })
    );
    assert!(matches!(
        gaussian_nll(&[0.0, f64::NAN, 1.0], 1.0, 3.0),
        Err(LikelihoodError::NonFinite { index: 1, .. })
    ));
    assert_eq!(
        demeaned_residuals(&[1.0; 3], &[1.0; 4]),
        Err(LikelihoodError::LengthMismatch {
            measured: 3,
            model: 4
        })
    );
}

/// The AR(1) effective sample size: `ρ̂` recovers `a`, and the sample mean's variance over seeds is
/// `σ_x²/n_eff` (Bayley & Hammersley 1946), not `σ_x²/n`.
#[test]
fn effective_sample_size_of_ar1_residuals() {
    let (a, sigma_e, n, seeds) = (0.8, 1.0, 2000, 400);
    let var_x = sigma_e * sigma_e / (1.0 - a * a);
    let mut means = Vec::new();
    let mut n_effs = Vec::new();
    for seed in 0..seeds {
        let x = ar1(30_000 + seed, a, sigma_e, n);
        let s = effective_sample_size(&x).unwrap();
        assert!(
            (s.rho - a).abs() < 5.0 * ((1.0 - a * a) / n as f64).sqrt(),
            "ρ̂ {}",
            s.rho
        );
        n_effs.push(s.n_eff);
        means.push(x.iter().sum::<f64>() / n as f64);
    }
    let n_eff = n_effs.iter().sum::<f64>() / seeds as f64;
    let (_, var_mean, _, se) = moments(&means);
    let want = var_x / n_eff;
    eprintln!(
        "AR(1) a = {a}: mean n_eff {n_eff:.1} of {n}; Var(mean) {var_mean:.5} ± {se:.5}, σ²/n_eff {want:.5}, σ²/n {:.5}",
        var_x / n as f64
    );
    assert!(
        (var_mean - want).abs() < 4.0 * se,
        "Var mean {var_mean} ± {se}, σ²/n_eff {want}"
    );
    assert!((var_mean - var_x / n as f64).abs() > 4.0 * se);
    // White residuals: ρ̂ ≈ 0, n_eff = n whenever ρ̂ ≤ 0.
    let w = white(1, 1.0, 5000);
    let s = effective_sample_size(&w).unwrap();
    assert!(s.rho.abs() < 4.0 / (5000f64).sqrt());
    assert!(s.n_eff <= 5000.0 && s.n_eff > 5000.0 * 0.9);
}

#[test]
fn whittle_nll_rejects_bad_input_with_its_numbers() {
    let cfg = WelchConfig::new(NPERSEG);
    let wl = WelchLikelihood::new(&cfg, 5, 3).unwrap();
    assert_eq!(
        wl.nll(&[1.0, 1.0], &[1.0, 1.0]),
        Err(LikelihoodError::LengthMismatch {
            measured: 2,
            model: 2
        })
    );
    assert_eq!(
        wl.nll(&[1.0, 1.0, 1.0], &[1.0, 0.0, 1.0]),
        Err(LikelihoodError::NonPositivePsd {
            side: Side::Model,
            index: 1,
            value: 0.0
        })
    );
    assert!(matches!(
        wl.nll(&[1.0, 1.0, f64::NAN], &[1.0; 3]),
        Err(LikelihoodError::NonPositivePsd {
            side: Side::Measured,
            index: 2,
            ..
        })
    ));
    assert_eq!(
        WelchLikelihood::new(&cfg, 0, 3),
        Err(LikelihoodError::TooFewSegments {
            n_segments: 0,
            min: 1
        })
    );
    assert_eq!(
        WelchLikelihood::new(&cfg, 3, 0),
        Err(LikelihoodError::EmptyBand)
    );
    let median = cfg.with_average(wiperlab::spectrum::Average::Median);
    let e = welch_dof(&median, 4).unwrap_err();
    assert!(e.to_string().contains("'median'"), "{e}");
    // Into the crate's error: a setting error (exit 2), readable back as the typed value.
    let err: wiperlab::Error = e.clone().into();
    assert!(err.is_input_error());
    assert_eq!(LikelihoodError::of(&err), Some(&e));
    // The NLL of one bin with ν = 2 (K = 1) is the exponential's: ln S + P/S (lnΓ(1) = 0, α = 1).
    let one = WelchLikelihood::new(&cfg, 1, 1).unwrap();
    assert_eq!(one.dof, 2.0);
    let got = one.nll(&[3.0], &[2.0]).unwrap();
    assert!((got - (2f64.ln() + 1.5)).abs() < 1e-12, "{got}");
}

/// `band_has_line` on white noise alone and with a sinusoid at 2.7 times the noise's density
/// (a bin-centred 195.3 Hz line of amplitude 0.25 beside σ = 1: Welch peak `a²/(2·ENBW)`, ENBW =
/// 1.5 fs/nperseg for Hann, 0.0053 against `2σ²/fs` = 0.002). On noise its false alarms must stay
/// near `LINE_FALSE_ALARM` (Bonferroni over the band's bins: at most that rate); a per-bin quantile
/// instead would call a line in nearly every band. The line must be found in (almost) every seed.
#[test]
fn a_band_of_noise_has_no_line_and_a_line_above_the_noise_is_found() {
    use wiperlab::fit::features::{BandSpec, features};
    let bands = [BandSpec::new("b", [50.0, 450.0], NPERSEG)];
    let seeds = 300;
    let (mut false_alarms, mut found) = (0, 0);
    for seed in 0..seeds {
        let x = white(9000 + seed, 1.0, N_SAMPLES);
        let f = features(&x, FS_HZ, &bands, 0).unwrap();
        false_alarms += usize::from(band_has_line(&f.bands[0]));
        let f_line = 50.0 * FS_HZ / NPERSEG as f64;
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, v)| v + 0.25 * (std::f64::consts::TAU * f_line * i as f64 / FS_HZ).sin())
            .collect();
        let f = features(&y, FS_HZ, &bands, 0).unwrap();
        found += usize::from(band_has_line(&f.bands[0]));
    }
    println!(
        "white noise: {false_alarms} of {seeds} bands called a line (α = {LINE_FALSE_ALARM}); \
         with the line: found in {found} of {seeds}"
    );
    // Binomial(300, 0.01): P(≥ 9) = 0.4 %.
    assert!(false_alarms <= 8, "{false_alarms} false alarms in {seeds}");
    assert!(
        found >= seeds as usize * 99 / 100,
        "line found in {found} of {seeds}"
    );
}

/// The white tracking noise's expected Welch ordinate (`spectrum::noise`; flat, so any frequency).
fn white_ordinate(sigma: f64, cfg: &wiperlab::spectrum::WelchConfig) -> f64 {
    wiperlab::spectrum::noise::TrackingNoise::white(sigma).welch_ordinate(1000.0, FS_HZ, cfg)
}
