//! Model-selection stage: which candidate the result reports, and why, in numbers.
//!
//! With a recording, candidates are compared in likelihood units ([`crate::search::evidence`]): Takeuchi's
//! `TIC = 2·tr(F⁺V) + 2·NLL` chooses ([`Evidence::tic`]), the AIC of a likelihood that is composite
//! and does not describe the ordinates' spread (its calibrated penalty `tr(F⁺V)` is a fraction of
//! `k` on the shipped recording, where Akaike's `2k` would overcharge each parameter). Candidates
//! within [`INDISTINGUISHABLE_TIC`] of the lowest TIC are not distinguishable by the recording: the
//! one with the fewest freed parameters among them is reported, and its reason and a warning say
//! so. Akaike's AIC, Schwarz's BIC and, for nested candidates, Wilks' likelihood-ratio test are
//! reported beside it. A target job has no likelihood (its targets carry no noise); it compares
//! `cost + 2k` ([`aic`]).

use super::features::BandSpec;
use super::result::{ModelTrial, RatioTest, TrialEvidence};
use super::warning::FitWarning;
use crate::job::Candidate;
use crate::likelihood::{self, Evidence};
use crate::search::FAILED_COST;
use crate::search::strategy::CandidateFit;
use std::sync::atomic::Ordering;

/// Akaike's information criterion with the cost read as −2 ln L (a χ² on the cost's scales):
/// `AIC = cost + 2k` for `k` freed parameters (Akaike 1974, IEEE TAC 19:716). Used for target
/// jobs, which have no likelihood.
pub fn aic(cost: f64, k: usize) -> f64 {
    cost + 2.0 * k as f64
}

/// Candidates whose TIC lies within 2 of the lowest are not distinguishable by the recording:
/// a difference of 2 in an information criterion is "substantial support" for both (Burnham &
/// Anderson, *Model Selection and Multimodel Inference*, 2nd ed. 2002, §2.6), and the simpler
/// model is reported.
pub const INDISTINGUISHABLE_TIC: f64 = 2.0;

/// The outcome of model selection: the chosen candidate's index and every candidate's trial.
pub(super) struct Selection {
    pub(super) chosen: usize,
    pub(super) trials: Vec<ModelTrial>,
}

/// Each candidate's evidence, when every candidate that produced a model has one (else none: the
/// comparison falls back to the cost).
fn evidences(fits: &[CandidateFit]) -> Option<Vec<Option<Evidence>>> {
    let e: Vec<Option<Evidence>> = fits
        .iter()
        .map(|f| {
            f.evidence
                .as_ref()
                .ok()
                .filter(|_| f.cost < FAILED_COST)
                .map(|p| p.evidence(f.free.len()))
        })
        .collect();
    let complete = fits
        .iter()
        .zip(&e)
        .all(|(f, e)| e.is_some() || f.cost >= FAILED_COST);
    (complete && e.iter().any(Option::is_some)).then_some(e)
}

/// Chooses by TIC (target jobs: `cost + 2k`) among the candidates that produced a model and can be compared: with the
/// recording's likelihood, every candidate but one that imposes a band from the head track (the
/// neck/lip model's low band, whose fit there proves nothing), since a model without a mode a band
/// needs is judged by how well it explains that band (on a head-only recording the high band holds
/// no neck–lip line, and the head model is the right answer); without a likelihood, the candidates
/// that can produce every band. If none qualifies, among all. `listed`: the job named its candidates (else the smallest capable model
/// was the only one). `spreads`: each candidate's cost spread between solver tolerances where the
/// integrator does not resolve its optimum, nats (0 where it does or was not probed; empty: all
/// 0), which widens the margin of "not distinguishable" ([`margin`]).
pub(super) fn choose(
    fits: &[CandidateFit],
    bands: &[BandSpec],
    listed: bool,
    spreads: &[f64],
) -> Selection {
    let evidence = evidences(fits);
    let (crit, scores) = criteria(fits, bands, evidence.as_deref());
    let ks: Vec<usize> = fits.iter().map(|f| f.free.len()).collect();
    let chosen = simplest_near_best(&scores, &ks, evidence.is_some(), spreads);
    let scored = Scored {
        crit: &crit,
        scores: &scores,
        chosen,
        evidence: evidence.as_deref(),
        spreads,
    };
    let trials = fits
        .iter()
        .enumerate()
        .map(|(i, f)| ModelTrial {
            model: f.candidate,
            parameters: f.free.iter().map(|p| p.name).collect(),
            cost: f.cost,
            wall_time_s: f.wall_time_s,
            model_evaluations: f.problem.evaluations.load(Ordering::Relaxed),
            failed_evaluations: super::failures(&f.problem).0,
            chosen: i == chosen,
            reason: match &f.search_note {
                Some(note) => format!("{}; {note}", scored.reason(fits, i, bands, listed)),
                None => scored.reason(fits, i, bands, listed),
            },
            not_distinguishable: scored.not_distinguishable(i),
            evidence: scored.trial_evidence(fits, i),
            friction: Some(f.problem.params_at(&f.best_u).friction),
        })
        .collect();
    Selection { chosen, trials }
}

