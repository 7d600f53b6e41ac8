//! Simulation-based calibration of a campaign whose recordings carry truths (a `[truth]` in the
//! template, or a `truth_json` column): how often the fit's intervals cover the truth, how far
//! its estimates land, whether its search reaches the truth's likelihood, which model it
//! chooses, and how long it takes. Written by `wiperlab campaign collect` as
//! `calibration.md` and `calibration.csv` (and `calibration_recordings.csv`, one row per
//! recording) in [`Campaign::calibration_dir`].
//!
//! The statistics (Talts et al. 2018, arXiv:1804.06788; Cook, Gelman & Rubin 2006, J. Comput.
//! Graph. Stat. 15:675):
//! * **coverage**: of `n` scored recordings, how many intervals contain the truth; under a
//!   calibrated method the count is Binomial(n, level), and [`binomial_band`] is its central 95 %
//!   band;
//! * **standardised error** `z` ([`standardised_error`]): the estimate's distance from the truth
//!   in units of the interval's half-width on the truth's side, read as `Φ⁻¹((1 + level)/2)` σ, in
//!   the search's coordinate (`ln θ` for a parameter searched on a log scale); a 95 % interval is
//!   `|z| ≤ 1.96` (for the fit's Laplace intervals, exactly their ±1.96σ);
//! * **Σz²** against χ²(n) ([`chi2_two_sided_p`]): too large, intervals too narrow; too small,
//!   too wide;
//! * median and 90th-percentile |relative error| ([`quantile`]);
//! * **search shortfall**: the fit's cost above the truth's own cost at the same model: in the true
//!   model's own candidate when the fits name it (`[truth] model`, the campaign's `truth_model`),
//!   whichever model was chosen; else where the chosen model contains the truth's (the same model,
//!   or a shoulder added to a shoulder-free truth, whose truth file then prices it with a contact
//!   that is never reached);
//! * the **model-choice confusion** matrix, true model × chosen model;
//! * fit wall time, and the recordings that failed or have no result.
//!
//! A truth file names the model that made the recording at `/model` (a name as in `[fit] models`).
//! A parameter is scored when the true model has it (the shoulder's `theta_c` and `k1c` only for a
//! truth with a shoulder) and the chosen model contains the true one; without `/model` every
//! parameter with a true value is scored and the confusion matrix is left out.

use super::Campaign;
use super::run::{EntryPaths, State, read_status};
use crate::fit::SHORTFALL_TOLERANCE_NATS;
use crate::fit::result::{FitResult, FittedParam, TrialEvidence};
use crate::fit::select::INDISTINGUISHABLE_TIC;
use crate::fit::tolerance::SPREAD_WARN_NATS;
use crate::fit::truth::{RIDGE_NATS, is_ridge};
use crate::io::write_atomic;
use crate::job::{Candidate, FreeParam};
use crate::model::ParamId;
use crate::{Error, Result};
use statrs::distribution::{Binomial, ChiSquared, ContinuousCDF, DiscreteCDF, Normal};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The nominal level of the second interval the table scores (from the reported one's width).
pub const WIDE_LEVEL: f64 = 0.95;

/// The central 95 % band of Binomial(n, p): from the largest `lo` with P(X < lo) ≤ 2.5 % to the
/// smallest `hi` with P(X > hi) ≤ 2.5 %; a count outside it is rejected at 5 %.
pub fn binomial_band(n: usize, p: f64) -> (usize, usize) {
    let Ok(b) = Binomial::new(p, n as u64) else {
        return (0, n);
    };
    let lo = (1..=n)
        .take_while(|&k| b.cdf(k as u64 - 1) <= 0.025)
        .last()
        .unwrap_or(0);
    let hi = (0..=n)
        .find(|&k| 1.0 - b.cdf(k as u64) <= 0.025)
        .unwrap_or(n);
    (lo, hi)
}

/// Two-sided p-value of `x` against χ²(n): `2·min(F(x), 1 − F(x))` (NaN for n = 0).
pub fn chi2_two_sided_p(x: f64, n: usize) -> f64 {
    if n == 0 {
        return f64::NAN;
    }
    if x.is_infinite() {
        return 0.0;
    }
    match ChiSquared::new(n as f64) {
        Ok(c) => (2.0 * c.cdf(x).min(c.sf(x))).min(1.0),
        Err(_) => f64::NAN,
    }
}

/// The `q`-quantile of `values` by linear interpolation between order statistics (Hyndman & Fan
/// 1996, Am. Stat. 50:361, definition 7; NumPy's default); NaN when empty.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let h = (v.len() - 1) as f64 * q.clamp(0.0, 1.0);
    let (i, frac) = (h.floor() as usize, h - h.floor());
    match v.get(i + 1) {
        Some(next) if frac > 0.0 => v[i] + frac * (next - v[i]),
        _ => v[i],
    }
}

/// Whether the fit searched `p` on a log scale ([`FreeParam::log`] of its bounds).
fn searched_on_log_scale(p: &FittedParam) -> bool {
    FreeParam::new(p.name, p.lower, p.upper).log
}

/// The search's coordinate of `p` (`ln` on a log scale, [`searched_on_log_scale`]).
fn search_coordinate(p: &FittedParam) -> impl Fn(f64) -> f64 {
    let log = searched_on_log_scale(p);
    move |x: f64| if log { x.ln() } else { x }
}

/// The z of a 1σ-equivalent half-width at `level`: `Φ⁻¹((1 + level)/2)`.
fn sigmas_at(level: f64) -> f64 {
    Normal::standard().inverse_cdf(0.5 * (1.0 + level))
}

/// How far out in likelihood a fit's truth lies ([`Calibration::wide_misses_against_ratio`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RatioAtTruth {
    /// D/(tr(F⁻¹V)/2): the truth's cost above the fit's over its mean under the calibrated
    /// likelihood.
    pub over_mean: f64,
    /// D exceeds the 95 % point of `(tr/k)·χ²(k)/2`.
    pub beyond_95: bool,
}

/// Whether the truth's cost `d` nats above the fit's exceeds the 95 % point of
/// `(tr/k)·χ²(k)/2`, the likelihood ratio's law under the calibrated likelihood with `k` freed
/// parameters and Takeuchi's `tr(F⁻¹V)` (Varin, Reid & Firth 2011, §2.3).
fn beyond_ratio_95(d: f64, k: usize, tr: f64) -> bool {
    ChiSquared::new(k as f64)
        .map(|c| d > tr / k as f64 * c.inverse_cdf(0.95) / 2.0)
        .unwrap_or(false)
}

/// `p`'s standardised error against `truth`: `(g(truth) − g(value)) / h · Φ⁻¹((1 + level)/2)`,
/// with `g` the search's coordinate (`ln` on a log scale) and `h` the interval's half-width in
/// it on the truth's side; `±∞` when that side has no width and the truth lies beyond it; `None`
/// without an interval.
pub fn standardised_error(p: &FittedParam, truth: f64) -> Option<f64> {
    let iv = p.interval.as_ref()?;
    Some(error_in_interval(p, [iv.lo, iv.hi], iv.level, truth))
}

/// [`standardised_error`] of the interval the method gave before it was widened to the search's
/// near-best points or the contact ridge (`widened_from`; the reported interval where it was
/// not widened): what the method alone covers.
pub fn method_standardised_error(p: &FittedParam, truth: f64) -> Option<f64> {
    let iv = p.interval.as_ref()?;
    let own = iv.widened_from.unwrap_or([iv.lo, iv.hi]);
    Some(error_in_interval(p, own, iv.level, truth))
}

/// [`standardised_error`] against the 95 % interval: the reported interval's half-widths times
/// 1.96 (exactly ±1.96σ for a Laplace interval), where this is [`standardised_error`], or the
/// method's own 95 % interval where the result gives one (`range_95`: a profile walked on to the
/// 95 % rise, a posterior's 2.5–97.5 % quantiles), at least those 1.96 half-widths as the fit
/// reports it ([`crate::uncertainty::floored_range_95`], applied again to results written
/// without it). Covered when `|z| ≤ Φ⁻¹(0.975)`.
pub fn wide_standardised_error(p: &FittedParam, truth: f64) -> Option<f64> {
    let iv = p.interval.as_ref()?;
    let fp = FreeParam::new(p.name, p.lower, p.upper);
    Some(
        match crate::uncertainty::floored_range_95(&fp, fp.u_of(p.value), iv) {
            Some(range) => error_in_interval(p, range, WIDE_LEVEL, truth),
            None => error_in_interval(p, [iv.lo, iv.hi], iv.level, truth),
        },
    )
}

/// [`standardised_error`] for the interval `[lo, hi]` at `level` around `p`'s value.
fn error_in_interval(p: &FittedParam, [lo, hi]: [f64; 2], level: f64, truth: f64) -> f64 {
    let g = search_coordinate(p);
    let (v, t) = (g(p.value), g(truth));
    if t == v {
        return 0.0;
    }
    let half = if t >= v { g(hi) - v } else { v - g(lo) };
    if half.is_nan() || half <= 0.0 {
        return f64::INFINITY.copysign(t - v);
    }
    (t - v) / half * sigmas_at(level)
}

/// `p`'s standardised error against `truth` in units of its sandwich 1σ (`std_error`, carried to
/// the search's coordinate by the derivative of `ln` on a log scale): the Laplace interval's, which
/// the curvature and the noise replicates at the fit give; `None` without a finite positive 1σ.
pub fn sandwich_standardised_error(p: &FittedParam, truth: f64) -> Option<f64> {
    let sigma = if searched_on_log_scale(p) {
        p.std_error / p.value
    } else {
        p.std_error
    };
    let g = search_coordinate(p);
    (sigma.is_finite() && sigma > 0.0).then(|| (g(truth) - g(p.value)) / sigma)
}

/// Whether `chosen` is `truth`'s model: the same model and shoulder, and the same law where the
/// truth names one. A truth without a law (a campaign's `/model` names the dynamics only) is
/// matched by a fit of that model with any law (`[fit] laws`): the law is scored as a curve.
pub fn same_model(chosen: Candidate, truth: Candidate) -> bool {
    chosen.kind == truth.kind
        && chosen.shoulder == truth.shoulder
        && (truth.law.is_none() || chosen.law == truth.law)
}

/// Whether `chosen` can state the truth of `truth`'s model: the same model ([`same_model`]), or
/// the same model with a shoulder added (a shoulder-free truth is that model with a contact never
/// reached).
pub fn contains(chosen: Candidate, truth: Candidate) -> bool {
    let shoulder_as_truth = Candidate {
        shoulder: truth.shoulder,
        ..chosen
    };
    same_model(shoulder_as_truth, truth) && (chosen.shoulder || !truth.shoulder)
}

