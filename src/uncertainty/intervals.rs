//! Uncertainty stage: bootstrap intervals and identifiability warnings for the chosen model.

use crate::Result;
use crate::estimate::warning::{End, FitWarning, SampledReason};
use crate::estimate::{FittedParam, Interval, IntervalMethod};
use crate::job::FreeParam;
use crate::job::{self, NoiseSpectrum, UncertaintyMethod};
use crate::posterior::PosteriorSummary;
use crate::search::evidence::RecordingLikelihood;
use crate::search::jitter::RoundingJitter;
use crate::search::problem::SpectralProblem;
use crate::search::strategy::{
    CandidateFit, Confirming, POLISH_STEP_U, ProgressObserver, Reporting, optimise, polish,
    polish_pinned,
};
use crate::simulate::blade::BladeSimulation;
use crate::spectrum::features::{features, noise_floor};
use crate::spectrum::stats::quantile_sorted;
use rand::SeedableRng;
use std::sync::atomic::AtomicUsize;
use std::sync::{Arc, Mutex};

/// The uncertainty stage: an interval for every freed parameter of the chosen fit, by the job's
/// method (`[fit.uncertainty] method`): Laplace's from the likelihood's Fisher information
/// ([`laplace_intervals`], no further fits), the profile likelihood ([`profile_intervals`], a few
/// conditional polishes per parameter) or the parametric bootstrap ([`bootstrap_intervals`]).
/// A target job gets a warning instead: its targets carry no measurement noise. Returns the
/// intervals (in the order of the freed parameters), warnings, and with `mcmc` the posterior sample
/// ([`mcmc_intervals`]).
///
/// # Errors
/// As [`bootstrap_intervals`] and [`mcmc_intervals`].
pub(crate) fn intervals(
    cf: &CandidateFit,
    best_sim: &BladeSimulation,
    fit: &job::FitSection,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<Intervals> {
    if cf.problem.targets.is_some() {
        return Ok((None, vec![FitWarning::TargetJobIntervals], None));
    }
    match fit.uncertainty.method() {
        UncertaintyMethod::Mcmc => sampled_intervals(cf, fit, pb, None),
        UncertaintyMethod::Auto => auto_intervals(cf, fit, pb),
        _ => {
            let (iv, w) = other_intervals(cf, best_sim, fit, pb)?;
            Ok((iv, w, None))
        }
    }
}

/// [`mcmc_intervals`] with their warnings, the search's shortfall against the walkers' best
/// point, and `why` a posterior was sampled (`method = "auto"`); a warning instead without a
/// likelihood.
fn sampled_intervals(
    cf: &CandidateFit,
    fit: &job::FitSection,
    pb: &Option<indicatif::ProgressBar>,
    why: Option<FitWarning>,
) -> Result<Intervals> {
    let method = fit.uncertainty.method();
    let nll = match &cf.evidence {
        Ok(nll) => nll,
        Err(e) => return Ok((None, vec![no_intervals(method, e)], None)),
    };
    let (iv, mut w, post) = mcmc_intervals(cf, nll.effective_parameters, fit, pb)?;
    w.extend(why);
    w.extend(search_short_of_best(cf));
    Ok((Some(iv), w, Some(post)))
}

/// How many times wider than a Laplace interval the likelihood must reach before `method =
/// "auto"` samples the posterior instead. Chosen on the development set (docs/validation.md,
/// "Intervals against the likelihood"): on the main job the search's evaluations inside the
/// profile region reach 1.47 times its widest Laplace interval, which covers the truth unwidened;
/// on the development fits whose Laplace intervals miss, 4.4–6.2 times.
pub const AUTO_WIDTH_FACTOR: f64 = 2.0;

/// `method = "auto"`: the Laplace intervals where the likelihood is the quadratic the curvature
/// at the fit says, else a posterior sample ([`sampled_intervals`]). The evidence, per parameter,
/// as a factor on its Laplace interval's width: the widening the search's evaluations inside the
/// profile region ([`widen_to_near_best`]) and the shoulder's contact ridge
/// ([`along_contact_ridge`]) would make, and the stretch of an axis the secant check finds flatter
/// than the curvature (mostly that parameter). Above [`AUTO_WIDTH_FACTOR`] anywhere the posterior is
/// sampled; otherwise the Laplace intervals stand as they are, not widened.
fn auto_intervals(
    cf: &CandidateFit,
    fit: &job::FitSection,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<Intervals> {
    if let Err(why) = &cf.evidence {
        return Ok((None, vec![no_intervals(UncertaintyMethod::Auto, why)], None));
    }
    let laplace = laplace_intervals(
        &cf.free,
        &cf.best_u,
        &cf.sigma_u,
        cf.fisher_steps_u.as_deref(),
    );
    let mut reached = laplace.clone();
    along_contact_ridge(cf, &mut reached);
    near_best_of(cf, &mut reached);
    let mut factor: Vec<f64> = laplace.iter().zip(&reached).map(width_ratio).collect();
    for w in secant_check(cf) {
        if let FitWarning::FlatterThanCurvature(a) = w
            && let Some(i) = cf.free.iter().position(|f| f.name == a.parameter)
        {
            factor[i] = factor[i].max(a.stretch);
        }
    }
    match widest_beyond(&factor) {
        Some(i) => {
            let why = FitWarning::IntervalsSampled(SampledReason {
                parameter: cf.free[i].name,
                width_factor: factor[i],
            });
            sampled_intervals(cf, fit, pb, Some(why))
        }
        _ => Ok((
            Some(laplace),
            search_short_of_best(cf).into_iter().collect(),
            None,
        )),
    }
}

/// The parameter whose factor on its Laplace width is the largest, when that exceeds
/// [`AUTO_WIDTH_FACTOR`] (`method = "auto"` then samples).
fn widest_beyond(factor: &[f64]) -> Option<usize> {
    (0..factor.len())
        .max_by(|&a, &b| factor[a].total_cmp(&factor[b]))
        .filter(|&i| factor[i] > AUTO_WIDTH_FACTOR)
}

/// How many times wider `reached` is than `laplace` (∞ where a zero-width interval grew, 1 where
/// neither has width).
fn width_ratio((laplace, reached): (&Interval, &Interval)) -> f64 {
    let (w0, w) = (laplace.hi - laplace.lo, reached.hi - reached.lo);
    if w0 > 0.0 {
        w / w0
    } else if w > 0.0 {
        f64::INFINITY
    } else {
        1.0
    }
}

/// [`intervals`]' intervals, warnings and posterior sample.
pub(crate) type Intervals = (
    Option<Vec<Interval>>,
    Vec<FitWarning>,
    Option<PosteriorSummary>,
);

/// [`FitWarning::ShortOfBestEvaluation`] when a point evaluated at the polish's tolerance (`near`:
/// by the search, or by the posterior sample's walkers, which can cross into a basin the search
/// missed) is more likely than the fit's `cost` by more than [`crate::search::strategy::CONFIRM_NATS`]. On a development
/// recording whose search ended 1.1 nats short of the truth, the walkers moved into the truth's
/// basin (docs/validation.md, "Intervals against the likelihood"): the sample's intervals then
/// describe another point than the fit's.
fn short_of_best(
    cost: f64,
    near: &crate::search::problem::EvaluatedNearBest,
) -> Option<FitWarning> {
    let gain = cost - near.lowest();
    (gain > crate::search::strategy::CONFIRM_NATS)
        .then_some(FitWarning::ShortOfBestEvaluation { gain_nats: gain })
}

/// [`short_of_best`] of the chosen fit against the points its problem kept.
fn search_short_of_best(cf: &CandidateFit) -> Option<FitWarning> {
    let near = cf.problem.near_best.lock();
    short_of_best(cf.cost, &near.unwrap_or_else(|e| e.into_inner()))
}

/// [`FitWarning::NoIntervals`] of `method`, for `why`.
fn no_intervals(method: UncertaintyMethod, why: &impl std::fmt::Display) -> FitWarning {
    FitWarning::NoIntervals {
        method,
        reason: why.to_string(),
    }
}

/// [`intervals`] by Laplace, the profile or the bootstrap.
fn other_intervals(
    cf: &CandidateFit,
    best_sim: &BladeSimulation,
    fit: &job::FitSection,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<(Option<Vec<Interval>>, Vec<FitWarning>)> {
    match fit.uncertainty.method() {
        UncertaintyMethod::Laplace => match &cf.evidence {
            Ok(_) => {
                let mut intervals = laplace_intervals(
                    &cf.free,
                    &cf.best_u,
                    &cf.sigma_u,
                    cf.fisher_steps_u.as_deref(),
                );
                let mut warnings = secant_check(cf);
                warnings.extend(along_contact_ridge(cf, &mut intervals));
                warnings.extend(near_best_of(cf, &mut intervals));
                Ok((Some(intervals), warnings))
            }
            Err(why) => Ok((None, vec![no_intervals(UncertaintyMethod::Laplace, why)])),
        },
        UncertaintyMethod::Profile => match &cf.evidence {
            Ok(_) => {
                let (mut intervals, mut warnings) = profile_intervals(cf, fit, pb)?;
                warnings.extend(near_best_of(cf, &mut intervals));
                floor_range_95(&cf.free, &cf.best_u, &mut intervals);
                Ok((Some(intervals), warnings))
            }
            Err(why) => Ok((None, vec![no_intervals(UncertaintyMethod::Profile, why)])),
        },
        UncertaintyMethod::Bootstrap if fit.uncertainty.bootstrap == 0 => {
            Ok((None, vec![FitWarning::NoBootstrapReplicates]))
        }
        // [`intervals`] samples the posterior itself.
        UncertaintyMethod::Mcmc | UncertaintyMethod::Auto => Ok((None, Vec::new())),
        UncertaintyMethod::Bootstrap => {
            let intervals = bootstrap_intervals(&cf.problem, &cf.best_u, best_sim, fit)?;
            Ok((Some(intervals), Vec::new()))
        }
    }
}

/// Split R̂ above which [`mcmc_intervals`] warns that the chains have not mixed (Vehtari, Gelman,
/// Simpson, Carpenter & Bürkner 2021, *Bayesian Analysis* 16:2, §4: 1.01).
pub const RHAT_LIMIT: f64 = 1.01;

/// Effective draws below which [`mcmc_intervals`] warns (Vehtari et al. 2021, §4: 400, enough
/// for a 95 % interval's ends to a few per cent of the posterior's spread).
pub const MIN_ESS: f64 = 400.0;

/// The power the likelihood is raised to before sampling: `k/tr(F⁻¹V)`, Ribatet, Cooley &
/// Davison's magnitude adjustment of a composite likelihood (2012, *Statistica Sinica* 22:813,
/// §3.2), with `tr(F⁻¹V)` Takeuchi's effective number of parameters at the fit. Near the optimum
/// the tempered posterior's covariance is then `F⁻¹·tr(F⁻¹V)/k`: where `V = μF` it is the sandwich
/// `F⁻¹VF⁻¹` exactly, otherwise its average scale. 1 without a finite positive trace.
pub fn posterior_tempering(k: usize, effective_parameters: Option<f64>) -> f64 {
    match effective_parameters {
        Some(t) if t.is_finite() && t > 0.0 => k as f64 / t,
        _ => 1.0,
    }
}

/// Intervals from a posterior sample of the chosen fit ([`crate::posterior`]): the affine-invariant
/// ensemble sampler on `−w·NLL(u)`, `w` = [`posterior_tempering`], over the search's normalised
/// coordinates `u ∈ [0, 1]ᵏ` (a flat prior there: uniform in θ, or in ln θ for a parameter
/// searched on a log scale; times `[fit.priors]`' untempered,
/// [`crate::likelihood::prior::Prior::log_posterior`]); a simulation that fails counts as zero density. The walkers start
/// in a Gaussian ball of the sandwich covariance around the fit (a 0.01 ball where it has no
/// finite 1σ), kept inside the box. Each interval is the 15.87–84.13 % quantiles; warnings name a
/// parameter whose chains have not mixed ([`RHAT_LIMIT`], [`MIN_ESS`]) or whose posterior spans
/// most of its search range. With `temperatures = K > 1` the sample is parallel-tempered
/// ([`crate::posterior::tempering`], the geometric ladder of K rungs): the hot ensembles cross
/// ridges between basins that the untempered one would not leave, and the intervals are the
/// untempered ensemble's quantiles. Costs `walkers × (K·steps + 1)` simulations, a walker half's
/// of every rung in parallel.
///
/// # Errors
/// [`crate::posterior::PosteriorError`] for too few walkers for the freed parameters or a start
/// whose simulations mostly fail.
pub(super) fn mcmc_intervals(
    cf: &CandidateFit,
    effective_parameters: Option<f64>,
    fit: &job::FitSection,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<(Vec<Interval>, Vec<FitWarning>, PosteriorSummary)> {
    let s = &fit.uncertainty;
    let w = posterior_tempering(cf.free.len(), effective_parameters);
    let inside = |u: &[f64]| u.iter().all(|x| (0.0..=1.0).contains(x));
    // The likelihood tempered, the prior not, as a density in θ (or ln θ): docs/priors.md, "Priors".
    let prior = &cf.problem.prior;
    let log_parts = |u: &[f64]| match inside(u).then(|| cf.problem.cost_at(u)) {
        Some(c) if c < crate::search::FAILED_COST => {
            prior.log_parts(c, w, &cf.free, &cf.problem.base, u)
        }
        _ => (f64::NEG_INFINITY, 0.0),
    };
    let spread = crate::likelihood::covariance::cholesky_of_covariance(&cf.sigma_u, &cf.corr);
    let k = cf.free.len();
    let l = spread.unwrap_or_else(|| nalgebra::DMatrix::identity(k, k) * 0.01);
    let start =
        crate::posterior::ensemble::gaussian_ball_with(&cf.best_u, &l, s.walkers, s.seed, inside);
    let settings = crate::posterior::EnsembleSettings::new(s.walkers, s.steps, s.seed);
    let ladder = crate::posterior::tempering::geometric_ladder(s.temperatures, k);
    let per_step = s.walkers * ladder.len();
    if let Some(bar) = pb {
        bar.inc_length((s.walkers + per_step * s.steps) as u64);
        bar.inc(s.walkers as u64);
        bar.set_message("posterior sample (MCMC)");
    }
    // Without a terminal the bar is hidden: a line every 50 steps instead, as the search prints.
    let piped = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let started = std::time::Instant::now();
    let run = crate::posterior::tempering::sample_tempered(
        log_parts,
        start,
        &settings,
        &ladder,
        |step| {
            if let Some(bar) = pb {
                bar.inc(per_step as u64);
                if piped && (step + 1) % 50 == 0 {
                    let t = started.elapsed().as_secs();
                    eprintln!(
                        "progress: posterior sample: {}/{} steps, {t} s",
                        step + 1,
                        s.steps
                    );
                }
            }
            !crate::search::interrupt::stop_requested()
        },
    )?;
    let chains = &run.cold;
    let names: Vec<_> = cf.free.iter().map(|f| f.name).collect();
    let burn_in = s.burn_in.min(chains.steps().saturating_sub(1));
    let mut post =
        PosteriorSummary::new(&names, chains, burn_in, 1.0, w, |i, u| cf.free[i].value(u));
    if ladder.len() > 1 {
        post.swap_fractions = run.swap_fractions();
        post.ladder = run.betas;
    }
    let method = IntervalMethod::Mcmc {
        walkers: s.walkers,
        steps: chains.steps(),
        burn_in,
        tempering: w,
        temperatures: ladder.len(),
    };
    let mut warnings = Vec::new();
    let intervals = post
        .parameters
        .iter()
        .map(|p| {
            if p.r_hat.is_nan() || p.r_hat > RHAT_LIMIT || p.ess.is_nan() || p.ess < MIN_ESS {
                let (parameter, r_hat, ess) = (p.name, p.r_hat, p.ess);
                warnings.push(FitWarning::PosteriorUnconverged {
                    parameter,
                    r_hat,
                    ess,
                });
            }
            if !p.determined {
                warnings.push(FitWarning::PosteriorSpansBounds {
                    parameter: p.name,
                    span_fraction: p.span_fraction,
                    interval: [p.quantiles[0], p.quantiles[4]],
                });
            }
            Interval {
                lo: p.quantiles[1],
                hi: p.quantiles[3],
                level: 0.6827,
                method: method.clone(),
                widened_from: None,
                range_95: Some([p.quantiles[0], p.quantiles[4]]),
            }
        })
        .collect();
    Ok((intervals, warnings, post))
}

/// Laplace intervals (68.27 %): `[θ(u − σ_u), θ(u + σ_u)]` for each freed parameter, with `σ_u`
/// the 1σ of its normalised coordinate from the sandwich covariance `F⁻¹ V F⁻¹` of the recording's
/// likelihood at the fit ([`crate::search::evidence::at_fit`]), whose differences took the steps
/// `steps_u` (default [`crate::search::evidence::FISHER_STEP_U`]); through the search's coordinates, so a parameter
/// searched on a log scale gets an interval symmetric in `ln θ`. Every interval contains its
/// estimate. A parameter the likelihood does not inform (`σ_u = ∞`) gets its search range.
///
/// Asymptotically (many effectively independent bins, a smooth likelihood) this is the interval of
/// the likelihood's maximiser (White 1982, *Econometrica* 50:1, Theorem 3.2, for a likelihood
/// whose law is not exactly the data's), which the fit's estimate is with the default `[fit]
/// objective = "likelihood"`; its coverage is measured in docs/validation.md, "Intervals".
pub fn laplace_intervals(
    free: &[FreeParam],
    best_u: &[f64],
    sigma_u: &[f64],
    steps_u: Option<&[f64]>,
) -> Vec<Interval> {
    free.iter()
        .zip(best_u)
        .zip(sigma_u)
        .enumerate()
        .map(|(i, ((fp, u), s))| {
            let (lo, hi) = if s.is_finite() {
                (fp.value_unclamped(u - s), fp.value_unclamped(u + s))
            } else {
                (fp.lower, fp.upper)
            };
            Interval {
                lo,
                hi,
                level: 0.6827,
                method: IntervalMethod::Laplace {
                    fisher_step_u: steps_u
                        .and_then(|h| h.get(i).copied())
                        .unwrap_or(crate::search::evidence::FISHER_STEP_U),
                    noise_replicates: crate::search::evidence::NOISE_REPLICATES,
                    span_sigma: crate::search::evidence::SANDWICH_SPAN_SIGMA,
                },
                widened_from: None,
                range_95: None,
            }
        })
        .collect()
}

/// Conditional polishes per side of a profile at the most: the walk doubles its distance from the
/// fit each time, so the eighth point lies 128 first steps from it (or the search box's bound is
/// met first).
pub const PROFILE_MAX_STEPS: usize = 8;

/// The profile walk's first step, normalised units, at least: a parameter whose 1σ is smaller
/// still starts here (ripples of the likelihood are finer than that, docs/fit.md, "Settling").
pub const PROFILE_MIN_STEP_U: f64 = 0.005;

/// The profile walk's first step, normalised units, at the most (an undetermined parameter's 1σ
/// is infinite).
pub const PROFILE_MAX_STEP_U: f64 = 0.1;

/// The NLL rise at a 68.27 % profile-likelihood bound of a parameter whose sandwich and Fisher
/// 1σ are `sigma_sandwich` and `sigma_fisher`: the likelihood is a composite (Whittle-type)
/// likelihood, so twice its rise is distributed as `μ·χ²₁` with `μ = σ²_sandwich/σ²_Fisher`, not as
/// `χ²₁` (Kent 1982, *Biometrika* 69:1, Theorem 3.1; Varin, Reid & Firth 2011, *Statistica Sinica*
/// 21:5, §2.3), and the bound is at `μ·`[`PROFILE_68_NATS`]. On a quadratic likelihood the
/// profile interval is then the Laplace one. `μ = 1` where either 1σ is not finite and positive.
pub fn profile_rise_limit(sigma_sandwich: f64, sigma_fisher: f64) -> f64 {
    let mu = (sigma_sandwich / sigma_fisher).powi(2);
    if mu.is_finite() && mu > 0.0 {
        PROFILE_68_NATS * mu
    } else {
        PROFILE_68_NATS
    }
}

/// Nelder–Mead iterations a profile step's polish typically makes before it stops at the
/// likelihood's ripples: only the progress bar's length estimate.
const PROFILE_POLISH_ITERATIONS_TYPICAL: u64 = 10;

/// One end of a parameter's profile-likelihood interval ([`profile_end`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileEnd {
    /// The 68.27 % end, normalised coordinate of the profiled parameter.
    pub u: f64,
    /// The profile crossed the 68.27 % rise limit (else the end is the search box's bound or the
    /// last point of the walk).
    pub closed: bool,
    /// The end is the search box's bound, reached with the profile still below the limit.
    pub at_bound: bool,
    /// The 95 % end: where the walk, carried on past the 68.27 % end, crossed the 95 % rise limit
    /// (else the bound or the walk's last point, as for `u`).
    pub u_95: f64,
    /// The lowest rise met along the walk, nats (negative: a point more likely than the fit).
    pub lowest_rise_nats: f64,
    /// Where that lowest rise was met, normalised coordinate.
    pub lowest_u: f64,
}

/// Where the profile crosses `limit` between a point at distance `d_in` (rise `r_in`) and one at
/// `d` (rise `r`) from the fit, linearly in √rise (exact for a quadratic profile).
fn crossing(limit: f64, (d_in, r_in): (f64, f64), (d, r): (f64, f64)) -> f64 {
    let (a, b) = (r_in.max(0.0).sqrt(), r.sqrt());
    let t = ((limit.sqrt() - a) / (b - a)).clamp(0.0, 1.0);
    d_in + t * (d - d_in)
}

/// Walks a parameter's profile from the fit at `u0` in direction `side` (±1): steps of
/// `first_step`, 2·`first_step`, 4·`first_step`, … (at most [`PROFILE_MAX_STEPS`]), each point's
/// `rise(u)` (the minimum of the NLL over the other parameters with this one held at `u`, minus
/// the fit's), until the rise exceeds `limit_95` (`[limit_68, limit_95]`: the rises at the 68.27 %
/// and the 95 % ends); each end is interpolated between the two points around its limit linearly
/// in √rise (exact for a quadratic profile). Stops at the unit box's bound if the profile stays
/// below a limit up to it.
pub fn profile_end(
    u0: f64,
    first_step: f64,
    side: f64,
    [limit, limit_95]: [f64; 2],
    mut rise: impl FnMut(f64) -> f64,
) -> ProfileEnd {
    let (mut d_in, mut r_in) = (0.0_f64, 0.0_f64);
    let mut end = ProfileEnd {
        u: u0,
        closed: false,
        at_bound: false,
        u_95: u0,
        lowest_rise_nats: 0.0,
        lowest_u: u0,
    };
    for j in 0..PROFILE_MAX_STEPS {
        let x = (u0 + side * first_step * f64::from(1u32 << j)).clamp(0.0, 1.0);
        let d = (x - u0).abs();
        if d <= d_in {
            end.at_bound = !end.closed;
            return end;
        }
        let r = rise(x);
        if r < end.lowest_rise_nats {
            (end.lowest_rise_nats, end.lowest_u) = (r, x);
        }
        if !end.closed && r > limit {
            end.u = u0 + side * crossing(limit, (d_in, r_in), (d, r));
            end.closed = true;
        }
        if r > limit_95.max(limit) {
            end.u_95 = u0 + side * crossing(limit_95.max(limit), (d_in, r_in), (d, r));
            return end;
        }
        (d_in, r_in) = (d, r);
        if !end.closed {
            end.u = x;
        }
        end.u_95 = x;
        if x == 0.0 || x == 1.0 {
            end.at_bound = !end.closed;
            return end;
        }
    }
    end
}

/// [`profile_intervals_at`] of the chosen fit, with its sandwich and Fisher 1σ and `[fit]
/// polish_iterations`, on the progress bar `pb`.
///
/// # Errors
/// As [`profile_intervals_at`].
fn profile_intervals(
    cf: &CandidateFit,
    fit: &job::FitSection,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<(Vec<Interval>, Vec<FitWarning>)> {
    // The climb's last walk started at this optimum with this spread: its intervals stand.
    if let Some(w) = cf.profile_walk.as_ref().filter(|w| w.at_u == cf.best_u) {
        return Ok((w.intervals.clone(), w.warnings.clone()));
    }
    profile_walk(cf, ProfileStart::of(cf), fit.polish_iterations, pb)
}

/// [`profile_intervals_at`] of the candidate fit `cf` from `at`, its walks moving the progress bar.
pub(super) fn profile_walk(
    cf: &CandidateFit,
    at: ProfileStart,
    polish_iterations: u64,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<(Vec<Interval>, Vec<FitWarning>)> {
    let progress = pb.as_ref().map(|bar| {
        // The bar's estimate: two steps a side, each polish its simplex and ten iterations (on
        // the main job's fit they stop at the ripples' depth after 6–12).
        let k = cf.free.len() as u64;
        bar.inc_length(4 * k * (k + 2 * PROFILE_POLISH_ITERATIONS_TYPICAL));
        let reporting = Reporting::new(pb, cf.candidate);
        reporting.stage(format_args!("profile likelihood"));
        ProgressObserver {
            reporting,
            evals: Arc::new(AtomicUsize::new(0)),
        }
    });
    profile_with(&cf.problem, at, polish_iterations, progress)
}

/// Where [`profile_intervals_at`] starts: a fit and its spread, normalised coordinates.
#[derive(Debug, Clone, Copy)]
pub struct ProfileStart<'a> {
    /// The fit.
    pub u: &'a [f64],
    /// The problem's cost there (the recording's NLL), nats.
    pub cost_nats: f64,
    /// 1σ of each coordinate from the sandwich `F⁻¹ V F⁻¹` ([`crate::search::evidence::at_fit_smoothed`]).
    pub sigma_u: &'a [f64],
    /// 1σ of each coordinate from the Fisher information `F⁻¹` alone.
    pub fisher_sigma_u: &'a [f64],
    /// The correlations of `F⁻¹` (with `fisher_sigma_u`): the valley the profile follows, from
    /// which each step's polish is also started ([`valley_start`]); `None`: every polish starts
    /// where the previous one ended.
    pub fisher_corr: Option<&'a [Vec<f64>]>,
}

impl<'a> ProfileStart<'a> {
    /// The chosen fit's optimum, cost and spread (the Fisher 1σ, or the sandwich's where the fit
    /// has none).
    fn of(cf: &'a CandidateFit) -> Self {
        let (fisher_sigma_u, fisher_corr) = match (&cf.fisher_sigma_u, &cf.fisher_corr) {
            (Some(s), Some(c)) => (s.as_slice(), c.as_slice()),
            _ => (cf.sigma_u.as_slice(), cf.corr.as_slice()),
        };
        ProfileStart {
            u: &cf.best_u,
            cost_nats: cf.cost,
            sigma_u: &cf.sigma_u,
            fisher_sigma_u,
            fisher_corr: Some(fisher_corr),
        }
    }
}

/// Where the polish of a profile step that moves coordinate `i` from `x_prev` to `x` starts on
/// the valley of a quadratic NLL with covariance `Σ = F⁻¹` (1σ `sigma`, correlations `corr`): the
/// other coordinates of `prev` (the previous step's end) moved by `(x − x_prev)·Σ_oi/Σ_ii`, their
/// regression on coordinate `i`, which is exactly the minimiser over them with `i` held at `x`
/// (Venzon & Moolgavkar 1988, *Appl. Stat.* 37:1, the profile trace's predictor step), kept in the
/// box. Where the likelihood's correlations are strong (0.96–0.99 between A, C and k1 on the
/// calibration recordings) a polish started beside the valley at `prev` must first walk several
/// of its widths across it; started here it corrects only the valley's bend. `None` where the
/// covariance is not finite or `σ_i` is not positive.
pub fn valley_start(
    prev: &[f64],
    (i, x_prev, x): (usize, f64, f64),
    sigma: &[f64],
    corr: &[Vec<f64>],
) -> Option<Vec<f64>> {
    let si = sigma[i];
    if !(si.is_finite() && si > 0.0) {
        return None;
    }
    let mut u = prev.to_vec();
    for (o, uo) in u.iter_mut().enumerate() {
        if o == i {
            *uo = x;
            continue;
        }
        let slope = corr[o][i] * sigma[o] / si;
        if !slope.is_finite() {
            return None;
        }
        *uo = (*uo + (x - x_prev) * slope).clamp(0.0, 1.0);
    }
    Some(u)
}

/// Profile-likelihood intervals (68.27 %) from a fit (Pawitan 2001, *In All Likelihood*, §2.6;
/// Raue et al. 2009, *Bioinformatics* 25:15, for models of this kind): for each freed parameter
/// and each side, [`profile_end`] with the other parameters re-polished by Nelder–Mead
/// (`polish_iterations`, initial simplex [`POLISH_STEP_U`]) at every step, each polish starting where the
/// previous one ended or, where that is more likely, on the valley of `F⁻¹` ([`valley_start`],
/// with `at.fisher_corr`), and the limit [`profile_rise_limit`] from the parameter's sandwich and
/// Fisher 1σ. Where the likelihood is quadratic this gives the Laplace interval; where it is flat
/// or bent (a ridge, a valley) the interval follows the likelihood instead of its curvature at the
/// fit. Where the cost's jitter at the fit ([`RoundingJitter`]) exceeds the smallest rise limit,
/// every rise is read between costs averaged over each point's `2k + 1` rounding draws
/// ([`RoundingJitter::probe`], `2k + 1` more simulations per step): the fit's own draw is the one
/// the search kept for being low, and a step's polish ends on a low draw too. The 2k walks run in
/// parallel; each costs one polish per step, typically two or three. A
/// failed simulation counts as an infinite rise. Warnings name a parameter whose profile reaches
/// its search bound or runs out of steps below the limit, and a walk that met a point more likely
/// than the fit by more than
/// [`crate::search::strategy::CONFIRM_NATS`] (the search ended short of the optimum). The problem's
/// evaluation and failure counters include the polishes.
///
/// # Errors
/// [`crate::search::FitError::Optimiser`] when argmin fails during an interrupt (otherwise a polish that
/// fails counts as an infinite rise).
pub fn profile_intervals_at(
    problem: &Arc<SpectralProblem>,
    at: ProfileStart,
    polish_iterations: u64,
) -> Result<(Vec<Interval>, Vec<FitWarning>)> {
    profile_with(problem, at, polish_iterations, None)
}

/// [`profile_intervals_at`], each polish reported to `progress`.
fn profile_with(
    problem: &Arc<SpectralProblem>,
    at: ProfileStart,
    polish_iterations: u64,
    progress: Option<ProgressObserver>,
) -> Result<(Vec<Interval>, Vec<FitWarning>)> {
    use rayon::prelude::*;
    let n = at.u.len();
    let limit = |i: usize| profile_rise_limit(at.sigma_u[i], at.fisher_sigma_u[i]);
    let jitter = RoundingJitter::at(problem, at.u);
    let jitter_nats = jitter.as_ref().map_or(0.0, |j| j.sd_nats);
    let smallest_limit = (0..n).map(limit).fold(f64::INFINITY, f64::min);
    // Where the cost jitters by more than a rise limit, each rise is read between draw-averaged
    // costs: the fit's own draw is the one the search kept for being low.
    let averaged_fit = jitter
        .as_ref()
        .filter(|j| j.sd_nats > smallest_limit)
        .map(RoundingJitter::mean_nats);
    let walk = |(i, side): (usize, f64)| -> Result<ProfileEnd> {
        let first = at.sigma_u[i].clamp(PROFILE_MIN_STEP_U, PROFILE_MAX_STEP_U);
        let first = if first.is_nan() {
            PROFILE_MAX_STEP_U
        } else {
            first
        };
        let mut start = at.u.to_vec();
        let mut x_prev = at.u[i];
        let mut failure = None;
        let limits = [limit(i), limit(i) * PROFILE_95_OVER_68];
        let end = profile_end(at.u[i], first, side, limits, |x| {
            let observer = progress.clone();
            let from = step_start(problem, &at, &start, (i, x_prev, x));
            x_prev = x;
            match polish_pinned(
                problem,
                &from,
                (i, x),
                (POLISH_STEP_U, jitter_nats),
                polish_iterations,
                observer,
            ) {
                Ok((u, cost)) => {
                    let rise = match averaged_fit {
                        Some(fit) => RoundingJitter::probe(problem, &u)
                            .map_or(cost - at.cost_nats, |j| j.mean_nats() - fit),
                        None => cost - at.cost_nats,
                    };
                    start = u;
                    rise
                }
                Err(e) => {
                    failure.get_or_insert(e);
                    f64::INFINITY
                }
            }
        });
        match failure {
            Some(e) if crate::search::interrupt::stop_requested() => Err(e),
            _ => Ok(end),
        }
    };
    let sides: Vec<(usize, f64)> = (0..n).flat_map(|i| [(i, -1.0), (i, 1.0)]).collect();
    let ends: Vec<ProfileEnd> = sides.par_iter().map(|s| walk(*s)).collect::<Result<_>>()?;
    let mut warnings: Vec<FitWarning> = (jitter.as_ref())
        .and_then(|j| j.warning_above(smallest_limit))
        .into_iter()
        .collect();
    let mut intervals = Vec::with_capacity(n);
    for (i, fp) in problem.free.iter().enumerate() {
        let (lo, hi) = (ends[2 * i], ends[2 * i + 1]);
        intervals.push(Interval {
            lo: fp.value(lo.u),
            hi: fp.value(hi.u),
            level: 0.6827,
            method: IntervalMethod::Profile {
                rise_limit_nats: limit(i),
            },
            widened_from: None,
            range_95: Some([fp.value(lo.u_95), fp.value(hi.u_95)]),
        });
        warnings.extend(profile_warnings(fp, limit(i), lo, hi));
    }
    Ok((intervals, warnings))
}

/// The start of a profile step's polish: the previous step's end `prev` with coordinate `i` at
/// `x`, or its [`valley_start`] where that is more likely (two simulations).
fn step_start(
    problem: &SpectralProblem,
    at: &ProfileStart,
    prev: &[f64],
    (i, x_prev, x): (usize, f64, f64),
) -> Vec<f64> {
    let mut held = prev.to_vec();
    held[i] = x;
    let Some(valley) =
        (at.fisher_corr).and_then(|c| valley_start(prev, (i, x_prev, x), at.fisher_sigma_u, c))
    else {
        return held;
    };
    if problem.cost_at(&valley) < problem.cost_at(&held) {
        valley
    } else {
        held
    }
}

/// [`profile_intervals_at`]'s warnings for one parameter: a side that reached the search box's
/// bound, and a point more likely than the fit.
fn profile_warnings(fp: &FreeParam, limit: f64, lo: ProfileEnd, hi: ProfileEnd) -> Vec<FitWarning> {
    let mut warnings = Vec::new();
    let bounds: Vec<End> = [(lo, End::Lower), (hi, End::Upper)]
        .iter()
        .filter(|(e, _)| e.at_bound)
        .map(|(_, s)| *s)
        .collect();
    if !bounds.is_empty() {
        warnings.push(FitWarning::ProfileAtBound {
            parameter: fp.name,
            rise_limit_nats: limit,
            bounds,
        });
    }
    for (e, end) in [(lo, End::Lower), (hi, End::Upper)] {
        if !e.closed && !e.at_bound {
            warnings.push(FitWarning::ProfileOpen {
                parameter: fp.name,
                rise_limit_nats: limit,
                end,
                value: fp.value(e.u),
            });
        }
    }
    let lowest = if lo.lowest_rise_nats <= hi.lowest_rise_nats {
        lo
    } else {
        hi
    };
    if lowest.lowest_rise_nats < -crate::search::strategy::CONFIRM_NATS {
        warnings.push(FitWarning::ProfileMoreLikely {
            parameter: fp.name,
            gain_nats: -lowest.lowest_rise_nats,
            value: fp.value(lowest.lowest_u),
        });
    }
    warnings
}

/// [`widen_to_near_best`] on the chosen fit, with the points its problem kept.
fn near_best_of(cf: &CandidateFit, intervals: &mut [Interval]) -> Vec<FitWarning> {
    let at = ProfileStart::of(cf);
    let near = cf
        .problem
        .near_best
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    widen_to_near_best(&cf.free, at, &near, intervals)
}

/// Widens each interval to contain the points the search evaluated whose cost lies within the
/// parameter's profile rise limit of the fit ([`profile_rise_limit`]). The profile likelihood at
/// a point's value of a parameter is at most the point's cost (the others held there instead of
/// re-optimised), so such a point lies inside that parameter's 68.27 % profile-likelihood region
/// (Pawitan 2001, *In All Likelihood*, §2.6), and a profile interval would contain it. The search's
/// own simulations (its polishes, settling, valley polishes, profile walks: every evaluation at the
/// polish's tolerance, [`crate::search::problem::EvaluatedNearBest`]) thereby sample the region a
/// curvature at the fit can understate where the likelihood is flat or bent: a valley whose
/// floor the polishes walked along, a resting neck's ridge. Costs no simulation.
///
/// Returns a warning for each parameter whose interval grew by more than a tenth of its width,
/// naming the span the points reach, and one when a point was more likely than the fit by more
/// than [`crate::search::strategy::CONFIRM_NATS`] (the search ended short of its own best evaluation).
pub fn widen_to_near_best(
    free: &[FreeParam],
    at: ProfileStart,
    near: &crate::search::problem::EvaluatedNearBest,
    intervals: &mut [Interval],
) -> Vec<FitWarning> {
    let mut warnings = Vec::new();
    for (i, fp) in free.iter().enumerate() {
        let limit = profile_rise_limit(at.sigma_u[i], at.fisher_sigma_u[i]);
        let (lo0, hi0) = (intervals[i].lo, intervals[i].hi);
        let (mut p_lo, mut p_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for (_, u) in near.at_most(at.cost_nats + limit) {
            let v = fp.value(u[i]);
            p_lo = p_lo.min(v);
            p_hi = p_hi.max(v);
        }
        widen(&mut intervals[i], p_lo, p_hi);
        widen_range_95(
            &mut intervals[i],
            near,
            at.cost_nats + limit * PROFILE_95_OVER_68,
            |u| fp.value(u[i]),
        );
        let (lo, hi) = (intervals[i].lo, intervals[i].hi);
        if (lo0 - lo) + (hi - hi0) > NEAR_BEST_WARN_WIDTH * (hi0 - lo0) {
            warnings.push(FitWarning::WidenedInterval {
                parameter: fp.name,
                rise_limit_nats: limit,
                points: [p_lo, p_hi],
                method: [lo0, hi0],
                widened: [lo, hi],
            });
        }
    }
    warnings.extend(short_of_best(at.cost_nats, near));
    warnings
}

/// The Laplace intervals of `cf` checked against its likelihood along the principal axes of
/// `F⁻¹` ([`crate::likelihood::secant`]): a warning per axis along which the likelihood is flatter than the
/// quadratic the intervals assume. `2k` simulations.
fn secant_check(cf: &CandidateFit) -> Vec<FitWarning> {
    use crate::likelihood::secant::{
        FlatAxisReport, SECANT_PROBE_SIGMA, flat_axes, main_parameter,
    };
    let (Some(fs), Some(fc)) = (&cf.fisher_sigma_u, &cf.fisher_corr) else {
        return Vec::new();
    };
    if crate::search::interrupt::stop_requested() {
        return Vec::new();
    }
    let cost_at =
        |u: &[f64]| Some(cf.problem.cost_at(u)).filter(|c| *c < crate::search::FAILED_COST);
    flat_axes(cost_at, &cf.best_u, cf.cost, (fs, fc))
        .iter()
        .map(|a| {
            FitWarning::FlatterThanCurvature(FlatAxisReport {
                parameter: main_parameter(&cf.free, a).name,
                rise_nats: a.rise_nats,
                quadratic_nats: 0.5 * SECANT_PROBE_SIGMA * SECANT_PROBE_SIGMA,
                stretch: a.stretch,
            })
        })
        .collect()
}

/// The profile rise limit ([`profile_rise_limit`]) of μ_d of `law` at each of `speeds_m_per_s`,
/// from its sandwich and Fisher 1σ by the delta method over the fit's spreads (`fisher` `None`:
/// μ = 1, the limit [`PROFILE_68_NATS`]).
pub fn mu_d_rise_limits(
    law: &crate::model::FrictionLaw,
    speeds_m_per_s: &[f64],
    sandwich: crate::model::friction_curve::Spread<'_>,
    fisher: Option<crate::model::friction_curve::Spread<'_>>,
) -> Vec<f64> {
    let sigma = |s: Option<crate::model::friction_curve::Spread<'_>>, v: f64| {
        s.and_then(|s| s.mu_sigma(law, v)).unwrap_or(f64::NAN)
    };
    (speeds_m_per_s.iter())
        .map(|&v| profile_rise_limit(sigma(Some(sandwich), v), sigma(fisher, v)))
        .collect()
}

/// The friction laws of the points the chosen fit's search evaluated within the largest of
/// `limits` (nats) of its cost, with each point's cost above the fit's
/// ([`crate::search::problem::EvaluatedNearBest`]).
pub(crate) fn near_best_laws(
    cf: &CandidateFit,
    limits: &[f64],
) -> Vec<(f64, crate::model::FrictionLaw)> {
    let widest = limits.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let near = (cf.problem.near_best.lock()).unwrap_or_else(|e| e.into_inner());
    near.at_most(cf.cost + widest)
        .map(|(c, u)| (c - cf.cost, cf.problem.params_at(u).friction))
        .collect()
}

/// Widens `interval` to contain `[lo, hi]`, keeping its ends before the first widening in
/// [`Interval::widened_from`]; its 95 % range, where it has one, keeps containing it.
fn widen(interval: &mut Interval, lo: f64, hi: f64) {
    if lo >= interval.lo && hi <= interval.hi {
        return;
    }
    interval
        .widened_from
        .get_or_insert([interval.lo, interval.hi]);
    interval.lo = interval.lo.min(lo);
    interval.hi = interval.hi.max(hi);
    if let Some(r) = interval.range_95.as_mut() {
        *r = [r[0].min(interval.lo), r[1].max(interval.hi)];
    }
}

/// How many of its 68.27 % half-widths a 95 % interval reaches on a quadratic likelihood:
/// Φ⁻¹(0.975)/Φ⁻¹(0.84135) = 1.959964/1.000022 (the 68.27 % level is 0.6827).
pub fn wide_over_68_half_widths() -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal};
    let n = Normal::standard();
    n.inverse_cdf(0.975) / n.inverse_cdf(0.5 * (1.0 + 0.6827))
}

/// Widens each interval's 95 % range to at least [`wide_over_68_half_widths`] times its reported
/// 68.27 % half-width on each side, in the search's coordinate (clamped to the search box), around
/// the estimate at `best_u`. Where the reported interval was widened to the search's points within
/// the 68.27 % rise ([`widen_to_near_best`]), the walk's polishes found the profile higher than
/// those points show it to be, and beyond them it is likely too high as well: a 95 % end short of
/// the reported interval's quadratic extrapolation would claim less than the reported interval
/// does. On the calibration recordings the walk's own 95 % end fell short of it on one side in
/// most widened fits (docs/validation.md, "Calibration by simulation").
fn floor_range_95(free: &[FreeParam], best_u: &[f64], intervals: &mut [Interval]) {
    for ((fp, &u0), iv) in free.iter().zip(best_u).zip(intervals.iter_mut()) {
        iv.range_95 = floored_range_95(fp, u0, iv);
    }
}

/// `iv`'s 95 % range as [`floor_range_95`] leaves it, for the parameter `fp` estimated at the
/// normalised coordinate `u0`; `None` where `iv` has no 95 % range.
pub fn floored_range_95(fp: &FreeParam, u0: f64, iv: &Interval) -> Option<[f64; 2]> {
    let r = iv.range_95?;
    let k = wide_over_68_half_widths();
    let (u_lo, u_hi) = (fp.u_of(iv.lo), fp.u_of(iv.hi));
    let lo = fp.value(u0 - k * (u0 - u_lo));
    let hi = fp.value(u0 + k * (u_hi - u0));
    Some([r[0].min(lo), r[1].max(hi)])
}

/// The 95 % rise over the 68.27 % one ([`PROFILE_95_NATS`] / [`PROFILE_68_NATS`]): a parameter's
/// 95 % limit is its calibrated 68.27 % limit times this.
pub const PROFILE_95_OVER_68: f64 = PROFILE_95_NATS / PROFILE_68_NATS;

/// Widens `interval`'s 95 % range (where it has one) to the values `value(u)` of the points in
/// `near` whose cost is at most `ceiling` nats: as [`widen_to_near_best`] does the 68.27 %
/// interval, at the 95 % rise.
fn widen_range_95(
    interval: &mut Interval,
    near: &crate::search::problem::EvaluatedNearBest,
    ceiling: f64,
    value: impl Fn(&[f64]) -> f64,
) {
    let Some(r) = interval.range_95.as_mut() else {
        return;
    };
    for (_, u) in near.at_most(ceiling) {
        let v = value(u);
        *r = [r[0].min(v), r[1].max(v)];
    }
}

/// The growth of an interval (a fraction of its width) above which [`widen_to_near_best`] warns.
pub const NEAR_BEST_WARN_WIDTH: f64 = 0.1;

/// How far [`along_contact_ridge`] looks: the free neck stiffness times each factor.
pub const RIDGE_K1_FACTORS: [f64; 4] = [
    0.5,
    std::f64::consts::FRAC_1_SQRT_2,
    std::f64::consts::SQRT_2,
    2.0,
];

/// The rise of the NLL at a 68.27 % one-parameter profile-likelihood bound: half the 68.27 % point of
/// χ²₁ (Pawitan 2001, *In All Likelihood*, §2.6).
pub const PROFILE_68_NATS: f64 = 0.5;

/// The rise of the NLL at a 95 % one-parameter profile-likelihood bound: half the 95 % point of
/// χ²₁, 3.841459/2 (Pawitan 2001, §2.6); scaled by μ like [`PROFILE_68_NATS`].
pub const PROFILE_95_NATS: f64 = 1.920_729_410_347_062;

/// Widens the intervals of `k1` and `theta_c` along the shoulder's contact-moment ridge, where a
/// fit frees both with `k1c`. While the neck rests on the shoulder its moment is
/// `k1c·θ − (k1c − k1)·θ_c` (docs/model.md, "Shoulder contact"), so a neck that rarely leaves the
/// shoulder shows the spectra `(k1c − k1)·θ_c`, not k1 and θ_c apart; the Fisher information at
/// the fit sees the stick–slip likelihood's ripples there and can call both determined
/// (docs/model-choice.md, "Shoulder contact"). Each point
/// `k1' = f·k1`, `θ_c' = (k1c − k1)·θ_c / (k1c − k1')` for f in [`RIDGE_K1_FACTORS`] inside the
/// search box is evaluated with the other parameters held; one whose cost is within
/// [`PROFILE_68_NATS`] of the fit's lies inside the 68.27 % profile-likelihood region (holding the
/// others only raises the cost), so the two intervals are widened to contain it. Returns a warning
/// naming the span found; nothing when the fit frees no such triple or no point qualifies. Costs
/// up to 4 simulations.
fn along_contact_ridge(cf: &CandidateFit, intervals: &mut [Interval]) -> Vec<FitWarning> {
    let cost = |u: &[f64]| cf.problem.cost_at(u);
    widen_along_ridge(&cf.free, &cf.best_u, cf.cost, cost, intervals)
        .map(|(k1_lo, k1_hi)| FitWarning::ContactRidge { k1_lo, k1_hi })
        .into_iter()
        .collect()
}

/// The point of the contact-moment ridge through `(k1, k1c, theta_c)` with free stiffness
/// `k1_r`: the contact angle that keeps `(k1c − k1)·θ_c`, or `None` where `k1_r` is on the other
/// side of `k1c` (no such angle).
pub fn ridge_theta_c(k1: f64, k1c: f64, theta_c: f64, k1_r: f64) -> Option<f64> {
    ((k1c - k1_r) * (k1c - k1) > 0.0).then(|| (k1c - k1) * theta_c / (k1c - k1_r))
}

/// [`along_contact_ridge`] on any `cost` of the normalised coordinates, with `cost0` at `best_u`:
/// the span of k1 found inside the profile region, `None` when the freed parameters lack k1, k1c
/// or theta_c or no ridge point qualifies.
fn widen_along_ridge(
    free: &[FreeParam],
    best_u: &[f64],
    cost0: f64,
    cost: impl Fn(&[f64]) -> f64,
    intervals: &mut [Interval],
) -> Option<(f64, f64)> {
    use crate::model::ParamId;
    let at = |id: ParamId| free.iter().position(|f| f.name == id);
    let (i_k1, i_kc, i_th) = (at(ParamId::K1)?, at(ParamId::K1c)?, at(ParamId::ThetaC)?);
    let value = |i: usize| free[i].value(best_u[i]);
    let (k1, k1c, theta_c) = (value(i_k1), value(i_kc), value(i_th));
    let inside = |i: usize, v: f64| (free[i].lower..=free[i].upper).contains(&v);
    let mut span: Option<(f64, f64)> = None;
    for k1_r in RIDGE_K1_FACTORS.map(|f| f * k1) {
        let Some(theta_r) = ridge_theta_c(k1, k1c, theta_c, k1_r) else {
            continue;
        };
        if !inside(i_k1, k1_r) || !inside(i_th, theta_r) {
            continue;
        }
        let mut u = best_u.to_vec();
        u[i_k1] = free[i_k1].u_of(k1_r);
        u[i_th] = free[i_th].u_of(theta_r);
        if cost(&u) - cost0 > PROFILE_68_NATS {
            continue;
        }
        for (i, v) in [(i_k1, k1_r), (i_th, theta_r)] {
            widen(&mut intervals[i], v, v);
        }
        let (lo, hi) = span.unwrap_or((k1, k1));
        span = Some((lo.min(k1_r), hi.max(k1_r)));
    }
    span
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
///    intervals come out too narrow: docs/uncertainty.md, "Uncertainty"); replicates run in parallel with rayon;
/// 4. the interval is the basic bootstrap interval `[2θ̂ − q(84.13 %), 2θ̂ − q(15.87 %)]` of the
///    replicates' estimates `θ*` (Davison & Hinkley 1997, eq. 5.6), which corrects the replicates' bias.
///
/// What it covers: the spread from tracking noise and spectral estimation. What it does not: the
/// optimiser ending in a different local minimum of the (rough) stick–slip cost surface, which can
/// be larger (docs/uncertainty.md, "What they measure").
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
            let at_fit = problem.params_at(best_u);
            rep.prior = Arc::new(problem.prior.replicate(&at_fit, &mut rng));
            for (o, src) in problem.others.iter().zip(&references[1..]) {
                rep.others.push(src.replicate(o, &mut rng)?);
            }
            let rep = Arc::new(rep);
            let (u, cost) = if settings.full_refit {
                let seed = fit.seed.wrapping_add(1 + r as u64);
                let found = optimise(&rep, fit, seed, &[], None, Confirming::NOW)?;
                (found.u, found.cost)
            } else {
                let (u, _, cost) = polish(
                    &rep,
                    best_u,
                    POLISH_STEP_U,
                    settings.polish_iterations,
                    None,
                )?;
                (u, cost)
            };
            // The estimator's last stage, as in the fit (`search::fit_candidate`).
            let u = if rep.cost_is_nll() {
                crate::search::evidence::settle_point(&rep, &u, cost)?.0
            } else {
                u
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
                widened_from: None,
                range_95: None,
            }
        })
        .collect())
}

