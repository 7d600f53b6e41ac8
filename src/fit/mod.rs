//! Fitting the friction law (A, B, C) and the neck stiffness (and any other blade parameter a job
//! frees) so that the model's spectra match the measured ones.
//!
//! This stage runs a job: each candidate model searched ([`crate::search`]), the model chosen
//! ([`select`]), the chosen optimum checked against the integrator's tolerance ([`tolerance`]) and
//! the job's truth ([`truth`]), its intervals ([`crate::uncertainty`]) and warnings attached
//! ([`warning`]), and the [`FitResult`] assembled ([`result`]).

/// The spectral features the fit compares (they belong to the spectrum stage).
pub use crate::spectrum::features;
mod drive;
pub mod result;
pub mod select;
pub mod tolerance;
pub mod truth;
pub mod warning;

pub use crate::search::{FitError, NoEvidence, NoLikelihood};
pub use result::{
    FitResult, FittedParam, HistoryPoint, Interval, IntervalMethod, ModelTrial, PeakComparison,
    RatioTest, SearchStage, SpreadSource, TrialEvidence,
};
pub use select::aic;
pub use truth::SHORTFALL_TOLERANCE_NATS;
pub use warning::{FitWarning, Severity, Warnings};

use crate::Result;
use crate::job::{self, LoadedJob};
use crate::likelihood;
use crate::likelihood::measure::measure;
use crate::model::BladeParams;
use crate::search::strategy::{
    self as search, CandidateFit, confirm_deferred, confirm_the_smaller, descend_chosen,
    fit_candidates, progress_bar,
};
use crate::search::{SpectralProblem, interrupt, scan};
use crate::simulate::blade::BladeSimulation;
use crate::trace::Trace;
use crate::uncertainty::{self, climb, identifiability_warnings};
use features::{Features, SignalKind};
use std::sync::atomic::Ordering;

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

