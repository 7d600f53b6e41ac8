//! The recording's likelihood of a fitted model, in nats: what model choice and the Laplace
//! intervals read ([`crate::likelihood`] has the statistics and their sources).
//!
//! For a recording with measured signal `d` (the job's `[spectrum] signal`) and a simulation `m`:
//!
//! - **spectral term**, per band: the Whittle-type NLL of the measured Welch ordinates in the band
//!   given the simulation's ordinates plus the tracking-noise density `2σ²/fs`
//!   ([`WelchLikelihood::nll`], with the band's window, overlap and segment count);
//! - **time-domain term**: the Gaussian NLL of the de-meaned residuals `d − m` at the tracking noise
//!   `σ`, weighed by the residuals' AR(1) effective sample size ([`likelihood::gaussian_nll`]);
//! - `σ` is the recording's own tracking noise, `1.4826·MAD(Δ²d)/√6`
//!   ([`likelihood::tracking_noise_sigma`]), the same for every candidate;
//! - with `[fit.likelihood] joint_signals`, the spectral term is the multivariate Whittle NLL of
//!   the signals' Welch cross-spectral matrices, and the Fisher information and the sandwich read
//!   their whitened entries ([`joint`]).
//!
//! The **Fisher information** at a fit is the Gauss–Newton form of the same likelihood, positive
//! semi-definite by construction: per band `(α/φ)·Σ_k ∇ln S_k ∇ln S_kᵀ` (α = ν/2 the Gamma shape, φ
//! the band's correlated-bin factor; the Fisher information of a Gamma mean on the log scale is α),
//! plus `(n_eff/n)·Σ_i ∇m_i ∇m_iᵀ / s²` for the residuals, with `s² = max(σ², mean e²)` so that a
//! model that does not reach the tracking noise does not claim the noise's precision (the
//! quasi-likelihood dispersion; McCullagh & Nelder 1989, *Generalized Linear Models*, §9.2). The
//! gradients are central differences in the search's normalised coordinates.
//!
//! The **spread of the estimate** is the sandwich `F⁻¹ V F⁻¹` ([`at_fit`], [`sandwich_covariance`]),
//! with `V` the variance of the NLL's gradient over replicates of the recording's tracking noise:
//! the Whittle-type likelihood's own `F⁻¹` overstates it for a deterministic motion plus noise.

mod joint;

use super::problem::SpectralProblem;
use crate::Result;
use crate::job::NoiseSpectrum;
use crate::likelihood::covariance::{
    cholesky_of_covariance, covariance, effective_parameters, sample_covariance,
    sandwich_covariance,
};
use crate::likelihood::{self, Evidence, WelchLikelihood};
use crate::simulate::blade::BladeSimulation;
use crate::spectrum::noise::{MAX_ABS_RHO, TrackingNoise, ordinate_per_density};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Step of the central differences of the Fisher information, in normalised coordinates (the
/// search box is `[0, 1]` per parameter; 1e-3 is 0.1 % of a linear range, 0.3 % of a decade).
///
/// At the main job's fit, steps of 1e-3 and 3e-3 give nearly the same 1σ; from 1e-2 on, the
/// stick–slip comb's jumps enter the differences and the intervals move.
pub const FISHER_STEP_U: f64 = 3e-3;

/// The largest step the central differences of a coordinate grow to where the response jitters
/// ([`RecordingLikelihood::noise_adapted`]), normalised units: a tenth of the box.
pub const MAX_FISHER_STEP_U: f64 = 0.1;

/// The share of a Jacobian column's information `Σ w J²` that the rounding's noise in its
/// differences may make up before the step grows ([`RecordingLikelihood::noise_adapted`]): at
/// 0.1 the noise inflates that coordinate's information by at most about 10 %, its 1σ by 5 %.
pub const FISHER_NOISE_SHARE: f64 = 0.1;

/// Half-span, in the whitened coordinates of `F⁻¹` (1 = the bowl's 1σ along an axis), of the
/// points whose Jacobians the sandwich averages ([`RecordingLikelihood::smoothed_jacobian`]).
pub const SANDWICH_SPAN_SIGMA: f64 = 0.5;

/// One band's measured side: its likelihood, its ordinates and what the noise's ordinates need.
struct BandTerm {
    lik: WelchLikelihood,
    measured: Vec<f64>,
    /// `cos(2πf/fs)` of the band's bins, for the noise's density.
    cos_w: Vec<f64>,
    /// The band's ordinate of a flat density of 1 unit²/Hz ([`ordinate_per_density`]).
    per_density: f64,
    /// The bins of the band's features the likelihood reads ([`BandTerm::new`]).
    bins: std::ops::Range<usize>,
    /// Their frequencies, Hz, and the band's name: where a misfit is said to sit.
    freq_hz: Vec<f64>,
    name: String,
}

impl BandTerm {
    /// The measured side of the band `b` of a recording sampled at `fs_hz`: its bins at least a
    /// main lobe away from 0 Hz and from Nyquist ([`likelihood::interior_bin`]), where the Welch
    /// ordinates follow the χ²_ν law the likelihood reads (the DC and Nyquist ordinates of a real
    /// series have half its degrees of freedom, and a detrend removes power near 0 Hz; Percival &
    /// Walden 1993, §6.6).
    ///
    /// # Errors
    /// [`likelihood::LikelihoodError::EmptyBand`] when no bin is interior, and those of
    /// [`WelchLikelihood::new`].
    fn new(b: &crate::spectrum::features::BandFeatures, fs_hz: f64) -> Result<Self> {
        let cfg = b.spec.welch_config()?;
        let interior: Vec<usize> = (0..b.freq_hz.len())
            .filter(|&i| likelihood::interior_bin(b.freq_hz[i], fs_hz, &cfg))
            .collect();
        let bins = match (interior.first(), interior.last()) {
            (Some(&lo), Some(&hi)) => lo..hi + 1,
            _ => return Err(likelihood::LikelihoodError::EmptyBand.into()),
        };
        Ok(BandTerm {
            lik: WelchLikelihood::new(&cfg, b.segments, bins.len())?,
            measured: b.psd[bins.clone()].to_vec(),
            cos_w: b.freq_hz[bins.clone()]
                .iter()
                .map(|f| (std::f64::consts::TAU * f / fs_hz).cos())
                .collect(),
            per_density: ordinate_per_density(fs_hz, &cfg),
            freq_hz: b.freq_hz[bins.clone()].to_vec(),
            name: b.spec.name.clone(),
            bins,
        })
    }

    /// The band's ordinates the likelihood reads, of a Welch estimate `psd` over the whole band.
    fn read<'a>(&self, psd: &'a [f64]) -> Result<&'a [f64]> {
        psd.get(self.bins.clone()).ok_or_else(|| {
            likelihood::LikelihoodError::LengthMismatch {
                measured: self.bins.end,
                model: psd.len(),
            }
            .into()
        })
    }

    /// The expected ordinates of `noise` in this band.
    fn noise_ordinates(&self, noise: &TrackingNoise, fs_hz: f64) -> Vec<f64> {
        self.cos_w
            .iter()
            .map(|&c| noise.density_at_cos(c, fs_hz) * self.per_density)
            .collect()
    }
}

/// The measured side of the likelihood of one recording, built once per fit.
pub struct RecordingLikelihood {
    bands: Vec<BandTerm>,
    /// The measured signal (NaN where missing or masked), m.
    measured_x: Vec<f64>,
    /// White-noise σ of the measured signal from its second differences, m
    /// ([`likelihood::tracking_noise_sigma`]): the noise of the `white` spectrum and the time-domain
    /// term, and where the `ar1` profile starts.
    pub sigma_m: f64,
    /// The tracking noise's spectrum ([`NoiseSpectrum`]).
    pub noise_spectrum: NoiseSpectrum,
    /// Sampling rate of the recording, Hz.
    fs_hz: f64,
    /// Whether the time-domain term is part of the likelihood.
    pub time_domain: bool,
    /// The time-domain term's block length, samples: block means with their variance profiled
    /// out ([`likelihood::profiled_gaussian_nll`]); `None` reads every sample at `sigma_m`.
    pub block_len: Option<usize>,
    /// The bands' NLL of the saturated model (every expected ordinate equal to the measured one),
    /// nats: the lowest value each band's term can take.
    saturated_spectral_nats: f64,
    /// Further signals read together with the measured one through their cross-spectra
    /// (`[fit.likelihood] joint_signals`; [`joint`]): the spectral term is then theirs.
    joint: Option<joint::JointSignals>,
    /// Why the job's joint signals are not read: a band too short for their matrix
    /// ([`RecordingLikelihood::with_joint`]).
    pub joint_dropped: Option<crate::estimate::warning::JointDropped>,
}

/// The time-domain term at one simulation.
struct TimeTerm {
    nats: f64,
    n_eff: f64,
    rms: f64,
    rho: f64,
    block_rms: Option<f64>,
}

/// A fit's negative log-likelihood, by term.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NllParts {
    /// Whittle NLL per band (the job's band order), nats.
    pub spectral_nats: Vec<f64>,
    /// Gaussian NLL of the time-domain residuals, nats (absent when the term is off).
    pub time_nats: Option<f64>,
    /// RMS of the de-meaned residuals, m.
    pub residual_rms_m: f64,
    /// Lag-one autocorrelation of the residuals.
    pub residual_rho: f64,
    /// RMS of the residuals' block means, m, when the time-domain term reads block means.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_rms_m: Option<f64>,
    /// Effective number of observations: the bands' independent bins plus (with the time term) the
    /// residuals' AR(1) effective sample size.
    pub n_effective: f64,
    /// Takeuchi's effective number of parameters `tr(F⁺V)` at the fit, when the variability was
    /// estimated ([`at_fit`]; [`crate::likelihood::covariance::effective_parameters`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effective_parameters: Option<f64>,
}

impl NllParts {
    /// The total NLL, nats.
    pub fn total(&self) -> f64 {
        self.spectral_nats.iter().sum::<f64>() + self.time_nats.unwrap_or(0.0)
    }

    /// The candidate's [`Evidence`] with `k` freed parameters.
    pub fn evidence(&self, k: usize) -> Evidence {
        Evidence {
            nll: self.total(),
            k,
            n_effective: self.n_effective,
            effective_parameters: self.effective_parameters,
        }
    }
}

impl RecordingLikelihood {
    /// The likelihood of `problem`'s measurement (its measured features, which hold each band's
    /// ordinates and segment count) with the measured signal `x` (NaN where missing; the problem's
    /// NaN mask applied).
    ///
    /// # Errors
    /// Those of [`likelihood::tracking_noise_sigma`] and [`WelchLikelihood::new`] (e.g. a median
    /// average, whose ordinates are not χ²_ν).
    pub fn new(problem: &SpectralProblem, x: &[f64], time_domain: bool) -> Result<Self> {
        let measured_x: Vec<f64> = x
            .iter()
            .zip(&problem.nan_mask)
            .map(|(v, m)| if *m { f64::NAN } else { *v })
            .collect();
        let sigma_m = likelihood::tracking_noise_sigma(&measured_x)?;
        let bands = problem
            .measured
            .bands
            .iter()
            .map(|b| BandTerm::new(b, problem.fs_hz))
            .collect::<Result<Vec<_>>>()?;
        let saturated_spectral_nats = bands
            .iter()
            .map(|b| b.lik.nll(&b.measured, &b.measured))
            .sum::<std::result::Result<f64, _>>()?;
        Ok(RecordingLikelihood {
            bands,
            measured_x,
            sigma_m,
            noise_spectrum: NoiseSpectrum::White,
            fs_hz: problem.fs_hz,
            time_domain,
            block_len: None,
            saturated_spectral_nats,
            joint: None,
            joint_dropped: None,
        })
    }

