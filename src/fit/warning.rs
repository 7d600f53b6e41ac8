//! What a fit warns its reader about: [`FitWarning`], one variant per kind of warning carrying its
//! numbers, with a [`Severity`] and the sentence it renders ([`std::fmt::Display`]).
//!
//! The result file keeps both: `warnings`, the sentences (what a reader, and a reader written for
//! result files without kinds, reads), and `warning_details`, each warning's severity, kind and
//! numbers ([`Warnings`]). A result written without `warning_details` loads each sentence as
//! [`FitWarning::Text`].
//!
//! Severity, per kind (docs/report.md, "Warnings"): a warning **needs attention** when the result
//! may be wrong or incomplete as it stands (a misfit, an interval open at a bound, a search that
//! ended short of its own best point, an optimum the integrator does not resolve, ...); it is **for
//! information** when it is normal on a good fit and the reported numbers already account for it
//! (an interval widened to points the search evaluated, a band that sees the same harmonic in the
//! recording and in the model, model evaluations that failed where the lip tip would leave the
//! glass).

use super::select::INDISTINGUISHABLE_TIC;
use super::tolerance::{SPREAD_WARN_NATS, TolerancePoint};
use super::uncertainty::{PROFILE_68_NATS, PROFILE_MAX_STEPS};
use crate::job::Candidate;
use crate::job::UncertaintyMethod;
use crate::likelihood::GoodnessOfFit;
use crate::likelihood::prior::{ParamConflict, PriorsReport, RigConflict};
use crate::likelihood::secant::FlatAxisReport;
use crate::model::ParamId;
use crate::names::named_enum;
use crate::simulate::failure::FailureCause;
use crate::spectrum::harmonics::{LineOrigin, MIN_PROMINENCE};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

named_enum! {
    /// How much a warning asks of its reader.
    pub enum Severity: "severity" {
        /// The result may be wrong or incomplete as it stands: act on it before using the numbers.
        Attention => "attention",
        /// Normal on a good fit; the reported numbers already account for it.
        Information => "information",
    }
}

named_enum! {
    /// Which end of a parameter's search range or interval.
    pub enum End: "end" {
        Lower => "lower",
        Upper => "upper",
    }
}

named_enum! {
    /// Whose spectrum a line belongs to.
    pub enum LineSource: "line source" {
        /// The recording's (or, for a target job, the target's).
        Recording => "recording",
        /// The fitted model's.
        Model => "model",
    }
}

/// Fraction of the model evaluations above which failures are worth a warning at all.
pub const FAILED_WARN_FRACTION: f64 = 0.1;

/// Fraction of the model evaluations above which failures need attention whatever their cause:
/// the search then spends most of its budget where the model cannot go.
pub const FAILED_ATTENTION_FRACTION: f64 = 0.5;

/// Why `method = "auto"` sampled the posterior: the likelihood reaches `width_factor` times the
/// Laplace interval of `parameter`, the widest such.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SampledReason {
    pub parameter: ParamId,
    pub width_factor: f64,
}