/// One parameter of one recording, scored.
#[derive(Debug, Clone, PartialEq)]
pub struct Scored {
    pub param: ParamId,
    pub value: f64,
    pub truth: f64,
    /// Standardised error ([`standardised_error`]); `None` without an interval.
    pub z: Option<f64>,
    /// The reported interval's level (NaN without one).
    pub level: f64,
    /// Standardised error of the method's own interval, before any widening
    /// ([`method_standardised_error`]).
    pub z_method: Option<f64>,
    /// Standardised error in sandwich σ ([`sandwich_standardised_error`]).
    pub z_sandwich: Option<f64>,
    /// Standardised error against the 95 % interval ([`wide_standardised_error`]): covered when
    /// `|z_95| ≤ 1.96`.
    pub z_95: Option<f64>,
}

/// One recording of the calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingScore {
    pub id: String,
    /// `done`, `failed` or `missing`.
    pub state: String,
    pub reason: String,
    /// The model that made the recording (`/model` of its truth file).
    pub true_model: Option<Candidate>,
    pub chosen: Option<Candidate>,
    /// Fit cost − the truth's own cost in the same model, nats, when the result has it
    /// ([`FitResult::shortfall_nats`]) and that model can state the truth.
    pub shortfall_nats: Option<f64>,
    /// The ridge on the segment from the fit to the truth, nats ([`crate::fit::truth`]).
    pub ridge_nats: Option<f64>,
    /// How far the truth's own cost moves between the job's tolerance and tenfold and hundredfold
    /// tighter ones, nats ([`FitResult::truth_tolerance`]), when the shortfall is priced and the
    /// result has the check.
    pub truth_spread_nats: Option<f64>,
    /// How much the truth's own cost jitters under rounding-level steps, nats (standard
    /// deviation; [`crate::search::jitter`]), when the result has it.
    pub truth_jitter_nats: Option<f64>,
    /// The largest of the chosen model's parameters' `rounding_widening`
    /// ([`crate::estimate::FittedParam::rounding_widening`]), when the result has them.
    pub rounding_widening_max: Option<f64>,
    /// The shortfall with each side's cost averaged over its rounding draws
    /// ([`FitResult::averaged_shortfall_nats`]), when the result has both jitter checks.
    pub averaged_shortfall_nats: Option<f64>,
    pub wall_time_s: f64,
    /// The scored parameters (empty when the chosen model does not contain the truth's).
    pub params: Vec<Scored>,
    /// What the recording departs from the fitted model by (`/departure` of its truth file).
    pub departure: Option<String>,
    /// The fitted friction law against the true one as a curve ([`super::law`]).
    pub law: Option<super::law::LawScore>,
    /// The goodness-of-fit test's p-value.
    pub gof_p: Option<f64>,
    /// The true model's TIC above the chosen model's (0 when it is the chosen one), when the fit
    /// tried it and the result has its TIC.
    pub true_model_delta_tic: Option<f64>,
    /// The true model's freed parameters `k` and Takeuchi's `tr(F⁻¹V)` at its fit, when the
    /// result has them ([`crate::fit::result::TrialEvidence::effective_parameters`]).
    pub true_model_k_tr: Option<(usize, f64)>,
}

impl RecordingScore {
    /// Whether the integrator resolves the truth's cost: it spreads by at most
    /// [`SPREAD_WARN_NATS`] over the tolerances (true where the result has no such check).
    pub fn truth_resolved(&self) -> bool {
        self.truth_spread_nats.is_none_or(|w| w <= SPREAD_WARN_NATS)
    }

    /// (D, k, tr(F⁻¹V)): the truth's cost above the fit's, nats, with the true model's freed
    /// parameters and Takeuchi's trace, where the result prices all three and `k`, `tr` are
    /// positive.
    fn priced_ratio(&self) -> Option<(f64, usize, f64)> {
        let (k, tr) = self.true_model_k_tr.filter(|(k, tr)| *k > 0 && *tr > 0.0)?;
        Some((-self.shortfall_nats?, k, tr))
    }

    /// Whether a truth that names a model saw another chosen ([`same_model`]).
    pub fn chose_another_model(&self) -> bool {
        match (self.chosen, self.true_model) {
            (Some(c), Some(t)) => !same_model(c, t),
            (None, Some(_)) => true,
            _ => false,
        }
    }

    /// Whether the chosen model contains the true one (true when the truth names no model).
    pub fn model_contains_truth(&self) -> bool {
        match (self.chosen, self.true_model) {
            (Some(c), Some(t)) => contains(c, t),
            (Some(_), None) => true,
            _ => false,
        }
    }
}

/// The table's statistics of one parameter over a set of recordings.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamStats {
    pub param: ParamId,
    /// Recordings with an interval for the parameter.
    pub n: usize,
    /// The intervals' level (the first scored one's).
    pub level: f64,
    pub covered: usize,
    pub band: (usize, usize),
    pub covered_wide: usize,
    pub band_wide: (usize, usize),
    pub sum_z2: f64,
    pub chi2_p: f64,
    /// Recordings with an estimate and a truth (with or without an interval).
    pub n_estimates: usize,
    pub median_abs_rel_error: f64,
    pub p90_abs_rel_error: f64,
}

impl ParamStats {
    /// Both coverage counts inside their bands.
    pub fn within_bands(&self) -> bool {
        (self.band.0..=self.band.1).contains(&self.covered)
            && (self.band_wide.0..=self.band_wide.1).contains(&self.covered_wide)
    }
}

/// The statistics of every parameter scored in `recordings`, in [`ParamId`] order.
pub fn param_stats<'a>(
    recordings: impl IntoIterator<Item = &'a RecordingScore>,
) -> Vec<ParamStats> {
    let mut by: BTreeMap<ParamId, Vec<&Scored>> = BTreeMap::new();
    for r in recordings {
        for s in &r.params {
            by.entry(s.param).or_default().push(s);
        }
    }
    let wide_sigmas = sigmas_at(WIDE_LEVEL);
    by.into_iter()
        .map(|(param, scored)| {
            let zs: Vec<(f64, f64, f64)> = scored
                .iter()
                .filter_map(|s| s.z.map(|z| (z, s.level, s.z_95.unwrap_or(z))))
                .collect();
            let n = zs.len();
            let level = zs.first().map_or(f64::NAN, |z| z.1);
            let covered = zs
                .iter()
                .filter(|(z, l, _)| z.abs() <= sigmas_at(*l))
                .count();
            let covered_wide = zs.iter().filter(|(.., w)| w.abs() <= wide_sigmas).count();
            let sum_z2: f64 = zs.iter().map(|(z, ..)| z * z).sum();
            let rel: Vec<f64> = scored
                .iter()
                .map(|s| ((s.value - s.truth) / s.truth).abs())
                .collect();
            ParamStats {
                param,
                n,
                level,
                covered,
                band: binomial_band(n, level),
                covered_wide,
                band_wide: binomial_band(n, WIDE_LEVEL),
                sum_z2,
                chi2_p: chi2_two_sided_p(sum_z2, n),
                n_estimates: scored.len(),
                median_abs_rel_error: quantile(&rel, 0.5),
                p90_abs_rel_error: quantile(&rel, 0.9),
            }
        })
        .collect()
}

/// The calibration of a campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    pub name: String,
    /// The campaign file, as the command was given it.
    pub campaign: PathBuf,
    pub recordings: Vec<RecordingScore>,
    /// Over every scored recording.
    pub overall: Vec<ParamStats>,
    /// By true model (when truths name one).
    pub by_model: Vec<(Candidate, Vec<ParamStats>)>,
}

impl Calibration {
    /// Recordings whose fit is done.
    pub fn done(&self) -> impl Iterator<Item = &RecordingScore> {
        self.recordings.iter().filter(|r| r.state == "done")
    }

    /// Of the fits above [`SHORTFALL_TOLERANCE_NATS`]: (those with a measured segment to the
    /// truth, of them those with a ridge above [`RIDGE_NATS`]: the truth in another basin).
    pub fn shortfall_ridges(&self) -> (usize, usize) {
        let short = self.done().filter(|r| {
            r.shortfall_nats
                .is_some_and(|s| s > SHORTFALL_TOLERANCE_NATS)
        });
        let ridges: Vec<f64> = short.filter_map(|r| r.ridge_nats).collect();
        let beyond = ridges.iter().filter(|h| is_ridge(**h)).count();
        (ridges.len(), beyond)
    }

    /// Of the fits above [`SHORTFALL_TOLERANCE_NATS`]: (those whose truth was priced at tighter
    /// tolerances too, of them those whose truth's cost spreads by more than the shortfall: the
    /// integrator, not the search, may have put the truth below the fit).
    pub fn shortfall_unresolved(&self) -> (usize, usize) {
        self.short_beside(|r| r.truth_spread_nats, |short, spread| spread > short)
    }

    /// Of the fits above [`SHORTFALL_TOLERANCE_NATS`]: (those whose truth's cost jitter was
    /// measured, of them those whose shortfall lies within two standard deviations of that
    /// jitter: the truth's cost is not known more closely than that).
    pub fn shortfall_jittered(&self) -> (usize, usize) {
        self.short_beside(
            |r| r.truth_jitter_nats,
            |short, jitter| short <= 2.0 * jitter,
        )
    }

    /// Of the fits whose truth's cost jitters by more than [`SHORTFALL_TOLERANCE_NATS`] and whose
    /// averaged shortfall is known ([`RecordingScore::averaged_shortfall_nats`]): (those, of them
    /// those short by the averaged cost, of those the ones not short by the optimum's own cost).
    pub fn averaged_shortfalls(&self) -> (usize, usize, usize) {
        let rows: Vec<(f64, Option<f64>)> = (self.done())
            .filter(|r| {
                r.truth_jitter_nats
                    .is_some_and(|j| j > SHORTFALL_TOLERANCE_NATS)
            })
            .filter_map(|r| Some((r.averaged_shortfall_nats?, r.shortfall_nats)))
            .collect();
        let short: Vec<&(f64, Option<f64>)> = (rows.iter())
            .filter(|(a, _)| *a > SHORTFALL_TOLERANCE_NATS)
            .collect();
        let hidden = (short.iter())
            .filter(|(_, s)| s.is_some_and(|s| s <= SHORTFALL_TOLERANCE_NATS))
            .count();
        (rows.len(), short.len(), hidden)
    }

