//! Fitting the friction law (A, B, C) and the neck stiffness (and any other blade parameter a job
//! frees) so that the model's spectra match the measured ones.
//!
//! Cost (per band `b`, measured `d`, model `m`, model PSD plus the measurement's noise floor):
//! `w_peak·(ln f_m/f_d / 0.01)² + w_level·(ln L_m/L_d / ln 2)² + w_shape·mean_k (ln P_m,k − ln P_d,k)²`.
//! Two peak frequencies alone cannot pin down four parameters, hence the level and shape terms; the
//! result still says which parameters the data leave undetermined (from the cost's curvature).
//!
//! Optimisation (argmin): a particle swarm over the bounded box (parallel cost evaluations with
//! rayon), then a Nelder–Mead polish from the best particle. Parameters are searched in normalised
//! coordinates `u ∈ [0, 1]` (logarithmic for bounds spanning a factor ≥ 10).

pub mod features;
pub mod instfreq;
pub mod job;
pub mod result;

pub use result::{
    FitResult, FittedParam, HistoryPoint, Interval, IntervalMethod, ModelTrial, PeakComparison,
    SearchStage,
};

use crate::model::BladeParams;
use crate::model::ParamId;
use crate::model::blade::StickForm;
use crate::simulate::SolverOptions;
use crate::simulate::blade::{BladeSimulation, ModelKind, simulate_model};
use crate::spectrum::stats::quantile_sorted;
use crate::trace::Trace;
use crate::{Error, Result};
use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{CostFunction, Executor, KV, State};
use argmin::solver::neldermead::NelderMead;
use argmin::solver::particleswarm::ParticleSwarm;
use features::{BandSpec, Features, SignalKind, features, noise_floor};
use job::{LoadedJob, Weights};
use rand::SeedableRng;
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Cost assigned to a parameter set whose simulation fails (contact loss, Painlevé, ...). Failures
/// are counted and the first message is reported; they are never silent.
pub const FAILED_COST: f64 = 1e9;

/// One freed parameter: which, bounds, and whether it is searched on a log scale.
#[derive(Debug, Clone, Serialize)]
pub struct FreeParam {
    pub name: ParamId,
    pub lower: f64,
    pub upper: f64,
    pub log: bool,
}

impl FreeParam {
    fn new(name: ParamId, lower: f64, upper: f64) -> Self {
        FreeParam {
            name,
            lower,
            upper,
            log: lower > 0.0 && upper / lower >= 10.0,
        }
    }
    /// Physical value at normalised coordinate `u` (clamped to [0, 1]).
    pub fn value(&self, u: f64) -> f64 {
        let u = u.clamp(0.0, 1.0);
        if self.log {
            (self.lower.ln() + u * (self.upper / self.lower).ln()).exp()
        } else {
            self.lower + u * (self.upper - self.lower)
        }
    }
    /// Normalised coordinate of `value` (the inverse of [`FreeParam::value`], clamped to [0, 1]).
    pub fn u_of(&self, value: f64) -> f64 {
        let u = if self.log {
            (value / self.lower).ln() / (self.upper / self.lower).ln()
        } else {
            (value - self.lower) / (self.upper - self.lower)
        };
        u.clamp(0.0, 1.0)
    }
    /// d(value)/du at `u`.
    pub fn slope(&self, u: f64) -> f64 {
        if self.log {
            self.value(u) * (self.upper / self.lower).ln()
        } else {
            self.upper - self.lower
        }
    }
}

/// Everything a cost evaluation needs; shared read-only between threads.
pub struct SpectralProblem {
    /// Which model of the hierarchy is simulated.
    pub model: ModelKind,
    /// Target ranges per band (a target job): the cost is then [`target_cost`].
    pub targets: Option<Vec<[f64; 2]>>,
    /// The recording's head drop, for the neck/lip model on a prescribed head.
    pub head: Option<Arc<crate::model::necklip::PrescribedHead>>,
    pub base: BladeParams,
    pub free: Vec<FreeParam>,
    pub measured: Features,
    pub floors: Vec<f64>,
    pub bands: Vec<BandSpec>,
    pub signal: SignalKind,
    pub sample_times: Vec<f64>,
    /// NaN mask of the measured signal (model samples there are set to NaN too).
    pub nan_mask: Vec<bool>,
    pub fs_hz: f64,
    pub max_fill: usize,
    pub window: (f64, f64),
    pub solver: SolverOptions,
    /// The solver of the particle-swarm stage (`[fit] swarm_rtol`; else `solver`).
    pub swarm_solver: SolverOptions,
    pub weights: Weights,
    /// Optional frequency-against-speed and trace-error terms (`None` when their weights are 0).
    pub time_targets: Option<instfreq::TimeTargets>,
    /// Further recordings fitted jointly (`[[more_recordings]]`): each is a problem of its own
    /// (its measurement, drive and base), sharing `free`; their costs add to this one's.
    pub others: Vec<SpectralProblem>,
    /// Name of this problem's recording in joint fits ("" for the main one).
    pub label: String,
    pub evaluations: Arc<AtomicUsize>,
    pub failures: AtomicUsize,
    pub first_failure: Mutex<Option<String>>,
    pub progress: Option<indicatif::ProgressBar>,
}

impl SpectralProblem {
    /// Blade parameters at normalised coordinates `u`.
    pub fn params_at(&self, u: &[f64]) -> BladeParams {
        let mut p = self.base;
        for (fp, ui) in self.free.iter().zip(u) {
            fp.name.set(&mut p, fp.value(*ui));
        }
        p
    }

    /// Simulates the model at `params`, sampled at the recording's times.
    pub fn simulate(&self, params: &BladeParams) -> Result<BladeSimulation> {
        self.simulate_with(params, &self.solver)
    }

    /// [`SpectralProblem::simulate`] with the given solver settings.
    fn simulate_with(
        &self,
        params: &BladeParams,
        solver: &SolverOptions,
    ) -> Result<BladeSimulation> {
        if self.model == ModelKind::Necklip {
            let head = self.head.as_ref().ok_or_else(|| {
                Error::Config("the neck/lip model needs the recording's head track".into())
            })?;
            return crate::simulate::blade::simulate_necklip(
                params,
                head,
                self.window,
                &self.sample_times,
                solver,
            );
        }
        simulate_model(
            self.model,
            params,
            self.window,
            &self.sample_times,
            solver,
            StickForm::Reduced,
        )
    }

    /// Spectral features of a simulation, through the measurement's estimator and NaN mask.
    pub fn model_features(&self, sim: &BladeSimulation) -> Result<Features> {
        let mut x = self.signal.extract(&sim.to_trace())?;
        for (xi, m) in x.iter_mut().zip(&self.nan_mask) {
            if *m {
                *xi = f64::NAN;
            }
        }
        features(&x, self.fs_hz, &self.bands, self.max_fill)
    }

    /// The cost of model features against the measurement (see the module docs).
    pub fn cost_of(&self, model: &Features) -> f64 {
        if let Some(t) = &self.targets {
            return target_cost(t, model);
        }
        let w = &self.weights;
        let mut total = 0.0;
        for ((d, m), floor) in self
            .measured
            .bands
            .iter()
            .zip(&model.bands)
            .zip(&self.floors)
        {
            match (d.peak, m.peak) {
                (Some(pd), Some(pm)) => {
                    let df = (pm.freq_hz / pd.freq_hz).ln() / 0.01;
                    let dl = ((pm.level + floor) / pd.level).ln() / std::f64::consts::LN_2;
                    total += w.peak * df * df + w.level * dl * dl;
                }
                _ => total += 100.0 * (w.peak + w.level),
            }
            let n = d.psd.len().min(m.psd.len()).max(1);
            let mut s = 0.0;
            for (pd, pm) in d.psd.iter().zip(&m.psd) {
                let r = ((pm + floor) / pd.max(f64::MIN_POSITIVE)).ln();
                if r.is_finite() {
                    s += r * r;
                }
            }
            total += w.shape * s / n as f64;
        }
        total
    }

