//! The report page's warnings: the result's own ([`FitWarning`]) and what the page finds itself
//! ([`PageWarning`]), each with a [`Severity`], a one-line headline that says what to do, and the
//! full sentence ([`std::fmt::Display`]) the page folds under it.

use super::html::num;
use crate::fit::warning::{End, LineSource};
use crate::fit::{FitWarning, Severity};
use crate::job::{Candidate, UncertaintyMethod};
use crate::model::ParamId;
use crate::simulate::failure::FailureCause;
use crate::spectrum::harmonics::{LineOrigin, MIN_PROMINENCE};
use std::collections::BTreeMap;
use std::fmt;
use std::path::PathBuf;

/// One warning on the report page.
#[derive(Debug, Clone, PartialEq)]
pub enum PageWarning {
    /// One of the result's own warnings.
    Fit(FitWarning),
    /// A parameter the result marks undetermined that none of its warnings names.
    Undetermined {
        parameter: ParamId,
        std_error: f64,
        lower: f64,
        upper: f64,
    },
    /// Model evaluations over all candidates failed, and the result does not warn about the
    /// chosen model's failures (fewer than a tenth of its evaluations).
    FailedEvaluations {
        failed: usize,
        evaluations: usize,
        first: Option<String>,
    },
    /// Figures the fit writes that are not in the report directory.
    FiguresMissing { dir: PathBuf, files: Vec<String> },
    /// The recording's SHA-256 differs from the one fitted.
    RecordingChanged {
        path: PathBuf,
        sha256_now: String,
        sha256_at_fit: String,
    },
    /// The recording could not be read to hash it.
    CannotHashRecording { reason: String },
}

impl PageWarning {
    /// How much the warning asks of its reader.
    pub fn severity(&self) -> Severity {
        match self {
            PageWarning::Fit(w) => w.severity(),
            PageWarning::FailedEvaluations { .. } => Severity::Information,
            PageWarning::Undetermined { .. }
            | PageWarning::FiguresMissing { .. }
            | PageWarning::RecordingChanged { .. }
            | PageWarning::CannotHashRecording { .. } => Severity::Attention,
        }
    }

    /// One line for the page: what was found and, where the reader should act, what to do.
    pub fn headline(&self) -> String {
        match self {
            PageWarning::Fit(w) => fit_headline(w),
            PageWarning::Undetermined {
                parameter,
                std_error,
                lower,
                upper,
            } => format!(
                "The data leave {parameter} undetermined (1σ {} over a search range [{}, {}]): \
                 read its value with care, or fix it from another measurement.",
                num(*std_error, 3),
                num(*lower, 4),
                num(*upper, 4)
            ),
            PageWarning::FailedEvaluations {
                failed,
                evaluations,
                ..
            } => format!(
                "{failed} of {evaluations} model evaluations over all candidates ({}) failed and \
                 were given the failure cost, fewer than a tenth of the chosen model's: the \
                 search moves away from them.",
                share(*failed, *evaluations)
            ),
            PageWarning::FiguresMissing { files, .. } => format!(
                "Figures missing: {}. Run `wiperlab report --refit` to redraw them.",
                files.join(", ")
            ),
            PageWarning::RecordingChanged { .. } => "The recording has changed since the fit: \
                 refit with `wiperlab report --refit`."
                .into(),
            PageWarning::CannotHashRecording { .. } => "The recording cannot be read, so the page \
                 cannot check that it is the one fitted."
                .into(),
        }
    }

    /// The full sentence, when it says more than [`PageWarning::headline`].
    pub fn details(&self) -> Option<String> {
        match self {
            PageWarning::Fit(FitWarning::Text { .. }) => None,
            other => Some(other.to_string()),
        }
    }
}

