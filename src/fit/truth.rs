//! The fit against the truth of a model-made recording (a job's `[truth]`): the cost at the true
//! parameters, and the likelihood along the straight segment from the fit to them. Both are read in
//! the true model's candidate when `[truth] model` names one the job fitted (so the search is
//! judged where the truth can be stated, whichever model was chosen), else in the chosen one.
//!
//! A fit less likely than the truth has failed its search; the segment says how. A ridge on it
//! (an interior point less likely than both ends by more than [`RIDGE_NATS`]) puts the truth in
//! another basin, which the global search did not enter; without one the search stopped on the
//! slope of the truth's own basin. A fit more likely than the truth whose intervals miss it is the
//! intervals' failure, and the segment's rise against the one the intervals' quadratic predicts
//! measures it (`examples/interval_check.rs`, docs/validation.md, "Intervals against the
//! likelihood").

use super::tolerance::ToleranceCheck;
use super::warning::FitWarning;
use crate::job::{Candidate, LoadedJob};
use crate::search::strategy::CandidateFit;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How far above the truth's cost a fit may end before it counts as a search that fell short,
/// nats: the integrator's own resolution of the cost (the tolerance check's spread on the main job
/// is a few hundredths of a nat).
pub const SHORTFALL_TOLERANCE_NATS: f64 = 0.1;

/// Interior points of the segment, evenly spaced (s = 0.1 … 0.9).
pub const SEGMENT_POINTS: usize = 9;

/// The height above both ends (nats) beyond which an interior point of the segment counts as a
/// ridge between two basins: five times the cost's jitter between nearby points (about 0.1 nats,
/// docs/validation.md, "Settling"). On the development set's six fits the segments either rose
/// 2–31 nats above both ends or never above the higher end (docs/validation.md, "Intervals
/// against the likelihood").
pub const RIDGE_NATS: f64 = 0.5;

/// The chosen model's NLL along the segment from the fit (s = 0) to the truth (s = 1) in the
/// search's normalised coordinates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthSegment {
    /// The cost at s = 0.1, 0.2, … 0.9 minus the fit's, nats (NaN where the simulation failed).
    pub rise_nats: Vec<f64>,
    /// The highest interior point's height above the higher of the two ends, nats (negative: the
    /// segment stays below the higher end).
    pub ridge_nats: f64,
}

/// Whether a segment's `ridge_nats` ([`TruthSegment::ridge_nats`]) is a ridge: higher than
/// [`RIDGE_NATS`], so that the truth lies in another basin than the fit.
pub fn is_ridge(ridge_nats: f64) -> bool {
    ridge_nats > RIDGE_NATS
}

/// What the truth says of a fit: the cost there and the segment to it, in the candidate the truth
/// is read in ([`truth_fit`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TruthCheck {
    /// The cost at the true parameters, nats.
    pub cost_nats: f64,
    pub segment: Option<TruthSegment>,
    /// The cost of the fit the truth is compared with (that candidate's own optimum), nats.
    pub fit_cost_nats: f64,
    /// The true model, when the truth is read in a candidate other than the chosen one.
    pub model: Option<Candidate>,
    /// The truth's cost again at tenfold and hundredfold tighter tolerances: a truth whose cost
    /// moves with the integrator by more than a shortfall does not show the search short.
    pub tolerance: Option<ToleranceCheck>,
}

/// The candidate fit the truth is read in: the chosen fit when its model is the truth's or the job
/// names no true model; else the lowest-cost fit among `others` of the true model (its kind and
/// shoulder, and its law where the truth names one); `None` when the job did not fit the true model.
pub(super) fn truth_fit<'a>(
    job: &LoadedJob,
    chosen: &'a CandidateFit,
    others: &'a [CandidateFit],
) -> Option<&'a CandidateFit> {
    let Some(m) = job.truth_model else {
        return Some(chosen);
    };
    let is_true = |c: &Candidate| {
        c.kind == m.kind && c.shoulder == m.shoulder && (m.law.is_none() || c.law == m.law)
    };
    if is_true(&chosen.candidate) {
        return Some(chosen);
    }
    others
        .iter()
        .filter(|f| is_true(&f.candidate))
        .min_by(|a, b| a.cost.total_cmp(&b.cost))
}