/// The choice among the candidates `fits` ([`select::choose`]), made again when the chosen one
/// descended to a more likely point ([`descend_chosen`]).
fn choose_descended(
    job: &LoadedJob,
    fits: &mut Vec<CandidateFit>,
    explicit: bool,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<select::Selection> {
    let bands = &job.job.spectrum.bands;
    let selection = select::choose(fits, bands, explicit, &[]);
    Ok(if descend_chosen(job, fits, selection.chosen, pb)? {
        select::choose(fits, bands, explicit, &[])
    } else {
        selection
    })
}

/// [`choose_descended`], made again when the chosen candidate extends a smaller one whose extra
/// batch of restarts moved it ([`confirm_the_smaller`]; `confirmed` marks the smaller candidates
/// that ran theirs).
fn choose_confirmed(
    job: &LoadedJob,
    fits: &mut Vec<CandidateFit>,
    explicit: bool,
    confirmed: &mut [bool],
    pb: &Option<indicatif::ProgressBar>,
) -> Result<select::Selection> {
    let selection = choose_descended(job, fits, explicit, pb)?;
    if confirm_the_smaller(job, fits, selection.chosen, confirmed, pb)? {
        choose_descended(job, fits, explicit, pb)
    } else {
        Ok(selection)
    }
}

/// Runs the job in stages: measure the recording (or read the targets), search each candidate
/// model (particle swarm, Nelder–Mead, curvature: [`search`]), choose among them by TIC (target
/// jobs: [`aic`]; [`select`]), attach intervals and warnings to the chosen fit ([`uncertainty`]), and assemble
/// the [`FitResult`].
///
/// `progress`: show a progress bar on stderr (hidden automatically when stderr is not a terminal),
/// moved by argmin observers after every iteration.
///
/// # Errors
/// Reading or measuring the recording, an optimiser failure, or a best-fit model that cannot be
/// simulated again.
pub fn run_fit(job: &LoadedJob, progress: bool) -> Result<FitOutcome> {
    let started = std::time::Instant::now();
    // Provenance: the hash of the recording as it was read.
    let input_sha256 = crate::io::sha256_file(&job.recording_path)?;
    let meas = measure(job)?;
    let (job, drive, drive_warning) = drive::fitted_drive(job, &meas.trace)?;
    let job = job.as_ref();
    let fit = &job.job.fit;
    let candidates = job.candidates();
    let pb = progress.then(|| progress_bar(job, &candidates));
    let mut fits = fit_candidates(job, &meas, &candidates, &pb)?;
    let gaps = select::score_gaps(&fits, &job.job.spectrum.bands);
    confirm_deferred(job, &mut fits, &gaps, &pb)?;
    search::take_nested_optima(&mut fits, &pb)?;
    let explicit = !fit.models.is_empty();
    let choose = |fits: &mut Vec<CandidateFit>| choose_descended(job, fits, explicit, &pb);
    let mut confirmed = vec![false; fits.len()];
    let mut selection = choose_confirmed(job, &mut fits, explicit, &mut confirmed, &pb)?;
    let (mut best, mut gof) = chosen_goodness(&fits[selection.chosen])?;
    let chosen_name = fits[selection.chosen].candidate.to_string();
    if let Some(why) = scan::scan_reason(fit.contact_angle_scan, &chosen_name, gof_ref(&gof))
        && fit.search.method == job::SearchMethod::Swarm
        && !interrupt::stop_requested()
    {
        // The scan's notes reach the trials' reasons through a new choice either way; the valley
        // polishes run again only from a moved optimum.
        if scan::scan_contact_angle(job, &meas, &mut fits, &pb, &why)? {
            selection = choose_confirmed(job, &mut fits, explicit, &mut confirmed, &pb)?;
            (best, gof) = chosen_goodness(&fits[selection.chosen])?;
        } else {
            selection = select::choose(&fits, &job.job.spectrum.bands, explicit, &[]);
        }
    }
    if fit.uncertainty.method() == job::UncertaintyMethod::Profile
        && climb::climb_chosen(job, &mut fits, selection.chosen, &pb)?
    {
        selection = choose(&mut fits)?;
        (best, gof) = chosen_goodness(&fits[selection.chosen])?;
    }
    let (tolerance_check, choice_warning) =
        choose_at_resolution(job, &fits, &mut selection, (&mut best, &mut gof), explicit)?;
    let absorbing = select::absorbing_warnings(&fits, selection.chosen, &job.job.spectrum.bands);
    // Laplace and profile intervals read the sandwich over the bowl's centre; a bootstrap's come
    // from its replicates, so its 1σ and correlations keep the sandwich at the fit.
    let mut cf = fits.swap_remove(selection.chosen);
    if fit.uncertainty.method() != job::UncertaintyMethod::Bootstrap {
        cf = cf.with_smoothed_spread();
    }
    let mut parameters = fitted_parameters(job, &cf);
    let peaks = peak_comparisons(&cf, &best.features)?;
    let (intervals, mut warnings, interrupted, posterior) = chosen_intervals(&cf, &best, fit, &pb)?;
    for (p, iv) in parameters.iter_mut().zip(intervals.into_iter().flatten()) {
        p.interval = Some(iv);
    }
    if let Some(pb) = &pb {
        pb.finish_and_clear();
    }
    let shoulder_listed = candidates.iter().any(|c| c.shoulder);
    let (goodness_of_fit, gof_warnings) =
        goodness_warnings(gof, &cf, &best.sim, &selection.trials, shoulder_listed);
    warnings.extend(gof_warnings);
    warnings.extend(absorbing);
    warnings.extend(line_warnings(&peaks));
    warnings.extend(identifiability_warnings(&parameters, &cf.corr, &cf.best_u));
    warnings.extend(choice_warning);
    let tol = tolerance_check.as_ref();
    let truth = optimum_checks(job, (&cf, &fits), &best, tol, interrupted, &mut warnings);
    warnings.extend(failure_warning(&cf.problem));
    warnings.extend(joint_dropped_warning(&cf.problem));
    warnings.extend(drive_warning);
    // The chosen model's counts include its bootstrap replicates and the tolerance check's
    // simulations (they share its counters).
    let chosen = &mut selection.trials[selection.chosen];
    chosen.model_evaluations = cf.problem.evaluations.load(Ordering::Relaxed);
    chosen.failed_evaluations = failures(&cf.problem).0;
    let modes = modes_or_warning(&best.params, &mut warnings);
    let result = assemble_result(
        job,
        &cf,
        Assembled {
            cost: best.cost,
            parameters,
            peaks,
            trials: selection.trials,
            warnings: warnings.into(),
            transitions: best.sim.transitions.len(),
            wall_time_s: started.elapsed().as_secs_f64(),
            input_sha256,
            modes,
            interrupted,
            goodness_of_fit,
            tolerance_check,
            tracking_noise: tracking_noise(&cf, &best.sim),
            truth,
        },
    );
    let result = FitResult {
        friction_curve: friction_curve(job, &result, &best, (&cf, &fits)),
        posterior,
        drive,
        ..result
    };
    Ok(FitOutcome {
        result,
        signal: job.job.spectrum.signal,
        fs_hz: meas.fs_hz,
        measured_trace: meas.trace,
        measured: meas.measured,
        model: best.features,
        best_sim: best.sim,
        best_params: best.params,
    })
}

/// The blade's modes at the fitted parameters, or none and a warning saying why.
fn modes_or_warning(
    params: &BladeParams,
    warnings: &mut Vec<FitWarning>,
) -> Vec<crate::model::modes::BladeMode> {
    blade_modes(params).unwrap_or_else(|e| {
        warnings.push(FitWarning::NoBladeModes {
            reason: e.to_string(),
        });
        Vec::new()
    })
}

/// The warning that the likelihood read the measured signal alone, its joint signals' bands too
/// short ([`crate::search::evidence::RecordingLikelihood::joint_dropped`]).
fn joint_dropped_warning(problem: &SpectralProblem) -> Option<FitWarning> {
    let d = problem.likelihood.as_ref().ok()?.joint_dropped?;
    Some(FitWarning::JointSignalsDropped(d))
}

/// The fitted law over the slip speeds of the chosen optimum's simulation, its band from the
/// result's 1σ and correlations widened, as Laplace and profile intervals are, to the points the
/// search evaluated within each speed's profile rise limit ([`uncertainty::mu_d_rise_limits`]),
/// the envelope of the bands of the candidates the recording does not distinguish from it
/// (`others`, the fits beside the chosen `cf`), and the job's true law
/// ([`LoadedJob::true_friction_law`]).
fn friction_curve(
    job: &LoadedJob,
    r: &FitResult,
    best: &BestModel,
    (cf, others): (&CandidateFit, &[CandidateFit]),
) -> Option<crate::model::friction_curve::FrictionCurve> {
    let widens = (r.parameters.iter())
        .filter_map(|p| p.interval.as_ref())
        .any(|iv| iv.method.widens_to_near_best());
    let law = best.params.friction;
    let chosen = CandidateSpread::of(job, cf);
    let curve = crate::model::friction_curve::FrictionCurve::new(
        law,
        &best.sim.slip_speeds(),
        Some(chosen.spread()),
        job.true_friction_law(),
    )?;
    let (limits, near) = chosen.near_best(&curve.speed_m_per_s, &law, widens, cf);
    let curve = curve.with_near_best(&near, &limits);
    let alternatives: Vec<_> = (r.model_trials.iter())
        .filter(|t| t.not_distinguishable)
        .filter_map(|t| {
            let law = t.friction?;
            let Some(o) = others.iter().find(|f| f.candidate == t.model) else {
                return Some(curve.alternative(law, None, &[], &[]));
            };
            let s = CandidateSpread::of(job, o);
            let (limits, near) = s.near_best(&curve.speed_m_per_s, &law, widens, o);
            Some(curve.alternative(law, Some(s.spread()), &near, &limits))
        })
        .collect();
    Some(curve.with_alternatives(&alternatives))
}

/// A candidate's parameters' 1σ and correlations (sandwich, and Fisher's where there is a
/// likelihood), for its friction law's band.
struct CandidateSpread {
    ids: Vec<crate::model::ParamId>,
    sigma: Vec<f64>,
    corr: Vec<Vec<f64>>,
    fisher: Option<(Vec<f64>, Vec<Vec<f64>>)>,
}

impl CandidateSpread {
    /// The candidate's, from its fit (the chosen one's are the result's parameters' 1σ and its
    /// correlations).
    fn of(job: &LoadedJob, cf: &CandidateFit) -> Self {
        let params = fitted_parameters(job, cf);
        let fisher_sigma = (params.iter())
            .map(|p| p.fisher_std_error.unwrap_or(f64::NAN))
            .collect();
        CandidateSpread {
            ids: params.iter().map(|p| p.name).collect(),
            sigma: params.iter().map(|p| p.std_error).collect(),
            corr: cf.corr.clone(),
            fisher: cf.fisher_corr.clone().map(|c| (fisher_sigma, c)),
        }
    }

    fn spread(&self) -> crate::model::friction_curve::Spread<'_> {
        crate::model::friction_curve::Spread {
            ids: &self.ids,
            sigma: &self.sigma,
            corr: &self.corr,
        }
    }

    /// μ_d's profile rise limit at each of `speeds` for `law`, and (when the intervals widen,
    /// `widens`) the points `cf`'s search evaluated within the largest of them.
    fn near_best(
        &self,
        speeds: &[f64],
        law: &crate::model::FrictionLaw,
        widens: bool,
        cf: &CandidateFit,
    ) -> (Vec<f64>, Vec<(f64, crate::model::FrictionLaw)>) {
        let fisher =
            (self.fisher.as_ref()).map(|(sigma, corr)| crate::model::friction_curve::Spread {
                ids: &self.ids,
                sigma,
                corr,
            });
        let limits = uncertainty::mu_d_rise_limits(law, speeds, self.spread(), fisher);
        let near = if widens {
            uncertainty::near_best_laws(cf, &limits)
        } else {
            Vec::new()
        };
        (limits, near)
    }
}

