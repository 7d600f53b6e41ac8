//! Model-selection stage: which candidate the result reports, and why, in numbers.

use super::features::BandSpec;
use super::problem::FAILED_COST;
use super::result::ModelTrial;
use super::search::CandidateFit;
use std::sync::atomic::Ordering;

/// Akaike's information criterion with the cost read as −2 ln L (a χ² on the cost's scales):
/// `AIC = cost + 2k` for `k` freed parameters (Akaike 1974, IEEE TAC 19:716).
pub fn aic(cost: f64, k: usize) -> f64 {
    cost + 2.0 * k as f64
}

/// The outcome of model selection: the chosen candidate's index and every candidate's trial.
pub(super) struct Selection {
    pub(super) chosen: usize,
    pub(super) trials: Vec<ModelTrial>,
}

/// Chooses by AIC among the candidates that produced a model and can produce every band (the
/// neck/lip model imposes a low band from the head track, so its cost there proves nothing); if
/// none can, among all. `listed`: the job named its candidates (else the smallest capable model
/// was the only one).
pub(super) fn choose(fits: &[CandidateFit], bands: &[BandSpec], listed: bool) -> Selection {
    let aics: Vec<f64> = fits
        .iter()
        .map(|f| {
            if f.cost < FAILED_COST {
                aic(f.cost, f.free.len())
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let capable: Vec<bool> = fits
        .iter()
        .map(|f| f.candidate.cannot_produce(bands).is_none())
        .collect();
    let any_capable = capable.contains(&true);
    let scores: Vec<f64> = (0..fits.len())
        .map(|i| {
            if capable[i] || !any_capable {
                aics[i]
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let chosen = (0..fits.len())
        .min_by(|&a, &b| scores[a].total_cmp(&scores[b]))
        .unwrap_or(0);
    let scored = Scored {
        aics: &aics,
        scores: &scores,
        chosen,
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
            reason: scored.reason(fits, i, bands, listed),
        })
        .collect();
    Selection { chosen, trials }
}

/// The candidates' criteria, for the reasons.
struct Scored<'a> {
    aics: &'a [f64],
    /// AIC where the candidate can be chosen, else infinity.
    scores: &'a [f64],
    chosen: usize,
}

impl Scored<'_> {
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
        if i == self.chosen {
            let next = (0..fits.len())
                .filter(|&j| j != self.chosen)
                .map(|j| self.scores[j])
                .fold(f64::INFINITY, f64::min);
            return if next.is_finite() {
                format!(
                    "lowest AIC = cost + 2k = {:.2} (k = {k}); next best {next:.2}",
                    self.scores[i]
                )
            } else {
                format!(
                    "AIC = cost + 2k = {:.2} (k = {k}); the only candidate that produced every band",
                    self.scores[i]
                )
            };
        }
        let mut r = format!(
            "AIC {:.2} (k = {k}), {:+.2} against the chosen model",
            self.aics[i],
            self.aics[i] - self.aics[self.chosen]
        );
        if let Some(why) = fits[i].candidate.cannot_produce(bands) {
            r.push_str(&format!("; {why}"));
        }
        r
    }
}