    /// The same likelihood with the spectral term of the measured signal and the signals `others`
    /// of the recording `trace` read together through their cross-spectra ([`joint`]); none keeps
    /// the one signal's. Build it after [`RecordingLikelihood::with_noise`]: each signal's noise
    /// follows the likelihood's noise spectrum. Where a band's segments between lost frames cannot
    /// carry the signals' cross-spectral matrix
    /// ([`likelihood::LikelihoodError::TooFewSegmentsForSignals`]), the likelihood keeps the one
    /// signal and says why in [`RecordingLikelihood::joint_dropped`].
    ///
    /// # Errors
    /// A signal the trace lacks, a signal whose noise cannot be estimated.
    pub fn with_joint(
        mut self,
        problem: &SpectralProblem,
        trace: &crate::trace::Trace,
        others: &[crate::spectrum::features::SignalKind],
    ) -> Result<Self> {
        if others.is_empty() {
            return Ok(self);
        }
        let kinds = std::iter::once(problem.signal)
            .chain(others.iter().copied())
            .collect();
        match joint::JointSignals::new(&self, problem, trace, kinds) {
            Ok(j) => self.joint = Some(j),
            Err(e) => match likelihood::LikelihoodError::of(&e) {
                Some(&likelihood::LikelihoodError::TooFewSegmentsForSignals {
                    n_segments,
                    half_dof,
                    signals,
                }) => {
                    self.joint_dropped = Some(crate::estimate::warning::JointDropped {
                        n_segments,
                        half_dof,
                        signals,
                    })
                }
                _ => return Err(e),
            },
        }
        Ok(self)
    }

    /// The signals the spectral term reads together, the measured one first (only it without
    /// joint signals).
    pub fn signals(&self, problem: &SpectralProblem) -> Vec<crate::spectrum::features::SignalKind> {
        match &self.joint {
            Some(j) => j.kinds.clone(),
            None => vec![problem.signal],
        }
    }

    /// The same likelihood with the tracking noise's spectrum `noise`.
    pub fn with_noise(mut self, noise: NoiseSpectrum) -> Self {
        self.noise_spectrum = noise;
        self
    }

    /// The same likelihood with the time-domain term read from block means of `block_len`
    /// samples (see [`RecordingLikelihood::block_len`]).
    pub fn with_blocks(mut self, block_len: Option<usize>) -> Self {
        self.block_len = block_len.filter(|&l| l > 1);
        self
    }