impl fmt::Display for PageWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PageWarning::Fit(w) => w.fmt(f),
            PageWarning::Undetermined {
                parameter,
                std_error,
                lower,
                upper,
            } => write!(
                f,
                "the data leave {parameter} undetermined (1σ {} over a search range [{}, {}]); \
                 read its value with care and see the correlations",
                num(*std_error, 3),
                num(*lower, 4),
                num(*upper, 4)
            ),
            PageWarning::FailedEvaluations {
                failed,
                evaluations,
                first,
            } => write!(
                f,
                "{failed} of {evaluations} model evaluations failed and were given the failure \
                 cost; first: {}",
                first.as_deref().unwrap_or("(not recorded)")
            ),
            PageWarning::FiguresMissing { dir, files } => write!(
                f,
                "figures missing from {}: {} (run `wiperlab report --refit` to redraw them)",
                dir.display(),
                files.join(", ")
            ),
            PageWarning::RecordingChanged {
                path,
                sha256_now,
                sha256_at_fit,
            } => write!(
                f,
                "the recording {} has changed since the fit (SHA-256 {sha256_now} now, \
                 {sha256_at_fit} at fit time); refit with `wiperlab report --refit`",
                path.display()
            ),
            PageWarning::CannotHashRecording { reason } => {
                write!(f, "cannot hash the recording: {reason}")
            }
        }
    }
}

/// `n` of `of` as a percentage, e.g. "11 %".
fn share(n: usize, of: usize) -> String {
    if of == 0 {
        return "—".into();
    }
    format!("{:.0} %", 100.0 * n as f64 / of as f64)
}

/// A failure cause in words.
fn cause_words(c: FailureCause) -> &'static str {
    match c {
        FailureCause::ContactLoss => "the lip tip would leave the glass",
        FailureCause::Painleve => "the slip equations have no solution (Painlevé)",
        FailureCause::ModelFault => "a model fault",
        FailureCause::StepBudget => "the integrator ran out of steps",
        FailureCause::NoLine => "a band held no line",
        FailureCause::Other => "another error",
    }
}

/// A line's name at the start of a sentence.
fn line_subject(source: LineSource, band: &str, o: &LineOrigin) -> String {
    let whose = match source {
        LineSource::Recording => "The recording's",
        LineSource::Model => "The model's",
    };
    format!("{whose} line in band '{band}' ({} Hz)", num(o.freq_hz, 4))
}

