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

use crate::model::BladeParams;
use crate::model::blade::StickForm;
use crate::simulate::SolverOptions;
use crate::simulate::blade::{BladeSimulation, simulate_blade};
use crate::trace::Trace;
use crate::{Error, Result};
use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{CostFunction, Executor, KV, State};
use argmin::solver::neldermead::NelderMead;
use argmin::solver::particleswarm::ParticleSwarm;
use features::{BandSpec, Features, SignalKind, features, noise_floor};
use job::{LoadedJob, Weights, set_param};
use rand::SeedableRng;
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Cost assigned to a parameter set whose simulation fails (contact loss, Painlevé, ...). Failures
/// are counted and the first message is reported; they are never silent.
pub const FAILED_COST: f64 = 1e9;

/// One freed parameter: name, bounds, and whether it is searched on a log scale.
#[derive(Debug, Clone, Serialize)]
pub struct FreeParam {
    pub name: String,
    pub lower: f64,
    pub upper: f64,
    pub log: bool,
}

impl FreeParam {
    fn new(name: &str, lower: f64, upper: f64) -> Self {
        FreeParam {
            name: name.into(),
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
    pub weights: Weights,
    /// Optional frequency-against-speed and trace-error terms (`None` when their weights are 0).
    pub time_targets: Option<instfreq::TimeTargets>,
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
            set_param(&mut p, &fp.name, fp.value(*ui));
        }
        p
    }

    /// Simulates the model at `params`, sampled at the recording's times.
    pub fn simulate(&self, params: &BladeParams) -> Result<BladeSimulation> {
        simulate_blade(
            params,
            self.window,
            &self.sample_times,
            &self.solver,
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
        let outside: f64 = u
            .iter()
            .map(|x| (x - x.clamp(0.0, 1.0)).powi(2))
            .sum::<f64>();
        let p = self.params_at(u);
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        if let Some(pb) = &self.progress {
            pb.inc(1);
        }
        let c = match self.simulate(&p).and_then(|s| self.total_cost(&s)) {
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
        c + 1e4 * outside
    }
}

/// Best cost after each iteration of each stage.
#[derive(Debug, Clone, Serialize)]
pub struct HistoryPoint {
    pub stage: String,
    pub iteration: u64,
    pub best_cost: f64,
    pub evaluations: usize,
}

struct HistoryObserver {
    stage: &'static str,
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
                stage: self.stage.into(),
                iteration: state.get_iter(),
                best_cost: state.get_best_cost(),
                evaluations: self.evals.load(Ordering::Relaxed),
            });
        Ok(())
    }
}

/// A fitted parameter with its uncertainty and, for synthetic data, the truth.
#[derive(Debug, Clone, Serialize)]
pub struct FittedParam {
    pub name: String,
    pub value: f64,
    pub lower: f64,
    pub upper: f64,
    /// 1σ from the cost's curvature (cost read as χ² with the module's scales); indicative.
    pub std_error: f64,
    /// False when the data do not pin the parameter down (1σ wider than 10 % of its search range,
    /// or no positive curvature).
    pub determined: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub true_value: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rel_error: Option<f64>,
}

/// Measured against model peak in one band.
#[derive(Debug, Clone, Serialize)]
pub struct PeakComparison {
    pub band: String,
    pub measured_hz: f64,
    pub model_hz: f64,
    /// (model − measured)/measured.
    pub rel_diff: f64,
    pub measured_level: f64,
    pub model_level: f64,
}