/// One warning of a fit, with its numbers. Serialised (in `warning_details`) as a table tagged by
/// `kind`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FitWarning {
    /// The fit was stopped by SIGINT or SIGTERM.
    Interrupted,
    /// The goodness-of-fit test could not run.
    NoGoodnessOfFit { reason: String },
    /// The job's truth is more likely than the fit: the search stopped short of the likelihood's
    /// maximum.
    TruthMoreLikely {
        /// The fit's cost, nats.
        fit_cost_nats: f64,
        /// The chosen model's cost at the truth, nats.
        truth_cost_nats: f64,
        /// The ridge on the segment from the fit to the truth ([`crate::fit::truth`]), nats;
        /// `None` where it was not measured.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ridge_nats: Option<f64>,
        /// The true model, when it is not the chosen one: the costs are that candidate's.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        model: Option<crate::job::Candidate>,
    },
    /// The chosen model does not explain the recording's spectra to their noise.
    Misfit {
        test: GoodnessOfFit,
        /// The job lists a `+shoulder` candidate (the sentence then says how a known contact
        /// angle helps the search).
        shoulder_listed: bool,
        /// Where the excess sits, band by band ([`crate::likelihood::misfit`]).
        #[serde(default)]
        shape: Vec<crate::likelihood::misfit::BandMisfit>,
    },
    /// A parameter moves between the chosen model and another capable one by more than the larger
    /// of their 1σ.
    AbsorbsModelStructure {
        parameter: ParamId,
        chosen: Candidate,
        value: f64,
        other: Candidate,
        other_value: f64,
        /// The move in units of the larger 1σ.
        sigmas: f64,
    },
    /// A band's line is a harmonic of a stronger line, barely stands over its floor, or lies far
    /// below the spectrum's dominant line.
    Line {
        band: String,
        source: LineSource,
        origin: LineOrigin,
        /// The other spectrum's line in the band is the same harmonic (same order) of its own
        /// fundamental: the fit compares like with like.
        same_harmonic_on_other_side: bool,
    },
    /// A parameter's 1σ spans 10 % or more of its search range.
    Undetermined { parameter: ParamId },
    /// Two parameters correlated beyond ±0.95.
    TradeOff {
        first: ParamId,
        second: ParamId,
        correlation: f64,
    },
    /// A parameter ended on a bound of its search range.
    OnBound {
        parameter: ParamId,
        bound: End,
        value: f64,
    },
    /// A profile-likelihood walk reached the search box's bound below the rise limit.
    ProfileAtBound {
        parameter: ParamId,
        rise_limit_nats: f64,
        bounds: Vec<End>,
    },
    /// A profile-likelihood walk ran out of steps below the rise limit.
    ProfileOpen {
        parameter: ParamId,
        rise_limit_nats: f64,
        end: End,
        /// The walk's last point, the parameter's unit.
        value: f64,
    },
    /// A profile walk met a point more likely than the fit.
    ProfileMoreLikely {
        parameter: ParamId,
        gain_nats: f64,
        value: f64,
    },
    /// An interval widened to points the search evaluated inside the profile region.
    WidenedInterval {
        parameter: ParamId,
        rise_limit_nats: f64,
        /// The span of those points.
        points: [f64; 2],
        /// The method's own interval.
        method: [f64; 2],
        /// The interval reported.
        widened: [f64; 2],
    },
    /// The likelihood is flatter along a principal axis of `F⁻¹` than the Laplace quadratic
    /// ([`crate::likelihood::secant`]): the Laplace intervals understate the spread along it.
    FlatterThanCurvature(FlatAxisReport),
    /// The search evaluated a point more likely than the fit.
    ShortOfBestEvaluation { gain_nats: f64 },
    /// `method = "auto"` sampled the posterior: the curvature does not describe the likelihood.
    IntervalsSampled(SampledReason),
    /// k1 and theta_c trade along the shoulder's contact-moment ridge; both intervals span it.
    ContactRidge { k1_lo: f64, k1_hi: f64 },
    /// The job's interval method gave no intervals.
    NoIntervals {
        method: UncertaintyMethod,
        reason: String,
    },
    /// The posterior sample's chains have not mixed for a parameter: split R̂ above
    /// [`crate::fit::RHAT_LIMIT`] or fewer effective draws than [`crate::fit::MIN_ESS`].
    PosteriorUnconverged {
        parameter: ParamId,
        r_hat: f64,
        ess: f64,
    },
    /// The parameter's 95 % posterior interval spans more than
    /// [`crate::posterior::UNDETERMINED_SPAN`] of its search range: the recording does not
    /// determine it within the bounds.
    PosteriorSpansBounds {
        parameter: ParamId,
        /// Fraction of the search range (normalised coordinates).
        span_fraction: f64,
        /// The 95 % interval, the parameter's unit.
        interval: [f64; 2],
    },
    /// A target job has no intervals: its targets carry no measurement noise.
    TargetJobIntervals,
    /// `[fit.uncertainty] bootstrap = 0` with the bootstrap method.
    NoBootstrapReplicates,
    /// Every probe of the tolerance check failed.
    ToleranceNotProbed { failures: Vec<String> },
    /// The optimum's cost moves between solver tolerances by more than [`SPREAD_WARN_NATS`].
    ToleranceUnresolved {
        points: Vec<TolerancePoint>,
        spread_nats: f64,
    },
    /// A candidate that adds structure to another (a shoulder) is chosen on a fit that fails the
    /// goodness-of-fit test: the structure may absorb the misfit rather than describe the blade.
    ChosenOnMisfit {
        chosen: Candidate,
        /// The candidate it adds structure to.
        nested: Candidate,
        /// The nested candidate's TIC above the chosen one's.
        delta_tic: f64,
    },
    /// The candidate with the lowest TIC (`runner_up`) is not reported because its lead over
    /// `chosen`, which has fewer parameters, lies within the margin widened by the optima's cost
    /// spreads between solver tolerances: the integrator does not resolve it.
    ChoiceUnresolved {
        chosen: Candidate,
        runner_up: Candidate,
        /// `runner_up`'s TIC minus `chosen`'s (negative).
        tic_gap: f64,
        /// The two optima's unresolved cost spreads, summed, nats.
        spread_nats: f64,
    },
    /// More than [`FAILED_WARN_FRACTION`] of the chosen model's evaluations failed.
    FailedEvaluations {
        failed: usize,
        evaluations: usize,
        /// Failures by cause (empty when not recorded).
        #[serde(default)]
        causes: BTreeMap<FailureCause, usize>,
        first: Option<String>,
    },
    /// The blade's modes at the fitted parameters could not be computed.
    NoBladeModes { reason: String },
    /// A parameter fitted beyond [`crate::likelihood::prior::PRIOR_CONFLICT_Z`] standard
    /// deviations of its `[fit.priors]` prior.
    PriorConflict(ParamConflict),
    /// The fitted law misses the `[fit.priors.friction_curve]` rig curve as a whole.
    RigCurveConflict(RigConflict),
    /// A warning read from a result written before warnings had kinds: its sentence only.
    Text { text: String },
}