/// The headline of one of the result's own warnings.
fn fit_headline(w: &FitWarning) -> String {
    use FitWarning::*;
    match w {
        Interrupted => "The fit was interrupted: the values are the best point the search had \
                        reached, without intervals. Run it again to the end."
            .into(),
        NoGoodnessOfFit { .. } => "The goodness-of-fit test could not run, so whether the model \
                                   explains the recording's spectra is not known."
            .into(),
        TruthMoreLikely {
            fit_cost_nats,
            truth_cost_nats,
            ridge_nats,
            model,
        } => truth_more_likely_headline(fit_cost_nats - truth_cost_nats, *ridge_nats, *model),
        Misfit { test, shape, .. } => misfit_headline(test.p_value, shape),
        AbsorbsModelStructure {
            parameter,
            chosen,
            value,
            other,
            other_value,
            sigmas,
        } => absorbs_headline(
            *parameter,
            [(chosen, *value), (other, *other_value)],
            *sigmas,
        ),
        Line {
            band,
            source,
            origin,
            same_harmonic_on_other_side,
        } => line_headline(*source, band, origin, *same_harmonic_on_other_side),
        Undetermined { parameter } => format!(
            "The data do not determine {parameter} (its 1σ spans 10 % or more of its search \
             range): fix it from another measurement or narrow its bounds."
        ),
        TradeOff {
            first,
            second,
            correlation,
        } => trade_off_headline([*first, *second], *correlation),
        OnBound {
            parameter,
            bound,
            value,
        } => on_bound_headline(*parameter, *bound, *value),
        ProfileAtBound {
            parameter, bounds, ..
        } => profile_at_bound_headline(*parameter, bounds),
        ProfileOpen { parameter, end, .. } => format!(
            "{parameter}'s interval does not close at its {end} end within the profile walk: \
             the interval there is a lower limit on the uncertainty."
        ),
        ProfileMoreLikely {
            parameter,
            gain_nats,
            ..
        } => profile_more_likely_headline(*parameter, *gain_nats),
        WidenedInterval {
            parameter,
            method,
            widened,
            ..
        } => widened_headline(*parameter, method, widened),
        FlatterThanCurvature(a) => flatter_headline(a.parameter, a.stretch),
        ShortOfBestEvaluation { gain_nats } => format!(
            "The search evaluated a point {gain_nats:.2} nats more likely than the fit: it ended \
             short of its own best point; refit with more restarts or polish iterations."
        ),
        IntervalsSampled(r) => sampled_headline(r.parameter, r.width_factor),
        ContactRidge { k1_lo, k1_hi } => contact_ridge_headline(*k1_lo, *k1_hi),
        PosteriorUnconverged { parameter, .. } => format!(
            "The posterior sample of {parameter} has not converged: its interval is not yet \
             reliable; run more steps or walkers."
        ),
        PosteriorSpansBounds { parameter, .. } => format!(
            "{parameter} is not determined by this recording: its posterior spans most of its \
             search range, so its interval is the bounds you gave, not a measurement."
        ),
        NoIntervals { method, .. } => no_intervals_headline(*method),
        TargetJobIntervals => {
            "No intervals: a target job's targets carry no measurement noise.".into()
        }
        NoBootstrapReplicates => {
            "No intervals: the job asks for 0 bootstrap replicates ([fit.uncertainty]).".into()
        }
        ToleranceNotProbed { .. } => "The tolerance check did not run (every tighter simulation \
                                      failed): whether the integrator resolves the optimum is not \
                                      known."
            .into(),
        ToleranceUnresolved { spread_nats, .. } => tolerance_unresolved_headline(*spread_nats),
        ChoiceUnresolved {
            chosen,
            runner_up,
            tic_gap,
            spread_nats,
        } => choice_unresolved_headline([chosen, runner_up], *tic_gap, *spread_nats),
        ChosenOnMisfit { chosen, nested, .. } => chosen_on_misfit_headline(chosen, nested),
        FailedEvaluations {
            failed,
            evaluations,
            causes,
            ..
        } => failed_evaluations_headline(w.severity(), *failed, *evaluations, causes),
        NoBladeModes { .. } => {
            "The blade's modes could not be computed at the fitted parameters.".into()
        }
        JointSignalsDropped(d) => joint_dropped_headline(d.half_dof),
        CostJitter(j) => cost_jitter_headline(j.sd_nats),
        DriveDeparts(c) => drive_departs_headline(c),
        PriorConflict(c) => prior_conflict_headline(c.parameter, c.z),
        RigCurveConflict(c) => rig_curve_conflict_headline(c.rms_z, c.points),
        Text { text } => text.clone(),
    }
}

/// [`FitWarning::ChosenOnMisfit`]'s headline: `chosen` kept over `nested` on a failed fit.
fn chosen_on_misfit_headline(
    chosen: &impl std::fmt::Display,
    nested: &impl std::fmt::Display,
) -> String {
    format!(
        "{chosen} is chosen on a fit that fails the goodness-of-fit test: what it adds to \
         {nested} is not confirmed by this recording. Read the misfit's description before \
         believing it."
    )
}

/// [`FitWarning::DriveDeparts`]'s headline: what departs, the head's second harmonic against the
/// fit's and its amplitude against the blade file's.
fn drive_departs_headline(c: &crate::model::drive::DriveCheck) -> String {
    let r = &c.reading;
    let mut what = Vec::new();
    if c.harmonic_departs() {
        what.push(format!(
            "second harmonic {:+.3} of the peak speed, the fit's {:+.3}",
            r.speed_harmonic, c.fitted_speed_harmonic
        ));
    }
    if c.amplitude_departs() {
        what.push(format!(
            "amplitude {:.1} mm, the blade file's {:.1} mm",
            1e3 * r.amplitude_m,
            1e3 * c.blade_amplitude_m
        ));
    }
    format!(
        "The tracked head does not move as the blade file's drive says ({}): the fitted law \
         absorbs the difference.",
        what.join("; ")
    )
}

/// [`FitWarning::PriorConflict`]'s headline: `parameter` fitted `z` prior sds from its prior.
fn prior_conflict_headline(parameter: ParamId, z: f64) -> String {
    format!(
        "{parameter} is fitted {z:+.1} prior standard deviations from its [fit.priors] prior: the \
         recording disagrees with the prior; check the prior's value, or the model."
    )
}