/// The TIC gap within which candidates `i` and `j` are not distinguishable:
/// [`INDISTINGUISHABLE_TIC`], widened by twice the cost spreads between solver tolerances of
/// either optimum where the integrator does not resolve it (`spreads`, nats; a cost known only to
/// within its spread moves the TIC by twice that, and a gap the integrator does not resolve says
/// nothing about the recording).
pub(super) fn margin(spreads: &[f64], i: usize, j: usize) -> f64 {
    INDISTINGUISHABLE_TIC + 2.0 * (spread(spreads, i) + spread(spreads, j))
}

/// Candidate `k`'s unresolved cost spread in `spreads` (0 beyond its end), nats.
fn spread(spreads: &[f64], k: usize) -> f64 {
    spreads.get(k).copied().unwrap_or(0.0)
}

/// The candidate [`choose`] reports from `scores` (TIC, +∞ where it cannot be chosen) and `ks`
/// (freed parameters): the one with the fewest parameters among those within the [`margin`] of
/// the lowest score (the lower score between equals), or the lowest when the scores are not in
/// likelihood units (`likelihood` false).
fn simplest_near_best(scores: &[f64], ks: &[usize], likelihood: bool, spreads: &[f64]) -> usize {
    let best = (0..scores.len())
        .min_by(|&a, &b| scores[a].total_cmp(&scores[b]))
        .unwrap_or(0);
    let near = |i: usize| {
        likelihood && scores[i].is_finite() && scores[i] - scores[best] <= margin(spreads, i, best)
    };
    (0..scores.len())
        .filter(|&i| near(i))
        .min_by(|&a, &b| ks[a].cmp(&ks[b]).then(scores[a].total_cmp(&scores[b])))
        .unwrap_or(best)
}

/// How far each candidate's score (the TIC [`choose`] chooses by) lies above the lowest, as
/// the fits stand: 0 for the chosen, +∞ for one that cannot be chosen (it imposes a band, or has
/// no AIC).
pub(super) fn score_gaps(fits: &[CandidateFit], bands: &[BandSpec]) -> Vec<f64> {
    let evidence = evidences(fits);
    let (_, scores) = criteria(fits, bands, evidence.as_deref());
    let best = scores.iter().copied().fold(f64::INFINITY, f64::min);
    scores
        .iter()
        .map(|&s| if s == best { 0.0 } else { s - best })
        .collect()
}

/// Every candidate's criterion (TIC with a likelihood, else `cost + 2k`), and its score: the
/// criterion where [`choose`] may choose it, else +∞.
fn criteria(
    fits: &[CandidateFit],
    bands: &[BandSpec],
    evidence: Option<&[Option<Evidence>]>,
) -> (Vec<f64>, Vec<f64>) {
    let crit: Vec<f64> = fits
        .iter()
        .enumerate()
        .map(|(i, f)| match evidence {
            Some(e) => e[i].map_or(f64::INFINITY, |e| e.tic()),
            None if f.cost < FAILED_COST => aic(f.cost, f.free.len()),
            None => f64::INFINITY,
        })
        .collect();
    let capable: Vec<bool> = fits
        .iter()
        .map(|f| match evidence {
            Some(_) => !f.candidate.imposes_a_band(bands),
            None => f.candidate.cannot_produce(bands).is_none(),
        })
        .collect();
    let any_capable = capable.contains(&true);
    let scores: Vec<f64> = (0..fits.len())
        .map(|i| {
            if capable[i] || !any_capable {
                crit[i]
            } else {
                f64::INFINITY
            }
        })
        .collect();
    (crit, scores)
}