impl FitWarning {
    /// How much the warning asks of its reader (module docs; docs/report.md, "Warnings").
    pub fn severity(&self) -> Severity {
        use FitWarning::*;
        match self {
            WidenedInterval { .. }
            | IntervalsSampled(_)
            | ContactRidge { .. }
            | TradeOff { .. }
            | TargetJobIntervals
            | NoBootstrapReplicates
            | NoBladeModes { .. } => Severity::Information,
            Line {
                origin,
                same_harmonic_on_other_side,
                ..
            } => {
                let weak = origin.prominence.is_nan() || origin.prominence < MIN_PROMINENCE;
                let far_below = origin.below_dominant > 100.0;
                let lone_harmonic = origin.harmonic_of.is_some() && !same_harmonic_on_other_side;
                if weak || far_below || lone_harmonic {
                    Severity::Attention
                } else {
                    Severity::Information
                }
            }
            FailedEvaluations {
                failed,
                evaluations,
                causes,
                ..
            } => {
                let unreachable = |c: &FailureCause| {
                    matches!(c, FailureCause::ContactLoss | FailureCause::Painleve)
                };
                let physical = !causes.is_empty()
                    && causes.iter().all(|(c, n)| *n == 0 || unreachable(c))
                    && causes.values().sum::<usize>() == *failed;
                if physical && (*failed as f64) <= FAILED_ATTENTION_FRACTION * *evaluations as f64 {
                    Severity::Information
                } else {
                    Severity::Attention
                }
            }
            Interrupted
            | NoGoodnessOfFit { .. }
            | TruthMoreLikely { .. }
            | Misfit { .. }
            | AbsorbsModelStructure { .. }
            | Undetermined { .. }
            | OnBound { .. }
            | ProfileAtBound { .. }
            | ProfileOpen { .. }
            | ProfileMoreLikely { .. }
            | FlatterThanCurvature(_)
            | ShortOfBestEvaluation { .. }
            | PosteriorUnconverged { .. }
            | PosteriorSpansBounds { .. }
            | NoIntervals { .. }
            | ToleranceNotProbed { .. }
            | ToleranceUnresolved { .. }
            | ChoiceUnresolved { .. }
            | ChosenOnMisfit { .. }
            | PriorConflict(_)
            | RigCurveConflict(_)
            | Text { .. } => Severity::Attention,
        }
    }

    /// The kind's name in the result file (`kind` of `warning_details`).
    pub fn kind(&self) -> &'static str {
        use FitWarning::*;
        match self {
            Interrupted => "interrupted",
            NoGoodnessOfFit { .. } => "no_goodness_of_fit",
            TruthMoreLikely { .. } => "truth_more_likely",
            Misfit { .. } => "misfit",
            AbsorbsModelStructure { .. } => "absorbs_model_structure",
            Line { .. } => "line",
            Undetermined { .. } => "undetermined",
            TradeOff { .. } => "trade_off",
            OnBound { .. } => "on_bound",
            ProfileAtBound { .. } => "profile_at_bound",
            ProfileOpen { .. } => "profile_open",
            ProfileMoreLikely { .. } => "profile_more_likely",
            WidenedInterval { .. } => "widened_interval",
            FlatterThanCurvature(_) => "flatter_than_curvature",
            ShortOfBestEvaluation { .. } => "short_of_best_evaluation",
            IntervalsSampled(_) => "intervals_sampled",
            PosteriorUnconverged { .. } => "posterior_unconverged",
            PosteriorSpansBounds { .. } => "posterior_spans_bounds",
            ContactRidge { .. } => "contact_ridge",
            NoIntervals { .. } => "no_intervals",
            TargetJobIntervals => "target_job_intervals",
            NoBootstrapReplicates => "no_bootstrap_replicates",
            ToleranceNotProbed { .. } => "tolerance_not_probed",
            ToleranceUnresolved { .. } => "tolerance_unresolved",
            ChoiceUnresolved { .. } => "choice_unresolved",
            ChosenOnMisfit { .. } => "chosen_on_misfit",
            FailedEvaluations { .. } => "failed_evaluations",
            NoBladeModes { .. } => "no_blade_modes",
            PriorConflict(_) => "prior_conflict",
            RigCurveConflict(_) => "rig_curve_conflict",
            Text { .. } => "text",
        }
    }

    /// The parameter the warning is about, when it is about one.
    pub fn parameter(&self) -> Option<ParamId> {
        use FitWarning::*;
        match self {
            AbsorbsModelStructure { parameter, .. }
            | Undetermined { parameter }
            | OnBound { parameter, .. }
            | ProfileAtBound { parameter, .. }
            | ProfileOpen { parameter, .. }
            | ProfileMoreLikely { parameter, .. }
            | WidenedInterval { parameter, .. }
            | PosteriorUnconverged { parameter, .. }
            | PosteriorSpansBounds { parameter, .. } => Some(*parameter),
            PriorConflict(c) => Some(c.parameter),
            FlatterThanCurvature(a) => Some(a.parameter),
            IntervalsSampled(r) => Some(r.parameter),
            _ => None,
        }
    }
}

/// Where the fit disagrees with the job's priors ([`PriorsReport::parameter_conflicts`],
/// [`PriorsReport::rig_conflict`]).
pub fn prior_warnings(priors: &PriorsReport) -> Vec<FitWarning> {
    let params = priors.parameter_conflicts().into_iter();
    (params.map(FitWarning::PriorConflict))
        .chain(priors.rig_conflict().map(FitWarning::RigCurveConflict))
        .collect()
}