/// [`FitWarning::RigCurveConflict`]'s headline: the rig's `points` at an rms z of `rms_z`.
fn rig_curve_conflict_headline(rms_z: f64, points: usize) -> String {
    format!(
        "The fitted friction law misses the rig curve as a whole (rms z {rms_z:.2} over {points} \
         points): the recording disagrees with the rig's μ(v); check the rig's sd and \
         conditions, or the friction law."
    )
}

/// [`FitWarning::TruthMoreLikely`]'s headline, the truth `short_nats` more likely than the fit (of
/// the true `model` when the choice took another).
fn truth_more_likely_headline(
    short_nats: f64,
    ridge_nats: Option<f64>,
    model: Option<Candidate>,
) -> String {
    let basin = match ridge_nats {
        Some(r) if crate::fit::truth::is_ridge(r) => {
            " The truth lies in another basin, beyond a ridge: refit with more restarts."
        }
        Some(_) => " No ridge lies between them: the search stopped on the truth's slope.",
        None => "",
    };
    match model {
        None => format!(
            "The truth is {short_nats:.2} nats more likely than the fit: the search stopped short \
             of the likelihood's maximum, so the values and intervals describe the wrong \
             point.{basin}"
        ),
        Some(m) => format!(
            "The truth is {short_nats:.2} nats more likely than the fit of its own model, {m}, \
             which the choice did not take: that model's search stopped short of its maximum, so \
             the models were compared at a point that is not its estimate.{basin}"
        ),
    }
}

/// [`FitWarning::AbsorbsModelStructure`]'s headline: the parameter's value with the chosen model,
/// then with the other.
fn absorbs_headline(
    parameter: ParamId,
    [(chosen, value), (other, other_value)]: [(&Candidate, f64); 2],
    sigmas: f64,
) -> String {
    format!(
        "{parameter} depends on the model choice: {} with {chosen}, {} with {other} ({:.1}σ \
         apart).",
        num(value, 4),
        num(other_value, 4),
        sigmas
    )
}

/// [`FitWarning::ProfileAtBound`]'s headline.
fn profile_at_bound_headline(parameter: ParamId, bounds: &[End]) -> String {
    format!(
        "{parameter}'s interval is open at its {} search bound{}: the recording does not \
         bound it there; widen the bounds to see how far it goes.",
        bounds
            .iter()
            .map(|b| b.name())
            .collect::<Vec<_>>()
            .join(" and "),
        if bounds.len() > 1 { "s" } else { "" }
    )
}

/// [`FitWarning::FlatterThanCurvature`]'s headline: how many times wider the likelihood is along
/// a direction that moves mostly `parameter`.
fn flatter_headline(parameter: ParamId, stretch: f64) -> String {
    format!(
        "The likelihood is {stretch:.1} times wider than its curvature at the fit says along a \
         direction that moves mostly {parameter}: the Laplace intervals understate the spread \
         there; refit with `method = \"mcmc\"`, which samples the likelihood itself \
         (docs/uncertainty.md)."
    )
}

/// [`FitWarning::WidenedInterval`]'s headline: the `widened` interval and the `method`'s own.
fn widened_headline(parameter: ParamId, method: &[f64; 2], widened: &[f64; 2]) -> String {
    format!(
        "{parameter}'s interval is widened to [{}, {}] to include points the search found \
         about as likely as the fit (the method alone gave [{}, {}]); the table shows the \
         widened one.",
        num(widened[0], 4),
        num(widened[1], 4),
        num(method[0], 4),
        num(method[1], 4)
    )
}

/// [`FitWarning::Misfit`]'s headline, with the test's p-value and where the excess sits.
fn misfit_headline(p_value: f64, shape: &[crate::likelihood::misfit::BandMisfit]) -> String {
    let words = crate::likelihood::misfit::describe(shape)
        .map(|w| format!("; {w}"))
        .unwrap_or_default();
    format!(
        "The model does not explain the recording's spectra to their noise (p = {:.3}{words}): \
         list more candidate models, check the bands and the tracking noise's spectrum, or bound \
         a known parameter (docs/likelihood.md, \"Goodness of fit\").",
        p_value
    )
}