/// The candidates' criteria, for the reasons.
struct Scored<'a> {
    /// Every candidate's criterion: TIC with a likelihood, else `cost + 2k`.
    crit: &'a [f64],
    /// The criterion where the candidate can be chosen, else infinity.
    scores: &'a [f64],
    chosen: usize,
    /// Every candidate's evidence, when the comparison is in likelihood units.
    evidence: Option<&'a [Option<Evidence>]>,
    /// Unresolved cost spreads, nats ([`choose`]).
    spreads: &'a [f64],
}

impl Scored<'_> {
    fn of(&self, i: usize) -> Option<Evidence> {
        self.evidence.and_then(|e| e[i])
    }

    /// The likelihood-ratio test of candidate `i` against the first candidate it nests
    /// ([`Candidate::extends`]: `X` for `X+shoulder`, `X@exponential` for
    /// `X@exponential_viscous`), when both have evidence.
    fn ratio_test(&self, fits: &[CandidateFit], i: usize) -> Option<RatioTest> {
        let c = fits[i].candidate;
        let j = fits.iter().position(|f| c.extends(&f.candidate))?;
        let t = likelihood::likelihood_ratio_test(&self.of(j)?, &self.of(i)?).ok()?;
        Some(RatioTest {
            against: fits[j].candidate,
            statistic: t.statistic,
            df: t.df,
            p_value: t.p_value,
        })
    }

    fn trial_evidence(&self, fits: &[CandidateFit], i: usize) -> Option<TrialEvidence> {
        let e = self.of(i)?;
        let parts = fits[i].evidence.as_ref().ok()?;
        let best = self.of(self.chosen)?;
        Some(TrialEvidence {
            log_likelihood_nats: e.log_likelihood(),
            spectral_nll_nats: parts.spectral_nats.clone(),
            time_nll_nats: parts.time_nats,
            residual_rms_m: parts.residual_rms_m,
            n_effective: e.n_effective,
            effective_parameters: e.effective_parameters,
            tic: Some(e.tic()),
            delta_tic: Some(e.tic() - best.tic()),
            aic: e.aic(),
            bic: e.bic(),
            delta_aic: e.aic() - best.aic(),
            delta_bic: e.bic() - best.bic(),
            lrt: self.ratio_test(fits, i),
        })
    }

    /// Whether candidate `i`, another than the chosen one, has its TIC within the margin of the
    /// chosen one's.
    fn not_distinguishable(&self, i: usize) -> bool {
        i != self.chosen
            && self.evidence.is_some()
            && (self.crit[i] - self.crit[self.chosen]).abs() <= margin(self.spreads, i, self.chosen)
            && self.scores[i].is_finite()
    }

    /// The criterion's name in the reasons.
    fn criterion(&self) -> &'static str {
        if self.evidence.is_some() {
            "TIC = 2·tr(F⁺V) + 2·NLL"
        } else {
            "AIC = cost + 2k"
        }
    }

    /// Why candidate `i` was (not) chosen, with its numbers.
    fn reason(&self, fits: &[CandidateFit], i: usize, bands: &[BandSpec], listed: bool) -> String {
        let k = fits[i].free.len();
        if fits.len() == 1 {
            return if listed {
                "the only model the job lists".into()
            } else {
                format!(
                    "the smallest model that can produce the job's bands ({})",
                    bands
                        .iter()
                        .map(|b| format!("{} {:.0}–{:.0} Hz", b.name, b.range_hz[0], b.range_hz[1]))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            };
        }
        let lnl = self
            .of(i)
            .map(|e| format!("ln L = {:.2} nats, ", e.log_likelihood()))
            .unwrap_or_default();
        if i == self.chosen {
            let runner = (0..fits.len())
                .filter(|&j| j != self.chosen)
                .min_by(|&a, &b| self.scores[a].total_cmp(&self.scores[b]));
            let next = runner.map_or(f64::INFINITY, |j| self.scores[j]);
            let lrt = self
                .ratio_test(fits, i)
                .map(|t| {
                    format!(
                        "; likelihood-ratio test against {}: 2Δln L = {:.2} on {} df, p = {:.3}",
                        t.against, t.statistic, t.df, t.p_value
                    )
                })
                .unwrap_or_default();
            if let Some(lowest) = runner.filter(|&j| self.scores[j] < self.scores[i]) {
                let m = margin(self.spreads, i, lowest);
                let widened = if m > INDISTINGUISHABLE_TIC {
                    " (2 widened by twice the optima's cost spreads between solver tolerances, \
                     which the integrator does not resolve)"
                } else {
                    ""
                };
                return format!(
                    "{} = {:.2} ({lnl}k = {k}), {:.2} above the lowest, within {m:.2}{widened}: \
                     the candidates there are not distinguishable by this recording, and this one \
                     has the fewest parameters{lrt}",
                    self.criterion(),
                    self.scores[i],
                    self.scores[i] - self.scores[lowest]
                );
            }
            return if next.is_finite() {
                format!(
                    "lowest {} = {:.2} ({lnl}k = {k}); next best {next:.2}{lrt}",
                    self.criterion(),
                    self.scores[i]
                )
            } else {
                format!(
                    "{} = {:.2} ({lnl}k = {k}); the only candidate that produced every band",
                    self.criterion(),
                    self.scores[i]
                )
            };
        }
        let penalty = self
            .of(i)
            .and_then(|e| e.effective_parameters)
            .map(|p| format!(", tr(F⁺V) = {p:.2}"))
            .unwrap_or_default();
        let name = self.criterion().split(' ').next().unwrap_or("AIC");
        let mut r = format!(
            "{name} {:.2} ({lnl}k = {k}{penalty}), {:+.2} against the chosen model",
            self.crit[i],
            self.crit[i] - self.crit[self.chosen]
        );
        let m = margin(self.spreads, i, self.chosen);
        if self.not_distinguishable(i) {
            let why = why_reported(fits[self.chosen].free.len(), k);
            r.push_str(&format!(
                "; not distinguishable by this recording (within {m:.2} of the chosen model's \
                 TIC{why})"
            ));
        }
        if let (Some(e), Some(best)) = (self.of(i), self.of(self.chosen)) {
            r.push_str(&format!("; ΔBIC {:+.2}", e.bic() - best.bic()));
        }
        if let Some(t) = self.ratio_test(fits, i) {
            r.push_str(&format!(
                "; likelihood-ratio test against {}: 2Δln L = {:.2} on {} df, p = {:.3} ({})",
                t.against,
                t.statistic,
                t.df,
                t.p_value,
                if t.p_value < 0.05 {
                    "a gain beyond chance, but not worth its parameters by TIC"
                } else {
                    "no gain beyond chance from the extra parameters"
                }
            ));
        }
        if let Some(why) = fits[i].candidate.cannot_produce(bands) {
            r.push_str(&format!("; {why}"));
        }
        r
    }
}

