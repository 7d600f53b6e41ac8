//! The fit job file (TOML): which recording, which blade, which parameters to free, and settings.
//!
//! Paths inside a job are relative to the job file. Example: `fits/reversal.toml`. The stage also
//! names the job's candidate models ([`Candidate`]) and writes a new job from its template
//! ([`template`], `wiperlab init`).

mod candidate;
mod error;
mod free;
pub mod laws;
pub mod prior;
pub mod rig;
pub mod template;

pub use candidate::{Candidate, NECK_BAND_MIN_HZ, smallest_capable_model};
pub use error::JobError;
pub use free::FreeParam;
pub use prior::{FrictionCurvePrior, ParamPrior, PriorsSection};
pub use rig::{RigCurve, RigPoint};

use crate::import::ImportSpec;
use crate::model::{BladeParams, FrictionLaw, LawKind, ParamId};
use crate::simulate::SolverOptions;
use crate::spectrum::features::{BandSpec, SignalKind, default_bands};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The directory, beside its input, where a command's figures and tables go by default: every
/// command writes `<input dir>/reports/…` (a fit job may move it with `reports_dir`).
pub const DEFAULT_REPORTS_DIR: &str = "reports";

/// A fit job as written in TOML.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FitJob {
    /// Name used for outputs (`<name>.result.toml` beside the job, `<reports_dir>/<name>/`);
    /// default: file stem.
    #[serde(default)]
    pub name: Option<String>,
    /// Directory of the job's figures and report page, `<reports_dir>/<name>/`, and of its
    /// exploration, `<reports_dir>/explore/<name>/`; relative to the job file like every path in
    /// a job. Default: `reports`, beside the job. The shipped jobs in `fits/` say `"../reports"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reports_dir: Option<PathBuf>,
    /// The recording to fit; a job gives either this or `[targets]`.
    #[serde(default)]
    pub recording: Option<RecordingSection>,
    /// Target peak frequencies instead of a recording (e.g. the seed paper's own numbers).
    #[serde(default)]
    pub targets: Option<TargetsSection>,
    /// Further recordings of the same blade (e.g. other sweep speeds) fitted together with
    /// `[recording]`: they share every freed parameter, each with its own drive.
    #[serde(default)]
    pub more_recordings: Vec<MoreRecording>,
    /// Blade parameter file (TOML with [`BladeParams`] fields); the freed parameters' values in it
    /// are ignored by the fit.
    pub blade: PathBuf,
    #[serde(default)]
    pub spectrum: SpectrumSection,
    /// Integrator settings for every model evaluation; default rtol 1e-7, atol 1e-9: with the
    /// default bands the fit's spectral peaks stay within 0.05 % of converged down to rtol 1e-5
    /// (`wiperlab bench`, reports/bench/spectra_vs_rtol.csv; docs/validation.md, "Spectra against
    /// tolerance"). `[fit] swarm_rtol` may loosen it for the swarm stage only.
    #[serde(default = "fit_solver_default")]
    pub solver: SolverOptions,
    pub fit: FitSection,
    /// Optional true parameters (for synthetic recordings), to report relative errors.
    #[serde(default)]
    pub truth: Option<TruthSection>,
}

fn fit_solver_default() -> SolverOptions {
    SolverOptions {
        rtol: 1e-7,
        atol: 1e-9,
        ..SolverOptions::default()
    }
}

/// Target frequencies to reach instead of a recording.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TargetsSection {
    /// Where the numbers come from (shown in the result and report).
    pub source: String,
    /// Sampling rate of the simulated signal, Hz (default 20 kHz).
    #[serde(default = "d_target_fps")]
    pub fps_hz: f64,
    /// One target per band of `[spectrum]`, by band name.
    pub peaks: Vec<TargetPeak>,
}

fn d_target_fps() -> f64 {
    20_000.0
}

/// A band's target: one frequency, or a range the model's peak should fall in.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TargetPeak {
    pub band: String,
    #[serde(default)]
    pub freq_hz: Option<f64>,
    #[serde(default)]
    pub range_hz: Option<[f64; 2]>,
}

impl TargetPeak {
    /// The target's range (a single frequency is a zero-width range).
    pub fn range(&self) -> [f64; 2] {
        match (self.freq_hz, self.range_hz) {
            (Some(f), _) => [f, f],
            (None, Some(r)) => r,
            (None, None) => [f64::NAN, f64::NAN],
        }
    }
}

/// Where the recording is and how to read it.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RecordingSection {
    pub file: PathBuf,
    /// Import settings (format, fps, scale, roles); `t0_s` puts frame 1 on the model's clock,
    /// where the drive is `v = a(1 − cos ωt)`.
    pub import: ImportSpec,
}

/// Another recording in a joint fit: where it is, how to read it, and its drive.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MoreRecording {
    /// Label used in the result's peak table (e.g. "slow").
    pub name: String,
    pub file: PathBuf,
    pub import: ImportSpec,
    /// Drive amplitude of this recording, m (default: the blade file's).
    #[serde(default)]
    pub drive_a_m: Option<f64>,
    /// Drive angular frequency of this recording, rad/s (default: the blade file's).
    #[serde(default)]
    pub drive_omega_rad_per_s: Option<f64>,
}

/// Spectral estimator settings shared by measurement and model.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SpectrumSection {
    pub signal: SignalKind,
    pub bands: Vec<BandSpec>,
    /// Longest gap (samples) filled by linear interpolation before Welch; longer gaps split the
    /// record.
    pub max_fill: usize,
}

impl Default for SpectrumSection {
    fn default() -> Self {
        SpectrumSection {
            signal: SignalKind::TipRelX,
            bands: default_bands(),
            max_fill: 5,
        }
    }
}

/// Cost weights (see [`crate::search::SpectralProblem::cost_of`]).
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct Weights {
    /// Weight of the squared log peak-frequency error in units of 1 % (`(Δln f / 0.01)²`).
    pub peak: f64,
    /// Weight of the squared log peak-level error in units of a factor 2.
    pub level: f64,
    /// Weight of the mean squared log-PSD difference across each band.
    pub shape: f64,
    /// Weight of the instantaneous frequency against tip speed (spectrogram ridge, binned by
    /// speed; `(Δln f / 0.01)²` per bin, see [`crate::likelihood::instfreq`]). Default 0: off.
    pub freq_speed: f64,
    /// Weight of the time-domain error of the job's signal (means removed, relative to the
    /// measurement's variance; see [`crate::likelihood::instfreq::trace_error`]). Default 0: off.
    pub trace: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Weights {
            peak: 1.0,
            level: 1.0,
            shape: 1.0,
            freq_speed: 0.0,
            trace: 0.0,
        }
    }
}