/// The chosen optimum's tolerance check ([`tolerance::ToleranceCheck`]) and, where an optimum the
/// choice reads is not resolved by the integrator, the choice again with its margins widened by
/// the unresolved spreads ([`select::margin`]): `selection`, `best` and `gof` move to the
/// candidate reported then (simulated again), and the warning says why. No check runs after an
/// interrupt.
///
/// # Errors
/// A newly chosen model that cannot be simulated again.
fn choose_at_resolution(
    job: &LoadedJob,
    fits: &[CandidateFit],
    selection: &mut select::Selection,
    (best, gof): (&mut BestModel, &mut GoodnessOutcome),
    explicit: bool,
) -> Result<(Option<tolerance::ToleranceCheck>, Option<FitWarning>)> {
    if interrupt::stop_requested() {
        return Ok((None, None));
    }
    let cf = &fits[selection.chosen];
    let at_job = (best.cost, best.sim.transitions.len());
    let check =
        tolerance::ToleranceCheck::run(&cf.problem, &cf.problem.params_at(&cf.best_u), at_job)
            .map(|c| c.with_jitter(&cf.problem, Some(&cf.best_u)));
    let mut checks = tolerance::checks_for_choice(fits, selection.chosen, check);
    let spreads: Vec<f64> = checks
        .iter()
        .map(|c| tolerance::unresolved_spread(c.as_ref()))
        .collect();
    // Chosen again in any case: the trials' evaluation counts then include the checks'.
    let widened = select::choose(fits, &job.job.spectrum.bands, explicit, &spreads);
    let mut warning = None;
    if widened.chosen != selection.chosen {
        warning = select::moved_choice(&widened, selection.chosen, &spreads);
        (*best, *gof) = chosen_goodness(&fits[widened.chosen])?;
    }
    *selection = widened;
    Ok((checks.swap_remove(selection.chosen), warning))
}