    /// Of the fits above [`SHORTFALL_TOLERANCE_NATS`]: (those with a measure `of` their truth's
    /// cost, of them those whose shortfall and measure are `within`).
    fn short_beside(
        &self,
        of: impl Fn(&RecordingScore) -> Option<f64>,
        within: impl Fn(f64, f64) -> bool,
    ) -> (usize, usize) {
        let pairs: Vec<(f64, f64)> = (self.done())
            .filter_map(|r| Some((r.shortfall_nats?, of(r)?)))
            .filter(|(s, _)| *s > SHORTFALL_TOLERANCE_NATS)
            .collect();
        let n = pairs.iter().filter(|(s, m)| within(*s, *m)).count();
        (pairs.len(), n)
    }

    /// Fits whose truth was priced at tighter tolerances, and of them those whose truth's cost
    /// spreads by more than [`SPREAD_WARN_NATS`]: a truth the integrator does not resolve.
    pub fn unresolved_truths(&self) -> (usize, usize) {
        let checked: Vec<&RecordingScore> = (self.done())
            .filter(|r| r.truth_spread_nats.is_some())
            .collect();
        let wide = checked.iter().filter(|r| !r.truth_resolved()).count();
        (checked.len(), wide)
    }

    /// Fits that reached the truth: done, their chosen model contains the true one, not short of
    /// the truth's cost (shortfall known and at most [`SHORTFALL_TOLERANCE_NATS`]), and their truth
    /// not moving with the integrator by more than [`SPREAD_WARN_NATS`] where the result says. Their
    /// intervals are the interval method's alone: a short fit's miss is its search's, and an
    /// unresolved truth has no cost to be near.
    pub fn reached(&self) -> impl Iterator<Item = &RecordingScore> {
        self.done().filter(|r| {
            r.model_contains_truth()
                && r.shortfall_nats
                    .is_some_and(|s| s <= SHORTFALL_TOLERANCE_NATS)
                && r.truth_resolved()
        })
    }

    /// (fits whose shortfall is known, of them above [`SHORTFALL_TOLERANCE_NATS`], the largest).
    pub fn shortfalls(&self) -> (usize, usize, f64) {
        let s: Vec<f64> = self.done().filter_map(|r| r.shortfall_nats).collect();
        let over = s.iter().filter(|x| **x > SHORTFALL_TOLERANCE_NATS).count();
        (s.len(), over, s.iter().copied().fold(f64::NAN, f64::max))
    }

    /// The likelihood ratio at the truth over the fits that did not fall short (shortfall at most
    /// [`SHORTFALL_TOLERANCE_NATS`]; a short fit measures its search, not the likelihood), whose
    /// truth the integrator resolves (its cost spreads by at most [`SPREAD_WARN_NATS`] over the
    /// tolerances, where the result has that check) and whose true model's `(k, tr(F⁻¹V))` are
    /// known: (fits, mean of D = truth's cost − fit's, mean `tr/2`, mean `k/2`, fits whose D
    /// exceeds the 95 % point of `(tr/k)·χ²(k)/2`).
    pub fn truth_ratios(&self) -> (usize, f64, f64, f64, usize) {
        let rows: Vec<(f64, usize, f64)> = self
            .done()
            .filter(|r| r.truth_resolved())
            .filter_map(RecordingScore::priced_ratio)
            .filter(|(d, ..)| *d >= -SHORTFALL_TOLERANCE_NATS)
            .collect();
        let n = rows.len();
        let mean =
            |f: &dyn Fn(&(f64, usize, f64)) -> f64| rows.iter().map(f).sum::<f64>() / n as f64;
        let beyond = rows
            .iter()
            .filter(|(d, k, tr)| beyond_ratio_95(*d, *k, *tr))
            .count();
        (
            n,
            mean(&|r| r.0),
            mean(&|r| r.2 / 2.0),
            mean(&|r| r.1 as f64 / 2.0),
            beyond,
        )
    }

    /// The fits that reached the truth ([`Calibration::reached`]) with their true model's `(k,
    /// tr(F⁻¹V))`, split by whether a parameter's 95 % interval misses the truth (`|z_95|` above
    /// 1.96): for each, D/(tr/2) (D = the truth's cost above the fit's, tr/2 its mean under the
    /// calibrated likelihood) and whether D exceeds the 95 % point of `(tr/k)·χ²(k)/2`;
    /// (fits with a miss, the others).
    pub fn wide_misses_against_ratio(&self) -> (Vec<RatioAtTruth>, Vec<RatioAtTruth>) {
        let wide = sigmas_at(WIDE_LEVEL);
        let (mut missed, mut covered) = (Vec::new(), Vec::new());
        for r in self.reached() {
            let Some((d, k, tr)) = r.priced_ratio() else {
                continue;
            };
            let row = RatioAtTruth {
                over_mean: d / (tr / 2.0),
                beyond_95: beyond_ratio_95(d, k, tr),
            };
            if r.params
                .iter()
                .any(|p| p.z_95.is_some_and(|z| z.abs() > wide))
            {
                missed.push(row);
            } else {
                covered.push(row);
            }
        }
        (missed, covered)
    }

    /// Of the done recordings whose chosen model is not the true one: (how many, of them how many
    /// have the true model within [`INDISTINGUISHABLE_TIC`] of the chosen one, the largest TIC lead
    /// against the true model among the rest).
    pub fn wrong_choices(&self) -> (usize, usize, f64) {
        let wrong: Vec<Option<f64>> = self
            .done()
            .filter(|r| r.chose_another_model())
            .map(|r| r.true_model_delta_tic)
            .collect();
        let near = |d: &Option<f64>| d.is_some_and(|d| d <= INDISTINGUISHABLE_TIC);
        let unresolved = wrong.iter().filter(|d| near(d)).count();
        let lead = (wrong.iter().flatten())
            .filter(|d| **d > INDISTINGUISHABLE_TIC)
            .fold(f64::NAN, |a, d| a.max(*d));
        (wrong.len(), unresolved, lead)
    }

    /// Counts of (true model, chosen model) over done recordings whose truth names a model.
    pub fn confusion(&self) -> BTreeMap<(String, String), usize> {
        let mut m = BTreeMap::new();
        for r in self.done() {
            if let (Some(t), Some(c)) = (r.true_model, r.chosen) {
                *m.entry((t.to_string(), c.to_string())).or_insert(0) += 1;
            }
        }
        m
    }
}

/// Reads every recording's truth, status and result, and computes the calibration; `None` when
/// the campaign's template has no `[truth]`.
///
/// # Errors
/// [`Error::Io`]/[`Error::Parse`] for a truth or result file that cannot be read, and
/// [`Error::Input`] for a truth whose `/model` is not a model name.
pub fn calibrate(campaign: &Campaign) -> Result<Option<Calibration>> {
    let out = campaign.out_dir();
    let mut recordings = Vec::with_capacity(campaign.entries.len());
    for e in &campaign.entries {
        let Some(truth) = campaign.truth_of(e) else {
            return Ok(None);
        };
        let (true_model, departure) = truth_labels(&truth.json)?;
        let paths = EntryPaths::new(&out, e);
        let status = read_status(&paths);
        let mut r = RecordingScore {
            id: e.id.clone(),
            state: "missing".into(),
            reason: String::new(),
            true_model,
            chosen: None,
            shortfall_nats: None,
            ridge_nats: None,
            truth_spread_nats: None,
            truth_jitter_nats: None,
            rounding_widening_max: None,
            averaged_shortfall_nats: None,
            wall_time_s: f64::NAN,
            params: Vec::new(),
            departure,
            law: None,
            gof_p: None,
            true_model_delta_tic: None,
            true_model_k_tr: None,
        };
        if let Some(s) = status {
            r.wall_time_s = s.wall_time_s;
            r.reason = s.reason.unwrap_or_default();
            r.state = match s.state {
                State::Done => "done".into(),
                State::Failed => "failed".into(),
            };
            if s.state == State::Done {
                let result = FitResult::read(&paths.result)?;
                score(&mut r, &result);
            }
        }
        recordings.push(r);
    }
    let overall = param_stats(recordings.iter().filter(|r| r.model_contains_truth()));
    let mut models: Vec<Candidate> = recordings.iter().filter_map(|r| r.true_model).collect();
    models.sort_by_key(|c| c.to_string());
    models.dedup();
    let by_model = models
        .into_iter()
        .map(|m| {
            let rs = recordings
                .iter()
                .filter(|r| r.true_model == Some(m) && r.model_contains_truth());
            (m, param_stats(rs))
        })
        .collect();
    Ok(Some(Calibration {
        name: campaign.name.clone(),
        campaign: campaign.path.clone(),
        recordings,
        overall,
        by_model,
    }))
}

/// `/model` and `/departure` of the truth file at `path`, where it names them.
fn truth_labels(path: &Path) -> Result<(Option<Candidate>, Option<String>)> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, "cannot read", e))?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| Error::parse(path, e.line(), e.column(), format!("not valid JSON: {e}")))?;
    let departure = v
        .pointer("/departure")
        .and_then(serde_json::Value::as_str)
        .map(str::to_string);
    let model = match v.pointer("/model").and_then(serde_json::Value::as_str) {
        Some(name) => Some(
            name.parse::<Candidate>()
                .map_err(|e| Error::input(path, format!("/model: {e}")))?,
        ),
        None => None,
    };
    Ok((model, departure))
}

/// Fills `r` from its fit `result`: the chosen model, the shortfall and the scored parameters.
fn score(r: &mut RecordingScore, result: &FitResult) {
    r.chosen = Some(result.model);
    r.shortfall_nats = priced_shortfall(r, result.shortfall_nats(), result.truth_model.is_some());
    // The true model's trial; with several laws of it (`[fit] laws`, a truth naming none), the
    // one closest to the chosen model's TIC.
    let tic = |e: &TrialEvidence| e.delta_tic.unwrap_or(f64::INFINITY);
    let true_trial = r.true_model.and_then(|t| {
        (result.model_trials.iter())
            .filter(|m| same_model(m.model, t))
            .filter_map(|m| Some((m.parameters.len(), m.evidence.as_ref()?)))
            .min_by(|(_, a), (_, b)| tic(a).total_cmp(&tic(b)))
    });
    r.true_model_delta_tic = true_trial.and_then(|(_, e)| e.delta_tic);
    r.true_model_k_tr = true_trial.and_then(|(k, e)| Some((k, e.effective_parameters?)));
    r.ridge_nats = result.truth_segment.as_ref().map(|s| s.ridge_nats);
    r.truth_spread_nats = (result.truth_tolerance.as_ref())
        .filter(|t| r.shortfall_nats.is_some() && t.probed())
        .map(|t| t.spread_nats);
    r.truth_jitter_nats = (result.truth_tolerance.as_ref())
        .and_then(|t| t.jitter.as_ref())
        .map(|j| j.sd_nats);
    r.rounding_widening_max = (result.parameters.iter())
        .filter_map(|p| p.rounding_widening)
        .reduce(f64::max);
    r.averaged_shortfall_nats = result.averaged_shortfall_nats();
    r.law = super::law::LawScore::of(result);
    r.gof_p = result.goodness_of_fit.as_ref().map(|g| g.p_value);
    if !r.model_contains_truth() {
        return;
    }
    for p in &result.parameters {
        if p.name.is_shoulder() && r.true_model.is_some_and(|t| !t.shoulder) {
            continue;
        }
        let Some(truth) = p.true_value else { continue };
        r.params.push(Scored {
            param: p.name,
            value: p.value,
            truth,
            z: standardised_error(p, truth),
            level: p.interval.as_ref().map_or(f64::NAN, |i| i.level),
            z_method: method_standardised_error(p, truth),
            z_sandwich: sandwich_standardised_error(p, truth),
            z_95: wide_standardised_error(p, truth),
        });
    }
}