/// Everything a fit reports; written as `fits/<job>.result.toml` and, with `--json`, to stdout.
#[derive(Debug, Clone, Serialize)]
pub struct FitResult {
    pub job: String,
    pub recording: String,
    pub wiperlab_version: String,
    pub cost: f64,
    pub parameters: Vec<FittedParam>,
    pub peaks: Vec<PeakComparison>,
    /// Names of parameters the data leave undetermined.
    pub undetermined: Vec<String>,
    /// Correlation matrix of the freed parameters (row-major, order of `parameters`); NaN where the
    /// curvature matrix is not positive definite.
    pub correlation: Vec<Vec<f64>>,
    pub swarm_iterations: u64,
    pub polish_iterations: u64,
    pub model_evaluations: usize,
    pub failed_evaluations: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_failure: Option<String>,
    pub wall_time_s: f64,
    pub threads: usize,
    pub solver_rtol: f64,
    pub solver_atol: f64,
    pub transitions_in_best_model: usize,
    pub history: Vec<HistoryPoint>,
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

/// The problem as argmin sees it: shared by the swarm's threads and both stages.
#[derive(Clone)]
struct Shared(Arc<SpectralProblem>);

impl CostFunction for Shared {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, u: &Self::Param) -> std::result::Result<f64, argmin::core::Error> {
        Ok(self.0.cost_at(u))
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

/// Runs the job: import, measured features, particle swarm, Nelder–Mead, curvature, best model.
///
/// `progress`: show a progress bar on stderr (hidden automatically when stderr is not a terminal).
pub fn run_fit(job: &LoadedJob, progress: bool) -> Result<FitOutcome> {
    let started = std::time::Instant::now();
    let spec = &job.job.recording.import;
    let trace = crate::import::read_trace(&job.recording_path, spec)?;
    let fs_hz = sampling_rate(&trace, spec.fps_hz)?;
    let signal = job.job.spectrum.signal;
    let x = signal.extract(&trace)?;
    let bands = job.job.spectrum.bands.clone();
    let max_fill = job.job.spectrum.max_fill;
    let measured = features(&x, fs_hz, &bands, max_fill)?;
    for b in &measured.bands {
        if b.peak.is_none() {
            return Err(Error::input(
                &job.recording_path,
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
    let free: Vec<FreeParam> = job
        .free
        .iter()
        .map(|(n, lo, hi)| FreeParam::new(n, *lo, *hi))
        .collect();
    let n = free.len();
    let fit = &job.job.fit;
    let hess_evals = 1 + 2 * n + 2 * n * n.saturating_sub(1);
    let budget = fit.particles as u64 * (fit.swarm_iterations + 1)
        + (n as u64 + 1)
        + 2 * fit.polish_iterations
        + hess_evals as u64;
    let pb = if progress {
        let pb = indicatif::ProgressBar::new(budget);
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg:12} [{bar:32}] {pos}/{len} model runs, {elapsed} (eta {eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        pb.set_message("swarm");
        Some(pb)
    } else {
        None
    };
    let evaluations = Arc::new(AtomicUsize::new(0));
    let problem = Arc::new(SpectralProblem {
        base: job.blade,
        free: free.clone(),
        measured,
        floors,
        bands,
        signal,
        nan_mask: x.iter().map(|v| !v.is_finite()).collect(),
        sample_times: trace.t_s.clone(),
        fs_hz,
        max_fill,
        window: (trace.t_s[0], *trace.t_s.last().unwrap_or(&trace.t_s[0])),
        solver: job.job.solver,
        weights: fit.weights,
        time_targets: instfreq::TimeTargets::for_job(&fit.weights, &trace, &x, fs_hz, signal)?,
        evaluations: evaluations.clone(),
        failures: AtomicUsize::new(0),
        first_failure: Mutex::new(None),
        progress: pb.clone(),
    });
    let history = Arc::new(Mutex::new(Vec::new()));
    let fit_err = |e: argmin::core::Error| Error::Fit(e.to_string());

    // Stage 1: particle swarm over [0, 1]^n.
    let pso = ParticleSwarm::new((vec![0.0; n], vec![1.0; n]), fit.particles)
        .with_rng_generator(rand::rngs::StdRng::seed_from_u64(fit.seed));
    let res = Executor::new(Shared(problem.clone()), pso)
        .configure(|s| s.max_iters(fit.swarm_iterations))
        .add_observer(
            HistoryObserver {
                stage: "swarm",
                log: history.clone(),
                evals: evaluations.clone(),
            },
            ObserverMode::Always,
        )
        .run()
        .map_err(fit_err)?;
    let swarm_best = res
        .state()
        .get_best_param()
        .map(|p| p.position.clone())
        .ok_or_else(|| Error::Fit("particle swarm returned no particle".into()))?;
    let swarm_iters = res.state().get_iter();

    // Stage 2: Nelder–Mead polish from the best particle.
    if let Some(pb) = &pb {
        pb.set_message("polish");
    }
    let mut simplex = vec![swarm_best.clone()];
    for i in 0..n {
        let mut v = swarm_best.clone();
        v[i] = if v[i] + 0.05 <= 1.0 {
            v[i] + 0.05
        } else {
            v[i] - 0.05
        };
        simplex.push(v);
    }
    let nm = NelderMead::new(simplex)
        .with_sd_tolerance(1e-3)
        .map_err(fit_err)?;
    let res = Executor::new(Shared(problem.clone()), nm)
        .configure(|s| s.max_iters(fit.polish_iterations))
        .add_observer(
            HistoryObserver {
                stage: "polish",
                log: history.clone(),
                evals: evaluations.clone(),
            },
            ObserverMode::Always,
        )
        .run()
        .map_err(fit_err)?;
    let best_u: Vec<f64> = res
        .state()
        .get_best_param()
        .cloned()
        .unwrap_or(swarm_best)
        .iter()
        .map(|u| u.clamp(0.0, 1.0))
        .collect();
    let polish_iters = res.state().get_iter();

    // Curvature of the cost at the optimum → standard errors, correlations, identifiability.
    if let Some(pb) = &pb {
        pb.set_message("curvature");
    }
    let (sigma_u, corr) = curvature(&problem, &best_u);

    if let Some(pb) = &pb {
        pb.finish_and_clear();
    }
    let best_params = problem.params_at(&best_u);
    let best_sim = problem.simulate(&best_params)?;
    let model = problem.model_features(&best_sim)?;
    let cost = problem.total_cost(&best_sim)?;

    let parameters: Vec<FittedParam> = free
        .iter()
        .zip(&best_u)
        .zip(&sigma_u)
        .map(|((fp, u), su)| {
            let value = fp.value(*u);
            let truth = job.truth.get(&fp.name).copied();
            FittedParam {
                name: fp.name.clone(),
                value,
                lower: fp.lower,
                upper: fp.upper,
                std_error: su * fp.slope(*u),
                determined: su.is_finite() && *su < 0.1,
                true_value: truth,
                rel_error: truth.map(|t| (value - t) / t),
            }
        })
        .collect();
    let peaks = problem
        .measured
        .bands
        .iter()
        .zip(&model.bands)
        .map(|(d, m)| {
            let (pd, pm) = (d.peak, m.peak);
            let fd = pd.map(|p| p.freq_hz).unwrap_or(f64::NAN);
            let fm = pm.map(|p| p.freq_hz).unwrap_or(f64::NAN);
            PeakComparison {
                band: d.spec.name.clone(),
                measured_hz: fd,
                model_hz: fm,
                rel_diff: (fm - fd) / fd,
                measured_level: pd.map(|p| p.level).unwrap_or(f64::NAN),
                model_level: pm.map(|p| p.level).unwrap_or(f64::NAN),
            }
        })
        .collect();
    let undetermined = parameters
        .iter()
        .filter(|p| !p.determined)
        .map(|p| p.name.clone())
        .collect();
    let result = FitResult {
        job: job.name.clone(),
        recording: job.recording_path.display().to_string(),
        wiperlab_version: env!("CARGO_PKG_VERSION").into(),
        cost,
        parameters,
        peaks,
        undetermined,
        correlation: corr,
        swarm_iterations: swarm_iters,
        polish_iterations: polish_iters,
        model_evaluations: problem.evaluations.load(Ordering::Relaxed),
        failed_evaluations: problem.failures.load(Ordering::Relaxed),
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
        history: history.lock().unwrap_or_else(|e| e.into_inner()).clone(),
    };
    Ok(FitOutcome {
        result,
        measured_trace: trace,
        measured: Features {
            bands: problem.measured.bands.clone(),
            filled: problem.measured.filled,
        },
        model,
        best_sim,
        best_params,
        fs_hz,
        signal,
    })
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
