//! The contact-angle scan ([`crate::job::ContactAngleScan`]): when the chosen model fails its
//! goodness-of-fit test, each `+shoulder` candidate is searched again, once per slice of the
//! contact angle θ_c, by its whole search (local polishes from the smaller model's optimum, the
//! global restarts and their second batch) with θ_c bounded to the slice; the best slice's end,
//! settled in the full box, replaces the candidate's optimum when it is more likely, and the
//! valley polishes of the new choice start from there.
//!
//! A shoulder that the neck touches only at the peaks of its swing stiffens it while
//! |θ| > θ_c, for a fraction of each swing that changes steeply with θ_c: the likelihood's basin is
//! then a few per cent wide in θ_c and in the friction law (docs/model-choice.md, "Shoulder contact"),
//! and the default search over the whole contact-angle range ends where a model without the
//! shoulder bends the law to mimic it. Bounds on θ_c of ±4–10 % around the confusion table's
//! 0.12 rad shoulder let the default search reach the truth's basin, ±17 % did not (docs/validation.md,
//! "Model choice"). The scan covers θ_c from the median to the largest |θ| of the same model's
//! motion without shoulder at its optimum (where a shoulder is crossed at the swing's peaks; a neck
//! resting on its shoulder, θ_c below the median, has a wide basin the default search reaches) in
//! overlapping slices of [`SLICE_LOG_WIDTH`] on the log scale.

use super::interrupt;
use super::strategy::{
    CandidateFit, Confirming, NESTED_WARM_POINTS, Optimised, Reporting, VALLEY_GAIN_NATS, add_note,
    fit_candidate, polish_budget, settle_anew, sorted_abs_theta,
};
use crate::Result;
use crate::job::Candidate;
use crate::job::{ContactAngleScan, LoadedJob};
use crate::likelihood::GoodnessOfFit;
use crate::likelihood::measure::Measurement;
use crate::model::ParamId;
use std::sync::atomic::Ordering;

/// The width of one slice of θ_c on the log scale: 0.2 (±10 % about its centre), the widest
/// bounds with which the search reached the often-crossed shoulder's basin (docs/validation.md, "Model
/// choice": ±4 %, ±5 % and ±10 % did, ±17 % did not).
pub const SLICE_LOG_WIDTH: f64 = 0.2;

/// At most this many slices per candidate: each costs a whole search of it.
pub const MAX_SLICES: usize = 4;

/// The quantiles of |θ| in the smaller model's motion that bound the scan: the median (below it
/// the neck would rest on the shoulder most of the window) and the largest.
const RANGE_QUANTILES: (f64, f64) = (0.5, 1.0);

/// Slices of `[lo, hi]` (rad, `0 < lo < hi`), each [`SLICE_LOG_WIDTH`] wide on the log scale
/// (narrower only when the range is), their centres spread evenly so that neighbours overlap by at
/// least half a slice: `⌈2·span/width⌉ − 1` of them for a range `span` wide (log scale), at most
/// [`MAX_SLICES`] (then they overlap less, or leave gaps). Empty unless `0 < lo < hi < ∞`.
pub fn contact_angle_slices(lo: f64, hi: f64) -> Vec<(f64, f64)> {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return Vec::new();
    }
    let span = (hi / lo).ln();
    if span <= SLICE_LOG_WIDTH {
        return vec![(lo, hi)];
    }
    let n = ((2.0 * span / SLICE_LOG_WIDTH).ceil() as usize - 1).clamp(2, MAX_SLICES);
    let step = (span - SLICE_LOG_WIDTH) / (n - 1) as f64;
    (0..n)
        .map(|k| {
            let a = lo * (step * k as f64).exp();
            let b = if k == n - 1 {
                hi
            } else {
                a * SLICE_LOG_WIDTH.exp()
            };
            (a, b)
        })
        .collect()
}

/// Why the scan runs after the first choice, or `None` when it does not: `setting` the job's,
/// `chosen` the chosen candidate's name, `gof` its goodness-of-fit test (`None` when there is none).
pub(crate) fn scan_reason(
    setting: ContactAngleScan,
    chosen: &str,
    gof: Option<&GoodnessOfFit>,
) -> Option<String> {
    match (setting, gof) {
        (ContactAngleScan::OnMisfit, Some(g)) if !g.fits() => Some(format!(
            "{chosen} failed the goodness-of-fit test, p = {:.3}",
            g.p_value
        )),
        _ => None,
    }
}

