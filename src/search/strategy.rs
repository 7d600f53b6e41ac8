//! The search strategy: each candidate fitted by particle swarm and Nelder–Mead polish (argmin),
//! with its history and progress reported through argmin observers, and the cost's curvature at
//! the optimum.

use super::FitError;
use super::evidence::LocalFit;
use super::evidence::RecordingLikelihood;
use super::history::{HistoryPoint, SearchStage};
use super::interrupt;
use super::problem::{Pinned, Shared, SpectralProblem};
use crate::Result;
use crate::estimate::{FitWarning, Interval};
use crate::job::Candidate;
use crate::job::FreeParam;
use crate::job::{self, LoadedJob};
use crate::likelihood::measure::{Measurement, measure, measure_recording, necklip_view};
use crate::likelihood::prior::Prior;
use crate::model::BladeParams;
use crate::model::ParamId;
use crate::simulate::SolverOptions;
use crate::simulate::blade::ModelKind;
use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{CostFunction, Executor, IterState, KV, State};
use argmin::solver::neldermead::NelderMead;
use argmin::solver::particleswarm::ParticleSwarm;
use rand::SeedableRng;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// A point of the normalised search space with its cost.
pub(crate) type Scored = (Vec<f64>, f64);

/// What a candidate's search reports, and where: its cost history and the job's progress bar.
#[derive(Clone)]
pub(crate) struct Reporting {
    pub(crate) history: Arc<Mutex<Vec<HistoryPoint>>>,
    /// The best point any iteration of this candidate's search reached, with its cost: what an
    /// interrupted search returns.
    pub(crate) best: Arc<Mutex<Option<Scored>>>,
    pub(crate) progress: Option<indicatif::ProgressBar>,
    /// The progress bar's position when this candidate started: its model runs count on from here.
    pub(crate) base: u64,
    /// When stderr is not a terminal (the bar is not drawn): the time of the last one-line
    /// progress message, so that one is printed at most every [`piped_interval`].
    pub(crate) last_line: Option<Arc<Mutex<std::time::Instant>>>,
    pub(crate) candidate: Candidate,
}

impl Reporting {
    /// The reporting of `candidate`'s search on the progress bar `pb` (from its position now), with
    /// one-line messages instead when stderr is not a terminal.
    pub(crate) fn new(pb: &Option<indicatif::ProgressBar>, candidate: Candidate) -> Reporting {
        let last_line = pb
            .as_ref()
            .filter(|_| !std::io::IsTerminal::is_terminal(&std::io::stderr()))
            .map(|_| Arc::new(Mutex::new(std::time::Instant::now())));
        Reporting {
            last_line,
            history: Arc::new(Mutex::new(Vec::new())),
            best: Arc::new(Mutex::new(None)),
            progress: pb.clone(),
            base: pb.as_ref().map_or(0, |pb| pb.position()),
            candidate,
        }
    }

    /// The reporting of a fitted candidate `f`'s later work (valley polishes, a scan, taking the
    /// smaller model's optimum): its history continued, its model runs counting on from the
    /// progress bar's position now.
    pub(crate) fn continuing(f: &CandidateFit, pb: &Option<indicatif::ProgressBar>) -> Reporting {
        Reporting {
            history: Arc::new(Mutex::new(f.history.clone())),
            ..Reporting::new(pb, f.candidate)
        }
        .resumed(f.problem.evaluations.load(Ordering::Relaxed))
    }

    /// The same reporting (history, best point) continued later in the job, after the candidate's
    /// first `evaluations` model runs: the bar's base moved so that its runs count on from the
    /// bar's position now.
    fn resumed(&self, evaluations: usize) -> Reporting {
        let mut r = self.clone();
        if let Some(pb) = &self.progress {
            r.base = pb.position().saturating_sub(evaluations as u64);
        }
        r
    }

    /// The search's history restart by restart, swarm then polish (restarts run in parallel and
    /// interleave their points).
    fn sorted_history(&self) -> Vec<HistoryPoint> {
        let mut history = self
            .history
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone();
        history.sort_by_key(|h| (h.restart, h.stage == SearchStage::Polish, h.iteration));
        history
    }

    /// Moves the progress bar to `evaluations` model runs from this reporting's base and, when
    /// stderr is not a terminal, prints a one-line message at most every [`piped_interval`].
    fn advance(&self, evaluations: usize) {
        let Some(pb) = &self.progress else { return };
        pb.set_position(self.base + evaluations as u64);
        if let Some(last) = &self.last_line {
            let mut last = last.lock().unwrap_or_else(|e| e.into_inner());
            if last.elapsed() >= piped_interval() {
                *last = std::time::Instant::now();
                eprintln!(
                    "progress: {}: {}/{} model runs, {:.0} s",
                    pb.message(),
                    pb.position(),
                    pb.length().unwrap_or(0),
                    pb.elapsed().as_secs_f64()
                );
            }
        }
    }

    /// Keeps one CMA-ES generation of `stage` in the history, as restart `restart`'s iteration,
    /// at `evaluations` of that run.
    fn generation(
        &self,
        stage: SearchStage,
        restart: usize,
        g: &super::ipop::Generation,
        evaluations: usize,
    ) {
        self.history
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(HistoryPoint {
                stage,
                restart,
                iteration: g.generation,
                best_cost: g.best_cost,
                evaluations,
            });
    }

    /// Names the stage on the progress bar.
    pub(crate) fn stage(&self, what: std::fmt::Arguments) {
        if let Some(pb) = &self.progress {
            pb.set_message(format!("{} {what}", self.candidate));
        }
    }
}

/// An argmin observer of the search: after every iteration it appends the best cost to the
/// history and moves the progress bar to the model runs done so far. The cost function itself
/// reports nothing; it only counts its evaluations.
pub(crate) struct SearchObserver {
    stage: SearchStage,
    restart: usize,
    reporting: Reporting,
    /// The candidate's evaluations (all restarts), for the progress bar.
    evals: Arc<AtomicUsize>,
    /// This restart's evaluations (swarm and polish), for the history.
    run_evals: Arc<AtomicUsize>,
}

/// A point of the search space as the solvers' states hold it.
pub(crate) trait AsPoint {
    fn point(&self) -> &[f64];
}

impl AsPoint for Vec<f64> {
    fn point(&self) -> &[f64] {
        self
    }
}

impl AsPoint for argmin::solver::particleswarm::Particle<Vec<f64>, f64> {
    fn point(&self) -> &[f64] {
        &self.position
    }
}

impl<I> Observe<I> for SearchObserver
where
    I: State<Float = f64>,
    I::Param: AsPoint,
{
    fn observe_iter(
        &mut self,
        state: &I,
        _kv: &KV,
    ) -> std::result::Result<(), argmin::core::Error> {
        let evaluations = self.evals.load(Ordering::Relaxed);
        self.reporting
            .history
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(HistoryPoint {
                stage: self.stage,
                restart: self.restart,
                iteration: state.get_iter(),
                best_cost: state.get_best_cost(),
                evaluations: self.run_evals.load(Ordering::Relaxed),
            });
        self.reporting.advance(evaluations);
        let cost = state.get_best_cost();
        if let Some(p) = state.get_best_param() {
            let mut best = self
                .reporting
                .best
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            if best.as_ref().is_none_or(|b| cost < b.1) {
                *best = Some((p.point().to_vec(), cost));
            }
        }
        Ok(())
    }
}

/// An argmin observer that only moves the progress bar (no history, no best point): the polishes
/// after the search ([`crate::uncertainty::intervals::profile_intervals_at`]). `evals` counts the model runs
/// of all of them.
#[derive(Clone)]
pub(crate) struct ProgressObserver {
    pub(crate) reporting: Reporting,
    pub(crate) evals: Arc<AtomicUsize>,
}

impl<I: State> Observe<I> for ProgressObserver {
    fn observe_iter(&mut self, _: &I, _: &KV) -> std::result::Result<(), argmin::core::Error> {
        self.reporting.advance(self.evals.load(Ordering::Relaxed));
        Ok(())
    }
}

/// One candidate fitted.
pub(crate) struct CandidateFit {
    pub(crate) candidate: Candidate,
    pub(crate) free: Vec<FreeParam>,
    pub(crate) problem: Arc<SpectralProblem>,
    pub(crate) best_u: Vec<f64>,
    pub(crate) sigma_u: Vec<f64>,
    pub(crate) corr: Vec<Vec<f64>>,
    /// 1σ of the normalised coordinates from the Fisher information alone, with a likelihood.
    pub(crate) fisher_sigma_u: Option<Vec<f64>>,
    /// The correlations of `F⁻¹`, with `fisher_sigma_u`.
    pub(crate) fisher_corr: Option<Vec<Vec<f64>>>,
    /// How much the rounding's draws widen each coordinate's 1σ
    /// ([`super::evidence::LocalFit::rounding_widening`]), once the smoothed spread is in.
    pub(crate) rounding_widening: Option<Vec<f64>>,
    /// The step of each coordinate's differences in that spread
    /// ([`super::evidence::LocalFit::fisher_steps_u`]).
    pub(crate) fisher_steps_u: Option<Vec<f64>>,
    /// The recording's NLL at the optimum (`sigma_u` and `corr` then come from its sandwich
    /// covariance, [`super::evidence::at_fit`]), or why there is none (then from the cost's
    /// curvature).
    pub(crate) evidence: std::result::Result<super::evidence::NllParts, super::NoEvidence>,
    pub(crate) swarm_iters: u64,
    pub(crate) polish_iters: u64,
    pub(crate) wall_time_s: f64,
    pub(crate) history: Vec<HistoryPoint>,
    pub(crate) cost: f64,
    /// The cost where the search ended, before settling (nats with the likelihood objective).
    pub(crate) search_cost: f64,
    /// How a nested candidate was searched (adaptive search), and whether a deferred confirmation
    /// was skipped, for the model-choice reason.
    pub(crate) search_note: Option<String>,
    /// The deferred confirmation of an unconfirmed best end, until [`confirm_deferred`].
    pub(crate) unconfirmed: Option<Unconfirmed>,
    /// Whether [`confirm_deferred`] left the candidate's second batch of restarts out because no
    /// end it could reach would make it the choice ([`confirmation_skipped`]); a contact-angle
    /// scan, more restarts in slices, is then left out too.
    pub(crate) more_restarts_futile: bool,
    /// The profile walk at the optimum ([`crate::uncertainty::climb::climb_chosen`]), kept for its intervals.
    pub(crate) profile_walk: Option<ProfileWalk>,
}

impl CandidateFit {
    /// The spread of the chosen candidate's estimate from the sandwich with the response's
    /// Jacobian averaged over the bowl's centre ([`super::evidence::at_fit_smoothed`]): the 1σ
    /// and correlations its intervals and result report. Unchanged where the fit has no
    /// likelihood, was interrupted, or the smoothed spread fails.
    pub(crate) fn with_smoothed_spread(mut self) -> Self {
        if self.evidence.is_err() || interrupt::stop_requested() {
            return self;
        }
        // The profile climb's last walk computed this spread at this optimum.
        let walked = self
            .profile_walk
            .as_ref()
            .filter(|w| w.at_u == self.best_u)
            .map(|w| Ok(w.spread.clone()));
        let smoothed =
            walked.unwrap_or_else(|| super::evidence::at_fit_smoothed(&self.problem, &self.best_u));
        if let Ok(l) = smoothed {
            self.sigma_u = l.sigma_u;
            self.corr = l.corr;
            self.fisher_sigma_u = Some(l.curvature_sigma_u);
            self.fisher_corr = Some(l.curvature_corr);
            self.rounding_widening = Some(l.rounding_widening);
            self.fisher_steps_u = Some(l.fisher_steps_u);
            self.evidence = Ok(l.nll);
        }
        self
    }
}

/// A profile walk of a fit's optimum: its intervals and warnings, the point it was walked at, and
/// the spread there it was walked with (what [`CandidateFit::with_smoothed_spread`] reports).
pub(crate) struct ProfileWalk {
    /// The normalised coordinates the walk started from (the intervals apply only there).
    pub(crate) at_u: Vec<f64>,
    pub(crate) spread: LocalFit,
    pub(crate) intervals: Vec<Interval>,
    pub(crate) warnings: Vec<FitWarning>,
}

/// How often a fit whose stderr is not a terminal prints a one-line progress message: 5 s, or
/// `WIPERLAB_PROGRESS_INTERVAL_S` seconds when set (tests use 0).
pub(crate) fn piped_interval() -> std::time::Duration {
    let s = std::env::var("WIPERLAB_PROGRESS_INTERVAL_S")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|v| v.is_finite() && *v >= 0.0)
        .unwrap_or(5.0);
    std::time::Duration::from_secs_f64(s)
}