    /// Spectral cost of a simulation plus the optional time-domain terms ([`instfreq::TimeTargets`]).
    pub fn total_cost(&self, sim: &BladeSimulation) -> Result<f64> {
        let spectral = self.cost_of(&self.model_features(sim)?);
        Ok(match &self.time_targets {
            Some(t) => spectral + t.cost(sim)?,
            None => spectral,
        })
    }

    /// Cost at normalised coordinates, with a quadratic penalty outside the box.
    pub fn cost_at(&self, u: &[f64]) -> f64 {
        self.cost_at_stage(u, SearchStage::Polish)
    }

    /// [`SpectralProblem::cost_at`] with the simulations of `stage` (the swarm's may be coarser).
    fn cost_at_stage(&self, u: &[f64], stage: SearchStage) -> f64 {
        let solver = match stage {
            SearchStage::Swarm => &self.swarm_solver,
            SearchStage::Polish => &self.solver,
        };
        let outside: f64 = u
            .iter()
            .map(|x| (x - x.clamp(0.0, 1.0)).powi(2))
            .sum::<f64>();
        let p = self.params_at(u);
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        if let Some(pb) = &self.progress {
            pb.inc(1);
        }
        let c = match self
            .simulate_with(&p, solver)
            .and_then(|s| self.total_cost(&s))
        {
            Ok(c) => c,
            Err(e) => {
                self.failures.fetch_add(1, Ordering::Relaxed);
                let mut g = self.first_failure.lock().unwrap_or_else(|e| e.into_inner());
                if g.is_none() {
                    *g = Some(e.to_string());
                }
                FAILED_COST
            }
        };
        let joint: f64 = self.others.iter().map(|o| o.cost_at_stage(u, stage)).sum();
        c + joint + 1e4 * outside
    }
}

struct HistoryObserver {
    stage: SearchStage,
    restart: usize,
    log: Arc<Mutex<Vec<HistoryPoint>>>,
    evals: Arc<AtomicUsize>,
}

impl<I: State<Float = f64>> Observe<I> for HistoryObserver {
    fn observe_iter(
        &mut self,
        state: &I,
        _kv: &KV,
    ) -> std::result::Result<(), argmin::core::Error> {
        self.log
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(HistoryPoint {
                stage: self.stage,
                restart: self.restart,
                iteration: state.get_iter(),
                best_cost: state.get_best_cost(),
                evaluations: self.evals.load(Ordering::Relaxed),
            });
        Ok(())
    }
}

/// The result plus what the report draws.
pub struct FitOutcome {
    pub result: FitResult,
    pub measured_trace: Trace,
    pub measured: Features,
    pub model: Features,
    pub best_sim: BladeSimulation,
    pub best_params: BladeParams,
    pub fs_hz: f64,
    pub signal: SignalKind,
}

/// The problem as argmin sees it in one stage: shared by the swarm's threads.
#[derive(Clone)]
struct Shared(Arc<SpectralProblem>, SearchStage);

impl CostFunction for Shared {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, u: &Self::Param) -> std::result::Result<f64, argmin::core::Error> {
        Ok(self.0.cost_at_stage(u, self.1))
    }
}

/// Sampling rate of a trace: the recording's fps if given, else from the time column. Errors if
/// the frame times are not uniform to 1e-6 relative (resample first).
fn sampling_rate(trace: &Trace, fps: Option<f64>) -> Result<f64> {
    let fs = match fps {
        Some(f) => f,
        None => crate::spectrum::median_rate_hz(&trace.t_s),
    };
    if !(fs.is_finite() && fs > 0.0) {
        return Err(Error::Config(
            "cannot tell the recording's frame rate: give recording.import.fps_hz".into(),
        ));
    }
    let dt = 1.0 / fs;
    for w in trace.t_s.windows(2) {
        if ((w[1] - w[0]) - dt).abs() > 1e-6 * dt.max(1e-12) * 1e3 {
            return Err(Error::Config(format!(
                "the recording's frame times are not uniform at {fs} Hz (step {} s found); resample it first",
                w[1] - w[0]
            )));
        }
    }
    Ok(fs)
}

/// Lower edge of a band, Hz, at or above which the band asks for the neck–lip mode. The head
/// model ([`ModelKind::Head1dof`]) has only the head's low mode (tens of Hz, seed §0.1: 12.9 and
/// 78.4 Hz) and the stick–slip it drives; the neck–lip component sits at hundreds of Hz (seed: 359–692
/// and ~900 Hz; free neck 195 Hz).
pub const NECK_BAND_MIN_HZ: f64 = 150.0;

/// One candidate of the model hierarchy: a model kind, with or without shoulder contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Candidate {
    pub kind: ModelKind,
    pub shoulder: bool,
}

impl Candidate {
    /// Every candidate a job may list, smallest first.
    pub fn all() -> Vec<Candidate> {
        ModelKind::ALL
            .iter()
            .flat_map(|&kind| {
                let shoulders: &[bool] = if kind.has_neck_mode() {
                    &[false, true]
                } else {
                    &[false]
                };
                shoulders
                    .iter()
                    .map(move |&shoulder| Candidate { kind, shoulder })
            })
            .collect()
    }

    /// The name used in jobs and reports: the model's name, with `+shoulder` when it has one.
    pub fn name(&self) -> String {
        self.to_string()
    }

    /// Why this candidate cannot produce `bands` (None if it can).
    pub fn cannot_produce(&self, bands: &[BandSpec]) -> Option<String> {
        if !self.kind.has_head_mode() {
            return bands
                .iter()
                .find(|b| b.range_hz[0] < NECK_BAND_MIN_HZ)
                .map(|b| {
                    format!(
                        "imposes band '{}' ({:.0}–{:.0} Hz) from the recording's head track instead of modelling it",
                        b.name, b.range_hz[0], b.range_hz[1]
                    )
                });
        }
        if self.kind.has_neck_mode() {
            return None;
        }
        bands
            .iter()
            .find(|b| b.range_hz[0] >= NECK_BAND_MIN_HZ)
            .map(|b| {
                format!(
                    "has no neck–lip mode for band '{}' ({:.0}–{:.0} Hz)",
                    b.name, b.range_hz[0], b.range_hz[1]
                )
            })
    }
}

/// Suffix of a candidate's name that adds shoulder contact.
const SHOULDER_SUFFIX: &str = "+shoulder";

impl std::fmt::Display for Candidate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.kind.name())?;
        if self.shoulder {
            f.write_str(SHOULDER_SUFFIX)?;
        }
        Ok(())
    }
}