/// A fit's `shortfall` where it measures the search: the truth priced in its own model's candidate
/// (`in_true_model`, the fit's `[truth] model`) or in a chosen model that can state it; `None`
/// where the truth was priced in a model that cannot (its cost there says nothing of the search).
fn priced_shortfall(
    r: &RecordingScore,
    shortfall: Option<f64>,
    in_true_model: bool,
) -> Option<f64> {
    shortfall.filter(|_| in_true_model || r.model_contains_truth())
}

pub(super) fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:.1} %", 100.0 * x)
    } else {
        "–".into()
    }
}

fn num(x: f64, digits: usize) -> String {
    if x.is_nan() {
        "–".into()
    } else if x.is_infinite() {
        "∞".into()
    } else {
        format!("{x:.digits$}")
    }
}

fn stats_table(md: &mut String, stats: &[ParamStats]) {
    let _ = writeln!(
        md,
        "| parameter | scored | 68 % interval covers | its 95 % band | 95 % interval covers | its 95 % band | Σz² (n) | χ²(n) two-sided p | median \\|rel. error\\| | 90th pct \\|rel. error\\| |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    for s in stats {
        let mark = |inside: bool| if inside { "" } else { " **outside**" };
        let _ = writeln!(
            md,
            "| {} | {} | {}{} | {}–{} | {}{} | {}–{} | {} ({}) | {} | {} | {} |",
            s.param,
            s.n_estimates,
            s.covered,
            mark((s.band.0..=s.band.1).contains(&s.covered) || s.n == 0),
            s.band.0,
            s.band.1,
            s.covered_wide,
            mark((s.band_wide.0..=s.band_wide.1).contains(&s.covered_wide) || s.n == 0),
            s.band_wide.0,
            s.band_wide.1,
            num(s.sum_z2, 1),
            s.n,
            num(s.chi2_p, 3),
            pct(s.median_abs_rel_error),
            pct(s.p90_abs_rel_error),
        );
    }
}

/// The coverage table over the fits that reached the truth ([`Calibration::reached`]).
fn reached_section(md: &mut String, c: &Calibration) {
    let reached = c.reached().count();
    if reached > 0 {
        let _ = writeln!(
            md,
            "\n### Where the search reached the truth\n\n\
             Over the {reached} of the fits above that did not fall short of the truth's cost (by more than \
             {SHORTFALL_TOLERANCE_NATS} nats) and whose truth the integrator resolves (its cost \
             spreads by at most {SPREAD_WARN_NATS} nats over tenfold and hundredfold tighter \
             tolerances, where the result has `truth_tolerance`): what the interval method covers \
             when the search and the integrator leave it nothing else to cover.\n"
        );
        stats_table(md, &param_stats(c.reached()));
        variants_section(md, c);
        wide_misses_paragraph(md, c);
    }
}

/// Where the 95 % intervals of the fits that reached the truth miss it, how far out in
/// likelihood the truth lies against the fits whose intervals all cover it
/// ([`Calibration::wide_misses_against_ratio`]). Nothing when no fit has a miss.
fn wide_misses_paragraph(md: &mut String, c: &Calibration) {
    let (missed, covered) = c.wide_misses_against_ratio();
    if missed.is_empty() {
        return;
    }
    let ratios = |rows: &[RatioAtTruth]| rows.iter().map(|r| r.over_mean).collect::<Vec<f64>>();
    let (m, n) = (missed.len(), missed.len() + covered.len());
    let beyond = missed.iter().filter(|r| r.beyond_95).count();
    let others = if covered.is_empty() {
        String::new()
    } else {
        let cr = ratios(&covered);
        format!(
            ", at the other {} a median {} (at most {})",
            covered.len(),
            num(quantile(&cr, 0.5), 1),
            num(cr.iter().copied().fold(f64::NAN, f64::max), 1)
        )
    };
    let _ = writeln!(
        md,
        "\nOf the {n} of these fits priced with their true model's `tr(F⁻¹V)`, {m} miss the truth \
         with a parameter's 95 % interval. There the truth's cost lies a median {} times \
         tr(F⁻¹V)/2 above the fit's{others}; {beyond} of the {m} lie beyond the 95 % point of \
         (tr/k)·χ²(k)/2. A miss whose truth lies that far out in likelihood is beyond the scale \
         the noise replicates give the intervals; a miss at the others' ratios is the interval \
         method's own.",
        num(quantile(&ratios(&missed), 0.5), 1)
    );
}

/// Coverage split by the truth's cost jitter ([`RecordingScore::truth_jitter_nats`]): the fits
/// whose chosen model contains the true one, with a truth whose cost jitters by at most
/// [`SHORTFALL_TOLERANCE_NATS`] (the resolution the table reads costs at) and by more. Nothing
/// when no result has the jitter.
fn jitter_section(md: &mut String, c: &Calibration) {
    let with = |rough: bool| {
        c.done().filter(move |r| {
            r.model_contains_truth()
                && r.truth_jitter_nats
                    .is_some_and(|j| (j > SHORTFALL_TOLERANCE_NATS) == rough)
        })
    };
    let (smooth, rough) = (with(false).count(), with(true).count());
    if smooth + rough == 0 {
        return;
    }
    let _ = writeln!(
        md,
        "\n### By the truth's cost jitter\n\n\
         The fits above whose result measured their truth's cost jitter under rounding-level steps \
         (`truth_jitter_nats`; docs/likelihood.md, \"Jitter\"), split at \
         {SHORTFALL_TOLERANCE_NATS} nats: {smooth} truths whose cost does not jitter beyond it, \
         then {rough} whose slip grows an oscillation out of the integrator's error.\n"
    );
    for (rough, n) in [(false, smooth), (true, rough)] {
        if n > 0 {
            let side = if rough { "above" } else { "at most" };
            let _ = writeln!(
                md,
                "**Truth's cost jitter {side} {SHORTFALL_TOLERANCE_NATS} nats** (fits: {n}):\n"
            );
            stats_table(md, &param_stats(with(rough)));
        }
    }
}

/// One parameter's coverage by three intervals over a set of recordings.
#[derive(Debug, Clone, PartialEq)]
pub struct VariantCoverage {
    pub param: ParamId,
    /// Recordings scored by all three intervals.
    pub n: usize,
    /// `(68 %, 95 %)` counts of the reported interval, the method's own and the sandwich's.
    pub reported: (usize, usize),
    pub method: (usize, usize),
    pub sandwich: (usize, usize),
}

/// Coverage of the reported interval, the method's own before widening and the sandwich Laplace
/// interval, per parameter, over `recordings` where all three exist; 68.27 % is `|z| ≤ 1`, 95 %
/// `|z| ≤ 1.96` (the reported one's 95 % interval: [`wide_standardised_error`]; the method's own
/// before widening and the sandwich's: 1.96 times their 68.27 % half-widths).
pub fn variant_coverage<'a>(
    recordings: impl IntoIterator<Item = &'a RecordingScore>,
) -> Vec<VariantCoverage> {
    let wide = sigmas_at(WIDE_LEVEL);
    let mut by: BTreeMap<ParamId, VariantCoverage> = BTreeMap::new();
    let count = |c: &mut (usize, usize), z: f64, z_95: f64| {
        c.0 += usize::from(z.abs() <= 1.0);
        c.1 += usize::from(z_95.abs() <= wide);
    };
    for s in recordings.into_iter().flat_map(|r| &r.params) {
        let (Some(z), Some(zm), Some(zs)) = (s.z, s.z_method, s.z_sandwich) else {
            continue;
        };
        let v = by.entry(s.param).or_insert(VariantCoverage {
            param: s.param,
            n: 0,
            reported: (0, 0),
            method: (0, 0),
            sandwich: (0, 0),
        });
        v.n += 1;
        count(&mut v.reported, z, s.z_95.unwrap_or(z));
        count(&mut v.method, zm, zm);
        count(&mut v.sandwich, zs, zs);
    }
    by.into_values().collect()
}

/// What the widening adds: [`variant_coverage`] over the fits that reached the truth.
fn variants_section(md: &mut String, c: &Calibration) {
    let rows = variant_coverage(c.reached());
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n### The method alone and the sandwich\n\n\
         Over the same fits: how many truths the reported interval contains, the interval method's \
         own before it was widened to the points the search evaluated within the rise limit or to \
         the contact ridge (`widened_from`), and the Laplace interval of the sandwich 1σ \
         (`std_error`, ±1σ and ±1.96σ in the search's coordinate). 68 % counts, then 95 %, with \
         their bands (`{{p}}_z`, `{{p}}_z_method`, `{{p}}_z_sandwich` in \
         calibration_recordings.csv).\n\n\
         | parameter | scored | reported | method alone | sandwich | 68 % band | 95 % band |\n\
         |---|---|---|---|---|---|---|"
    );
    for v in rows {
        let (b68, b95) = (binomial_band(v.n, 0.6827), binomial_band(v.n, WIDE_LEVEL));
        let pair = |c: (usize, usize)| format!("{}, {}", c.0, c.1);
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {}–{} | {}–{} |",
            v.param,
            v.n,
            pair(v.reported),
            pair(v.method),
            pair(v.sandwich),
            b68.0,
            b68.1,
            b95.0,
            b95.1
        );
    }
}