/// The job's progress bar, its length the model runs the search is expected to take: per
/// candidate and restart the swarm's particles × (iterations + 1), the local CMA-ES run's cap, the
/// polish's simplex and two runs per iteration, and the curvature's stencil. A nested candidate searched adaptively counts
/// its local polishes only; its global search, when it runs, lengthens the bar
/// ([`nested_search`]).
pub(crate) fn progress_bar(job: &LoadedJob, candidates: &[Candidate]) -> indicatif::ProgressBar {
    let fit = &job.job.fit;
    let mut budget = 0u64;
    for (i, c) in candidates.iter().enumerate() {
        let n = job.freed(*c).map_or(job.free.len(), |(_, free)| free.len());
        // The curvature's stencil, or the likelihood's settling steps and its Fisher information.
        let hess_evals = (1 + 2 * n + 2 * n * n.saturating_sub(1))
            .max(super::evidence::settle_evaluations(n)) as u64;
        let nested = candidates[..i].iter().any(|f| c.extends(f));
        let adaptive = nested
            && fit.nested_search == job::NestedSearch::Adaptive
            && fit.objective == job::Objective::Likelihood
            && job.job.targets.is_none();
        budget += hess_evals
            + if fit.search.method == job::SearchMethod::Cmaes {
                fit.search.max_evaluations as u64
            } else if adaptive {
                NESTED_WARM_POINTS * polish_budget(fit, n)
            } else {
                restarts_budget(fit, n)
            };
    }
    let pb = indicatif::ProgressBar::new(budget);
    pb.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg:28} [{bar:32}] {pos}/{len} model runs, {elapsed} (eta {eta})",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    pb
}

/// How many warm points a nested candidate's search starts from ([`nested_warm_points`]): its
/// local search polishes from each, and the first restarts of its global search start a particle
/// at one.
pub(crate) const NESTED_WARM_POINTS: u64 =
    1 + (FREE_NECK_QUANTILES.len() + RESTING_QUANTILES.len()) as u64;

/// The quantiles of |θ| in the smaller model's motion at which [`nested_warm_points`] puts the
/// contact angle of a shoulder that changes no moment (k1_contact = k1): the median and the 90th
/// percentile, where a polish feels k1_contact at once.
const FREE_NECK_QUANTILES: [f64; 2] = [0.5, 0.9];

/// The quantiles of |θ| in the smaller model's motion at which [`nested_warm_points`] puts a
/// resting neck's contact angle: from the 10th percentile, a neck resting nearly all the window,
/// to the 75th, one that touches its shoulder for a quarter of it.
const RESTING_QUANTILES: [f64; 4] = [0.1, 0.25, 0.5, 0.75];

/// Model runs of one Nelder–Mead polish over `n` parameters: its simplex and two per iteration.
pub(crate) fn polish_budget(fit: &job::FitSection, n: usize) -> u64 {
    n as u64 + 1 + 2 * fit.polish_iterations
}

/// Model runs of [`optimise`]'s restarts over `n` parameters: each a swarm, its local CMA-ES run
/// when `[fit.search] local = "cmaes"` (counted at its cap, `local_evaluations`) and a polish.
fn restarts_budget(fit: &job::FitSection, n: usize) -> u64 {
    let local = match fit.search.local {
        job::LocalSearch::Cmaes => fit.search.local_evaluations as u64,
        job::LocalSearch::NelderMead => 0,
    };
    fit.restarts.max(1) as u64
        * (fit.particles as u64 * (fit.swarm_iterations + 1) + local + polish_budget(fit, n))
}

/// Fits every candidate in turn; a `+shoulder` candidate starts from the fit of the same model
/// without shoulder when that came first (see [`fit_candidate`]). With more than one candidate,
/// the confirmation of a best end that no second restart reached is deferred
/// ([`Confirmation::Deferred`], [`confirm_deferred`]) for every candidate that no later one starts
/// from, and for one that trails a candidate fitted before it by more than its ends' spread
/// ([`hopelessly_behind`]).
pub(crate) fn fit_candidates(
    job: &LoadedJob,
    meas: &Measurement,
    candidates: &[Candidate],
    pb: &Option<indicatif::ProgressBar>,
) -> Result<Vec<CandidateFit>> {
    let mut fits: Vec<CandidateFit> = Vec::new();
    for (i, c) in candidates.iter().enumerate() {
        let nested = fits.iter().find(|f| c.extends(&f.candidate));
        let base_of_later = candidates[i + 1..].iter().any(|l| l.extends(c));
        let when = if candidates.len() > 1 && !base_of_later {
            Confirmation::Deferred
        } else {
            Confirmation::Now
        };
        let confirming = Confirming {
            when,
            leader: leader(&fits),
        };
        let fitted = fit_candidate(job, meas, *c, pb, nested, confirming)?;
        fits.push(fitted);
        if interrupt::stop_requested() {
            break;
        }
    }
    Ok(fits)
}

/// The lowest cost (nats: the recording's NLL) among the candidates fitted so far, the one a
/// later candidate's search is measured against ([`hopelessly_behind`]); `None` before the first
/// or without a likelihood.
fn leader(fits: &[CandidateFit]) -> Option<f64> {
    fits.iter()
        .filter(|f| f.problem.cost_is_nll() && f.cost.is_finite())
        .map(|f| f.cost)
        .min_by(f64::total_cmp)
}

/// The cost problem of one candidate: its freed parameters (the job's, plus the shoulder's when
/// the candidate has one) and the measurement as that model sees it, with any further recordings
/// of a joint fit attached.
pub(crate) fn build_problem(
    job: &LoadedJob,
    meas: &Measurement,
    candidate: Candidate,
) -> Result<(SpectralProblem, Vec<FreeParam>)> {
    let (base, free) = job.freed(candidate)?;
    let evaluations = Arc::new(AtomicUsize::new(0));
    let build = |m: &Measurement, base: BladeParams, label: String| {
        let recording = Recording { m, base, label };
        problem_of(job, candidate, recording, &free, evaluations.clone())
    };
    let mut main = build(meas, base, String::new())?;
    let priors = &job.job.fit.priors;
    main.prior = Arc::new(Prior::new(priors, job.rig_curve.as_ref(), &free));
    let dir = job.path.parent().unwrap_or(std::path::Path::new("."));
    for more in &job.job.more_recordings {
        let m = measure_recording(job, &dir.join(&more.file), &more.import)?;
        let mut b = base;
        b.drive_a_m = more.drive_a_m.unwrap_or(b.drive_a_m);
        b.drive_omega_rad_per_s = more
            .drive_omega_rad_per_s
            .unwrap_or(b.drive_omega_rad_per_s);
        main.others.push(build(&m, b, more.name.clone())?);
    }
    Ok((main, free))
}

/// One recording of a fit: its measurement, the blade's base parameters for it (its own drive) and
/// its label (empty for the job's main recording).
struct Recording<'a> {
    m: &'a Measurement,
    base: BladeParams,
    label: String,
}

/// The job's solver settings with their rtol replaced by a search stage's own `rtol` (and atol
/// scaled with it) when the job sets one (`[fit] swarm_rtol`, `[fit.search] local_rtol`).
fn solver_at(job: &LoadedJob, rtol: Option<f64>) -> SolverOptions {
    let solver = job.job.solver;
    match rtol {
        Some(r) => SolverOptions {
            rtol: r,
            atol: solver.atol * r / solver.rtol,
            ..solver
        },
        None => solver,
    }
}

/// The cost problem of `candidate` on one recording `r`, sharing the evaluation counter.
fn problem_of(
    job: &LoadedJob,
    candidate: Candidate,
    r: Recording,
    free: &[FreeParam],
    evaluations: Arc<AtomicUsize>,
) -> Result<SpectralProblem> {
    let (fit, m) = (&job.job.fit, r.m);
    let (measured, floors, nan_mask) = if candidate.kind == ModelKind::Necklip {
        necklip_view(job, m, &r.base)?
    } else {
        (
            m.measured.clone(),
            m.floors.clone(),
            m.x.iter().map(|v| !v.is_finite()).collect(),
        )
    };
    let t = &m.trace.t_s;
    let mut p = SpectralProblem {
        model: candidate.kind,
        head: m.head.clone().ok(),
        targets: m.targets.clone(),
        time_targets: m.time_targets.clone(),
        others: Vec::new(),
        label: r.label,
        base: r.base,
        free: free.to_vec(),
        lines: measured
            .bands
            .iter()
            .map(crate::likelihood::band_has_line)
            .collect(),
        measured,
        floors,
        bands: job.job.spectrum.bands.clone(),
        signal: job.job.spectrum.signal,
        nan_mask,
        sample_times: t.clone(),
        fs_hz: m.fs_hz,
        max_fill: job.job.spectrum.max_fill,
        window: (t[0], *t.last().unwrap_or(&t[0])),
        solver: job.job.solver,
        swarm_solver: solver_at(job, fit.swarm_rtol),
        local_solver: solver_at(job, fit.search.local_rtol),
        swarm_cost: fit.search.swarm_cost,
        objective: fit.objective,
        weights: fit.weights,
        likelihood: Err(super::NoLikelihood::NotBuilt),
        signal_likelihood: None,
        evaluations,
        failures: Arc::new(AtomicUsize::new(0)),
        failure_causes: Default::default(),
        first_failure: Mutex::new(None),
        near_best: Mutex::new(Default::default()),
        last_jitter: Mutex::new(None),
        prior: Default::default(),
    };
    let own = |p: &SpectralProblem| {
        RecordingLikelihood::new(p, &m.x, fit.likelihood.time_domain).map(|l| {
            l.with_noise(fit.likelihood.noise).with_blocks(
                fit.likelihood
                    .block_s
                    .map(|b| (b * p.fs_hz).round() as usize),
            )
        })
    };
    p.likelihood = if p.targets.is_some() {
        Err(super::NoLikelihood::TargetJob)
    } else {
        own(&p)
            .and_then(|l| l.with_joint(&p, &m.trace, &fit.likelihood.joint_signals))
            .map(Arc::new)
            .map_err(|e| super::NoLikelihood::Recording(Arc::new(e)))
    };
    if !fit.likelihood.joint_signals.is_empty() && p.likelihood.is_ok() {
        p.signal_likelihood = own(&p).ok().map(Arc::new);
    }
    Ok(p)
}

/// The cost problem of the candidate `model` on the
/// job's recording or targets, without fitting it: for evaluating the cost at given parameters
/// ([`SpectralProblem::cost_at`], [`SpectralProblem::params_at`]).
///
/// # Errors
/// Every error of reading and measuring the recording.
pub fn problem_for(job: &LoadedJob, candidate: Candidate) -> Result<SpectralProblem> {
    let meas = measure(job)?;
    Ok(build_problem(job, &meas, candidate)?.0)
}

/// Fits one candidate: particle swarm, Nelder–Mead polish, curvature.
///
/// `nested`: the fit of the candidate without shoulder, when `candidate` adds one to it and that
/// fit is done. Its optimum, with k1_contact = k1 (so the shoulder changes no moment), seeds one
/// particle of the first swarm and is itself kept if no restart ends below it (see `optimise`):
/// the larger model then cannot end above the smaller one's cost, which the AIC comparison of
/// nested models assumes. Without the warm particle a swarm can leave the larger candidate above
/// the optimum of the model it contains.
///
/// `confirming`: when an unconfirmed end is confirmed, and the lowest cost of the candidates
/// fitted before ([`Confirming`]).
pub(crate) fn fit_candidate(
    job: &LoadedJob,
    meas: &Measurement,
    candidate: Candidate,
    pb: &Option<indicatif::ProgressBar>,
    nested: Option<&CandidateFit>,
    confirming: Confirming,
) -> Result<CandidateFit> {
    let started = std::time::Instant::now();
    let reporting = Reporting::new(pb, candidate);
    reporting.stage(format_args!("swarm"));
    let (main, free) = build_problem(job, meas, candidate)?;
    let problem = Arc::new(main);
    let warm = nested.map_or_else(Vec::new, |smaller| {
        nested_warm_points(smaller, candidate, &free)
    });
    let (found, search_note) = search(
        job,
        &problem,
        nested.map(|s| (s.search_cost, candidate.nested_phrase(&s.candidate))),
        &warm,
        &reporting,
        confirming,
    )?;
    let unconfirmed = found.unconfirmed_ends.clone().map(|ends| Unconfirmed {
        ends,
        reporting: reporting.clone(),
    });
    let mut fit = finish(
        candidate,
        free,
        problem,
        found,
        (&reporting, pb),
        Settling::Settle,
    )?;
    let mut search_note = search_note;
    if let (Some(smaller), Some(w)) = (nested, warm.first()) {
        fit = keep_the_smaller_optimum(fit, smaller, w, &reporting, pb, &mut search_note)?;
    }
    fit.search_note = search_note;
    fit.unconfirmed = unconfirmed;
    fit.wall_time_s = started.elapsed().as_secs_f64();
    Ok(fit)
}

/// The NLL gain (nats) by which a fresh Nelder–Mead polish from the search's best end must lower
/// the cost to be kept ([`descend_the_valley`]): 0.1 nats, twice the ripple depth at which a polish
/// stops ([`POLISH_SD_NATS`]), so that hopping from one ripple to the next does not count.
pub const VALLEY_GAIN_NATS: f64 = 0.1;