/// `name`'s line in `band` as the line warnings name it.
fn line_name(source: LineSource, band: &str) -> String {
    match source {
        LineSource::Recording => format!("the recording's line in band '{band}'"),
        LineSource::Model => format!("the model's line in band '{band}'"),
    }
}

/// [`FitWarning::Line`]'s sentence: the `origin`'s concern about the line called `name`.
fn line(f: &mut fmt::Formatter<'_>, name: String, origin: &LineOrigin) -> fmt::Result {
    let concern = origin.concern(&name);
    f.write_str(&concern.unwrap_or_else(|| format!("{name} needs no warning")))
}

impl fmt::Display for FitWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use FitWarning::*;
        match self {
            Interrupted => f.write_str(
                "interrupted: the best point the search had reached, without the remaining \
                 restarts, candidates, curvature or intervals",
            ),
            NoGoodnessOfFit { reason } => write!(f, "no goodness-of-fit test: {reason}"),
            TruthMoreLikely {
                fit_cost_nats,
                truth_cost_nats,
                ridge_nats,
                model,
            } => truth_more_likely(f, [*fit_cost_nats, *truth_cost_nats], *ridge_nats, *model),
            Misfit {
                test,
                shoulder_listed,
                shape,
            } => misfit(f, test, *shoulder_listed, shape),
            AbsorbsModelStructure {
                parameter,
                chosen,
                value,
                other,
                other_value,
                sigmas,
            } => absorbs_model_structure(
                f,
                *parameter,
                [(chosen, *value), (other, *other_value)],
                *sigmas,
            ),
            Line {
                band,
                source,
                origin,
                ..
            } => line(f, line_name(*source, band), origin),
            Undetermined { parameter } => undetermined(f, *parameter),
            TradeOff {
                first,
                second,
                correlation,
            } => trade_off(f, [*first, *second], *correlation),
            OnBound {
                parameter,
                bound,
                value,
            } => on_bound(f, *parameter, *bound, *value),
            ProfileAtBound {
                parameter,
                rise_limit_nats,
                bounds,
            } => profile_at_bound(f, *parameter, *rise_limit_nats, bounds),
            ProfileOpen {
                parameter,
                rise_limit_nats,
                end,
                value,
            } => profile_open(f, *parameter, *rise_limit_nats, *end, *value),
            ProfileMoreLikely {
                parameter,
                gain_nats,
                value,
            } => profile_more_likely(f, *parameter, *gain_nats, *value),
            WidenedInterval {
                parameter,
                rise_limit_nats,
                points,
                method,
                widened,
            } => widened_interval(f, *parameter, *rise_limit_nats, [points, method, widened]),
            FlatterThanCurvature(a) => flatter_than_curvature(f, a),
            ShortOfBestEvaluation { gain_nats } => short_of_best_evaluation(f, *gain_nats),
            IntervalsSampled(r) => intervals_sampled(f, r),
            PosteriorUnconverged {
                parameter,
                r_hat,
                ess,
            } => posterior_unconverged(f, *parameter, *r_hat, *ess),
            PosteriorSpansBounds {
                parameter,
                span_fraction,
                interval,
            } => posterior_spans_bounds(f, *parameter, *span_fraction, *interval),
            ContactRidge { k1_lo, k1_hi } => contact_ridge(f, *k1_lo, *k1_hi),
            NoIntervals { method, reason } => no_intervals(f, *method, reason),
            TargetJobIntervals => f.write_str(TARGET_JOB_INTERVALS),
            NoBootstrapReplicates => f.write_str(NO_BOOTSTRAP_REPLICATES),
            ToleranceNotProbed { failures } => tolerance_not_probed(f, failures),
            ToleranceUnresolved {
                points,
                spread_nats,
            } => tolerance_unresolved(f, points, *spread_nats),
            ChoiceUnresolved {
                chosen,
                runner_up,
                tic_gap,
                spread_nats,
            } => choice_unresolved(f, [chosen, runner_up], *tic_gap, *spread_nats),
            ChosenOnMisfit {
                chosen,
                nested,
                delta_tic: d,
            } => chosen_on_misfit(f, chosen, nested, *d),
            FailedEvaluations {
                failed,
                evaluations,
                first,
                ..
            } => failed_evaluations(f, *failed, *evaluations, first.as_deref()),
            NoBladeModes { reason } => {
                write!(f, "no blade modes at the fitted parameters: {reason}")
            }
            PriorConflict(c) => c.fmt(f),
            RigCurveConflict(c) => c.fmt(f),
            Text { text } => f.write_str(text),
        }
    }
}