/// How many short fits lie within their truth's own spread over the tolerances.
fn shortfall_unresolved_paragraph(md: &mut String, c: &Calibration) {
    let (checked, wider) = c.shortfall_unresolved();
    if checked > 0 {
        let _ = writeln!(
            md,
            "\nOf the {checked} short fits whose truth was priced at tighter tolerances too, \
             {wider} have a truth whose cost moves by more than the shortfall between them: \
             there the integrator, not the search, may have put the fit above the truth."
        );
    }
    let (jittered, over) = c.shortfall_jittered();
    if jittered > 0 {
        let _ = writeln!(
            md,
            "\nOf the {jittered} short fits whose truth's cost jitter was measured, {over} have a \
             shortfall within two standard deviations of their truth's cost jitter under \
             rounding-level steps (`truth_jitter_nats` in calibration_recordings.csv): their slip \
             grows an oscillation out of the integrator's error, whose timing sets the cost \
             (docs/likelihood.md, \"Jitter\"), so the truth's cost is known only to within that \
             jitter."
        );
    }
    let (rough, short, hidden) = c.averaged_shortfalls();
    if rough > 0 {
        let _ = writeln!(
            md,
            "\nOf the {rough} fits whose truth's cost jitters by more than \
             {SHORTFALL_TOLERANCE_NATS} nats, {short} are short when each side's cost is averaged \
             over its rounding draws (`averaged_shortfall_nats`), {hidden} of them not short by \
             the optimum's own cost: their search ended on a draw that suits the recording."
        );
    }
}

/// How far above the fit the truth's cost lies, against what the calibrated likelihood predicts.
fn ratio_section(md: &mut String, c: &Calibration) {
    let (n, d, tr, k, beyond) = c.truth_ratios();
    if n == 0 {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Likelihood ratio at the truth\n\n\
         Over the {n} fits priced in the true model with its `tr(F⁻¹V)` that did not fall short: \
         the truth's cost lies on average {} nats above the fit's (D). Under the \
         likelihood as its intervals calibrate it, 2D is distributed as Σλᵢχ²(1) with \
         Σλᵢ = tr(F⁻¹V) (Takeuchi; Varin, Reid & Firth 2011), mean tr/2 = {} on average; Wilks' \
         uncalibrated χ²(k) has mean k/2 = {}. {beyond} of the {n} exceed the 95 % point of \
         (tr/k)·χ²(k)/2 (5 % expected): a share far above it says the truth lies further from \
         the fit, in likelihood, than the noise replicates at the fit say (`true_model_k`, \
         `true_model_tr_fv` and `shortfall_nats` in calibration_recordings.csv).",
        num(d, 2),
        num(tr, 2),
        num(k, 2)
    );
    let (checked, wide) = c.unresolved_truths();
    if checked > 0 {
        let _ = writeln!(
            md,
            "\nOf the {checked} fits whose result prices the truth at tenfold and hundredfold \
             tighter tolerances too, {wide} have a truth whose cost spreads by more than \
             {SPREAD_WARN_NATS} nats over them: the integrator does not resolve that truth, so \
             its cost says nothing of the noise, and those fits are left out above \
             (`truth_spread_nats` in calibration_recordings.csv)."
        );
    }
}

/// The model-choice section: the confusion matrix, true model × chosen model (nothing when no
/// recording names its true model), and how many wrong choices were reported as not
/// distinguishable.
fn confusion_section(md: &mut String, c: &Calibration) {
    let confusion = c.confusion();
    if confusion.is_empty() {
        return;
    }
    {
        let mut chosen: Vec<&String> = confusion.keys().map(|k| &k.1).collect();
        chosen.sort();
        chosen.dedup();
        let mut truths: Vec<&String> = confusion.keys().map(|k| &k.0).collect();
        truths.sort();
        truths.dedup();
        let _ = writeln!(
            md,
            "\n## Model choice\n\nRows: the model that made the recording; columns: the model the fit chose (fitted recordings).\n"
        );
        let _ = writeln!(
            md,
            "| true \\ chosen | {} |",
            chosen
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(" | ")
        );
        let _ = writeln!(md, "|---|{}", "---|".repeat(chosen.len()));
        for t in &truths {
            let cells: Vec<String> = chosen
                .iter()
                .map(|ch| {
                    confusion
                        .get(&((*t).clone(), (*ch).clone()))
                        .copied()
                        .unwrap_or(0)
                        .to_string()
                })
                .collect();
            let _ = writeln!(md, "| {t} | {} |", cells.join(" | "));
        }
    }
    let (wrong, unresolved, lead) = c.wrong_choices();
    if wrong > 0 {
        let others = if unresolved == wrong {
            String::new()
        } else {
            format!(
                "; the others, silent wrong choices, chose against it by a TIC of up to {}",
                num(lead, 2)
            )
        };
        let _ = writeln!(
            md,
            "\n{wrong} fits chose another model than the true one; {unresolved} of them report the \
             true model as not distinguishable by the recording (its TIC within \
             {INDISTINGUISHABLE_TIC} of the chosen model's){others} \
             (`true_model_delta_tic` in calibration_recordings.csv)."
        );
    }
}

/// The calibration as Markdown: what was run, the coverage tables (overall and by true model),
/// the search shortfall, the model-choice confusion matrix, fit times and failures.
pub fn to_markdown(c: &Calibration, notes: Option<&str>, command: &str) -> String {
    let mut md = String::new();
    let total = c.recordings.len();
    let done = c.done().count();
    let failed = c.recordings.iter().filter(|r| r.state == "failed").count();
    let _ = writeln!(md, "# Calibration: {}\n", c.name);
    if let Some(n) = notes {
        let _ = writeln!(md, "{}\n", n.trim());
    }
    let _ = writeln!(
        md,
        "Made by `{command}` (wiperlab {}) from the results of {total} recordings: {done} fitted, {failed} failed, {} without a result.\n",
        env!("CARGO_PKG_VERSION"),
        total - done - failed
    );
    let scored = c.done().filter(|r| r.model_contains_truth()).count();
    let _ = writeln!(
        md,
        "## Coverage and error by parameter\n\n\
         Over the {scored} fitted recordings whose chosen model contains the true one (a parameter is \
         scored when the true model has it). The 68 % interval is the one the result reports (level \
         0.6827); the 95 % interval is the reported interval's half-widths times 1.96 in the search's \
         coordinate (for Laplace intervals, ±1.96σ), or the method's own where the result gives one \
         and it reaches further (`range_95`: the profile walked on to the 95 % rise, a posterior's \
         2.5–97.5 % quantiles). A count is **outside** when it leaves the central \
         95 % band of Binomial(n, level). z = the truth's distance from the estimate in σ read from the \
         interval on the truth's side; Σz² is compared with χ²(n), small p on either side: too large, \
         intervals too narrow; too small, too wide.\n"
    );
    stats_table(&mut md, &c.overall);
    for (m, stats) in &c.by_model {
        let of_model = || c.recordings.iter().filter(|r| r.true_model == Some(*m));
        let _ = writeln!(
            md,
            "\n### True model {m} ({} of {} recordings fitted)\n",
            of_model().filter(|r| r.state == "done").count(),
            of_model().count()
        );
        stats_table(&mut md, stats);
    }
    reached_section(&mut md, c);
    jitter_section(&mut md, c);
    let (known, over, max) = c.shortfalls();
    let _ = writeln!(
        md,
        "\n## Search shortfall\n\n\
         {over} of {known} fits (those whose result has the truth's own cost in the true model's \
         candidate, or in a chosen model that contains it) end more than {SHORTFALL_TOLERANCE_NATS} nats above the truth's cost; \
         rate {}; largest shortfall {} nats (negative: the fit is more likely than the truth).",
        if known > 0 {
            pct(over as f64 / known as f64)
        } else {
            "–".into()
        },
        num(max, 3)
    );
    let (measured, beyond) = c.shortfall_ridges();
    if measured > 0 {
        let _ = writeln!(
            md,
            "\nOf the {measured} short fits whose result has the segment from the fit to the truth, \
             {beyond} have a ridge higher than {RIDGE_NATS} nats on it: the truth lies in another \
             basin, which the global search did not enter; in the other {} the search stopped on \
             the slope of the truth's own basin (`ridge_nats` in calibration_recordings.csv).",
            measured - beyond
        );
    }
    shortfall_unresolved_paragraph(&mut md, c);
    ratio_section(&mut md, c);
    confusion_section(&mut md, c);
    super::law::law_section(&mut md, c);
    let times: Vec<f64> = c.done().map(|r| r.wall_time_s).collect();
    let _ = writeln!(
        md,
        "\n## Fit time\n\nWall time per fitted recording: median {} s, 90th percentile {} s, over {} fits; \
         their sum {} h (the campaign's length when the fits run one at a time; where they ran side by \
         side on shared cores, each took longer and the sum overstates it).",
        num(quantile(&times, 0.5), 1),
        num(quantile(&times, 0.9), 1),
        times.len(),
        num(times.iter().sum::<f64>() / 3600.0, 2)
    );
    let failed: Vec<&RecordingScore> = c
        .recordings
        .iter()
        .filter(|r| r.state == "failed")
        .collect();
    let missing: Vec<&str> = c
        .recordings
        .iter()
        .filter(|r| r.state == "missing")
        .map(|r| r.id.as_str())
        .collect();
    if !failed.is_empty() || !missing.is_empty() {
        let _ = writeln!(md, "\n## Recordings without a result\n");
        for r in failed {
            let _ = writeln!(md, "- {} failed: {}", r.id, r.reason);
        }
        if !missing.is_empty() {
            let _ = writeln!(
                md,
                "- {} not fitted (or still running): {}",
                missing.len(),
                missing.join(", ")
            );
        }
    }
    md
}

fn csv_num(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else {
        format!("{x:e}")
    }
}

/// The statistics as CSV: one row per (scope, parameter), scope `all` or a true model.
///
/// # Errors
/// [`Error::Write`] if the CSV writer fails (it writes to memory).
pub fn stats_csv(c: &Calibration) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| Error::write("calibration.csv", "CSV", e);
    w.write_record([
        "scope",
        "parameter",
        "scored",
        "with_interval",
        "level",
        "covered",
        "band_lo",
        "band_hi",
        "covered_95",
        "band_95_lo",
        "band_95_hi",
        "sum_z2",
        "chi2_two_sided_p",
        "median_abs_rel_error",
        "p90_abs_rel_error",
    ])
    .map_err(err)?;
    let scopes = std::iter::once(("all".to_string(), &c.overall))
        .chain(c.by_model.iter().map(|(m, s)| (m.to_string(), s)));
    for (scope, stats) in scopes {
        for s in stats {
            w.write_record([
                scope.clone(),
                s.param.to_string(),
                s.n_estimates.to_string(),
                s.n.to_string(),
                csv_num(s.level),
                s.covered.to_string(),
                s.band.0.to_string(),
                s.band.1.to_string(),
                s.covered_wide.to_string(),
                s.band_wide.0.to_string(),
                s.band_wide.1.to_string(),
                csv_num(s.sum_z2),
                csv_num(s.chi2_p),
                csv_num(s.median_abs_rel_error),
                csv_num(s.p90_abs_rel_error),
            ])
            .map_err(err)?;
        }
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::write("calibration.csv", "CSV", e.into_error()))?;
    String::from_utf8(bytes).map_err(|e| Error::write("calibration.csv", "CSV", e))
}