/// Which parameters to fit and how.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FitSection {
    /// Parameter → `[lower, upper]` bounds (see [`ParamId`] for the names).
    pub parameters: BTreeMap<ParamId, [f64; 2]>,
    /// Particles of the global particle-swarm stage.
    #[serde(default = "d_particles")]
    pub particles: usize,
    /// Iterations of the particle-swarm stage.
    #[serde(default = "d_swarm")]
    pub swarm_iterations: u64,
    /// Iterations of the Nelder–Mead polish.
    #[serde(default = "d_polish")]
    pub polish_iterations: u64,
    /// Seed of the swarm's random generator (the fit is reproducible for a given seed).
    #[serde(default = "d_seed")]
    pub seed: u64,
    /// Independent swarm-and-polish runs; the lowest cost is kept (see `optimise` in
    /// [`crate::fit`]). Each run costs a full swarm and polish.
    #[serde(default = "d_restarts")]
    pub restarts: usize,
    /// Relative tolerance of the simulations in the particle-swarm stage (its absolute tolerance
    /// scaled by the same factor against `[solver]`): a cheaper coarse search. The polish, the
    /// reported cost, the curvature and everything after use `[solver]`. Default (`None`): the
    /// `[solver]` tolerance throughout.
    #[serde(default)]
    pub swarm_rtol: Option<f64>,
    /// What the search minimises (default: the recording's likelihood; a target job always uses
    /// its targets' cost).
    #[serde(default = "d_objective")]
    pub objective: Objective,
    /// Weights of the `features` objective (refused with the `likelihood` objective, which has no
    /// weights).
    #[serde(default)]
    pub weights: Weights,
    /// Models of the hierarchy to fit and compare ([`Candidate`]), e.g. `["head1dof",
    /// "blade2dof", "blade2dof+shoulder"]`. Empty (the default): only the smallest model that can produce every
    /// band the job asks for (see [`crate::job::smallest_capable_model`]). With several, each is
    /// fitted and the one with the lowest Akaike criterion (cost + 2k) is reported.
    #[serde(default)]
    pub models: Vec<Candidate>,
    /// Friction laws compared as candidates ([`LawKind`]; docs/model-choice.md, "Which friction law"):
    /// each model of `models` is fitted with each law and all are ranked together. Empty (the
    /// default): the blade file's law only.
    #[serde(
        default,
        skip_serializing_if = "Vec::is_empty",
        deserialize_with = "d_laws"
    )]
    pub laws: Vec<LawKind>,
    /// Bounds of the shoulder-contact parameters freed by the `+shoulder` candidates.
    #[serde(default)]
    pub shoulder: Option<ShoulderBounds>,
    /// How a `+shoulder` candidate is searched once the same model without shoulder is fitted
    /// (default `adaptive`: a local search from that fit first, the restarts' global search only
    /// when the local one finds the likelihood worth it).
    #[serde(default = "d_nested_search")]
    pub nested_search: NestedSearch,
    /// Whether a `+shoulder` candidate is searched again slice by slice in θ_c when the chosen
    /// model fails its goodness-of-fit test (default `on-misfit`; [`crate::search::scan`]).
    #[serde(default)]
    pub contact_angle_scan: ContactAngleScan,
    /// Where the drive's second harmonic comes from (default `blade`: the blade file's
    /// `drive_speed_harmonic`; `recording`: read from the tracked head x,
    /// [`crate::model::drive::read_drive`]).
    #[serde(default)]
    pub drive: DriveSource,
    /// Fresh Nelder–Mead polishes from the chosen model's settled optimum, each kept while it
    /// lowers the likelihood's cost by more than 0.1 nats (see `search::descend_chosen` and
    /// docs/fit.md, "Down the valley"). Default (`None`): [`SHOULDER_VALLEY_POLISHES`] when the
    /// chosen candidate has a shoulder, none otherwise ([`FitSection::valley_polishes_for`]).
    #[serde(default)]
    pub valley_polishes: Option<usize>,
    /// The global search of every candidate (`[fit.search]`; docs/fit.md, "Search").
    #[serde(default)]
    pub search: SearchSection,
    /// Confidence intervals: Laplace (from the likelihood's Fisher information) or parametric
    /// bootstrap (see [`crate::uncertainty::bootstrap_intervals`]).
    #[serde(default)]
    pub uncertainty: UncertaintySection,
    /// The likelihood that model choice and Laplace intervals read ([`crate::search::evidence`]).
    #[serde(default)]
    pub likelihood: LikelihoodSection,
    /// What the user knows before the recording (`[fit.priors]`; docs/priors.md, "Priors").
    #[serde(default, skip_serializing_if = "PriorsSection::is_empty")]
    pub priors: PriorsSection,
}

/// Which terms the recording's likelihood has (docs/likelihood.md, "Likelihood").
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq, Default)]
#[serde(deny_unknown_fields, default)]
pub struct LikelihoodSection {
    /// Add the Gaussian likelihood of the signal's time-domain residuals to the Welch spectra's.
    pub time_domain: bool,
    /// Read the time-domain term from block means of this length, s, with their variance
    /// profiled out, instead of every sample at the tracking noise.
    pub block_s: Option<f64>,
    /// The tracking noise's spectrum ([`NoiseSpectrum`]).
    pub noise: NoiseSpectrum,
    /// Further tracked signals read together with `[spectrum] signal` through their Welch
    /// cross-spectra (the multivariate Whittle likelihood,
    /// [`crate::likelihood::multivariate`]); none reads the one signal alone. Each signal's
    /// tracking noise is its own (`noise`, estimated per signal); the signals may share no
    /// tracked coordinate, so that their noises are independent.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joint_signals: Vec<crate::spectrum::features::SignalKind>,
}

crate::names::named_enum! {
    /// The tracking noise's spectrum in the likelihood (docs/likelihood.md, "Likelihood";
    /// [`crate::spectrum::noise`]).
    #[derive(Default)]
    pub enum NoiseSpectrum: "noise spectrum" {
        /// White noise of the σ second differences give, `1.4826·MAD(Δ²x)/√6`, fixed before the
        /// fit.
        White => "white",
        /// AR(1) noise whose σ and ρ maximise the recording's likelihood at every simulation (the
        /// profile likelihood; [`crate::search::evidence::RecordingLikelihood::profile_noise`]).
        /// The default: white noise is its case ρ = 0, which it finds on a white recording, and
        /// trackers correlate neighbouring frames (docs/validation.md, "Tracking-noise
        /// departures").
        #[default]
        Ar1 => "ar1",
    }
}

crate::names::named_enum! {
    /// What the fit's search minimises (docs/fit.md, "How it works").
    pub enum Objective: "objective" {
        /// The recording's negative log-likelihood in nats above the saturated model's
        /// ([`crate::search::evidence::RecordingLikelihood::excess_nll`]): the Whittle NLL of every
        /// band's Welch ordinates, plus the time-domain term with `[fit.likelihood] time_domain`.
        /// Model choice, intervals and the search then read one quantity.
        Likelihood => "likelihood",
        /// The weighted feature cost ([`crate::search::SpectralProblem::cost_of`]): squared log
        /// errors of each band's peak frequency (1 % scale), level (factor-2 scale) and shape, with
        /// `[fit.weights]` and their optional frequency-against-speed and trace terms.
        Features => "features",
    }
}

crate::names::named_enum! {
    /// How a nested candidate (`X+shoulder`, fitted after `X`) is searched (docs/fit.md, "Nested
    /// candidates").
    pub enum NestedSearch: "nested search" {
        /// Nelder–Mead polishes from `X`'s optimum (θ_c at its bound, the median and the 90th
        /// percentile of |θ|; and X's k1 as the contact stiffness with θ_c at the 10th) first; the
        /// global search (`restarts` swarms) follows only when they
        /// lower the recording's NLL by more than
        /// [`crate::search::NESTED_GLOBAL_GAIN_NATS`]. With the features objective, or a target job
        /// (no likelihood), always the global search.
        Adaptive => "adaptive",
        /// Always the global search, warm-started from `X`'s optimum.
        Global => "global",
    }
}

/// Valley polishes a candidate with a shoulder gets by default. While the neck rests on the
/// shoulder its moment is `k1c·θ − (k1c − k1)·θ_c`, so the likelihood has a long, shallow valley
/// along `(k1c − k1)·θ_c` constant that a polish can stop on the slope of (docs/fit.md, "Down the
/// valley", and "Why the free k1 of a resting neck is not recovered").
pub const SHOULDER_VALLEY_POLISHES: usize = 4;

impl FitSection {
    /// The valley polishes (`[fit] valley_polishes`) for the chosen `candidate`: the job's count,
    /// or by default [`SHOULDER_VALLEY_POLISHES`] for a candidate with a shoulder and 0 otherwise.
    /// With the CMA-ES search, none.
    pub fn valley_polishes_for(&self, candidate: Candidate) -> usize {
        if self.search.method == SearchMethod::Cmaes {
            return 0;
        }
        self.valley_polishes.unwrap_or(if candidate.shoulder {
            SHOULDER_VALLEY_POLISHES
        } else {
            0
        })
    }
}

crate::names::named_enum! {
    /// The global search of every candidate model (docs/fit.md, "Search").
    #[derive(Default)]
    pub enum SearchMethod: "search method" {
        /// Independent particle swarms (`[fit] particles`, `swarm_iterations`, `restarts`), each
        /// followed by a Nelder–Mead polish, with the nested search, valley polishes and
        /// contact-angle scan of docs/fit.md.
        #[default]
        Swarm => "swarm",
        /// CMA-ES with restarts of increasing population (IPOP) over the normalised box, bounds
        /// by mirroring (`[fit.search] population`, `restarts`, `max_evaluations`).
        Cmaes => "cmaes",
    }
}