/// [`FitWarning::TruthMoreLikely`]'s sentence.
fn truth_more_likely(
    f: &mut fmt::Formatter<'_>,
    [fit, truth]: [f64; 2],
    ridge: Option<f64>,
    model: Option<crate::job::Candidate>,
) -> fmt::Result {
    let whose = model.map_or(String::new(), |m| format!(" of the true model {m}"));
    write!(
        f,
        "the truth is more likely than the fit{whose}: cost {truth:.2} nats at the true \
         parameters against {fit:.2} at the fit ({:.2} nats short): the search stopped before \
         the likelihood's maximum, so the fitted values and their intervals describe a point that \
         is not the estimate",
        fit - truth
    )?;
    match ridge {
        Some(r) if super::truth::is_ridge(r) => write!(
            f,
            "; a ridge {r:.2} nats high lies between them on the straight line, so the truth's \
             basin is another one, which the global search did not enter (more restarts)"
        ),
        Some(_) => f.write_str(
            "; no ridge lies between them on the straight line, so the search stopped on the \
             slope of the truth's own basin (a longer polish)",
        ),
        None => Ok(()),
    }
}

/// [`FitWarning::Misfit`]'s sentence, with the shoulder's advice when the job lists a shoulder
/// candidate.
fn misfit(
    f: &mut fmt::Formatter<'_>,
    g: &GoodnessOfFit,
    shoulder_listed: bool,
    shape: &[crate::likelihood::misfit::BandMisfit],
) -> fmt::Result {
    write!(
        f,
        "the chosen model does not explain the recording's spectra to their noise: excess NLL \
         {:.1} nats against {:.1} ± {:.1} for {} noise replicates of the fit (p = {:.3}, \
         {:.1}σ); the recording holds structure no candidate reproduces, or the search missed a \
         candidate's basin, and the fitted parameters may be bent to absorb it",
        g.excess_nll_nats,
        g.replicate_mean_nats,
        g.replicate_sd_nats,
        g.replicates,
        g.p_value,
        g.z()
    )?;
    if let Some(words) = crate::likelihood::misfit::describe(shape) {
        write!(f, "; {words}")?;
    }
    if shoulder_listed {
        f.write_str(
            "; a shoulder the neck touches only at the peaks of its swing has a basin a few per \
             cent wide in theta_c that the search can miss: bounding [fit.shoulder] theta_c to a \
             contact angle known from the blade's drawing lets it find one (docs/model-choice.md, \
             \"Shoulder contact\")",
        )?;
    }
    Ok(())
}

/// [`FitWarning::AbsorbsModelStructure`]'s sentence: the parameter's value in the chosen model,
/// then in the other.
fn absorbs_model_structure(
    f: &mut fmt::Formatter<'_>,
    parameter: ParamId,
    [(chosen, value), (other, other_value)]: [(&Candidate, f64); 2],
    sigmas: f64,
) -> fmt::Result {
    write!(
        f,
        "{parameter} moves from {value:.6} ({chosen}) to {other_value:.6} ({other}), \
         {sigmas:.1}σ: it absorbs structure one model has and the other has not, so its \
         value depends on the model choice"
    )
}

/// [`FitWarning::Undetermined`]'s sentence.
fn undetermined(f: &mut fmt::Formatter<'_>, parameter: ParamId) -> fmt::Result {
    write!(
        f,
        "{parameter} is not determined by the data: its 1σ spans 10 % or more of its \
         search range"
    )
}

/// [`FitWarning::TradeOff`]'s sentence.
fn trade_off(
    f: &mut fmt::Formatter<'_>,
    [first, second]: [ParamId; 2],
    correlation: f64,
) -> fmt::Result {
    write!(
        f,
        "{first} and {second} trade off (correlation {correlation:+.3}): the data pin \
         down a combination of them, not each"
    )
}

/// [`FitWarning::OnBound`]'s sentence.
fn on_bound(f: &mut fmt::Formatter<'_>, parameter: ParamId, bound: End, value: f64) -> fmt::Result {
    write!(
        f,
        "{parameter} ended on its {bound} bound ({value}); widen the bound or fix the \
         parameter"
    )
}

/// [`FitWarning::ShortOfBestEvaluation`]'s sentence.
fn short_of_best_evaluation(f: &mut fmt::Formatter<'_>, gain_nats: f64) -> fmt::Result {
    write!(
        f,
        "the search evaluated a point {gain_nats:.2} nats more likely than the fit: it \
         ended short of its own best evaluation"
    )
}

/// [`FitWarning::ProfileAtBound`]'s sentence.
fn profile_at_bound(
    f: &mut fmt::Formatter<'_>,
    parameter: ParamId,
    rise_limit_nats: f64,
    bounds: &[End],
) -> fmt::Result {
    write!(
        f,
        "{parameter}'s profile likelihood stays within {rise_limit_nats:.3} nats of the fit up \
         to its search box's {} bound: the recording does not bound it there",
        bounds
            .iter()
            .map(|b| b.name())
            .collect::<Vec<_>>()
            .join(" and ")
    )
}

/// [`FitWarning::ProfileOpen`]'s sentence.
fn profile_open(
    f: &mut fmt::Formatter<'_>,
    parameter: ParamId,
    rise_limit_nats: f64,
    end: End,
    value: f64,
) -> fmt::Result {
    write!(
        f,
        "{parameter}'s profile likelihood stays within {rise_limit_nats:.3} nats of the fit over \
         the walk's {PROFILE_MAX_STEPS} steps: its {end} end ({value:.4e}) is the last step, not \
         where the likelihood bounds it"
    )
}

