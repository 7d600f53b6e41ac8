//! A calibrated likelihood in nats for comparing a model with a recording: Welch PSD estimates
//! through a Whittle-type (Gamma) likelihood, time-domain residuals of tracked coordinates through
//! a Gaussian likelihood, and the information criteria and likelihood-ratio test built on them.
//!
//! # Welch estimates (Whittle-type likelihood)
//!
//! A Welch estimate averaged over `K` (possibly overlapping) tapered segments of a Gaussian process
//! with a spectrum `S(f)` that is locally flat over the window's bandwidth is distributed as
//! `P̂(f) ≈ S(f)·χ²_ν/ν`, i.e. Gamma with shape `α = ν/2` and mean `S(f)`, with the *equivalent
//! degrees of freedom* (Welch 1967; Percival & Walden 1993, *Spectral Analysis for Physical
//! Applications*, §6.17, for overlapping segments)
//!
//! `ν = 2K / (1 + 2 Σ_{m=1}^{K−1} (1 − m/K)·c(m·step))`, `c(d) = (Σ_t h_t h_{t+d})² / (Σ_t h_t²)²`,
//!
//! where `h` is the segment window, the sum runs over the `nperseg − d` overlapping samples and
//! `step = nperseg − noverlap` ([`welch_dof`]). For the periodic Hann window with 50 % overlap
//! `c(nperseg/2) = 1/36` (`Σ_{t<N/2} h_t h_{t+N/2} = Σ sin²cos² = N/16`, `Σ h_t² = 3N/8`), so
//! `ν = 36K²/(19K − 1) ≈ 1.89 K` (Percival & Walden's value for this case); without overlap
//! `ν = 2K`. The formula is the
//! exact variance of the estimate for white Gaussian noise at frequencies at least a main lobe away
//! from 0 and Nyquist (where the periodogram of a real series is χ²₁ instead of χ²₂; see
//! [`interior_bin`]), and the Gamma law with that variance is Welch's and Percival & Walden's
//! approximation. `tests/suite/likelihood.rs` checks the mean and variance of `P̂/S` against it on white
//! noise and on an AR(1) process.
//!
//! The negative log-likelihood of one bin, including every constant (so that it is a true NLL in
//! nats of the density of `P̂` in the PSD's units), is
//!
//! `ℓ_k = ln Γ(α) − α ln α + α ln S_k − (α − 1) ln P̂_k + α P̂_k / S_k`.
//!
//! **Correlated neighbouring bins.** A tapered segment's periodogram ordinates are correlated over
//! the window's bandwidth (Percival & Walden 1993, ch. 6: the covariance of tapered periodogram
//! ordinates is set by the taper's spectral window; for Hann without zero padding or overlap
//! neighbouring bins have correlation 4/9 and bins two apart 1/36). Summing `ℓ_k` over the bins of a band as if
//! they were independent is a composite (independence) likelihood whose curvature overstates the
//! information by the factor `φ = 1 + 2 Σ_{j=1}^{M−1} (1 − j/M) r(j)` for `M` bins whose
//! ordinates have correlation `r(j)` at `j` bins apart. Dividing the summed NLL by `φ` (the
//! "magnitude adjustment" of composite likelihood: Chandler & Bate, *Biometrika* 94(1):167, 2007;
//! Varin, Reid & Firth, *Statistica Sinica* 21:5, 2011) gives a log-likelihood whose
//! curvature equals the variance of its score for a parameter that moves the spectrum smoothly
//! across the band, so that likelihood ratios, AIC and intervals read on the usual χ² scale.
//! `r(j)` is computed exactly for white Gaussian noise from the window, the overlap and `K`
//! ([`bin_correlation`]); `M/φ` is the band's number of effectively independent bins, used as
//! `n` in BIC. The test checks both the variance of a band sum and the spread of a fitted scale
//! against `φ`.
//!
//! **The model's spectrum includes the tracking noise.** A tracked coordinate is the true motion
//! plus white tracking noise of standard deviation `σ`, so the PSD a model must match is
//! `S_model(f) = S_sim(f) + S_noise` with the one-sided density `S_noise = 2σ²/fs`
//! ([`crate::spectrum::noise::TrackingNoise`], whose AR(1) form the `ar1` noise spectrum reads). `σ` is estimated from the recording itself by [`tracking_noise_sigma`]:
//! `σ̂ = 1.4826·MAD(Δ²x)/√6` (white noise of variance σ² has `Var Δ²x = 6σ²`; the median ignores
//! the samples where the motion's own curvature is large, such as stick–slip kinks; Hampel 1974
//! for the MAD's 1.4826), which needs no choice of a "noise-only" band. The spectral floor would
//! need a band above every motion component, which a stick–slip comb reaching Nyquist does not leave.
//!
//! # Time-domain residuals (Gaussian likelihood)
//!
//! With residuals `e_i = d_i − m_i` of a tracked coordinate and the tracking noise `σ`, the
//! Gaussian NLL is `n/2·ln(2πσ²) + Σ e_i²/(2σ²)` ([`gaussian_nll`]). Residuals of an imperfect model
//! are serially correlated; the sum is then weighed by `n_eff/n` with the effective sample size of
//! an AR(1) sequence, `n_eff = n(1 − ρ)/(1 + ρ)` for lag-one autocorrelation `ρ` (Bayley &
//! Hammersley, *J. R. Stat. Soc. Suppl.* 8:184, 1946; Zwiers & von Storch, *J. Climate* 8:336,
//! 1995), estimated from the residuals ([`effective_sample_size`]); `ρ ≤ 0` gives `n_eff = n`.
//!
//! # Model choice
//!
//! [`Evidence`] carries one candidate's NLL, its number of freed parameters `k` and its effective
//! number of observations `n`: `AIC = 2k + 2·NLL` (Akaike, *IEEE TAC* 19:716, 1974),
//! `BIC = k ln n + 2·NLL` (Schwarz, *Ann. Stat.* 6:461, 1978). For nested candidates
//! [`likelihood_ratio_test`] gives Wilks' statistic `2(NLL_small − NLL_large)` and its χ² p-value
//! with `k_large − k_small` degrees of freedom (Wilks, *Ann. Math. Stat.* 9:60, 1938), from
//! `statrs`' χ² distribution.
//!
//! Units: PSD in (signal units)²/Hz (or units² for `Scaling::Spectrum`, consistently on both
//! sides), σ in signal units, NLL in nats.
//!
//! What the likelihood and the cost read of a recording is measured here too: [`measure`] reads the
//! recording (or a target job's targets) into features per band and noise floors, [`instfreq`]
//! adds frequency against tip speed. [`covariance`] turns the likelihood's information into the
//! spread of an estimate, and [`secant`] checks that spread's quadratic against the likelihood.