/// The warning of a choice that a margin widened by unresolved cost spreads ([`margin`]) moved
/// from candidate `was` to `selection.chosen`, which has fewer parameters: `was`'s TIC is lower,
/// by less than the integrator resolves. `None` without both TICs.
pub(super) fn moved_choice(
    selection: &Selection,
    was: usize,
    spreads: &[f64],
) -> Option<FitWarning> {
    let tic = |i: usize| {
        let t: &ModelTrial = selection.trials.get(i)?;
        t.evidence.as_ref().and_then(|e| e.tic)
    };
    let now = selection.chosen;
    Some(FitWarning::ChoiceUnresolved {
        chosen: selection.trials[now].model,
        runner_up: selection.trials.get(was)?.model,
        tic_gap: tic(was)? - tic(now)?,
        spread_nats: spread(spreads, now) + spread(spreads, was),
    })
}

/// Warnings when a parameter moves between the chosen candidate and another candidate that can
/// produce every band by more than the larger of their 1σ (both from the likelihood's Fisher
/// information): the parameter is then absorbing structure that one model has and the other has
/// not (e.g. a friction law bent to stand in for a missing shoulder), and its value depends on the
/// model more than on the data. Only candidates with the chosen one's friction law are compared.
pub(super) fn absorbing_warnings(
    fits: &[CandidateFit],
    chosen: usize,
    bands: &[BandSpec],
) -> Vec<super::FitWarning> {
    let c = &fits[chosen];
    if c.evidence.is_err() {
        return Vec::new();
    }
    let mut w = Vec::new();
    for (j, o) in fits.iter().enumerate() {
        // Another law's coefficients are other quantities (B against v_s, C beside D|v|).
        if j == chosen
            || o.candidate.law != c.candidate.law
            || o.evidence.is_err()
            || o.cost >= FAILED_COST
            || o.candidate.cannot_produce(bands).is_some()
        {
            continue;
        }
        for (i, fp) in c.free.iter().enumerate() {
            let Some(m) = o.free.iter().position(|f| f.name == fp.name) else {
                continue;
            };
            let (vc, vo) = (fp.value(c.best_u[i]), o.free[m].value(o.best_u[m]));
            let sc = c.sigma_u[i] * fp.slope(c.best_u[i]);
            let so = o.sigma_u[m] * o.free[m].slope(o.best_u[m]);
            let s = sc.max(so);
            if s.is_finite() && (vc - vo).abs() > s {
                w.push(super::FitWarning::AbsorbsModelStructure {
                    parameter: fp.name,
                    chosen: c.candidate,
                    value: vc,
                    other: o.candidate,
                    other_value: vo,
                    sigmas: (vc - vo).abs() / s,
                });
            }
        }
    }
    w
}