/// One row per recording: state, true and chosen model, shortfall, wall time, and per parameter
/// its estimate, truth and z (empty cells where not scored).
///
/// # Errors
/// [`Error::Write`] if the CSV writer fails (it writes to memory).
pub fn recordings_csv(c: &Calibration) -> Result<String> {
    let mut params: Vec<ParamId> = c
        .recordings
        .iter()
        .flat_map(|r| r.params.iter().map(|s| s.param))
        .collect();
    params.sort();
    params.dedup();
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| Error::write("calibration_recordings.csv", "CSV", e);
    let mut header: Vec<String> = [
        "id",
        "state",
        "true_model",
        "chosen_model",
        "shortfall_nats",
        "ridge_nats",
        "truth_spread_nats",
        "truth_jitter_nats",
        "rounding_widening_max",
        "averaged_shortfall_nats",
        "wall_time_s",
        "departure",
        "law_rms_rel_diff",
        "law_share_in_band",
        "law_share_in_envelope",
        "law_open_rel",
        "gof_p",
        "true_model_delta_tic",
        "true_model_k",
        "true_model_tr_fv",
    ]
    .map(String::from)
    .to_vec();
    for p in &params {
        header.extend([
            format!("{p}"),
            format!("{p}_true"),
            format!("{p}_z"),
            format!("{p}_z_method"),
            format!("{p}_z_sandwich"),
            format!("{p}_z_95"),
        ]);
    }
    w.write_record(&header).map_err(err)?;
    let name = |m: Option<Candidate>| m.map(|m| m.to_string()).unwrap_or_default();
    for r in &c.recordings {
        let mut rec = vec![
            r.id.clone(),
            r.state.clone(),
            name(r.true_model),
            name(r.chosen),
            r.shortfall_nats.map(csv_num).unwrap_or_default(),
            r.ridge_nats.map(csv_num).unwrap_or_default(),
            r.truth_spread_nats.map(csv_num).unwrap_or_default(),
            r.truth_jitter_nats.map(csv_num).unwrap_or_default(),
            r.rounding_widening_max.map(csv_num).unwrap_or_default(),
            r.averaged_shortfall_nats.map(csv_num).unwrap_or_default(),
            csv_num(r.wall_time_s),
            r.departure.clone().unwrap_or_default(),
            r.law.map(|l| csv_num(l.rms_rel_diff)).unwrap_or_default(),
            r.law
                .and_then(|l| l.within_band)
                .map(csv_num)
                .unwrap_or_default(),
            r.law
                .and_then(|l| l.within_envelope)
                .map(csv_num)
                .unwrap_or_default(),
            r.law
                .and_then(|l| l.open_rel)
                .map(csv_num)
                .unwrap_or_default(),
            r.gof_p.map(csv_num).unwrap_or_default(),
            r.true_model_delta_tic.map(csv_num).unwrap_or_default(),
            r.true_model_k_tr
                .map(|(k, _)| k.to_string())
                .unwrap_or_default(),
            r.true_model_k_tr
                .map(|(_, tr)| csv_num(tr))
                .unwrap_or_default(),
        ];
        for p in &params {
            match r.params.iter().find(|s| s.param == *p) {
                Some(s) => rec.extend([
                    csv_num(s.value),
                    csv_num(s.truth),
                    s.z.map(csv_num).unwrap_or_default(),
                    s.z_method.map(csv_num).unwrap_or_default(),
                    s.z_sandwich.map(csv_num).unwrap_or_default(),
                    s.z_95.map(csv_num).unwrap_or_default(),
                ]),
                None => rec.extend(std::iter::repeat_n(String::new(), 6)),
            }
        }
        w.write_record(&rec).map_err(err)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::write("calibration_recordings.csv", "CSV", e.into_error()))?;
    String::from_utf8(bytes).map_err(|e| Error::write("calibration_recordings.csv", "CSV", e))
}