/// [`FitWarning::TradeOff`]'s headline.
fn trade_off_headline([first, second]: [ParamId; 2], correlation: f64) -> String {
    format!(
        "{first} and {second} trade off (correlation {correlation:+.3}): the data pin down a \
         combination of them; each one's interval already spans what the other allows."
    )
}

/// [`FitWarning::OnBound`]'s headline.
fn on_bound_headline(parameter: ParamId, bound: End, value: f64) -> String {
    format!(
        "{parameter} ended on its {bound} search bound ({}): widen the bound or fix the \
         parameter.",
        num(value, 4)
    )
}

/// [`FitWarning::ProfileMoreLikely`]'s headline.
fn profile_more_likely_headline(parameter: ParamId, gain_nats: f64) -> String {
    format!(
        "{parameter}'s profile met a point {gain_nats:.2} nats more likely than the fit: the \
         search ended short of the optimum; refit with more restarts."
    )
}

/// [`FitWarning::ToleranceUnresolved`]'s headline.
fn tolerance_unresolved_headline(spread_nats: f64) -> String {
    format!(
        "The optimum's cost moves by {} nats between solver tolerances: the intervals \
         understate the uncertainty; tighten [solver] rtol and refit.",
        num(spread_nats, 2)
    )
}

/// [`FitWarning::IntervalsSampled`]'s headline.
fn sampled_headline(parameter: ParamId, width_factor: f64) -> String {
    format!(
        "The intervals come from a posterior sample: the likelihood reaches {width_factor:.1} times \
         {parameter}'s curvature interval."
    )
}

/// [`FitWarning::ChoiceUnresolved`]'s headline: `chosen` over `runner_up`.
fn choice_unresolved_headline(
    [chosen, runner_up]: [&Candidate; 2],
    tic_gap: f64,
    spread_nats: f64,
) -> String {
    format!(
        "{chosen} is reported, not {runner_up} (TIC {} lower): the cost moves {} nats between \
         solver tolerances, more than the lead can be told from; tighten [solver] rtol and refit.",
        num(-tic_gap, 2),
        num(spread_nats, 2)
    )
}

/// [`FitWarning::ContactRidge`]'s headline.
fn contact_ridge_headline(k1_lo: f64, k1_hi: f64) -> String {
    format!(
        "k1 and theta_c trade along the shoulder's contact ridge (k1 from {} to {} N·m/rad \
         fits as well); both intervals span it.",
        num(k1_lo, 4),
        num(k1_hi, 4)
    )
}

/// [`FitWarning::NoIntervals`]'s headline, naming the method.
fn no_intervals_headline(method: UncertaintyMethod) -> String {
    format!(
        "No {} intervals: the chosen model has no likelihood to read them from.",
        match method {
            UncertaintyMethod::Laplace => "Laplace",
            UncertaintyMethod::Profile => "profile-likelihood",
            UncertaintyMethod::Bootstrap => "bootstrap",
            UncertaintyMethod::Mcmc => "posterior (MCMC)",
            UncertaintyMethod::Auto => "automatic",
        }
    )
}

/// [`FitWarning::FailedEvaluations`]'s headline at the warning's `severity`: the failures by
/// cause, and what to do when they take much of the budget.
fn failed_evaluations_headline(
    severity: Severity,
    failed: usize,
    evaluations: usize,
    causes: &BTreeMap<FailureCause, usize>,
) -> String {
    let by: Vec<String> = causes
        .iter()
        .filter(|(_, n)| **n > 0)
        .map(|(c, n)| format!("{n} where {}", cause_words(*c)))
        .collect();
    let why = if by.is_empty() {
        "causes not recorded".to_string()
    } else {
        by.join(", ")
    };
    match severity {
        Severity::Information => format!(
            "{failed} of {evaluations} evaluations of the chosen model ({}) failed, \
             {why}: the search box reaches parameter sets this blade cannot take, and the \
             search discards them.",
            share(failed, evaluations)
        ),
        Severity::Attention => format!(
            "{failed} of {evaluations} evaluations of the chosen model ({}) failed \
             ({why}): the search spends much of its budget where the model cannot go; \
             narrow the bounds, or for integrator failures raise [solver] max_steps.",
            share(failed, evaluations)
        ),
    }
}