/// Fresh Nelder–Mead polishes from the search's best end, with the likelihood as the cost, kept
/// while each lowers it by more than [`VALLEY_GAIN_NATS`] (at most `polishes`). A polish
/// stops when its simplex has shrunk to the ripples' depth ([`POLISH_SD_NATS`]); in a long shallow
/// valley of the likelihood that can happen on the valley's slope, and a new simplex of the first
/// one's size, started where the last one stopped, goes on down the valley (restarting Nelder–Mead
/// at its claimed minimum: Press et al., *Numerical Recipes*, 3rd ed. 2007, §10.5). Where the end
/// is already at a valley's floor, one polish confirms it and the end is kept as the search left
/// it. Each polish costs up to `polish_iterations` Nelder–Mead iterations, one model run after
/// another, and gains nothing where the search already ended at the floor (as on the main job's
/// recording), so only a candidate with a shoulder, whose contact moment makes a valley, gets
/// them by default ([`job::FitSection::valley_polishes_for`]).
fn descend_the_valley(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    polishes: usize,
    mut found: Optimised,
    reporting: &Reporting,
) -> Result<(Optimised, usize)> {
    if !problem.cost_is_nll() || !found.cost.is_finite() {
        return Ok((found, 0));
    }
    let n = problem.free.len();
    let mut kept = 0;
    for k in 0..polishes {
        if interrupt::stop_requested() {
            break;
        }
        if let Some(pb) = &reporting.progress {
            pb.inc_length(polish_budget(fit, n));
        }
        reporting.stage(format_args!("valley polish {}", k + 1));
        let observer = SearchObserver {
            stage: SearchStage::Polish,
            restart: 2 * fit.restarts.max(1) + k,
            reporting: reporting.clone(),
            evals: problem.evaluations.clone(),
            run_evals: Arc::new(AtomicUsize::new(0)),
        };
        let (u, iters, cost) = match polish(
            problem,
            &found.u,
            POLISH_STEP_U,
            fit.polish_iterations,
            Some(observer),
        ) {
            Ok(p) => p,
            Err(_) if interrupt::stop_requested() => break,
            Err(e) => return Err(e),
        };
        found.polish_iters += iters;
        if found.cost - cost <= VALLEY_GAIN_NATS {
            break;
        }
        (found.u, found.cost) = (u, cost);
        kept += 1;
    }
    Ok((found, kept))
}

