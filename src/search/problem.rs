//! The fit's cost problem: everything one cost evaluation needs ([`SpectralProblem`]), as argmin
//! sees it ([`Shared`]).

use super::history::SearchStage;
use crate::Result;
use crate::job::{FreeParam, Objective, Weights};
use crate::likelihood::instfreq;
use crate::model::BladeParams;
use crate::model::blade::StickForm;
use crate::simulate::SolverOptions;
use crate::simulate::blade::{BladeSimulation, ModelKind, simulate_model};
use crate::spectrum::features::{BandSpec, Features, SignalKind, features};
use argmin::core::CostFunction;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use crate::simulate::failure::FailureCause;

/// Cost assigned to a parameter set whose simulation fails (contact loss, Painlevé, ...). Failures
/// are counted and the first message is reported; they are never silent.
pub const FAILED_COST: f64 = 1e9;

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
    /// Per band, whether the measured band has a line above its noise
    /// ([`crate::likelihood::band_has_line`]); [`SpectralProblem::cost_of`] compares peak
    /// frequencies only where it has.
    pub lines: Vec<bool>,
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
    /// The solver of the local CMA-ES stage (`[fit.search] local_rtol`; else `solver`).
    pub local_solver: SolverOptions,
    /// What the particle swarm ranks by under the likelihood objective (`[fit.search] swarm_cost`).
    pub swarm_cost: crate::job::SwarmCost,
    /// What [`SpectralProblem::total_cost`] is: the likelihood or the weighted features.
    pub objective: Objective,
    pub weights: Weights,
    /// Optional frequency-against-speed and trace-error terms (`None` when their weights are 0).
    pub time_targets: Option<instfreq::TimeTargets>,
    /// Further recordings fitted jointly (`[[more_recordings]]`): each is a problem of its own
    /// (its measurement, drive and base), sharing `free`; their costs add to this one's.
    pub others: Vec<SpectralProblem>,
    /// Name of this problem's recording in joint fits ("" for the main one).
    pub label: String,
    /// The recording's likelihood ([`super::evidence`]), for model choice and intervals; why not,
    /// for a target job or a recording it cannot be computed for.
    pub likelihood:
        std::result::Result<Arc<super::evidence::RecordingLikelihood>, super::NoLikelihood>,
    /// The measured signal's own likelihood when `likelihood` also reads further signals
    /// (`[fit.likelihood] joint_signals`): the cost of [`SearchStage::SignalLocal`], a second
    /// local run beside the joint one (docs/fit.md, "The local CMA-ES stage").
    pub signal_likelihood: Option<Arc<super::evidence::RecordingLikelihood>>,
    pub evaluations: Arc<AtomicUsize>,
    /// Failed evaluations, shared like `evaluations` with the bootstrap's replicate problems.
    pub failures: Arc<AtomicUsize>,
    /// Failed evaluations by cause, shared like `failures`.
    pub failure_causes: Arc<Mutex<BTreeMap<FailureCause, usize>>>,
    pub first_failure: Mutex<Option<String>>,
    /// The polish-stage evaluations found about as likely as the best one
    /// ([`EvaluatedNearBest`]), which the intervals read.
    pub near_best: Mutex<EvaluatedNearBest>,
    /// The last cost-jitter check and the point it was made at
    /// ([`super::jitter::RoundingJitter::at`]): the tolerance check and the profile walk read the
    /// same optimum's.
    pub last_jitter: Mutex<Option<(Vec<f64>, Option<super::jitter::RoundingJitter>)>>,
    /// `[fit.priors]`' terms that read this candidate's freed parameters (empty: flat; a joint
    /// fit's other recordings have none, the main one carries them once).
    pub prior: Arc<crate::likelihood::prior::Prior>,
}

/// How far above the lowest cost seen (nats) [`EvaluatedNearBest`] keeps a point: above the
/// profile rise limits the intervals use (0.5 nats times σ²_sandwich/σ²_Fisher,
/// [`crate::uncertainty::intervals::profile_rise_limit`]) for a sandwich up to twice the Fisher 1σ.
pub const NEAR_BEST_MARGIN_NATS: f64 = 2.0;