/// `[fit.search]`: which global search fits each candidate, and its budget.
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SearchSection {
    /// The search (default `swarm`).
    pub method: SearchMethod,
    /// `cmaes`: the first run's population λ; each restart doubles it. Default (`None`):
    /// CMA-ES's own 4 + ⌊3 ln n⌋ for n free parameters.
    pub population: Option<usize>,
    /// `cmaes`: at most this many restarts after the first run.
    pub restarts: usize,
    /// `cmaes`: model evaluations one candidate's search may spend over all its runs; a run that
    /// would pass it is cut short.
    pub max_evaluations: usize,
    /// `swarm`: the local search from each swarm's best particle.
    pub local: LocalSearch,
    /// `swarm` with `local = "cmaes"`: model evaluations each local run may spend.
    pub local_evaluations: usize,
    /// `swarm` with `local = "cmaes"`: the tolerance the local runs simulate at (atol scaled
    /// alike). Default (`None`): `[solver]`'s. The polish after each run and everything the
    /// result reports stay at `[solver]`'s.
    pub local_rtol: Option<f64>,
    /// `swarm`: what the particle swarm ranks its particles by (default `features`).
    pub swarm_cost: SwarmCost,
}

crate::names::named_enum! {
    /// What the particle swarm ranks its particles by, with the likelihood objective
    /// (docs/fit.md, "How it works").
    #[derive(Default)]
    pub enum SwarmCost: "swarm cost" {
        /// The feature cost (peak frequencies at a 1 % scale, levels, log-PSD shapes): it funnels
        /// the swarm into the lines' basin.
        #[default]
        Features => "features",
        /// The recording's negative log-likelihood, the cost the polish minimises, at the swarm's
        /// tolerance (`[fit] swarm_rtol`).
        Likelihood => "likelihood",
    }
}

crate::names::named_enum! {
    /// The local search from each swarm's best particle (docs/fit.md, "Search").
    #[derive(Default)]
    pub enum LocalSearch: "local search" {
        /// A Nelder–Mead simplex of `[fit] polish_iterations` iterations.
        #[default]
        NelderMead => "nelder-mead",
        /// One CMA-ES run from the particle with step size 0.1 box widths
        /// ([`crate::search::ipop::local`]), at most `[fit.search] local_evaluations` evaluations.
        Cmaes => "cmaes",
    }
}

impl Default for SearchSection {
    fn default() -> Self {
        SearchSection {
            method: SearchMethod::Swarm,
            population: None,
            restarts: 4,
            max_evaluations: 4000,
            local: LocalSearch::NelderMead,
            local_evaluations: 1000,
            local_rtol: None,
            swarm_cost: SwarmCost::Features,
        }
    }
}

impl SearchSection {
    /// The first CMA-ES run's population for `n` free parameters.
    pub fn first_population(&self, n: usize) -> usize {
        self.population.unwrap_or(default_population(n))
    }
}

/// CMA-ES's default population for `n` free parameters, 4 + ⌊3 ln n⌋ (Hansen 2016, "The CMA
/// Evolution Strategy: A Tutorial", table 1).
pub fn default_population(n: usize) -> usize {
    4 + (3.0 * (n.max(1) as f64).ln()).floor() as usize
}

crate::names::named_enum! {
    /// Where the fit's drive `v = a(1 − cos ωt) + (h·a/2)·sin 2ωt` comes from (docs/fit.md,
    /// "The drive").
    #[derive(Default)]
    pub enum DriveSource: "drive source" {
        /// The blade file's a, ω and h as written; the tracked head only checks them.
        #[default]
        Blade => "blade",
        /// The blade file's a and ω, with the second harmonic h read from the tracked head x.
        Recording => "recording",
    }
}

crate::names::named_enum! {
    /// When the contact-angle scan ([`crate::search::scan`]) runs.
    #[derive(Default)]
    pub enum ContactAngleScan: "contact-angle scan" {
        /// When the chosen model's spectra fail the goodness-of-fit test (p ≤ 0.01): the search
        /// may have missed a shoulder's narrow basin. Each `+shoulder` candidate is then searched
        /// again once per slice of θ_c (up to four whole searches of it).
        #[default]
        OnMisfit => "on-misfit",
        /// Never.
        Never => "never",
    }
}

fn d_nested_search() -> NestedSearch {
    NestedSearch::Adaptive
}

fn d_objective() -> Objective {
    Objective::Likelihood
}

crate::names::named_enum! {
    /// How the fit gives each parameter an interval.
    pub enum UncertaintyMethod: "uncertainty method" {
        /// Laplace's approximation: ±1σ of the sandwich `F⁻¹ V F⁻¹` of the recording's
        /// likelihood at the fit, with the response's Jacobian averaged over the bowl's centre
        /// (`(2k + 1)·2k` simulations and replicates of the recording's noise).
        Laplace => "laplace",
        /// Basic parametric bootstrap: `bootstrap` replicates, each re-fitted.
        Bootstrap => "bootstrap",
        /// Profile likelihood: each parameter walked out from the fit, the others re-polished at
        /// every step, to where the likelihood has dropped by the sandwich-calibrated 68.27 %
        /// threshold (a few conditional polishes per side).
        Profile => "profile",
        /// A posterior sample of the likelihood tempered by its calibrated scale, from an
        /// affine-invariant ensemble sampler (`walkers` × `steps` simulations): quantile intervals
        /// with convergence diagnostics.
        Mcmc => "mcmc",
        /// Laplace where the likelihood is the quadratic its curvature says, else the posterior
        /// sample of `mcmc`: the sample replaces the Laplace intervals when the secant check finds
        /// an axis flatter than the curvature, or the search's own evaluations (or the shoulder's
        /// contact ridge) reach more than twice a Laplace interval's width inside the profile
        /// region.
        Auto => "auto",
    }
}

/// Most rungs of a parallel-tempering ladder (`[fit.uncertainty] temperatures`): at the geometric
/// ladder's ratio for 4 parameters (`crate::posterior::tempering::geometric_ladder`) the 16th rung
/// has β ≈ 3·10⁻⁴, which flattens a ridge of thousands of nats.
pub const MAX_TEMPERATURES: usize = 16;

/// Settings of the parametric bootstrap that gives each fitted parameter an interval.
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct UncertaintySection {
    /// How (default: `bootstrap` when `bootstrap > 0`, else `laplace`).
    pub method: Option<UncertaintyMethod>,
    /// Bootstrap replicates.
    pub bootstrap: usize,
    /// Re-run the whole estimator (swarm and polish) on each replicate; otherwise only a
    /// Nelder–Mead polish from the optimum.
    pub full_refit: bool,
    /// Nelder–Mead iterations of a polish-only replicate.
    pub polish_iterations: u64,
    /// Seed of the replicates' noise, and of the ensemble sampler's moves.
    pub seed: u64,
    /// `method = "mcmc"` (and `"auto"` when it samples): walkers of the ensemble (even, at least
    /// twice the freed parameters).
    pub walkers: usize,
    /// `method = "mcmc"` / `"auto"`: steps of every walker, burn-in included.
    pub steps: usize,
    /// `method = "mcmc"` / `"auto"`: steps discarded at the start of every walker's chain.
    pub burn_in: usize,
    /// `method = "mcmc"` / `"auto"`: rungs of the parallel-tempering ladder, each an ensemble of
    /// `walkers` on the likelihood raised to a smaller power (1: the plain ensemble; K costs K
    /// times its simulations). Hot rungs cross the ridges between the likelihood's basins.
    pub temperatures: usize,
}

impl UncertaintySection {
    /// The method in effect: the one named, else `bootstrap` when replicates are asked for, else
    /// `laplace`.
    pub fn method(&self) -> UncertaintyMethod {
        self.method.unwrap_or(if self.bootstrap > 0 {
            UncertaintyMethod::Bootstrap
        } else {
            UncertaintyMethod::Laplace
        })
    }
}

impl Default for UncertaintySection {
    fn default() -> Self {
        UncertaintySection {
            method: None,
            bootstrap: 0,
            full_refit: true,
            polish_iterations: 30,
            seed: 7,
            walkers: 32,
            steps: 1000,
            burn_in: 300,
            temperatures: 1,
        }
    }
}