/// The warning of a candidate that adds structure to another listed one (`X+shoulder` over `X`)
/// and is chosen on a fit that fails the goodness-of-fit test (the caller's condition): the
/// structure may only absorb what the model cannot explain (coloured tracking noise, a friction
/// law the model lacks), so the choice is said, never silent. `None` when the chosen candidate
/// adds no structure or its nested candidate was not listed.
pub(super) fn chosen_on_misfit(trials: &[ModelTrial]) -> Option<FitWarning> {
    let outline: Vec<(Candidate, bool, Option<f64>)> = trials
        .iter()
        .map(|t| {
            let delta = t.evidence.as_ref().and_then(|e| e.delta_tic);
            (t.model, t.chosen, delta)
        })
        .collect();
    nested_on_misfit(&outline)
}

/// Why the chosen candidate (`k_chosen` parameters) is reported before one of `k` parameters
/// within the margin of its TIC, as the reason's clause ([`simplest_near_best`]'s order).
fn why_reported(k_chosen: usize, k: usize) -> &'static str {
    match k_chosen.cmp(&k) {
        std::cmp::Ordering::Less => ", which has fewer parameters",
        std::cmp::Ordering::Equal => ", which has as many parameters and the lower TIC",
        std::cmp::Ordering::Greater => "",
    }
}

