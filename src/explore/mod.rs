//! Where a job's freed parameters can take the model's lines: `wiperlab explore`.
//!
//! The freed parameters' box (`[fit.parameters]`, in the fit's normalised coordinates, so a
//! parameter the fit searches on a log scale is sampled on one) is sampled by a seeded
//! Owen-scrambled Sobol sequence (`sobol_burley`; Burley 2020, "Practical Hash-based Owen
//! Scrambling", JCGT 9(4)). Every sample is simulated over the job's window with the job's model,
//! solver and signal, and goes through the fit's own feature code: per band the line the fit would
//! compare (the band's largest local maximum), its prominence over the local floor (power ratio,
//! [`crate::spectrum::Peak::prominence`]) and whether it is a harmonic of a stronger line
//! ([`crate::spectrum::harmonics`]); or why the run failed ([`FailureCause`]). Around the job's
//! start (the blade file's values) each freed parameter is moved alone by ±[`OAT_STEP`] to give
//! the lines' elasticities d ln f / d ln θ (a one-at-a-time sensitivity table).
//!
//! Samples run in parallel (rayon); each is independent of the others and of the thread count, so
//! a seed gives the same table on any machine with the same build.

pub mod reach;

use crate::fit::FitError;
use crate::job::{Candidate, FreeParam, LoadedJob, smallest_capable_model};
use crate::model::BladeParams;
use crate::search::{SpectralProblem, problem_for};
use crate::simulate::failure::FailureCause;
use crate::spectrum::features::line_origin;
use crate::{Error, Result};
use rayon::prelude::*;
use serde::Serialize;

/// Samples drawn when the command line names no count.
pub const DEFAULT_SAMPLES: usize = 256;

/// Most samples one seed's Sobol sequence holds (`sobol_burley`'s 2¹⁶).
pub const MAX_SAMPLES: usize = 1 << 16;

/// Relative step of the one-at-a-time sensitivity around the start (5 %).
pub const OAT_STEP: f64 = 0.05;

/// The line one band shows at one parameter set.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BandLine {
    /// The band's largest local maximum, Hz (the line the fit compares).
    pub freq_hz: f64,
    /// Its PSD over the local median floor (power ratio).
    pub prominence: f64,
    /// The stronger line it is a harmonic of, Hz, if it is one.
    pub harmonic_of_hz: Option<f64>,
    /// The whole spectrum's dominant line over this one (1 when it is the dominant one).
    pub below_dominant: f64,
}

/// What one parameter set gave: a line per band and the job's cost, or why not.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Outcome {
    /// Lines per band (in the job's band order) and the job's cost at the point.
    Lines { lines: Vec<BandLine>, cost: f64 },
    /// The run failed: the cause and the first line of the message.
    Failed {
        cause: FailureCause,
        message: String,
    },
}

impl Outcome {
    /// The lines, when the run gave them.
    pub fn lines(&self) -> Option<&[BandLine]> {
        match self {
            Outcome::Lines { lines, .. } => Some(lines),
            Outcome::Failed { .. } => None,
        }
    }
}

/// One sample: its freed parameters' values (job order) and what they gave.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sample {
    pub values: Vec<f64>,
    pub outcome: Outcome,
}

/// One freed parameter moved alone around the start by ±[`OAT_STEP`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensitivity {
    pub parameter: crate::model::ParamId,
    /// Its values below, at and above the start.
    pub values: [f64; 3],
    /// What each gave.
    pub outcomes: [Outcome; 3],
    /// Per band, d ln f / d ln θ from the two ends (central difference); `None` when an end
    /// failed or the start is 0.
    pub elasticity: Vec<Option<f64>>,
}

/// The whole exploration of a job.
#[derive(Debug, Clone, Serialize)]
pub struct Exploration {
    pub job: String,
    pub model: String,
    pub free: Vec<FreeParam>,
    /// Band names and ranges, Hz, in the job's order.
    pub bands: Vec<(String, [f64; 2])>,
    /// Per band, the frequency range to reach: a target job's targets, else the recording's line.
    pub targets: Vec<Option<[f64; 2]>>,
    pub signal: crate::spectrum::features::SignalKind,
    pub seed: u32,
    pub samples: Vec<Sample>,
    /// The job's start (the blade file's values of the freed parameters) and what it gave.
    pub start: Sample,
    pub sensitivity: Vec<Sensitivity>,
    /// The closest achievable pair ([`reach::closest_pair`]): an index into `samples`.
    pub closest_pair: Option<usize>,
    /// The one-at-a-time sensitivity around the closest achievable pair (empty without one).
    pub around_closest: Vec<Sensitivity>,
    /// The closest pair with each lever set to its first-order value, simulated ([`lever_checks`]).
    pub lever_checks: Vec<reach::LeverCheck>,
    pub wall_time_s: f64,
    pub threads: usize,
}