    /// The time-domain term, nats, and its effective number of observations: the Gaussian NLL of
    /// the residuals at the tracking noise (AR(1)-weighted), or of their block means with the
    /// variance profiled out; with the residuals' RMS and lag-one autocorrelation.
    fn time_term(&self, problem: &SpectralProblem, sim: &BladeSimulation) -> Result<TimeTerm> {
        let m = self.model_x(problem, sim)?;
        let e = likelihood::demeaned_residuals(&self.measured_x, &m)?;
        let size = likelihood::effective_sample_size(&e)?;
        let rms = (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt();
        let (nats, n_eff, block_rms) = match self.block_len {
            Some(len) => {
                let (nats, blocks, brms) = self.block_term(&m, len)?;
                (nats, blocks as f64, Some(brms))
            }
            None => (
                likelihood::gaussian_nll(&e, self.sigma_m, size.n_eff)?,
                size.n_eff,
                None,
            ),
        };
        Ok(TimeTerm {
            nats,
            n_eff,
            rms,
            rho: size.rho,
            block_rms,
        })
    }

    /// The block-mean form of the time-domain term for the model signal `m`: its NLL, nats, the
    /// blocks kept and their RMS (at least the block-averaged noise), m.
    fn block_term(&self, m: &[f64], len: usize) -> Result<(f64, usize, f64)> {
        let b = likelihood::block_mean_residuals(&self.measured_x, m, len)?;
        // White tracking noise averages down to σ²/L in a block mean.
        let floor = self.sigma_m * self.sigma_m / len as f64;
        let nats = likelihood::profiled_gaussian_nll(&b, floor)?;
        let rms = (b.iter().map(|v| v * v).sum::<f64>() / b.len() as f64).sqrt();
        Ok((nats, b.len(), rms.max(floor.sqrt())))
    }

    /// The model's expected ordinates of every band: the simulation's plus the tracking noise's
    /// ([`RecordingLikelihood::noise_for`]).
    fn model_psd(&self, problem: &SpectralProblem, sim: &BladeSimulation) -> Result<Vec<Vec<f64>>> {
        let sim_psd = self.sim_psd(problem, sim)?;
        let noise = self.recording_noise(&sim_psd);
        Ok(self.expected(&sim_psd, &noise))
    }

    /// The measured signal's tracking noise beside the simulation's ordinates `sim_psd`: the
    /// recording's own ordinates and σ̂ through [`RecordingLikelihood::noise_for`].
    fn recording_noise(&self, sim_psd: &[Vec<f64>]) -> TrackingNoise {
        let measured: Vec<&[f64]> = self.bands.iter().map(|b| b.measured.as_slice()).collect();
        self.noise_for(sim_psd, &measured, self.sigma_m)
    }

    /// The simulation's Welch ordinates of every band.
    fn sim_psd(&self, problem: &SpectralProblem, sim: &BladeSimulation) -> Result<Vec<Vec<f64>>> {
        let f = problem.model_features(sim)?;
        self.bands
            .iter()
            .zip(&f.bands)
            .map(|(t, b)| Ok(t.read(&b.psd)?.to_vec()))
            .collect()
    }

    /// The expected ordinates of every band: `sim_psd` plus the ordinates of `noise`.
    fn expected(&self, sim_psd: &[Vec<f64>], noise: &TrackingNoise) -> Vec<Vec<f64>> {
        self.bands
            .iter()
            .zip(sim_psd)
            .map(|(b, s)| {
                s.iter()
                    .zip(b.noise_ordinates(noise, self.fs_hz))
                    .map(|(p, n)| p + n)
                    .collect()
            })
            .collect()
    }

    /// The tracking noise the likelihood of ordinates `measured` reads beside the simulation's
    /// `sim_psd`: white of `white_sigma_m` (the recording's or a replicate's second-difference
    /// estimate) for the `white` spectrum, the profile's AR(1) for `ar1`
    /// ([`RecordingLikelihood::profile_noise`]).
    fn noise_for(
        &self,
        sim_psd: &[Vec<f64>],
        measured: &[&[f64]],
        white_sigma_m: f64,
    ) -> TrackingNoise {
        match self.noise_spectrum {
            NoiseSpectrum::White => TrackingNoise::white(white_sigma_m),
            NoiseSpectrum::Ar1 => self.profile_noise(sim_psd, measured, white_sigma_m),
        }
    }

    /// The AR(1) tracking noise that maximises the Whittle likelihood of the bands' ordinates
    /// `measured` given the simulation's `sim_psd`: the noise's σ and ρ profiled out (Pawitan 2001,
    /// *In All Likelihood*, §3.4), by Nelder–Mead over `(ln σ, atanh(ρ/ρ_max))` from white noise of
    /// `start_sigma_m`. The bands share one noise process, so the low band's floor and the high
    /// band's are tied by the AR(1) shape. No simulation: one pass over the bands' bins per step.
    pub fn profile_noise(
        &self,
        sim_psd: &[Vec<f64>],
        measured: &[&[f64]],
        start_sigma_m: f64,
    ) -> TrackingNoise {
        let profile = NoiseProfile {
            lik: self,
            sim_psd,
            measured,
        };
        let start = [start_sigma_m.max(f64::MIN_POSITIVE).ln(), 0.0];
        let simplex = vec![
            start.to_vec(),
            vec![start[0] + 0.3, start[1]],
            vec![start[0], start[1] + 0.5],
        ];
        let solver = argmin::solver::neldermead::NelderMead::new(simplex)
            .with_sd_tolerance(NOISE_PROFILE_SD_NATS)
            .expect("a non-negative tolerance");
        let best = argmin::core::Executor::new(profile, solver)
            .configure(|s| s.max_iters(NOISE_PROFILE_MAX_ITERS))
            .run()
            .ok()
            .and_then(|r| r.state.best_param)
            .unwrap_or_else(|| start.to_vec());
        NoiseProfile::noise(&best)
    }

    /// The tracking noise the likelihood reads at the simulation `sim` (for `ar1` the profile's;
    /// for `white` the recording's fixed estimate).
    ///
    /// # Errors
    /// The simulation's features' errors.
    pub fn noise_at(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
    ) -> Result<TrackingNoise> {
        Ok(self.recording_noise(&self.sim_psd(problem, sim)?))
    }

    /// Each joint signal's tracking noise at the simulation `sim` (the measured signal's is
    /// [`RecordingLikelihood::noise_at`]'s); empty without joint signals.
    ///
    /// # Errors
    /// The simulation's cross-spectra's errors.
    pub fn joint_noises_at(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
    ) -> Result<Vec<(crate::spectrum::features::SignalKind, TrackingNoise)>> {
        let Some(j) = &self.joint else {
            return Ok(Vec::new());
        };
        let noises = j.recording_noises(self, &j.sim_matrices(problem, sim)?);
        Ok(j.kinds.iter().copied().zip(noises).skip(1).collect())
    }

    /// The model's signal at the recording's samples, NaN where the measurement is.
    fn model_x(&self, problem: &SpectralProblem, sim: &BladeSimulation) -> Result<Vec<f64>> {
        let mut x = problem.signal.extract(&sim.to_trace())?;
        for (xi, d) in x.iter_mut().zip(&self.measured_x) {
            if !d.is_finite() {
                *xi = f64::NAN;
            }
        }
        Ok(x)
    }

    /// The measured signal the likelihood reads, m (NaN where missing or masked).
    pub fn measured_signal(&self) -> &[f64] {
        &self.measured_x
    }

    /// The NLL of a simulation, by term.
    ///
    /// # Errors
    /// The features' errors, and [`likelihood::LikelihoodError`] for a non-positive ordinate or
    /// too few residuals.
    pub fn nll(&self, problem: &SpectralProblem, sim: &BladeSimulation) -> Result<NllParts> {
        self.terms(problem, sim)
    }

    /// What the search minimises with `[fit] objective = "likelihood"`: the NLL above the saturated
    /// model's, nats (half the deviance; McCullagh & Nelder 1989, *Generalized Linear Models*,
    /// §2.3). Per band `Σ_k α(ln(S_k/P̂_k) + P̂_k/S_k − 1)/φ ≥ 0`, the Whittle NLL minus its value
    /// at `S = P̂`; with the time-domain term, `(n_eff/n)·Σe²/(2σ²) ≥ 0`, that term minus its
    /// normalisation `(n_eff/2)·ln(2πσ²)`. It differs from [`RecordingLikelihood::nll`]'s total by
    /// a constant of the recording (while the residuals' `n_eff` stays put), so its minimum is the
    /// maximum-likelihood estimate and differences between parameter sets are log-likelihood
    /// ratios.
    ///
    /// # Errors
    /// Those of [`RecordingLikelihood::nll`].
    pub fn excess_nll(&self, problem: &SpectralProblem, sim: &BladeSimulation) -> Result<f64> {
        // The fit's cost: the residuals are only formed when the time-domain term needs them.
        let mut excess = self.spectral_excess_nll(problem, sim)?;
        if self.time_domain {
            excess += match self.block_len {
                Some(len) => self.block_term(&self.model_x(problem, sim)?, len)?.0,
                None => {
                    let t = self.time_term(problem, sim)?;
                    t.nats
                        - 0.5 * t.n_eff * (std::f64::consts::TAU * self.sigma_m * self.sigma_m).ln()
                }
            };
        }
        Ok(excess)
    }

    /// The spectral part of [`RecordingLikelihood::excess_nll`], nats: the bands' NLL above the
    /// saturated model's, of the measured signal or of the joint signals' cross-spectra.
    fn spectral_excess_nll(&self, problem: &SpectralProblem, sim: &BladeSimulation) -> Result<f64> {
        match &self.joint {
            Some(j) => {
                let nats = j.nll(&j.model(self, problem, sim)?)?;
                Ok(nats.iter().sum::<f64>() - j.saturated_nats())
            }
            None => self.signal_excess_nll(problem, sim),
        }
    }

    /// The measured signal's Whittle NLL above the saturated model's, nats: the statistic of
    /// [`RecordingLikelihood::goodness_of_fit`] (the one signal's, also when the fit reads joint
    /// signals).
    fn signal_excess_nll(&self, problem: &SpectralProblem, sim: &BladeSimulation) -> Result<f64> {
        let (spectral_nats, _) = self.signal_terms(problem, sim)?;
        Ok(spectral_nats.iter().sum::<f64>() - self.saturated_spectral_nats)
    }

    /// The spectral NLL of every band, nats (the joint signals' when read), and the bands'
    /// effectively independent bins.
    fn spectral_terms(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
    ) -> Result<(Vec<f64>, f64)> {
        match &self.joint {
            Some(j) => Ok((j.nll(&j.model(self, problem, sim)?)?, j.effective_bins())),
            None => self.signal_terms(problem, sim),
        }
    }

    /// The measured signal's Whittle NLL of every band, nats, and the bands' effectively
    /// independent bins.
    fn signal_terms(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
    ) -> Result<(Vec<f64>, f64)> {
        let psd = self.model_psd(problem, sim)?;
        let mut spectral_nats = Vec::with_capacity(self.bands.len());
        let mut effective_bins = 0.0;
        for (b, s) in self.bands.iter().zip(&psd) {
            spectral_nats.push(b.lik.nll(&b.measured, s)?);
            effective_bins += b.lik.effective_bins();
        }
        Ok((spectral_nats, effective_bins))
    }

    /// The NLL by term.
    fn terms(&self, problem: &SpectralProblem, sim: &BladeSimulation) -> Result<NllParts> {
        let (spectral_nats, mut n_effective) = self.spectral_terms(problem, sim)?;
        let t = self.time_term(problem, sim)?;
        let time_nats = if self.time_domain {
            n_effective += t.n_eff;
            Some(t.nats)
        } else {
            None
        };
        Ok(NllParts {
            spectral_nats,
            time_nats,
            residual_rms_m: t.rms,
            residual_rho: t.rho,
            block_rms_m: t.block_rms,
            n_effective,
            effective_parameters: None,
        })
    }

    /// What one simulation contributes to the Gauss–Newton Fisher information: the log expected
    /// ordinates of every band and the de-meaned model signal (over the samples both sides have).
    /// With joint signals the spectral part is the expected matrices' entries
    /// ([`joint::JointSignals::entries`]), whitened at the fit by [`RecordingLikelihood::jacobian`].
    fn response(&self, problem: &SpectralProblem, sim: &BladeSimulation) -> Result<Vec<f64>> {
        let mut r: Vec<f64> = match &self.joint {
            Some(j) => j.entries(&j.model(self, problem, sim)?),
            None => self
                .model_psd(problem, sim)?
                .into_iter()
                .flatten()
                .map(f64::ln)
                .collect(),
        };
        if self.time_domain
            && let Some(len) = self.block_len
        {
            let m = self.model_x(problem, sim)?;
            r.extend(likelihood::block_means(&self.measured_x, &m, len, |_, m| m));
        } else if self.time_domain {
            let m = self.model_x(problem, sim)?;
            let both: Vec<f64> = m
                .iter()
                .zip(&self.measured_x)
                .filter(|(a, d)| a.is_finite() && d.is_finite())
                .map(|(a, _)| *a)
                .collect();
            let mean = both.iter().sum::<f64>() / both.len().max(1) as f64;
            r.extend(both.iter().map(|v| v - mean));
        }
        Ok(r)
    }

    /// Weight of each response component in the Fisher information (see the module docs); `parts`
    /// are the NLL terms at the fit.
    fn weights(&self, parts: &NllParts, n_time: usize) -> Vec<f64> {
        let mut w = Vec::new();
        match &self.joint {
            Some(j) => w.extend(j.weights()),
            None => {
                for b in &self.bands {
                    w.extend(std::iter::repeat_n(
                        b.lik.dof / 2.0 / b.lik.bin_factor,
                        b.measured.len(),
                    ));
                }
            }
        }
        if self.time_domain
            && let Some(b) = parts.block_rms_m
        {
            // The profiled variance's estimate: 1/s² per block mean.
            w.extend(std::iter::repeat_n(
                1.0 / (b * b).max(f64::MIN_POSITIVE),
                n_time,
            ));
        } else if self.time_domain {
            let s2 = (self.sigma_m * self.sigma_m).max(parts.residual_rms_m.powi(2));
            let n_eff = if parts.residual_rho > 0.0 {
                (1.0 - parts.residual_rho) / (1.0 + parts.residual_rho)
            } else {
                1.0
            };
            w.extend(std::iter::repeat_n(n_eff / s2, n_time));
        }
        w
    }

    /// The Gauss–Newton Fisher information of the likelihood at normalised coordinates `u`, in
    /// normalised coordinates (`k × k`, positive semi-definite), from `2k` simulations at the
    /// problem's solver (one-sided at a bound of the box). `parts`: the NLL at `u`.
    ///
    /// # Errors
    /// A simulation that fails at a displaced point, or responses of different lengths (a
    /// displaced simulation that lost samples).
    pub fn fisher(
        &self,
        problem: &SpectralProblem,
        u: &[f64],
        parts: &NllParts,
    ) -> Result<DMatrix<f64>> {
        self.fisher_with_step(problem, u, parts, FISHER_STEP_U)
    }

    /// [`RecordingLikelihood::fisher`] with central differences of step `h` (normalised units).
    ///
    /// # Errors
    /// As [`RecordingLikelihood::fisher`].
    pub fn fisher_with_step(
        &self,
        problem: &SpectralProblem,
        u: &[f64],
        parts: &NllParts,
        h: f64,
    ) -> Result<DMatrix<f64>> {
        let metric = match self.joint {
            Some(_) => self.metric_at(problem, &problem.simulate(&problem.params_at(u))?)?,
            None => None,
        };
        let j = self.jacobian(problem, u, h, metric.as_ref())?;
        Ok(j.fisher(&self.weights(parts, j.n_time(self))))
    }

    /// The whitening of the joint signals' matrices at the simulation `sim` (the fit's), which
    /// the response's derivatives and the replicates' residuals are read in; `None` for one
    /// signal.
    ///
    /// # Errors
    /// The model's matrices' errors, and a matrix that is not positive definite.
    fn metric_at(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
    ) -> Result<Option<joint::Metric>> {
        self.joint
            .as_ref()
            .map(|j| j.metric(&j.model(self, problem, sim)?))
            .transpose()
    }

    /// Components of the response that belong to the spectral term.
    fn spectral_len(&self) -> usize {
        match &self.joint {
            Some(j) => j.response_len(),
            None => self.bands.iter().map(|b| b.measured.len()).sum(),
        }
    }

    /// The response's derivatives at `u` by central differences of step `h` (one-sided at a bound
    /// of the box, or where a displaced simulation fails: [`difference_column`]): `2k` simulations,
    /// and one more at `u` when a side fails. The joint signals' part is whitened by `metric`
    /// ([`RecordingLikelihood::metric_at`]).
    fn jacobian(
        &self,
        problem: &SpectralProblem,
        u: &[f64],
        h: f64,
        metric: Option<&joint::Metric>,
    ) -> Result<Jacobian> {
        self.jacobian_with_steps(problem, u, &vec![h; u.len()], metric)
    }

    /// [`RecordingLikelihood::jacobian`] with a step of its own for each coordinate.
    fn jacobian_with_steps(
        &self,
        problem: &SpectralProblem,
        u: &[f64],
        steps: &[f64],
        metric: Option<&joint::Metric>,
    ) -> Result<Jacobian> {
        let steps: Vec<(usize, f64)> = steps.iter().copied().enumerate().collect();
        Ok(Jacobian {
            columns: self.difference_columns(problem, u, &steps, metric)?,
        })
    }

    /// The response's derivatives at `u` along the coordinates `steps` names, each by central
    /// differences of its own step ([`difference_column`]), in parallel, the joint signals' part
    /// whitened by `metric`.
    fn difference_columns(
        &self,
        problem: &SpectralProblem,
        u: &[f64],
        steps: &[(usize, f64)],
        metric: Option<&joint::Metric>,
    ) -> Result<Vec<Vec<f64>>> {
        use rayon::prelude::*;
        let response_at = |p: &[f64]| -> Result<Vec<f64>> {
            self.response(problem, &problem.simulate(&problem.params_at(p))?)
        };
        let center = std::sync::OnceLock::<Option<Vec<f64>>>::new();
        let mut columns: Vec<Vec<f64>> = steps
            .par_iter()
            .map(|&(i, h)| {
                let at = |v: f64| {
                    let mut p = u.to_vec();
                    p[i] = v;
                    response_at(&p)
                };
                let center = || center.get_or_init(|| response_at(u).ok()).clone();
                difference_column(at, center, u[i], h)
            })
            .collect::<Result<_>>()?;
        if let (Some(joint), Some(metric)) = (&self.joint, metric) {
            let n = self.spectral_len();
            for c in &mut columns {
                let white = joint.whiten(metric, &c[..n]);
                c[..n].copy_from_slice(&white);
            }
        }
        Ok(columns)
    }

    /// The Jacobian `j` (central differences of [`FISHER_STEP_U`] at `u`) with each column's step
    /// grown, three-fold at a time up to [`MAX_FISHER_STEP_U`], until the rounding's noise makes
    /// up no more than [`FISHER_NOISE_SHARE`] of the column's information. `draws`: the
    /// responses' deviations at the rounding points ([`RecordingLikelihood::rounding_draws`]);
    /// `w`: the weights `W`. Returns the Jacobian, each coordinate's step and the simulations
    /// it took (2 per column recomputed). No draws, or draws that do not differ: `j` as it is.
    ///
    /// Why: where the slip is unstable each simulation carries a draw of the onset's noise of
    /// variance `ε²` per response component ([`RecordingLikelihood::rounding_variability`]), so
    /// a central difference of step `h` carries noise of variance `ε²/(2h²)`, which `JᵀWJ` reads
    /// as information: with the fits' own step the information of such a recording is the
    /// noise's, and the 1σ grows in proportion to the step (docs/validation.md, "Jitter").
    /// Choosing the step against the function's noise is the standard remedy for differences
    /// of a noisy simulation (Moré & Wild 2011, "Estimating derivatives of noisy simulations",
    /// *ACM TOMS* 38:19). Where the response does not jitter the step stays [`FISHER_STEP_U`].
    fn noise_adapted(
        &self,
        problem: &SpectralProblem,
        u: &[f64],
        mut j: Jacobian,
        w: &[f64],
        draws: &[Vec<f64>],
        metric: Option<&joint::Metric>,
    ) -> Result<(Jacobian, Vec<f64>, usize)> {
        let mut steps = vec![FISHER_STEP_U; u.len()];
        let Some(noise) = noise_information(draws, w) else {
            return Ok((j, steps, 0));
        };
        // A column whose larger step lost response samples keeps the step it has.
        let mut kept = vec![false; u.len()];
        let mut sims = 0;
        loop {
            let grow: Vec<(usize, f64)> = (j.columns.iter().enumerate())
                .filter(|(i, c)| {
                    let info: f64 = c.iter().zip(w).map(|(a, wk)| wk * a * a).sum();
                    let h = steps[*i];
                    !kept[*i]
                        && h < MAX_FISHER_STEP_U
                        && noise / (2.0 * h * h) > FISHER_NOISE_SHARE * info
                })
                .map(|(i, _)| (i, (3.0 * steps[i]).min(MAX_FISHER_STEP_U)))
                .collect();
            if grow.is_empty() {
                return Ok((j, steps, sims));
            }
            sims += 2 * grow.len();
            let columns = self.difference_columns(problem, u, &grow, metric)?;
            for (&(i, h), c) in grow.iter().zip(columns) {
                if c.len() == j.columns[i].len() {
                    steps[i] = h;
                    j.columns[i] = c;
                } else {
                    kept[i] = true;
                }
            }
        }
    }

    /// The response's linearisation over the central part of the likelihood's bowl: the mean of
    /// the Jacobian `j` at `u` (each coordinate differenced with its step of `steps`) and of the
    /// Jacobians with the same steps at `u ± r·L eᵢ`, with `r` =
    /// [`SANDWICH_SPAN_SIGMA`], `L` the Cholesky factor of `F⁻¹ = (jᵀWj)⁻¹` (`w`: the weights
    /// `W`) and `eᵢ` the axes; points outside the box are moved onto it, and a displaced Jacobian
    /// whose response lost samples is left out. `j` itself where `F` is singular. Returns the mean
    /// and the number of simulations it took (`2k` per displaced point). A displaced point whose
    /// simulation fails is left out too.
    ///
    /// Why: the stick–slip response is rough below the bowl's scale, so a Jacobian by central
    /// differences at one point moves with the point: on the main job's blade2dof fit, at points
    /// 0.05–0.15 of `F`'s 1σ apart, the sandwich's 1σ of A moved by up to 31 % with one Jacobian.
    /// The estimate itself scatters over about `±0.5σ` of `F` (the sandwich's 1σ is 0.5–0.7 of
    /// `F`'s), so the linearisation that describes its spread is the response's mean slope over
    /// that region, not its slope at the point where one fit happened to end.
    fn smoothed_jacobian(
        &self,
        problem: &SpectralProblem,
        u: &[f64],
        (j, steps): (Jacobian, &[f64]),
        w: &[f64],
        metric: Option<&joint::Metric>,
    ) -> Result<(Jacobian, usize)> {
        let k = u.len();
        let (sigma, corr) = covariance(&j.fisher(w));
        let Some(l) = cholesky_of_covariance(&sigma, &corr) else {
            return Ok((j, 0));
        };
        let (mut sum, mut n, mut sims) = (j.columns, 1.0, 0);
        for i in 0..k {
            for sign in [1.0, -1.0] {
                let at: Vec<f64> = (0..k)
                    .map(|a| (u[a] + sign * SANDWICH_SPAN_SIGMA * l[(a, i)]).clamp(0.0, 1.0))
                    .collect();
                sims += 2 * k;
                let Ok(ji) = self.jacobian_with_steps(problem, &at, steps, metric) else {
                    continue;
                };
                if ji.columns[0].len() != sum[0].len() {
                    continue;
                }
                for (s, c) in sum.iter_mut().zip(&ji.columns) {
                    s.iter_mut().zip(c).for_each(|(x, y)| *x += y);
                }
                n += 1.0;
            }
        }
        sum.iter_mut()
            .for_each(|s| s.iter_mut().for_each(|x| *x /= n));
        Ok((Jacobian { columns: sum }, sims))
    }

    /// The variability matrix `V = Var(∇NLL)` at the fit `sim` (normalised coordinates, `k × k`,
    /// positive semi-definite): the sample covariance, over [`NOISE_REPLICATES`] recordings made of
    /// the fit's signal plus fresh white tracking noise of the recording's `σ`, of the NLL's
    /// gradient `Σ_c w_c r_c ∇resp_c` with the Jacobian `j` of the response at the fit and each
    /// replicate's residuals `r` ([`RecordingLikelihood::replicate_residuals`]). Each replicate
    /// estimates its own tracking noise as the fit does ([`likelihood::tracking_noise_sigma`]), so
    /// `V` carries the noise estimate's error too: `σ̂` scatters by about 1 % over a 0.67 s
    /// window, and the fitted parameters move with the noise density it sets. The replicates need
    /// no simulation: their ordinates go through the measurement's own estimator
    /// ([`crate::spectrum::features::features`], its bands, gap filling and NaN mask).
    /// Deterministic: replicate `r` draws from seed [`NOISE_SEED`]` + r`.
    ///
    /// # Errors
    /// The features' and the noise estimate's errors on a replicate; a replicate whose ordinates
    /// differ in number from the fit's ([`likelihood::LikelihoodError::LengthMismatch`]).
    fn variability(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
        parts: &NllParts,
        j: &Jacobian,
        metric: Option<&joint::Metric>,
    ) -> Result<DMatrix<f64>> {
        use rayon::prelude::*;
        let base = self.replicate_base(problem, sim)?;
        let w = self.weights(parts, j.n_time(self));
        let scores: Vec<Vec<f64>> = (0..NOISE_REPLICATES)
            .into_par_iter()
            .map(|r| Ok(j.score(&w, &self.replicate_residuals(problem, r, &base, metric)?)))
            .collect::<Result<_>>()?;
        Ok(sample_covariance(&scores))
    }

    /// The responses simulated at `u` and at [`crate::search::jitter::JITTER_STEP_U`] either way
    /// along each coordinate ([`crate::search::jitter::rounding_points`]), as deviations from
    /// their mean, the joint signals' part whitened by `metric`; and the simulations made
    /// (`2k + 1`). A step whose simulation fails or whose response differs in length from `len`
    /// (the Jacobian's) is left out; with fewer than three left there are no draws (they cannot
    /// be told from the steps).
    fn rounding_draws(
        &self,
        problem: &SpectralProblem,
        u: &[f64],
        len: usize,
        metric: Option<&joint::Metric>,
    ) -> (Vec<Vec<f64>>, usize) {
        use rayon::prelude::*;
        let points = super::jitter::rounding_points(u);
        let responses: Vec<Vec<f64>> = points
            .par_iter()
            .filter_map(|p| {
                let sim = problem.simulate(&problem.params_at(p)).ok()?;
                self.response(problem, &sim).ok()
            })
            .filter(|r| r.len() == len)
            .collect();
        if responses.len() < 3 {
            return (Vec::new(), points.len());
        }
        let n = responses.len() as f64;
        let mean: Vec<f64> = (0..len)
            .map(|c| responses.iter().map(|r| r[c]).sum::<f64>() / n)
            .collect();
        let draws = responses
            .iter()
            .map(|r| {
                let mut d: Vec<f64> = r.iter().zip(&mean).map(|(a, b)| a - b).collect();
                if let (Some(joint), Some(metric)) = (&self.joint, metric) {
                    let n = self.spectral_len();
                    let white = joint.whiten(metric, &d[..n]);
                    d[..n].copy_from_slice(&white);
                }
                d
            })
            .collect();
        (draws, points.len())
    }

    /// The variability the trajectory's sensitivity to rounding adds to `V`
    /// ([`RecordingLikelihood::variability`]), normalised coordinates (`k × k`, positive
    /// semi-definite): twice the sample covariance of the scores `Jᵀ W (ρ_r − ρ̄)` of the
    /// rounding's draws ([`RecordingLikelihood::rounding_draws`]); zero without draws.
    ///
    /// Why: where the slip near the reversal is unstable, the growing oscillation's onset is seeded
    /// by the integrator's error ([`crate::search::jitter`]), so the model's spectra at one
    /// parameter point are one draw among many that differ by far more than the parameters' effect
    /// over that step. The recording carries a draw of its own and the model at the fit another,
    /// independent of it and of the tracking noise: each adds the draws' covariance to the score's
    /// variance, hence the factor 2. Zero where the motion does not depend on rounding. What it
    /// leaves out: the search picks, among nearby draws, the ones that suit the recording, which
    /// moves the estimate further than one draw does (docs/uncertainty.md, "Jitter").
    fn rounding_variability(&self, j: &Jacobian, w: &[f64], draws: &[Vec<f64>]) -> DMatrix<f64> {
        let k = j.columns.len();
        if draws.len() < 3 {
            return DMatrix::zeros(k, k);
        }
        let scores: Vec<Vec<f64>> = draws.iter().map(|d| j.score(w, d)).collect();
        sample_covariance(&scores) * 2.0
    }

    /// What the noise replicates of the simulation `sim` are drawn around
    /// ([`ReplicateBase`]).
    ///
    /// # Errors
    /// The simulation's features' errors; [`likelihood::LikelihoodError::InvalidSigma`] for a
    /// recording's σ that is no normal distribution's.
    fn replicate_base(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
    ) -> Result<ReplicateBase> {
        let sim_psd = self.sim_psd(problem, sim)?;
        let noise = self.recording_noise(&sim_psd);
        if !(noise.sigma_m.is_finite() && noise.sigma_m > 0.0) {
            return Err(likelihood::LikelihoodError::InvalidSigma {
                sigma: noise.sigma_m,
            }
            .into());
        }
        let joint = match &self.joint {
            Some(j) => {
                let signals = j.model_signals(sim)?;
                let sim = j.sim_matrices(problem, sim)?;
                Some(JointBase {
                    noises: j.recording_noises(self, &sim),
                    signals,
                    sim,
                })
            }
            None => None,
        };
        Ok(ReplicateBase {
            m: self.model_x(problem, sim)?,
            sim_psd,
            noise,
            joint,
        })
    }

    /// A replicate's Welch ordinates through the measurement's estimator, and per band the noise
    /// ordinates the replicate's own noise estimate gives (as the fit estimates the recording's:
    /// its own `σ̂`, or its own profile against the simulation's ordinates `base`).
    fn replicate_spectra(
        &self,
        problem: &SpectralProblem,
        x: &[f64],
        base: &ReplicateBase,
    ) -> Result<ReplicateSpectra> {
        let sigma = likelihood::tracking_noise_sigma(x)?;
        let f = crate::spectrum::features::features(
            x,
            problem.fs_hz,
            &problem.bands,
            problem.max_fill,
        )?;
        let measured = self
            .bands
            .iter()
            .zip(&f.bands)
            .map(|(t, b)| Ok(t.read(&b.psd)?.to_vec()))
            .collect::<Result<Vec<Vec<f64>>>>()?;
        let views: Vec<&[f64]> = measured.iter().map(Vec::as_slice).collect();
        let noise = self.noise_for(&base.sim_psd, &views, sigma);
        let ordinates = self
            .bands
            .iter()
            .map(|b| b.noise_ordinates(&noise, self.fs_hz))
            .collect();
        Ok((measured, ordinates))
    }

    /// Noise replicate `r`'s residuals in the response's order: per spectral ordinate
    /// `1 − P̂_k/S_k` with `S_k` the simulation's ordinate `sim_psd` plus the noise density of the
    /// replicate's own `σ̂` (with joint signals, the whitened `S − P̂` of their matrices,
    /// [`joint::JointSignals::replicate_residuals`]); per time-domain sample or block mean the
    /// negated noise, de-meaned. The replicate is drawn around `base`.
    fn replicate_residuals(
        &self,
        problem: &SpectralProblem,
        r: usize,
        base: &ReplicateBase,
        metric: Option<&joint::Metric>,
    ) -> Result<Vec<f64>> {
        let x = base.signal(r);
        let mut res = match (&self.joint, &base.joint, metric) {
            (Some(j), Some(b), Some(metric)) => {
                j.replicate_residuals(self, problem, &b.sim, &b.replicate(r), metric)?
            }
            _ => self.signal_residuals(problem, &x, base)?,
        };
        if self.time_domain {
            res.extend(self.time_residuals(&x, &base.m)?.into_iter().map(|e| -e));
        }
        Ok(res)
    }

    /// The measured signal's spectral residuals of a replicate `x` drawn around `base`: per
    /// ordinate `1 − P̂_k/S_k` ([`RecordingLikelihood::replicate_residuals`]).
    fn signal_residuals(
        &self,
        problem: &SpectralProblem,
        x: &[f64],
        base: &ReplicateBase,
    ) -> Result<Vec<f64>> {
        let (f, noise) = self.replicate_spectra(problem, x, base)?;
        let mut res = Vec::with_capacity(base.m.len());
        for ((fb, s), noise) in f.iter().zip(&base.sim_psd).zip(noise) {
            if fb.len() != s.len() || noise.len() != s.len() {
                return Err(likelihood::LikelihoodError::LengthMismatch {
                    measured: fb.len(),
                    model: s.len(),
                }
                .into());
            }
            res.extend(
                fb.iter()
                    .zip(s)
                    .zip(&noise)
                    .map(|((p, s), n)| 1.0 - p / (s + n)),
            );
        }
        Ok(res)
    }

    /// The goodness of fit of the simulation `sim` to the recording's spectra
    /// ([`likelihood::GoodnessOfFit`]): the recording's spectral excess NLL against that of
    /// [`GOODNESS_OF_FIT_REPLICATES`] noise replicates of `sim`
    /// ([`RecordingLikelihood::replicate_excess_nll`]). One Welch estimate per band and replicate;
    /// no simulation.
    ///
    /// # Errors
    /// Those of [`RecordingLikelihood::replicate_excess_nll`] and
    /// [`likelihood::GoodnessOfFit::of`].
    pub fn goodness_of_fit(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
    ) -> Result<likelihood::GoodnessOfFit> {
        let observed = self.signal_excess_nll(problem, sim)?;
        let replicates = self.replicate_excess_nll(problem, sim, GOODNESS_OF_FIT_REPLICATES)?;
        Ok(likelihood::GoodnessOfFit::of(observed, &replicates)?)
    }

    /// Where the simulation `sim`'s spectra depart from the recording's, band by band
    /// ([`likelihood::misfit::band_misfit`]): what a failed goodness-of-fit test says in words.
    ///
    /// # Errors
    /// Those of the model's spectra and of [`likelihood::misfit::band_misfit`].
    pub fn misfit_shape(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
    ) -> Result<Vec<likelihood::misfit::BandMisfit>> {
        let psd = self.model_psd(problem, sim)?;
        self.bands
            .iter()
            .zip(&psd)
            .map(|(b, s)| {
                Ok(likelihood::misfit::band_misfit(
                    &b.name,
                    &b.lik,
                    &b.freq_hz,
                    &b.measured,
                    s,
                )?)
            })
            .collect()
    }

    /// The spectral excess NLL ([`RecordingLikelihood::excess_nll`]'s spectral part, nats) of
    /// `replicates` recordings made of the simulation `sim`'s signal plus fresh white tracking noise
    /// of the recording's `σ`, each read as the fit reads the recording: its own noise estimate, its
    /// Welch ordinates through the measurement's estimator, against the simulation's ordinates plus
    /// its noise density, above its own saturated model. Replicate `r` draws from seed
    /// [`NOISE_SEED`]` + r`; no simulation.
    ///
    /// # Errors
    /// As [`RecordingLikelihood::variability`].
    pub fn replicate_excess_nll(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
        replicates: usize,
    ) -> Result<Vec<f64>> {
        use rayon::prelude::*;
        let base = self.replicate_base(problem, sim)?;
        (0..replicates)
            .into_par_iter()
            .map(|r| {
                let x = base.signal(r);
                let (f, noise) = self.replicate_spectra(problem, &x, &base)?;
                let mut excess = 0.0;
                for (((fb, s), noise), b) in f.iter().zip(&base.sim_psd).zip(noise).zip(&self.bands)
                {
                    let expected: Vec<f64> = s.iter().zip(noise).map(|(v, n)| v + n).collect();
                    excess += b.lik.nll(fb, &expected)? - b.lik.nll(fb, fb)?;
                }
                Ok(excess)
            })
            .collect()
    }

    /// The time-domain residuals of a signal `x` against the model signal `m`, in the order and
    /// form of the response's time-domain part: de-meaned per sample
    /// ([`likelihood::demeaned_residuals`]) or de-meaned block means
    /// ([`likelihood::block_mean_residuals`]).
    fn time_residuals(&self, x: &[f64], m: &[f64]) -> Result<Vec<f64>> {
        Ok(match self.block_len {
            Some(len) => likelihood::block_mean_residuals(x, m, len)?,
            None => likelihood::demeaned_residuals(x, m)?,
        })
    }
}

/// Recordings of noise the variability matrix is estimated from
/// ([`RecordingLikelihood::variability`]). The 1σ it gives has a relative Monte Carlo error of
/// about `1/√(2R)`, 4.4 % for R = 256; each replicate costs one Welch estimate per band and no
/// simulation.
pub const NOISE_REPLICATES: usize = 256;

/// What noise replicates of a simulation are drawn around: the model's signal at the recording's
/// samples (NaN where the recording is), its Welch ordinates per band, and the tracking noise the
/// likelihood reads at the simulation (white of the recording's `σ`, or the `ar1` profile's).
struct ReplicateBase {
    m: Vec<f64>,
    sim_psd: Vec<Vec<f64>>,
    noise: TrackingNoise,
    joint: Option<JointBase>,
}

/// What noise replicates of the joint signals are drawn around: the simulation's signals (NaN
/// where the recording's are), their matrices, and each signal's noise at the fit.
struct JointBase {
    signals: Vec<Vec<f64>>,
    sim: Vec<joint::Matrices>,
    noises: Vec<TrackingNoise>,
}

impl JointBase {
    /// Replicate `r`'s signals: each simulated signal plus its own noise. The measured signal's
    /// noise is drawn from seed [`NOISE_SEED`]` + r` as [`ReplicateBase::signal`]'s, signal `a`'s
    /// from that seed plus `a·2³²`.
    fn replicate(&self, r: usize) -> Vec<Vec<f64>> {
        self.signals
            .iter()
            .zip(&self.noises)
            .enumerate()
            .map(|(a, (m, noise))| {
                let seed = NOISE_SEED
                    .wrapping_add(r as u64)
                    .wrapping_add((a as u64) << 32);
                with_noise(m, noise, seed)
            })
            .collect()
    }
}

/// `m` plus `noise` drawn from `seed`.
fn with_noise(m: &[f64], noise: &TrackingNoise, seed: u64) -> Vec<f64> {
    use rand::SeedableRng;
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    m.iter()
        .zip(noise.sample(m.len(), &mut rng))
        .map(|(v, e)| v + e)
        .collect()
}

impl ReplicateBase {
    /// Replicate `r`'s signal: `m` plus the noise drawn from seed [`NOISE_SEED`]` + r`.
    fn signal(&self, r: usize) -> Vec<f64> {
        with_noise(&self.m, &self.noise, NOISE_SEED + r as u64)
    }
}

/// Convergence of the noise profile ([`RecordingLikelihood::profile_noise`]): the simplex's
/// spread of NLL values, nats; far below the 0.1-nat scale on which fits are compared.
const NOISE_PROFILE_SD_NATS: f64 = 1e-7;

/// Nelder–Mead iterations the noise profile may take (it converges in about 60–100 in two
/// dimensions).
const NOISE_PROFILE_MAX_ITERS: u64 = 400;

/// The bands' Whittle NLL as a function of the noise's `(ln σ, atanh(ρ/ρ_max))`, for
/// [`RecordingLikelihood::profile_noise`].
struct NoiseProfile<'a> {
    lik: &'a RecordingLikelihood,
    sim_psd: &'a [Vec<f64>],
    measured: &'a [&'a [f64]],
}