impl std::str::FromStr for Candidate {
    type Err = crate::names::UnknownName;
    /// Parses a model name with an optional `+shoulder` (the head model has no shoulder).
    fn from_str(name: &str) -> std::result::Result<Self, Self::Err> {
        Candidate::all()
            .into_iter()
            .find(|c| *c == name)
            .ok_or_else(|| crate::names::UnknownName {
                kind: "model",
                given: name.to_string(),
                known: Candidate::all()
                    .iter()
                    .map(|c| c.to_string())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }
}

impl Serialize for Candidate {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for Candidate {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

impl PartialEq<&str> for Candidate {
    fn eq(&self, other: &&str) -> bool {
        match other.strip_suffix(SHOULDER_SUFFIX) {
            Some(base) => self.shoulder && self.kind.name() == base,
            None => !self.shoulder && self.kind.name() == *other,
        }
    }
}

/// The smallest model of the hierarchy that can produce every band in `bands`: the head model when
/// all bands lie below [`NECK_BAND_MIN_HZ`], else the full blade.
///
/// The neck/lip model on a prescribed head is not in this default chain, although it models less:
/// on a tracked recording it costs more, not less. On the shipped recording with the true blade one
/// run takes 1.7 s against 0.066 s for the full blade (158 thousand steps against 22 thousand;
/// the tracking noise in the prescribed head drives extra stick–slip transitions, 218 against 144).
/// Fitting the high band alone (README, "Which model the scene needs"): 227 runs took 280 s and left
/// k1 77 % off (the peak matched with the wrong parameters), where the full blade took 20 s for 824
/// runs and came within 0.12 %. Name it in `[fit] models`
/// when the head's suspension (k0, c0, the head mass) is unknown: it takes the head's motion from
/// the recording instead.
pub fn smallest_capable_model(bands: &[BandSpec]) -> ModelKind {
    [ModelKind::Head1dof, ModelKind::Blade2dof]
        .into_iter()
        .find(|&kind| {
            Candidate {
                kind,
                shoulder: false,
            }
            .cannot_produce(bands)
            .is_none()
        })
        .unwrap_or(ModelKind::Blade2dof)
}

/// Standard deviation of the Gaussian kernel that smooths a recorded head drop for the neck/lip
/// model, s. Its gain `exp(−(2πfσ)²/2)` is 0.988 at the sample's 49 Hz low component and 0.02 at
/// 900 Hz, where the heavy head hardly moves. A local quadratic fit's piecewise interpolant made the
/// integrator cut its step at every sample; the kernel smooth is infinitely differentiable (measured
/// on the shipped recording with the true blade: 4.3 thousand rejected steps instead of 157
/// thousand).
pub const HEAD_KERNEL_SIGMA_S: f64 = 5e-4;

/// The measured side of a fit, shared by every candidate.
struct Measurement {
    /// The head drop `−y` of the `head` point and the lean (tip x − head x), smoothed, for the
    /// neck/lip model; why not, when the recording cannot give them.
    head: std::result::Result<Arc<crate::model::necklip::PrescribedHead>, String>,
    /// Target ranges per band (a target job), instead of measured peaks.
    targets: Option<Vec<[f64; 2]>>,
    /// Time-domain objectives (frequency against tip speed, trace error) when weighted.
    time_targets: Option<instfreq::TimeTargets>,
    trace: Trace,
    x: Vec<f64>,
    fs_hz: f64,
    measured: Features,
    floors: Vec<f64>,
}

/// The measurement as the neck/lip model sees it: the samples in the guard around the blade's flip
/// (where the model does not run, [`crate::model::necklip::PrescribedHead::segments`]) are masked,
/// and the measured features and noise floors are taken again without them, so that measurement
/// and model are compared on the same samples. Returns `(features, floors, NaN mask)`.
fn necklip_view(
    job: &LoadedJob,
    m: &Measurement,
    base: &BladeParams,
) -> Result<(Features, Vec<f64>, Vec<bool>)> {
    let head = m.head.as_ref().map_err(|e| {
        Error::Config(format!(
            "the neck/lip model needs the recording's head and tip tracks: {e}"
        ))
    })?;
    let t = &m.trace.t_s;
    let window = (t[0], *t.last().unwrap_or(&t[0]));
    let guard = crate::model::necklip::FLIP_GUARD_OF_REACH * (base.l1_m + base.l2_m);
    let segments = head.segments(window, guard);
    let mask: Vec<bool> = t
        .iter()
        .zip(&m.x)
        .map(|(ti, xi)| !xi.is_finite() || !segments.iter().any(|s| s.0 <= *ti && *ti <= s.1))
        .collect();
    let x: Vec<f64> =
        m.x.iter()
            .zip(&mask)
            .map(|(v, masked)| if *masked { f64::NAN } else { *v })
            .collect();
    let measured = features(
        &x,
        m.fs_hz,
        &job.job.spectrum.bands,
        job.job.spectrum.max_fill,
    )?;
    let floors = measured.bands.iter().map(noise_floor).collect();
    Ok((measured, floors, mask))
}

/// One candidate fitted.
struct CandidateFit {
    candidate: Candidate,
    free: Vec<FreeParam>,
    problem: Arc<SpectralProblem>,
    best_u: Vec<f64>,
    sigma_u: Vec<f64>,
    corr: Vec<Vec<f64>>,
    swarm_iters: u64,
    polish_iters: u64,
    wall_time_s: f64,
    history: Vec<HistoryPoint>,
    cost: f64,
}

/// The cost problem of one candidate: its freed parameters (the job's, plus the shoulder's when
/// the candidate has one) and the measurement as that model sees it, with any further recordings
/// of a joint fit attached.
fn build_problem(
    job: &LoadedJob,
    meas: &Measurement,
    candidate: Candidate,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<(SpectralProblem, Vec<FreeParam>)> {
    let fit = &job.job.fit;
    let mut base = job.blade;
    let mut free: Vec<FreeParam> = job
        .free
        .iter()
        .map(|&(n, lo, hi)| FreeParam::new(n, lo, hi))
        .collect();
    if candidate.shoulder {
        let sb = fit.shoulder.ok_or_else(|| {
            Error::Config("the shoulder candidate needs [fit.shoulder] bounds".into())
        })?;
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
    let evaluations = Arc::new(AtomicUsize::new(0));
    let build = |m: &Measurement, base: BladeParams, label: String, progress| -> Result<_> {
        let (measured, floors, nan_mask) = if candidate.kind == ModelKind::Necklip {
            necklip_view(job, m, &base)?
        } else {
            (
                m.measured.clone(),
                m.floors.clone(),
                m.x.iter().map(|v| !v.is_finite()).collect(),
            )
        };
        Ok(SpectralProblem {
            model: candidate.kind,
            head: m.head.clone().ok(),
            targets: m.targets.clone(),
            time_targets: m.time_targets.clone(),
            others: Vec::new(),
            label,
            base,
            free: free.clone(),
            measured,
            floors,
            bands: job.job.spectrum.bands.clone(),
            signal: job.job.spectrum.signal,
            nan_mask,
            sample_times: m.trace.t_s.clone(),
            fs_hz: m.fs_hz,
            max_fill: job.job.spectrum.max_fill,
            window: (
                m.trace.t_s[0],
                *m.trace.t_s.last().unwrap_or(&m.trace.t_s[0]),
            ),
            solver: job.job.solver,
            swarm_solver: match fit.swarm_rtol {
                Some(r) => SolverOptions {
                    rtol: r,
                    atol: job.job.solver.atol * r / job.job.solver.rtol,
                    ..job.job.solver
                },
                None => job.job.solver,
            },
            weights: fit.weights,
            evaluations: evaluations.clone(),
            failures: AtomicUsize::new(0),
            first_failure: Mutex::new(None),
            progress,
        })
    };
    let mut main = build(meas, base, String::new(), pb.clone())?;
    let dir = job.path.parent().unwrap_or(std::path::Path::new("."));
    for more in &job.job.more_recordings {
        let m = measure_recording(job, &dir.join(&more.file), &more.import)?;
        let mut b = base;
        b.drive_a_m = more.drive_a_m.unwrap_or(b.drive_a_m);
        b.drive_omega_rad_per_s = more
            .drive_omega_rad_per_s
            .unwrap_or(b.drive_omega_rad_per_s);
        main.others.push(build(&m, b, more.name.clone(), None)?);
    }
    Ok((main, free))
}

/// The cost problem of the candidate `model` on the
/// job's recording or targets, without fitting it: for evaluating the cost at given parameters
/// ([`SpectralProblem::cost_at`], [`SpectralProblem::params_at`]).
///
/// # Errors
/// Every error of reading and measuring the recording.
pub fn problem_for(job: &LoadedJob, candidate: Candidate) -> Result<SpectralProblem> {
    let meas = measure(job)?;
    Ok(build_problem(job, &meas, candidate, &None)?.0)
}

/// Fits one candidate: particle swarm, Nelder–Mead polish, curvature.
///
/// `nested`: the fit of the candidate without shoulder, when `candidate` adds one to it and that
/// fit is done. Its optimum, with k1_contact = k1 (so the shoulder changes no moment), seeds one
/// particle of the first swarm and is itself kept if no restart ends below it (see `optimise`):
/// the larger model then cannot end above the smaller one's cost, which the AIC comparison of
/// nested models assumes. On the shipped recording without the warm particle, the shoulder
/// candidate ended at 0.158 against 0.125 for the model it contains.
fn fit_candidate(
    job: &LoadedJob,
    meas: &Measurement,
    candidate: Candidate,
    pb: &Option<indicatif::ProgressBar>,
    nested: Option<&CandidateFit>,
) -> Result<CandidateFit> {
    let started = std::time::Instant::now();
    let fit = &job.job.fit;
    if let Some(pb) = pb {
        pb.set_message(format!("{} swarm", candidate.name()));
    }
    let (main, free) = build_problem(job, meas, candidate, pb)?;
    let problem = Arc::new(main);
    let history = Arc::new(Mutex::new(Vec::new()));
    let warm: Option<Vec<f64>> = nested.map(|smaller| {
        let params = smaller.problem.params_at(&smaller.best_u);
        free.iter()
            .map(|fp| {
                let source = if fp.name == ParamId::K1c {
                    ParamId::K1
                } else {
                    fp.name
                };
                // The smaller model's own coordinate where the scales agree: then the values are
                // bitwise the same (a value → u → value round trip through ln/exp can move them by
                // an ulp, and on this chaotic cost surface one ulp of k1 moved the main job's cost by
                // 0.4 %).
                if let Some(i) = smaller.free.iter().position(|f| {
                    f.name == source
                        && f.lower == fp.lower
                        && f.upper == fp.upper
                        && f.log == fp.log
                }) {
                    return smaller.best_u[i];
                }
                let v = match fp.name {
                    ParamId::K1c => params.k1_nm_per_rad,
                    ParamId::ThetaC => fp.upper,
                    id => id.get(&params).unwrap_or(fp.lower),
                };
                fp.u_of(v)
            })
            .collect()
    });
    let (best_u, swarm_iters, polish_iters, cost) = optimise(
        &problem,
        fit,
        fit.seed,
        warm.as_deref(),
        Some((&history, pb, candidate)),
    )?;

    // Curvature of the cost at the optimum → standard errors, correlations, identifiability.
    if let Some(pb) = pb {
        pb.set_message(format!("{} curvature", candidate.name()));
    }
    let (sigma_u, corr) = curvature(&problem, &best_u);
    let history = history.lock().unwrap_or_else(|e| e.into_inner()).clone();
    Ok(CandidateFit {
        candidate,
        free,
        problem,
        best_u,
        sigma_u,
        corr,
        swarm_iters,
        polish_iters,
        wall_time_s: started.elapsed().as_secs_f64(),
        history,
        cost,
    })
}

/// The estimator: `restarts` independent runs of a particle swarm over `[0, 1]^n` (`particles`,
/// `swarm_iterations`; 0 iterations skips it and starts from the problem's centre), each followed by
/// a Nelder–Mead polish from its best particle; the run with the lowest cost is kept. Restart `r`
/// seeds its swarm with `seed ^ (r · 0x9E3779B97F4A7C15)`, so restart 0 is the single-run fit.
///
/// Restarts because the cost surface is rough: the stick–slip comb's largest line jumps as the
/// parameters move, so one swarm can settle in a nearby minimum. On the shipped recording, single
/// swarms of 24 particles × 25 iterations ended in the truth's basin (cost 0.25) for some seeds and
/// at 0.97 or 0.45 for others (README, "Restarts").
/// `warm`: a point that one particle of the first swarm starts at (the others at random); it is
/// also returned itself if no restart ends below its cost.
/// Returns `(best_u, swarm iterations, polish iterations, best cost)`, the iterations summed over
/// the restarts.
#[allow(clippy::type_complexity)]
fn optimise(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    seed: u64,
    warm: Option<&[f64]>,
    log: Option<(
        &Arc<Mutex<Vec<HistoryPoint>>>,
        &Option<indicatif::ProgressBar>,
        Candidate,
    )>,
) -> Result<(Vec<f64>, u64, u64, f64)> {
    let n = problem.free.len();
    let fit_err = |e: argmin::core::Error| Error::Fit(e.to_string());
    let evaluations = problem.evaluations.clone();
    let observer = |stage: SearchStage, restart: usize| {
        log.map(|(h, _, _)| HistoryObserver {
            stage,
            restart,
            log: h.clone(),
            evals: evaluations.clone(),
        })
    };
    let restarts = fit.restarts.max(1);
    // The warm point itself, at the polish's tolerance, is a candidate result: then a nested fit
    // cannot end above the smaller model's cost even when the swarm ranks points at a looser
    // tolerance (`[fit] swarm_rtol`) and leaves the warm particle's basin.
    let mut best: Option<(Vec<f64>, f64)> = warm.map(|w| (w.to_vec(), problem.cost_at(w)));
    let (mut swarm_iters, mut polish_iters) = (0, 0);
    for r in 0..restarts {
        if let Some((_, Some(pb), c)) = log {
            pb.set_message(if restarts > 1 {
                format!("{} swarm {}/{restarts}", c.name(), r + 1)
            } else {
                format!("{} swarm", c.name())
            });
        }
        let run_seed = seed ^ (r as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let pso = ParticleSwarm::new((vec![0.0; n], vec![1.0; n]), fit.particles)
            .with_rng_generator(rand::rngs::StdRng::seed_from_u64(run_seed));
        let population = match warm {
            Some(w) if r == 0 && fit.particles > 0 => {
                Some(warm_population(problem, w, fit.particles, run_seed))
            }
            _ => None,
        };
        let mut ex =
            Executor::new(Shared(problem.clone(), SearchStage::Swarm), pso).configure(|s| {
                let s = s.max_iters(fit.swarm_iterations);
                match population {
                    Some(p) => s.population(p),
                    None => s,
                }
            });
        if let Some(o) = observer(SearchStage::Swarm, r) {
            ex = ex.add_observer(o, ObserverMode::Always);
        }
        let res = ex.run().map_err(fit_err)?;
        let swarm_best = res
            .state()
            .get_best_param()
            .map(|p| p.position.clone())
            .ok_or_else(|| Error::Fit("particle swarm returned no particle".into()))?;
        swarm_iters += res.state().get_iter();
        if let Some((_, Some(pb), c)) = log {
            pb.set_message(format!("{} polish", c.name()));
        }
        let (u, iters, cost) = polish(
            problem,
            &swarm_best,
            0.05,
            fit.polish_iterations,
            observer(SearchStage::Polish, r),
        )?;
        polish_iters += iters;
        if best.as_ref().is_none_or(|b| cost < b.1) {
            best = Some((u, cost));
        }
    }
    let (u, cost) = best.ok_or_else(|| Error::Fit("no optimiser run".into()))?;
    Ok((u, swarm_iters, polish_iters, cost))
}

/// A swarm's first population with one particle at `warm` and the others drawn uniformly over
/// `[0, 1]^n` (velocities uniform in `[−1, 1]^n`, as argmin draws them); costs evaluated in parallel.
fn warm_population(
    problem: &Arc<SpectralProblem>,
    warm: &[f64],
    particles: usize,
    seed: u64,
) -> Vec<argmin::solver::particleswarm::Particle<Vec<f64>, f64>> {
    use rand::Rng;
    use rayon::prelude::*;
    let n = warm.len();
    // A stream of its own, so that the swarm's generator (same seed) does not replay these draws.
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed ^ 0x5741_524D);
    let mut start: Vec<(Vec<f64>, Vec<f64>)> = (0..particles)
        .map(|_| {
            let x: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..=1.0)).collect();
            let v: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..=1.0)).collect();
            (x, v)
        })
        .collect();
    start[0].0 = warm.to_vec();
    start
        .into_par_iter()
        .map(|(x, v)| {
            let c = problem.cost_at_stage(&x, SearchStage::Swarm);
            argmin::solver::particleswarm::Particle::new(x, c, v)
        })
        .collect()
}

/// Nelder–Mead from `start` with an initial simplex of edge `step` (normalised units).
fn polish(
    problem: &Arc<SpectralProblem>,
    start: &[f64],
    step: f64,
    iterations: u64,
    observer: Option<HistoryObserver>,
) -> Result<(Vec<f64>, u64, f64)> {
    let fit_err = |e: argmin::core::Error| Error::Fit(e.to_string());
    let n = start.len();
    let mut simplex = vec![start.to_vec()];
    for i in 0..n {
        let mut v = start.to_vec();
        v[i] = if v[i] + step <= 1.0 {
            v[i] + step
        } else {
            v[i] - step
        };
        simplex.push(v);
    }
    let nm = NelderMead::new(simplex)
        .with_sd_tolerance(1e-3)
        .map_err(fit_err)?;
    let mut ex = Executor::new(Shared(problem.clone(), SearchStage::Polish), nm)
        .configure(|s| s.max_iters(iterations));
    if let Some(o) = observer {
        ex = ex.add_observer(o, ObserverMode::Always);
    }
    let res = ex.run().map_err(fit_err)?;
    let u: Vec<f64> = res
        .state()
        .get_best_param()
        .cloned()
        .unwrap_or_else(|| start.to_vec())
        .iter()
        .map(|u| u.clamp(0.0, 1.0))
        .collect();
    Ok((u, res.state().get_iter(), res.state().get_best_cost()))
}

/// Akaike's information criterion with the cost read as −2 ln L (a χ² on the cost's scales):
/// `AIC = cost + 2k` for `k` freed parameters (Akaike 1974, IEEE TAC 19:716).
pub fn aic(cost: f64, k: usize) -> f64 {
    cost + 2.0 * k as f64
}

/// Reads the recording and its features.
fn measure_recording(
    job: &LoadedJob,
    path: &std::path::Path,
    spec: &crate::import::ImportSpec,
) -> Result<Measurement> {
    let trace = crate::import::read_trace(path, spec)?;
    let fs_hz = sampling_rate(&trace, spec.fps_hz)?;
    let signal = job.job.spectrum.signal;
    let x = signal.extract(&trace)?;
    let measured = features(
        &x,
        fs_hz,
        &job.job.spectrum.bands,
        job.job.spectrum.max_fill,
    )?;
    for b in &measured.bands {
        if b.peak.is_none() {
            return Err(Error::input(
                path,
                format!(
                    "the measured {} has no spectral peak in band '{}' {:?} Hz",
                    signal.label(),
                    b.spec.name,
                    b.spec.range_hz
                ),
            ));
        }
    }
    let floors: Vec<f64> = measured.bands.iter().map(noise_floor).collect();
    // The head drop u = −y (the import puts y up with the origin at the upright head), for the
    // neck/lip model, smoothed by a Gaussian kernel (HEAD_KERNEL_SIGMA_S).
    // The lean d = tip x − head x, smoothed alike, locates the blade's flip (which the neck/lip model
    // cannot pass) and gives the model's state after it.
    let head = match trace.point("head").zip(trace.point("tip")) {
        Some((h, tip)) => {
            let u: Vec<f64> = h.y_m.iter().map(|y| -y).collect();
            let d: Vec<f64> = tip.x_m.iter().zip(&h.x_m).map(|(a, b)| a - b).collect();
            crate::model::necklip::PrescribedHead::from_tracked_samples(
                trace.t_s[0],
                1.0 / fs_hz,
                &u,
                HEAD_KERNEL_SIGMA_S,
            )
            .and_then(|p| p.with_lean(&d, 15))
            .map(Arc::new)
            .map_err(|e| format!("{}: {e}", path.display()))
        }
        None => Err(format!(
            "{}: the recording has no 'head' and 'tip' points",
            path.display()
        )),
    };
    Ok(Measurement {
        head,
        time_targets: instfreq::TimeTargets::for_job(
            &job.job.fit.weights,
            &trace,
            &x,
            fs_hz,
            signal,
        )?,
        trace,
        x,
        fs_hz,
        measured,
        floors,
        targets: None,
    })
}

/// A target job's "measurement": the model's default reversal window sampled at the target rate, no
/// recorded points, and per band the target range.
fn measure_targets(job: &LoadedJob, t: &job::TargetsSection) -> Result<Measurement> {
    let (t0, t1) = crate::simulate::blade::default_window(&job.blade);
    let n = ((t1 - t0) * t.fps_hz).floor() as usize + 1;
    let times: Vec<f64> = (0..n).map(|k| t0 + k as f64 / t.fps_hz).collect();
    let mut targets = Vec::new();
    let mut bands = Vec::new();
    for b in &job.job.spectrum.bands {
        let tp = t.peaks.iter().find(|p| p.band == b.name).ok_or_else(|| {
            Error::Config(format!("[targets] gives no target for band '{}'", b.name))
        })?;
        let r = tp.range();
        targets.push(r);
        bands.push(features::BandFeatures {
            spec: b.clone(),
            freq_hz: Vec::new(),
            psd: Vec::new(),
            peak: Some(crate::spectrum::Peak {
                freq_hz: (r[0] * r[1]).sqrt(),
                level: f64::NAN,
                bin: 0,
                prominence: f64::NAN,
            }),
            full_freq_hz: Vec::new(),
            full_psd: Vec::new(),
        });
    }
    Ok(Measurement {
        x: vec![0.0; n],
        trace: Trace {
            t_s: times,
            points: Vec::new(),
        },
        fs_hz: t.fps_hz,
        measured: Features { bands, filled: 0 },
        floors: vec![0.0; job.job.spectrum.bands.len()],
        head: Err("a target job has no recording".into()),
        targets: Some(targets),
        time_targets: None,
    })
}

/// Cost of a target job: per band, `(ln f_m/f_edge / 0.01)²` when the model's peak `f_m` lies outside
/// the target range (`f_edge` the nearest edge; 0 inside), 100 when the model has no peak in the band.
pub fn target_cost(targets: &[[f64; 2]], model: &Features) -> f64 {
    targets
        .iter()
        .zip(&model.bands)
        .map(|(r, b)| match b.peak {
            Some(p) => {
                let f = p.freq_hz;
                let edge = f.clamp(r[0], r[1]);
                let d = (f / edge).ln() / 0.01;
                d * d
            }
            None => 1e4,
        })
        .sum()
}

/// The job's measured side: its recording measured, or its targets.
fn measure(job: &LoadedJob) -> Result<Measurement> {
    match (&job.job.recording, &job.job.targets) {
        (Some(rec), _) => measure_recording(job, &job.recording_path, &rec.import),
        (None, Some(t)) => measure_targets(job, t),
        (None, None) => Err(Error::Config(
            "the job gives neither [recording] nor [targets]".into(),
        )),
    }
}

/// Runs the job: import, measured features, then for each candidate model a particle swarm,
/// Nelder–Mead and the curvature; the candidate with the lowest [`aic`] is reported.
///
/// `progress`: show a progress bar on stderr (hidden automatically when stderr is not a terminal).
pub fn run_fit(job: &LoadedJob, progress: bool) -> Result<FitOutcome> {
    let started = std::time::Instant::now();
    // Provenance: the recording's hash and the effective settings (job with defaults filled in).
    let input_sha256 = result::sha256_file(&job.recording_path)?;
    let settings = toml::to_string_pretty(&job.job)
        .or_else(|_| job::read_text(&job.path))
        .unwrap_or_default();
    let signal = job.job.spectrum.signal;
    let bands = job.job.spectrum.bands.clone();
    let meas = measure(job)?;
    let fs_hz = meas.fs_hz;

    let fit = &job.job.fit;
    let candidates: Vec<Candidate> = if fit.models.is_empty() {
        vec![Candidate {
            kind: smallest_capable_model(&bands),
            shoulder: false,
        }]
    } else {
        fit.models.clone()
    };
    let pb = if progress {
        let mut budget = 0u64;
        for c in &candidates {
            let n = job.free.len() + if c.shoulder { 2 } else { 0 };
            let hess_evals = 1 + 2 * n + 2 * n * n.saturating_sub(1);
            budget += fit.restarts.max(1) as u64
                * (fit.particles as u64 * (fit.swarm_iterations + 1)
                    + (n as u64 + 1)
                    + 2 * fit.polish_iterations)
                + hess_evals as u64;
        }
        let pb = indicatif::ProgressBar::new(budget);
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg:28} [{bar:32}] {pos}/{len} model runs, {elapsed} (eta {eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        Some(pb)
    } else {
        None
    };
    let mut fits = Vec::new();
    for c in &candidates {
        let nested = fits.iter().find(|f: &&CandidateFit| {
            c.shoulder && f.candidate.kind == c.kind && !f.candidate.shoulder
        });
        let fitted = fit_candidate(job, &meas, *c, &pb, nested)?;
        fits.push(fitted);
    }
    // Choose by AIC among candidates that produced a model and can produce every band (the
    // neck/lip model imposes a low band from the head track, so its cost there proves nothing);
    // if none can, among all.
    let aics: Vec<f64> = fits
        .iter()
        .map(|f| {
            if f.cost < FAILED_COST {
                aic(f.cost, f.free.len())
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let capable: Vec<bool> = fits
        .iter()
        .map(|f| f.candidate.cannot_produce(&bands).is_none())
        .collect();
    let any_capable = capable.iter().any(|c| *c);
    let scores: Vec<f64> = (0..fits.len())
        .map(|i| {
            if capable[i] || !any_capable {
                aics[i]
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let chosen = (0..fits.len())
        .min_by(|&a, &b| scores[a].total_cmp(&scores[b]))
        .unwrap_or(0);
    let model_trials: Vec<ModelTrial> = fits
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let capable = f.candidate.cannot_produce(&bands);
            let reason = if fits.len() == 1 {
                if fit.models.is_empty() {
                    format!(
                        "the smallest model that can produce the job's bands ({})",
                        bands
                            .iter()
                            .map(|b| format!(
                                "{} {:.0}–{:.0} Hz",
                                b.name, b.range_hz[0], b.range_hz[1]
                            ))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                } else {
                    "the only model the job lists".into()
                }
            } else if i == chosen {
                let next = (0..fits.len())
                    .filter(|&j| j != chosen)
                    .map(|j| scores[j])
                    .fold(f64::INFINITY, f64::min);
                if next.is_finite() {
                    format!(
                        "lowest AIC = cost + 2k = {:.2} (k = {}); next best {:.2}",
                        scores[i],
                        f.free.len(),
                        next
                    )
                } else {
                    format!(
                        "AIC = cost + 2k = {:.2} (k = {}); the only candidate that produced every band",
                        scores[i],
                        f.free.len()
                    )
                }
            } else {
                let mut r = format!(
                    "AIC {:.2} (k = {}), {:+.2} against the chosen model",
                    aics[i],
                    f.free.len(),
                    aics[i] - aics[chosen]
                );
                if let Some(why) = capable {
                    r.push_str(&format!("; {why}"));
                }
                r
            };
            ModelTrial {
                model: f.candidate,
                parameters: f.free.iter().map(|p| p.name).collect(),
                cost: f.cost,
                wall_time_s: f.wall_time_s,
                model_evaluations: f.problem.evaluations.load(Ordering::Relaxed),
                chosen: i == chosen,
                reason,
            }
        })
        .collect();
    let total_evals: usize = model_trials.iter().map(|t| t.model_evaluations).sum();
    let cf = fits.swap_remove(chosen);
    let problem = &cf.problem;
    let best_params = problem.params_at(&cf.best_u);
    let best_sim = problem.simulate(&best_params)?;
    let model = problem.model_features(&best_sim)?;
    let cost = problem.total_cost(&best_sim)?;

    let parameters: Vec<FittedParam> = cf
        .free
        .iter()
        .zip(&cf.best_u)
        .zip(&cf.sigma_u)
        .map(|((fp, u), su)| {
            let value = fp.value(*u);
            let truth = job.truth.get(&fp.name).copied();
            FittedParam {
                name: fp.name,
                value,
                lower: fp.lower,
                upper: fp.upper,
                std_error: su * fp.slope(*u),
                determined: su.is_finite() && *su < 0.1,
                true_value: truth,
                rel_error: truth.map(|t| (value - t) / t),
                interval: None,
            }
        })
        .collect();
    let peaks = problem
        .measured
        .bands
        .iter()
        .zip(&model.bands)
        .enumerate()
        .map(|(i, (d, m))| {
            let (pd, pm) = (d.peak, m.peak);
            let fm = pm.map(|p| p.freq_hz).unwrap_or(f64::NAN);
            let range = problem.targets.as_ref().map(|t| t[i]);
            // Against a target range: the nearest edge (the model's own peak when inside).
            let fd = match range {
                Some(r) if fm.is_finite() => fm.clamp(r[0], r[1]),
                Some(r) => (r[0] * r[1]).sqrt(),
                None => pd.map(|p| p.freq_hz).unwrap_or(f64::NAN),
            };
            PeakComparison {
                target_range_hz: range.filter(|r| r[0] < r[1]),
                band: d.spec.name.clone(),
                measured_hz: fd,
                model_hz: fm,
                rel_diff: (fm - fd) / fd,
                measured_level: pd.map(|p| p.level).unwrap_or(f64::NAN),
                model_level: pm.map(|p| p.level).unwrap_or(f64::NAN),
            }
        })
        .collect();
    let mut peaks: Vec<PeakComparison> = peaks;
    for o in &problem.others {
        let p = o.params_at(&cf.best_u);
        let f = o.simulate(&p).and_then(|sim| o.model_features(&sim))?;
        for (d, m) in o.measured.bands.iter().zip(&f.bands) {
            let fd = d.peak.map(|p| p.freq_hz).unwrap_or(f64::NAN);
            let fm = m.peak.map(|p| p.freq_hz).unwrap_or(f64::NAN);
            peaks.push(PeakComparison {
                band: format!("{}:{}", o.label, d.spec.name),
                measured_hz: fd,
                model_hz: fm,
                rel_diff: (fm - fd) / fd,
                measured_level: d.peak.map(|p| p.level).unwrap_or(f64::NAN),
                model_level: m.peak.map(|p| p.level).unwrap_or(f64::NAN),
                target_range_hz: None,
            });
        }
    }
    let mut parameters = parameters;
    let mut warnings = Vec::new();
    if fit.uncertainty.bootstrap > 0 && problem.targets.is_some() {
        warnings.push(
            "no bootstrap intervals for a target job: targets carry no measurement noise".into(),
        );
    } else if fit.uncertainty.bootstrap > 0 {
        if let Some(pb) = &pb {
            pb.set_message("bootstrap");
        }
        let intervals = bootstrap_intervals(problem, &cf.best_u, &best_sim, fit)?;
        for (p, iv) in parameters.iter_mut().zip(intervals) {
            p.interval = Some(iv);
        }
    }
    let undetermined: Vec<ParamId> = parameters
        .iter()
        .filter(|p| !p.determined)
        .map(|p| p.name)
        .collect();
    if let Some(pb) = &pb {
        pb.finish_and_clear();
    }
    warnings.extend(identifiability_warnings(&parameters, &cf.corr, &cf.best_u));
    let evaluations = problem.evaluations.load(Ordering::Relaxed);
    let failures = problem.failures.load(Ordering::Relaxed)
        + problem
            .others
            .iter()
            .map(|o| o.failures.load(Ordering::Relaxed))
            .sum::<usize>();
    if failures * 10 > evaluations {
        warnings.push(format!(
            "{failures} of {evaluations} model evaluations failed (first: {}); the bounds reach parameter sets the model cannot simulate",
            problem
                .first_failure
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .clone()
                .unwrap_or_default()
        ));
    }
    let result = FitResult {
        job: job.name.clone(),
        recording: job.recording_path.display().to_string(),
        wiperlab_version: env!("CARGO_PKG_VERSION").into(),
        model: cf.candidate,
        cost,
        parameters,
        peaks,
        undetermined,
        correlation: cf.corr.clone(),
        swarm_iterations: cf.swarm_iters,
        polish_iterations: cf.polish_iters,
        model_evaluations: total_evals,
        failed_evaluations: failures,
        first_failure: problem
            .first_failure
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone(),
        wall_time_s: started.elapsed().as_secs_f64(),
        threads: rayon::current_num_threads(),
        solver_rtol: job.job.solver.rtol,
        solver_atol: job.job.solver.atol,
        transitions_in_best_model: best_sim.transitions.len(),
        model_trials,
        warnings,
        input_sha256,
        settings,
        target_job: job.job.targets.is_some(),
        spectrum: Some(job.job.spectrum.clone()),
        fit_settings: Some(job.job.fit.clone()),
        fitted_at: Some(jiff::Timestamp::now()),
        data_files: Vec::new(),
        history: cf.history.clone(),
    };
    Ok(FitOutcome {
        result,
        measured_trace: meas.trace,
        measured: meas.measured,
        model,
        best_sim,
        best_params,
        fs_hz,
        signal,
    })
}

/// Confidence intervals (68.27 %, i.e. ±1σ-equivalent) for every freed parameter by a parametric
/// bootstrap (Efron & Tibshirani 1993, *An Introduction to the Bootstrap*, ch. 6 and 13):
///
/// 1. the best-fit model's signal, with the measurement's NaN mask, is the noiseless reference;
///    in a joint fit each recording has its own (the model at the fitted parameters with that
///    recording's drive);
/// 2. each recording's white noise is estimated from the noise floor `P` of its last band
///    ([`features::noise_floor`]; a one-sided density of white noise of variance σ² is `2σ²/fs`, so
///    `σ = √(P·fs/2)`);
/// 3. each replicate adds fresh Gaussian noise of that σ to every recording, recomputes the measured
///    features, and re-runs the estimator: the whole fit (its restarts of swarm and polish,
///    `full_refit = true`) or only a
///    Nelder–Mead polish from the optimum (cheaper, but blind to the swarm's own scatter, so the
///    intervals come out too narrow: README, "Uncertainty"); replicates run in parallel with rayon;
/// 4. the interval is the basic bootstrap interval `[2θ̂ − q(84.13 %), 2θ̂ − q(15.87 %)]` of the
///    replicates' estimates `θ*` (Davison & Hinkley 1997, eq. 5.6), which corrects the replicates' bias.
///
/// What it covers: the spread from tracking noise and spectral estimation. What it does not: the
/// optimiser ending in a different local minimum of the (rough) stick–slip cost surface, which can
/// be larger (README, "Uncertainty").
///
/// # Errors
/// [`Error::Fit`] when argmin fails; simulation failures inside replicates count as failed
/// evaluations like in the fit.
pub fn bootstrap_intervals(
    problem: &SpectralProblem,
    best_u: &[f64],
    best_sim: &BladeSimulation,
    fit: &job::FitSection,
) -> Result<Vec<Interval>> {
    let settings = &fit.uncertainty;
    use rayon::prelude::*;
    // The noiseless reference and noise level of every recording: the main one, then those of a
    // joint fit, each simulated at the fit's parameters with its own drive.
    let mut references = vec![ReplicateSource::new(problem, best_sim)?];
    for o in &problem.others {
        let sim = o.simulate(&o.params_at(best_u))?;
        references.push(ReplicateSource::new(o, &sim)?);
    }
    let n = best_u.len();
    let estimates: Vec<Result<Vec<f64>>> = (0..settings.bootstrap)
        .into_par_iter()
        .map(|r| {
            let mut rng = rand::rngs::StdRng::seed_from_u64(settings.seed.wrapping_add(r as u64));
            let mut rep = references[0].replicate(problem, &mut rng)?;
            for (o, src) in problem.others.iter().zip(&references[1..]) {
                rep.others.push(src.replicate(o, &mut rng)?);
            }
            let rep = Arc::new(rep);
            let u = if settings.full_refit {
                optimise(&rep, fit, fit.seed.wrapping_add(1 + r as u64), None, None)?.0
            } else {
                polish(&rep, best_u, 0.05, settings.polish_iterations, None)?.0
            };
            Ok(problem
                .free
                .iter()
                .zip(&u)
                .map(|(fp, ui)| fp.value(*ui))
                .collect())
        })
        .collect();
    let estimates: Vec<Vec<f64>> = estimates.into_iter().collect::<Result<_>>()?;
    let b = estimates.len();
    Ok((0..n)
        .map(|i| {
            let mut v: Vec<f64> = estimates.iter().map(|e| e[i]).collect();
            v.sort_by(|a, b| a.total_cmp(b));
            // Basic (reverse-percentile) interval: θ* − θ̂ stands in for θ̂ − θ, which corrects the
            // bias the replicates show (Davison & Hinkley 1997, *Bootstrap Methods*, eq. 5.6).
            let est = problem.free[i].value(best_u[i]);
            Interval {
                lo: 2.0 * est - quantile_sorted(&v, 0.841_345),
                hi: 2.0 * est - quantile_sorted(&v, 0.158_655),
                level: 0.6827,
                method: IntervalMethod::Bootstrap {
                    replicates: b,
                    noise_sigma_m: references.iter().map(|r| r.sigma).collect(),
                    full_refit: settings.full_refit,
                },
            }
        })
        .collect())
}

/// One recording's side of a bootstrap replicate: the best-fit model's signal (NaN where the
/// measurement is) and the white-noise level estimated from the measurement's floor.
struct ReplicateSource {
    x_model: Vec<f64>,
    sigma: f64,
    normal: rand_distr::Normal<f64>,
}

impl ReplicateSource {
    fn new(problem: &SpectralProblem, best_sim: &BladeSimulation) -> Result<Self> {
        let mut x_model = problem.signal.extract(&best_sim.to_trace())?;
        for (xi, m) in x_model.iter_mut().zip(&problem.nan_mask) {
            if *m {
                *xi = f64::NAN;
            }
        }
        let floor = problem.floors.last().copied().unwrap_or(0.0);
        let sigma = (floor * problem.fs_hz / 2.0).sqrt();
        if !(sigma.is_finite() && sigma > 0.0) {
            return Err(Error::Fit(format!(
                "bootstrap: cannot estimate the measurement noise{} (floor {floor:e}); no intervals",
                if problem.label.is_empty() {
                    String::new()
                } else {
                    format!(" of recording '{}'", problem.label)
                }
            )));
        }
        let normal = rand_distr::Normal::new(0.0, sigma).map_err(|e| Error::Fit(e.to_string()))?;
        Ok(ReplicateSource {
            x_model,
            sigma,
            normal,
        })
    }

    /// `problem` with its measurement replaced by the model signal plus fresh noise (no joint
    /// recordings attached; the caller adds their replicates).
    fn replicate(
        &self,
        problem: &SpectralProblem,
        rng: &mut rand::rngs::StdRng,
    ) -> Result<SpectralProblem> {
        use rand_distr::Distribution;
        let x: Vec<f64> = self
            .x_model
            .iter()
            .map(|v| v + self.normal.sample(rng))
            .collect();
        let measured = features(&x, problem.fs_hz, &problem.bands, problem.max_fill)?;
        let floors: Vec<f64> = measured.bands.iter().map(noise_floor).collect();
        Ok(SpectralProblem {
            model: problem.model,
            head: problem.head.clone(),
            targets: problem.targets.clone(),
            // The time-domain targets stay the recording's (they are not re-noised).
            time_targets: problem.time_targets.clone(),
            others: Vec::new(),
            label: problem.label.clone(),
            base: problem.base,
            free: problem.free.clone(),
            measured,
            floors,
            bands: problem.bands.clone(),
            signal: problem.signal,
            sample_times: problem.sample_times.clone(),
            nan_mask: problem.nan_mask.clone(),
            fs_hz: problem.fs_hz,
            max_fill: problem.max_fill,
            window: problem.window,
            solver: problem.solver,
            swarm_solver: problem.swarm_solver,
            weights: problem.weights,
            evaluations: problem.evaluations.clone(),
            failures: AtomicUsize::new(0),
            first_failure: Mutex::new(None),
            progress: problem.progress.clone(),
        })
    }
}

/// Warnings naming what the data do not determine: parameters whose 1σ (from the curvature) spans
/// ≥ 10 % of their search range, pairs correlated beyond ±0.95 (they trade off), and parameters that
/// ended on a bound.
pub fn identifiability_warnings(
    params: &[FittedParam],
    corr: &[Vec<f64>],
    best_u: &[f64],
) -> Vec<String> {
    let mut w = Vec::new();
    for p in params.iter().filter(|p| !p.determined) {
        w.push(format!(
            "{} is not determined by the data: its 1σ spans 10 % or more of its search range",
            p.name
        ));
    }
    for i in 0..params.len() {
        for j in (i + 1)..params.len() {
            let r = corr
                .get(i)
                .and_then(|row| row.get(j))
                .copied()
                .unwrap_or(f64::NAN);
            if r.abs() > 0.95 {
                w.push(format!(
                    "{} and {} trade off (correlation {r:+.3}): the data pin down a combination of them, not each",
                    params[i].name, params[j].name
                ));
            }
        }
    }
    for (p, u) in params.iter().zip(best_u) {
        if *u <= 0.005 || *u >= 0.995 {
            w.push(format!(
                "{} ended on its {} bound ({}); widen the bound or fix the parameter",
                p.name,
                if *u <= 0.005 { "lower" } else { "upper" },
                p.value
            ));
        }
    }
    w
}

/// Finite-difference curvature of the cost at `u0` (step 0.03 in normalised units, stencil kept
/// inside the box). Returns the 1σ half-widths in normalised units from the
/// covariance `2 H⁻¹` (cost read as χ²), and the correlation matrix.
fn curvature(problem: &SpectralProblem, u0: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
    use rayon::prelude::*;
    let n = u0.len();
    let d = 0.03;
    let centre: Vec<f64> = u0.iter().map(|u| u.clamp(d, 1.0 - d)).collect();
    let mut points: Vec<(usize, usize, f64, f64)> = vec![(usize::MAX, usize::MAX, 0.0, 0.0)];
    for i in 0..n {
        points.push((i, usize::MAX, d, 0.0));
        points.push((i, usize::MAX, -d, 0.0));
        for j in (i + 1)..n {
            for (si, sj) in [(d, d), (d, -d), (-d, d), (-d, -d)] {
                points.push((i, j, si, sj));
            }
        }
    }
    let costs: Vec<f64> = points
        .par_iter()
        .map(|&(i, j, si, sj)| {
            let mut u = centre.clone();
            if i != usize::MAX {
                u[i] += si;
            }
            if j != usize::MAX {
                u[j] += sj;
            }
            problem.cost_at(&u)
        })
        .collect();
    let f0 = costs[0];
    let mut h = nalgebra::DMatrix::<f64>::zeros(n, n);
    let mut k = 1;
    for i in 0..n {
        let (fp, fm) = (costs[k], costs[k + 1]);
        k += 2;
        h[(i, i)] = (fp - 2.0 * f0 + fm) / (d * d);
        for j in (i + 1)..n {
            let v = (costs[k] - costs[k + 1] - costs[k + 2] + costs[k + 3]) / (4.0 * d * d);
            k += 4;
            h[(i, j)] = v;
            h[(j, i)] = v;
        }
    }
    match h.clone().cholesky() {
        Some(ch) => {
            let cov = ch.inverse() * 2.0;
            let sig: Vec<f64> = (0..n).map(|i| cov[(i, i)].sqrt()).collect();
            let corr = (0..n)
                .map(|i| (0..n).map(|j| cov[(i, j)] / (sig[i] * sig[j])).collect())
                .collect();
            (sig, corr)
        }
        None => {
            let sig = (0..n)
                .map(|i| {
                    if h[(i, i)] > 0.0 {
                        (2.0 / h[(i, i)]).sqrt()
                    } else {
                        f64::INFINITY
                    }
                })
                .collect();
            (sig, vec![vec![f64::NAN; n]; n])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn band(name: &str, lo: f64, hi: f64) -> BandSpec {
        BandSpec {
            name: name.into(),
            range_hz: [lo, hi],
            nperseg: 1024,
        }
    }

    /// The default chain: the head model for low bands only, the full blade as soon as a band
    /// needs the neck–lip mode; the neck/lip model only when named.
    #[test]
    fn smallest_capable_model_follows_the_bands() {
        let low = band("low", 30.0, 300.0);
        let high = band("high", 500.0, 5000.0);
        assert_eq!(
            smallest_capable_model(std::slice::from_ref(&low)),
            ModelKind::Head1dof
        );
        assert_eq!(
            smallest_capable_model(std::slice::from_ref(&high)),
            ModelKind::Blade2dof
        );
        assert_eq!(
            smallest_capable_model(&[low.clone(), high]),
            ModelKind::Blade2dof
        );
        // The neck/lip model imposes a low band, so it cannot produce one.
        let nl = "necklip+shoulder".parse::<Candidate>().unwrap();
        assert!(nl.shoulder && nl.kind == ModelKind::Necklip);
        assert!(nl.cannot_produce(&[low]).is_some());
    }

    /// `[fit] swarm_rtol`: the swarm stage simulates at its own tolerance (atol scaled alike),
    /// while `cost_at` (polish, curvature, reports) keeps `[solver]`'s; they give different costs
    /// at the same point, and without the key both stages are the same.
    #[test]
    fn swarm_stage_uses_its_own_tolerance() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(root.join("fits/reversal.toml")).unwrap();
        let dir = std::env::temp_dir().join(format!("wiperlab_swarm_rtol_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // The job's `../data/...` paths made absolute, so that a copy works from a temp dir.
        let text = text.replace("\"../data/", &format!("\"{}/", root.join("data").display()));
        let strip = |t: &str| {
            t.lines()
                .filter(|l| !l.trim_start().starts_with("swarm_rtol"))
                .collect::<Vec<_>>()
                .join("\n")
        };
        let with = strip(&text).replace("restarts = 5", "restarts = 5\nswarm_rtol = 1e-5");
        let without = strip(&text);
        let load = |name: &str, t: &str| {
            let path = dir.join(name);
            std::fs::write(&path, t).unwrap();
            LoadedJob::load(&path).unwrap()
        };
        let p = problem_for(&load("with.toml", &with), "blade2dof".parse().unwrap()).unwrap();
        assert_eq!(p.solver.rtol, 1e-8);
        assert_eq!(p.swarm_solver.rtol, 1e-5);
        assert!(
            (p.swarm_solver.atol / 1e-7 - 1.0).abs() < 1e-12,
            "{}",
            p.swarm_solver.atol
        );
        // At the sample's true parameters (data/reversal/truth.json), where the model runs.
        let truth = [
            ("A", 0.88),
            ("B", 69.74712740275162),
            ("C", 0.56),
            ("k1", 0.029748408887917077),
        ];
        let u: Vec<f64> = p
            .free
            .iter()
            .map(|f| f.u_of(truth.iter().find(|t| f.name == t.0).unwrap().1))
            .collect();
        let (polish, swarm) = (p.cost_at(&u), p.cost_at_stage(&u, SearchStage::Swarm));
        assert!(polish < 1.0 && swarm < 1.0, "{polish}, {swarm}");
        assert_ne!(
            polish, swarm,
            "rtol 1e-5 and 1e-8 should not give the same cost"
        );
        let q = problem_for(
            &load("without.toml", &without),
            "blade2dof".parse().unwrap(),
        )
        .unwrap();
        assert_eq!(q.swarm_solver.rtol, q.solver.rtol);
        assert_eq!(q.cost_at(&u), q.cost_at_stage(&u, SearchStage::Swarm));
        std::fs::remove_dir_all(&dir).ok();
    }
}