/// The points a problem's search evaluated at the polish's tolerance, inside the search box, with a
/// cost within [`NEAR_BEST_MARGIN_NATS`] of the lowest seen: with the likelihood objective, points
/// the recording's likelihood found about as likely as the best. Each simulation the search runs
/// is a sample of the likelihood; those near the best one outline the region it leaves open, which
/// a curvature at the fit can miss where the likelihood is flat or bent
/// ([`crate::uncertainty::intervals::widen_to_near_best`]).
#[derive(Debug, Clone)]
pub struct EvaluatedNearBest {
    lowest: f64,
    /// `(cost, u)`: cost in nats, `u` the problem's normalised coordinates.
    points: Vec<(f64, Vec<f64>)>,
    /// The number of points after the last pruning (pruned again when it doubles).
    kept: usize,
}

impl Default for EvaluatedNearBest {
    fn default() -> Self {
        EvaluatedNearBest {
            lowest: f64::INFINITY,
            points: Vec::new(),
            kept: 0,
        }
    }
}

impl EvaluatedNearBest {
    /// Keeps `(u, cost)` when the cost is finite and within the margin of the lowest seen; the
    /// points left behind by a lower one are dropped each time the list doubles.
    pub fn record(&mut self, u: &[f64], cost: f64) {
        if !cost.is_finite() {
            return;
        }
        self.lowest = self.lowest.min(cost);
        if cost > self.lowest + NEAR_BEST_MARGIN_NATS {
            return;
        }
        self.points.push((cost, u.to_vec()));
        if self.points.len() >= 2 * self.kept.max(64) {
            let limit = self.lowest + NEAR_BEST_MARGIN_NATS;
            self.points.retain(|p| p.0 <= limit);
            self.kept = self.points.len();
        }
    }

    /// The lowest cost recorded, nats (`+∞` when none).
    pub fn lowest(&self) -> f64 {
        self.lowest
    }

    /// The lowest recorded point when its cost is below `cost` (where a search that ended at
    /// `cost` plus a margin could go on from).
    pub fn lowest_point_below(&self, cost: f64) -> Option<&[f64]> {
        (self.lowest < cost)
            .then(|| self.at_most(self.lowest).next().map(|(_, u)| u))
            .flatten()
    }

    /// The recorded points whose cost is at most `cost`, as `(cost, u)`.
    pub fn at_most(&self, cost: f64) -> impl Iterator<Item = (f64, &[f64])> {
        self.points
            .iter()
            .filter(move |p| p.0 <= cost)
            .map(|p| (p.0, p.1.as_slice()))
    }
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