pub mod covariance;
mod error;
pub mod instfreq;
pub mod measure;
pub mod misfit;
pub mod multivariate;
pub mod prior;
pub mod secant;

pub use error::{MeasureError, NoHeadTrack};

use crate::spectrum::instfreq::noise_sigma;
use crate::spectrum::{Average, WelchConfig, Window, WindowSums};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use statrs::function::gamma::ln_gamma;
use std::fmt;

/// Which side of a comparison a value belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The recording's.
    Measured,
    /// The model's.
    Model,
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Side::Measured => "measured",
            Side::Model => "model",
        })
    }
}

/// The quantity a non-finite value was found in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// A time-domain residual.
    Residual,
    /// A candidate's negative log-likelihood.
    NegLogLikelihood,
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Quantity::Residual => "residual",
            Quantity::NegLogLikelihood => "negative log-likelihood",
        })
    }
}

/// Inputs a likelihood cannot be computed from, each with its numbers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LikelihoodError {
    /// A PSD bin that is zero, negative or not finite.
    #[error("Whittle likelihood: {side} PSD bin {index} is {value}; expected a finite PSD > 0")]
    NonPositivePsd {
        side: Side,
        index: usize,
        value: f64,
    },
    /// A residual or NLL that is NaN or infinite.
    #[error("likelihood: {what} {index} is {value}; expected a finite value")]
    NonFinite {
        what: Quantity,
        index: usize,
        value: f64,
    },
    /// Measured and model arrays of different lengths.
    #[error(
        "likelihood: {measured} measured values against {model} model values; expected equal lengths"
    )]
    LengthMismatch { measured: usize, model: usize },
    /// A Welch estimate of fewer segments than the likelihood needs.
    #[error(
        "Whittle likelihood: the Welch estimate averaged {n_segments} segments; expected at least {min}"
    )]
    TooFewSegments { n_segments: usize, min: usize },
    /// A Welch estimate of several signals whose equivalent degrees of freedom cannot carry their
    /// cross-spectral matrix (`ν/2` below the number of signals: the matrix is then near singular).
    #[error(
        "multivariate Whittle likelihood: {n_segments} segments give ν/2 = {half_dof:.2} equivalent degrees of freedom for {signals} signals; expected at least one per signal (more segments: a longer record or a shorter nperseg; or fewer signals, [fit.likelihood] joint_signals)"
    )]
    TooFewSegmentsForSignals {
        n_segments: usize,
        half_dof: f64,
        signals: usize,
    },
    /// A band without a bin.
    #[error("Whittle likelihood: the band has no frequency bin")]
    EmptyBand,
    /// The median average, whose distribution is not the χ²_ν of the mean.
    #[error(
        "Whittle likelihood: Welch average = '{average}' is not supported; expected 'mean' (the χ²_ν law holds for the mean of the segments' periodograms)"
    )]
    UnsupportedAverage { average: Average },
    /// A noise level that is zero, negative or not finite.
    #[error("likelihood: noise standard deviation σ = {sigma}; expected finite and > 0")]
    InvalidSigma { sigma: f64 },
    /// Too few samples to estimate the noise or a correlation.
    #[error("likelihood: {samples} finite samples; expected at least {min}")]
    TooFewSamples { samples: usize, min: usize },
    /// A likelihood-ratio test between candidates that are not nested by their parameter counts.
    #[error(
        "likelihood-ratio test: the larger model frees {k_larger} parameters, the smaller {k_smaller}; expected more in the larger one"
    )]
    NotNested { k_smaller: usize, k_larger: usize },
}