/// The checks at the chosen optimum `best` that simulate again or read its tolerance check: the
/// check's warnings pushed to `warnings`, and the truth's cost and segment ([`truth::check`]) in
/// the chosen fit `cf` or, where `[truth] model` names another, in that model's fit among
/// `others`, with the shortfall warning. The truth is not checked after an interrupt.
fn optimum_checks(
    job: &LoadedJob,
    (cf, others): (&CandidateFit, &[CandidateFit]),
    best: &BestModel,
    tolerance_check: Option<&tolerance::ToleranceCheck>,
    interrupted: bool,
    warnings: &mut Vec<FitWarning>,
) -> Option<truth::TruthCheck> {
    warnings.extend(tolerance_check.and_then(|t| t.warning()));
    if job.job.fit.uncertainty.method() != job::UncertaintyMethod::Profile {
        warnings.extend(tolerance_check.and_then(|t| t.jitter_warning()));
    }
    if interrupted {
        return None;
    }
    let tf = truth::truth_fit(job, cf, others)?;
    let truth = if std::ptr::eq(tf, cf) {
        truth::check(job, cf, best.cost, None)
    } else {
        truth::check(job, tf, tf.cost, Some(tf.candidate))
    };
    warnings.extend(truth.as_ref().and_then(truth::shortfall_warning));
    truth
}

/// The chosen fit's goodness of fit to the recording's spectra
/// ([`crate::search::evidence::RecordingLikelihood::goodness_of_fit`]); `None` without a likelihood, for a joint
/// fit (whose other recordings the test does not read) and when interrupted.
///
/// # Errors
/// Why the test could not run (a replicate's spectra or noise estimate failed), for a warning.
fn goodness_of_fit(cf: &CandidateFit, sim: &BladeSimulation) -> GoodnessOutcome {
    let p = &cf.problem;
    let Ok(lik) = p.likelihood.as_ref() else {
        return Ok(None);
    };
    if !p.cost_is_nll() || !p.others.is_empty() || interrupt::stop_requested() {
        return Ok(None);
    }
    lik.goodness_of_fit(p, sim).map(Some)
}