/// One recording's side of a bootstrap replicate: the best-fit model's signal (NaN where the
/// measurement is) and the white-noise level estimated from the measurement's floor.
pub(super) struct ReplicateSource {
    pub(super) x_model: Vec<f64>,
    pub(super) sigma: f64,
    pub(super) normal: rand_distr::Normal<f64>,
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
            return Err(crate::search::FitError::NoNoise {
                label: problem.label.clone(),
                floor,
            }
            .into());
        }
        let normal = rand_distr::Normal::new(0.0, sigma)
            .map_err(|source| crate::search::FitError::NoiseDistribution { sigma, source })?;
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
            // The replicate's bands keep the recording's verdict on lines: the same comparison.
            lines: problem.lines.clone(),
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
            local_solver: problem.local_solver,
            swarm_cost: problem.swarm_cost,
            objective: problem.objective,
            weights: problem.weights,
            likelihood: Err(crate::search::NoLikelihood::NotBuilt),
            signal_likelihood: None,
            evaluations: problem.evaluations.clone(),
            failures: problem.failures.clone(),
            failure_causes: problem.failure_causes.clone(),
            first_failure: Mutex::new(None),
            near_best: Mutex::new(Default::default()),
            last_jitter: Mutex::new(None),
            prior: problem.prior.clone(),
        })
        .map(|mut rep| {
            // The replicate's own likelihood: its measured ordinates and noise, the recording's
            // terms.
            let time_domain = problem.likelihood.as_ref().is_ok_and(|l| l.time_domain);
            let blocks = problem.likelihood.as_ref().ok().and_then(|l| l.block_len);
            let noise = problem
                .likelihood
                .as_ref()
                .map_or(NoiseSpectrum::default(), |l| l.noise_spectrum);
            rep.likelihood = RecordingLikelihood::new(&rep, &x, time_domain)
                .map(|l| l.with_noise(noise).with_blocks(blocks))
                .map(Arc::new)
                .map_err(|e| crate::search::NoLikelihood::Recording(Arc::new(e)));
            rep
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
) -> Vec<FitWarning> {
    let mut w = Vec::new();
    for p in params.iter().filter(|p| !p.determined) {
        w.push(FitWarning::Undetermined { parameter: p.name });
    }
    for i in 0..params.len() {
        for j in (i + 1)..params.len() {
            let r = corr
                .get(i)
                .and_then(|row| row.get(j))
                .copied()
                .unwrap_or(f64::NAN);
            if r.abs() > 0.95 {
                w.push(FitWarning::TradeOff {
                    first: params[i].name,
                    second: params[j].name,
                    correlation: r,
                });
            }
        }
    }
    for (p, u) in params.iter().zip(best_u) {
        if *u <= 0.005 || *u >= 0.995 {
            w.push(FitWarning::OnBound {
                parameter: p.name,
                bound: if *u <= 0.005 { End::Lower } else { End::Upper },
                value: p.value,
            });
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ParamId;
    use nalgebra::{DMatrix, DVector};

    /// `auto` samples where the likelihood reaches more than twice a Laplace width: the main
    /// job's largest factor (1.47, C's near-best points) keeps Laplace; a development fit's 4.4
    /// (dev_001's A) samples, naming that parameter; a zero-width interval that grew is infinitely
    /// wider.
    #[test]
    fn auto_samples_beyond_twice_a_laplace_width() {
        let iv = |lo: f64, hi: f64| Interval {
            lo,
            hi,
            level: 0.6827,
            method: IntervalMethod::Laplace {
                fisher_step_u: 0.003,
                noise_replicates: 256,
                span_sigma: 0.5,
            },
            widened_from: None,
            range_95: None,
        };
        assert!((width_ratio((&iv(1.0, 2.0), &iv(0.8, 2.2))) - 1.4).abs() < 1e-12);
        assert_eq!(width_ratio((&iv(1.0, 1.0), &iv(0.9, 1.0))), f64::INFINITY);
        assert_eq!(width_ratio((&iv(1.0, 1.0), &iv(1.0, 1.0))), 1.0);
        assert_eq!(widest_beyond(&[1.09, 1.07, 1.47, 1.0]), None);
        assert_eq!(widest_beyond(&[4.4, 1.3, 4.7, 1.7]), Some(2));
        assert_eq!(widest_beyond(&[2.0]), None);
        assert_eq!(widest_beyond(&[]), None);
    }

    /// The NLL rise of a quadratic profile with 1σ `sigma` in a composite likelihood whose rise is
    /// `μ` times the exact one: `μ·(x − u0)²/(2σ²)`.
    fn quadratic_rise(u0: f64, sigma: f64, mu: f64) -> impl FnMut(f64) -> f64 {
        move |x| mu * (x - u0).powi(2) / (2.0 * sigma * sigma)
    }

    #[test]
    fn the_tempered_posterior_has_the_sandwich_covariance_where_v_is_proportional_to_f() {
        // Closed form: with V = μF, tr(F⁻¹V) = μk, w = 1/μ, and exp(−w·NLL) of a quadratic NLL
        // has covariance F⁻¹/w = μF⁻¹ = F⁻¹VF⁻¹.
        let (k, mu) = (4, 0.275);
        assert!((posterior_tempering(k, Some(mu * k as f64)) - 1.0 / mu).abs() < 1e-12);
        assert_eq!(posterior_tempering(k, None), 1.0);
        assert_eq!(posterior_tempering(k, Some(0.0)), 1.0);
        assert_eq!(posterior_tempering(k, Some(f64::NAN)), 1.0);
    }

    #[test]
    fn a_quadratic_profile_ends_at_one_sigma() {
        // Closed form: a quadratic log-likelihood's 68.27 % profile interval is the estimate ± 1σ
        // and its 95 % one ± 1.959964σ (√(2·PROFILE_95_NATS), the 97.5 % point of N(0, 1)); with
        // the rise scaled by μ = σ²_sandwich/σ²_Fisher the calibrated limits give the same ends
        // (the walk interpolates in √rise, exact for a quadratic).
        assert!(((2.0 * PROFILE_95_NATS).sqrt() - 1.959_963_984_540_054).abs() < 1e-12);
        for (u0, sigma, first, mu) in [
            (0.4, 0.02, 0.02, 1.0),
            (0.4, 0.02, 0.005, 0.3),
            (0.7, 0.013, 0.1, 0.5),
        ] {
            for side in [-1.0, 1.0] {
                let limits = [PROFILE_68_NATS * mu, PROFILE_95_NATS * mu];
                let end = profile_end(u0, first, side, limits, quadratic_rise(u0, sigma, mu));
                assert!(end.closed && !end.at_bound, "{end:?}");
                assert!(
                    (end.u - (u0 + side * sigma)).abs() < 1e-12,
                    "u0 {u0} σ {sigma} side {side}: end {}",
                    end.u
                );
                let want_95 = u0 + side * 1.959_963_984_540_054 * sigma;
                assert!(
                    (end.u_95 - want_95).abs() < 1e-12,
                    "u0 {u0} σ {sigma} side {side}: 95 % end {}",
                    end.u_95
                );
            }
        }
        // The calibrated limit: μ = (σ_sandwich/σ_Fisher)².
        assert!((profile_rise_limit(0.5, 1.0) - 0.125).abs() < 1e-15);
        assert_eq!(profile_rise_limit(1.0, f64::INFINITY), PROFILE_68_NATS);
        assert_eq!(profile_rise_limit(f64::NAN, 1.0), PROFILE_68_NATS);
    }

    /// μ_d's rise limit by the delta method: with A and C uncorrelated, σ_A = 0 and σ_C twice as
    /// wide in the sandwich as in the Fisher information, μ_d's σ ratio is 2 at every speed and
    /// the limit 0.5·4 = 2 nats; A alone enters with the weight e^(−Bv), which cancels in the
    /// ratio (2 again); without a Fisher spread the limit is [`PROFILE_68_NATS`].
    #[test]
    fn mu_d_rise_limits_follow_the_ratio_of_the_two_spreads() {
        use crate::model::friction_curve::Spread;
        let law = crate::model::FrictionLaw::Exponential {
            a: 0.8,
            b_s_per_m: 10.0,
            c: 0.2,
        };
        let speeds = [0.0, 0.01, 0.1];
        let ids = [ParamId::A, ParamId::C];
        let eye = vec![vec![1.0, 0.0], vec![0.0, 1.0]];
        let spread = |sigma: &'static [f64; 2]| Spread {
            ids: &ids,
            sigma,
            corr: &eye,
        };
        for (sandwich, fisher) in [(&[0.0, 0.02], &[0.0, 0.01]), (&[0.04, 0.0], &[0.02, 0.0])] {
            let limits = mu_d_rise_limits(&law, &speeds, spread(sandwich), Some(spread(fisher)));
            for l in limits {
                assert!((l - 2.0).abs() < 1e-12, "{l}");
            }
        }
        let limits = mu_d_rise_limits(&law, &speeds, spread(&[0.0, 0.02]), None);
        assert_eq!(limits, vec![PROFILE_68_NATS; 3]);
    }

    #[test]
    fn a_flat_profile_reaches_the_bound_and_a_dip_is_reported() {
        // Flat: the walk doubles its step (0.01, 0.02, …) to the box's bound (0.45 + 0.64 > 1).
        let end = profile_end(0.45, 0.01, 1.0, [0.5, 1.9], |_| 0.1);
        assert!(end.at_bound && !end.closed, "{end:?}");
        assert_eq!((end.u, end.u_95), (1.0, 1.0));
        // An estimate on the bound: nothing to walk.
        let end = profile_end(0.0, 0.01, -1.0, [0.5, 1.9], |_| {
            panic!("no step beyond the bound")
        });
        assert!(end.at_bound && end.u == 0.0);
        // A point more likely than the fit on the way out is kept.
        let end = profile_end(0.5, 0.01, 1.0, [0.5, 1.9], |x| {
            if (x - 0.52).abs() < 1e-12 {
                -2.0
            } else {
                10.0 * (x - 0.5)
            }
        });
        assert_eq!((end.lowest_rise_nats, end.lowest_u), (-2.0, 0.52));
        assert!(end.closed);
        // Eight doublings and still below the limit: open, at the walk's last point.
        let end = profile_end(0.5, 1e-4, 1.0, [0.5, 1.9], |_| 0.0);
        assert!(!end.closed && !end.at_bound);
        assert!((end.u - (0.5 + 1e-4 * 128.0)).abs() < 1e-15);
        assert_eq!(end.u_95, end.u);
        // A profile that flattens past its 68.27 % end (rise 0.6 from 0.52 on, below the 95 %
        // limit up to the bound): the 95 % end is the bound, where the 68.27 % end stays closed.
        let end = profile_end(0.5, 0.01, 1.0, [0.5, 1.9], |x| {
            if x > 0.515 { 0.6 } else { 0.1 }
        });
        assert!(end.closed && !end.at_bound, "{end:?}");
        assert!(end.u < 0.52 && end.u_95 == 1.0, "{end:?}");
    }

    #[test]
    fn a_failed_step_closes_the_interval_at_the_last_good_point() {
        // Steps 0.01, 0.02, 0.04 from 0.5. A simulation that fails beyond 0.53 is an infinite
        // rise: the end is the last point the model could simulate (0.52), not beyond it.
        let end = profile_end(0.5, 0.01, 1.0, [0.5, 1.9], |x| {
            if x > 0.53 { f64::INFINITY } else { 0.1 }
        });
        assert!(end.closed);
        assert!((end.u - 0.52).abs() < 1e-12, "{}", end.u);
        assert_eq!(end.u_95, end.u);
    }

    #[test]
    fn profile_warnings_name_an_open_side_and_a_more_likely_point() {
        let k1 = FreeParam::new(ParamId::K1, 0.005, 0.15);
        let end = |u: f64, at_bound: bool, lowest_rise_nats: f64| ProfileEnd {
            u,
            closed: !at_bound,
            at_bound,
            u_95: u,
            lowest_rise_nats,
            lowest_u: 0.6,
        };
        // Both sides closed, nothing below the fit by more than CONFIRM_NATS: no warning.
        assert!(profile_warnings(&k1, 0.2, end(0.4, false, -0.3), end(0.6, false, 0.0)).is_empty());
        let w = profile_warnings(&k1, 0.2, end(0.0, true, 0.0), end(0.6, false, -1.25));
        assert_eq!(w.len(), 2, "{w:?}");
        assert_eq!(
            w[0],
            FitWarning::ProfileAtBound {
                parameter: ParamId::K1,
                rise_limit_nats: 0.2,
                bounds: vec![End::Lower],
            }
        );
        assert!(w[0].to_string().contains("box's lower bound"), "{}", w[0]);
        // A walk that ran out of steps under the limit, away from the bound.
        let open = ProfileEnd {
            closed: false,
            ..end(0.6, false, 0.0)
        };
        let w_open = profile_warnings(&k1, 0.2, end(0.4, false, 0.0), open);
        assert!(
            matches!(
                w_open[..],
                [FitWarning::ProfileOpen {
                    parameter: ParamId::K1,
                    end: End::Upper,
                    ..
                }]
            ),
            "{w_open:?}"
        );
        // The point's value: u = 0.6 on k1's log axis, 0.005·30^0.6.
        let v = 0.005 * 30f64.powf(0.6);
        let FitWarning::ProfileMoreLikely {
            parameter: ParamId::K1,
            gain_nats,
            value,
        } = w[1]
        else {
            panic!("{:?}", w[1]);
        };
        assert_eq!(gain_nats, 1.25);
        assert!((value - v).abs() < 1e-12 * v, "{value} {v}");
    }

    #[test]
    fn a_ridge_point_keeps_the_moment_at_contact() {
        // (k1c − k1)·θ_c = (0.1 − 0.03)·0.05 = 3.5e-3 N·m at every point of the ridge.
        for k1_r in [0.015, 0.0212, 0.0424, 0.06] {
            let th = ridge_theta_c(0.03, 0.1, 0.05, k1_r).unwrap();
            assert!(((0.1 - k1_r) * th - 3.5e-3).abs() < 1e-15);
        }
        // Past k1c no angle keeps it.
        assert!(ridge_theta_c(0.03, 0.1, 0.05, 0.12).is_none());
    }

    fn setup() -> (Vec<FreeParam>, Vec<f64>, Vec<Interval>) {
        let free = vec![
            FreeParam::new(ParamId::K1, 0.005, 0.15),
            FreeParam::new(ParamId::K1c, 0.005, 0.15),
            FreeParam::new(ParamId::ThetaC, 0.02, 0.2),
        ];
        let u: Vec<f64> = [0.03, 0.1, 0.05]
            .iter()
            .zip(&free)
            .map(|(v, f)| f.u_of(*v))
            .collect();
        let iv = laplace_intervals(&free, &u, &[0.01, 0.01, 0.01], None);
        (free, u, iv)
    }

    #[test]
    fn intervals_widen_over_a_flat_contact_moment_ridge_and_not_over_a_bowl() {
        let (free, u, iv0) = setup();
        let phys =
            |u: &[f64]| -> Vec<f64> { free.iter().zip(u).map(|(f, x)| f.value(*x)).collect() };
        // A cost that sees only the moment at contact and k1c: flat along the ridge.
        let ridge = |u: &[f64]| {
            let p = phys(u);
            (((p[1] - p[0]) * p[2] - 3.5e-3) / 1e-5).powi(2) + ((p[1] - 0.1) / 1e-3).powi(2)
        };
        let mut iv = iv0.clone();
        let span = widen_along_ridge(&free, &u, 0.0, ridge, &mut iv).unwrap();
        assert!((span.0 - 0.015).abs() < 1e-12 && (span.1 - 0.06).abs() < 1e-12);
        assert!(iv[0].lo <= 0.015 + 1e-12 && iv[0].hi >= 0.06 - 1e-12);
        assert_eq!(iv[0].widened_from, Some([iv0[0].lo, iv0[0].hi]));
        // θ_c spans the ridge's angles: 3.5e-3/(0.1 − 0.015) to 3.5e-3/(0.1 − 0.06).
        assert!(iv[2].lo <= 3.5e-3 / 0.085 + 1e-12 && iv[2].hi >= 3.5e-3 / 0.04 - 1e-12);
        assert_eq!((iv[1].lo, iv[1].hi), (iv0[1].lo, iv0[1].hi));
        // A cost that also sees k1 (1 nat at ±1 % of it): no ridge point is within 0.5 nats.
        let bowl = |u: &[f64]| ridge(u) + ((phys(u)[0] - 0.03) / 3e-4).powi(2);
        let mut iv = iv0.clone();
        assert!(widen_along_ridge(&free, &u, 0.0, bowl, &mut iv).is_none());
        assert_eq!(iv, iv0);
    }

    /// Evaluates `cost` at each point of a grid over a square of half-width `half` around `u0`
    /// (21 × 21 points) and keeps them in a register, as the search's evaluations would be.
    fn evaluated_grid(
        u0: &[f64],
        half: f64,
        cost: impl Fn(&[f64]) -> f64,
    ) -> crate::search::problem::EvaluatedNearBest {
        let mut near = crate::search::problem::EvaluatedNearBest::default();
        for i in 0..21 {
            for j in 0..21 {
                let u = [
                    u0[0] + half * (i as f64 / 10.0 - 1.0),
                    u0[1] + half * (j as f64 / 10.0 - 1.0),
                ];
                near.record(&u, cost(&u));
            }
        }
        near
    }

    /// A point evaluated more than `CONFIRM_NATS` (0.5) below the fit's cost is reported with its
    /// gain; one 0.3 nats below is the likelihood's ripple and is not.
    #[test]
    fn a_point_more_likely_than_the_fit_is_reported() {
        let mut near = crate::search::problem::EvaluatedNearBest::default();
        near.record(&[0.5], 8.0);
        match short_of_best(9.0, &near) {
            Some(FitWarning::ShortOfBestEvaluation { gain_nats }) => assert_eq!(gain_nats, 1.0),
            other => panic!("{other:?}"),
        }
        assert!(short_of_best(8.3, &near).is_none());
    }

    #[test]
    fn near_best_keeps_what_lies_within_the_margin_of_the_lowest() {
        let mut near = crate::search::problem::EvaluatedNearBest::default();
        near.record(&[0.5], 10.0);
        near.record(&[0.6], 11.5);
        near.record(&[0.7], f64::NAN);
        // 2.5 nats above the lowest: never kept.
        near.record(&[0.8], 12.5);
        assert_eq!(near.at_most(f64::INFINITY).count(), 2);
        // A lower point leaves the first two behind the margin; the next pruning drops them.
        near.record(&[0.4], 8.0);
        for k in 0..200 {
            near.record(&[0.4 + 1e-4 * k as f64], 8.0 + 0.01 * k as f64);
        }
        assert_eq!(near.lowest(), 8.0);
        assert!(
            near.at_most(f64::INFINITY)
                .all(|(c, _)| c <= 8.0 + crate::search::problem::NEAR_BEST_MARGIN_NATS)
        );
        assert_eq!(near.at_most(8.0).count(), 2);
    }

    /// Closed form: on the quadratic NLL `½ Δuᵀ Σ⁻¹ Δu` of three coordinates (1σ 0.02, 0.01, 0.05,
    /// correlations 0.99, −0.6, −0.5) the minimum over the others with coordinate 0 held at `x`
    /// lies at `Δu_o = Σ_o0/Σ_00 · Δx`, where the NLL is the profile `Δx²/(2σ_0²)`; the start
    /// predicted from the fit (and again from that point, a second step) lies there, and holding
    /// the others where they were rises `1/(1 − R²)` times as much, R² the others' share of
    /// coordinate 0's variance.
    #[test]
    fn the_valley_start_lies_on_the_profile_of_a_quadratic() {
        let sigma = [0.02, 0.01, 0.05];
        let corr = vec![
            vec![1.0, 0.99, -0.6],
            vec![0.99, 1.0, -0.5],
            vec![-0.6, -0.5, 1.0],
        ];
        let cov = DMatrix::from_fn(3, 3, |a, b| corr[a][b] * sigma[a] * sigma[b]);
        let prec = cov.clone().try_inverse().unwrap();
        let u0 = [0.5, 0.4, 0.6];
        let nll = |u: &[f64]| {
            let d = DVector::from_iterator(3, u.iter().zip(&u0).map(|(a, b)| a - b));
            0.5 * (d.transpose() * &prec * &d)[(0, 0)]
        };
        let profile = |x: f64| 0.5 * ((x - u0[0]) / sigma[0]).powi(2);
        let x1 = u0[0] + 0.03;
        let v1 = valley_start(&u0, (0, u0[0], x1), &sigma, &corr).unwrap();
        assert!((nll(&v1) - profile(x1)).abs() < 1e-9 * profile(x1));
        let x2 = u0[0] + 0.06;
        let v2 = valley_start(&v1, (0, x1, x2), &sigma, &corr).unwrap();
        assert!((nll(&v2) - profile(x2)).abs() < 1e-9 * profile(x2));
        let mut held = u0.to_vec();
        held[0] = x1;
        let r2 = 1.0 - 1.0 / (cov[(0, 0)] * prec[(0, 0)]);
        assert!((nll(&held) / profile(x1) - 1.0 / (1.0 - r2)).abs() < 1e-9 / (1.0 - r2));
        assert!(nll(&held) > 40.0 * profile(x1));
        // Kept in the box, and refused without a positive 1σ for the held coordinate.
        let edge = valley_start(&[0.5, 0.999, 0.6], (0, 0.5, 0.6), &sigma, &corr).unwrap();
        assert_eq!(edge[1], 1.0);
        assert!(valley_start(&u0, (0, 0.5, 0.6), &[0.0, 0.01, 0.05], &corr).is_none());
    }

    /// The 95 % range reaches at least 1.959964/1.000022 = 1.96 reported half-widths on each side
    /// (in the search's coordinate): A searched linearly on [0.2, 1.5] at u = 0.4 with the
    /// interval u ∈ [0.35, 0.5] and the range u ∈ [0.33, 0.7] gets its lower end at
    /// u = 0.4 − 1.96·0.05 and keeps its upper one (0.7 beyond 0.4 + 1.96·0.1).
    #[test]
    fn the_95_range_reaches_at_least_the_quadratic_extrapolation_of_the_reported_interval() {
        let k = wide_over_68_half_widths();
        assert!(
            (k - 1.959_963_984_540_054 / 1.000_021_713_322_999).abs() < 1e-6,
            "{k}"
        );
        let free = [FreeParam::new(ParamId::A, 0.2, 1.5)];
        let mut iv = laplace_intervals(&free, &[0.4], &[0.05], None);
        iv[0].hi = free[0].value(0.5);
        iv[0].range_95 = Some([free[0].value(0.33), free[0].value(0.7)]);
        floor_range_95(&free, &[0.4], &mut iv);
        let r = iv[0].range_95.expect("range");
        assert!(
            (r[0] - free[0].value(0.4 - k * 0.05)).abs() < 1e-12,
            "{r:?}"
        );
        assert!((r[1] - free[0].value(0.7)).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn intervals_widen_to_evaluated_points_where_the_likelihood_is_flatter_than_its_curvature() {
        let free = vec![
            FreeParam::new(ParamId::A, 0.2, 2.0),
            FreeParam::new(ParamId::C, 0.3, 0.8),
        ];
        let u0 = [0.4, 0.6];
        let sigma = [0.01, 0.01];
        let at = ProfileStart {
            u: &u0,
            cost_nats: 0.0,
            sigma_u: &sigma,
            fisher_sigma_u: &sigma,
            fisher_corr: None,
        };
        // Closed form: on the quadratic bowl of 1σ = 0.01 in each coordinate, a point within
        // 0.5 nats has |Δu| ≤ 0.01 in each, so the Laplace intervals already hold every one.
        let bowl = |u: &[f64]| {
            ((u[0] - u0[0]) / sigma[0]).powi(2) / 2.0 + ((u[1] - u0[1]) / sigma[1]).powi(2) / 2.0
        };
        let iv0 = laplace_intervals(&free, &u0, &sigma, None);
        let mut iv = iv0.clone();
        let near = evaluated_grid(&u0, 0.05, bowl);
        let w = widen_to_near_best(&free, at, &near, &mut iv);
        for (a, b) in iv.iter().zip(&iv0) {
            assert!(
                (a.lo - b.lo).abs() < 1e-12 && (a.hi - b.hi).abs() < 1e-12,
                "{a:?} {b:?}"
            );
        }
        assert!(w.is_empty(), "{w:?}");
        // A valley 100× flatter in A than the curvature at the fit says (1σ 0.1 instead of
        // 0.01): the points within 0.5 nats reach Δu = ±0.05 (the grid's edge) in A, not in C.
        let valley = |u: &[f64]| {
            ((u[0] - u0[0]) / 0.1).powi(2) / 2.0 + ((u[1] - u0[1]) / sigma[1]).powi(2) / 2.0
        };
        let mut iv = iv0.clone();
        let near = evaluated_grid(&u0, 0.05, valley);
        let w = widen_to_near_best(&free, at, &near, &mut iv);
        assert!(
            (iv[0].lo - free[0].value(0.35)).abs() < 1e-12,
            "{:?}",
            iv[0]
        );
        assert!(
            (iv[0].hi - free[0].value(0.45)).abs() < 1e-12,
            "{:?}",
            iv[0]
        );
        assert_eq!(iv[0].widened_from, Some([iv0[0].lo, iv0[0].hi]));
        assert!((iv[1].lo - iv0[1].lo).abs() < 1e-12 && (iv[1].hi - iv0[1].hi).abs() < 1e-12);
        assert_eq!(w.len(), 1, "{w:?}");
        assert_eq!(
            w[0],
            FitWarning::WidenedInterval {
                parameter: ParamId::A,
                rise_limit_nats: 0.5,
                points: [iv[0].lo, iv[0].hi],
                method: [iv0[0].lo, iv0[0].hi],
                widened: [iv[0].lo, iv[0].hi],
            }
        );
        // The 95 % range widens alike at the 95 % rise: in A the valley's points within 1.92
        // nats reach the grid's edge (Δu = ±0.05, rise 0.125); in C, where the bowl is the
        // curvature's, the farthest within 1.92 nats lies at ±0.015 (±0.02 rises 2.0), inside
        // the range's own ±1.96σ, which stays.
        let z95 = (2.0 * PROFILE_95_NATS).sqrt();
        let mut iv = iv0.clone();
        for (i, v) in iv.iter_mut().enumerate() {
            let r = [u0[i] - z95 * sigma[i], u0[i] + z95 * sigma[i]];
            v.range_95 = Some(r.map(|u| free[i].value(u)));
        }
        let before = iv[1].range_95;
        widen_to_near_best(&free, at, &near, &mut iv);
        let r = iv[0].range_95.expect("A's 95 % range");
        assert!((r[0] - free[0].value(0.35)).abs() < 1e-12, "{r:?}");
        assert!((r[1] - free[0].value(0.45)).abs() < 1e-12, "{r:?}");
        assert_eq!(iv[1].range_95, before);
        // One point 1.125 nats below the bowl at Δu = (0.005, 0), where the bowl is 0.125: a
        // point 1 nat more likely than the fit, which the search ended short of.
        let dip = |u: &[f64]| {
            let here = (u[0] - 0.405).abs() < 1e-9 && (u[1] - u0[1]).abs() < 1e-9;
            bowl(u) - if here { 1.125 } else { 0.0 }
        };
        let mut iv = iv0.clone();
        let near = evaluated_grid(&u0, 0.05, dip);
        let w = widen_to_near_best(&free, at, &near, &mut iv);
        assert!(
            w.iter().any(|m| matches!(
                m,
                FitWarning::ShortOfBestEvaluation { gain_nats } if (gain_nats - 1.0).abs() < 1e-9
            )),
            "{w:?}"
        );
    }
}