impl LikelihoodError {
    /// True for errors that come from the job's settings or the recording's length (exit 2).
    pub fn is_setting(&self) -> bool {
        matches!(
            self,
            LikelihoodError::UnsupportedAverage { .. }
                | LikelihoodError::TooFewSegments { .. }
                | LikelihoodError::TooFewSegmentsForSignals { .. }
        )
    }

    /// The likelihood's error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&LikelihoodError> {
        e.stage_error()
    }
}

impl From<LikelihoodError> for crate::Error {
    fn from(e: LikelihoodError) -> Self {
        let input = e.is_setting();
        crate::Error::stage(e, input)
    }
}

type Result<T> = std::result::Result<T, LikelihoodError>;

/// `|Σ_{t=0}^{N−1−d} h_t h_{t+d} e^{−2πi·lag·t/nfft}|²` for the window `h` (`N` samples).
fn lagged_window_power(h: &[f64], d: usize, lag: usize, nfft: usize) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    for t in 0..h.len().saturating_sub(d) {
        let p = h[t] * h[t + d];
        let phase = -2.0 * std::f64::consts::PI * ((lag * t) % nfft) as f64 / nfft as f64;
        re += p * phase.cos();
        im += p * phase.sin();
    }
    re * re + im * im
}

/// `Σ_{i,j} |E X_i(f_k) X_j(f_{k+lag})*|²` over the `K` contiguous segments, divided by σ⁴: the
/// covariance of `K²·P̂_k` and `K²·P̂_{k+lag}` for unit white noise, up to the density scaling.
fn segment_pair_power(cfg: &WelchConfig, h: &[f64], n_segments: usize, lag: usize) -> f64 {
    let step = cfg.step();
    let k = n_segments;
    let mut total = k as f64 * lagged_window_power(h, 0, lag, cfg.nfft);
    let mut m = 1;
    while m < k && m * step < cfg.nperseg {
        total += 2.0 * (k - m) as f64 * lagged_window_power(h, m * step, lag, cfg.nfft);
        m += 1;
    }
    total
}

fn check_config(cfg: &WelchConfig, n_segments: usize) -> Result<()> {
    if cfg.average != Average::Mean {
        return Err(LikelihoodError::UnsupportedAverage {
            average: cfg.average,
        });
    }
    if n_segments < 1 {
        return Err(LikelihoodError::TooFewSegments { n_segments, min: 1 });
    }
    Ok(())
}

/// Equivalent degrees of freedom `ν` of a Welch estimate with settings `cfg` averaged over
/// `n_segments` contiguous segments (see the module docs; Percival & Walden 1993, §6.17).
///
/// Segments of a record split by gaps ([`crate::spectrum::welch_gappy`]) overlap less than
/// contiguous ones, so this `ν` is then a slight underestimate (a conservative likelihood).
///
/// # Errors
/// [`LikelihoodError::UnsupportedAverage`] for the median average,
/// [`LikelihoodError::TooFewSegments`] for `n_segments = 0`.
pub fn welch_dof(cfg: &WelchConfig, n_segments: usize) -> Result<f64> {
    check_config(cfg, n_segments)?;
    let h = cfg.window.periodic(cfg.nperseg);
    let sum_sq = WindowSums::of(&h).sum_sq;
    let k = n_segments as f64;
    Ok(2.0 * k * k * sum_sq * sum_sq / segment_pair_power(cfg, &h, n_segments, 0))
}

/// Correlation `r(lag)` of the Welch ordinates `lag` bins apart for white Gaussian noise, for
/// each lag in `0..lags` (`r(0) = 1`): the segments' cross-spectral window at the frequency offset,
/// `Σ_{i,j} |Σ_t h_t h_{t+d_ij} e^{−2πi·lag·t/nfft}|² / Σ_{i,j} (Σ_t h_t h_{t+d_ij})²`.
///
/// # Errors
/// As [`welch_dof`].
pub fn bin_correlation(cfg: &WelchConfig, n_segments: usize, lags: usize) -> Result<Vec<f64>> {
    check_config(cfg, n_segments)?;
    let h = cfg.window.periodic(cfg.nperseg);
    let zero = segment_pair_power(cfg, &h, n_segments, 0);
    Ok((0..lags)
        .map(|lag| segment_pair_power(cfg, &h, n_segments, lag) / zero)
        .collect())
}