/// [`chosen_on_misfit`] on each trial's candidate, whether it is chosen and its ΔTIC.
fn nested_on_misfit(trials: &[(Candidate, bool, Option<f64>)]) -> Option<FitWarning> {
    let &(chosen, ..) = trials.iter().find(|t| t.1)?;
    if !chosen.shoulder {
        return None;
    }
    let nested = Candidate {
        shoulder: false,
        ..chosen
    };
    let &(_, _, delta) = trials.iter().find(|t| t.0 == nested)?;
    Some(FitWarning::ChosenOnMisfit {
        chosen,
        nested,
        delta_tic: delta.unwrap_or(f64::NAN),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::blade::ModelKind;

    /// The choice among friction laws: `X@exponential` (k = 4) against `X@exponential_viscous`
    /// (k = 5, D freed). The viscous law contains the exponential one (D = 0), so its NLL is at
    /// most the smaller's; its TIC wins only by more than [`INDISTINGUISHABLE_TIC`]: 1.5 lower is
    /// not distinguishable and the exponential law (fewer parameters) is reported, 2.5 lower
    /// chooses the viscous law. A candidate that cannot be chosen (+∞) never is, and without a
    /// likelihood the lowest score wins whatever its parameters.
    #[test]
    fn a_law_within_the_margin_of_the_best_gives_way_to_the_simpler() {
        let ks = [4, 5];
        assert_eq!(simplest_near_best(&[100.0, 98.5], &ks, true, &[]), 0);
        assert_eq!(simplest_near_best(&[100.0, 98.0], &ks, true, &[]), 0);
        assert_eq!(simplest_near_best(&[100.0, 97.5], &ks, true, &[]), 1);
        assert_eq!(simplest_near_best(&[97.0, 100.0], &ks, true, &[]), 0);
        assert_eq!(simplest_near_best(&[100.0, 98.5], &ks, false, &[]), 1);
        // Stribeck (k = 6) beside them: the two within 2 of the best, the fewest parameters.
        assert_eq!(
            simplest_near_best(&[103.0, 101.5, 100.0], &[4, 5, 6], true, &[]),
            1
        );
        assert_eq!(
            simplest_near_best(&[f64::INFINITY, 101.0, 100.0], &[4, 5, 6], true, &[]),
            1
        );
        // Equal parameter counts: the lower TIC.
        assert_eq!(simplest_near_best(&[100.0, 99.0], &[5, 5], true, &[]), 1);
        // The reasons say which of the two rules reported the chosen one.
        assert_eq!(why_reported(4, 5), ", which has fewer parameters");
        assert_eq!(
            why_reported(4, 4),
            ", which has as many parameters and the lower TIC"
        );
    }

    /// A TIC lead the integrator does not resolve: blade2dof (k = 4) against a shoulder (k = 6)
    /// 3.84 lower. The margin is 2 + 2·(sum of the unresolved cost spreads): resolved optima
    /// (no spread) or a 0.6-nat spread (margin 3.2) leave the shoulder chosen; 1.0 nat (margin
    /// 4.0), on either optimum or split between them, reports blade2dof.
    #[test]
    fn a_lead_within_the_unresolved_spread_gives_way_to_the_simpler() {
        let (scores, ks) = ([100.0, 96.16], [4, 6]);
        assert_eq!(simplest_near_best(&scores, &ks, true, &[]), 1);
        assert_eq!(simplest_near_best(&scores, &ks, true, &[0.0, 0.6]), 1);
        assert_eq!(simplest_near_best(&scores, &ks, true, &[0.0, 1.0]), 0);
        assert_eq!(simplest_near_best(&scores, &ks, true, &[1.0, 0.0]), 0);
        assert_eq!(simplest_near_best(&scores, &ks, true, &[0.5, 0.5]), 0);
        assert!((margin(&[0.0, 1.0], 0, 1) - 4.0).abs() < 1e-12);
        assert_eq!(margin(&[], 0, 1), INDISTINGUISHABLE_TIC);
        // Without a likelihood the lowest score wins whatever the spreads.
        assert_eq!(simplest_near_best(&scores, &ks, false, &[0.0, 5.0]), 1);
    }

    /// A shoulder chosen over its shoulder-free model is said (the caller asks only on a failed
    /// test); a shoulder-free choice or a job without the nested candidate says nothing.
    #[test]
    fn a_shoulder_chosen_on_a_misfit_is_said() {
        let free = Candidate {
            kind: ModelKind::Blade2dof,
            shoulder: false,
            law: None,
        };
        let shoulder = Candidate {
            shoulder: true,
            ..free
        };
        let trials = [(free, false, Some(12.5)), (shoulder, true, Some(0.0))];
        let w = nested_on_misfit(&trials).expect("a warning");
        assert_eq!(
            w,
            FitWarning::ChosenOnMisfit {
                chosen: shoulder,
                nested: free,
                delta_tic: 12.5
            }
        );
        let text = w.to_string();
        assert!(
            text.contains("TIC 12.5 lower") && text.contains("not confirmed"),
            "{text}"
        );
        let free_chosen = [(free, true, Some(0.0)), (shoulder, false, Some(1.0))];
        assert_eq!(nested_on_misfit(&free_chosen), None);
        assert_eq!(nested_on_misfit(&[(shoulder, true, None)]), None);
    }
}