/// The candidate the exploration simulates: the job's first candidate ([`LoadedJob::candidates`]:
/// its first listed model, else the smallest one that can produce its bands, as `wiperlab fit`
/// without `models`; with its first law when `[fit] laws` lists some).
pub fn explored_candidate(job: &LoadedJob) -> Candidate {
    job.candidates().first().copied().unwrap_or(Candidate {
        kind: smallest_capable_model(&job.job.spectrum.bands),
        shoulder: false,
        law: None,
    })
}

/// Samples the job's freed parameters (`samples` Sobol points, scrambled by `seed`) and runs the
/// one-at-a-time sensitivity around the start; `progress` is moved once per simulation.
///
/// # Errors
/// [`FitError::Samples`] for 0 or more than [`MAX_SAMPLES`] samples; the errors of reading and
/// measuring the job's recording. Failed simulations are outcomes, not errors.
pub fn explore(
    job: &LoadedJob,
    samples: usize,
    seed: u32,
    progress: Option<&indicatif::ProgressBar>,
) -> Result<Exploration> {
    if samples == 0 || samples > MAX_SAMPLES {
        let max = MAX_SAMPLES;
        return Err(FitError::Samples { samples, max }.into());
    }
    let started = std::time::Instant::now();
    let candidate = explored_candidate(job);
    let problem = problem_for(job, candidate)?;
    let dims = problem.free.len();
    let tick = || {
        if let Some(pb) = progress {
            pb.inc(1);
        }
    };
    let drawn: Vec<Sample> = (0..samples)
        .into_par_iter()
        .map(|i| {
            let u: Vec<f64> = (0..dims)
                .map(|d| f64::from(sobol_burley::sample(i as u32, d as u32, seed)))
                .collect();
            let p = problem.params_at(&u);
            let s = Sample {
                values: problem
                    .free
                    .iter()
                    .zip(&u)
                    .map(|(f, x)| f.value(*x))
                    .collect(),
                outcome: outcome(&problem, &p),
            };
            tick();
            s
        })
        .collect();
    let start = Sample {
        values: start_values(&problem),
        outcome: outcome(&problem, &problem.base),
    };
    tick();
    let oat = |at: &Sample, origin: &BladeParams| -> Vec<Sensitivity> {
        (0..dims)
            .into_par_iter()
            .map(|i| {
                let s = sensitivity(&problem, i, at, origin);
                tick();
                tick();
                s
            })
            .collect()
    };
    let sensitivity = oat(&start, &problem.base);
    let targets = targets(&problem);
    let closest_pair = reach::closest_pair(&drawn, &targets).map(|c| c.sample);
    let around_closest = match closest_pair {
        Some(k) => oat(&drawn[k], &params_with(&problem, &drawn[k].values)),
        None => Vec::new(),
    };
    let mut e = Exploration {
        job: job.name.clone(),
        model: candidate.name(),
        free: problem.free.clone(),
        bands: problem
            .bands
            .iter()
            .map(|b| (b.name.clone(), b.range_hz))
            .collect(),
        targets,
        signal: problem.signal,
        seed,
        samples: drawn,
        start,
        sensitivity,
        closest_pair,
        around_closest,
        lever_checks: Vec::new(),
        wall_time_s: 0.0,
        threads: rayon::current_num_threads(),
    };
    e.lever_checks = lever_checks(&problem, &e, &tick);
    e.wall_time_s = started.elapsed().as_secs_f64();
    Ok(e)
}