/// Half-width of the window's main lobe in bins of `fs/nperseg`: the first zero of the transform of
/// a cosine window with `J` cosine terms is at `J + 1` bins (boxcar 1, Hann and Hamming 2,
/// Blackman 3; F.J. Harris, Proc. IEEE 66(1), 1978, §4).
fn main_lobe_half_width_bins(window: Window) -> f64 {
    match window {
        Window::Boxcar => 1.0,
        Window::Hann | Window::Hamming => 2.0,
        Window::Blackman => 3.0,
    }
}

/// Whether the bin at `freq_hz` lies at least one main-lobe half-width away from 0 and from
/// Nyquist, where the χ²_ν law holds (nearer, the periodogram of a real series tends to χ²₁ and the
/// constant or linear detrend removes power).
pub fn interior_bin(freq_hz: f64, fs_hz: f64, cfg: &WelchConfig) -> bool {
    let guard = main_lobe_half_width_bins(cfg.window) * fs_hz / cfg.nperseg as f64;
    freq_hz >= guard && freq_hz <= fs_hz / 2.0 - guard
}

/// The distribution of one band's Welch ordinates: what [`WelchLikelihood::nll`] needs, computed
/// once per band and job.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WelchLikelihood {
    /// Equivalent degrees of freedom `ν` ([`welch_dof`]).
    pub dof: f64,
    /// Segments averaged, `K`.
    pub n_segments: usize,
    /// Bins in the band, `M`.
    pub n_bins: usize,
    /// Variance-inflation factor `φ ≥ 1` of the band's correlated bins (module docs).
    pub bin_factor: f64,
    /// `ln Γ(α) − α ln α`, `α = ν/2`: the constant of each bin's NLL.
    log_norm: f64,
}

impl WelchLikelihood {
    /// The likelihood of a band of `n_bins` consecutive bins of a Welch estimate with settings
    /// `cfg` over `n_segments` segments.
    ///
    /// # Errors
    /// [`LikelihoodError::EmptyBand`] for `n_bins = 0`, and those of [`welch_dof`].
    pub fn new(cfg: &WelchConfig, n_segments: usize, n_bins: usize) -> Result<Self> {
        if n_bins == 0 {
            return Err(LikelihoodError::EmptyBand);
        }
        let dof = welch_dof(cfg, n_segments)?;
        // Beyond a few main-lobe widths the correlation is sidelobe leakage (< 1e-4 for Hann);
        // zero padding widens the lobe by nfft/nperseg.
        let pad = cfg.nfft.div_ceil(cfg.nperseg);
        let lags = n_bins.min(16 * pad + 1);
        let r = bin_correlation(cfg, n_segments, lags)?;
        let m = n_bins as f64;
        let bin_factor = 1.0
            + 2.0
                * r.iter()
                    .enumerate()
                    .skip(1)
                    .map(|(j, rj)| (1.0 - j as f64 / m) * rj)
                    .sum::<f64>();
        let alpha = dof / 2.0;
        Ok(WelchLikelihood {
            dof,
            n_segments,
            n_bins,
            bin_factor,
            log_norm: ln_gamma(alpha) - alpha * alpha.ln(),
        })
    }

    /// Effectively independent bins, `M/φ` (the band's `n` in BIC).
    pub fn effective_bins(&self) -> f64 {
        self.n_bins as f64 / self.bin_factor
    }

    /// The band's negative log-likelihood in nats, `Σ_k ℓ_k / φ` (module docs), of the measured
    /// Welch ordinates `measured` given the model's expected ones `model` (the simulation's Welch
    /// PSD plus the tracking noise's). No allocation.
    ///
    /// # Errors
    /// [`LikelihoodError::LengthMismatch`] unless both hold `n_bins` values;
    /// [`LikelihoodError::NonPositivePsd`] for a bin ≤ 0 or not finite on either side.
    pub fn nll(&self, measured: &[f64], model: &[f64]) -> Result<f64> {
        if measured.len() != model.len() || measured.len() != self.n_bins {
            return Err(LikelihoodError::LengthMismatch {
                measured: measured.len(),
                model: model.len(),
            });
        }
        let alpha = self.dof / 2.0;
        let mut sum = 0.0;
        for (index, (&p, &s)) in measured.iter().zip(model).enumerate() {
            for (side, value) in [(Side::Measured, p), (Side::Model, s)] {
                if !(value.is_finite() && value > 0.0) {
                    return Err(LikelihoodError::NonPositivePsd { side, index, value });
                }
            }
            sum += self.log_norm + alpha * s.ln() - (alpha - 1.0) * p.ln() + alpha * p / s;
        }
        Ok(sum / self.bin_factor)
    }
}

/// Family-wise false-alarm rate of [`band_has_line`]: the chance that a band of pure noise is
/// taken to have a line.
pub const LINE_FALSE_ALARM: f64 = 0.01;