/// Computes the calibration of `campaign` and writes `calibration.md`, `calibration.csv` and
/// `calibration_recordings.csv` into [`Campaign::calibration_dir`]; `command` is the command line
/// quoted in the table. Returns the calibration and the Markdown file's path; `None` when the
/// recordings carry no truth.
///
/// # Errors
/// Those of [`calibrate`]; [`Error::Io`] when a file cannot be written.
pub fn write(campaign: &Campaign, command: &str) -> Result<Option<(Calibration, PathBuf)>> {
    let Some(c) = calibrate(campaign)? else {
        return Ok(None);
    };
    let dir = campaign.calibration_dir();
    crate::io::create_dir(&dir)?;
    let md = dir.join("calibration.md");
    write_atomic(
        &md,
        to_markdown(&c, campaign.file.notes.as_deref(), command).as_bytes(),
    )?;
    write_atomic(&dir.join("calibration.csv"), stats_csv(&c)?.as_bytes())?;
    write_atomic(
        &dir.join("calibration_recordings.csv"),
        recordings_csv(&c)?.as_bytes(),
    )?;
    Ok(Some((c, md)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::result::{Interval, IntervalMethod};

    /// P(X ≤ k) of Binomial(n, p) by summing the mass function, each term from the last by the
    /// ratio (n − i)/(i + 1)·p/(1 − p): independent of statrs' CDF (a regularised incomplete
    /// beta function).
    fn cdf_by_sum(k: usize, n: usize, p: f64) -> f64 {
        let mut term = (1.0 - p).powi(n as i32);
        let mut sum = term;
        for i in 0..k {
            term *= (n - i) as f64 / (i + 1) as f64 * p / (1.0 - p);
            sum += term;
        }
        sum
    }

    /// The bands against exact rational arithmetic (Python's `fractions` and `math.comb`:
    /// the largest lo with P(X ≤ lo − 1) ≤ 1/40, the smallest hi with P(X > hi) ≤ 1/40):
    /// n = 100, p = 0.68 → 59–77; p = 0.6827 → 59–77; p = 0.95 → 90–99; n = 42, p = 0.68 →
    /// 23–34 (the band issue 42 quotes); and at each band's ends the summed mass function agrees
    /// that the ends are the last and first counts inside.
    #[test]
    fn binomial_bands_match_exact_counts() {
        assert_eq!(binomial_band(100, 0.68), (59, 77));
        assert_eq!(binomial_band(100, 0.6827), (59, 77));
        assert_eq!(binomial_band(100, 0.95), (90, 99));
        assert_eq!(binomial_band(42, 0.68), (23, 34));
        for (n, p) in [(100, 0.68), (100, 0.95), (42, 0.68), (6, 0.6827)] {
            let (lo, hi) = binomial_band(n, p);
            assert!(cdf_by_sum(lo - 1, n, p) <= 0.025 && cdf_by_sum(lo, n, p) > 0.025);
            assert!(1.0 - cdf_by_sum(hi, n, p) <= 0.025);
            assert!(1.0 - cdf_by_sum(hi - 1, n, p) > 0.025);
        }
    }

    /// χ² p-values against closed forms of the CDF: χ²(2) has F(x) = 1 − e^{−x/2}, χ²(4) has
    /// F(x) = 1 − e^{−x/2}(1 + x/2) (Abramowitz & Stegun 26.4.21, even degrees of freedom).
    #[test]
    fn chi2_p_values_match_closed_forms() {
        for x in [0.1, 1.0, 2.0, 5.0, 12.0] {
            let f2 = 1.0 - (-x / 2.0_f64).exp();
            let f4 = 1.0 - (-x / 2.0_f64).exp() * (1.0 + x / 2.0);
            let two_sided = |f: f64| 2.0 * f.min(1.0 - f);
            assert!(
                (chi2_two_sided_p(x, 2) - two_sided(f2)).abs() < 1e-12,
                "{x}"
            );
            assert!(
                (chi2_two_sided_p(x, 4) - two_sided(f4)).abs() < 1e-12,
                "{x}"
            );
        }
        assert_eq!(chi2_two_sided_p(f64::INFINITY, 3), 0.0);
        assert!(chi2_two_sided_p(1.0, 0).is_nan());
    }

    /// Definition 7: 1…10 has median 5.5 and 90th percentile 9.1; one value is every quantile.
    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let v: Vec<f64> = (1..=10).rev().map(f64::from).collect();
        assert!((quantile(&v, 0.5) - 5.5).abs() < 1e-12);
        assert!((quantile(&v, 0.9) - 9.1).abs() < 1e-12);
        assert_eq!(quantile(&[3.0], 0.9), 3.0);
        assert!(quantile(&[], 0.5).is_nan());
    }

    fn param(name: ParamId, value: f64, bounds: [f64; 2], interval: [f64; 2]) -> FittedParam {
        FittedParam {
            name,
            value,
            lower: bounds[0],
            upper: bounds[1],
            std_error: f64::NAN,
            fisher_std_error: None,
            rounding_widening: None,
            determined: true,
            true_value: None,
            rel_error: None,
            interval: Some(Interval {
                lo: interval[0],
                hi: interval[1],
                level: 0.6827,
                method: IntervalMethod::Curvature,
                widened_from: None,
                range_95: None,
            }),
        }
    }

    /// z on each side of an asymmetric interval, on a linear and on a log scale; a 68.27 %
    /// interval's half-width is 1.0000 σ (Φ⁻¹(0.84135) = 0.99998).
    #[test]
    fn standardised_errors_read_the_interval_on_the_truths_side() {
        // A on [0.2, 1.5] is searched linearly (bounds less than a decade apart).
        let c = param(ParamId::A, 0.5, [0.2, 1.5], [0.45, 0.6]);
        let sigma = Normal::standard().inverse_cdf(0.5 * 1.6827);
        assert!((standardised_error(&c, 0.7).unwrap() - 2.0 * sigma).abs() < 1e-12);
        assert!((standardised_error(&c, 0.4).unwrap() + 2.0 * sigma).abs() < 1e-12);
        assert_eq!(standardised_error(&c, 0.5), Some(0.0));
        // B on [10, 300] is searched in ln B (so is C on [0.1, 1.0], a decade exactly): the
        // interval [50, 200] around 100 is ±ln 2.
        let b = param(ParamId::B, 100.0, [10.0, 300.0], [50.0, 200.0]);
        assert!((standardised_error(&b, 400.0).unwrap() - 2.0 * sigma).abs() < 1e-12);
        assert!((standardised_error(&b, 25.0).unwrap() + 2.0 * sigma).abs() < 1e-12);
        let flat = param(ParamId::A, 0.5, [0.2, 1.5], [0.5, 0.6]);
        assert_eq!(standardised_error(&flat, 0.4), Some(f64::NEG_INFINITY));
    }

    /// The 95 % interval: without a `range_95` it is the reported one's half-widths times 1.96,
    /// so the wide z is the 68.27 % z; with one, z reads the wider of its half-width and that on
    /// the truth's side as Φ⁻¹(0.975) σ. A = 0.5 on [0.45, 0.6] with the 95 % range [0.3, 0.65]:
    /// a truth at 0.4 is 2σ out by the 68.27 % interval (outside ±1.96) and 0.5·1.96 σ inside the
    /// range (half-width 0.2 against 1.96·0.05); above, the range's 0.15 is narrower than
    /// 1.96·0.1, so a truth at 0.7 scores as without the range.
    #[test]
    fn the_95_range_is_scored_where_the_result_has_one() {
        let mut a = param(ParamId::A, 0.5, [0.2, 1.5], [0.45, 0.6]);
        let sigma = Normal::standard().inverse_cdf(0.5 * 1.6827);
        let z95 = Normal::standard().inverse_cdf(0.975);
        assert_eq!(
            wide_standardised_error(&a, 0.4),
            standardised_error(&a, 0.4)
        );
        assert!((standardised_error(&a, 0.4).unwrap() + 2.0 * sigma).abs() < 1e-12);
        a.interval.as_mut().unwrap().range_95 = Some([0.3, 0.65]);
        assert!((wide_standardised_error(&a, 0.4).unwrap() + 0.5 * z95).abs() < 1e-12);
        let without = standardised_error(&a, 0.7).unwrap();
        assert!((wide_standardised_error(&a, 0.7).unwrap() - without).abs() < 1e-12);
    }

    /// A profile interval [0.48, 0.52] around A = 0.5 widened to [0.40, 0.52], sandwich 1σ 0.01:
    /// a truth at 0.45 lies inside the reported interval (z = −0.5), 2.5 half-widths outside the
    /// method's own and 5σ outside the sandwich's; a truth at 0.51 is inside all three (z = 0.5, 0.5, 1).
    #[test]
    fn the_method_alone_and_the_sandwich_are_scored_beside_the_reported_interval() {
        let mut a = param(ParamId::A, 0.5, [0.2, 1.5], [0.40, 0.52]);
        a.std_error = 0.01;
        if let Some(iv) = a.interval.as_mut() {
            iv.widened_from = Some([0.48, 0.52]);
        }
        let sigma = Normal::standard().inverse_cdf(0.5 * 1.6827);
        let close = |x: Option<f64>, want: f64| (x.unwrap() - want).abs() < 1e-9;
        assert!(close(standardised_error(&a, 0.45), -0.5 * sigma));
        assert!(close(method_standardised_error(&a, 0.45), -2.5 * sigma));
        assert!(close(sandwich_standardised_error(&a, 0.45), -5.0));
        assert!(close(method_standardised_error(&a, 0.51), 0.5 * sigma));
        assert!(close(sandwich_standardised_error(&a, 0.51), 1.0));
        // Not widened: the method's own interval is the reported one.
        let b = param(ParamId::A, 0.5, [0.2, 1.5], [0.45, 0.6]);
        assert_eq!(
            method_standardised_error(&b, 0.7),
            standardised_error(&b, 0.7)
        );
        assert_eq!(sandwich_standardised_error(&b, 0.7), None);
        // Counted per interval over a recording whose three z differ.
        let mut r = recording(&[0.5]);
        r.params[0].z_method = Some(1.5);
        r.params[0].z_sandwich = Some(2.5);
        let v = variant_coverage([&r]);
        assert_eq!(v.len(), 1);
        assert_eq!(
            (v[0].n, v[0].reported, v[0].method, v[0].sandwich),
            (1, (1, 1), (0, 1), (0, 0))
        );
    }

    /// A calibration of `recordings` with no coverage tables, for the sections read from the
    /// recordings alone.
    fn unscored(recordings: Vec<RecordingScore>) -> Calibration {
        Calibration {
            name: "t".into(),
            campaign: PathBuf::from("t.toml"),
            recordings,
            overall: Vec::new(),
            by_model: Vec::new(),
        }
    }

    fn recording(z: &[f64]) -> RecordingScore {
        RecordingScore {
            id: "r".into(),
            state: "done".into(),
            reason: String::new(),
            true_model: None,
            chosen: "blade2dof".parse().ok(),
            shortfall_nats: Some(0.0),
            ridge_nats: None,
            truth_spread_nats: None,
            truth_jitter_nats: None,
            rounding_widening_max: None,
            averaged_shortfall_nats: None,
            wall_time_s: 1.0,
            params: z
                .iter()
                .map(|&z| Scored {
                    param: ParamId::A,
                    value: 1.0 + 0.1 * z,
                    truth: 1.0,
                    z: Some(z),
                    level: 0.6827,
                    z_method: Some(z),
                    z_sandwich: Some(z),
                    z_95: Some(z),
                })
                .collect(),
            departure: None,
            law: None,
            gof_p: None,
            true_model_delta_tic: None,
            true_model_k_tr: None,
        }
    }

    /// Three fits with A's z of 0.5, 2 and 3: the first two truths' costs do not jitter beyond
    /// the shortfall tolerance, the third's does; a fourth has no jitter measured and is left out
    /// of the split.
    #[test]
    fn the_table_splits_coverage_by_the_truths_cost_jitter() {
        let fit = |z: f64, jitter: Option<f64>| {
            let mut r = recording(&[z]);
            r.truth_jitter_nats = jitter;
            r
        };
        let recordings = vec![
            fit(0.5, Some(0.0)),
            fit(2.0, Some(0.05)),
            fit(3.0, Some(4.0)),
            fit(0.1, None),
        ];
        let cal = Calibration {
            name: "t".into(),
            campaign: PathBuf::from("t.toml"),
            overall: param_stats(recordings.iter()),
            by_model: Vec::new(),
            recordings,
        };
        let md = to_markdown(&cal, None, "collect");
        let section = &md[md
            .find("### By the truth's cost jitter")
            .expect("the section")..];
        assert!(section.contains("2 truths whose cost does not jitter beyond it, then 1"));
        assert!(section.contains("**Truth's cost jitter at most 0.1 nats** (fits: 2)"));
        assert!(section.contains("**Truth's cost jitter above 0.1 nats** (fits: 1)"));
    }

    /// Four fits: short by 2 nats with a truth jittering by 1.5 (within two standard deviations)
    /// and by 0.5 (beyond), one within the tolerance, one short without a measured jitter: one of
    /// the two measured short fits lies within its truth's jitter.
    #[test]
    fn short_fits_within_their_truths_jitter_are_counted() {
        let fit = |short: f64, jitter: Option<f64>| {
            let mut r = recording(&[]);
            r.shortfall_nats = Some(short);
            r.truth_jitter_nats = jitter;
            r
        };
        let c = unscored(vec![
            fit(2.0, Some(1.5)),
            fit(2.0, Some(0.5)),
            fit(0.05, Some(1.0)),
            fit(3.0, None),
        ]);
        assert_eq!(c.shortfall_jittered(), (2, 1));
    }

    /// Four fits on jittery truths and one on a calm truth: short by the averaged cost by 15 nats
    /// while 0.8 nats more likely than the truth by the optimum's own cost (a lucky draw), short
    /// by both, not short by the averaged cost, and one without the averaged cost. The calm
    /// truth's fit is left out even though short.
    #[test]
    fn fits_short_by_the_draw_averaged_cost_are_counted() {
        let fit = |jitter: f64, averaged: Option<f64>, short: f64| {
            let mut r = recording(&[]);
            r.truth_jitter_nats = Some(jitter);
            r.averaged_shortfall_nats = averaged;
            r.shortfall_nats = Some(short);
            r
        };
        let c = unscored(vec![
            fit(3.7, Some(15.0), -0.8),
            fit(9.8, Some(6.0), 4.0),
            fit(0.3, Some(-1.0), -1.3),
            fit(2.0, None, 0.5),
            fit(0.01, Some(5.0), 5.0),
        ]);
        assert_eq!(c.averaged_shortfalls(), (3, 2, 1));
    }

    /// Four fits: two short (by 2 and by 0.3 nats) whose truths' costs spread by 5 and by 0.2 nats
    /// over the tolerances, one 40 nats more likely than a truth that spreads by 90, one 1 nat
    /// more likely than a resolved truth. Only the 2-nat shortfall lies within its truth's spread;
    /// the likelihood ratio reads the 1-nat fit alone (the 0.3-nat one fell short, the 40-nat
    /// one's truth is unresolved): D = 1 nat against tr/2 = 0.5.
    #[test]
    fn unresolved_truths_are_counted_and_left_out_of_the_ratio() {
        let fit = |short: f64, spread: f64| {
            let mut r = recording(&[]);
            r.shortfall_nats = Some(short);
            r.truth_spread_nats = Some(spread);
            r.true_model_k_tr = Some((4, 1.0));
            r
        };
        let c = unscored(vec![
            fit(2.0, 5.0),
            fit(0.3, 0.2),
            fit(-40.0, 90.0),
            fit(-1.0, 0.1),
        ]);
        assert_eq!(c.shortfall_unresolved(), (2, 1));
        let reached: Vec<f64> = c.reached().filter_map(|r| r.shortfall_nats).collect();
        assert_eq!(reached, vec![-1.0], "neither short nor unresolved");
        assert_eq!(c.unresolved_truths(), (4, 2));
        let (n, d, tr, k, _) = c.truth_ratios();
        assert_eq!(n, 1);
        assert_eq!((d, tr, k), (1.0, 0.5, 2.0));
        let md = to_markdown(&c, None, "wiperlab campaign collect t.toml");
        assert!(
            md.contains("2 short fits whose truth was priced at tighter tolerances too, 1 have"),
            "{md}"
        );
        assert!(md.contains("4 fits whose result prices the truth"), "{md}");
        assert!(
            md.contains("Over the 1 of the fits above that did not fall short"),
            "{md}"
        );
    }

    /// Three fits that reached the truth with k = 4 and tr(F⁻¹V) = 1: the truth 0.25 nats out with
    /// every 95 % interval covering, 0.5 and 3.0 nats out with a miss (|z_95| = 2.5). The 95 %
    /// point of (1/4)·χ²(4)/2 is 9.4877/8 = 1.186 nats (χ²(4)'s 95 % point from the table of
    /// Abramowitz & Stegun 26.8), so only the 3-nat one lies beyond it.
    #[test]
    fn wide_misses_are_set_against_the_likelihood_ratio() {
        let fit = |d: f64, z: f64| {
            let mut r = recording(&[z]);
            r.shortfall_nats = Some(-d);
            r.true_model_k_tr = Some((4, 1.0));
            r
        };
        let c = unscored(vec![fit(0.25, 1.0), fit(0.5, 2.5), fit(3.0, -2.5)]);
        let (missed, covered) = c.wide_misses_against_ratio();
        let rows = |v: &[RatioAtTruth]| {
            v.iter()
                .map(|r| (r.over_mean, r.beyond_95))
                .collect::<Vec<_>>()
        };
        assert_eq!(rows(&missed), vec![(1.0, false), (6.0, true)]);
        assert_eq!(rows(&covered), vec![(0.5, false)]);
        let md = to_markdown(&c, None, "wiperlab campaign collect t.toml");
        assert!(
            md.contains("Of the 3 of these fits priced with their true model's `tr(F⁻¹V)`, 2 miss"),
            "{md}"
        );
        assert!(md.contains("a median 3.5 times"), "{md}");
        assert!(
            md.contains("at the other 1 a median 0.5 (at most 0.5); 1 of the 2 lie beyond"),
            "{md}"
        );
    }

    /// Ten recordings with z = ±0.5 (×6), ±1.5 (×3), 2.5: 6 covered at 68 %, 9 at 95 %, Σz² =
    /// 6·0.25 + 3·2.25 + 6.25 = 14.5; the bands of Binomial(10, 0.6827) and (10, 0.95).
    #[test]
    fn stats_count_coverage_and_sum_z2() {
        let zs = [0.5, -0.5, 0.5, -0.5, 0.5, -0.5, 1.5, -1.5, 1.5, 2.5];
        let rs: Vec<RecordingScore> = zs.iter().map(|z| recording(&[*z])).collect();
        let s = &param_stats(&rs)[0];
        assert_eq!((s.n, s.covered, s.covered_wide), (10, 6, 9));
        assert!((s.sum_z2 - 14.5).abs() < 1e-12);
        assert_eq!(s.band, binomial_band(10, 0.6827));
        assert_eq!(s.band_wide, binomial_band(10, 0.95));
        assert!((s.median_abs_rel_error - 0.05).abs() < 1e-12);
    }

    /// The page of six recordings: a shoulder-free truth fitted with a shoulder (scored, its
    /// shortfall 0.3 nats counted), shoulder truths fitted without (not scored, in the confusion
    /// matrix; a shortfall counted only where the fit priced the truth in the true model, one of
    /// them 18 nats short), a failure with its reason and a recording not yet fitted.
    #[test]
    fn markdown_counts_shortfalls_confusion_and_missing_fits() {
        let c = |s: &str| s.parse::<Candidate>().ok();
        let mut free = recording(&[0.5]);
        free.id = "free".into();
        free.true_model = c("blade2dof");
        free.chosen = c("blade2dof+shoulder");
        free.shortfall_nats = Some(0.3);
        free.ridge_nats = Some(2.2);
        let mut shoulder = recording(&[]);
        shoulder.id = "shoulder".into();
        shoulder.true_model = c("blade2dof+shoulder");
        shoulder.shortfall_nats = priced_shortfall(&shoulder, Some(5.0), false);
        assert_eq!(
            shoulder.shortfall_nats, None,
            "priced in the chosen blade2dof"
        );
        shoulder.true_model_delta_tic = Some(1.2);
        let mut priced = shoulder.clone();
        priced.id = "priced".into();
        priced.shortfall_nats = priced_shortfall(&priced, Some(-0.4), true);
        priced.true_model_delta_tic = Some(7.5);
        priced.true_model_k_tr = Some((6, 1.5));
        assert_eq!(priced.shortfall_nats, Some(-0.4), "priced in its own model");
        let mut failed = recording(&[]);
        failed.id = "broken".into();
        failed.state = "failed".into();
        failed.reason = "simulation failed".into();
        failed.chosen = None;
        let mut missing = failed.clone();
        missing.id = "later".into();
        missing.state = "missing".into();
        let mut short = priced.clone();
        short.id = "short".into();
        short.shortfall_nats = Some(18.0);
        short.true_model_delta_tic = Some(1.0);
        let recordings = vec![free, shoulder, priced, short, failed, missing];
        let cal = Calibration {
            name: "t".into(),
            campaign: PathBuf::from("t.toml"),
            overall: param_stats(recordings.iter().filter(|r| r.model_contains_truth())),
            by_model: Vec::new(),
            recordings,
        };
        assert_eq!(
            cal.shortfalls().0,
            3,
            "the shoulder truth fitted without one is priced only in its own model"
        );
        assert_eq!(cal.shortfalls().1, 2);
        let md = to_markdown(&cal, Some("notes here"), "wiperlab campaign collect t.toml");
        assert!(md.contains("notes here") && md.contains("`wiperlab campaign collect t.toml`"));
        assert!(
            md.contains("4 fitted, 1 failed, 1 without a result"),
            "{md}"
        );
        assert!(md.contains("2 of 3 fits"), "{md}");
        // Its segment to the truth crosses a 2.2-nat ridge: another basin.
        assert_eq!(cal.shortfall_ridges(), (1, 1));
        assert!(
            md.contains("Of the 1 short fits whose result has the segment")
                && md.contains("1 have a ridge"),
            "{md}"
        );
        assert!(md.contains("| blade2dof | 0 | 1 |"), "{md}");
        assert!(md.contains("| blade2dof+shoulder | 3 | 0 |"), "{md}");
        // The one ratio (the short fit left out): D = 0.4 against tr/2 = 0.75, below
        // (1.5/6)·χ²(6)'s 95 % point/2 = 1.57.
        assert_eq!(cal.truth_ratios(), (1, 0.4, 0.75, 3.0, 0));
        assert!(md.contains("## Likelihood ratio at the truth"), "{md}");
        // Four wrong choices: the shoulder-free truth's shoulder (no TIC known), two shoulder
        // truths not distinguishable (1.2, 1.0), one chosen against by 7.5.
        assert_eq!(cal.wrong_choices().0, 4);
        assert_eq!(cal.wrong_choices().1, 2);
        assert!(
            md.contains("4 fits chose another model than the true one; 2 of them")
                && md.contains("by a TIC of up to 7.50"),
            "{md}"
        );
        assert!(md.contains("- broken failed: simulation failed"), "{md}");
        assert!(
            md.contains("- 1 not fitted (or still running): later"),
            "{md}"
        );
        assert!(md.contains("| A | 1 | 1 |"), "{md}");
        assert!(
            !md.contains("Friction law over"),
            "no law section without law scores"
        );
    }

    /// The law section groups by departure: a viscous recording found within 3 % with a failed
    /// test and an invented shoulder, one not found though its envelope leaves 2 % open (both
    /// determined); a recording of the model itself, found, whose envelope leaves 5 % open.
    #[test]
    fn the_law_section_scores_curves_by_departure() {
        use super::super::law::LawScore;
        let c = |s: &str| s.parse::<Candidate>().ok();
        let law = |rms, band, envelope, open| {
            Some(LawScore {
                rms_rel_diff: rms,
                within_band: Some(band),
                within_envelope: Some(envelope),
                open_rel: Some(open),
            })
        };
        let mut a = recording(&[]);
        a.true_model = c("blade2dof");
        a.chosen = c("blade2dof+shoulder");
        a.departure = Some("viscous".into());
        a.law = law(0.02, 0.5, 1.0, 0.01);
        a.gof_p = Some(0.001);
        let mut b = a.clone();
        b.chosen = c("blade2dof");
        b.law = law(0.08, 0.0, 0.0, 0.02);
        b.gof_p = Some(0.4);
        let mut own = recording(&[]);
        own.true_model = c("blade2dof");
        own.law = law(0.004, 1.0, 1.0, 0.05);
        let recordings = vec![a, b, own];
        let cal = unscored(recordings);
        let md = to_markdown(&cal, None, "x");
        assert!(
            md.contains(
                "| viscous | 2 | 2 | 1 | 2 | 1 | 5.0 % | 8.0 % | 25.0 % | 50.0 % | 1 | 1 |"
            ),
            "{md}"
        );
        assert!(
            md.contains("| none | 1 | 1 | 1 | 0 | 0 | 0.4 % | 0.4 % | 100.0 % | 100.0 % | 0 | 0 |"),
            "{md}"
        );
    }

    #[test]
    fn a_shoulder_contains_a_shoulder_free_truth_not_the_reverse() {
        let c = |s: &str| s.parse::<Candidate>().unwrap();
        assert!(contains(c("blade2dof+shoulder"), c("blade2dof")));
        assert!(contains(c("blade2dof"), c("blade2dof")));
        assert!(!contains(c("blade2dof"), c("blade2dof+shoulder")));
        assert!(!contains(c("blade2dof"), c("head1dof")));
        assert!(!contains(c("head1dof"), c("blade2dof")));
    }

    /// A truth that names no law (a campaign's `/model`) is the same model as a fit of it with any
    /// law of `[fit] laws`; a truth that names one is matched by that law only.
    #[test]
    fn a_truth_without_a_law_is_matched_by_every_law_of_its_model() {
        let c = |s: &str| s.parse::<Candidate>().unwrap();
        assert!(same_model(c("blade2dof@exponential"), c("blade2dof")));
        assert!(same_model(c("blade2dof@stribeck"), c("blade2dof")));
        assert!(!same_model(
            c("blade2dof+shoulder@exponential"),
            c("blade2dof")
        ));
        assert!(contains(
            c("blade2dof+shoulder@exponential"),
            c("blade2dof")
        ));
        assert!(!contains(c("head1dof@exponential"), c("blade2dof")));
        assert!(same_model(
            c("blade2dof@exponential_viscous"),
            c("blade2dof@exponential_viscous")
        ));
        assert!(!same_model(
            c("blade2dof@exponential"),
            c("blade2dof@exponential_viscous")
        ));
        assert!(!contains(
            c("blade2dof+shoulder@exponential"),
            c("blade2dof@exponential_viscous")
        ));
    }
}