/// Scans every `+shoulder` candidate of `fits` whose model without shoulder was fitted too, when the
/// job bounds the shoulder in `[fit.shoulder]`, unless the deferred confirmation found more
/// restarts of it futile (it trails the chosen model by more than its ends' spread + 5 nats:
/// [`CandidateFit::more_restarts_futile`]). `why` goes into each scanned candidate's search
/// note. Returns whether any candidate moved.
pub(crate) fn scan_contact_angle(
    job: &LoadedJob,
    meas: &Measurement,
    fits: &mut [CandidateFit],
    pb: &Option<indicatif::ProgressBar>,
    why: &str,
) -> Result<bool> {
    let mut moved = false;
    if job.job.fit.shoulder.is_none() {
        return Ok(false);
    }
    for i in 0..fits.len() {
        let c = fits[i].candidate;
        let Some(s) = fits
            .iter()
            .position(|f| c.shoulder && !f.candidate.shoulder && c.extends(&f.candidate))
        else {
            continue;
        };
        if interrupt::stop_requested() {
            break;
        }
        if fits[i].more_restarts_futile {
            add_note(
                &mut fits[i].search_note,
                "no contact-angle scan: no more restarts could make it the choice".into(),
            );
            continue;
        }
        let Some((lo, hi)) = scan_range(&fits[s], &fits[i]) else {
            continue;
        };
        let slices = contact_angle_slices(lo, hi);
        let found = search_slices(job, meas, c, &fits[s], &slices, pb)?;
        moved |= keep_if_better(&mut fits[i], found, &slices, pb, why)?;
    }
    Ok(moved)
}

/// The scan's θ_c range: [`RANGE_QUANTILES`] of |θ| in `smaller`'s simulation at its optimum,
/// within `larger`'s contact-angle bounds; `None` when it frees no θ_c or the motion cannot be
/// simulated.
fn scan_range(smaller: &CandidateFit, larger: &CandidateFit) -> Option<(f64, f64)> {
    let fp = larger.free.iter().find(|fp| fp.name == ParamId::ThetaC)?;
    let abs_theta = sorted_abs_theta(smaller)?;
    let q = |p: f64| crate::spectrum::stats::quantile_sorted(&abs_theta, p);
    let (lo, hi) = (
        q(RANGE_QUANTILES.0).max(fp.lower),
        q(RANGE_QUANTILES.1).min(fp.upper),
    );
    (lo < hi).then_some((lo, hi))
}

/// What [`search_slices`] found: the most likely slice fit and what all slices cost.
struct SliceSearch {
    best: Option<CandidateFit>,
    evaluations: usize,
    failures: usize,
    swarm_iters: u64,
    polish_iters: u64,
    wall_time_s: f64,
}

/// The candidate searched once per slice (the job with `[fit.shoulder] theta_c` set to it), one
/// slice after another.
fn search_slices(
    job: &LoadedJob,
    meas: &Measurement,
    candidate: Candidate,
    smaller: &CandidateFit,
    slices: &[(f64, f64)],
    pb: &Option<indicatif::ProgressBar>,
) -> Result<SliceSearch> {
    let mut found = SliceSearch {
        best: None,
        evaluations: 0,
        failures: 0,
        swarm_iters: 0,
        polish_iters: 0,
        wall_time_s: 0.0,
    };
    for &(a, b) in slices {
        if interrupt::stop_requested() {
            break;
        }
        let mut sliced = job.clone();
        if let Some(sb) = sliced.job.fit.shoulder.as_mut() {
            sb.theta_c = [a, b];
        }
        if let Some(pb) = pb {
            // The nested search's local polishes; a global search adds its own length.
            let n = smaller.free.len() + 2;
            pb.inc_length(NESTED_WARM_POINTS * polish_budget(&job.job.fit, n));
        }
        let f = fit_candidate(&sliced, meas, candidate, pb, Some(smaller), Confirming::NOW)?;
        found.evaluations += f.problem.evaluations.load(Ordering::Relaxed);
        found.failures += f.problem.failures.load(Ordering::Relaxed);
        found.swarm_iters += f.swarm_iters;
        found.polish_iters += f.polish_iters;
        found.wall_time_s += f.wall_time_s;
        if found.best.as_ref().is_none_or(|b| f.cost < b.cost) {
            found.best = Some(f);
        }
    }
    Ok(found)
}