/// Whether a band of a Welch estimate has a line: its largest ordinate stands above what white
/// noise reaches. Under noise alone each ordinate is `S·χ²_ν/ν` ([`welch_dof`]), and the band's
/// median ordinate estimates `S·m_ν` (`m_ν` the median of `χ²_ν/ν`); the band has a line when
/// its largest ordinate exceeds the median by more than `q/m_ν`, `q` the `1 − α/M` quantile of
/// `χ²_ν/ν` for `M` bins and `α` = [`LINE_FALSE_ALARM`] (Bonferroni over the bins, conservative as
/// neighbouring bins correlate). A band whose motion raises its median only makes the test
/// stricter. Without a distribution for the band (median average, no segments) it says yes.
///
/// A band of tracking noise alone (the confusion table's head-only recording, in 500–5000 Hz) has
/// its largest ordinate anywhere, below the threshold.
pub fn band_has_line(band: &crate::spectrum::features::BandFeatures) -> bool {
    let mut finite: Vec<f64> = band
        .psd
        .iter()
        .copied()
        .filter(|p| p.is_finite() && *p > 0.0)
        .collect();
    if finite.len() < 3 {
        return true;
    }
    finite.sort_by(f64::total_cmp);
    let median = finite[finite.len() / 2];
    let largest = finite[finite.len() - 1];
    let Ok(cfg) = band.spec.welch_config() else {
        return true;
    };
    let Ok(nu) = welch_dof(&cfg, band.segments) else {
        return true;
    };
    let Ok(chi2) = ChiSquared::new(nu) else {
        return true;
    };
    let q = chi2.inverse_cdf(1.0 - LINE_FALSE_ALARM / finite.len() as f64);
    let m = chi2.inverse_cdf(0.5);
    largest > median * q / m
}

/// Robust white-noise standard deviation of a tracked coordinate `x` (NaN for missing samples):
/// `1.4826·MAD(Δ²x)/√6` ([`crate::spectrum::instfreq::noise_sigma`]; module docs).
///
/// # Errors
/// [`LikelihoodError::TooFewSamples`] with fewer than 8 finite second differences;
/// [`LikelihoodError::InvalidSigma`] for a noise-free `x` (σ̂ = 0).
pub fn tracking_noise_sigma(x: &[f64]) -> Result<f64> {
    let samples = x
        .windows(3)
        .filter(|w| w.iter().all(|v| v.is_finite()))
        .count();
    if samples < 8 {
        return Err(LikelihoodError::TooFewSamples { samples, min: 8 });
    }
    let sigma = noise_sigma(x);
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(LikelihoodError::InvalidSigma { sigma });
    }
    Ok(sigma)
}

/// Residuals `(d_i − d̄) − (m_i − m̄)` over the samples where both are finite, means removed
/// (camera and model frames differ by a constant offset).
///
/// # Errors
/// [`LikelihoodError::LengthMismatch`] for different lengths.
pub fn demeaned_residuals(measured: &[f64], model: &[f64]) -> Result<Vec<f64>> {
    if measured.len() != model.len() {
        return Err(LikelihoodError::LengthMismatch {
            measured: measured.len(),
            model: model.len(),
        });
    }
    let both = || {
        measured
            .iter()
            .zip(model)
            .filter(|(d, m)| d.is_finite() && m.is_finite())
    };
    let n = both().count().max(1) as f64;
    let (dm, mm) = both().fold((0.0, 0.0), |(a, b), (d, m)| (a + d / n, b + m / n));
    Ok(both().map(|(d, m)| (d - dm) - (m - mm)).collect())
}

/// Block means of the de-meaned residuals: `d − m` averaged over consecutive blocks of `len`
/// samples (over the samples of a block where both are finite; a block with fewer than half its
/// samples finite is left out), minus the mean of `d − m` over every such sample (camera and model
/// frames differ by a constant offset). Returns the block means and, per block kept, its first
/// sample's index.
///
/// # Errors
/// [`LikelihoodError::LengthMismatch`] for different lengths.
pub fn block_mean_residuals(measured: &[f64], model: &[f64], len: usize) -> Result<Vec<f64>> {
    if measured.len() != model.len() {
        return Err(LikelihoodError::LengthMismatch {
            measured: measured.len(),
            model: model.len(),
        });
    }
    Ok(block_means(measured, model, len, |d, m| d - m))
}

/// Block means of `f(d_i, m_i)` over the blocks [`block_mean_residuals`] keeps, de-meaned.
pub fn block_means(
    measured: &[f64],
    model: &[f64],
    len: usize,
    f: impl Fn(f64, f64) -> f64,
) -> Vec<f64> {
    let len = len.max(1);
    let mut means = Vec::with_capacity(measured.len() / len + 1);
    let (mut total, mut count) = (0.0, 0usize);
    for (d, m) in measured.chunks(len).zip(model.chunks(len)) {
        let (mut s, mut c) = (0.0, 0usize);
        for (a, b) in d.iter().zip(m) {
            if a.is_finite() && b.is_finite() {
                s += f(*a, *b);
                c += 1;
            }
        }
        if 2 * c >= len {
            means.push(s / c as f64);
        }
        total += s;
        count += c;
    }
    let mean = total / count.max(1) as f64;
    means.iter_mut().for_each(|v| *v -= mean);
    means
}

