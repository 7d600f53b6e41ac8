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
        for ((d, m), floor) in self.measured.bands.iter().zip(&model.bands).zip(&self.floors) {
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
        let c = match self.simulate(&p).and_then(|s| self.model_features(&s)) {
            Ok(f) => self.cost_of(&f),
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

impl CostFunction for SpectralProblem {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, u: &Self::Param) -> std::result::Result<f64, argmin::core::Error> {
        Ok(self.cost_at(u))
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
    fn observe_iter(&mut self, state: &I, _kv: &KV) -> std::result::Result<(), argmin::core::Error> {
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
