//! The friction law scored as a curve: for each fitted recording whose result knows the true law,
//! how far the fitted μ_d(v) lies from the true one over the slip speeds the fitted motion covers
//! (the result's `[friction_curve]`, [`crate::model::friction_curve`]) and whether the fit's ±1σ
//! band holds it. This, not A, B, C alone, is what a recording made by a law outside the fitted
//! family (a viscous term, a Stribeck exponent) or under a departure the model lacks (coloured or
//! smoothed tracking noise, a distorted drive) can be scored by. Grouped by the truth file's
//! `/departure` label ("none" for a recording made by the fitted model itself).

use super::calibrate::{Calibration, RecordingScore, pct, quantile};
use crate::fit::result::FitResult;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// The rms relative difference from the true curve under which the fitted law counts as found.
pub const LAW_TOLERANCE: f64 = 0.03;

/// The fitted law of one recording against its truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawScore {
    /// Root mean square of (μ_d − μ_d,true)/μ_d,true over the measured slip speeds.
    pub rms_rel_diff: f64,
    /// Share of the measured speeds where the true μ_d lies within the fitted 68 % band.
    pub within_band: Option<f64>,
    /// Share where it lies within the envelope of the models the recording does not distinguish
    /// (the band where there are none).
    pub within_envelope: Option<f64>,
    /// How much of μ_d the envelope (or band) leaves open: its median half-width relative to the
    /// fitted μ_d ([`crate::model::friction_curve::FrictionCurve::open_rel_half_width`]).
    pub open_rel: Option<f64>,
}

impl LawScore {
    /// The score of `result`'s friction curve; `None` without a true law.
    pub fn of(result: &FitResult) -> Option<LawScore> {
        let c = result.friction_curve.as_ref()?;
        Some(LawScore {
            rms_rel_diff: c.rms_rel_diff_to_truth?,
            within_band: c.truth_within_band,
            within_envelope: c.truth_within_envelope.or(c.truth_within_band),
            open_rel: c.open_rel_half_width(),
        })
    }

    /// Whether the recording determines the law to [`LAW_TOLERANCE`]: the envelope (or band)
    /// leaves at most that much of μ_d open.
    pub fn determined(&self) -> bool {
        self.open_rel.is_some_and(|o| o <= LAW_TOLERANCE)
    }

    /// Whether the fitted law lies within [`LAW_TOLERANCE`] of the true one.
    pub fn found(&self) -> bool {
        self.rms_rel_diff < LAW_TOLERANCE
    }
}

/// The law section of the calibration table: per departure, the fitted recordings, how many find
/// the law within [`LAW_TOLERANCE`], how many the recording determines to that tolerance and how
/// many of those find it, the median and largest rms difference, the median share of speeds
/// inside the band and the envelope, shoulders chosen for shoulder-free truths, and failed
/// goodness-of-fit tests. Nothing when no recording has a law score.
pub fn law_section(md: &mut String, c: &Calibration) {
    // The fitted recordings of each departure: one row each.
    let mut groups: BTreeMap<&str, Vec<&RecordingScore>> = BTreeMap::new();
    for r in c.done() {
        let key = r.departure.as_deref().unwrap_or("none");
        groups.entry(key).or_default().push(r);
    }
    if !c.recordings.iter().any(|r| r.law.is_some()) {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Friction law over the measured slip speeds\n\n\
         The fitted μ_d(v) against the true law over the 10th–90th percentile of the fitted motion's \
         slip speeds (the result's `[friction_curve]`), by the departure the recording was made with \
         (none: the fitted model itself). Found: rms relative difference below {}. Band: the share \
         of the range's speeds where the true μ_d lies inside the fitted 68 % band (±1σ, widened \
         to the points the search evaluated within μ_d's profile rise limit). \
         Envelope: inside that band or the bands of the models the recording does not distinguish \
         from the chosen one (the band where there are none). Determined: the envelope leaves at \
         most {} of μ_d open (its median half-width relative to the fitted μ_d); a recording that \
         determines the law should find it. \
         Invented shoulder: a shoulder chosen for a blade without one. Misfit: the goodness-of-fit \
         test failed (p ≤ 0.01).\n",
        pct(LAW_TOLERANCE),
        pct(LAW_TOLERANCE)
    );
    let _ = writeln!(
        md,
        "| departure | fitted | law scored | found | determined | found where determined | median rms difference | largest | median share in band | median share in envelope | invented shoulder | misfit |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, fitted) in &groups {
        let scored: Vec<LawScore> = fitted.iter().filter_map(|r| r.law).collect();
        let rms: Vec<f64> = scored.iter().map(|s| s.rms_rel_diff).collect();
        let found = scored.iter().filter(|s| s.found()).count();
        let determined = scored.iter().filter(|s| s.determined()).count();
        let found_determined = (scored.iter())
            .filter(|s| s.determined() && s.found())
            .count();
        let largest = rms.iter().copied().fold(f64::NAN, f64::max);
        let band: Vec<f64> = scored.iter().filter_map(|s| s.within_band).collect();
        let envelope: Vec<f64> = scored.iter().filter_map(|s| s.within_envelope).collect();
        let invented = fitted
            .iter()
            .filter(|r| {
                r.true_model.is_some_and(|t| !t.shoulder) && r.chosen.is_some_and(|c| c.shoulder)
            })
            .count();
        let misfit = fitted
            .iter()
            .filter(|r| {
                r.gof_p
                    .is_some_and(|p| p <= crate::likelihood::GOODNESS_OF_FIT_LEVEL)
            })
            .count();
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {found} | {determined} | {found_determined} | {} | {} | {} | {} | {invented} | {misfit} |",
            fitted.len(),
            scored.len(),
            pct(quantile(&rms, 0.5)),
            pct(largest),
            pct(quantile(&band, 0.5)),
            pct(quantile(&envelope, 0.5)),
        );
    }
}