/// The truth's cost and segment for the fit `cf` of cost `fit_cost`, at the fit's solver; `None`
/// without a truth for every freed parameter or when the truth cannot be simulated. The segment is
/// left out where a true value lies outside the search box; the truth's [`ToleranceCheck`] beside
/// them, with the truth's cost jitter ([`ToleranceCheck::with_jitter`]) where it lies inside the box.
/// `1 + 9 + 2 + (2k + 1)` simulations: the segment's 9, the tolerance check's 2 and the jitter's
/// `2k + 1` are counted as `cf`'s evaluations, the truth's own is not (a truth the model cannot
/// simulate adds no failure to the fit's record); none of them enters the intervals (already
/// computed) or the search's record of near-best points. `model` is the true model when `cf` is
/// not the chosen fit.
pub(super) fn check(
    job: &LoadedJob,
    cf: &CandidateFit,
    fit_cost: f64,
    model: Option<Candidate>,
) -> Option<TruthCheck> {
    let p = &cf.problem;
    let mut params = p.base;
    let mut u_true = Vec::with_capacity(p.free.len());
    let mut inside = true;
    for fp in &p.free {
        let t = *job.truth.get(&fp.name)?;
        fp.name.set(&mut params, t);
        inside &= (fp.lower..=fp.upper).contains(&t);
        u_true.push(fp.u_of(t));
    }
    let sim = p.simulate(&params).ok()?;
    let cost_nats = p.total_cost(&sim).ok()? + p.prior.nats(&params);
    let segment = inside.then(|| segment(cf, &u_true, fit_cost, cost_nats));
    let tolerance = ToleranceCheck::run(p, &params, (cost_nats, sim.transitions.len()))
        .map(|c| c.with_jitter(p, inside.then_some(u_true.as_slice())));
    Some(TruthCheck {
        cost_nats,
        segment,
        fit_cost_nats: fit_cost,
        model,
        tolerance,
    })
}

/// [`TruthSegment`] from the fit `cf.best_u` (cost `fit_cost`) to `u_true` (cost `truth_cost`).
fn segment(cf: &CandidateFit, u_true: &[f64], fit_cost: f64, truth_cost: f64) -> TruthSegment {
    let p = &cf.problem;
    let rise_nats: Vec<f64> = (1..=SEGMENT_POINTS)
        .into_par_iter()
        .map(|i| {
            let s = i as f64 / (SEGMENT_POINTS + 1) as f64;
            let u: Vec<f64> = cf
                .best_u
                .iter()
                .zip(u_true)
                .map(|(a, b)| a + s * (b - a))
                .collect();
            p.cost_with_solver(&u, &p.solver)
                .map_or(f64::NAN, |(c, _)| c - fit_cost)
        })
        .collect();
    TruthSegment {
        ridge_nats: ridge_height(&rise_nats, truth_cost - fit_cost),
        rise_nats,
    }
}

/// The highest of `interior` (rises above the fit) above `max(0, truth_rise)`; a failed point
/// (NaN) counts as a ridge of infinite height (the model cannot be simulated between them).
pub fn ridge_height(interior: &[f64], truth_rise: f64) -> f64 {
    let top = interior
        .iter()
        .map(|r| if r.is_nan() { f64::INFINITY } else { *r })
        .fold(f64::NEG_INFINITY, f64::max);
    top - truth_rise.max(0.0)
}

/// The warning of a fit whose cost lies above the truth's own by more than
/// [`SHORTFALL_TOLERANCE_NATS`] (in the candidate the truth is read in): the search stopped short
/// of the likelihood's maximum, with the segment's ridge when it was measured.
pub fn shortfall_warning(truth: &TruthCheck) -> Option<FitWarning> {
    (truth.fit_cost_nats - truth.cost_nats > SHORTFALL_TOLERANCE_NATS).then(|| {
        FitWarning::TruthMoreLikely {
            fit_cost_nats: truth.fit_cost_nats,
            truth_cost_nats: truth.cost_nats,
            ridge_nats: truth.segment.as_ref().map(|s| s.ridge_nats),
            model: truth.model,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A segment that climbs between its ends has a ridge measured above the higher end; one that
    /// rises steadily from the fit to a less likely truth has none; a failed interior point is a
    /// ridge.
    #[test]
    fn the_ridge_is_measured_above_the_higher_end() {
        // Fit at 0, truth 2.5 nats more likely, a hump of 31 nats between (dev_018's shape).
        let hump = [5.0, 20.0, 31.0, 18.0, 4.0, 1.0, -1.0, -2.0, -2.4];
        assert_eq!(ridge_height(&hump, -2.5), 31.0);
        // A fit more likely than the truth (+0.71), rising steadily to it (dev_001's shape).
        let slope = [0.003, 0.011, 0.026, 0.048, 0.085, 0.14, 0.22, 0.33, 0.49];
        let r = ridge_height(&slope, 0.71);
        assert!((r - (0.49 - 0.71)).abs() < 1e-12, "{r}");
        assert!(!is_ridge(r));
        assert_eq!(ridge_height(&[0.1, f64::NAN, 0.2], 0.3), f64::INFINITY);
    }
}