/// [`FitWarning::ProfileMoreLikely`]'s sentence.
fn profile_more_likely(
    f: &mut fmt::Formatter<'_>,
    parameter: ParamId,
    gain_nats: f64,
    value: f64,
) -> fmt::Result {
    write!(
        f,
        "{parameter}'s profile met a point {gain_nats:.2} nats more likely than the fit \
         ({parameter} = {value:.4e}): the search ended short of the likelihood's maximum"
    )
}

/// [`FitWarning::WidenedInterval`]'s sentence: the span of the evaluated points, the method's
/// interval and the widened one, in that order.
fn widened_interval(
    f: &mut fmt::Formatter<'_>,
    parameter: ParamId,
    rise_limit_nats: f64,
    [[p_lo, p_hi], [lo0, hi0], [lo, hi]]: [&[f64; 2]; 3],
) -> fmt::Result {
    write!(
        f,
        "{parameter}: points the search evaluated within {rise_limit_nats:.2} nats of the fit \
         span {p_lo:.4e} to {p_hi:.4e}, beyond the method's own interval [{lo0:.4e}, \
         {hi0:.4e}]: the likelihood is flatter there than that interval says, so it is widened \
         to [{lo:.4e}, {hi:.4e}]"
    )
}

/// [`FitWarning::FlatterThanCurvature`]'s sentence.
fn flatter_than_curvature(f: &mut fmt::Formatter<'_>, a: &FlatAxisReport) -> fmt::Result {
    write!(
        f,
        "along a principal axis of the Fisher information (mostly {}) the likelihood rises {:.2} \
         nats at ±{}σ where the Laplace quadratic rises {:.1}: it is {:.1} times wider there than \
         the curvature at the fit says, so the Laplace intervals understate the spread of the \
         parameters that direction moves; method = \"mcmc\" samples the likelihood itself",
        a.parameter,
        a.rise_nats,
        crate::likelihood::secant::SECANT_PROBE_SIGMA,
        a.quadratic_nats,
        a.stretch
    )
}

/// [`FitWarning::ContactRidge`]'s sentence.
fn contact_ridge(f: &mut fmt::Formatter<'_>, k1_lo: f64, k1_hi: f64) -> fmt::Result {
    write!(
        f,
        "k1 and theta_c trade along the shoulder's contact-moment ridge ((k1c − k1)·θ_c held): \
         k1 from {k1_lo:.4e} to {k1_hi:.4e} N·m/rad stays within {PROFILE_68_NATS} nats of the \
         fit, so both intervals span it; the recording determines the moment at contact, not k1 \
         and theta_c apart"
    )
}

/// [`FitWarning::NoIntervals`]'s sentence, naming the method.
fn no_intervals(
    f: &mut fmt::Formatter<'_>,
    method: UncertaintyMethod,
    reason: &str,
) -> fmt::Result {
    match method {
        UncertaintyMethod::Laplace => write!(f, "no Laplace intervals: {reason}"),
        UncertaintyMethod::Profile => write!(f, "no profile-likelihood intervals: {reason}"),
        UncertaintyMethod::Bootstrap => write!(f, "no bootstrap intervals: {reason}"),
        UncertaintyMethod::Mcmc => write!(f, "no posterior (MCMC) intervals: {reason}"),
        UncertaintyMethod::Auto => write!(f, "no intervals: {reason}"),
    }
}

/// [`FitWarning::ToleranceNotProbed`]'s sentence.
fn tolerance_not_probed(f: &mut fmt::Formatter<'_>, failures: &[String]) -> fmt::Result {
    write!(
        f,
        "the tolerance check did not run: every probe failed ({}), so it is not known whether \
         the integrator resolves the likelihood at the optimum (docs/likelihood.md, \"Tolerance \
         check\")",
        failures.join("; ")
    )
}

/// [`FitWarning::ToleranceUnresolved`]'s sentence, with the cost at each tolerance.
fn tolerance_unresolved(
    f: &mut fmt::Formatter<'_>,
    points: &[TolerancePoint],
    spread_nats: f64,
) -> fmt::Result {
    let at: Vec<String> = points
        .iter()
        .map(|p| {
            format!(
                "{:.3} nats at rtol {:e} ({} transitions)",
                p.cost_nats, p.rtol, p.transitions
            )
        })
        .collect();
    write!(
        f,
        "the likelihood at the optimum is not resolved by the integrator: {} ({:.2} nats apart, \
         more than the {SPREAD_WARN_NATS} nats of a 1σ interval); the stick–slip sequence hangs \
         on grazing events, so the cost surface is rough at that depth, cost differences below \
         it do not tell parameter sets apart and the intervals understate the uncertainty \
         (docs/likelihood.md, \"Tolerance check\")",
        crate::names::join(&at, ", "),
        spread_nats
    )
}

/// [`FitWarning::TargetJobIntervals`]'s sentence.
const TARGET_JOB_INTERVALS: &str =
    "no intervals for a target job: targets carry no measurement noise";

/// [`FitWarning::NoBootstrapReplicates`]'s sentence.
const NO_BOOTSTRAP_REPLICATES: &str =
    "no bootstrap intervals: [fit.uncertainty] bootstrap = 0 replicates";