/// [`descend_the_valley`] from the settled optimum of the chosen candidate `fits[chosen]` (its
/// estimate is what the result reports; the others' fits only score the choice). When it gains,
/// the candidate is settled anew from the valley's end, and a candidate nested on it
/// (`X+shoulder` on `X`) left less likely than it takes its optimum
/// ([`keep_the_smaller_optimum`]), so the larger model stays at least as likely as the smaller,
/// as the likelihood-ratio test assumes. The chosen candidate's score only falls, so the choice
/// stands. The candidate's search note says how many polishes were kept and what they gained.
/// Returns whether the chosen candidate moved.
pub(crate) fn descend_chosen(
    job: &LoadedJob,
    fits: &mut Vec<CandidateFit>,
    chosen: usize,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<bool> {
    let f = &fits[chosen];
    let polishes = job.job.fit.valley_polishes_for(f.candidate);
    if polishes == 0 || !f.problem.cost_is_nll() || interrupt::stop_requested() {
        return Ok(false);
    }
    let started = std::time::Instant::now();
    let reporting = Reporting::continuing(f, pb);
    let at_fit = Optimised {
        u: f.best_u.clone(),
        swarm_iters: f.swarm_iters,
        polish_iters: f.polish_iters,
        cost: f.cost,
        unconfirmed_ends: None,
    };
    let (found, kept) = descend_the_valley(&f.problem, &job.job.fit, polishes, at_fit, &reporting)?;
    let f = &mut fits[chosen];
    let wall_time_s = f.wall_time_s;
    let moved = found.cost < f.cost && !interrupt::stop_requested();
    add_note(
        &mut f.search_note,
        valley_note(kept, polishes, f.cost - found.cost),
    );
    if moved {
        settle_anew(f, found, &reporting, pb)?;
    } else {
        f.polish_iters = found.polish_iters;
        f.history = reporting.sorted_history();
    }
    f.wall_time_s = wall_time_s + started.elapsed().as_secs_f64();
    if moved {
        keep_nested_above(fits, chosen, pb)?;
    }
    Ok(moved)
}

/// `text` appended to a candidate's search note (the trial's `reason` in the result).
pub(crate) fn add_note(note: &mut Option<String>, text: String) {
    *note = Some(match note.take() {
        Some(n) => format!("{n}; {text}"),
        None => text,
    });
}

/// What [`descend_chosen`] did, for the candidate's search note: `kept` of at most `polishes`
/// valley polishes kept, lowering the cost by `gain_nats`.
fn valley_note(kept: usize, polishes: usize, gain_nats: f64) -> String {
    if kept == 0 {
        format!(
            "valley polishes: none of up to {polishes} gained more than {VALLEY_GAIN_NATS} nats, the optimum kept"
        )
    } else {
        format!("valley polishes: {kept} of up to {polishes} kept, {gain_nats:.3} nats lower")
    }
}

/// The candidate `f` settled anew ([`finish`] with [`Settling::Settle`]) from a better search end
/// `found`, keeping its search note (its wall time is the caller's).
pub(crate) fn settle_anew(
    f: &mut CandidateFit,
    found: Optimised,
    reporting: &Reporting,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<()> {
    let note = f.search_note.take();
    *f = finish(
        f.candidate,
        f.free.clone(),
        f.problem.clone(),
        found,
        (reporting, pb),
        Settling::Settle,
    )?;
    f.search_note = note;
    Ok(())
}

/// Every candidate `X` on which a fitted candidate `Y` is nested (`X+shoulder`, or `X@law` with a
/// larger law) takes `Y`'s optimum read in `X`'s own parameters when that is more than
/// [`VALLEY_GAIN_NATS`] more likely than `X`'s search end, and is settled anew from it; candidates
/// nested on a moved `X` then keep at least its likelihood ([`keep_nested_above`]). Why: `Y`
/// starts from `X`'s optimum and searches further, so it can end at a point of `X`'s own family
/// (a viscous term at D = 0, a shoulder the neck never reaches) that `X`'s shorter search missed;
/// `X` would then lose the choice to a larger model that adds nothing, or be reported short of
/// its own optimum. One simulation per nested pair.
pub(crate) fn take_nested_optima(
    fits: &mut Vec<CandidateFit>,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<()> {
    for small in 0..fits.len() {
        let x = &fits[small];
        if !x.problem.cost_is_nll() || interrupt::stop_requested() {
            continue;
        }
        let best = fits
            .iter()
            .filter(|y| y.candidate.extends(&x.candidate) && y.cost < x.cost - VALLEY_GAIN_NATS)
            .filter_map(|y| {
                let u = projection(x, y)?;
                let cost = x.problem.cost_at(&u);
                cost.is_finite().then_some((u, cost, y.candidate))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let Some((u, cost, larger)) = best else {
            continue;
        };
        let f = &mut fits[small];
        if cost >= f.cost - VALLEY_GAIN_NATS {
            continue;
        }
        let started = std::time::Instant::now();
        let wall_time_s = f.wall_time_s;
        add_note(
            &mut f.search_note,
            format!(
                "{larger}'s optimum, read in this model's parameters, is {:.3} nats more likely \
                 than its own search end ({cost:.3} against {:.3}), so it continues from there",
                f.cost - cost,
                f.cost
            ),
        );
        let reporting = Reporting::continuing(f, pb);
        let found = Optimised {
            u,
            swarm_iters: f.swarm_iters,
            polish_iters: f.polish_iters,
            cost,
            unconfirmed_ends: None,
        };
        settle_anew(f, found, &reporting, pb)?;
        f.wall_time_s = wall_time_s + started.elapsed().as_secs_f64();
        keep_nested_above(fits, small, pb)?;
    }
    Ok(())
}

/// `larger`'s optimum in `smaller`'s normalised coordinates: each of `smaller`'s freed parameters
/// at its value in `larger`'s parameters; `None` when one is not among them or lies outside
/// `smaller`'s bounds.
fn projection(smaller: &CandidateFit, larger: &CandidateFit) -> Option<Vec<f64>> {
    let params = larger.problem.params_at(&larger.best_u);
    smaller
        .free
        .iter()
        .map(|fp| {
            let v = fp.name.get(&params)?;
            (fp.lower..=fp.upper).contains(&v).then(|| fp.u_of(v))
        })
        .collect()
}

/// Every candidate nested on `fits[smaller]` (`X+shoulder` on `X`) that is less likely than it
/// takes its optimum ([`keep_the_smaller_optimum`]).
pub(crate) fn keep_nested_above(
    fits: &mut Vec<CandidateFit>,
    smaller: usize,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<()> {
    for i in 0..fits.len() {
        if !fits[i].candidate.extends(&fits[smaller].candidate) {
            continue;
        }
        let larger = fits.remove(i);
        let small = &fits[if smaller < i { smaller } else { smaller - 1 }];
        let Some(warm) = nested_warm_points(small, larger.candidate, &larger.free)
            .into_iter()
            .next()
        else {
            fits.insert(i, larger);
            continue;
        };
        let reporting = Reporting::continuing(&larger, pb);
        let (mut note, wall_time_s) = (larger.search_note.clone(), larger.wall_time_s);
        let mut kept = keep_the_smaller_optimum(larger, small, &warm, &reporting, pb, &mut note)?;
        (kept.search_note, kept.wall_time_s) = (note, wall_time_s);
        fits.insert(i, kept);
    }
    Ok(())
}

/// A nested candidate (`X+shoulder`) whose settled optimum is less likely than `X`'s: it takes
/// `X`'s settled optimum instead, its first warm point `warm` (the same parameters, and while the
/// neck stays below θ_c the same simulation), with its local fit there and no settling. Both
/// settled points are centres of bowls at the intervals' scale, not maxima, so the larger
/// model's can land a few hundredths of a nat below the smaller one's; but the larger model
/// contains the smaller one's optimum, so its maximum likelihood is never below it, as the
/// likelihood-ratio test and AIC of nested models assume. Unchanged otherwise.
fn keep_the_smaller_optimum(
    fit: CandidateFit,
    smaller: &CandidateFit,
    warm: &[f64],
    reporting: &Reporting,
    pb: &Option<indicatif::ProgressBar>,
    note: &mut Option<String>,
) -> Result<CandidateFit> {
    if !fit.problem.cost_is_nll() || fit.cost <= smaller.cost || interrupt::stop_requested() {
        return Ok(fit);
    }
    let at_warm = fit.problem.cost_at(warm);
    if !at_warm.is_finite() || at_warm >= fit.cost {
        return Ok(fit);
    }
    let found = Optimised {
        u: warm.to_vec(),
        swarm_iters: fit.swarm_iters,
        polish_iters: fit.polish_iters,
        cost: at_warm,
        unconfirmed_ends: None,
    };
    let kept = format!(
        "its settled optimum ({:.3} nats) was less likely than {}'s, so it keeps that model's \
         optimum ({at_warm:.3} nats)",
        fit.cost,
        fit.candidate.nested_phrase(&smaller.candidate)
    );
    add_note(note, kept);
    let mut kept_fit = finish(
        fit.candidate,
        fit.free.clone(),
        fit.problem.clone(),
        found,
        (reporting, pb),
        Settling::AsFound,
    )?;
    kept_fit.search_cost = fit.search_cost;
    Ok(kept_fit)
}

/// Whether [`finish`] settles the likelihood's optimum or takes the search's end as it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Settling {
    /// [`super::evidence::settle`]: the optimum at the intervals' scale.
    Settle,
    /// The local fit at the search's end (a point already settled once).
    AsFound,
}

/// The last stage of a candidate's fit, from its search's best end: settling (`settling`) and
/// the sandwich with a likelihood ([`super::evidence::settle`]), else the cost's curvature; and
/// the search's history (its wall time and search note are the caller's).
fn finish(
    candidate: Candidate,
    free: Vec<FreeParam>,
    problem: Arc<SpectralProblem>,
    found: Optimised,
    (reporting, pb): (&Reporting, &Option<indicatif::ProgressBar>),
    settling: Settling,
) -> Result<CandidateFit> {
    let Optimised {
        u: mut best_u,
        swarm_iters,
        polish_iters,
        mut cost,
        ..
    } = found;
    let search_cost = cost;

    // The likelihood at the optimum → NLL for model choice, and the inverse Fisher information →
    // standard errors, correlations, identifiability; the cost's curvature where there is no
    // likelihood (a target job).
    reporting.stage(format_args!("curvature"));
    let n = best_u.len();
    let (sigma_u, corr, fisher, evidence) = if interrupt::stop_requested() {
        (
            vec![f64::NAN; n],
            vec![vec![f64::NAN; n]; n],
            None,
            Err(super::NoEvidence::Interrupted),
        )
    } else {
        // With the likelihood as the cost, the estimate is its optimum at the intervals' scale
        // ([`super::evidence::settle`]), not the ripple the polish stopped in.
        let local = if settling == Settling::Settle && problem.cost_is_nll() {
            super::evidence::settle(&problem, &best_u, cost).map(|(u, c, l)| {
                (best_u, cost) = (u, c);
                l
            })
        } else {
            super::evidence::at_fit(&problem, &best_u)
        };
        match local {
            Ok(l) => (
                l.sigma_u,
                l.corr,
                Some((l.curvature_sigma_u, l.curvature_corr)),
                Ok(l.nll),
            ),
            Err(e) => {
                let (s, c) = curvature(&problem, &best_u);
                (s, c, None, Err(super::NoEvidence::Failed(Arc::new(e))))
            }
        }
    };
    if let Some(pb) = pb {
        pb.set_position(reporting.base + problem.evaluations.load(Ordering::Relaxed) as u64);
    }
    let (fisher_sigma_u, fisher_corr) = fisher.unzip();
    Ok(CandidateFit {
        candidate,
        free,
        problem,
        best_u,
        sigma_u,
        corr,
        fisher_sigma_u,
        fisher_corr,
        rounding_widening: None,
        fisher_steps_u: None,
        evidence,
        swarm_iters,
        polish_iters,
        wall_time_s: 0.0,
        history: reporting.sorted_history(),
        cost,
        search_cost,
        search_note: None,
        unconfirmed: None,
        profile_walk: None,
        more_restarts_futile: false,
    })
}

/// A candidate's search whose best end no second end confirmed, its second batch of restarts
/// deferred ([`Confirmation::Deferred`]).
#[derive(Clone)]
pub(crate) struct Unconfirmed {
    /// The search ends' finite costs, nats.
    ends: Vec<f64>,
    reporting: Reporting,
}

/// The margin (nats) beyond the spread of its search ends by which a candidate with an
/// unconfirmed best end must trail the chosen one for [`confirm_deferred`] to leave it: 5 nats, an
/// AIC difference of 10, beyond which a model has "essentially no support" (Burnham & Anderson,
/// *Model Selection and Multimodel Inference*, 2nd ed. 2002, §2.6). A basin as far below the best
/// end as the ends spread above it would then still leave the candidate behind: on the shipped
/// recording head1dof trails blade2dof by far more than its ends spread.
pub const DEFERRED_CONFIRM_MARGIN_NATS: f64 = 5.0;

/// Why a candidate's deferred confirmation need not run ([`confirm_deferred`]), or `None` when it
/// must: `ends` are its search ends' finite costs (nats), `score_gap` its score (TIC) minus the chosen
/// candidate's (+∞ when it cannot be chosen). It is skipped when the candidate trails by more than
/// the spread of its ends plus [`DEFERRED_CONFIRM_MARGIN_NATS`] (in nats: half the TIC gap).
fn confirmation_skipped(ends: &[f64], score_gap: f64) -> Option<String> {
    let behind_nats = 0.5 * score_gap;
    let (lo, hi) = hopelessly_behind(ends, behind_nats)?;
    let why = if behind_nats.is_finite() {
        format!(
            "{behind_nats:.1} nats behind the chosen model, more than that spread + \
             {DEFERRED_CONFIRM_MARGIN_NATS} nats"
        )
    } else {
        "the candidate cannot be chosen".to_string()
    };
    Some(format!(
        "best search end unconfirmed (its {} ends span {lo:.1}–{hi:.1} nats), no more restarts: \
         {why}",
        ends.len()
    ))
}

/// The range `(lowest, highest)` of a search's ends `ends` (nats) when the search trails by
/// `behind_nats` more than their spread plus [`DEFERRED_CONFIRM_MARGIN_NATS`]: a basin as far
/// below the best end as the ends spread above it would still leave the candidate that far
/// behind, so more restarts could not make it the choice. A run that failed
/// ([`super::FAILED_COST`] or not finite) has no end. `None` otherwise (or when `behind_nats` is
/// NaN).
pub(crate) fn hopelessly_behind(ends: &[f64], behind_nats: f64) -> Option<(f64, f64)> {
    let (lo, hi) = ends
        .iter()
        .filter(|c| c.is_finite() && **c < super::FAILED_COST)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &c| {
            (lo.min(c), hi.max(c))
        });
    let beyond = behind_nats > (hi - lo) + DEFERRED_CONFIRM_MARGIN_NATS;
    (lo <= hi && beyond).then_some((lo, hi))
}

/// Runs the deferred second batch of restarts (`R..2R`) of each candidate whose best end is
/// unconfirmed, unless its AIC trails the chosen candidate's by more than
/// `2 · (spread of its ends + DEFERRED_CONFIRM_MARGIN_NATS)` or it cannot be chosen: then more
/// restarts of it could not change the choice, and its reason says so. `score_gaps[i]`: candidate
/// `i`'s score minus the chosen one's ([`crate::fit::select::score_gaps`]; +∞ when it cannot be chosen).
/// A batch that ends below the candidate's search end replaces it, and the candidate is settled
/// anew.
pub(crate) fn confirm_deferred(
    job: &LoadedJob,
    fits: &mut [CandidateFit],
    score_gaps: &[f64],
    pb: &Option<indicatif::ProgressBar>,
) -> Result<()> {
    let fit = &job.job.fit;
    for (f, &gap) in fits.iter_mut().zip(score_gaps) {
        let Some(unconfirmed) = f.unconfirmed.take() else {
            continue;
        };
        if interrupt::stop_requested() {
            break;
        }
        if let Some(note) = confirmation_skipped(&unconfirmed.ends, gap) {
            add_note(&mut f.search_note, note);
            f.more_restarts_futile = true;
            continue;
        }
        let started = std::time::Instant::now();
        let reporting = unconfirmed
            .reporting
            .resumed(f.problem.evaluations.load(Ordering::Relaxed));
        let runs = more_restarts(&f.problem, fit, fit.seed, Some(&reporting));
        let wall_time_s = f.wall_time_s;
        take_batch(f, runs, &reporting, pb)?;
        f.wall_time_s = wall_time_s + started.elapsed().as_secs_f64();
    }
    Ok(())
}

/// Before a candidate that extends another (`X+shoulder` on `X`, `X@law` on `X`) is chosen over
/// it, one more batch of `X`'s restarts runs (new seeds, [`restart_batch_from`]). The larger model
/// contains `X`'s optimum, so it wins on any recording where `X`'s search stopped short of that
/// optimum, with structure the blade need not have: on a departure scene two of `X`'s first three
/// restarts ended in one basin 7 nats above its optimum (a confirmed end, so no second batch ran)
/// and a shoulder was chosen that the blade lacks
/// (docs/validation.md, "Confirming the smaller model").
/// A batch that ends below `X`'s search end replaces it: `X` is settled anew, a candidate nested on
/// it polishes again from its new optimum ([`rewarm_nested`]) and keeps at least its likelihood
/// ([`keep_nested_above`]). The notes say what ran.
/// Each smaller candidate runs this batch once per fit (`confirmed[i]`, indexed like `fits`), so
/// a larger candidate chosen later (after the contact-angle scan) confirms the smaller ones it was
/// not yet weighed against.
/// Returns whether a candidate moved (the choice is then made again).
pub(crate) fn confirm_the_smaller(
    job: &LoadedJob,
    fits: &mut Vec<CandidateFit>,
    chosen: usize,
    confirmed: &mut [bool],
    pb: &Option<indicatif::ProgressBar>,
) -> Result<bool> {
    let fit = &job.job.fit;
    if fit.search.method != job::SearchMethod::Swarm {
        return Ok(false);
    }
    let larger = fits[chosen].candidate;
    let smaller: Vec<usize> = (0..fits.len())
        .filter(|&i| {
            !confirmed[i] && larger.extends(&fits[i].candidate) && fits[i].problem.cost_is_nll()
        })
        .collect();
    let mut moved = false;
    for i in smaller {
        if interrupt::stop_requested() {
            break;
        }
        confirmed[i] = true;
        let started = std::time::Instant::now();
        let f = &fits[i];
        let first = next_restart(f, fit);
        let reporting = Reporting::continuing(f, pb);
        let why = format!("{larger} chosen over it");
        let runs = restart_batch_from(&f.problem, fit, fit.seed, first, Some(&reporting), &why);
        let f = &mut fits[i];
        let (wall_time_s, search_cost) = (f.wall_time_s, f.search_cost);
        let (best_end, took) = take_batch(f, runs, &reporting, pb)?;
        add_note(
            &mut f.search_note,
            smaller_note(&larger, first, fit.restarts.max(1), best_end, search_cost),
        );
        f.wall_time_s = wall_time_s + started.elapsed().as_secs_f64();
        if took {
            rewarm_nested(fits, i, fit, pb)?;
            keep_nested_above(fits, i, pb)?;
            moved = true;
        }
    }
    Ok(moved)
}

/// A further batch of restarts `runs` of the candidate `f`: its best end replaces the candidate's
/// search end when lower, and the candidate is settled anew from it ([`settle_anew`]); otherwise
/// the batch's iterations and history are added to the candidate's. Returns the batch's best end
/// (nats; ∞ with none) and whether it was taken. The caller keeps the wall time.
fn take_batch(
    f: &mut CandidateFit,
    runs: Vec<Result<Option<Run>>>,
    reporting: &Reporting,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<(f64, bool)> {
    let mut best: Option<Run> = None;
    let (mut swarm_iters, mut polish_iters) = (0, 0);
    for run in runs {
        let Some(run) = run? else { continue };
        swarm_iters += run.swarm_iters;
        polish_iters += run.polish_iters;
        if best.as_ref().is_none_or(|b| run.cost < b.cost) {
            best = Some(run);
        }
    }
    let best_end = best.as_ref().map_or(f64::INFINITY, |r| r.cost);
    let lower = best_end < f.search_cost && !interrupt::stop_requested();
    let end = best.map(|r| (r.u, r.cost)).filter(|_| lower);
    continue_from(f, end, (swarm_iters, polish_iters), reporting, pb)?;
    Ok((best_end, lower))
}

/// The candidate `f` after further search work of `iterations` (swarm, polish): settled anew from
/// `end` ([`settle_anew`]) when there is one to take, else with the iterations and the history
/// added to its own.
fn continue_from(
    f: &mut CandidateFit,
    end: Option<Scored>,
    (swarm_iters, polish_iters): (u64, u64),
    reporting: &Reporting,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<()> {
    match end {
        Some((u, cost)) => {
            let found = Optimised {
                u,
                swarm_iters: f.swarm_iters + swarm_iters,
                polish_iters: f.polish_iters + polish_iters,
                cost,
                unconfirmed_ends: None,
            };
            settle_anew(f, found, reporting, pb)
        }
        None => {
            f.swarm_iters += swarm_iters;
            f.polish_iters += polish_iters;
            f.history = reporting.sorted_history();
            Ok(())
        }
    }
}

/// Each candidate nested on `fits[smaller]`, whose search started from the smaller model's earlier
/// optimum, polished again from the warm points of its new one ([`nested_warm_points`],
/// [`warm_polishes`]): a shoulder that adds to the smaller model's true basin is found from there,
/// not from the basin it has left. An end more than [`VALLEY_GAIN_NATS`] below the candidate's own
/// search end replaces it, and the candidate is settled anew; its note says what the polishes did.
fn rewarm_nested(
    fits: &mut [CandidateFit],
    smaller: usize,
    fit: &job::FitSection,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<()> {
    for j in 0..fits.len() {
        if !fits[j].candidate.extends(&fits[smaller].candidate) || interrupt::stop_requested() {
            continue;
        }
        let started = std::time::Instant::now();
        let warm = nested_warm_points(&fits[smaller], fits[j].candidate, &fits[j].free);
        let from = fits[smaller].candidate;
        let f = &fits[j];
        let reporting = Reporting::continuing(f, pb);
        if let Some(pb) = pb {
            pb.inc_length(warm.len() as u64 * polish_budget(fit, f.free.len()));
        }
        reporting.stage(format_args!("local search from {from}'s new optimum"));
        let (ends, iters) = warm_polishes(&f.problem, fit, &warm, &reporting)?;
        let best = ends.into_iter().min_by(|a, b| a.1.total_cmp(&b.1));
        let f = &mut fits[j];
        let (wall_time_s, search_cost) = (f.wall_time_s, f.search_cost);
        let best_cost = best.as_ref().map_or(f64::INFINITY, |b| b.1);
        let gained = best_cost < search_cost - VALLEY_GAIN_NATS && !interrupt::stop_requested();
        add_note(
            &mut f.search_note,
            format!(
                "{} polishes from {from}'s new optimum: best end {best_cost:.3} nats against its \
                 search end {search_cost:.3}{}",
                warm.len(),
                if gained {
                    ", so it continues from there"
                } else {
                    ", which stands"
                }
            ),
        );
        continue_from(f, best.filter(|_| gained), (0, iters), &reporting, pb)?;
        f.wall_time_s = wall_time_s + started.elapsed().as_secs_f64();
    }
    Ok(())
}

/// The first restart index no search of `f` has used: one past the highest swarm restart in its
/// history, and at least `[fit] restarts` (a nested candidate's warm polishes record none).
fn next_restart(f: &CandidateFit, fit: &job::FitSection) -> usize {
    f.history
        .iter()
        .filter(|h| h.stage == SearchStage::Swarm)
        .map(|h| h.restart + 1)
        .max()
        .unwrap_or(0)
        .max(fit.restarts.max(1))
}

/// What [`confirm_the_smaller`] did, for the smaller candidate's search note: restarts
/// `first..first + n` ran because `larger` was chosen over it, their best end `best_end` against
/// the search end `search_end` (nats).
fn smaller_note(
    larger: &Candidate,
    first: usize,
    n: usize,
    best_end: f64,
    search_end: f64,
) -> String {
    let verdict = if best_end < search_end {
        format!(
            "{:.3} nats below its search end ({search_end:.3}), so it continues from there",
            search_end - best_end
        )
    } else {
        format!("none below its search end ({search_end:.3}): the end stands")
    };
    format!(
        "{larger} was chosen over it, so restarts {}–{} ran first: best end {best_end:.3} nats, {verdict}",
        first + 1,
        first + n
    )
}

/// The search of one candidate: [`nested_search`] for a nested candidate searched adaptively (a
/// likelihood to gauge the local gain by), else [`optimise`]'s restarts. Returns [`optimise`]'s
/// tuple and the nested search's note. `nested`: the cost where the smaller model's search ended,
/// and how the reasons name that model, for a nested candidate.
fn search(
    job: &LoadedJob,
    problem: &Arc<SpectralProblem>,
    nested: Option<(f64, String)>,
    warm: &[Vec<f64>],
    reporting: &Reporting,
    confirming: Confirming,
) -> Result<(Optimised, Option<String>)> {
    let fit = &job.job.fit;
    if fit.search.method == job::SearchMethod::Cmaes {
        let (found, note) = cmaes_search(problem, fit, fit.seed, Some(reporting))?;
        return Ok((found, Some(note)));
    }
    let configured = nested.is_some()
        && fit.nested_search == job::NestedSearch::Adaptive
        && fit.objective == job::Objective::Likelihood
        && job.job.targets.is_none();
    if configured && problem.cost_is_nll() {
        return nested_search(problem, fit, warm, nested, reporting, confirming);
    }
    if configured && let Some(pb) = &reporting.progress {
        // The bar counted an adaptive search, but this problem has no likelihood to gauge it.
        let n = problem.free.len();
        pb.inc_length(
            restarts_budget(fit, n).saturating_sub(NESTED_WARM_POINTS * polish_budget(fit, n)),
        );
    }
    let found = optimise(problem, fit, fit.seed, warm, Some(reporting), confirming)?;
    Ok((found, None))
}

/// The NLL gain (nats) above which a nested candidate's local search is followed by the global one
/// ([`crate::job::NestedSearch::Adaptive`]): 0.1 nats, a likelihood-ratio statistic 2Δ = 0.2,
/// below the 10th percentile of χ²₂, the law the global search's statistic follows when the two
/// shoulder parameters add nothing. A smaller local gain says they do nothing near the smaller
/// model's optimum. The local gain is not a test of the shoulder: a real shoulder away from the
/// smaller model's optimum can give a local gain far from significant that the global search then
/// finds (the confusion table, `reports/model_choice/`), so a gain above the threshold only
/// decides whether the global search runs.
pub const NESTED_GLOBAL_GAIN_NATS: f64 = 0.1;

/// The adaptive search of a nested candidate: Nelder–Mead polishes from each of `warm` (in
/// parallel), then [`optimise`]'s global search only when the best of them lowers the cost (the
/// recording's NLL, nats) by more than [`NESTED_GLOBAL_GAIN_NATS`] below the first warm point (the
/// smaller model's optimum) or below the cost in `smaller`, where the smaller model's own search
/// ended, whichever is lower (its phrase names that model in the note). The warm point is the smaller model's settled optimum, at the centre
/// of the likelihood's bowl, where a polish descends by a ripple's depth (about 0.05–0.1 nats on the
/// main job) without any help from the shoulder; the gain is therefore read polish end against
/// polish end. Returns [`optimise`]'s tuple and a note for the model-choice reason.
fn nested_search(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    warm: &[Vec<f64>],
    smaller: Option<(f64, String)>,
    reporting: &Reporting,
    confirming: Confirming,
) -> Result<(Optimised, Option<String>)> {
    reporting.stage(format_args!("local search"));
    let at_warm = warm.first().map_or(f64::INFINITY, |w| problem.cost_at(w));
    let (smaller_search_cost, smaller) =
        smaller.unwrap_or((f64::INFINITY, "the smaller model".into()));
    let base = at_warm.min(smaller_search_cost);
    let mut local: Option<(Vec<f64>, f64)> = warm.first().map(|w| (w.clone(), at_warm));
    let mut ends = vec![at_warm, smaller_search_cost];
    let (polished, polish_iters) = warm_polishes(problem, fit, warm, reporting)?;
    for (u, cost) in polished {
        ends.push(cost);
        if local.as_ref().is_none_or(|b| cost < b.1) {
            local = Some((u, cost));
        }
    }
    let (u, cost) = local.ok_or(FitError::NoNestedStart)?;
    let gain = base - cost;
    let behind = match confirming {
        Confirming {
            when: Confirmation::Deferred,
            leader: Some(l),
        } if gain > NESTED_GLOBAL_GAIN_NATS => hopelessly_behind(&ends, cost - l).map(|_| cost - l),
        _ => None,
    };
    if let Some(behind_nats) = behind {
        // The global search is the deferred confirmation's second batch of restarts.
        let ends: Vec<f64> = ends.into_iter().filter(|c| c.is_finite()).collect();
        let note = format!(
            "local search ended {gain:.3} nats below {smaller}'s search (> \
             {NESTED_GLOBAL_GAIN_NATS}), {behind_nats:.1} nats behind the best candidate fitted \
             before it, more than its ends' spread + {DEFERRED_CONFIRM_MARGIN_NATS} nats: global \
             search only where it could change the choice"
        );
        let found = Optimised {
            u,
            swarm_iters: 0,
            polish_iters,
            cost,
            unconfirmed_ends: Some(ends),
        };
        return Ok((found, Some(note)));
    }
    if gain <= NESTED_GLOBAL_GAIN_NATS || interrupt::stop_requested() {
        let note = format!(
            "local search only: it ended {gain:.3} nats below {smaller}'s search, not more than {NESTED_GLOBAL_GAIN_NATS} nats: its extra parameters do \
             nothing near that model's optimum, so no global search"
        );
        let found = Optimised {
            u,
            swarm_iters: 0,
            polish_iters,
            cost,
            unconfirmed_ends: None,
        };
        return Ok((found, Some(note)));
    }
    if let Some(pb) = &reporting.progress {
        pb.inc_length(restarts_budget(fit, problem.free.len()));
    }
    // The leader was read above, for the decision to search globally at all.
    let own = Confirming {
        leader: None,
        ..confirming
    };
    let mut global = optimise(problem, fit, fit.seed, warm, Some(reporting), own)?;
    let note = format!(
        "global search: the local search ended {gain:.3} nats below {smaller}'s search (> \
         {NESTED_GLOBAL_GAIN_NATS})"
    );
    global.polish_iters += polish_iters;
    if cost <= global.cost {
        (global.u, global.cost) = (u, cost);
    }
    Ok((global, Some(note)))
}

/// Nelder–Mead polishes from each of `warm` (in parallel, each its own restart in the history):
/// their ends with their costs, in order, and the iterations they took (an interrupted polish has
/// no end).
fn warm_polishes(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    warm: &[Vec<f64>],
    reporting: &Reporting,
) -> Result<(Vec<Scored>, u64)> {
    use rayon::prelude::*;
    let observer = |r: usize| SearchObserver {
        stage: SearchStage::Polish,
        restart: r,
        reporting: reporting.clone(),
        evals: problem.evaluations.clone(),
        run_evals: Arc::new(AtomicUsize::new(0)),
    };
    let runs: Vec<Result<(Vec<f64>, u64, f64)>> = warm
        .par_iter()
        .enumerate()
        .map(|(r, w)| {
            polish(
                problem,
                w,
                POLISH_STEP_U,
                fit.polish_iterations,
                Some(observer(r)),
            )
        })
        .collect();
    let (mut ends, mut iterations) = (Vec::new(), 0);
    for run in runs {
        let (u, iters, cost) = match run {
            Err(_) if interrupt::stop_requested() => continue,
            other => other?,
        };
        iterations += iters;
        ends.push((u, cost));
    }
    Ok((ends, iterations))
}

/// Where a nested candidate (`X+shoulder`) starts: `X`'s optimum with k1_contact = k1, so that
/// the shoulder changes no moment. The first point has θ_c on its upper bound and the smaller
/// model's own normalised coordinates (bitwise its parameters and, while the neck stays below θ_c,
/// its simulation); it is also the point [`optimise`] keeps if no restart ends below it. The
/// next two put θ_c at the median and the 90th percentile of |θ| in the smaller model's simulation
/// (inside the contact-angle bounds): the same motion, but a polish from there feels k1_contact at
/// once, while from the first it must first bring θ_c into the range the neck visits. On the
/// confusion table's often-crossed shoulder (docs/validation.md, "Model choice") the search from the first point alone
/// does not leave blade2dof's optimum. The last [`RESTING_QUANTILES`] points read X's stiffness as
/// that of a neck resting on the shoulder: k1_contact = X's k1, the free k1 halfway (log scale)
/// between its lower bound and X's k1, and θ_c swept from the 10th to the 75th percentile of |θ|.
/// Beyond θ_c the moment is `k1_contact·|θ| + (k1 − k1_contact)·θ_c`: such a neck has X's stiffness
/// while it rests and is soft (k1) within ±θ_c, which it crosses at each reversal. The contact
/// angle sets how long that crossing lasts, and a polish from one contact angle stops at the first
/// ridge in it. Without a resting point the global search on the confusion table's neck resting on
/// a shoulder (0.025 rad) stops short of the truth's likelihood and chooses blade2dof; with one
/// resting point, the calibration recording cal_067's search stops short in the local polishes
/// (docs/validation.md, "Resting-neck starts of a shoulder candidate").
///
/// A candidate nested by its law (`X@exponential` in `X@exponential_viscous` or `X@stribeck`)
/// starts from the one point where its law is `X`'s: D = 0, or δ = 1 with v_s = 1/B.
fn nested_warm_points(
    smaller: &CandidateFit,
    larger: Candidate,
    free: &[FreeParam],
) -> Vec<Vec<f64>> {
    let mut params = smaller.problem.params_at(&smaller.best_u);
    if let Some(f) = larger.law.and_then(|l| params.friction.as_kind(l)) {
        params.friction = f;
    }
    let first: Vec<f64> = free
        .iter()
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
                f.name == source && f.lower == fp.lower && f.upper == fp.upper && f.log == fp.log
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
        .collect();
    let mut points = vec![first.clone()];
    if smaller.candidate.shoulder {
        return points;
    }
    let (Some(i), Some(abs_theta)) = (
        free.iter().position(|fp| fp.name == ParamId::ThetaC),
        sorted_abs_theta(smaller),
    ) else {
        return points;
    };
    for q in FREE_NECK_QUANTILES {
        let mut p = first.clone();
        p[i] = free[i].u_of(crate::spectrum::stats::quantile_sorted(&abs_theta, q));
        points.push(p);
    }
    points.extend(resting_neck_points(
        &first,
        free,
        &abs_theta,
        params.k1_nm_per_rad,
    ));
    points
}

/// `first` with X's neck stiffness `k1_x` (N·m/rad) read as the contact stiffness of a neck resting
/// on its shoulder, one point per [`RESTING_QUANTILES`] of `abs_theta` (X's |θ|, rad, ascending) as
/// the contact angle, the free k1 halfway (log scale) between its lower bound and `k1_x`. Empty
/// unless `free` holds k1, k1_contact and θ_c.
fn resting_neck_points(
    first: &[f64],
    free: &[FreeParam],
    abs_theta: &[f64],
    k1_x: f64,
) -> Vec<Vec<f64>> {
    let at = |id| free.iter().position(|fp| fp.name == id);
    let (Some(i), Some(j), Some(c)) = (at(ParamId::ThetaC), at(ParamId::K1), at(ParamId::K1c))
    else {
        return Vec::new();
    };
    RESTING_QUANTILES
        .iter()
        .map(|&q| {
            let mut p = first.to_vec();
            p[i] = free[i].u_of(crate::spectrum::stats::quantile_sorted(abs_theta, q));
            p[c] = free[c].u_of(k1_x);
            p[j] = free[j].u_of((free[j].lower * k1_x).sqrt());
            p
        })
        .collect()
}

/// |θ| of the neck in `fit`'s simulation at its optimum, finite samples in ascending order: where
/// a shoulder's contact angle would act on that motion. `None` when it cannot be simulated or has
/// no finite sample.
pub(crate) fn sorted_abs_theta(fit: &CandidateFit) -> Option<Vec<f64>> {
    let sim = fit
        .problem
        .simulate(&fit.problem.params_at(&fit.best_u))
        .ok()?;
    let mut abs_theta: Vec<f64> = sim
        .theta_rad
        .iter()
        .filter(|t| t.is_finite())
        .map(|t| t.abs())
        .collect();
    abs_theta.sort_by(f64::total_cmp);
    (!abs_theta.is_empty()).then_some(abs_theta)
}

/// The estimator: `restarts` independent runs of a particle swarm over `[0, 1]^n` (`particles`,
/// `swarm_iterations`; 0 iterations skips it and starts from the problem's centre), each followed by
/// a Nelder–Mead polish from its best particle; the run with the lowest cost is kept. Restart `r`
/// seeds its swarm with `seed ^ (r · 0x9E3779B97F4A7C15)`, so restart 0 is the single-run fit.
///
/// Restarts because the cost surface is rough: the stick–slip comb's largest line jumps as the
/// parameters move, so one swarm can settle in a nearby minimum: on the shipped recording a single
/// swarm ends in the truth's basin for some seeds and in a higher minimum for others
/// (docs/fit.md, "Restarts").
/// `warm`: points that one particle of restart `r`'s swarm starts at (`warm[r]`; the others at
/// random); the first is also returned itself if no restart ends below its cost.
/// With the likelihood as the cost and more than one restart, a best end that no second end
/// confirms ([`confirmed`]) runs the restarts once more (restarts `R..2R`, new seeds), at once or,
/// with [`Confirmation::Deferred`], when [`confirm_deferred`] finds it could change the choice.
pub(crate) fn optimise(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    seed: u64,
    warm: &[Vec<f64>],
    log: Option<&Reporting>,
    confirming: Confirming,
) -> Result<Optimised> {
    if fit.search.method == job::SearchMethod::Cmaes {
        return Ok(cmaes_search(problem, fit, seed, log)?.0);
    }
    let restarts = fit.restarts.max(1);
    if let Some(reporting) = log {
        if restarts > 1 {
            reporting.stage(format_args!("{restarts} restarts"));
        } else {
            reporting.stage(format_args!("swarm and polish"));
        }
    }
    // The warm point itself, at the polish's tolerance, is a candidate result: then a nested fit
    // cannot end above the smaller model's cost even when the swarm ranks points at a looser
    // tolerance (`[fit] swarm_rtol`) and leaves the warm particle's basin.
    let mut best: Option<(Vec<f64>, f64)> = warm.first().map(|w| (w.clone(), problem.cost_at(w)));
    let mut runs = restart_batch(problem, fit, seed, 0..restarts, warm, log);
    let mut ends: Vec<f64> = best.iter().map(|b| b.1).collect();
    ends.extend(
        runs.iter()
            .filter_map(|r| r.as_ref().ok()?.as_ref().map(|r| r.cost)),
    );
    let unconfirmed =
        restarts > 1 && problem.cost_is_nll() && !confirmed(&ends) && !interrupt::stop_requested();
    let deferred = unconfirmed && confirming.defers(&ends);
    if unconfirmed && !deferred {
        // No second restart reached the best one's basin: one more batch of restarts.
        runs.extend(more_restarts(problem, fit, seed, log));
    }
    let (mut swarm_iters, mut polish_iters) = (0, 0);
    for run in runs {
        let Some(run) = run? else { continue };
        swarm_iters += run.swarm_iters;
        polish_iters += run.polish_iters;
        if best.as_ref().is_none_or(|b| run.cost < b.1) {
            best = Some((run.u, run.cost));
        }
    }
    if interrupt::stop_requested()
        && let Some(seen) =
            log.and_then(|r| r.best.lock().unwrap_or_else(|e| e.into_inner()).clone())
        && best.as_ref().is_none_or(|b| seen.1 < b.1)
    {
        // Interrupted: the best point the observer saw in the unfinished runs.
        best = Some(seen);
    }
    let (u, cost) = best.ok_or_else(|| {
        if interrupt::stop_requested() {
            FitError::InterruptedEarly
        } else {
            FitError::NoRun
        }
    })?;
    Ok(Optimised {
        u,
        swarm_iters,
        polish_iters,
        cost,
        unconfirmed_ends: deferred.then(|| ends.into_iter().filter(|c| c.is_finite()).collect()),
    })
}

/// The CMA-ES search of one candidate ([`super::ipop`], `[fit.search]`): IPOP runs on the cost
/// ([`SearchStage::Cmaes`]: the recording's likelihood at the job's tolerance) over the normalised
/// box, seeded with `seed`. Each generation goes into the history (its run as the restart) and
/// moves the progress bar; an interrupt stops it at the next generation with the best point so
/// far. Returns the lowest point and a note on the runs for the candidate's reason.
fn cmaes_search(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    seed: u64,
    log: Option<&Reporting>,
) -> Result<(Optimised, String)> {
    let n = problem.free.len();
    let settings = super::ipop::Settings {
        population: fit.search.first_population(n),
        restarts: fit.search.restarts,
        max_evaluations: fit.search.max_evaluations,
        tol_fun: polish_sd(problem),
        seed,
    };
    if let Some(reporting) = log {
        reporting.stage(format_args!("CMA-ES"));
    }
    let cost = |u: &[f64]| problem.cost_at_stage(u, SearchStage::Cmaes);
    let mut observe = |g: super::ipop::Generation| {
        if let Some(reporting) = log {
            reporting.generation(SearchStage::Cmaes, g.run, &g, g.run_evaluations);
            if g.generation == 1 {
                reporting.stage(format_args!(
                    "CMA-ES run {} (λ = {})",
                    g.run + 1,
                    g.population
                ));
            }
            reporting.advance(problem.evaluations.load(Ordering::Relaxed));
            let mut best = reporting.best.lock().unwrap_or_else(|e| e.into_inner());
            if best.as_ref().is_none_or(|b| g.best_cost < b.1) {
                *best = Some((g.best_u.to_vec(), g.best_cost));
            }
        }
        !interrupt::stop_requested()
    };
    let found = super::ipop::search(n, &cost, &settings, &mut observe).ok_or_else(|| {
        if interrupt::stop_requested() {
            FitError::InterruptedEarly
        } else {
            FitError::NoRun
        }
    })?;
    let ends: Vec<String> = found
        .runs
        .iter()
        .map(|r| format!("{:.2}", r.cost))
        .collect();
    let populations: Vec<String> = found
        .runs
        .iter()
        .map(|r| r.population.to_string())
        .collect();
    let note = format!(
        "CMA-ES: {} run(s) of population {}, {} evaluations, run ends {} (cost)",
        found.runs.len(),
        populations.join(", "),
        found.evaluations,
        ends.join(", ")
    );
    let optimised = Optimised {
        u: found.u,
        swarm_iters: 0,
        polish_iters: 0,
        cost: found.cost,
        unconfirmed_ends: None,
    };
    Ok((optimised, note))
}

/// Restarts `range` of [`optimise`] (the warm point `warm[r]` for restart `r`), in parallel, in
/// restart order: independent runs (each its own seed), so both cores stay busy during the
/// polishes (Nelder–Mead evaluates one point at a time) and the result is the sequential one's.
fn restart_batch(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    seed: u64,
    range: std::ops::Range<usize>,
    warm: &[Vec<f64>],
    log: Option<&Reporting>,
) -> Vec<Result<Option<Run>>> {
    use rayon::prelude::*;
    range
        .into_par_iter()
        .map(|r| restart(problem, fit, seed, r, warm.get(r).map(Vec::as_slice), log))
        .collect()
}

/// The batch of restarts `R..2R` (new seeds, no warm points) that confirms or replaces an
/// unconfirmed best end ([`confirmed`]), with the progress bar's length and stage.
fn more_restarts(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    seed: u64,
    log: Option<&Reporting>,
) -> Vec<Result<Option<Run>>> {
    let restarts = fit.restarts.max(1);
    restart_batch_from(problem, fit, seed, restarts, log, "best unconfirmed")
}

/// The batch of restarts `first..first + R` (new seeds, no warm points), with the progress bar's
/// length and a stage saying `why` it runs.
fn restart_batch_from(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    seed: u64,
    first: usize,
    log: Option<&Reporting>,
    why: &str,
) -> Vec<Result<Option<Run>>> {
    let restarts = fit.restarts.max(1);
    if let Some(reporting) = log {
        if let Some(pb) = &reporting.progress {
            pb.inc_length(restarts_budget(fit, problem.free.len()));
        }
        reporting.stage(format_args!("{restarts} more restarts ({why})"));
    }
    restart_batch(problem, fit, seed, first..first + restarts, &[], log)
}

/// When a candidate's best search end is unconfirmed ([`confirmed`]): [`optimise`] runs its
/// second batch of restarts at once (`Now`: the candidate's optimum is needed before the next
/// candidate starts, or it is the only one), or leaves it to [`confirm_deferred`] once every
/// candidate is fitted (`Deferred`), which runs it only where it could change the model choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Confirmation {
    Now,
    Deferred,
}

/// How a candidate's search treats an unconfirmed best end: `when` ([`Confirmation`]), and
/// `leader`, the lowest cost (nats) of the candidates fitted before it ([`leader`]). A search
/// that ends hopelessly behind the leader ([`hopelessly_behind`]) defers its second batch even
/// when `Now`, and a nested candidate searched with `Deferred` its global search, to
/// [`confirm_deferred`], which runs them only where they could change the choice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Confirming {
    pub(crate) when: Confirmation,
    pub(crate) leader: Option<f64>,
}

impl Confirming {
    /// At once, measured against no other candidate (a single search).
    pub(crate) const NOW: Confirming = Confirming {
        when: Confirmation::Now,
        leader: None,
    };

    /// Whether the second batch of restarts of a search whose unconfirmed ends are `ends` (nats)
    /// is left to [`confirm_deferred`].
    fn defers(&self, ends: &[f64]) -> bool {
        match (self.when, self.leader) {
            (Confirmation::Deferred, _) => true,
            (Confirmation::Now, None) => false,
            (Confirmation::Now, Some(leader)) => {
                let best = ends.iter().copied().fold(f64::INFINITY, f64::min);
                hopelessly_behind(ends, best - leader).is_some()
            }
        }
    }
}

/// What [`optimise`] found.
pub(crate) struct Optimised {
    /// The best end, normalised coordinates.
    pub(crate) u: Vec<f64>,
    /// Iterations summed over the restarts.
    pub(crate) swarm_iters: u64,
    pub(crate) polish_iters: u64,
    /// The best end's cost (nats with the likelihood objective).
    pub(crate) cost: f64,
    /// With [`Confirmation::Deferred`], the search ends' finite costs when no second end confirms
    /// the best one.
    pub(crate) unconfirmed_ends: Option<Vec<f64>>,
}

/// The depth (nats) within which a second search end confirms the best one: 0.5 nats, the
/// likelihood's drop at one standard error of one parameter (the 68 % interval's edge), so two
/// ends that close lie in the same bowl at the intervals' scale. On the main job the restarts'
/// polishes end 0.08 nats apart (the ripple of one bowl) or 9 nats above (another basin).
pub const CONFIRM_NATS: f64 = 0.5;

/// Whether the lowest of the search ends `ends` (costs in nats: the restarts' and a warm point's)
/// is confirmed: a second end lies within [`CONFIRM_NATS`] of it. A best end no other restart
/// reaches is a basin the swarms find by chance, and a better one may lie where none looked, so
/// [`optimise`] then runs its restarts once more with new seeds (restarts `R..2R`).
pub(crate) fn confirmed(ends: &[f64]) -> bool {
    let mut e: Vec<f64> = ends.iter().copied().filter(|c| c.is_finite()).collect();
    e.sort_by(f64::total_cmp);
    e.len() < 2 || e[1] - e[0] <= CONFIRM_NATS
}

/// One restart's outcome.
struct Run {
    u: Vec<f64>,
    cost: f64,
    swarm_iters: u64,
    polish_iters: u64,
}

/// Restart `r` of [`optimise`]: a particle swarm seeded with `seed ^ (r · 0x9E3779B97F4A7C15)` (its
/// first particle at `warm`), then a Nelder–Mead polish from its best particle.
/// `None` when interrupted.
fn restart(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    seed: u64,
    r: usize,
    warm: Option<&[f64]>,
    log: Option<&Reporting>,
) -> Result<Option<Run>> {
    let n = problem.free.len();
    let fit_err = FitError::Optimiser;
    let run_evals = Arc::new(AtomicUsize::new(0));
    let observer = |stage: SearchStage| {
        log.map(|reporting| SearchObserver {
            stage,
            restart: r,
            reporting: reporting.clone(),
            evals: problem.evaluations.clone(),
            run_evals: run_evals.clone(),
        })
    };
    let run_seed = seed ^ (r as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let pso = ParticleSwarm::new((vec![0.0; n], vec![1.0; n]), fit.particles)
        .with_rng_generator(rand::rngs::StdRng::seed_from_u64(run_seed));
    let population = match warm {
        Some(w) if fit.particles > 0 => Some(warm_population(problem, w, fit.particles, run_seed)),
        _ => None,
    };
    let mut ex = Executor::new(
        Shared(problem.clone(), SearchStage::Swarm, run_evals.clone()),
        pso,
    )
    .configure(|s| {
        let s = s.max_iters(fit.swarm_iterations);
        match population {
            Some(p) => s.population(p),
            None => s,
        }
    });
    if let Some(o) = observer(SearchStage::Swarm) {
        ex = ex.add_observer(o, ObserverMode::Always);
    }
    let res = match ex.run() {
        Ok(res) => res,
        Err(_) if interrupt::stop_requested() => return Ok(None),
        Err(e) => return Err(fit_err(e).into()),
    };
    let swarm_best = res
        .state()
        .get_best_param()
        .map(|p| p.position.clone())
        .ok_or(FitError::NoParticle)?;
    let swarm_iters = res.state().get_iter();
    let run = (run_seed, r, &run_evals);
    let Some((mut u, mut polish_iters, mut cost)) =
        local_route(problem, fit, &swarm_best, run, Route::Joint, log)?
    else {
        return Ok(None);
    };
    if fit.search.local == job::LocalSearch::Cmaes && problem.signal_likelihood.is_some() {
        let Some(second) = local_route(problem, fit, &swarm_best, run, Route::Signal, log)? else {
            return Ok(None);
        };
        polish_iters += second.1;
        if second.2 < cost {
            (u, cost) = (second.0, second.2);
        }
    }
    Ok(Some(Run {
        u,
        cost,
        swarm_iters,
        polish_iters,
    }))
}

/// Which likelihood a restart's local CMA-ES run reads ([`local_route`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Route {
    /// The polish's own cost.
    Joint,
    /// In a fit that reads further signals, the measured signal's own likelihood
    /// ([`SpectralProblem::signal_likelihood`]).
    Signal,
}

/// One local route of restart `r` from its swarm's best particle `start`: the local CMA-ES run
/// (`[fit.search] local = "cmaes"`) on the likelihood `route` names, then the Nelder–Mead polish
/// on the job's cost: its end, the polish's iterations and its cost, `None` when interrupted.
///
/// A fit that reads further signals runs both routes and keeps the lower end: the further
/// signals sharpen the likelihood until its basin around the truth can be too narrow for a local
/// run from the swarm's best to find, while the signal's own, wider basins lead there; on other
/// recordings the signal's own basins lead away from it (docs/fit.md, "The local CMA-ES stage").
fn local_route(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    start: &[f64],
    run: (u64, usize, &Arc<AtomicUsize>),
    route: Route,
    log: Option<&Reporting>,
) -> Result<Option<(Vec<f64>, u64, f64)>> {
    let (local, polishing) = match route {
        Route::Joint => (SearchStage::Local, SearchStage::Polish),
        Route::Signal => (SearchStage::SignalLocal, SearchStage::SignalPolish),
    };
    let from = match fit.search.local {
        job::LocalSearch::NelderMead => start.to_vec(),
        job::LocalSearch::Cmaes => match local_cmaes(problem, fit, start, run, local, log) {
            Some(u) => u,
            None if interrupt::stop_requested() => return Ok(None),
            None => start.to_vec(),
        },
    };
    let observer = log.map(|reporting| SearchObserver {
        stage: polishing,
        restart: run.1,
        reporting: reporting.clone(),
        evals: problem.evaluations.clone(),
        run_evals: run.2.clone(),
    });
    match polish(
        problem,
        &from,
        POLISH_STEP_U,
        fit.polish_iterations,
        observer,
    ) {
        Ok(p) => Ok(Some(p)),
        Err(_) if interrupt::stop_requested() => Ok(None),
        Err(e) => Err(e),
    }
}

/// The local CMA-ES run of restart `r` from its swarm's best particle `start`
/// (`[fit.search] local = "cmaes"`, [`super::ipop::local`]) on the cost of `stage`
/// ([`SearchStage::Local`] or [`SearchStage::SignalLocal`]), its generations in the history
/// under that stage: the run's lowest point, `None` when no generation finished (interrupted).
/// The Nelder–Mead polish then goes on from it. `run`: the run's seed, the restart and its
/// evaluation counter.
fn local_cmaes(
    problem: &Arc<SpectralProblem>,
    fit: &job::FitSection,
    start: &[f64],
    (seed, r, run_evals): (u64, usize, &Arc<AtomicUsize>),
    stage: SearchStage,
    log: Option<&Reporting>,
) -> Option<Vec<f64>> {
    let cost = |u: &[f64]| {
        run_evals.fetch_add(1, Ordering::Relaxed);
        problem.cost_at_stage(u, stage)
    };
    let mut observe = |g: super::ipop::Generation| {
        if let Some(reporting) = log {
            reporting.generation(stage, r, &g, run_evals.load(Ordering::Relaxed));
            reporting.advance(problem.evaluations.load(Ordering::Relaxed));
        }
        !interrupt::stop_requested()
    };
    let sd = polish_sd(problem);
    super::ipop::local(
        start,
        &cost,
        fit.search.local_evaluations,
        sd,
        seed,
        &mut observe,
    )
    .map(|found| found.u)
}

/// A swarm's first population with one particle at `warm` and the others drawn uniformly over
/// `[0, 1]^n` (velocities uniform in `[−1, 1]^n`, as argmin draws them); costs evaluated in parallel.
pub(crate) fn warm_population(
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

/// When a polish of the likelihood stops: the standard deviation of the cost over the simplex's
/// vertices below 0.05 nats (or `polish_iterations`). That is the depth of the ripples the
/// stick–slip likelihood has at a scale far below its intervals (between points σ/50 apart on the
/// main job's fit; docs/validation.md), so a
/// simplex that small only walks from ripple to ripple; the settling that follows fits the bowl
/// over ±1σ ([`super::evidence::settle`]).
pub const POLISH_SD_NATS: f64 = 0.05;

/// The edge of a polish's initial simplex, normalised units: every polish of the fit (after a
/// swarm, from a warm point, down a valley), of a bootstrap replicate and of a profile step.
pub(crate) const POLISH_STEP_U: f64 = 0.05;

/// When a polish of any other cost (the feature cost, a target job's) stops: the standard
/// deviation of its values over the simplex's vertices below 1e-3.
const POLISH_SD_OTHER: f64 = 1e-3;

/// Nelder–Mead from `start` with an initial simplex of edge `step` (normalised units), stopping at
/// [`POLISH_SD_NATS`] with the likelihood, [`POLISH_SD_OTHER`] otherwise, or after `iterations`.
pub(crate) fn polish(
    problem: &Arc<SpectralProblem>,
    start: &[f64],
    step: f64,
    iterations: u64,
    observer: Option<SearchObserver>,
) -> Result<(Vec<f64>, u64, f64)> {
    let run_evals = observer
        .as_ref()
        .map_or_else(|| Arc::new(AtomicUsize::new(0)), |o| o.run_evals.clone());
    let cost = Shared(problem.clone(), SearchStage::Polish, run_evals);
    nelder_mead(cost, start, step, polish_sd(problem), iterations, observer)
}

/// Nelder–Mead on `cost` from `start` with an initial simplex of edge `step`, stopping when the
/// simplex's costs spread by less than `sd` or after `iterations`: the best point (clamped to the
/// unit box), the iterations made and the best cost.
fn nelder_mead<C, O>(
    cost: C,
    start: &[f64],
    step: f64,
    sd: f64,
    iterations: u64,
    observer: Option<O>,
) -> Result<(Vec<f64>, u64, f64)>
where
    C: CostFunction<Param = Vec<f64>, Output = f64>,
    O: Observe<IterState<Vec<f64>, (), (), (), (), f64>> + 'static,
{
    let fit_err = FitError::Optimiser;
    let nm = NelderMead::new(initial_simplex(start, step))
        .with_sd_tolerance(sd)
        .map_err(fit_err)?;
    let mut ex = Executor::new(NoInterruptError(cost), nm).configure(|s| s.max_iters(iterations));
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

/// A cost for argmin's Nelder–Mead, which unwraps the costs of its first simplex: an interrupt's
/// error there would panic, so it becomes the failure cost, which no vertex ranks below. Each later
/// evaluation is then a failure too, made at once without a simulation, and the simplex keeps the
/// best point it had.
struct NoInterruptError<C>(C);

impl<C: CostFunction<Param = Vec<f64>, Output = f64>> CostFunction for NoInterruptError<C> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, u: &Vec<f64>) -> std::result::Result<f64, argmin::core::Error> {
        match self.0.cost(u) {
            Err(_) if interrupt::stop_requested() => Ok(super::problem::FAILED_COST),
            other => other,
        }
    }
}

/// Where [`polish`] starts: `start` and, for each coordinate, `start` moved by `step` (back by
/// `step` where forward would leave the unit box).
fn initial_simplex(start: &[f64], step: f64) -> Vec<Vec<f64>> {
    let mut simplex = vec![start.to_vec()];
    for i in 0..start.len() {
        let mut v = start.to_vec();
        v[i] = if v[i] + step <= 1.0 {
            v[i] + step
        } else {
            v[i] - step
        };
        simplex.push(v);
    }
    simplex
}

/// The spread of the simplex's costs at which [`polish`] stops.
fn polish_sd(problem: &SpectralProblem) -> f64 {
    if problem.cost_is_nll() {
        POLISH_SD_NATS
    } else {
        POLISH_SD_OTHER
    }
}

/// [`polish`] of every coordinate but `index`, which is held at `u_held`: the minimum of the cost
/// over the others from `start` (full coordinates; its `index` entry is replaced), stopping when
/// the simplex's costs spread by less than [`polish`]'s limit or `jitter_nats`, whichever is
/// larger (a simplex cannot settle below the cost's own jitter, [`super::jitter`]). Returns the
/// full coordinates of the best point and its cost.
pub(crate) fn polish_pinned(
    problem: &Arc<SpectralProblem>,
    start: &[f64],
    (index, u_held): (usize, f64),
    (step, jitter_nats): (f64, f64),
    iterations: u64,
    progress: Option<ProgressObserver>,
) -> Result<(Vec<f64>, f64)> {
    let mut others = start.to_vec();
    others.remove(index);
    let counter = progress
        .as_ref()
        .map_or_else(|| Arc::new(AtomicUsize::new(0)), |o| o.evals.clone());
    let pinned = Pinned {
        shared: Shared(problem.clone(), SearchStage::Polish, counter),
        index,
        u: u_held,
    };
    let sd = polish_sd(problem).max(jitter_nats);
    let (best, _, cost) = nelder_mead(pinned.clone(), &others, step, sd, iterations, progress)?;
    Ok((pinned.full(&best), cost))
}

/// Finite-difference curvature of the cost at `u0` (step 0.03 in normalised units, stencil kept
/// inside the box). Returns the 1σ half-widths in normalised units from the
/// covariance `2 H⁻¹` (cost read as χ²), and the correlation matrix.
pub(crate) fn curvature(problem: &SpectralProblem, u0: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
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

    /// The main job (`fits/reversal.toml`) and its blade2dof problem on the shipped recording.
    fn main_job_problem() -> (LoadedJob, Candidate, Arc<SpectralProblem>) {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let job = LoadedJob::load(&root.join("fits/reversal.toml")).expect("main job");
        let candidate: Candidate = "blade2dof".parse().expect("candidate");
        let problem = Arc::new(problem_for(&job, candidate).expect("problem"));
        (job, candidate, problem)
    }

    /// The progress bar counts each restart's local CMA-ES run at its cap: with the main job's
    /// settings (3 restarts of 24 particles × 26 swarm iterations, a local run of at most 1,000
    /// evaluations, a polish of 4 + 1 + 2 × 60 over 4 parameters) 3 × (624 + 1,000 + 125) = 5,247
    /// runs, against 3 × 749 without the local stage.
    #[test]
    fn restarts_budget_counts_the_local_stage() {
        let (job, _, _) = main_job_problem();
        let fit = &job.job.fit;
        assert_eq!(fit.search.local, job::LocalSearch::Cmaes);
        assert_eq!(restarts_budget(fit, 4), 5_247);
        let mut nelder_mead = fit.clone();
        nelder_mead.search.local = job::LocalSearch::NelderMead;
        assert_eq!(restarts_budget(&nelder_mead, 4), 2_247);
    }

    /// The smaller candidate's note names the restarts 1-based and says whether the batch moved
    /// its end (costs chosen by hand: one end below, one above).
    #[test]
    fn the_smaller_candidates_note_says_what_its_batch_found() {
        let larger: Candidate = "blade2dof+shoulder".parse().expect("candidate");
        let moved = smaller_note(&larger, 3, 3, 81.472, 88.532);
        assert!(moved.contains("restarts 4–6"), "{moved}");
        assert!(
            moved.contains("7.060 nats below its search end (88.532)"),
            "{moved}"
        );
        let stood = smaller_note(&larger, 6, 3, 90.0, 88.5);
        assert!(stood.contains("restarts 7–9"), "{stood}");
        assert!(stood.contains("the end stands"), "{stood}");
    }

    /// The resting-neck starts: the contact stiffness is X's k1, so beyond θ_c the neck is as stiff
    /// as X's; θ_c sweeps X's |θ| from its 10th to its 75th percentile (here |θ| = 0.01, 0.02, …,
    /// 0.10 rad, whose percentiles by linear interpolation are 0.019, 0.0325, 0.055, 0.0775 rad);
    /// the free k1 is the geometric mean of its lower bound and X's k1.
    #[test]
    fn resting_neck_starts_sweep_the_contact_angle_at_the_neck_s_stiffness() {
        let free = [
            FreeParam::new(ParamId::A, 0.2, 1.5),
            FreeParam::new(ParamId::K1, 0.005, 0.15),
            FreeParam::new(ParamId::ThetaC, 0.005, 0.2),
            FreeParam::new(ParamId::K1c, 0.005, 0.15),
        ];
        let abs_theta: Vec<f64> = (1..=10).map(|k| 0.01 * k as f64).collect();
        let first = vec![0.3, 0.6, 1.0, 0.6];
        let points = resting_neck_points(&first, &free, &abs_theta, 0.08);
        let theta_c: Vec<f64> = points.iter().map(|p| free[2].value(p[2])).collect();
        for (got, want) in theta_c.iter().zip([0.019, 0.0325, 0.055, 0.0775]) {
            assert!((got - want).abs() < 1e-12, "{theta_c:?}");
        }
        for p in &points {
            assert_eq!(p[0], first[0], "A stays X's");
            assert!((free[3].value(p[3]) - 0.08).abs() < 1e-12);
            assert!((free[1].value(p[1]) - (0.005f64 * 0.08).sqrt()).abs() < 1e-12);
        }
        assert!(resting_neck_points(&first, &free[..3], &abs_theta, 0.08).is_empty());
    }

    /// The normalised coordinates of `value(name)` for every freed parameter of `problem`.
    fn coordinates(problem: &SpectralProblem, value: impl Fn(&str) -> f64) -> Vec<f64> {
        problem
            .free
            .iter()
            .map(|f| f.u_of(value(f.name.name())))
            .collect()
    }

    /// A file of the repository, as text.
    fn repository_file(path: &str) -> String {
        std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path))
            .expect(path)
    }

    /// [`descend_the_valley`] from `end` with the main job's settings and 4 valley polishes.
    fn descend_four(
        job: &LoadedJob,
        candidate: Candidate,
        problem: &Arc<SpectralProblem>,
        end: Optimised,
    ) -> Optimised {
        descend_the_valley(
            problem,
            &job.job.fit,
            4,
            end,
            &Reporting::new(&None, candidate),
        )
        .expect("descent")
        .0
    }

    /// A search end at `u`, its cost read there.
    fn end_at(problem: &SpectralProblem, u: Vec<f64>) -> Optimised {
        let cost = problem.cost_at(&u);
        Optimised {
            u,
            swarm_iters: 0,
            polish_iters: 0,
            cost,
            unconfirmed_ends: None,
        }
    }

    /// `[fit.search] swarm_cost`: by default the swarm ranks the shipped recording's truth
    /// (`data/reversal/truth.json`) by the feature cost, a sum of squared log errors of order one
    /// there; with `"likelihood"` by the recording's NLL, the polish's own cost (tens of nats)
    /// whenever the two stages simulate at one tolerance.
    #[test]
    fn the_swarm_ranks_by_the_cost_the_job_names() {
        let (job, candidate, _) = main_job_problem();
        let truth: serde_json::Value =
            serde_json::from_str(&repository_file("data/reversal/truth.json")).expect("truth json");
        let mut problem = problem_for(&job, candidate).expect("problem");
        problem.swarm_solver = problem.solver;
        let u = coordinates(&problem, |name| {
            truth["params"][name].as_f64().expect("true value")
        });
        let nll = problem.cost_at_stage(&u, SearchStage::Polish);
        let features = problem.cost_at_stage(&u, SearchStage::Swarm);
        problem.swarm_cost = job::SwarmCost::Likelihood;
        let by_likelihood = problem.cost_at_stage(&u, SearchStage::Swarm);
        assert_eq!(by_likelihood, nll, "the swarm's likelihood is the polish's");
        assert!(
            features < 2.0 && nll > 20.0,
            "feature cost {features:.3} against NLL {nll:.3} nats at the truth"
        );
    }

    /// `[fit.search] local_rtol = 1e-7` in the main job (`fits/reversal.toml`, `[solver]` rtol
    /// 1e-8, atol 1e-10): the local stage simulates at rtol 1e-7 with atol scaled alike (1e-9),
    /// so its cost at the truth differs from the polish's; only the polish's point enters the
    /// near-best points the intervals read, whose costs must be the job's own.
    #[test]
    fn the_local_stage_simulates_at_its_own_tolerance_and_keeps_no_near_best_point() {
        let (job, candidate, _) = main_job_problem();
        let truth: serde_json::Value =
            serde_json::from_str(&repository_file("data/reversal/truth.json")).expect("truth json");
        let problem = problem_for(&job, candidate).expect("problem");
        assert_eq!(problem.local_solver.rtol, 1e-7);
        assert!((problem.local_solver.atol / 1e-9 - 1.0).abs() < 1e-12);
        assert_eq!(problem.solver.rtol, 1e-8);
        let u = coordinates(&problem, |name| {
            truth["params"][name].as_f64().expect("true value")
        });
        let near = |p: &SpectralProblem| p.near_best.lock().unwrap().at_most(f64::INFINITY).count();
        let local = problem.cost_at_stage(&u, SearchStage::Local);
        assert_eq!(
            near(&problem),
            0,
            "a local-stage point kept among the near-best"
        );
        let polish = problem.cost_at_stage(&u, SearchStage::Polish);
        assert_eq!(near(&problem), 1, "the polish's point not kept");
        assert!(local.is_finite() && polish.is_finite());
        assert_ne!(local, polish, "rtol 1e-7 and 1e-8 gave the same cost");
    }

    /// A fit that reads head y beside tip − head x keeps the signal's own likelihood for its
    /// second local route ([`local_route`]): at the shipped recording's truth
    /// (`data/reversal/truth.json`) that stage's cost is the one-signal problem's local-stage cost
    /// (same signal, noise model and tolerance), below the joint one by head y's own terms, and
    /// none of its points enters the near-best points, whose costs are the joint likelihood's.
    #[test]
    fn the_signal_route_reads_the_signals_own_likelihood_and_keeps_no_near_best_point() {
        let (mut job, candidate, one) = main_job_problem();
        assert!(
            one.signal_likelihood.is_none(),
            "one signal needs no second"
        );
        job.job.fit.likelihood.joint_signals = vec![crate::spectrum::features::SignalKind::HeadY];
        let joint = problem_for(&job, candidate).expect("joint problem");
        assert!(joint.signal_likelihood.is_some());
        let truth: serde_json::Value =
            serde_json::from_str(&repository_file("data/reversal/truth.json")).expect("truth json");
        let u = coordinates(&joint, |name| {
            truth["params"][name].as_f64().expect("true value")
        });
        let own = joint.cost_at_stage(&u, SearchStage::SignalLocal);
        let alone = one.cost_at_stage(&u, SearchStage::Local);
        assert!(
            (own - alone).abs() <= 1e-9 * alone.abs().max(1.0),
            "{own} against {alone}"
        );
        let near = |p: &SpectralProblem| p.near_best.lock().unwrap().at_most(f64::INFINITY).count();
        assert_eq!(
            near(&joint),
            0,
            "a signal-route point kept among the near-best"
        );
        let both = joint.cost_at_stage(&u, SearchStage::Local);
        assert!(
            both - own > 10.0,
            "joint {both} against the signal's own {own}"
        );
        joint.cost_at_stage(&u, SearchStage::SignalPolish);
        assert_eq!(near(&joint), 1, "the signal route's polish point not kept");
    }

    /// A polish cut short (10 iterations) from A ×0.9 and B ×0.85 of the truth
    /// (`data/reversal/truth.json`; C and k1 true), in the A–B valley of the shipped recording's
    /// likelihood, ends above the valley's floor, and the fresh polishes of
    /// [`descend_the_valley`] go on down it by more than [`VALLEY_GAIN_NATS`].
    #[test]
    fn fresh_polishes_go_on_down_the_valley() {
        let (job, candidate, problem) = main_job_problem();
        let truth: serde_json::Value =
            serde_json::from_str(&repository_file("data/reversal/truth.json")).expect("truth json");
        let start = coordinates(&problem, |name| {
            let v = truth["params"][name].as_f64().expect("true value");
            v * match name {
                "A" => 0.9,
                "B" => 0.85,
                _ => 1.0,
            }
        });
        let (u, _, cost) = polish(&problem, &start, 0.05, 10, None).expect("polish");
        let down = descend_four(&job, candidate, &problem, end_at(&problem, u));
        assert!(
            down.cost < cost - VALLEY_GAIN_NATS,
            "the short polish ended at {cost:.3} nats, the valley's polishes at {:.3}",
            down.cost
        );
    }

    /// At the main job's settled optimum (`fits/reversal.result.toml`, written by `wiperlab fit
    /// fits/reversal.toml`) a fresh polish gains less than [`VALLEY_GAIN_NATS`], so the end stays
    /// as it was, bit for bit (the main job's result does not move).
    #[test]
    fn at_the_main_jobs_optimum_the_end_is_kept() {
        let (job, candidate, problem) = main_job_problem();
        let result: toml::Value =
            toml::from_str(&repository_file("fits/reversal.result.toml")).expect("result toml");
        let fitted = result["parameters"].as_array().expect("parameters").clone();
        let start = coordinates(&problem, |name| {
            fitted
                .iter()
                .find(|p| p["name"].as_str() == Some(name))
                .and_then(|p| p["value"].as_float())
                .expect("fitted value")
        });
        let at_fit = end_at(&problem, start.clone());
        let cost = at_fit.cost;
        let kept = descend_four(&job, candidate, &problem, at_fit);
        assert_eq!(
            kept.u, start,
            "no gain beyond {VALLEY_GAIN_NATS} nats: the end stays"
        );
        assert_eq!(kept.cost, cost);
        assert!(kept.polish_iters > 0, "one polish ran");
    }

    #[test]
    fn a_deferred_confirmation_is_skipped_only_when_no_better_end_could_change_the_choice() {
        // The shipped recording's head1dof: five ends 530.9–587.4 nats, 452.6 nats (AIC 905.2)
        // behind blade2dof (fits/reversal.result.toml).
        let ends = [587.357, 551.579, 544.633, 556.500, 530.915];
        let note = confirmation_skipped(&ends, 905.23).expect("far behind: skipped");
        assert!(
            note.contains("530.9–587.4") && note.contains("452.6 nats"),
            "{note}"
        );
        // The chosen candidate itself, and one within the spread + margin, are confirmed.
        assert!(confirmation_skipped(&ends, 0.0).is_none());
        let edge = 2.0 * (587.357 - 530.915 + DEFERRED_CONFIRM_MARGIN_NATS);
        assert!(confirmation_skipped(&ends, 0.999 * edge).is_none());
        assert!(confirmation_skipped(&ends, 1.001 * edge).is_some());
        // One that cannot be chosen is never worth more restarts; a NaN gap runs them.
        let never = confirmation_skipped(&ends, f64::INFINITY).unwrap();
        assert!(never.contains("cannot be chosen"), "{never}");
        assert!(confirmation_skipped(&ends, f64::NAN).is_none());
    }

    #[test]
    fn a_search_is_hopelessly_behind_only_beyond_the_spread_of_its_finite_ends() {
        // Shaped like a head-only recording's blade2dof+shoulder (calibration cal_091): the smaller
        // model's search end, a warm point that could not be simulated, a polish that failed, two
        // local polish ends, and the candidate 2533.7 nats behind head1dof.
        let ends = [
            2914.0,
            f64::INFINITY,
            super::super::FAILED_COST,
            2602.67,
            2750.0,
        ];
        assert_eq!(hopelessly_behind(&ends, 2533.7), Some((2602.67, 2914.0)));
        let edge = 2914.0 - 2602.67 + DEFERRED_CONFIRM_MARGIN_NATS;
        assert!(hopelessly_behind(&ends, 0.999 * edge).is_none());
        assert!(hopelessly_behind(&ends, 1.001 * edge).is_some());
        // No finite end, or no gap to read: never behind.
        assert!(hopelessly_behind(&[f64::INFINITY], 1e9).is_none());
        assert!(hopelessly_behind(&ends, f64::NAN).is_none());
    }

    #[test]
    fn a_best_end_is_confirmed_only_by_a_second_end_in_its_bowl() {
        // The main job's five restarts (fits/reversal.result.toml's history): three ends within
        // 0.11 nats of the best, one in another basin 9 nats up.
        assert!(confirmed(&[78.2596, 78.2834, 78.1798, 87.1792, 78.2786]));
        // The confusion table's head-only scene (docs/validation.md, "Model choice"): the best end 7.7 nats below the
        // next one, a basin one restart of five found.
        assert!(!confirmed(&[106.30, 70.82, 79.32, 78.55, 78.58]));
        // The threshold is CONFIRM_NATS, failed runs (infinite cost) confirm nothing, and a single
        // end has nothing to be compared with.
        assert!(confirmed(&[10.0, 10.0 + CONFIRM_NATS]));
        assert!(!confirmed(&[10.0, 10.0 + 1.001 * CONFIRM_NATS]));
        assert!(!confirmed(&[10.0, f64::INFINITY, 12.0]));
        assert!(confirmed(&[10.0, f64::NAN]));
    }
}