/// Bounds `[lower, upper]` of the shoulder parameters (see [`crate::model::Shoulder`]).
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShoulderBounds {
    /// Neck stiffness while touching the shoulder, N·m/rad.
    pub k1c: [f64; 2],
    /// Contact angle, rad.
    pub theta_c: [f64; 2],
}

/// `[fit] laws`: law names, an unknown one refused with the key and the known laws.
fn d_laws<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Vec<LawKind>, D::Error> {
    Vec::<String>::deserialize(d)?
        .iter()
        .map(|n| {
            n.parse()
                .map_err(|e| serde::de::Error::custom(format!("[fit] laws: {e}")))
        })
        .collect()
}

fn d_particles() -> usize {
    12
}
fn d_swarm() -> u64 {
    8
}
fn d_polish() -> u64 {
    40
}
fn d_seed() -> u64 {
    1
}
fn d_restarts() -> usize {
    1
}

/// The `[fit]` keys of the swarm search, refused beside `[fit.search] method = "cmaes"`.
const SWARM_KEYS: [&str; 7] = [
    "particles",
    "swarm_iterations",
    "restarts",
    "swarm_rtol",
    "nested_search",
    "contact_angle_scan",
    "valley_polishes",
];

/// True parameter values from a JSON file (e.g. the sample's `truth.json`).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TruthSection {
    pub json: PathBuf,
    /// Parameter → JSON pointer (RFC 6901), e.g. `A = "/params/A"`. A pointer to `null` gives
    /// the parameter no true value (the true model lacks it).
    pub keys: BTreeMap<ParamId, String>,
    /// JSON pointer to the true friction law, an object as a blade file's `[friction]` table
    /// (`{"law": "exponential_viscous", "a": …}`): for a recording whose true law is not the
    /// blade file's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_law: Option<String>,
    /// JSON pointer to the name of the model that made the recording (as in `[fit] models`, e.g.
    /// `"blade2dof+shoulder"`): the truth's cost is then read in that candidate's fit, whichever
    /// model the fit chooses ([`crate::fit::truth`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
}

/// One step of a path into a TOML document: a key of a table or an index into an array.
#[derive(Debug, Clone, Copy)]
pub enum Key<'k> {
    Name(&'k str),
    Index(usize),
}

/// Where the keys and values of a TOML file are, from the TOML parser's spans: validation errors
/// found after deserialising name the line and column of the offending value.
pub struct Spans<'t> {
    text: &'t str,
    doc: Option<toml::Spanned<toml::de::DeTable<'t>>>,
}

impl<'t> Spans<'t> {
    /// Parses `text` for its spans (a document that does not parse has none: every lookup then
    /// answers line 1, column 1; such a document never reaches validation).
    pub fn new(text: &'t str) -> Self {
        Spans {
            text,
            doc: toml::de::DeTable::parse(text).ok(),
        }
    }

    /// 1-based `(line, column)` of the value at `path` (e.g. `[Name("fit"), Name("swarm_rtol")]`);
    /// of the deepest part of `path` present when the rest is missing.
    pub fn at(&self, path: &[Key]) -> (usize, usize) {
        let Some(doc) = &self.doc else {
            return (1, 1);
        };
        let mut span = doc.span();
        let mut value: Option<&toml::de::DeValue> = None;
        let mut table = Some(doc.get_ref());
        for key in path {
            let next = match (key, value, table) {
                (Key::Name(n), _, Some(t)) => t
                    .iter()
                    .find(|(k, _)| k.get_ref().as_ref() == *n)
                    .map(|(_, v)| v),
                (Key::Index(i), Some(toml::de::DeValue::Array(a)), _) => a.get(*i),
                _ => None,
            };
            let Some(next) = next else { break };
            span = next.span();
            value = Some(next.get_ref());
            table = match next.get_ref() {
                toml::de::DeValue::Table(t) => Some(t),
                _ => None,
            };
        }
        line_col(self.text, span.start)
    }

    /// Whether the document holds a value at `path`.
    pub fn contains(&self, path: &[Key]) -> bool {
        let Some(doc) = &self.doc else {
            return false;
        };
        let mut table = doc.get_ref();
        for (i, key) in path.iter().enumerate() {
            let Key::Name(n) = key else { return false };
            let Some((_, v)) = table.iter().find(|(k, _)| k.get_ref().as_ref() == *n) else {
                return false;
            };
            if i + 1 == path.len() {
                return true;
            }
            match v.get_ref() {
                toml::de::DeValue::Table(t) => table = t,
                _ => return false,
            }
        }
        true
    }

    /// [`Error::Parse`] in `path` at the value at `key_path`.
    pub fn error(&self, path: &Path, key_path: &[Key], message: impl Into<String>) -> Error {
        let (line, column) = self.at(key_path);
        Error::parse(path, line, column, message)
    }
}

/// 1-based line and column (in characters) of byte offset `at` of `text`.
fn line_col(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before
        .rsplit('\n')
        .next()
        .map(|s| s.chars().count())
        .unwrap_or(0)
        + 1;
    (line, col)
}

/// Parses TOML `text` from `path` into `T`, turning syntax and schema errors into
/// [`Error::Parse`] with line and column.
pub fn parse_toml<T: serde::de::DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    toml::from_str(text).map_err(|e| {
        let (line, col) = e
            .span()
            .map(|sp| line_col(text, sp.start))
            .unwrap_or((0, 0));
        Error::parse(path, line, col, e.message().to_string())
    })
}

/// Reads a file to a string, naming it on failure.
pub fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| Error::io(path, "cannot read", e))
}

/// A loaded, validated job with its paths resolved.
#[derive(Debug, Clone)]
pub struct LoadedJob {
    pub job: FitJob,
    pub name: String,
    pub path: PathBuf,
    pub recording_path: PathBuf,
    pub blade: BladeParams,
    /// Freed parameters in a fixed order: (parameter, lower, upper).
    pub free: Vec<(ParamId, f64, f64)>,
    /// True values of freed parameters, when the job names a truth file.
    pub truth: BTreeMap<ParamId, f64>,
    /// The true friction law at `[truth] friction_law`, when the job names one.
    pub truth_friction_law: Option<FrictionLaw>,
    /// The model that made the recording, at `[truth] model`, when the job names one.
    pub truth_model: Option<Candidate>,
    /// The rig curve of `[fit.priors.friction_curve]`, as read.
    pub rig_curve: Option<RigCurve>,
}

impl LoadedJob {
    /// Loads and validates the job at `path`.
    ///
    /// # Errors
    /// [`Error::Io`] for unreadable files; [`Error::Parse`] (file, line, column, from the TOML
    /// parser's spans) for TOML syntax, unknown fields, an unknown parameter or model name, bounds
    /// the wrong way round and other invalid settings.
    pub fn load(path: &Path) -> Result<LoadedJob> {
        let text = read_text(path)?;
        let job: FitJob = parse_toml(path, &text)?;
        let spans = Spans::new(&text);
        let dir = path.parent().unwrap_or(Path::new("."));
        let name = job.name.clone().unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "fit".into())
        });
        let blade_path = dir.join(&job.blade);
        let blade_text = read_text(&blade_path)?;
        let blade: BladeParams = parse_toml(&blade_path, &blade_text)?;
        blade
            .validate()
            .map_err(|m| Error::input(&blade_path, m.to_string()))?;
        let check = Check {
            path,
            spans: &spans,
            job: &job,
        };
        check.name(&name)?;
        let free = check.parameters(&blade, &blade_path)?;
        check.fit_settings()?;
        check.source()?;
        check.recording_import(dir, &blade)?;
        check.more_recordings()?;
        check.solver()?;
        check.bands()?;
        let rig_curve = check.priors(&free, dir)?;
        let TruthRead {
            values: truth,
            law: truth_friction_law,
            model: truth_model,
        } = read_truth(dir, job.truth.as_ref())?;
        Ok(LoadedJob {
            recording_path: match &job.recording {
                Some(r) => dir.join(&r.file),
                // A target job's input is the job file itself (its hash is the provenance).
                None => path.to_path_buf(),
            },
            job,
            name,
            path: path.to_path_buf(),
            blade,
            free,
            truth,
            truth_friction_law,
            truth_model,
            rig_curve,
        })
    }
}