/// [`FitWarning::PosteriorUnconverged`]'s sentence.
fn posterior_unconverged(
    f: &mut fmt::Formatter<'_>,
    parameter: ParamId,
    r_hat: f64,
    ess: f64,
) -> fmt::Result {
    write!(
        f,
        "the posterior sample of {parameter} has not converged: split R̂ {r_hat:.3} (limit {}), \
         {ess:.0} effective draws (at least {}); run more steps or walkers",
        super::RHAT_LIMIT,
        super::MIN_ESS
    )
}

/// [`FitWarning::PosteriorSpansBounds`]'s sentence.
fn posterior_spans_bounds(
    f: &mut fmt::Formatter<'_>,
    parameter: ParamId,
    span_fraction: f64,
    interval: [f64; 2],
) -> fmt::Result {
    write!(
        f,
        "{parameter} is not determined by this recording: its 95 % posterior interval \
         [{:.6}, {:.6}] spans {:.0} % of its search range",
        interval[0],
        interval[1],
        100.0 * span_fraction
    )
}

/// [`FitWarning::ChosenOnMisfit`]'s sentence.
fn chosen_on_misfit(
    f: &mut fmt::Formatter<'_>,
    chosen: &Candidate,
    nested: &Candidate,
    delta_tic: f64,
) -> fmt::Result {
    write!(
        f,
        "{chosen} is chosen over {nested} (TIC {delta_tic:.1} lower) by a fit that fails the \
         goodness-of-fit test: what it adds to {nested} may absorb the misfit rather than \
         describe the blade, so it is not confirmed by this recording"
    )
}

/// [`FitWarning::IntervalsSampled`]'s sentence.
fn intervals_sampled(f: &mut fmt::Formatter<'_>, r: &SampledReason) -> fmt::Result {
    let (parameter, factor) = (r.parameter, r.width_factor);
    write!(
        f,
        "the likelihood reaches {factor:.1} times the Laplace interval of {parameter} (the \
         search's evaluations inside its profile region, or the check along the Fisher \
         information's axes), more than the curvature at the fit describes, so every interval \
         comes from a posterior sample ([fit.uncertainty] method = \"auto\"; docs/uncertainty.md, \
         \"Automatic\")"
    )
}

/// [`FitWarning::ChoiceUnresolved`]'s sentence: `chosen` reported over `runner_up`.
fn choice_unresolved(
    f: &mut fmt::Formatter<'_>,
    [chosen, runner_up]: [&Candidate; 2],
    tic_gap: f64,
    spread_nats: f64,
) -> fmt::Result {
    write!(
        f,
        "{chosen} is reported, not {runner_up}, whose TIC is {:.2} lower: the optima's costs \
         spread by {spread_nats:.2} nats between solver tolerances, so the TIC is known only to \
         within {:.2} and a lead below {INDISTINGUISHABLE_TIC} + {:.2} is not resolved by the \
         integrator; the candidate with fewer parameters is reported (docs/likelihood.md, \
         \"Tolerance check\")",
        -tic_gap,
        2.0 * spread_nats,
        2.0 * spread_nats
    )
}

/// [`FitWarning::FailedEvaluations`]'s sentence.
fn failed_evaluations(
    f: &mut fmt::Formatter<'_>,
    failed: usize,
    evaluations: usize,
    first: Option<&str>,
) -> fmt::Result {
    write!(
        f,
        "{failed} of {evaluations} model evaluations failed (first: {}); the bounds reach \
         parameter sets the model cannot simulate",
        first.unwrap_or_default()
    )
}

/// A fit's warnings, in the order the fit found them. In the result file: `warnings`, their
/// sentences, and `warning_details`, each one's severity and its kind with its numbers
/// ([`WarningsFile`]).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(from = "WarningsFile", into = "WarningsFile")]
pub struct Warnings(pub Vec<FitWarning>);

impl std::ops::Deref for Warnings {
    type Target = Vec<FitWarning>;
    fn deref(&self) -> &Vec<FitWarning> {
        &self.0
    }
}

impl std::ops::DerefMut for Warnings {
    fn deref_mut(&mut self) -> &mut Vec<FitWarning> {
        &mut self.0
    }
}

impl From<Vec<FitWarning>> for Warnings {
    fn from(v: Vec<FitWarning>) -> Self {
        Warnings(v)
    }
}

impl<'a> IntoIterator for &'a Warnings {
    type Item = &'a FitWarning;
    type IntoIter = std::slice::Iter<'a, FitWarning>;
    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}

/// One entry of `warning_details`: the severity the fit gave the warning (for scripts; a reader
/// recomputes it from the kind) and the warning.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct WarningDetail {
    severity: Severity,
    warning: FitWarning,
}

/// [`Warnings`] as the result file holds them.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct WarningsFile {
    /// One sentence per warning.
    #[serde(default)]
    warnings: Vec<String>,
    /// Each warning's severity, kind and numbers, in the order of `warnings`; absent in results
    /// written before warnings had kinds.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    warning_details: Vec<WarningDetail>,
}

impl From<Warnings> for WarningsFile {
    fn from(w: Warnings) -> Self {
        WarningsFile {
            warnings: w.0.iter().map(ToString::to_string).collect(),
            warning_details: w
                .0
                .into_iter()
                .map(|warning| WarningDetail {
                    severity: warning.severity(),
                    warning,
                })
                .collect(),
        }
    }
}

