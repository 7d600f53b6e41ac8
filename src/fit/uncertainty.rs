//! Uncertainty stage: bootstrap intervals and identifiability warnings for the chosen model.

use super::evidence::RecordingLikelihood;
use super::features::{features, noise_floor};
use super::job::{self, UncertaintyMethod};
use super::problem::{FreeParam, SpectralProblem};
use super::result::{FittedParam, Interval, IntervalMethod};
use super::search::{CandidateFit, optimise, polish};
use crate::Result;
use crate::simulate::blade::BladeSimulation;
use crate::spectrum::stats::quantile_sorted;
use rand::SeedableRng;
use std::sync::{Arc, Mutex};

/// The uncertainty stage: an interval for every freed parameter of the chosen fit, by the job's
/// method (`[fit.uncertainty] method`): Laplace's from the likelihood's Fisher information
/// ([`laplace_intervals`], no further fits) or the parametric bootstrap ([`bootstrap_intervals`]).
/// A target job gets a warning instead: its targets carry no measurement noise. Returns the
/// intervals (in the order of the freed parameters) and warnings.
///
/// # Errors
/// As [`bootstrap_intervals`].
pub(super) fn intervals(
    cf: &CandidateFit,
    best_sim: &BladeSimulation,
    fit: &job::FitSection,
) -> Result<(Option<Vec<Interval>>, Vec<String>)> {
    if cf.problem.targets.is_some() {
        return Ok((
            None,
            vec!["no intervals for a target job: targets carry no measurement noise".into()],
        ));
    }
    match fit.uncertainty.method() {
        UncertaintyMethod::Laplace => match &cf.evidence {
            Ok(_) => Ok((
                Some(laplace_intervals(&cf.free, &cf.best_u, &cf.sigma_u)),
                Vec::new(),
            )),
            Err(why) => Ok((None, vec![format!("no Laplace intervals: {why}")])),
        },
        UncertaintyMethod::Bootstrap if fit.uncertainty.bootstrap == 0 => Ok((
            None,
            vec!["no bootstrap intervals: [fit.uncertainty] bootstrap = 0 replicates".into()],
        )),
        UncertaintyMethod::Bootstrap => {
            let intervals = bootstrap_intervals(&cf.problem, &cf.best_u, best_sim, fit)?;
            Ok((Some(intervals), Vec::new()))
        }
    }
}

/// Laplace intervals (68.27 %): `[θ(u − σ_u), θ(u + σ_u)]` for each freed parameter, with `σ_u`
/// the 1σ of its normalised coordinate from the inverse Fisher information of the recording's
/// likelihood ([`super::evidence::at_fit`]); through the search's coordinates, so a parameter
/// searched on a log scale gets an interval symmetric in `ln θ`. Every interval contains its
/// estimate. A parameter the likelihood does not inform (`σ_u = ∞`) gets its search range.
///
/// Asymptotically (many effectively independent bins, a smooth likelihood) this is the
/// maximum-likelihood estimate's interval (Pawitan 2001, *In All Likelihood*, §9.4), which the
/// fit's estimate is with the default `[fit] objective = "likelihood"`; its coverage is measured in
/// docs/fit.md, "Uncertainty".
pub fn laplace_intervals(free: &[FreeParam], best_u: &[f64], sigma_u: &[f64]) -> Vec<Interval> {
    free.iter()
        .zip(best_u)
        .zip(sigma_u)
        .map(|((fp, u), s)| {
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
                    fisher_step_u: super::evidence::FISHER_STEP_U,
                },
            }
        })
        .collect()
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
///    intervals come out too narrow: docs/fit.md, "Uncertainty"); replicates run in parallel with rayon;
/// 4. the interval is the basic bootstrap interval `[2θ̂ − q(84.13 %), 2θ̂ − q(15.87 %)]` of the
///    replicates' estimates `θ*` (Davison & Hinkley 1997, eq. 5.6), which corrects the replicates' bias.
///
/// What it covers: the spread from tracking noise and spectral estimation. What it does not: the
/// optimiser ending in a different local minimum of the (rough) stick–slip cost surface, which can
/// be larger (docs/fit.md, "Uncertainty").
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
            let (u, cost) = if settings.full_refit {
                let (u, _, _, cost) =
                    optimise(&rep, fit, fit.seed.wrapping_add(1 + r as u64), &[], None)?;
                (u, cost)
            } else {
                let (u, _, cost) = polish(&rep, best_u, 0.05, settings.polish_iterations, None)?;
                (u, cost)
            };
            // The estimator's last stage, as in the fit (`search::fit_candidate`).
            let u = if rep.cost_is_nll() {
                super::evidence::settle(&rep, &u, cost)?.0
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
            return Err(super::FitError::NoNoise {
                label: problem.label.clone(),
                floor,
            }
            .into());
        }
        let normal = rand_distr::Normal::new(0.0, sigma)
            .map_err(|source| super::FitError::NoiseDistribution { sigma, source })?;
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
            objective: problem.objective,
            weights: problem.weights,
            likelihood: Err("not built yet".into()),
            evaluations: problem.evaluations.clone(),
            failures: problem.failures.clone(),
            first_failure: Mutex::new(None),
        })
        .map(|mut rep| {
            // The replicate's own likelihood: its measured ordinates and noise, the recording's
            // terms.
            let time_domain = problem.likelihood.as_ref().is_ok_and(|l| l.time_domain);
            let blocks = problem.likelihood.as_ref().ok().and_then(|l| l.block_len);
            rep.likelihood = RecordingLikelihood::new(&rep, &x, time_domain)
                .map(|l| l.with_blocks(blocks))
                .map(Arc::new)
                .map_err(|e| e.to_string());
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