impl NoiseProfile<'_> {
    /// The noise at the profile's coordinates `p`.
    fn noise(p: &[f64]) -> TrackingNoise {
        TrackingNoise::ar1(p[0].exp(), MAX_ABS_RHO * p[1].tanh())
    }
}

impl argmin::core::CostFunction for NoiseProfile<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, p: &Self::Param) -> std::result::Result<f64, argmin::core::Error> {
        let noise = Self::noise(p);
        let mut nll = 0.0;
        for ((b, s), d) in self.lik.bands.iter().zip(self.sim_psd).zip(self.measured) {
            let expected: Vec<f64> = s
                .iter()
                .zip(&b.cos_w)
                .map(|(v, &c)| v + noise.density_at_cos(c, self.lik.fs_hz) * b.per_density)
                .collect();
            nll += match b.lik.nll(d, &expected) {
                Ok(v) => v,
                Err(_) => return Ok(f64::INFINITY),
            };
        }
        Ok(nll)
    }
}

/// Noise replicates of a goodness-of-fit test ([`RecordingLikelihood::goodness_of_fit`]): 999
/// resolve a p-value of 0.001 (Davison & Hinkley 1997, §4.2, on the
/// number of simulations); each costs a noise draw and its Welch estimate, no simulation.
pub const GOODNESS_OF_FIT_REPLICATES: usize = 999;