impl From<WarningsFile> for Warnings {
    /// The details when there is one per sentence, else the sentences as [`FitWarning::Text`].
    fn from(f: WarningsFile) -> Self {
        if f.warning_details.len() == f.warnings.len() {
            Warnings(f.warning_details.into_iter().map(|d| d.warning).collect())
        } else {
            Warnings(
                f.warnings
                    .into_iter()
                    .map(|text| FitWarning::Text { text })
                    .collect(),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::harmonics::Fundamental;

    fn harmonic_line(source: LineSource, matched: bool) -> FitWarning {
        FitWarning::Line {
            band: "low".into(),
            source,
            origin: LineOrigin {
                freq_hz: 49.88,
                prominence: 338.0,
                harmonic_of: Some(Fundamental {
                    freq_hz: 24.63,
                    order: 2,
                    level_ratio: 69.5,
                }),
                dominant_hz: 24.63,
                below_dominant: 69.5,
            },
            same_harmonic_on_other_side: matched,
        }
    }

    #[test]
    fn a_harmonic_both_spectra_share_is_information_and_renders_the_concern() {
        let w = harmonic_line(LineSource::Recording, true);
        assert_eq!(w.severity(), Severity::Information);
        assert_eq!(
            w.to_string(),
            "the recording's line in band 'low' at 49.88 Hz is harmonic 2 of a line at 24.63 Hz \
             that is 69.5× stronger (a stick–slip comb: the band sees a harmonic, not the \
             cycle's fundamental)"
        );
        // The model's line its own while the recording's is a harmonic: not like with like.
        assert_eq!(
            harmonic_line(LineSource::Recording, false).severity(),
            Severity::Attention
        );
        // A weak line needs attention even when both sides agree.
        let mut weak = harmonic_line(LineSource::Model, true);
        if let FitWarning::Line { origin, .. } = &mut weak {
            origin.prominence = f64::NAN;
        }
        assert_eq!(weak.severity(), Severity::Attention);
    }

    #[test]
    fn failures_where_the_lip_would_leave_the_glass_are_information_up_to_half() {
        let failed =
            |failed: usize, causes: &[(FailureCause, usize)]| FitWarning::FailedEvaluations {
                failed,
                evaluations: 1000,
                causes: causes.iter().copied().collect(),
                first: Some("contact lost".into()),
            };
        let contact = failed(400, &[(FailureCause::ContactLoss, 400)]);
        assert_eq!(contact.severity(), Severity::Information);
        assert_eq!(
            contact.to_string(),
            "400 of 1000 model evaluations failed (first: contact lost); the bounds reach \
             parameter sets the model cannot simulate"
        );
        let most = failed(600, &[(FailureCause::ContactLoss, 600)]);
        assert_eq!(most.severity(), Severity::Attention);
        let numeric = failed(
            200,
            &[
                (FailureCause::ContactLoss, 150),
                (FailureCause::StepBudget, 50),
            ],
        );
        assert_eq!(numeric.severity(), Severity::Attention);
        // Causes not recorded: not known to be harmless.
        assert_eq!(failed(200, &[]).severity(), Severity::Attention);
    }

    #[test]
    fn the_file_keeps_sentences_and_details_and_reads_sentences_alone() {
        let w: Warnings = vec![
            harmonic_line(LineSource::Model, true),
            FitWarning::OnBound {
                parameter: ParamId::K1,
                bound: End::Upper,
                value: 0.15,
            },
            FitWarning::PriorConflict(ParamConflict {
                parameter: ParamId::ThetaC,
                prior: crate::job::ParamPrior::Lognormal {
                    median: 0.08,
                    sd_log: 0.1,
                },
                value: 0.1,
                z: 2.23,
            }),
        ]
        .into();
        #[derive(Serialize, Deserialize)]
        struct Holder {
            #[serde(flatten)]
            w: Warnings,
        }
        let text = toml::to_string(&Holder { w: w.clone() }).unwrap();
        let t: toml::Table = toml::from_str(&text).unwrap();
        let sentences = t["warnings"].as_array().unwrap();
        assert_eq!(
            sentences[1].as_str(),
            Some("k1 ended on its upper bound (0.15); widen the bound or fix the parameter")
        );
        let details = t["warning_details"].as_array().unwrap();
        assert_eq!(details[0]["severity"].as_str(), Some("information"));
        assert_eq!(details[1]["warning"]["kind"].as_str(), Some("on_bound"));
        assert_eq!(
            details[2]["warning"]["kind"].as_str(),
            Some("prior_conflict")
        );
        assert_eq!(details[2]["severity"].as_str(), Some("attention"));
        let back: Holder = toml::from_str(&text).unwrap();
        assert_eq!(back.w, w);
        // A result without details: each sentence as text, needing attention.
        let old: Holder = toml::from_str("warnings = [\"something odd\"]\n").unwrap();
        assert_eq!(
            old.w.0,
            [FitWarning::Text {
                text: "something odd".into()
            }]
        );
        assert_eq!(old.w[0].severity(), Severity::Attention);
        assert_eq!(old.w[0].kind(), "text");
    }
}
