//! What a fit reports: [`FitResult`] and its parts, written as `fits/<job>.result.toml` by
//! `wiperlab fit` (and as JSON with `--json`) and read back by `wiperlab report`.
//!
//! Every type here is `Serialize + Deserialize`. Optional fields carry `#[serde(default)]`, so a
//! result file without them loads (with the field empty).

pub use crate::estimate::{FittedParam, Interval, IntervalMethod};
use crate::job::Candidate;
use crate::job::{FitSection, SpectrumSection};
use crate::model::ParamId;
use crate::names::named_enum;
pub use crate::search::history::{HistoryPoint, SearchStage};
use crate::simulate::blade::ModelKind;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

named_enum! {
    /// Where the fitted parameters' 1σ and correlations come from.
    pub enum SpreadSource: "spread source" {
        /// The sandwich `F⁻¹ V F⁻¹` of the recording's likelihood: its Gauss–Newton Fisher
        /// information `F` and its gradient's variance `V` under the recording's noise (positive
        /// semi-definite by construction: [`crate::search::evidence::at_fit`]).
        Sandwich => "sandwich",
        /// The inverse Fisher information of the recording's likelihood alone (results written
        /// before the sandwich).
        FisherInformation => "fisher_information",
        /// The cost's curvature at the optimum, read as a χ² (a target job, which has no
        /// likelihood; NaN when the curvature is not positive definite).
        CostCurvature => "cost_curvature",
    }
}

fn default_spread_source() -> SpreadSource {
    SpreadSource::CostCurvature
}

/// Measured against model peak in one band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PeakComparison {
    pub band: String,
    pub measured_hz: f64,
    pub model_hz: f64,
    /// (model − measured)/measured.
    pub rel_diff: f64,
    pub measured_level: f64,
    pub model_level: f64,
    /// For a target job with a range target: the range, Hz (`measured_hz` is then the nearest edge,
    /// or the model's peak when it lies inside).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_range_hz: Option<[f64; 2]>,
    /// What the recording's line is: its own or a harmonic of a stronger line, and how far below
    /// the spectrum's dominant line ([`crate::spectrum::harmonics`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measured_line: Option<crate::spectrum::harmonics::LineOrigin>,
    /// The same for the model's line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_line: Option<crate::spectrum::harmonics::LineOrigin>,
}

/// One model of the hierarchy tried on the recording (speed against error at the level of the
/// model).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelTrial {
    /// The model, e.g. `"blade2dof"`.
    pub model: Candidate,
    /// Parameters freed in this trial.
    pub parameters: Vec<ParamId>,
    /// Best cost reached (same cost function for every trial).
    pub cost: f64,
    /// Wall-clock time of the trial, s.
    pub wall_time_s: f64,
    pub model_evaluations: usize,
    /// Of those, the evaluations whose simulation failed (they cost [`crate::fit::FAILED_COST`]).
    /// For the chosen model both counts include its bootstrap replicates; the result's totals are
    /// the sums over the trials.
    #[serde(default)]
    pub failed_evaluations: usize,
    /// True for the model whose parameters the result reports.
    pub chosen: bool,
    /// Why it was (not) chosen, with numbers.
    pub reason: String,
    /// Whether the recording does not distinguish it from the chosen model (its TIC within the
    /// choice's margin, docs/model-choice.md); false for the chosen one.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub not_distinguishable: bool,
    /// The trial in likelihood units (absent for a target job, which has no likelihood).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub evidence: Option<TrialEvidence>,
    /// The friction law at the trial's optimum: its name (`law`) and every coefficient, fitted or
    /// held at the blade file's value (absent in results written before it was kept).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<crate::model::FrictionLaw>,
}

/// One candidate's fit in likelihood units ([`crate::search::evidence`], docs/likelihood.md, "Likelihood").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialEvidence {
    /// `ln L` at the candidate's fit, nats.
    pub log_likelihood_nats: f64,
    /// Whittle NLL of each band (the job's order), nats.
    pub spectral_nll_nats: Vec<f64>,
    /// Gaussian NLL of the time-domain residuals, nats, when `[fit.likelihood] time_domain`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_nll_nats: Option<f64>,
    /// RMS of the signal's de-meaned time-domain residuals, m.
    pub residual_rms_m: f64,
    /// Effective number of observations (BIC's n).
    pub n_effective: f64,
    /// Takeuchi's effective number of parameters `tr(F⁺V)` (the TIC's penalty is twice it), when
    /// the score's variability was estimated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effective_parameters: Option<f64>,
    /// `2·tr(F⁺V) + 2·NLL`, the criterion the choice reads (`2k + 2·NLL` without `tr(F⁺V)`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tic: Option<f64>,
    /// TIC minus the chosen model's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delta_tic: Option<f64>,
    /// `2k + 2·NLL`.
    pub aic: f64,
    /// `k ln n + 2·NLL`.
    pub bic: f64,
    /// AIC minus the chosen model's.
    pub delta_aic: f64,
    /// BIC minus the chosen model's.
    pub delta_bic: f64,
    /// The likelihood-ratio test against the candidate this one nests (`X` for `X+shoulder`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lrt: Option<RatioTest>,
}