/// Seed of the first noise replicate ([`RecordingLikelihood::variability`]).
pub const NOISE_SEED: u64 = 0x05ee_d0f7_015e;

/// One column of a Jacobian: the derivative of the response `at(v)` with respect to one
/// normalised coordinate at `u_i` (inside `[0, 1]`), by central differences of step `h`.
///
/// Where one side's simulation fails or loses samples (a displaced point beyond the model's
/// validity, e.g. a lip that loses contact with the glass), the derivative is the one-sided
/// difference between the other side and `center()` (the response at `u_i`), first-order instead
/// of second-order accurate (Nocedal & Wright 2006, *Numerical Optimization*, §8.1). Where both
/// sides fail, the same is tried at `h/4` before giving up.
///
/// # Errors
/// The first side's error (or a length mismatch) when no step gives a difference.
fn difference_column(
    at: impl Fn(f64) -> Result<Vec<f64>>,
    center: impl Fn() -> Option<Vec<f64>>,
    u_i: f64,
    h: f64,
) -> Result<Vec<f64>> {
    let mut first_error = None;
    for step in [h, 0.25 * h] {
        let (lo, hi) = ((u_i - step).max(0.0), (u_i + step).min(1.0));
        let (a, b) = (at(lo), at(hi));
        if let (Ok(a), Ok(b)) = (&a, &b)
            && a.len() == b.len()
        {
            return Ok(slope(a, lo, b, hi));
        }
        if let Some(c) = center() {
            let fits = |r: &Result<Vec<f64>>| matches!(r, Ok(r) if r.len() == c.len());
            if hi > u_i && fits(&b) {
                return Ok(slope(&c, u_i, b.as_ref().expect("checked"), hi));
            }
            if lo < u_i && fits(&a) {
                return Ok(slope(a.as_ref().expect("checked"), lo, &c, u_i));
            }
        }
        first_error.get_or_insert(match (a, b) {
            (Err(e), _) | (_, Err(e)) => e,
            (Ok(a), Ok(b)) => likelihood::LikelihoodError::LengthMismatch {
                measured: a.len(),
                model: b.len(),
            }
            .into(),
        });
    }
    Err(first_error.expect("two steps were tried"))
}