impl LoadedJob {
    /// The true friction law: `[truth] friction_law` when given, else the blade file's law with
    /// every friction coefficient the job frees at its `[truth]` value; `None` when the job frees
    /// no friction coefficient or the truth lacks one of them.
    pub fn true_friction_law(&self) -> Option<FrictionLaw> {
        if self.truth_friction_law.is_some() {
            return self.truth_friction_law;
        }
        let mut p = self.blade;
        let mut any = false;
        for (id, _, _) in self.free.iter().filter(|f| f.0.is_friction()) {
            id.set(&mut p, *self.truth.get(id)?);
            any = true;
        }
        any.then_some(p.friction)
    }

    /// The candidates the job asks for, or the smallest model capable of its bands, each with
    /// each of `[fit] laws` ([`Candidate::with_laws`]).
    pub fn candidates(&self) -> Vec<Candidate> {
        let models = if self.job.fit.models.is_empty() {
            vec![Candidate {
                kind: smallest_capable_model(&self.job.spectrum.bands),
                shoulder: false,
                law: None,
            }]
        } else {
            self.job.fit.models.clone()
        };
        Candidate::with_laws(&models, &self.job.fit.laws)
    }

    /// The base parameters and the freed ones of `candidate`: the job's, and for a shoulder candidate
    /// the shoulder's two, started at the middle of their `[fit.shoulder]` bounds. With a law
    /// ([`Candidate::law`]), the blade's law written as that law and the law's coefficients
    /// ([`laws::law_free`]).
    ///
    /// # Errors
    /// [`JobError::ShoulderBounds`] for a shoulder candidate without `[fit.shoulder]` bounds.
    pub fn freed(&self, candidate: Candidate) -> Result<(BladeParams, Vec<FreeParam>)> {
        let mut base = self.blade;
        let mut free: Vec<FreeParam> = match candidate.law {
            Some(law) => {
                base.friction = laws::base_law(&base.friction, law).map_err(|e| {
                    self.error_at(&[Key::Name("fit"), Key::Name("laws")], e.to_string())
                })?;
                laws::law_free(&self.free, law)
            }
            None => self
                .free
                .iter()
                .map(|&(n, lo, hi)| FreeParam::new(n, lo, hi))
                .collect(),
        };
        if candidate.shoulder {
            let sb = self.job.fit.shoulder.ok_or(JobError::ShoulderBounds)?;
            base.shoulder = Some(crate::model::Shoulder {
                contact_angle_rad: 0.5 * (sb.theta_c[0] + sb.theta_c[1]),
                k1_contact_nm_per_rad: 0.5 * (sb.k1c[0] + sb.k1c[1]),
            });
            free.push(FreeParam::new(ParamId::K1c, sb.k1c[0], sb.k1c[1]));
            free.push(FreeParam::new(
                ParamId::ThetaC,
                sb.theta_c[0],
                sb.theta_c[1],
            ));
        }
        Ok((base, free))
    }

    /// `<job dir>/<reports_dir>` (default `<job dir>/reports`): where the job's figures, report
    /// page and exploration go, wherever the command runs.
    pub fn reports_dir(&self) -> PathBuf {
        self.dir().join(
            self.job
                .reports_dir
                .as_deref()
                .unwrap_or(Path::new(DEFAULT_REPORTS_DIR)),
        )
    }

    /// The job file's directory (`.` for a bare file name).
    pub fn dir(&self) -> &Path {
        match self.path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        }
    }

    /// [`Error::Parse`] in the job file at the value at `key_path`, for checks that need the
    /// recording (the job's text is read again for its spans).
    pub fn error_at(&self, key_path: &[Key], message: impl Into<String>) -> Error {
        match read_text(&self.path) {
            Ok(text) => Spans::new(&text).error(&self.path, key_path, message),
            Err(e) => e,
        }
    }
}

/// The validation of a parsed job, each error at its value's line and column.
struct Check<'a> {
    path: &'a Path,
    spans: &'a Spans<'a>,
    job: &'a FitJob,
}