/// Gaussian NLL of `residuals` whose variance is the known noise variance `floor_var` plus an
/// unknown non-negative discrepancy variance, estimated by maximum likelihood (profiled out; the
/// concentrated likelihood, Pawitan 2001, *In All Likelihood*, §10.3): with `v = max(Σe²/n,
/// floor_var)`, `n/2·ln(2πv) + Σe²/(2v)`, i.e. `n/2·(ln(2π·Σe²/n) + 1)` for a model whose residuals
/// exceed the noise and the known-noise Gaussian NLL for one that reaches it.
///
/// # Errors
/// [`LikelihoodError::TooFewSamples`] with fewer than 3 residuals,
/// [`LikelihoodError::NonFinite`] for a non-finite one, [`LikelihoodError::InvalidSigma`] for a
/// floor that is not finite and > 0.
pub fn profiled_gaussian_nll(residuals: &[f64], floor_var: f64) -> Result<f64> {
    check_residuals(residuals)?;
    if !(floor_var.is_finite() && floor_var > 0.0) {
        return Err(LikelihoodError::InvalidSigma {
            sigma: floor_var.sqrt(),
        });
    }
    let n = residuals.len() as f64;
    let ss: f64 = residuals.iter().map(|e| e * e).sum();
    let var = (ss / n).max(floor_var);
    Ok(0.5 * n * (std::f64::consts::TAU * var).ln() + ss / (2.0 * var))
}

/// Effective sample size of serially correlated residuals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleSize {
    /// Residuals, `n`.
    pub n: usize,
    /// Lag-one autocorrelation `ρ̂` (about the mean).
    pub rho: f64,
    /// `n(1 − ρ)/(1 + ρ)` for `ρ > 0`, else `n`.
    pub n_eff: f64,
}

/// The AR(1) effective sample size of `residuals` (module docs; Zwiers & von Storch 1995).
///
/// # Errors
/// [`LikelihoodError::TooFewSamples`] for fewer than 3 residuals;
/// [`LikelihoodError::NonFinite`] for a NaN or infinite residual.
pub fn effective_sample_size(residuals: &[f64]) -> Result<SampleSize> {
    check_residuals(residuals)?;
    let n = residuals.len();
    let mean = residuals.iter().sum::<f64>() / n as f64;
    let var: f64 = residuals.iter().map(|e| (e - mean).powi(2)).sum();
    let cov: f64 = residuals
        .windows(2)
        .map(|w| (w[0] - mean) * (w[1] - mean))
        .sum();
    let rho = if var > 0.0 { cov / var } else { 0.0 };
    let n_eff = if rho > 0.0 {
        n as f64 * (1.0 - rho) / (1.0 + rho)
    } else {
        n as f64
    };
    Ok(SampleSize { n, rho, n_eff })
}

fn check_residuals(residuals: &[f64]) -> Result<()> {
    if residuals.len() < 3 {
        return Err(LikelihoodError::TooFewSamples {
            samples: residuals.len(),
            min: 3,
        });
    }
    if let Some(index) = residuals.iter().position(|e| !e.is_finite()) {
        return Err(LikelihoodError::NonFinite {
            what: Quantity::Residual,
            index,
            value: residuals[index],
        });
    }
    Ok(())
}

/// Gaussian NLL in nats of `residuals` with noise `sigma`, weighed by `n_eff/n`:
/// `(n_eff/n)·(n/2·ln(2πσ²) + Σ e²/(2σ²))`. Pass `n_eff = residuals.len()` for independent
/// residuals, or [`SampleSize::n_eff`].
///
/// # Errors
/// [`LikelihoodError::InvalidSigma`], and those of [`effective_sample_size`].
pub fn gaussian_nll(residuals: &[f64], sigma: f64, n_eff: f64) -> Result<f64> {
    check_residuals(residuals)?;
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(LikelihoodError::InvalidSigma { sigma });
    }
    let n = residuals.len() as f64;
    let var = sigma * sigma;
    let ss: f64 = residuals.iter().map(|e| e * e).sum();
    Ok((n_eff / n) * (0.5 * n * (2.0 * std::f64::consts::PI * var).ln() + ss / (2.0 * var)))
}

/// One candidate's fit in likelihood units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evidence {
    /// Negative log-likelihood at the fitted parameters, nats.
    pub nll: f64,
    /// Freed parameters.
    pub k: usize,
    /// Effective number of observations (BIC's `n`): effectively independent bins plus the
    /// residuals' `n_eff`.
    pub n_effective: f64,
    /// Takeuchi's effective number of parameters `tr(F⁺V)`
    /// ([`covariance::effective_parameters`]), when the variability of the score was estimated.
    pub effective_parameters: Option<f64>,
}