/// `Σ_c w_c ε_c²`: the rounding's noise variance `ε_c²` of each response component (the sample
/// variance over `draws`, deviations from their mean) weighted by `w`; `None` without three
/// draws or where the draws do not differ.
fn noise_information(draws: &[Vec<f64>], w: &[f64]) -> Option<f64> {
    if draws.len() < 3 {
        return None;
    }
    let n = draws.len() as f64;
    let total: f64 = w
        .iter()
        .enumerate()
        .map(|(c, wc)| wc * draws.iter().map(|d| d[c] * d[c]).sum::<f64>() / (n - 1.0))
        .sum();
    (total > 0.0 && total.is_finite()).then_some(total)
}

/// `(r1 − r0)/(v1 − v0)` component by component.
fn slope(r0: &[f64], v0: f64, r1: &[f64], v1: f64) -> Vec<f64> {
    r1.iter()
        .zip(r0)
        .map(|(y1, y0)| (y1 - y0) / (v1 - v0))
        .collect()
}

/// The response's derivatives in the normalised coordinates: one column per coordinate.
struct Jacobian {
    columns: Vec<Vec<f64>>,
}

impl Jacobian {
    /// Components of the response that belong to the time-domain term.
    fn n_time(&self, lik: &RecordingLikelihood) -> usize {
        self.columns[0].len() - lik.spectral_len()
    }

    /// `Jᵀ W J` for per-component weights `w`.
    fn fisher(&self, w: &[f64]) -> DMatrix<f64> {
        let k = self.columns.len();
        DMatrix::from_fn(k, k, |i, j| {
            self.columns[i]
                .iter()
                .zip(&self.columns[j])
                .zip(w)
                .map(|((a, b), wk)| wk * a * b)
                .sum()
        })
    }

    /// `Jᵀ W r`: the NLL's gradient for per-component residuals `r`.
    fn score(&self, w: &[f64], r: &[f64]) -> Vec<f64> {
        self.columns
            .iter()
            .map(|c| {
                c.iter()
                    .zip(w)
                    .zip(r)
                    .map(|((a, wk), rk)| a * wk * rk)
                    .sum()
            })
            .collect()
    }
}

/// A candidate's fit read through the likelihood: its NLL by term, the spread of its estimate
/// (the sandwich) and the likelihood's own curvature (the Fisher information).
#[derive(Debug, Clone)]
pub struct LocalFit {
    /// The NLL at the fit (a joint fit's recordings summed: bands in order, recording after
    /// recording).
    pub nll: NllParts,
    /// 1σ of each normalised coordinate's estimate, from the sandwich `F⁻¹ V F⁻¹`
    /// ([`sandwich_covariance`]); ∞ where the likelihood is flat.
    pub sigma_u: Vec<f64>,
    /// Correlations of the estimate (NaN for a parameter with infinite σ).
    pub corr: Vec<Vec<f64>>,
    /// 1σ of each normalised coordinate from the inverse Fisher information `F⁻¹` alone: the
    /// width of the likelihood's bowl, which [`settle`]'s Newton steps read.
    pub curvature_sigma_u: Vec<f64>,
    /// Correlations of `F⁻¹`.
    pub curvature_corr: Vec<Vec<f64>>,
    /// Per coordinate, `sigma_u` over the sandwich's 1σ with the tracking noise's `V` alone: how
    /// much the rounding's draws widen the spread ([`at_fit_smoothed`]; 1 for [`at_fit`], NaN
    /// where either 1σ is not finite and positive).
    pub rounding_widening: Vec<f64>,
    /// The step of each coordinate's central differences in `F` and `V` (normalised units):
    /// [`FISHER_STEP_U`], grown where the rounding's noise would make up the information
    /// ([`at_fit_smoothed`]; the main recording's in a joint fit).
    pub fisher_steps_u: Vec<f64>,
}

/// The likelihood of `problem`'s recording (and of a joint fit's further recordings, whose NLLs,
/// Fisher informations and variabilities add) at normalised coordinates `u`: `1 + 2k`
/// simulations per recording, counted as model evaluations, and [`NOISE_REPLICATES`] Welch
/// estimates of noise replicates per recording (no simulation).
///
/// **Why a sandwich.** The Whittle-type likelihood reads every ordinate as a Gaussian process's
/// (`P̂ = S·χ²_ν/ν`, variance `S²/α`), and its composite form divides by the bins' correlation
/// factor for a spectrum that moves smoothly across a band. A recording of a blade is a
/// deterministic motion plus white tracking noise: where the motion's lines stand above the noise
/// an ordinate varies far less than `S²/α` (the noise enters through its cross term with the
/// line), and a parameter that shifts a line moves neighbouring ordinates in opposite directions,
/// which the correlation factor does not describe. The likelihood's maximum is still a consistent
/// estimate, but `F⁻¹` is not its spread: the spread of the maximiser of a misspecified or
/// composite likelihood is `F⁻¹ V F⁻¹` with `V` the variance of the NLL's gradient under the data's
/// actual law (Godambe 1960, *Ann. Math. Stat.* 31:1208; White 1982, *Econometrica* 50:1, eq. 3.3;
/// Varin, Reid & Firth 2011, *Statistica Sinica* 21:5, §2.3, where `V` may be estimated by
/// simulation). `V` is estimated here from the recording's own noise model, the fit's signal plus
/// white noise of the recording's `σ` ([`RecordingLikelihood::variability`]). Where the likelihood
/// is right (Gaussian-process ordinates, independent bins) `V = F` and the sandwich is `F⁻¹`. Model
/// choice keeps the likelihood's NLL; only the spread changes.
///
/// # Errors
/// [`crate::Error::Fit`] with the reason when a recording has no likelihood (a target job); the
/// simulations', the replicates' and the likelihood's errors.
pub fn at_fit(problem: &SpectralProblem, u: &[f64]) -> Result<LocalFit> {
    local_fit(problem, u, Spread::AtPoint)
}

/// [`at_fit`] with `F` and `V` from the response's Jacobian averaged over the central part of the
/// likelihood's bowl ([`RecordingLikelihood::smoothed_jacobian`]), and with the variability the
/// trajectory's sensitivity to rounding adds to `V`
/// ([`RecordingLikelihood::rounding_variability`]): the spread the chosen model's intervals
/// report. Costs `2k` more Jacobians and `2k + 1` rounding steps (`4k² + 2k + 1` simulations)
/// per recording. The effective number of parameters ([`NllParts::effective_parameters`]) reads
/// the tracking noise's `V` alone, as [`at_fit`]'s does.
///
/// # Errors
/// As [`at_fit`].
pub fn at_fit_smoothed(problem: &SpectralProblem, u: &[f64]) -> Result<LocalFit> {
    local_fit(problem, u, Spread::Smoothed)
}

/// [`at_fit`] and [`at_fit_smoothed`].
fn local_fit(problem: &SpectralProblem, u: &[f64], spread: Spread) -> Result<LocalFit> {
    let (mut nll, mut info, var) = information(problem, u, spread)?;
    let (mut var, rounding, fisher_steps_u) = var.expect("asked for");
    // Model choice reads the likelihood's own penalty, whose V is the tracking noise's; the
    // rounding's draws then widen the spread, and the prior's information adds to both sides of
    // the sandwich as a pseudo-observation's (docs/priors.md, "Priors").
    nll.effective_parameters = Some(effective_parameters(&info, &var));
    let prior = problem.prior.information_u(&problem.free, &problem.base, u);
    info += &prior;
    var += prior;
    let (noise_sigma_u, _) = sandwich_covariance(&info, &var);
    var += rounding;
    let (sigma_u, corr) = sandwich_covariance(&info, &var);
    let (curvature_sigma_u, curvature_corr) = covariance(&info);
    let rounding_widening = sigma_u
        .iter()
        .zip(&noise_sigma_u)
        .map(|(with, without)| with / without)
        .collect();
    Ok(LocalFit {
        nll,
        sigma_u,
        corr,
        curvature_sigma_u,
        curvature_corr,
        rounding_widening,
        fisher_steps_u,
    })
}

/// The 1σ and correlations of the inverse Fisher information `F⁻¹` at `u` (as
/// [`LocalFit::curvature_sigma_u`] and [`LocalFit::curvature_corr`]), without the variability:
/// `1 + 2k` simulations per recording and no noise replicates.
///
/// # Errors
/// As [`at_fit`].
pub fn curvature_at(problem: &SpectralProblem, u: &[f64]) -> Result<(Vec<f64>, Vec<Vec<f64>>)> {
    let (_, info, _) = information(problem, u, Spread::CurvatureOnly)?;
    Ok(covariance(
        &(info + problem.prior.information_u(&problem.free, &problem.base, u)),
    ))
}

/// The NLL, the Fisher information and (unless `spread` is [`Spread::CurvatureOnly`]) the
/// variability of `problem`'s recordings at `u`, summed over a joint fit's recordings
/// ([`at_fit`]).
fn information(
    problem: &SpectralProblem,
    u: &[f64],
    spread: Spread,
) -> Result<(NllParts, DMatrix<f64>, Option<Variability>)> {
    let mut nll: Option<NllParts> = None;
    let mut info = DMatrix::<f64>::zeros(u.len(), u.len());
    let mut var = DMatrix::<f64>::zeros(u.len(), u.len());
    let mut rounding = DMatrix::<f64>::zeros(u.len(), u.len());
    let mut main_steps: Option<Vec<f64>> = None;
    for p in std::iter::once(problem).chain(&problem.others) {
        let lik = p
            .likelihood
            .as_ref()
            .map_err(|why| super::FitError::NoLikelihood { why: why.clone() })?;
        let sim = p.simulate(&p.params_at(u))?;
        let parts = lik.nll(p, &sim)?;
        let metric = lik.metric_at(p, &sim)?;
        let j = lik.jacobian(p, u, FISHER_STEP_U, metric.as_ref())?;
        let w = lik.weights(&parts, j.n_time(lik));
        let mut sims = 1 + 2 * u.len();
        let j = match spread {
            Spread::Smoothed => {
                let len = j.columns[0].len();
                let (draws, rounding_sims) = lik.rounding_draws(p, u, len, metric.as_ref());
                let (j, steps, grown) = lik.noise_adapted(p, u, j, &w, &draws, metric.as_ref())?;
                main_steps.get_or_insert_with(|| steps.clone());
                let (j, more) = lik.smoothed_jacobian(p, u, (j, &steps), &w, metric.as_ref())?;
                rounding += lik.rounding_variability(&j, &w, &draws);
                sims += rounding_sims + grown + more;
                j
            }
            Spread::CurvatureOnly | Spread::AtPoint => j,
        };
        info += j.fisher(&w);
        if spread != Spread::CurvatureOnly {
            var += lik.variability(p, &sim, &parts, &j, metric.as_ref())?;
        }
        problem
            .evaluations
            .fetch_add(sims, std::sync::atomic::Ordering::Relaxed);
        nll = Some(match nll {
            None => parts,
            Some(mut acc) => {
                acc.spectral_nats.extend(parts.spectral_nats);
                acc.time_nats = match (acc.time_nats, parts.time_nats) {
                    (None, None) => None,
                    (a, b) => Some(a.unwrap_or(0.0) + b.unwrap_or(0.0)),
                };
                acc.n_effective += parts.n_effective;
                acc.residual_rms_m = acc.residual_rms_m.max(parts.residual_rms_m);
                acc.residual_rho = acc.residual_rho.max(parts.residual_rho);
                acc
            }
        });
    }
    Ok((
        nll.expect("the main recording is always there"),
        info,
        (spread != Spread::CurvatureOnly).then(|| {
            let steps = main_steps.unwrap_or_else(|| vec![FISHER_STEP_U; u.len()]);
            (var, rounding, steps)
        }),
    ))
}