impl Check<'_> {
    fn error(&self, at: &[Key], message: impl Into<String>) -> Error {
        self.spans.error(self.path, at, message)
    }

    /// The freed parameters in a fixed order, with bounds checked against the blade.
    fn parameters(
        &self,
        blade: &BladeParams,
        blade_path: &Path,
    ) -> Result<Vec<(ParamId, f64, f64)>> {
        let mut free = Vec::new();
        for &law in &self.job.fit.laws {
            laws::base_law(&blade.friction, law).map_err(|e| {
                let at = [Key::Name("fit"), Key::Name("laws")];
                self.error(&at, format!("{e} (blade file {})", blade_path.display()))
            })?;
        }
        for (&id, &[lo, hi]) in &self.job.fit.parameters {
            let at = [
                Key::Name("fit"),
                Key::Name("parameters"),
                Key::Name(id.name()),
            ];
            if id.is_shoulder() && blade.shoulder.is_none() {
                return Err(self.error(
                    &at,
                    format!(
                        "[fit.parameters]: '{id}' is a shoulder parameter but the blade file {} has no [shoulder] section (or list \"blade2dof+shoulder\" in [fit] models with [fit.shoulder] bounds)",
                        blade_path.display()
                    ),
                ));
            }
            if !self.job.fit.laws.is_empty() {
                if let Some(m) = laws::no_listed_law_has(id, &self.job.fit.laws) {
                    return Err(self.error(&at, m));
                }
            } else if id.get(blade).is_none() {
                return Err(self.error(
                    &at,
                    format!(
                        "[fit.parameters]: '{id}' ({}) is not a coefficient of the friction law `{}` in the blade file {}; it needs law = {}",
                        id.axis_label(),
                        blade.friction.name(),
                        blade_path.display(),
                        id.friction_laws()
                            .iter()
                            .map(|l| format!("\"{l}\""))
                            .collect::<Vec<_>>()
                            .join(" or ")
                    ),
                ));
            }
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(self.error(
                    &at,
                    format!(
                        "[fit.parameters]: bounds of '{id}' must be finite with lower < upper (got [{lo}, {hi}])"
                    ),
                ));
            }
            if lo < 0.0 || (id.strictly_positive() && lo <= 0.0) {
                return Err(self.error(
                    &at,
                    format!(
                        "[fit.parameters]: '{id}' ({}) is a physical magnitude; its lower bound must be {} (got {lo})",
                        id.meaning(),
                        if id.strictly_positive() { "> 0" } else { ">= 0" }
                    ),
                ));
            }
            if let Some(other) = id
                .holds()
                .iter()
                .find(|o| self.job.fit.parameters.contains_key(o))
            {
                return Err(self.error(
                    &at,
                    format!(
                        "[fit.parameters]: '{id}' moves '{other}' to hold the blade's measured frequencies ({}); free one of them",
                        id.meaning()
                    ),
                ));
            }
            free.push((id, lo, hi));
        }
        if free.is_empty() {
            return Err(self.error(
                &[Key::Name("fit"), Key::Name("parameters")],
                "[fit.parameters] frees no parameter",
            ));
        }
        Ok(free)
    }

    /// The job's name names its outputs (`<name>.result.toml`, `reports/<name>/`): a plain file
    /// stem, so they stay where the docs say.
    fn name(&self, name: &str) -> Result<()> {
        if crate::io::is_plain_stem(name) {
            return Ok(());
        }
        Err(self.error(
            &[Key::Name("name")],
            format!(
                "name = {name:?} must be a plain file stem (no '/', '\\' or leading '.'): it names \
                 the outputs <name>.result.toml and reports/<name>/"
            ),
        ))
    }

    /// `[solver]` tolerances, at the `[solver]` table.
    fn solver(&self) -> Result<()> {
        self.job
            .solver
            .validate()
            .map_err(|e| self.error(&[Key::Name("solver")], format!("[solver] {e}")))
    }

    /// The recording's import settings (at `[recording.import]`), with `t0_s` inside the blade's
    /// drive period 2π/ω: frame 1 must fall on the first period of the model's clock.
    fn recording_import(&self, dir: &Path, blade: &BladeParams) -> Result<()> {
        let Some(r) = &self.job.recording else {
            return Ok(());
        };
        let at = [Key::Name("recording"), Key::Name("import")];
        let format = r.import.resolve_format(&dir.join(&r.file))?;
        r.import
            .validate(format)
            .map_err(|e| match crate::import::ImportError::of(&e) {
                Some(ie) => self.error(&at, format!("[recording.import] {ie}")),
                None => e,
            })?;
        let period_s = std::f64::consts::TAU / blade.drive_omega_rad_per_s;
        let t0 = r.import.t0_s;
        if !(0.0..period_s).contains(&t0) {
            return Err(self.error(
                &[
                    Key::Name("recording"),
                    Key::Name("import"),
                    Key::Name("t0_s"),
                ],
                format!(
                    "[recording.import] t0_s = {t0} s must lie in the blade's drive period [0, \
                     {period_s:.4}) s (2π/ω, ω = {} rad/s): it places frame 1 on the drive's clock",
                    blade.drive_omega_rad_per_s
                ),
            ));
        }
        Ok(())
    }

    /// `[fit.search]`: a budget CMA-ES can run with, and none of the swarm search's keys beside
    /// the CMA-ES search (they would do nothing).
    fn search_settings(&self) -> Result<()> {
        let search = &self.job.fit.search;
        let at = |key: &'static str| [Key::Name("fit"), Key::Name("search"), Key::Name(key)];
        if search.population.is_some_and(|p| p < 2) {
            return Err(self.error(
                &at("population"),
                "[fit.search] population must be >= 2 (CMA-ES samples λ points per generation)",
            ));
        }
        if search.max_evaluations < 1 {
            return Err(self.error(
                &at("max_evaluations"),
                "[fit.search] max_evaluations must be >= 1",
            ));
        }
        if search.local == LocalSearch::Cmaes && search.local_evaluations < 2 {
            return Err(self.error(
                &at("local_evaluations"),
                "[fit.search] local_evaluations must be >= 2",
            ));
        }
        if search.method == SearchMethod::Cmaes {
            for key in ["local", "local_evaluations", "local_rtol", "swarm_cost"] {
                if self.spans.contains(&at(key)) {
                    return Err(self.error(
                        &at(key),
                        format!(
                            "[fit.search] {key} belongs to the swarm search; with \
                             method = \"cmaes\" there is no swarm (docs/fit.md, \"Search\")"
                        ),
                    ));
                }
            }
            for key in SWARM_KEYS {
                let path = [Key::Name("fit"), Key::Name(key)];
                if self.spans.contains(&path) {
                    return Err(self.error(
                        &path,
                        format!(
                            "[fit] {key} belongs to the swarm search; with [fit.search] method = \
                             \"cmaes\" the search is set by [fit.search] population, restarts and \
                             max_evaluations (docs/fit.md, \"Search\")"
                        ),
                    ));
                }
            }
        }
        self.stage_rtol(
            &at("local_rtol"),
            "[fit.search] local_rtol",
            search.local_rtol,
        )?;
        if search.local_rtol.is_some() && search.local != LocalSearch::Cmaes {
            return Err(self.error(
                &at("local_rtol"),
                "[fit.search] local_rtol sets the tolerance of the local CMA-ES runs: it \
                 needs local = \"cmaes\" (docs/fit.md, \"The local CMA-ES stage\")",
            ));
        }
        Ok(())
    }

    /// A search stage's own tolerance (`[fit] swarm_rtol`, `[fit.search] local_rtol`), when set:
    /// a relative tolerance in (0, 1).
    fn stage_rtol(&self, at: &[Key], name: &str, rtol: Option<f64>) -> Result<()> {
        match rtol {
            Some(r) if !(r.is_finite() && r > 0.0 && r < 1.0) => {
                Err(self.error(at, format!("{name} must be in (0, 1) (got {r})")))
            }
            _ => Ok(()),
        }
    }

    /// Optimiser settings, candidate models and shoulder bounds.
    fn fit_settings(&self) -> Result<()> {
        let fit = &self.job.fit;
        self.search_settings()?;
        if fit.particles < 2 {
            return Err(self.error(
                &[Key::Name("fit"), Key::Name("particles")],
                "[fit] particles must be >= 2",
            ));
        }
        if fit.restarts < 1 {
            return Err(self.error(
                &[Key::Name("fit"), Key::Name("restarts")],
                "[fit] restarts must be >= 1 (independent swarm + polish runs, the best kept)",
            ));
        }
        let u = &fit.uncertainty;
        if matches!(
            u.method(),
            UncertaintyMethod::Mcmc | UncertaintyMethod::Auto
        ) {
            let at = |key| [Key::Name("fit"), Key::Name("uncertainty"), Key::Name(key)];
            if u.walkers < 4 || u.walkers % 2 == 1 {
                return Err(self.error(
                    &at("walkers"),
                    format!(
                        "[fit.uncertainty] walkers must be even and at least twice the freed parameters (got {})",
                        u.walkers
                    ),
                ));
            }
            if !(1..=MAX_TEMPERATURES).contains(&u.temperatures) {
                return Err(self.error(
                    &at("temperatures"),
                    format!(
                        "[fit.uncertainty] temperatures must be 1 (the plain ensemble) to {MAX_TEMPERATURES} (got {}): each rung is a whole ensemble",
                        u.temperatures
                    ),
                ));
            }
            if u.burn_in >= u.steps {
                return Err(self.error(
                    &at("burn_in"),
                    format!(
                        "[fit.uncertainty] burn_in ({}) must be fewer than steps ({}): the chains keep the steps after it",
                        u.burn_in, u.steps
                    ),
                ));
            }
        }
        for (i, m) in fit.models.iter().enumerate() {
            if let Some(law) = m.law {
                return Err(self.error(
                    &[Key::Name("fit"), Key::Name("models"), Key::Index(i)],
                    format!(
                        "[fit] models lists \"{m}\": name the model alone and the law in [fit] \
                         laws = [\"{law}\", ...]"
                    ),
                ));
            }
            if m.shoulder && fit.shoulder.is_none() {
                return Err(self.error(
                    &[Key::Name("fit"), Key::Name("models"), Key::Index(i)],
                    format!(
                        "[fit] models lists \"{m}\": give its bounds in [fit.shoulder] (k1c = [lo, hi], theta_c = [lo, hi])"
                    ),
                ));
            }
        }
        if let Some(sb) = &fit.shoulder {
            for (id, [lo, hi]) in [(ParamId::K1c, sb.k1c), (ParamId::ThetaC, sb.theta_c)] {
                if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo < hi) {
                    return Err(self.error(
                        &[
                            Key::Name("fit"),
                            Key::Name("shoulder"),
                            Key::Name(id.name()),
                        ],
                        format!("[fit.shoulder] {id}: need 0 < lower < upper (got [{lo}, {hi}])"),
                    ));
                }
            }
        }
        if fit.objective == Objective::Likelihood && fit.weights != Weights::default() {
            return Err(self.error(
                &[Key::Name("fit"), Key::Name("weights")],
                "[fit.weights] weigh the feature cost: set [fit] objective = \"features\" to use \
                 them (the default objective, \"likelihood\", has no weights)",
            ));
        }
        self.stage_rtol(
            &[Key::Name("fit"), Key::Name("swarm_rtol")],
            "[fit] swarm_rtol",
            fit.swarm_rtol,
        )?;
        self.joint_signals(fit)?;
        if let Some(b) = fit.likelihood.block_s {
            let at = [
                Key::Name("fit"),
                Key::Name("likelihood"),
                Key::Name("block_s"),
            ];
            if !fit.likelihood.time_domain {
                return Err(self.error(
                    &at,
                    "[fit.likelihood] block_s reads the time-domain term: set time_domain = true \
                     to use it",
                ));
            }
            if !(b.is_finite() && b > 0.0) {
                return Err(self.error(
                    &at,
                    format!("[fit.likelihood] block_s must be a duration > 0 s (got {b})"),
                ));
            }
        }
        Ok(())
    }

    /// `[fit.likelihood] joint_signals`: none is the fit's own signal or shares a tracked
    /// coordinate with another signal read, and the intervals' method refits no replicate of the
    /// one signal alone (`bootstrap`).
    fn joint_signals(&self, fit: &FitSection) -> Result<()> {
        let joint = &fit.likelihood.joint_signals;
        if joint.is_empty() {
            return Ok(());
        }
        let at = [
            Key::Name("fit"),
            Key::Name("likelihood"),
            Key::Name("joint_signals"),
        ];
        let main = self.job.spectrum.signal;
        let all: Vec<_> = std::iter::once(main).chain(joint.iter().copied()).collect();
        for (i, a) in all.iter().enumerate() {
            for b in &all[..i] {
                if a.shares_coordinate(*b) {
                    return Err(self.error(
                        &at,
                        format!(
                            "[fit.likelihood] joint_signals: \"{a}\" shares a tracked coordinate \
                             with \"{b}\" ({}); expected signals of separate coordinates, e.g. \
                             [\"head_y\"] beside signal = \"tip_rel_x\"",
                            if *b == main {
                                "the fit's [spectrum] signal"
                            } else {
                                "another joint signal"
                            }
                        ),
                    ));
                }
            }
        }
        if fit.uncertainty.method() == UncertaintyMethod::Bootstrap {
            return Err(self.error(
                &at,
                "[fit.likelihood] joint_signals: the bootstrap refits replicates of the one signal; \
                 use [fit.uncertainty] method = \"laplace\", \"profile\", \"mcmc\" or \"auto\"",
            ));
        }
        Ok(())
    }

    /// Exactly one of `[recording]` and `[targets]`, and a target job's peaks.
    fn source(&self) -> Result<()> {
        let t = match (&self.job.recording, &self.job.targets) {
            (Some(_), None) => return Ok(()),
            (None, Some(t)) => t,
            _ => {
                return Err(Error::parse(
                    self.path,
                    1,
                    1,
                    "a fit job gives either [recording] (a tracked recording) or [targets] (frequencies to reach), and exactly one of them",
                ));
            }
        };
        for (i, tp) in t.peaks.iter().enumerate() {
            let at = [Key::Name("targets"), Key::Name("peaks"), Key::Index(i)];
            if !self.job.spectrum.bands.iter().any(|b| b.name == tp.band) {
                return Err(self.error(
                    &at,
                    format!(
                        "[targets] peak for band '{}', which [spectrum] does not define",
                        tp.band
                    ),
                ));
            }
            let [lo, hi] = tp.range();
            if tp.freq_hz.is_some() == tp.range_hz.is_some() || !(lo > 0.0 && lo <= hi) {
                return Err(self.error(
                    &at,
                    format!(
                        "[targets] band '{}': give exactly one of freq_hz = F or range_hz = [LO, HI] with 0 < LO <= HI",
                        tp.band
                    ),
                ));
            }
        }
        if !(t.fps_hz.is_finite() && t.fps_hz > 0.0) {
            return Err(self.error(
                &[Key::Name("targets"), Key::Name("fps_hz")],
                "[targets] fps_hz must be > 0",
            ));
        }
        Ok(())
    }

    /// Further recordings of a joint fit.
    fn more_recordings(&self) -> Result<()> {
        if !self.job.more_recordings.is_empty() && self.job.recording.is_none() {
            return Err(self.error(
                &[Key::Name("more_recordings")],
                "[[more_recordings]] needs a [recording] to join (not a [targets] job)",
            ));
        }
        for (i, m) in self.job.more_recordings.iter().enumerate() {
            for (what, v) in [
                ("drive_a_m", m.drive_a_m),
                ("drive_omega_rad_per_s", m.drive_omega_rad_per_s),
            ] {
                if let Some(x) = v
                    && !(x.is_finite() && x > 0.0)
                {
                    return Err(self.error(
                        &[Key::Name("more_recordings"), Key::Index(i), Key::Name(what)],
                        format!(
                            "[[more_recordings]] '{}': {what} must be > 0 (got {x})",
                            m.name
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Spectral bands: ordered edges and a usable segment length.
    fn bands(&self) -> Result<()> {
        for (i, b) in self.job.spectrum.bands.iter().enumerate() {
            if !(b.range_hz[0] >= 0.0 && b.range_hz[0] < b.range_hz[1]) || b.nperseg < 8 {
                return Err(self.error(
                    &[Key::Name("spectrum"), Key::Name("bands"), Key::Index(i)],
                    format!(
                        "[spectrum] band '{}': need range_hz = [lower, upper] with 0 <= lower < upper and nperseg >= 8 (got {:?}, nperseg {})",
                        b.name, b.range_hz, b.nperseg
                    ),
                ));
            }
            if let Err(e) = b.welch_config() {
                return Err(self.error(
                    &[Key::Name("spectrum"), Key::Name("bands"), Key::Index(i)],
                    format!("[spectrum] band '{}': {e}", b.name),
                ));
            }
        }
        Ok(())
    }
}

/// What a job's `[truth]` says ([`read_truth`]).
#[derive(Debug, Default)]
struct TruthRead {
    /// True values of the freed parameters.
    values: BTreeMap<ParamId, f64>,
    /// The true friction law, at `[truth] friction_law`.
    law: Option<FrictionLaw>,
    /// The model that made the recording, at `[truth] model`.
    model: Option<Candidate>,
}

/// The job's `[truth]` JSON file read at its keys and pointers (empty without one).
fn read_truth(dir: &Path, truth: Option<&TruthSection>) -> Result<TruthRead> {
    let Some(t) = truth else {
        return Ok(TruthRead::default());
    };
    let tp = dir.join(&t.json);
    let v: serde_json::Value = serde_json::from_str(&read_text(&tp)?)
        .map_err(|e| Error::parse(&tp, e.line(), e.column(), format!("not valid JSON: {e}")))?;
    let mut values = BTreeMap::new();
    for (k, ptr) in &t.keys {
        // `null`: the recording's true model has no such parameter (a friction law of another
        // family), so the fit's value has no truth to be scored against.
        if v.pointer(ptr).is_some_and(serde_json::Value::is_null) {
            continue;
        }
        let x = v.pointer(ptr).and_then(|x| x.as_f64()).ok_or_else(|| {
            Error::input(
                &tp,
                format!("no number (or null) at JSON pointer {ptr} (for '{k}')"),
            )
        })?;
        values.insert(*k, x);
    }
    let law = t
        .friction_law
        .as_deref()
        .map(|ptr| true_law(&tp, &v, ptr))
        .transpose()?;
    let model = t
        .model
        .as_deref()
        .map(|ptr| {
            let name = v.pointer(ptr).and_then(|x| x.as_str()).ok_or_else(|| {
                Error::input(
                    &tp,
                    format!("no model name at JSON pointer {ptr} (for model)"),
                )
            })?;
            name.parse::<Candidate>()
                .map_err(|e| Error::input(&tp, format!("the model at JSON pointer {ptr}: {e}")))
        })
        .transpose()?;
    Ok(TruthRead { values, law, model })
}

/// The friction law at JSON pointer `ptr` of the truth file `tp` (parsed as `v`).
fn true_law(tp: &Path, v: &serde_json::Value, ptr: &str) -> Result<FrictionLaw> {
    let at = v.pointer(ptr).ok_or_else(|| {
        Error::input(
            tp,
            format!("nothing at JSON pointer {ptr} (for friction_law)"),
        )
    })?;
    let law = FrictionLaw::deserialize(at)
        .map_err(|e| Error::input(tp, format!("the friction law at JSON pointer {ptr}: {e}")))?;
    law.validate()
        .map_err(|e| Error::input(tp, format!("the friction law at JSON pointer {ptr}: {e}")))?;
    Ok(law)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The true law of the main job: the blade's exponential law at truth.json's A, B, C (its
    /// `[truth]` keys); a `[truth] friction_law` pointer read from a JSON object replaces it, and
    /// a pointer to a table that is no law is refused naming the pointer and the keys it needs.
    #[test]
    fn the_true_friction_law_comes_from_the_truth() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut job = LoadedJob::load(&root.join("fits/reversal.toml")).unwrap();
        assert_eq!(
            job.true_friction_law(),
            Some(FrictionLaw::Exponential {
                a: 0.88,
                b_s_per_m: 69.74712740275162,
                c: 0.56
            })
        );
        job.truth.remove(&ParamId::B);
        assert_eq!(job.true_friction_law(), None);
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("truth.json"),
            r#"{"law": {"law": "exponential_viscous", "a": 0.8, "b_s_per_m": 10, "c": 0.2, "d_s_per_m": 0.1},
                "bad": {"law": "stribeck", "a": 0.8}}"#,
        )
        .unwrap();
        let section = |ptr: &str| TruthSection {
            json: "truth.json".into(),
            keys: BTreeMap::new(),
            friction_law: Some(ptr.into()),
            model: None,
        };
        job.truth_friction_law = read_truth(dir.path(), Some(&section("/law"))).unwrap().law;
        assert_eq!(
            job.true_friction_law(),
            Some(FrictionLaw::ExponentialViscous {
                a: 0.8,
                b_s_per_m: 10.0,
                c: 0.2,
                d_s_per_m: 0.1
            })
        );
        let e = read_truth(dir.path(), Some(&section("/bad")))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("/bad") && e.contains("needs a, c, v_s_m_per_s, delta"),
            "{e}"
        );
        let e = read_truth(dir.path(), Some(&section("/none")))
            .unwrap_err()
            .to_string();
        assert!(e.contains("nothing at JSON pointer /none"), "{e}");
    }

    /// A truth key pointing at `null` gives its parameter no true value (the true law lacks it);
    /// a string there is refused naming the pointer.
    #[test]
    fn a_null_truth_is_no_truth() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("truth.json"),
            r#"{"params": {"A": null, "k1": 0.03, "C": "x"}}"#,
        )
        .unwrap();
        let section = |keys: &[(ParamId, &str)]| TruthSection {
            json: "truth.json".into(),
            keys: keys.iter().map(|(k, p)| (*k, p.to_string())).collect(),
            friction_law: None,
            model: None,
        };
        let values = read_truth(
            dir.path(),
            Some(&section(&[
                (ParamId::A, "/params/A"),
                (ParamId::K1, "/params/k1"),
            ])),
        )
        .unwrap()
        .values;
        assert_eq!(values, BTreeMap::from([(ParamId::K1, 0.03)]));
        let e = read_truth(dir.path(), Some(&section(&[(ParamId::C, "/params/C")])))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no number (or null) at JSON pointer /params/C"),
            "{e}"
        );
    }

    /// `[truth] model` reads the true model's name (a shoulder model here); a pointer to nothing
    /// or to a name that is no model is refused naming the pointer.
    #[test]
    fn the_true_model_comes_from_the_truth() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("truth.json"),
            r#"{"model": "blade2dof+shoulder", "bad": "blade3dof"}"#,
        )
        .unwrap();
        let section = |ptr: &str| TruthSection {
            json: "truth.json".into(),
            keys: BTreeMap::new(),
            friction_law: None,
            model: Some(ptr.into()),
        };
        let model = read_truth(dir.path(), Some(&section("/model")))
            .unwrap()
            .model
            .unwrap();
        assert_eq!(model.to_string(), "blade2dof+shoulder");
        for (ptr, says) in [
            ("/bad", "the model at JSON pointer /bad"),
            ("/none", "no model name at JSON pointer /none"),
        ] {
            let e = read_truth(dir.path(), Some(&section(ptr)))
                .unwrap_err()
                .to_string();
            assert!(e.contains(says), "{e}");
        }
    }

    #[test]
    fn spans_locate_keys_tables_and_array_entries() {
        let text = "name = \"x\"\n\n[fit]\nparticles = 1\n\n[[spectrum.bands]]\nname = \"low\"\n\n[[spectrum.bands]]\nname = \"high\"\nnperseg = 4\n";
        let spans = Spans::new(text);
        assert_eq!(
            spans.at(&[Key::Name("fit"), Key::Name("particles")]),
            (4, 13)
        );
        let second = [Key::Name("spectrum"), Key::Name("bands"), Key::Index(1)];
        assert_eq!(
            spans
                .at(&[second[0], second[1], second[2], Key::Name("nperseg")])
                .0,
            11
        );
        // A missing key answers its deepest present ancestor.
        assert_eq!(spans.at(&[Key::Name("fit"), Key::Name("seed")]).0, 3);
    }

    #[test]
    fn band_welch_settings_read_with_scipy_names() {
        let b: BandSpec = toml::from_str(
            "name = \"high\"\nrange_hz = [500.0, 5000.0]\nnperseg = 512\nwindow = \"hamming\"\naverage = \"median\"\nnoverlap = 384",
        )
        .unwrap();
        let cfg = b.welch_config().unwrap();
        assert_eq!(cfg.window, crate::spectrum::Window::Hamming);
        assert_eq!(cfg.average, crate::spectrum::Average::Median);
        assert_eq!((cfg.noverlap, cfg.nfft), (384, 512));
        // SciPy's defaults when not given, and they are not written back out.
        let d = BandSpec::new("low", [30.0, 300.0], 4096);
        assert_eq!(
            d.welch_config().unwrap(),
            crate::spectrum::WelchConfig::new(4096)
        );
        assert!(!toml::to_string(&d).unwrap().contains("window"));
        let bad = BandSpec {
            noverlap: Some(512),
            ..b
        };
        assert!(bad.welch_config().is_err());
    }

    #[test]
    fn candidates_round_trip_by_name() {
        for c in Candidate::all() {
            assert_eq!(c.to_string().parse::<Candidate>(), Ok(c));
        }
        let e = "head1dof+shoulder".parse::<Candidate>().unwrap_err();
        assert!(e.to_string().contains("known: head1dof, necklip"), "{e}");
        // Each model with each law, models in the job's order, laws nested first (duplicates
        // once); every name reads back as its candidate.
        let models: Vec<Candidate> = ["blade2dof", "blade2dof+shoulder"]
            .iter()
            .map(|n| n.parse().unwrap())
            .collect();
        let laws = [
            LawKind::Stribeck,
            LawKind::Exponential,
            LawKind::ExponentialViscous,
            LawKind::Exponential,
        ];
        let all = Candidate::with_laws(&models, &laws);
        let names: Vec<String> = all.iter().map(Candidate::name).collect();
        assert_eq!(
            names,
            [
                "blade2dof@exponential",
                "blade2dof@exponential_viscous",
                "blade2dof@stribeck",
                "blade2dof+shoulder@exponential",
                "blade2dof+shoulder@exponential_viscous",
                "blade2dof+shoulder@stribeck",
            ]
        );
        for c in &all {
            assert_eq!(c.name().parse::<Candidate>(), Ok(*c));
            let text = toml::to_string(&BTreeMap::from([("m", c)])).unwrap();
            let back: BTreeMap<String, Candidate> = toml::from_str(&text).unwrap();
            assert_eq!(back["m"], *c);
        }
        assert_eq!(Candidate::with_laws(&models, &[]), models);
        let e = "blade2dof@viscous".parse::<Candidate>().unwrap_err();
        assert!(
            e.to_string()
                .contains("known: exponential, exponential_viscous, stribeck"),
            "{e}"
        );
        // Each extends the one before it by one step: a law (D, or δ and v_s) or the shoulder.
        let extends = |a: usize, b: usize| all[a].extends(&all[b]);
        assert!(extends(1, 0) && extends(2, 0) && extends(3, 0) && extends(4, 1));
        assert!(extends(4, 3) && extends(5, 3) && extends(5, 2));
        assert!(!extends(2, 1) && !extends(0, 1) && !extends(4, 0) && !extends(0, 0));
        assert!(!models[1].extends(&all[0]) && models[1].extends(&models[0]));
    }

    #[test]
    fn valley_polishes_default_to_the_shoulder_candidates_only() {
        let fit = |extra: &str| -> FitSection {
            toml::from_str(&format!("{extra}\n[parameters]\nA = [0.2, 1.5]\n")).unwrap()
        };
        let plain: Candidate = "blade2dof".parse().unwrap();
        let shoulder: Candidate = "blade2dof+shoulder".parse().unwrap();
        let default = fit("");
        assert_eq!(default.valley_polishes_for(plain), 0);
        assert_eq!(
            default.valley_polishes_for(shoulder),
            SHOULDER_VALLEY_POLISHES
        );
        let set = fit("valley_polishes = 2");
        assert_eq!(set.valley_polishes_for(plain), 2);
        assert_eq!(set.valley_polishes_for(shoulder), 2);
        let off = fit("valley_polishes = 0");
        assert_eq!(off.valley_polishes_for(shoulder), 0);
    }
}