/// `f` moved to the best slice fit's end when that is more than [`VALLEY_GAIN_NATS`] more likely
/// than `f`'s optimum: its coordinates mapped into `f`'s box and settled there. The slice fits'
/// model runs, failures and iterations count as `f`'s. Returns whether `f` moved.
fn keep_if_better(
    f: &mut CandidateFit,
    found: SliceSearch,
    slices: &[(f64, f64)],
    pb: &Option<indicatif::ProgressBar>,
    why: &str,
) -> Result<bool> {
    f.problem
        .evaluations
        .fetch_add(found.evaluations, Ordering::Relaxed);
    f.problem
        .failures
        .fetch_add(found.failures, Ordering::Relaxed);
    f.swarm_iters += found.swarm_iters;
    f.polish_iters += found.polish_iters;
    let Some(best) = found.best else {
        return Ok(false);
    };
    let started = std::time::Instant::now();
    let before = f.cost;
    let kept = best.cost < before - VALLEY_GAIN_NATS && !interrupt::stop_requested();
    add_note(
        &mut f.search_note,
        scan_note(why, slices, best.cost, before, kept),
    );
    let wall_time_s = f.wall_time_s + found.wall_time_s;
    if kept {
        let u: Vec<f64> = f
            .free
            .iter()
            .zip(best.free.iter().zip(&best.best_u))
            .map(|(full, (sliced, u))| full.u_of(sliced.value(*u)))
            .collect();
        let reporting = Reporting::continuing(f, pb);
        let found = Optimised {
            cost: f.problem.cost_at(&u),
            u,
            swarm_iters: f.swarm_iters,
            polish_iters: f.polish_iters,
            unconfirmed_ends: None,
        };
        settle_anew(f, found, &reporting, pb)?;
    }
    f.wall_time_s = wall_time_s + started.elapsed().as_secs_f64();
    Ok(kept)
}

/// What the scan did, for the candidate's search note.
fn scan_note(why: &str, slices: &[(f64, f64)], best: f64, before: f64, kept: bool) -> String {
    let (lo, hi) = (slices[0].0, slices[slices.len() - 1].1);
    let head = format!(
        "contact-angle scan ({why}): searched again in {} slices of θ_c from {lo:.4} to {hi:.4} \
         rad (the median to the largest |θ| without shoulder)",
        slices.len()
    );
    if kept {
        format!(
            "{head}; its best end is {:.2} nats more likely ({best:.2} against {before:.2}), kept",
            before - best
        )
    } else {
        format!("{head}; its best end, {best:.2} nats against {before:.2}, not kept")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_cover_the_range_overlapping_by_half_a_slice_or_more() {
        // ln(0.142/0.098) = 0.371: ⌈2·0.371/0.2⌉ − 1 = 3 slices of 0.2, centres 0.0855 apart.
        let s = contact_angle_slices(0.098, 0.142);
        assert_eq!(s.len(), 3);
        assert_eq!(s[0].0, 0.098);
        assert_eq!(s[2].1, 0.142);
        for &(a, b) in &s {
            assert!(((b / a).ln() - SLICE_LOG_WIDTH).abs() < 1e-12, "{a} {b}");
        }
        for w in s.windows(2) {
            let overlap = (w[0].1 / w[1].0).ln();
            assert!(overlap >= 0.5 * SLICE_LOG_WIDTH, "{overlap}");
        }
    }

    #[test]
    fn a_narrow_range_is_one_slice_and_a_wide_one_at_most_the_limit() {
        assert_eq!(contact_angle_slices(0.1, 0.11), vec![(0.1, 0.11)]);
        let wide = contact_angle_slices(0.02, 0.2);
        assert_eq!(wide.len(), MAX_SLICES);
        assert_eq!((wide[0].0, wide[MAX_SLICES - 1].1), (0.02, 0.2));
    }

    #[test]
    fn an_empty_or_reversed_range_has_no_slices() {
        assert!(contact_angle_slices(0.1, 0.1).is_empty());
        assert!(contact_angle_slices(0.1, 0.05).is_empty());
        assert!(contact_angle_slices(0.0, 0.05).is_empty());
        assert!(contact_angle_slices(0.01, f64::INFINITY).is_empty());
    }

    #[test]
    fn the_scan_runs_on_a_failed_test_unless_switched_off() {
        let g = |p_value| GoodnessOfFit {
            excess_nll_nats: 0.0,
            replicate_mean_nats: 0.0,
            replicate_sd_nats: 1.0,
            replicates: 999,
            p_value,
        };
        let (fail, pass) = (g(0.001), g(0.3));
        let on = ContactAngleScan::OnMisfit;
        assert!(scan_reason(on, "blade2dof", Some(&fail)).is_some());
        assert!(scan_reason(on, "blade2dof", Some(&pass)).is_none());
        assert!(scan_reason(on, "blade2dof", None).is_none());
        assert!(scan_reason(ContactAngleScan::Never, "blade2dof", Some(&fail)).is_none());
    }
}