/// Wilks' likelihood-ratio test of a smaller candidate nested in this one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RatioTest {
    /// The smaller candidate.
    pub against: Candidate,
    /// `2(NLL_small − NLL_large)`.
    pub statistic: f64,
    /// Degrees of freedom, the extra parameters.
    pub df: usize,
    /// `P(χ²_df ≥ statistic)`.
    pub p_value: f64,
}

fn default_model() -> Candidate {
    Candidate {
        kind: ModelKind::Blade2dof,
        shoulder: false,
        law: None,
    }
}

/// Everything a fit reports; written as `fits/<job>.result.toml` and, with `--json`, to stdout.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitResult {
    pub job: String,
    pub recording: String,
    pub wiperlab_version: String,
    /// Name of the model whose parameters are reported (default `"blade2dof"`, the 2-DOF blade).
    #[serde(default = "default_model")]
    pub model: Candidate,
    pub cost: f64,
    pub parameters: Vec<FittedParam>,
    pub peaks: Vec<PeakComparison>,
    /// Parameters the data leave undetermined.
    pub undetermined: Vec<ParamId>,
    /// Correlation matrix of the freed parameters (row-major, order of `parameters`); NaN for a
    /// parameter the likelihood does not inform, or everywhere when the cost's curvature (without a
    /// likelihood) is not positive definite.
    pub correlation: Vec<Vec<f64>>,
    /// Where the 1σ (`std_error`) and the correlations come from.
    #[serde(default = "default_spread_source")]
    pub spread_source: SpreadSource,
    pub swarm_iterations: u64,
    pub polish_iterations: u64,
    pub model_evaluations: usize,
    pub failed_evaluations: usize,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_failure: Option<String>,
    pub wall_time_s: f64,
    pub threads: usize,
    pub solver_rtol: f64,
    pub solver_atol: f64,
    pub transitions_in_best_model: usize,
    /// Models tried, when the fit compared several (empty: only `model` was fitted).
    #[serde(default)]
    pub model_trials: Vec<ModelTrial>,
    /// Warnings for the reader (undetermined parameters, bounds reached, ...): in the file,
    /// `warnings` holds one sentence each and `warning_details` each one's severity, kind and
    /// numbers ([`super::Warnings`]).
    #[serde(flatten)]
    pub warnings: crate::fit::Warnings,
    /// SHA-256 (lower-case hex) of the recording file the fit read; empty if not recorded.
    #[serde(default)]
    pub input_sha256: String,
    /// The job file's text as the fit read it (settings provenance); empty if not recorded.
    #[serde(default)]
    pub settings: String,
    /// True when the job gave target frequencies (`[targets]`) instead of a recording.
    #[serde(default)]
    pub target_job: bool,
    /// The spectral settings the fit used (signal, bands, gap filling); `None` in results written
    /// before this field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spectrum: Option<SpectrumSection>,
    /// The fit settings the fit used (swarm, polish, restarts, seed, weights); `None` in results
    /// written before this field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit_settings: Option<FitSection>,
    /// When the fit finished (UTC, RFC 3339 in the file); `None` in results written before this
    /// field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fitted_at: Option<jiff::Timestamp>,
    /// CSV files with the numbers behind the figures (measured and model PSD per band, measured and
    /// model traces), by name inside the report directory `reports/<job>/`; see
    /// `report::figures::fit_data_files` for their columns.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub data_files: Vec<String>,
    /// The linearised 2-DOF blade's modes at the fitted parameters, in stick and in steady slip at
    /// the window's speeds ([`crate::model::Blade::window_modes`]); empty when they could not be
    /// computed (a warning says why) and in results written before this field.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub modes: Vec<crate::model::modes::BladeMode>,
    /// True when the fit was stopped by SIGINT or SIGTERM: the values are the best point the
    /// search had reached, `model_evaluations` says how far it got.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub interrupted: bool,
    /// Whether the chosen model explains the recording's spectra to the recording's own noise: the
    /// parametric-bootstrap test of [`crate::search::evidence::RecordingLikelihood::goodness_of_fit`];
    /// `None` without a likelihood (a target job, a joint fit), when interrupted, and in results
    /// written before this field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goodness_of_fit: Option<crate::likelihood::GoodnessOfFit>,
    /// The chosen optimum's cost again at tenfold and hundredfold tighter solver tolerances
    /// ([`crate::fit::tolerance::ToleranceCheck`]): whether the integrator resolves the likelihood
    /// there. `None` without a likelihood, for a joint fit, when interrupted, and in results written
    /// before this field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance_check: Option<crate::fit::tolerance::ToleranceCheck>,
    /// The tracking noise the chosen fit's likelihood reads at its optimum (`[fit.likelihood]
    /// noise`); `None` without a likelihood.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tracking_noise: Option<NoiseEstimate>,
    /// The drive the fit used beside the one read from the tracked head x
    /// ([`crate::model::drive`]); `None` without a tracked head or when it cannot be read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive: Option<crate::model::drive::DriveCheck>,
    /// The chosen model's cost at the job's `[truth]` (every freed parameter at its true value, the
    /// rest as the blade file), nats, at the fit's solver: a fit whose cost lies above it stopped
    /// short of the likelihood's maximum. `None` without a truth for every freed parameter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth_cost: Option<f64>,
    /// The chosen model's cost along the segment from the fit to the truth
    /// ([`crate::fit::truth`]): a ridge on it puts the truth in another basin. `None` without a
    /// truth inside the search box for every freed parameter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth_segment: Option<crate::fit::truth::TruthSegment>,
    /// The truth's cost at the job's tolerance and at tenfold and hundredfold tighter ones: a
    /// spread wider than [`FitResult::shortfall_nats`] leaves the shortfall to the integrator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth_tolerance: Option<crate::fit::tolerance::ToleranceCheck>,
    /// The model the truth's cost and segment are read in when it is not the chosen one (the
    /// job's `[truth] model`, [`crate::fit::truth`]); `None`: the chosen model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth_model: Option<Candidate>,
    /// The cost of [`FitResult::truth_model`]'s own fit, nats (its optimum, which the choice did
    /// not take).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth_model_cost: Option<f64>,
    /// The fitted μ_d(v) over the slip speeds the fitted motion covers, with its ±1σ band and the
    /// true law when known ([`crate::model::friction_curve`]); `None` when the fitted model never
    /// slips, and in results written before this field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_curve: Option<crate::model::friction_curve::FrictionCurve>,
    /// The posterior sample of `[fit.uncertainty] method = "mcmc"`: quantiles, diagnostics and
    /// thinned draws; `None` for the other methods.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub posterior: Option<crate::posterior::PosteriorSummary>,
    /// The job's priors beside the fit (`[fit.priors]`): each prior with the fitted value and
    /// interval, the rig curve's points with the fitted μ_d, and the prior's nats in `cost`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub priors: Option<crate::likelihood::prior::PriorsReport>,
    pub history: Vec<HistoryPoint>,
}