    /// Whether `p` is a shoulder that softens the neck (`k1_contact < k1`) in a fit that frees the
    /// contact stiffness. A shoulder is a stop the neck leans on: touching it adds stiffness, so the
    /// neck is stiffer beyond θ_c, never softer (physics.md §2.3: "a bilinear k1(θ) (soft, then
    /// stiff past the shoulder-contact angle)"; docs/model.md, "Shoulder contact"). Without this
    /// bound a misspecified recording (coloured tracking noise, a viscous friction term) is fitted
    /// by a softening neck the blade does not have and reported as a shoulder. `k1_contact = k1`, the
    /// shoulder that changes nothing, is allowed (to a relative 1e-9, the round trip of a value
    /// through another parameter's normalised coordinate): the nested candidates start there.
    pub(crate) fn softening_shoulder(&self, p: &BladeParams) -> bool {
        self.free
            .iter()
            .any(|f| f.name == crate::model::ParamId::K1c)
            && p.shoulder
                .is_some_and(|s| s.k1_contact_nm_per_rad < p.k1_nm_per_rad * (1.0 - 1e-9))
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
            let head = self
                .head
                .as_ref()
                .ok_or_else(|| super::FitError::NecklipNeedsHead)?;
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
        for (i, ((d, m), floor)) in self
            .measured
            .bands
            .iter()
            .zip(&model.bands)
            .zip(&self.floors)
            .enumerate()
        {
            match (d.peak, m.peak) {
                (Some(pd), Some(pm)) => {
                    // The frequency of a band's largest noise ordinate is no measured quantity: a
                    // band without a line compares levels and shape only.
                    let df = if self.lines.get(i).copied().unwrap_or(true) {
                        (pm.freq_hz / pd.freq_hz).ln() / 0.01
                    } else {
                        0.0
                    };
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

    /// The cost of a simulation: for a target job its [`target_cost`]; with the likelihood
    /// objective the recording's NLL above the saturated model's, nats
    /// ([`super::evidence::RecordingLikelihood::excess_nll`]); with the features objective the
    /// weighted feature cost ([`SpectralProblem::cost_of`]) plus the optional time-domain terms
    /// ([`instfreq::TimeTargets`]).
    ///
    /// # Errors
    /// The simulation's features' errors, and [`super::FitError::LikelihoodObjective`] when the likelihood objective has
    /// no likelihood (e.g. a median-averaged band, whose ordinates are not χ²).
    pub fn total_cost(&self, sim: &BladeSimulation) -> Result<f64> {
        self.stage_cost(sim, SearchStage::Polish)
    }

    /// The cost a search `stage` ranks a simulation by: [`SpectralProblem::total_cost`], except
    /// that with the likelihood objective and `[fit.search] swarm_cost = "features"` (the default)
    /// the particle swarm ranks by the feature cost ([`SpectralProblem::cost_of`], default
    /// weights). Its 1 %-scale peak-frequency term funnels the swarm into the lines' basin; the
    /// Whittle likelihood is flat along valleys a short recording leaves open (docs/fit.md, "How
    /// it works"), where the polish then finds its minimum.
    fn stage_cost(&self, sim: &BladeSimulation, stage: SearchStage) -> Result<f64> {
        let by_features =
            stage == SearchStage::Swarm && self.swarm_cost == crate::job::SwarmCost::Features;
        if self.objective == Objective::Likelihood && self.targets.is_none() && !by_features {
            let lik = self
                .likelihood
                .as_ref()
                .map_err(|why| super::FitError::LikelihoodObjective { why: why.clone() })?;
            let lik = match (&self.signal_likelihood, stage) {
                (Some(own), SearchStage::SignalLocal) => own,
                _ => lik,
            };
            return lik.excess_nll(self, sim);
        }
        let spectral = self.cost_of(&self.model_features(sim)?);
        Ok(match &self.time_targets {
            Some(t) => spectral + t.cost(sim)?,
            None => spectral,
        })
    }

    /// True when the polish's cost is the recording's NLL in nats (the likelihood objective, a
    /// recording with a likelihood, not a target job): cost differences are then log-likelihood
    /// ratios.
    pub fn cost_is_nll(&self) -> bool {
        self.objective == Objective::Likelihood && self.targets.is_none() && self.likelihood.is_ok()
    }

    /// The cost ([`SpectralProblem::total_cost`]) at normalised coordinates `u` simulated with
    /// `solver` instead of the job's, and the simulation's number of transitions; counted as a model
    /// evaluation (and a failed one on error). This recording only (a joint fit's others are not
    /// run).
    ///
    /// # Errors
    /// The simulation's and the cost's.
    pub fn cost_with_solver(&self, u: &[f64], solver: &SolverOptions) -> Result<(f64, usize)> {
        self.params_cost_with_solver(&self.params_at(u), solver)
    }

    /// [`SpectralProblem::cost_with_solver`] at the parameters `p` as given. A truth's values
    /// taken through the normalised coordinates and back differ from them in the last bits, which
    /// moves the cost by the likelihood's ripple (0.015 nats at the shipped recording's truth):
    /// price given values here.
    ///
    /// # Errors
    /// The simulation's and the cost's.
    pub fn params_cost_with_solver(
        &self,
        p: &BladeParams,
        solver: &SolverOptions,
    ) -> Result<(f64, usize)> {
        self.counted(|| {
            let s = self.simulate_with(p, solver)?;
            Ok((
                self.total_cost(&s)? + self.prior.nats(p),
                s.transitions.len(),
            ))
        })
    }

    /// `run`, one model evaluation: counted in `evaluations`, and on error in `failures` with
    /// the first failure's message kept.
    fn counted<T>(&self, run: impl FnOnce() -> Result<T>) -> Result<T> {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        run().inspect_err(|e| {
            self.failures.fetch_add(1, Ordering::Relaxed);
            *self
                .failure_causes
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .entry(FailureCause::of(e))
                .or_insert(0) += 1;
            let mut g = self.first_failure.lock().unwrap_or_else(|e| e.into_inner());
            if g.is_none() {
                *g = Some(e.to_string());
            }
        })
    }

    /// Cost at normalised coordinates, with a quadratic penalty outside the box.
    pub fn cost_at(&self, u: &[f64]) -> f64 {
        self.cost_at_stage(u, SearchStage::Polish)
    }

    /// [`SpectralProblem::cost_at`] with the simulations of `stage` (the swarm's may be coarser).
    ///
    /// With the likelihood as the cost, an evaluation inside the box at the job's own tolerance
    /// (not the swarm's, nor a looser local stage's, nor the signal's own likelihood's, whose costs
    /// are not comparable) is kept in
    /// [`SpectralProblem::near_best`] when it is near the lowest seen.
    pub(crate) fn cost_at_stage(&self, u: &[f64], stage: SearchStage) -> f64 {
        let c = self.unrecorded_cost_at_stage(u, stage);
        let inside = u.iter().all(|x| (0.0..=1.0).contains(x));
        if !matches!(stage, SearchStage::Swarm | SearchStage::SignalLocal)
            && *self.solver_of(stage) == self.solver
            && inside
            && c < FAILED_COST
            && self.cost_is_nll()
        {
            self.near_best
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .record(u, c);
        }
        c
    }

    /// The integrator settings `stage` simulates with.
    fn solver_of(&self, stage: SearchStage) -> &SolverOptions {
        match stage {
            SearchStage::Swarm => &self.swarm_solver,
            SearchStage::Local | SearchStage::SignalLocal => &self.local_solver,
            SearchStage::Polish | SearchStage::SignalPolish | SearchStage::Cmaes => &self.solver,
        }
    }

    /// [`SpectralProblem::cost_at`] without keeping the point among the near-best ones (a
    /// probe of the cost, not a step of a search).
    pub(crate) fn unrecorded_cost_at(&self, u: &[f64]) -> f64 {
        self.unrecorded_cost_at_stage(u, SearchStage::Polish)
    }

    /// [`SpectralProblem::cost_at_stage`] without keeping the point (a joint fit's other
    /// recordings, whose cost is a part of the whole).
    fn unrecorded_cost_at_stage(&self, u: &[f64], stage: SearchStage) -> f64 {
        let solver = self.solver_of(stage);
        let outside: f64 = u
            .iter()
            .map(|x| (x - x.clamp(0.0, 1.0)).powi(2))
            .sum::<f64>();
        if super::interrupt::stop_requested() {
            // Stopping: no more simulations (not counted as an evaluation).
            return FAILED_COST;
        }
        let p = self.params_at(u);
        if self.softening_shoulder(&p) {
            // Outside the model's physics: no simulation, not an evaluation.
            return FAILED_COST;
        }
        let c = self
            .counted(|| self.stage_cost(&self.simulate_with(&p, solver)?, stage))
            .unwrap_or(FAILED_COST)
            + self.prior.nats(&p);
        let joint: f64 = self
            .others
            .iter()
            .map(|o| o.unrecorded_cost_at_stage(u, stage))
            .sum();
        c + joint + 1e4 * outside
    }
}

/// The problem as argmin sees it in one stage: shared by the swarm's threads. The third field counts
/// this run's evaluations (restarts run in parallel; the problem's own counter sums them all).
#[derive(Clone)]
pub(crate) struct Shared(
    pub(crate) Arc<SpectralProblem>,
    pub(crate) SearchStage,
    pub(crate) Arc<AtomicUsize>,
);

impl CostFunction for Shared {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, u: &Self::Param) -> std::result::Result<f64, argmin::core::Error> {
        if super::interrupt::stop_requested() {
            return Err(argmin::core::Error::msg("interrupted"));
        }
        self.2.fetch_add(1, Ordering::Relaxed);
        Ok(self.0.cost_at_stage(u, self.1))
    }
}

/// [`Shared`] with one normalised coordinate held: the cost as a function of the others (a
/// profile likelihood's inner minimisation, [`crate::uncertainty::intervals::profile_intervals`]).
#[derive(Clone)]
pub(crate) struct Pinned {
    pub(crate) shared: Shared,
    /// The held coordinate's index in the full vector.
    pub(crate) index: usize,
    /// Its value, normalised.
    pub(crate) u: f64,
}

impl Pinned {
    /// The full coordinates: `others` with the held one inserted at its index.
    pub(crate) fn full(&self, others: &[f64]) -> Vec<f64> {
        let mut u = others.to_vec();
        u.insert(self.index, self.u);
        u
    }
}

impl CostFunction for Pinned {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, others: &Self::Param) -> std::result::Result<f64, argmin::core::Error> {
        self.shared.cost(&self.full(others))
    }
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