impl Evidence {
    /// `ln L = −NLL`, nats.
    pub fn log_likelihood(&self) -> f64 {
        -self.nll
    }

    /// Akaike's criterion `2k + 2·NLL`.
    pub fn aic(&self) -> f64 {
        2.0 * self.k as f64 + 2.0 * self.nll
    }

    /// Takeuchi's criterion `2·tr(F⁺V) + 2·NLL`, the AIC of a misspecified or composite
    /// likelihood ([`covariance::effective_parameters`]); Akaike's `2k + 2·NLL` without a
    /// variability estimate.
    pub fn tic(&self) -> f64 {
        2.0 * self.effective_parameters.unwrap_or(self.k as f64) + 2.0 * self.nll
    }

    /// Schwarz's criterion `k ln n + 2·NLL`.
    pub fn bic(&self) -> f64 {
        self.k as f64 * self.n_effective.ln() + 2.0 * self.nll
    }
}

/// Wilks' likelihood-ratio test of a smaller model nested in a larger one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LikelihoodRatio {
    /// `2(NLL_small − NLL_large)`; negative when the larger model's search ended worse than the
    /// smaller one (a nested model can always do at least as well at its optimum).
    pub statistic: f64,
    /// `k_large − k_small`.
    pub df: usize,
    /// `P(χ²_df ≥ max(statistic, 0))`: the chance of a gain this large if the smaller model is
    /// true.
    pub p_value: f64,
}

/// The likelihood-ratio test of `smaller` against `larger` (module docs).
///
/// # Errors
/// [`LikelihoodError::NotNested`] unless `larger.k > smaller.k`; [`LikelihoodError::NonFinite`]
/// for a NaN or infinite NLL (index 0 the smaller model, 1 the larger).
pub fn likelihood_ratio_test(smaller: &Evidence, larger: &Evidence) -> Result<LikelihoodRatio> {
    if larger.k <= smaller.k {
        return Err(LikelihoodError::NotNested {
            k_smaller: smaller.k,
            k_larger: larger.k,
        });
    }
    for (index, e) in [smaller, larger].iter().enumerate() {
        if !e.nll.is_finite() {
            return Err(LikelihoodError::NonFinite {
                what: Quantity::NegLogLikelihood,
                index,
                value: e.nll,
            });
        }
    }
    let df = larger.k - smaller.k;
    let statistic = 2.0 * (smaller.nll - larger.nll);
    let chi2 = ChiSquared::new(df as f64).expect("df ≥ 1 is a valid χ² parameter");
    Ok(LikelihoodRatio {
        statistic,
        df,
        p_value: chi2.sf(statistic.max(0.0)),
    })
}

/// Significance level below which [`GoodnessOfFit::fits`] says no: a fit whose spectra are less
/// likely than all but 1 % of replicates of its own noise.
pub const GOODNESS_OF_FIT_LEVEL: f64 = 0.01;

/// A parametric-bootstrap goodness-of-fit test of a fitted model's spectra: the recording's
/// excess NLL at the fit (above the saturated model, nats) against the same statistic of
/// recordings made of the fitted model's signal plus fresh white tracking noise of the
/// recording's `σ`, read through the same estimator (Davison & Hinkley 1997, *Bootstrap Methods
/// and their Application*, §4.2: parametric simulation of a goodness-of-fit statistic). The
/// replicates are not refitted, so the recording's statistic, minimised over the freed
/// parameters, sits about `k/2` nats below the replicates' on average: the test is conservative.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GoodnessOfFit {
    /// The recording's spectral excess NLL at the fit, nats.
    pub excess_nll_nats: f64,
    /// Mean of the replicates' excess NLL, nats.
    pub replicate_mean_nats: f64,
    /// Standard deviation of the replicates' excess NLL, nats.
    pub replicate_sd_nats: f64,
    /// Noise replicates drawn.
    pub replicates: usize,
    /// Monte Carlo p-value `(1 + #{replicates ≥ recording}) / (1 + R)` ([`monte_carlo_p_value`]).
    pub p_value: f64,
}

impl GoodnessOfFit {
    /// The test of `observed` against the replicates' statistics `replicates`.
    ///
    /// # Errors
    /// [`LikelihoodError::NonFinite`] for a NaN or infinite statistic (index 0 the recording's,
    /// `r + 1` replicate `r`'s); [`LikelihoodError::TooFewSamples`] with fewer than 2 replicates.
    pub fn of(observed: f64, replicates: &[f64]) -> Result<GoodnessOfFit> {
        if replicates.len() < 2 {
            return Err(LikelihoodError::TooFewSamples {
                samples: replicates.len(),
                min: 2,
            });
        }
        for (index, &value) in std::iter::once(&observed).chain(replicates).enumerate() {
            if !value.is_finite() {
                return Err(LikelihoodError::NonFinite {
                    what: Quantity::NegLogLikelihood,
                    index,
                    value,
                });
            }
        }
        use statrs::statistics::Statistics;
        Ok(GoodnessOfFit {
            excess_nll_nats: observed,
            replicate_mean_nats: replicates.mean(),
            // The sample standard deviation (divisor R − 1).
            replicate_sd_nats: replicates.std_dev(),
            replicates: replicates.len(),
            p_value: monte_carlo_p_value(observed, replicates),
        })
    }