/// The tracking noise the chosen fit's likelihood reads at its optimum `sim`; `None` without a
/// likelihood or when the simulation's spectra cannot be computed.
fn tracking_noise(cf: &CandidateFit, sim: &BladeSimulation) -> Option<result::NoiseEstimate> {
    let lik = cf.problem.likelihood.as_ref().ok()?;
    let n = lik.noise_at(&cf.problem, sim).ok()?;
    // A joint signal's noise that cannot be read leaves the measured signal's in the result.
    let joint = lik
        .joint_noises_at(&cf.problem, sim)
        .unwrap_or_default()
        .into_iter()
        .map(|(signal, n)| result::SignalNoise {
            signal,
            sigma_m: n.sigma_m,
            rho: n.rho,
        })
        .collect();
    Some(result::NoiseEstimate {
        spectrum: lik.noise_spectrum,
        sigma_m: n.sigma_m,
        rho: n.rho,
        joint,
    })
}

/// The chosen fit's simulation at its optimum and its [`goodness_of_fit`] (or why there is none).
///
/// # Errors
/// A best-fit model that cannot be simulated again.
fn chosen_goodness(cf: &CandidateFit) -> Result<(BestModel, GoodnessOutcome)> {
    let best = BestModel::of(cf)?;
    let gof = goodness_of_fit(cf, &best.sim);
    Ok((best, gof))
}

/// A goodness-of-fit test, `None` when there is none, or why it could not run.
type GoodnessOutcome = Result<Option<likelihood::GoodnessOfFit>>;

/// The test in `gof`, when it ran.
fn gof_ref(gof: &GoodnessOutcome) -> Option<&likelihood::GoodnessOfFit> {
    gof.as_ref().ok().and_then(Option::as_ref)
}

/// The warning of a fit whose spectra are less likely than its own noise makes likely, with
/// where the excess sits (`shape`, asked only then). `shoulder_listed`: the job lists a
/// `+shoulder` candidate; the warning then says how a known contact angle helps the search
/// (docs/model-choice.md, "Shoulder contact").
fn misfit_warning(
    g: &likelihood::GoodnessOfFit,
    shoulder_listed: bool,
    shape: impl FnOnce() -> Vec<likelihood::misfit::BandMisfit>,
) -> Option<FitWarning> {
    (!g.fits()).then(|| FitWarning::Misfit {
        test: *g,
        shoulder_listed,
        shape: shape(),
    })
}

/// The goodness-of-fit test's outcome as the result keeps it, with its warnings: that it could
/// not run, or a misfit (where it sits, and a shoulder chosen on it).
fn goodness_warnings(
    gof: GoodnessOutcome,
    cf: &CandidateFit,
    sim: &BladeSimulation,
    trials: &[result::ModelTrial],
    shoulder_listed: bool,
) -> (Option<likelihood::GoodnessOfFit>, Vec<FitWarning>) {
    let g = match gof {
        Ok(g) => g,
        Err(e) => {
            let reason = e.to_string();
            return (None, vec![FitWarning::NoGoodnessOfFit { reason }]);
        }
    };
    let mut warnings = Vec::new();
    if let Some(w) = g
        .as_ref()
        .and_then(|g| misfit_warning(g, shoulder_listed, || misfit_shape(cf, sim)))
    {
        warnings.push(w);
        warnings.extend(select::chosen_on_misfit(trials));
    }
    (g, warnings)
}

/// Where the chosen fit's spectra depart from the recording's; empty when the likelihood cannot
/// say (a description of a misfit already found, never a reason to fail the fit).
fn misfit_shape(cf: &CandidateFit, sim: &BladeSimulation) -> Vec<likelihood::misfit::BandMisfit> {
    let p = &cf.problem;
    p.likelihood
        .as_ref()
        .ok()
        .and_then(|l| l.misfit_shape(p, sim).ok())
        .unwrap_or_default()
}