impl FitResult {
    /// How far the fit's cost lies above the truth's own ([`FitResult::truth_cost`]), nats, in the
    /// model the truth is read in (the chosen one, or [`FitResult::truth_model`]): positive when
    /// the search stopped short of a point it could have reached.
    pub fn shortfall_nats(&self) -> Option<f64> {
        let fit = self.truth_model_cost.unwrap_or(self.cost);
        self.truth_cost.map(|t| fit - t)
    }

    /// [`FitResult::shortfall_nats`] with each side's cost averaged over its rounding draws (the
    /// mean of the jitter check's costs at the optimum, `[tolerance_check.jitter]`, and at the
    /// truth, `[truth_tolerance.jitter]`): where the cost jitters, whether the search's optimum is
    /// a draw that suits the recording rather than the likelihood's optimum (docs/likelihood.md,
    /// "Jitter"). `None` without both checks, or when the truth is read in another model than
    /// the chosen one (the optimum's check is the chosen model's).
    pub fn averaged_shortfall_nats(&self) -> Option<f64> {
        if self.truth_model.is_some_and(|m| m != self.model) {
            return None;
        }
        let mean = |t: &Option<crate::fit::tolerance::ToleranceCheck>| {
            Some(t.as_ref()?.jitter.as_ref()?.mean_nats())
        };
        Some(mean(&self.tolerance_check)? - mean(&self.truth_tolerance)?)
    }
}

/// The tracking noise of the measured signal as the likelihood reads it
/// ([`crate::spectrum::noise::TrackingNoise`]): white of the second-difference σ, or the AR(1)
/// profile's σ and ρ at the fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseEstimate {
    /// The noise spectrum of the job (`white` or `ar1`).
    pub spectrum: crate::job::NoiseSpectrum,
    /// Marginal standard deviation, m.
    pub sigma_m: f64,
    /// Lag-one autocorrelation (0 for white noise).
    pub rho: f64,
    /// The noise of each further signal the likelihood reads with the measured one
    /// (`[fit.likelihood] joint_signals`), estimated the same way from that signal.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joint: Vec<SignalNoise>,
}

/// One joint signal's tracking noise at the fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SignalNoise {
    /// The signal.
    pub signal: crate::spectrum::features::SignalKind,
    /// Marginal standard deviation, m.
    pub sigma_m: f64,
    /// Lag-one autocorrelation (0 for white noise).
    pub rho: f64,
}

impl FitResult {
    /// Reads a result file written by `wiperlab fit`.
    ///
    /// # Errors
    /// [`Error::Io`] if unreadable; [`Error::Parse`] (line, column) if not a result TOML.
    pub fn read(path: &Path) -> Result<FitResult> {
        let text = crate::job::read_text(path)?;
        crate::job::parse_toml(path, &text)
    }

    /// The result as TOML text (`fits/<job>.result.toml`).
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string_pretty(self).map_err(|e| Error::write("the fit result", "TOML", e))
    }
}