/// A line warning's headline: the concern that needs attention first, else the harmonic both
/// spectra share.
fn line_headline(source: LineSource, band: &str, o: &LineOrigin, same: bool) -> String {
    let subject = line_subject(source, band, o);
    if o.prominence.is_nan() || o.prominence < MIN_PROMINENCE {
        let stands = if o.prominence.is_nan() {
            "has no measurable floor".to_string()
        } else {
            format!("stands only {}× over its floor", num(o.prominence, 2))
        };
        return format!(
            "{subject} {stands}: the band's peak may be noise; choose a band around a clear \
             line."
        );
    }
    if o.below_dominant > 100.0 {
        return format!(
            "{subject} lies {}× below the spectrum's dominant line at {} Hz: the band may see \
             that line's leakage, not a line of its own.",
            num(o.below_dominant, 2),
            num(o.dominant_hz, 4)
        );
    }
    match (o.harmonic_of, same) {
        (Some(h), true) => {
            let other = match source {
                LineSource::Recording => "so is the model's",
                LineSource::Model => "as the recording's is",
            };
            format!(
                "{subject} is harmonic {} of a {} Hz line, {other}: the band compares the same \
                 line of the stick–slip comb in both.",
                h.order,
                num(h.freq_hz, 4)
            )
        }
        (Some(h), false) => format!(
            "{subject} is harmonic {} of a {} Hz line, the other spectrum's is not: the band \
             compares different lines; widen it to take in the fundamental.",
            h.order,
            num(h.freq_hz, 4)
        ),
        (None, _) => subject,
    }
}

/// [`FitWarning::CostJitter`]'s headline.
fn cost_jitter_headline(sd_nats: f64) -> String {
    format!(
        "The cost jitters by {} nats at the optimum under rounding-level steps: intervals and cost \
         differences within that are read through it (a profile reads its rises between \
         draw-averaged costs).",
        num(sd_nats, 2)
    )
}

/// [`FitWarning::JointSignalsDropped`]'s headline.
fn joint_dropped_headline(half_dof: f64) -> String {
    format!(
        "Head y and the job's other joint signals were not read: a band keeps too few segments \
         between lost frames for their cross-spectra (ν/2 = {half_dof:.2}), so the fit reads its \
         own signal alone."
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::drive::{DriveCheck, DriveReading};

    /// The headline names what departs: a head 2 % beyond the blade file's amplitude with the
    /// drive's harmonic as the fit's gives the amplitude alone; dep_009's harmonic (−0.0436,
    /// docs/validation.md, "The drive read from the head") gives the harmonic alone.
    #[test]
    fn the_drive_headline_names_what_departs() {
        let reading = DriveReading {
            amplitude_m: 0.102,
            amplitude_se_m: 4.2e-8,
            speed_harmonic: 0.0,
            speed_harmonic_se: 6.9e-7,
            clock_offset_s: 0.0,
            clock_offset_se_s: 2.1e-7,
            residual_rms_m: 2.4e-6,
            residual_lag_one: 0.0,
            samples: 33_953,
        };
        let check = DriveCheck {
            reading,
            blade_amplitude_m: 0.1,
            blade_speed_harmonic: 0.0,
            fitted_speed_harmonic: 0.0,
        };
        let amplitude = drive_departs_headline(&check);
        assert!(
            amplitude.contains("(amplitude 102.0 mm, the blade file's 100.0 mm)"),
            "{amplitude}"
        );
        let harmonic = drive_departs_headline(&DriveCheck {
            reading: DriveReading {
                amplitude_m: 0.1,
                speed_harmonic: -0.043_624,
                ..reading
            },
            ..check
        });
        assert!(
            harmonic.contains("(second harmonic -0.044 of the peak speed, the fit's +0.000)"),
            "{harmonic}"
        );
    }
}