    /// Whether the fitted model explains the recording's spectra to its noise: `p` above
    /// [`GOODNESS_OF_FIT_LEVEL`].
    pub fn fits(&self) -> bool {
        self.p_value > GOODNESS_OF_FIT_LEVEL
    }

    /// The recording's statistic above the replicates' mean, in their standard deviations.
    pub fn z(&self) -> f64 {
        (self.excess_nll_nats - self.replicate_mean_nats) / self.replicate_sd_nats
    }
}

/// The Monte Carlo p-value of an `observed` statistic against `replicates` of it under the null
/// hypothesis, large values counting against it: `(1 + #{r ≥ observed}) / (1 + R)` (Davison &
/// Hinkley 1997, §4.2), never 0; with `R = 999` it resolves 0.001.
pub fn monte_carlo_p_value(observed: f64, replicates: &[f64]) -> f64 {
    let at_least = replicates.iter().filter(|&&r| r >= observed).count();
    (1 + at_least) as f64 / (1 + replicates.len()) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monte_carlo_p_value_counts_the_replicates_at_least_as_extreme() {
        // 9 replicates 1..=9: 3 of them ≥ 7 → (1 + 3)/10; above all of them → 1/10, never 0.
        let r: Vec<f64> = (1..=9).map(f64::from).collect();
        assert!((monte_carlo_p_value(7.0, &r) - 0.4).abs() < 1e-15);
        assert!((monte_carlo_p_value(100.0, &r) - 0.1).abs() < 1e-15);
        assert!((monte_carlo_p_value(0.0, &r) - 1.0).abs() < 1e-15);
        let g = GoodnessOfFit::of(100.0, &r).unwrap();
        // p = 0.1 > 0.01: nine replicates cannot reject; mean 5, sample sd √7.5 of 1..=9.
        assert!(g.fits());
        assert!((g.replicate_mean_nats - 5.0).abs() < 1e-12);
        assert!((g.replicate_sd_nats - 7.5f64.sqrt()).abs() < 1e-12);
        assert!((g.z() - 95.0 / 7.5f64.sqrt()).abs() < 1e-12);
        // Above all of 99 replicates: p = 1/100, not above the level.
        let r99: Vec<f64> = (1..=99).map(f64::from).collect();
        assert!(!GoodnessOfFit::of(100.0, &r99).unwrap().fits());
        assert!(GoodnessOfFit::of(98.5, &r99).unwrap().fits());
        assert!(GoodnessOfFit::of(f64::NAN, &r).is_err());
        assert!(GoodnessOfFit::of(1.0, &[1.0]).is_err());
    }

    #[test]
    fn block_means_of_a_constant_offset_vanish_and_a_step_is_resolved() {
        // d − m = 5 everywhere: the de-meaned block means are 0. A step of height 2 at a block
        // boundary gives −1, +1 (mean removed), and a NaN-heavy block is left out.
        let d = [5.0; 8];
        let m = [0.0; 8];
        assert!(
            block_mean_residuals(&d, &m, 4)
                .unwrap()
                .iter()
                .all(|v| v.abs() < 1e-15)
        );
        let d = [0.0, 0.0, 2.0, 2.0, f64::NAN, f64::NAN, f64::NAN, 1.0];
        let b = block_mean_residuals(&d, &[0.0; 8], 2).unwrap();
        assert_eq!(b.len(), 3);
        assert!((b[0] + 1.0).abs() < 1e-12 && (b[1] - 1.0).abs() < 1e-12 && b[2].abs() < 1e-12);
    }

    #[test]
    fn profiled_nll_is_the_concentrated_likelihood_above_the_floor_and_gaussian_below() {
        // Σe² = 4·9 = 36, n = 4: v̂ = 9 → 2·ln(2π·9) + 2. Below a floor of 16: the Gaussian NLL
        // at σ² = 16, 2·ln(2π·16) + 36/32.
        let e = [3.0, -3.0, 3.0, -3.0];
        let tau = std::f64::consts::TAU;
        let above = profiled_gaussian_nll(&e, 1.0).unwrap();
        assert!((above - (2.0 * (tau * 9.0).ln() + 2.0)).abs() < 1e-12);
        let below = profiled_gaussian_nll(&e, 16.0).unwrap();
        assert!((below - (2.0 * (tau * 16.0).ln() + 36.0 / 32.0)).abs() < 1e-12);
        assert!(profiled_gaussian_nll(&e, 0.0).is_err());
    }
}