/// The variability `V` of [`information`]: the tracking noise's
/// ([`RecordingLikelihood::variability`]) and the rounding's
/// ([`RecordingLikelihood::rounding_variability`], zero unless [`Spread::Smoothed`]), and the
/// main recording's steps of the differences ([`LocalFit::fisher_steps_u`]).
type Variability = (DMatrix<f64>, DMatrix<f64>, Vec<f64>);

/// What [`information`] linearises the response with, and whether it estimates the variability.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Spread {
    /// `F` from the Jacobian at the point; no variability.
    CurvatureOnly,
    /// `F` and `V` from the Jacobian at the point.
    AtPoint,
    /// `F` and `V` from the Jacobian averaged over the bowl's centre
    /// ([`RecordingLikelihood::smoothed_jacobian`]), and the rounding's variability
    /// ([`RecordingLikelihood::rounding_variability`]).
    Smoothed,
}

/// Rounds of [`settle`]: each fits a quadratic to the cost over a design around the last round's
/// minimum and moves to the quadratic's minimum.
pub const SETTLE_ROUNDS: usize = 3;

/// Sizes of [`settle`]'s design ([`surface_design`]), in the whitened coordinates of `F⁻¹` (1 =
/// one standard deviation of the bowl along that direction): the cube's half-side and the axial
/// points' radius.
pub const SETTLE_DESIGN_RADII: [f64; 2] = [0.5, 1.0];

/// The most [`settle`] may raise the cost above the search's end, nats: the rise of a quadratic
/// NLL at 1σ.
pub const SETTLE_MAX_RISE_NATS: f64 = 0.5;

/// The most simulations [`settle`] takes for `k` coordinates: `F` at the start, every round's
/// design, the settled point's cost and [`at_fit`] there.
pub fn settle_evaluations(k: usize) -> usize {
    (1 + 2 * k) + SETTLE_ROUNDS * surface_design(k).len() + 1 + (1 + 2 * k)
}

/// [`settle_point`] and [`at_fit`] at the settled point: the point, its cost and its local fit.
///
/// # Errors
/// Those of [`settle_point`] and [`at_fit`].
pub fn settle(
    problem: &SpectralProblem,
    u0: &[f64],
    cost0: f64,
) -> Result<(Vec<f64>, f64, LocalFit)> {
    let (u, cost) = settle_point(problem, u0, cost0)?;
    let local = at_fit(problem, &u)?;
    Ok((u, cost, local))
}

/// The likelihood's optimum at the scale of its own intervals, from a search's end `u0` of cost
/// `cost0`: [`SETTLE_ROUNDS`] rounds of a quadratic response surface ([`surface_step`]), each
/// fitted by least squares to the cost at a design of points around the last round's minimum
/// (radii [`SETTLE_DESIGN_RADII`] in the whitened coordinates of the Fisher information `F` at
/// `u0`, [`curvature_at`]) and moving to its minimum, clamped to the design's radius and the box.
/// Returns the point and its cost; `u0` and `cost0` when no round can be taken (a coordinate the
/// likelihood does not inform, a design that would leave the box, a failed simulation in it) or
/// when the settled point's cost exceeds `cost0` by more than [`SETTLE_MAX_RISE_NATS`] (then the
/// bowl is not quadratic over its interval).
///
/// Why: the stick–slip likelihood is rough at a scale far below its intervals. On the main job's
/// fit its cost jitters by about 0.05 nats between points σ/50 apart, while its bowl rises by
/// tenths of a nat to nats at ±σ/2, so a Nelder–Mead polish stops in whichever ripple it meets,
/// and two swarm seeds ended up to 0.4 of an interval's width apart (docs/validation.md, "Settling"). A
/// quadratic fitted over a design one standard deviation wide sees the bowl, not the ripples
/// (response-surface methodology: Box & Wilson 1951, *J. R. Stat. Soc. B* 13:1; as a filter of a
/// rough objective, Kelley 2011, *Implicit Filtering*, SIAM, ch. 1), and the Laplace interval
/// assumes that bowl. The surface's own Hessian is used, not `F`: the likelihood is misspecified,
/// so its curvature is not the Fisher information's, and Newton steps with `F` crawl along the
/// correlated valleys (A–B, C–k1) instead of reaching their floor. `F` only shapes the design.
/// Costs `1 + 2k` simulations for `F`, the design's points per round ([`surface_design`]: 25 for
/// k = 4 coordinates, 45 for 6) and one for the settled point's cost.
///
/// # Errors
/// Those of [`curvature_at`] at `u0`.
pub fn settle_point(problem: &SpectralProblem, u0: &[f64], cost0: f64) -> Result<(Vec<f64>, f64)> {
    use rayon::prelude::*;
    let (sigma, corr) = curvature_at(problem, u0)?;
    let costs = |points: &[Vec<f64>]| -> Vec<f64> {
        points.par_iter().map(|p| problem.cost_at(p)).collect()
    };
    let mut u = u0.to_vec();
    for _ in 0..SETTLE_ROUNDS {
        let Some(next) = surface_step(&u, &sigma, &corr, costs) else {
            break;
        };
        u = next;
    }
    if u == u0 {
        return Ok((u, cost0));
    }
    let cost = problem.cost_at(&u);
    if cost.is_finite() && cost <= cost0 + SETTLE_MAX_RISE_NATS {
        Ok((u, cost))
    } else {
        Ok((u0.to_vec(), cost0))
    }
}

/// The design of [`surface_step`] in whitened coordinates, a central composite design (Box &
/// Wilson 1951): the centre, the corners `(±a, …, ±a)` of a cube of half-side
/// `a` = [`SETTLE_DESIGN_RADII`]`[0]` (all `2^k` for `k ≤ 4`; for more coordinates the half
/// whose last sign is the product of the others, a resolution-`k` fraction that still separates
/// every linear, square and cross term), and `±α` on every axis, `α` = [`SETTLE_DESIGN_RADII`]`[1]`.
/// With `α = 2a` it is rotatable for `k = 4`. `1 + 2k + 2^k` points (`2^(k−1)` for `k ≥ 5`): 25
/// for four coordinates, 45 for six.
fn surface_design(k: usize) -> Vec<Vec<f64>> {
    let [side, axial] = SETTLE_DESIGN_RADII;
    let mut d = vec![vec![0.0; k]];
    let free = if k <= 4 { k } else { k - 1 };
    for bits in 0..(1usize << free) {
        let mut z: Vec<f64> = (0..free)
            .map(|i| if bits >> i & 1 == 1 { side } else { -side })
            .collect();
        if free < k {
            let sign: f64 = z.iter().map(|x| x.signum()).product();
            z.push(sign * side);
        }
        d.push(z);
    }
    for i in 0..k {
        for sign in [1.0, -1.0] {
            let mut z = vec![0.0; k];
            z[i] = sign * axial;
            d.push(z);
        }
    }
    d
}

/// One round of [`settle`] from `u`, with the 1σ `sigma` and correlations `corr` of `F⁻¹`: the
/// cost (`costs` evaluates a list of points) at [`surface_design`] mapped by `u + L z` (`L` the
/// Cholesky factor of `F⁻¹`), a quadratic `c + gᵀz + ½ zᵀHz` fitted by least squares, and the
/// point of its minimum `z = −H⁻¹g`, each coordinate clamped to the design's outer radius (or
/// `z = −g` clamped so, a step in `F`'s metric, where the fitted `H` is not positive definite),
/// then to the box. `None` when no round can be taken.
fn surface_step(
    u: &[f64],
    sigma: &[f64],
    corr: &[Vec<f64>],
    costs: impl Fn(&[Vec<f64>]) -> Vec<f64>,
) -> Option<Vec<f64>> {
    let k = u.len();
    if k == 0 || sigma.iter().any(|s| *s <= 0.0) {
        return None;
    }
    let l = cholesky_of_covariance(sigma, corr)?;
    let to_u = |z: &[f64]| -> Vec<f64> {
        (0..k)
            .map(|i| u[i] + (0..=i).map(|j| l[(i, j)] * z[j]).sum::<f64>())
            .collect()
    };
    let design = surface_design(k);
    let points: Vec<Vec<f64>> = design.iter().map(|z| to_u(z)).collect();
    if points.iter().flatten().any(|x| !(0.0..=1.0).contains(x)) {
        return None;
    }
    let c = costs(&points);
    if c.iter()
        .any(|c| !c.is_finite() || *c >= super::problem::FAILED_COST)
    {
        return None;
    }
    let (g, h) = fit_quadratic(&design, &c)?;
    let z = match h.clone().cholesky() {
        Some(ch) => ch.solve(&(-&g)),
        None => -&g,
    };
    let outer = SETTLE_DESIGN_RADII[1];
    let z: Vec<f64> = z.iter().map(|x| x.clamp(-outer, outer)).collect();
    Some(to_u(&z).into_iter().map(|x| x.clamp(0.0, 1.0)).collect())
}

/// Least-squares quadratic `c + gᵀz + ½ zᵀHz` through the values `y` at the points `z`: its
/// gradient `g` and Hessian `H` at the origin. `None` when the design does not determine them.
fn fit_quadratic(z: &[Vec<f64>], y: &[f64]) -> Option<(nalgebra::DVector<f64>, DMatrix<f64>)> {
    let k = z.first()?.len();
    let pairs: Vec<(usize, usize)> = (0..k).flat_map(|i| (i..k).map(move |j| (i, j))).collect();
    let p = 1 + k + pairs.len();
    if z.len() < p {
        return None;
    }
    let x = DMatrix::from_fn(z.len(), p, |r, col| match col {
        0 => 1.0,
        c if c <= k => z[r][c - 1],
        c => {
            let (i, j) = pairs[c - 1 - k];
            z[r][i] * z[r][j]
        }
    });
    let beta = x
        .svd(true, true)
        .solve(&nalgebra::DVector::from_column_slice(y), 1e-12)
        .ok()?;
    let g = nalgebra::DVector::from_fn(k, |i, _| beta[1 + i]);
    let mut h = DMatrix::<f64>::zeros(k, k);
    for (n, &(i, j)) in pairs.iter().enumerate() {
        let b = beta[1 + k + n];
        if i == j {
            h[(i, i)] = 2.0 * b;
        } else {
            h[(i, j)] = b;
            h[(j, i)] = b;
        }
    }
    Some((g, h))
}

/// A noise replicate's Welch ordinates per band, and per band the noise ordinates its own noise
/// estimate gives.
type ReplicateSpectra = (Vec<Vec<f64>>, Vec<Vec<f64>>);

#[cfg(test)]
mod tests {
    use super::*;

    /// A response `[v², v³]` whose "simulation" fails outside `[lo, hi]` (a model losing contact
    /// there), for [`difference_column`].
    fn cut_response(lo: f64, hi: f64) -> impl Fn(f64) -> Result<Vec<f64>> {
        move |v: f64| {
            if (lo..=hi).contains(&v) {
                Ok(vec![v * v, v * v * v])
            } else {
                Err(likelihood::LikelihoodError::LengthMismatch {
                    measured: 0,
                    model: 1,
                }
                .into())
            }
        }
    }

    /// Closed forms: the central difference of v² is exactly 2u, the backward difference
    /// (v² at u minus v² at u − h, over h) exactly 2u − h, and of v³ 3u² − 3uh + h².
    #[test]
    fn a_failed_side_gives_the_one_sided_difference_from_the_centre() {
        let (u, h) = (0.4, 3e-3);
        let both = difference_column(cut_response(0.0, 1.0), || None, u, h).unwrap();
        assert!((both[0] - 2.0 * u).abs() < 1e-12, "{both:?}");
        let f = cut_response(0.0, u + 1e-4);
        let centre = || Some(vec![u * u, u * u * u]);
        let back = difference_column(&f, centre, u, h).unwrap();
        assert!((back[0] - (2.0 * u - h)).abs() < 1e-12, "{back:?}");
        let cube = 3.0 * u * u - 3.0 * u * h + h * h;
        assert!((back[1] - cube).abs() < 1e-12, "{back:?} against {cube}");
        // Without the centre's response there is no one-sided difference: the error stays.
        assert!(difference_column(&f, || None, u, h).is_err());
    }