/// The closest achievable pair with each lever of its binding band ([`reach::Push`] within
/// [`reach::MAX_LEVER_FACTOR`]) set alone to its first-order value, inside the box or beyond
/// it, and simulated.
fn lever_checks(
    problem: &SpectralProblem,
    e: &Exploration,
    tick: &(dyn Fn() + Sync),
) -> Vec<reach::LeverCheck> {
    let Some(k) = e.closest_pair else {
        return Vec::new();
    };
    let at = &e.samples[k];
    let c = reach::constraint(e);
    c.pushes
        .par_iter()
        .filter(|p| p.is_lever(at.values[p.param]))
        .map(|p| {
            let mut values = at.values.clone();
            values[p.param] = p.needed;
            let outcome = outcome(problem, &params_with(problem, &values));
            tick();
            reach::LeverCheck {
                param: p.param,
                value: p.needed,
                outcome,
            }
        })
        .collect()
}

/// Simulations [`explore`] runs for `samples` samples of a job with `free` freed parameters (for
/// a progress bar's length): the samples, the start, the one-at-a-time steps around the start and
/// around the closest achievable pair, and at most one lever check per parameter (when there is a
/// pair; the bar may stop short otherwise).
pub fn simulations(samples: usize, free: usize) -> u64 {
    (samples + 1 + 5 * free) as u64
}

/// The job's blade with the freed parameters set to `values` (job order, as
/// [`SpectralProblem::params_at`] sets them).
fn params_with(problem: &SpectralProblem, values: &[f64]) -> BladeParams {
    let mut p = problem.base;
    for (f, v) in problem.free.iter().zip(values) {
        f.name.set(&mut p, *v);
    }
    p
}

/// The blade file's values of the freed parameters.
fn start_values(problem: &SpectralProblem) -> Vec<f64> {
    problem
        .free
        .iter()
        .map(|f| f.name.get(&problem.base).unwrap_or(f64::NAN))
        .collect()
}

/// Per band, the range to reach: the target job's (a frequency as a zero-width range), else the
/// recording's line.
fn targets(problem: &SpectralProblem) -> Vec<Option<[f64; 2]>> {
    match &problem.targets {
        Some(t) => t.iter().map(|r| Some(*r)).collect(),
        None => problem
            .measured
            .bands
            .iter()
            .map(|b| b.peak.map(|p| [p.freq_hz, p.freq_hz]))
            .collect(),
    }
}

/// Simulates `p` and reads each band's line, or the cause of the failure.
pub fn outcome(problem: &SpectralProblem, p: &BladeParams) -> Outcome {
    let failed = |e: Error| Outcome::Failed {
        cause: FailureCause::of(&e),
        message: e.to_string().lines().next().unwrap_or_default().to_string(),
    };
    let features = match problem
        .simulate(p)
        .and_then(|sim| problem.model_features(&sim))
    {
        Ok(f) => f,
        Err(e) => return failed(e),
    };
    let mut lines = Vec::with_capacity(features.bands.len());
    for b in &features.bands {
        let (Some(peak), Some(origin)) = (b.peak, line_origin(b)) else {
            return Outcome::Failed {
                cause: FailureCause::NoLine,
                message: format!(
                    "band '{}' ({}–{} Hz) holds no local maximum",
                    b.spec.name, b.spec.range_hz[0], b.spec.range_hz[1]
                ),
            };
        };
        lines.push(BandLine {
            freq_hz: peak.freq_hz,
            prominence: peak.prominence,
            harmonic_of_hz: origin.harmonic_of.map(|h| h.freq_hz),
            below_dominant: origin.below_dominant,
        });
    }
    Outcome::Lines {
        lines,
        cost: problem.cost_of(&features),
    }
}