/// The chosen fit's intervals and their warnings, and whether the run was interrupted (then no
/// intervals, and a warning saying what was left out).
fn chosen_intervals(
    cf: &CandidateFit,
    best: &BestModel,
    fit: &job::FitSection,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<ChosenIntervals> {
    if let (Some(pb), true) = (
        pb,
        fit.uncertainty.method() == job::UncertaintyMethod::Bootstrap,
    ) {
        pb.set_message("bootstrap");
    }
    let (intervals, mut warnings, posterior) = if interrupt::stop_requested() {
        (None, Vec::new(), None)
    } else {
        match uncertainty::intervals(cf, &best.sim, fit, pb) {
            Err(_) if interrupt::stop_requested() => (None, Vec::new(), None),
            other => other?,
        }
    };
    let interrupted = interrupt::stop_requested();
    if interrupted {
        warnings.push(FitWarning::Interrupted);
    }
    Ok((intervals, warnings, interrupted, posterior))
}

/// [`chosen_intervals`]' intervals, warnings, interrupt and posterior sample.
type ChosenIntervals = (
    Option<Vec<result::Interval>>,
    Vec<FitWarning>,
    bool,
    Option<crate::posterior::PosteriorSummary>,
);

/// The chosen candidate's best fit simulated again at the polish's tolerance.
struct BestModel {
    params: BladeParams,
    sim: BladeSimulation,
    features: Features,
    cost: f64,
}

impl BestModel {
    fn of(cf: &CandidateFit) -> Result<BestModel> {
        let params = cf.problem.params_at(&cf.best_u);
        let sim = cf.problem.simulate(&params)?;
        let features = cf.problem.model_features(&sim)?;
        let cost = cf.problem.total_cost(&sim)? + cf.problem.prior.nats(&params);
        Ok(BestModel {
            params,
            sim,
            features,
            cost,
        })
    }
}

/// The freed parameters at the optimum, with their 1σ (the sandwich's, and the Fisher
/// information's alone) and, for synthetic recordings, the truth.
fn fitted_parameters(job: &LoadedJob, cf: &CandidateFit) -> Vec<FittedParam> {
    cf.free
        .iter()
        .zip(&cf.best_u)
        .zip(&cf.sigma_u)
        .enumerate()
        .map(|(i, ((fp, u), su))| {
            let value = fp.value(*u);
            let truth = job.truth.get(&fp.name).copied();
            FittedParam {
                name: fp.name,
                value,
                lower: fp.lower,
                upper: fp.upper,
                std_error: su * fp.slope(*u),
                fisher_std_error: cf.fisher_sigma_u.as_ref().map(|f| f[i] * fp.slope(*u)),
                rounding_widening: cf.rounding_widening.as_ref().map(|w| w[i]),
                determined: su.is_finite() && *su < 0.1,
                true_value: truth,
                rel_error: truth.map(|t| (value - t) / t),
                interval: None,
            }
        })
        .collect()
}

/// Measured (or target) against model peak per band, for the main recording and then for each
/// further recording of a joint fit (bands named `<recording>:<band>`).
fn peak_comparisons(cf: &CandidateFit, model: &Features) -> Result<Vec<PeakComparison>> {
    let problem = &cf.problem;
    let mut peaks: Vec<PeakComparison> = problem
        .measured
        .bands
        .iter()
        .zip(&model.bands)
        .enumerate()
        .map(|(i, (d, m))| {
            let fm = m.peak.map(|p| p.freq_hz).unwrap_or(f64::NAN);
            let range = problem.targets.as_ref().map(|t| t[i]);
            // Against a target range: the nearest edge (the model's own peak when inside).
            let fd = match range {
                Some(r) if fm.is_finite() => fm.clamp(r[0], r[1]),
                Some(r) => (r[0] * r[1]).sqrt(),
                None => d.peak.map(|p| p.freq_hz).unwrap_or(f64::NAN),
            };
            let mut c = peak_comparison(d.spec.name.clone(), d, m);
            c.measured_hz = fd;
            c.rel_diff = (fm - fd) / fd;
            c.target_range_hz = range.filter(|r| r[0] < r[1]);
            c
        })
        .collect();
    for o in &problem.others {
        let p = o.params_at(&cf.best_u);
        let f = o.simulate(&p).and_then(|sim| o.model_features(&sim))?;
        for (d, m) in o.measured.bands.iter().zip(&f.bands) {
            peaks.push(peak_comparison(
                format!("{}:{}", o.label, d.spec.name),
                d,
                m,
            ));
        }
    }
    Ok(peaks)
}

/// One band's measured peak against the model's.
fn peak_comparison(
    band: String,
    d: &features::BandFeatures,
    m: &features::BandFeatures,
) -> PeakComparison {
    let fd = d.peak.map(|p| p.freq_hz).unwrap_or(f64::NAN);
    let fm = m.peak.map(|p| p.freq_hz).unwrap_or(f64::NAN);
    PeakComparison {
        band,
        measured_hz: fd,
        model_hz: fm,
        rel_diff: (fm - fd) / fd,
        measured_level: d.peak.map(|p| p.level).unwrap_or(f64::NAN),
        model_level: m.peak.map(|p| p.level).unwrap_or(f64::NAN),
        target_range_hz: None,
        measured_line: features::line_origin(d),
        model_line: features::line_origin(m),
    }
}

/// Warnings for lines that are harmonics of stronger lines, barely stand over their floor, or lie
/// more than 100× below their spectrum's dominant line ([`crate::spectrum::harmonics`]): the band
/// then may not see the component it was meant for. Each says whether the other spectrum's line in
/// the band is the same harmonic (then the fit compares like with like).
fn line_warnings(peaks: &[PeakComparison]) -> Vec<FitWarning> {
    use warning::LineSource;
    let order = |o: Option<crate::spectrum::harmonics::LineOrigin>| {
        o.and_then(|o| o.harmonic_of).map(|h| h.order)
    };
    let mut w = Vec::new();
    for p in peaks {
        let same =
            order(p.measured_line).is_some() && order(p.measured_line) == order(p.model_line);
        for (source, line) in [
            (LineSource::Recording, p.measured_line),
            (LineSource::Model, p.model_line),
        ] {
            let Some(origin) = line else { continue };
            let warning = FitWarning::Line {
                band: p.band.clone(),
                source,
                origin,
                same_harmonic_on_other_side: same,
            };
            let what = match source {
                LineSource::Recording => "the recording's line",
                LineSource::Model => "the model's line",
            };
            if origin.concern(what).is_some() {
                w.push(warning);
            }
        }
    }
    w
}

/// The chosen problem's failed evaluations (its own and its joint recordings'), with the first
/// failure's message.
pub(crate) fn failures(problem: &SpectralProblem) -> (usize, Option<String>) {
    let failed = problem.failures.load(Ordering::Relaxed)
        + problem
            .others
            .iter()
            .map(|o| o.failures.load(Ordering::Relaxed))
            .sum::<usize>();
    let first = problem
        .first_failure
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .clone();
    (failed, first)
}

/// A warning when more than [`warning::FAILED_WARN_FRACTION`] of the chosen model's evaluations
/// failed, with the failures by cause.
fn failure_warning(problem: &SpectralProblem) -> Option<FitWarning> {
    let evaluations = problem.evaluations.load(Ordering::Relaxed);
    let (failed, first) = failures(problem);
    (failed as f64 > warning::FAILED_WARN_FRACTION * evaluations as f64).then(|| {
        FitWarning::FailedEvaluations {
            failed,
            evaluations,
            causes: failure_causes(problem),
            first,
        }
    })
}

/// The chosen problem's failed evaluations by cause (its own and its joint recordings').
fn failure_causes(
    problem: &SpectralProblem,
) -> std::collections::BTreeMap<crate::simulate::failure::FailureCause, usize> {
    let mut causes = std::collections::BTreeMap::new();
    for p in std::iter::once(problem).chain(&problem.others) {
        let by = p.failure_causes.lock().unwrap_or_else(|e| e.into_inner());
        for (c, n) in by.iter() {
            *causes.entry(*c).or_insert(0) += n;
        }
    }
    causes
}

/// What the stages computed, for [`assemble_result`].
struct Assembled {
    cost: f64,
    parameters: Vec<FittedParam>,
    peaks: Vec<PeakComparison>,
    trials: Vec<ModelTrial>,
    warnings: Warnings,
    transitions: usize,
    wall_time_s: f64,
    input_sha256: String,
    modes: Vec<crate::model::modes::BladeMode>,
    interrupted: bool,
    goodness_of_fit: Option<likelihood::GoodnessOfFit>,
    tolerance_check: Option<tolerance::ToleranceCheck>,
    tracking_noise: Option<result::NoiseEstimate>,
    truth: Option<truth::TruthCheck>,
}

/// The result of the chosen fit, with the job's provenance (the recording's hash and the effective
/// settings, defaults filled in).
fn assemble_result(job: &LoadedJob, cf: &CandidateFit, a: Assembled) -> FitResult {
    let settings = toml::to_string_pretty(&job.job)
        .or_else(|_| job::read_text(&job.path))
        .unwrap_or_default();
    let (_, first_failure) = failures(&cf.problem);
    let undetermined = a
        .parameters
        .iter()
        .filter(|p| !p.determined)
        .map(|p| p.name)
        .collect();
    let priors = (!cf.problem.prior.is_empty()).then(|| {
        let intervals: Vec<_> = (a.parameters.iter())
            .map(|p| (p.name, p.interval.as_ref().map(|i| [i.lo, i.hi])))
            .collect();
        let at_fit = cf.problem.params_at(&cf.best_u);
        (cf.problem.prior).report(&at_fit, &intervals, job.rig_curve.as_ref())
    });
    let mut warnings = a.warnings;
    warnings.extend(priors.iter().flat_map(warning::prior_warnings));
    FitResult {
        job: job.name.clone(),
        recording: job.recording_path.display().to_string(),
        wiperlab_version: env!("CARGO_PKG_VERSION").into(),
        model: cf.candidate,
        cost: a.cost,
        parameters: a.parameters,
        peaks: a.peaks,
        undetermined,
        correlation: cf.corr.clone(),
        spread_source: if cf.evidence.is_ok() {
            result::SpreadSource::Sandwich
        } else {
            result::SpreadSource::CostCurvature
        },
        swarm_iterations: cf.swarm_iters,
        polish_iterations: cf.polish_iters,
        model_evaluations: a.trials.iter().map(|t| t.model_evaluations).sum(),
        failed_evaluations: a.trials.iter().map(|t| t.failed_evaluations).sum(),
        first_failure,
        wall_time_s: a.wall_time_s,
        threads: rayon::current_num_threads(),
        solver_rtol: job.job.solver.rtol,
        solver_atol: job.job.solver.atol,
        transitions_in_best_model: a.transitions,
        model_trials: a.trials,
        warnings,
        input_sha256: a.input_sha256,
        settings,
        target_job: job.job.targets.is_some(),
        spectrum: Some(job.job.spectrum.clone()),
        fit_settings: Some(job.job.fit.clone()),
        fitted_at: Some(jiff::Timestamp::now()),
        data_files: Vec::new(),
        modes: a.modes,
        interrupted: a.interrupted,
        goodness_of_fit: a.goodness_of_fit,
        tolerance_check: a.tolerance_check,
        tracking_noise: a.tracking_noise,
        truth_cost: a.truth.as_ref().map(|t| t.cost_nats),
        truth_model: a.truth.as_ref().and_then(|t| t.model),
        truth_model_cost: (a.truth.as_ref())
            .and_then(|t| t.model.is_some().then_some(t.fit_cost_nats)),
        truth_tolerance: a.truth.as_ref().and_then(|t| t.tolerance.clone()),
        truth_segment: a.truth.and_then(|t| t.segment),
        friction_curve: None,
        posterior: None,
        drive: None,
        priors,
        history: cf.history.clone(),
    }
}

/// The linearised 2-DOF blade's modes at `params` (whatever candidate was fitted: the modes say
/// which lines the full blade has at these parameters).
fn blade_modes(
    params: &BladeParams,
) -> std::result::Result<Vec<crate::model::modes::BladeMode>, crate::model::modes::ModesError> {
    crate::model::Blade::new(*params, crate::model::StickForm::Reduced).window_modes()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ParamId;
    use crate::search::problem_for;

    /// The misfit warning fires only when the recording's statistic is beyond all but 1 % of its
    /// replicates', and quotes the numbers.
    #[test]
    fn misfit_warning_fires_below_the_level_only() {
        let replicates: Vec<f64> = (0..999).map(|i| 60.0 + 0.04 * f64::from(i)).collect();
        let above_all = likelihood::GoodnessOfFit::of(171.0, &replicates).unwrap();
        let w = misfit_warning(&above_all, false, Vec::new).expect("p = 0.001 is below the level");
        assert_eq!(
            w,
            FitWarning::Misfit {
                test: above_all,
                shoulder_listed: false,
                shape: Vec::new(),
            }
        );
        assert_eq!(w.severity(), Severity::Attention);
        let text = w.to_string();
        assert!(
            text.contains("171.0 nats") && text.contains("p = 0.001"),
            "{text}"
        );
        assert!(!text.contains("theta_c"), "{text}");
        let with_shoulder = misfit_warning(&above_all, true, Vec::new)
            .expect("the same test")
            .to_string();
        assert!(
            with_shoulder.contains("[fit.shoulder] theta_c"),
            "{with_shoulder}"
        );
        let typical = likelihood::GoodnessOfFit::of(80.0, &replicates).unwrap();
        assert_eq!(misfit_warning(&typical, false, Vec::new), None);
        assert_eq!(misfit_warning(&typical, true, Vec::new), None);
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
        // The feature objective, so that both stages read the same cost and only the tolerance
        // differs; the default (likelihood) objective is checked at the end.
        let features =
            strip(&text).replace("restarts = 3", "restarts = 3\nobjective = \"features\"");
        let with = features.replace("restarts = 3", "restarts = 3\nswarm_rtol = 1e-5");
        let without = features.clone();
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
            (ParamId::A, 0.88),
            (ParamId::B, 69.74712740275162),
            (ParamId::C, 0.56),
            (ParamId::K1, 0.029748408887917077),
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
        // With the likelihood objective the swarm ranks by the same feature cost, and the polish by
        // the NLL above the saturated model, which is never negative.
        let l = problem_for(
            &load("likelihood.toml", &strip(&text)),
            "blade2dof".parse().unwrap(),
        )
        .unwrap();
        assert_eq!(
            l.cost_at_stage(&u, SearchStage::Swarm),
            q.cost_at_stage(&u, SearchStage::Swarm)
        );
        let nll = l.cost_at(&u);
        assert!(nll >= 0.0 && nll != q.cost_at(&u), "{nll}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