    #[test]
    fn both_sides_failing_retry_at_a_quarter_step_then_give_up() {
        let (u, h) = (0.4, 3e-3);
        // Valid within ±1e-3 of u: the step h fails on both sides, h/4 = 7.5e-4 does not.
        let near = cut_response(u - 1e-3, u + 1e-3);
        let d = difference_column(near, || None, u, h).unwrap();
        assert!((d[0] - 2.0 * u).abs() < 1e-12, "{d:?}");
        // Valid only at u itself: no step works, and the simulation's error is returned.
        let only = cut_response(u, u);
        let centre = || Some(vec![u * u, u * u * u]);
        assert!(difference_column(only, centre, u, h).is_err());
    }

    /// The likelihood of a pure-noise recording `x` at 10 kHz over the main job's bands (low
    /// 30–300 Hz at nperseg 4096, high 500–5000 Hz at 512), read with the noise spectrum `kind`;
    /// with the simulation's ordinates (all zero: no motion).
    fn noise_only_likelihood(
        x: &[f64],
        kind: NoiseSpectrum,
    ) -> (RecordingLikelihood, Vec<Vec<f64>>) {
        use crate::spectrum::features::{BandSpec, features};
        let fs_hz = 10_000.0;
        let specs = [
            BandSpec::new("low", [30.0, 300.0], 4096),
            BandSpec::new("high", [500.0, 5000.0], 512),
        ];
        let f = features(x, fs_hz, &specs, 0).unwrap();
        let bands: Vec<BandTerm> = f
            .bands
            .iter()
            .map(|b| BandTerm::new(b, fs_hz).unwrap())
            .collect();
        let zeros = bands.iter().map(|b| vec![0.0; b.measured.len()]).collect();
        let lik = RecordingLikelihood {
            bands,
            measured_x: x.to_vec(),
            sigma_m: likelihood::tracking_noise_sigma(x).unwrap(),
            noise_spectrum: kind,
            fs_hz,
            time_domain: false,
            block_len: None,
            saturated_spectral_nats: 0.0,
            joint: None,
            joint_dropped: None,
        };
        (lik, zeros)
    }

    #[test]
    fn the_ar1_profile_recovers_correlated_tracking_noise_that_the_white_estimate_misreads() {
        // AR(1) noise, σ = 1.5 µm (0.1 px at 15 µm/px), ρ = 0.6, 2 s at 10 kHz. Second differences
        // read σ√(1 − 4ρ/3 + ρ²/3) = 0.566σ (spectrum::noise module docs); the profile's σ and ρ
        // land within a few standard errors of the truth (the low band alone holds ~54 Welch
        // segments of 4096 samples: σ̂ to ~2 %, ρ̂ to ~0.02).
        use rand::SeedableRng;
        let (sigma, rho) = (1.5e-6, 0.6);
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let x = TrackingNoise::ar1(sigma, rho).sample(20_000, &mut rng);
        let (lik, zeros) = noise_only_likelihood(&x, NoiseSpectrum::Ar1);
        let white = (1.0 - 4.0 * rho / 3.0 + rho * rho / 3.0_f64).sqrt();
        assert!(
            (lik.sigma_m / sigma - white).abs() < 0.03,
            "{}",
            lik.sigma_m / sigma
        );
        let measured: Vec<&[f64]> = lik.bands.iter().map(|b| b.measured.as_slice()).collect();
        let n = lik.profile_noise(&zeros, &measured, lik.sigma_m);
        assert!(
            (n.sigma_m / sigma - 1.0).abs() < 0.08,
            "σ̂/σ = {}",
            n.sigma_m / sigma
        );
        assert!((n.rho - rho).abs() < 0.06, "ρ̂ = {}", n.rho);
        // The profile is the likelihood's maximum: the truth's noise is no more likely.
        let nll = |noise: &TrackingNoise| {
            let e = lik.expected(&zeros, noise);
            lik.bands
                .iter()
                .zip(&e)
                .map(|(b, s)| b.lik.nll(&b.measured, s).unwrap())
                .sum::<f64>()
        };
        assert!(nll(&n) <= nll(&TrackingNoise::ar1(sigma, rho)) + 1e-6);
        // The white floor of the second-difference σ is far less likely (hundreds of nats).
        assert!(nll(&TrackingNoise::white(lik.sigma_m)) > nll(&n) + 100.0);
    }

    #[test]
    fn the_ar1_profile_of_white_noise_finds_no_correlation() {
        // White noise: the profile's ρ̂ stays near 0 and σ̂ near σ, as the white estimate's does.
        use rand::SeedableRng;
        let sigma = 1.5e-6;
        let mut rng = rand::rngs::StdRng::seed_from_u64(12);
        let x = TrackingNoise::white(sigma).sample(20_000, &mut rng);
        let (lik, zeros) = noise_only_likelihood(&x, NoiseSpectrum::Ar1);
        let measured: Vec<&[f64]> = lik.bands.iter().map(|b| b.measured.as_slice()).collect();
        let n = lik.profile_noise(&zeros, &measured, lik.sigma_m);
        assert!(n.rho.abs() < 0.05, "ρ̂ = {}", n.rho);
        assert!(
            (n.sigma_m / sigma - 1.0).abs() < 0.05,
            "σ̂/σ = {}",
            n.sigma_m / sigma
        );
        assert!((lik.sigma_m / sigma - 1.0).abs() < 0.03);
    }

    /// A bowl `0.5 (u − m)ᵀ Σ⁻¹ (u − m)` with σ = (0.01, 0.02) and correlation 0.5, plus (with
    /// `ripple`) `0.05 (sin(2π·7 u₀/σ₀) + cos(2π·7 u₁/σ₁))`: ripples of 0.05 nats at σ/7, the
    /// main job's likelihood's scale (docs/fit.md, "Settling").
    fn rippled_bowl(ripple: f64) -> impl Fn(&[Vec<f64>]) -> Vec<f64> {
        let (m, sigma, rho) = ([0.4, 0.6], [0.01, 0.02], 0.5);
        move |pts: &[Vec<f64>]| {
            pts.iter()
                .map(|p| {
                    let z = [(p[0] - m[0]) / sigma[0], (p[1] - m[1]) / sigma[1]];
                    let q = (z[0] * z[0] - 2.0 * rho * z[0] * z[1] + z[1] * z[1])
                        / (2.0 * (1.0 - rho * rho));
                    let tau = 2.0 * std::f64::consts::PI * 7.0;
                    q + ripple * ((tau * p[0] / sigma[0]).sin() + (tau * p[1] / sigma[1]).cos())
                })
                .collect()
        }
    }

    #[test]
    fn a_quadratic_surface_lands_on_a_bowls_centre_and_its_ripples_move_it_little() {
        let (m, sigma) = ([0.4, 0.6], [0.01, 0.02]);
        let corr = vec![vec![1.0, 0.5], vec![0.5, 1.0]];
        // From (+0.5σ, −0.5σ): whitened (0.5, −0.87), inside the design's radius of 1.
        let u = [m[0] + 0.5 * sigma[0], m[1] - 0.5 * sigma[1]];
        // A quadratic is fitted exactly, so without ripples the round lands on the centre.
        let next = surface_step(&u, &sigma, &corr, rippled_bowl(0.0)).unwrap();
        for i in 0..2 {
            assert!(
                (next[i] - m[i]).abs() < 1e-9 * sigma[i],
                "coordinate {i}: {next:?}"
            );
        }
        // With them: a central difference over ±σ/2 would be off by up to 0.05/(σ/2) per
        // coordinate, 0.15σ in the step (the Newton step settling took before); a least-squares fit
        // over the 9 points' spread must do better than that.
        let next = surface_step(&u, &sigma, &corr, rippled_bowl(0.05)).unwrap();
        for i in 0..2 {
            let off = (next[i] - m[i]).abs() / sigma[i];
            assert!(off < 0.15, "coordinate {i}: {off:.3}σ from the centre");
        }
    }

    #[test]
    fn no_surface_step_for_an_uninformed_coordinate_or_where_the_design_leaves_the_box() {
        let corr = vec![vec![1.0, 0.0], vec![0.0, 1.0]];
        let costs = |pts: &[Vec<f64>]| vec![0.0; pts.len()];
        assert!(surface_step(&[0.5, 0.5], &[0.01, f64::INFINITY], &corr, costs).is_none());
        assert!(surface_step(&[0.009, 0.5], &[0.01, 0.01], &corr, costs).is_none());
        assert!(surface_step(&[0.5, 0.5], &[0.01, 0.01], &corr, costs).is_some());
        let failed = |pts: &[Vec<f64>]| vec![f64::NAN; pts.len()];
        assert!(surface_step(&[0.5, 0.5], &[0.01, 0.01], &corr, failed).is_none());
    }

    #[test]
    fn the_half_fraction_design_separates_every_term_of_a_quadratic_in_six_coordinates() {
        // y = Σ (i + 1) zᵢ + ½ zᵀHz, H_ii = 2 + i and H_ij = 0.1 (1 + i + j)/(1 + |i − j|): every
        // one of the 28 coefficients nonzero, recovered exactly from the 45 points.
        let k = 6;
        let design = surface_design(k);
        assert_eq!(design.len(), 1 + 2 * k + (1 << (k - 1)));
        let h = DMatrix::from_fn(k, k, |i, j| {
            if i == j {
                2.0 + i as f64
            } else {
                0.1 * (1 + i + j) as f64 / (1 + i.abs_diff(j)) as f64
            }
        });
        let y: Vec<f64> = design
            .iter()
            .map(|z| {
                let zv = nalgebra::DVector::from_column_slice(z);
                (0..k).map(|i| (i + 1) as f64 * z[i]).sum::<f64>()
                    + 0.5 * (zv.transpose() * &h * &zv)[(0, 0)]
            })
            .collect();
        let (gf, hf) = fit_quadratic(&design, &y).unwrap();
        for i in 0..k {
            assert!((gf[i] - (i + 1) as f64).abs() < 1e-9, "g[{i}] = {}", gf[i]);
            for j in 0..k {
                assert!((hf[(i, j)] - h[(i, j)]).abs() < 1e-9, "H[{i}][{j}]");
            }
        }
    }

    #[test]
    fn a_quadratic_is_fitted_exactly_from_the_design() {
        // y = 2 + (1, −2, 0.5)·z + ½ zᵀHz with H = [[3, 1, 0], [1, 2, −0.5], [0, −0.5, 1]].
        let h = DMatrix::from_row_slice(3, 3, &[3.0, 1.0, 0.0, 1.0, 2.0, -0.5, 0.0, -0.5, 1.0]);
        let g = [1.0, -2.0, 0.5];
        let design = surface_design(3);
        assert_eq!(design.len(), 1 + 2 * 3 + 8);
        let y: Vec<f64> = design
            .iter()
            .map(|z| {
                let zv = nalgebra::DVector::from_column_slice(z);
                2.0 + g.iter().zip(z).map(|(a, b)| a * b).sum::<f64>()
                    + 0.5 * (zv.transpose() * &h * &zv)[(0, 0)]
            })
            .collect();
        let (gf, hf) = fit_quadratic(&design, &y).unwrap();
        for i in 0..3 {
            assert!((gf[i] - g[i]).abs() < 1e-10);
            for j in 0..3 {
                assert!((hf[(i, j)] - h[(i, j)]).abs() < 1e-10);
            }
        }
    }
}