/// Freed parameter `i` moved alone by ±[`OAT_STEP`] of its value at `at` (±[`OAT_STEP`] of its
/// range when that is 0), the other parameters at `at` (`origin` is the blade there). A freed
/// preload is set again after the move, so it stays what `at` says (it is set through h_d, which a
/// moved head or lip mass would otherwise carry to another preload).
fn sensitivity(
    problem: &SpectralProblem,
    i: usize,
    at: &Sample,
    origin: &BladeParams,
) -> Sensitivity {
    let f = &problem.free[i];
    let v0 = at.values[i];
    let h = if v0 != 0.0 {
        OAT_STEP * v0.abs()
    } else {
        OAT_STEP * (f.upper - f.lower)
    };
    let moved = |v: f64| {
        let mut p = *origin;
        f.name.set(&mut p, v);
        for (g, w) in problem.free.iter().zip(&at.values).skip(i + 1) {
            if g.name == crate::model::ParamId::Preload {
                g.name.set(&mut p, *w);
            }
        }
        outcome(problem, &p)
    };
    let (lo, hi) = (v0 - h, v0 + h);
    let outcomes = [moved(lo), at.outcome.clone(), moved(hi)];
    let bands = problem.bands.len();
    let elasticity = (0..bands)
        .map(|b| {
            let fl = outcomes[0].lines()?[b].freq_hz;
            let fh = outcomes[2].lines()?[b].freq_hz;
            (lo > 0.0 && hi > 0.0).then(|| (fh / fl).ln() / (hi / lo).ln())
        })
        .collect();
    Sensitivity {
        parameter: f.name,
        values: [lo, v0, hi],
        outcomes,
        elasticity,
    }
}

impl Exploration {
    /// How many samples gave a line in every band (the others failed).
    pub fn with_lines(&self) -> usize {
        self.samples
            .iter()
            .filter(|s| s.outcome.lines().is_some())
            .count()
    }

    /// Samples that gave lines, and those that failed, per cause (in [`FailureCause::ALL`]'s
    /// order, causes that never occurred left out).
    pub fn failure_counts(&self) -> Vec<(FailureCause, usize)> {
        FailureCause::ALL
            .iter()
            .map(|c| {
                let n = self
                    .samples
                    .iter()
                    .filter(|s| matches!(&s.outcome, Outcome::Failed { cause, .. } if cause == c))
                    .count();
                (*c, n)
            })
            .filter(|(_, n)| *n > 0)
            .collect()
    }

    /// Whether sample `s` reaches every band's target: its line within `rel_tol` of the target
    /// (of the range's edges for a range), at least [`crate::spectrum::harmonics::MIN_PROMINENCE`]
    /// times its local floor, and not a harmonic of a stronger line (the criterion for the seed
    /// paper's pairs, [`reach::band_tolerance`], takes 1 % for the low line and 2 % for the
    /// high one).
    pub fn reaches(&self, s: &Sample, rel_tol: &[f64]) -> bool {
        let Some(lines) = s.outcome.lines() else {
            return false;
        };
        lines
            .iter()
            .zip(&self.targets)
            .zip(rel_tol)
            .all(|((l, t), tol)| match t {
                Some([lo, hi]) => {
                    l.freq_hz >= lo * (1.0 - tol)
                        && l.freq_hz <= hi * (1.0 + tol)
                        && l.prominence >= crate::spectrum::harmonics::MIN_PROMINENCE
                        && l.harmonic_of_hz.is_none()
                }
                None => true,
            })
    }

    /// The sample with the lowest job cost (the nearest to the targets or the recording), if any
    /// sample gave lines.
    pub fn closest(&self) -> Option<&Sample> {
        self.samples
            .iter()
            .filter_map(|s| match s.outcome {
                Outcome::Lines { cost, .. } => Some((s, cost)),
                Outcome::Failed { .. } => None,
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(s, _)| s)
    }

    /// The two freed parameters that best tell failed samples from the others: the largest
    /// difference of the groups' mean normalised coordinates (the first two when nothing failed
    /// or fewer than two are freed). Indices into [`Exploration::free`].
    pub fn failure_axes(&self) -> (usize, usize) {
        let n = self.free.len();
        if n < 2 {
            return (0, 0);
        }
        let mean = |failed: bool, i: usize| {
            let (sum, count) = self
                .samples
                .iter()
                .filter(|s| matches!(s.outcome, Outcome::Failed { .. }) == failed)
                .fold((0.0, 0usize), |(a, c), s| {
                    (a + self.free[i].u_of(s.values[i]), c + 1)
                });
            (count > 0).then(|| sum / count as f64)
        };
        let mut gap: Vec<(usize, f64)> = (0..n)
            .map(|i| match (mean(true, i), mean(false, i)) {
                (Some(a), Some(b)) => (i, (a - b).abs()),
                _ => (i, 0.0),
            })
            .collect();
        gap.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        let (a, b) = (gap[0].0, gap[1].0);
        (a.min(b), a.max(b))
    }
}
