//! What a fit warns its reader about, as data: [`FitWarning`], one variant per kind of warning
//! carrying its numbers, with a [`Severity`] and a kind name.
//!
//! The search, the intervals and the model choice all raise these warnings, so the type comes before
//! them; the sentence each renders ([`std::fmt::Display`]) quotes those stages' thresholds and is
//! written in `fit::warning`, with the result file's form of a fit's warnings.

use crate::job::Candidate;
use crate::job::UncertaintyMethod;
use crate::likelihood::GoodnessOfFit;
use crate::likelihood::prior::{ParamConflict, RigConflict};
use crate::likelihood::secant::FlatAxisReport;
use crate::model::ParamId;
use crate::names::named_enum;
use crate::simulate::failure::FailureCause;
use crate::spectrum::harmonics::{LineOrigin, MIN_PROMINENCE};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

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
    /// [`crate::uncertainty::RHAT_LIMIT`] or fewer effective draws than [`crate::uncertainty::MIN_ESS`].
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
    /// `[fit.likelihood] joint_signals` could not be read, so the fit read its own signal alone.
    JointSignalsDropped(JointDropped),
    /// The cost at the optimum jitters under rounding-level steps by more than the likelihood's
    /// rise at an interval's edge ([`crate::search::jitter`]).
    CostJitter(Jitter),
    /// The tracked head departs from the drive the fit used (its second harmonic or its
    /// amplitude: [`crate::model::drive::DriveCheck`]).
    DriveDeparts(crate::model::drive::DriveCheck),
    /// A parameter fitted beyond [`crate::likelihood::prior::PRIOR_CONFLICT_Z`] standard
    /// deviations of its `[fit.priors]` prior.
    PriorConflict(ParamConflict),
    /// The fitted law misses the `[fit.priors.friction_curve]` rig curve as a whole.
    RigCurveConflict(RigConflict),
    /// A warning read from a result written before warnings had kinds: its sentence only.
    Text { text: String },
}

/// Why `[fit.likelihood] joint_signals` were not read: a band's `n_segments` segments give
/// `half_dof` (`ν/2`) equivalent degrees of freedom, fewer than the cross-spectral matrix of
/// `signals` signals needs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JointDropped {
    pub n_segments: usize,
    pub half_dof: f64,
    pub signals: usize,
}

/// The cost's jitter at the optimum: its standard deviation `sd_nats` over steps of `step_u`
/// (normalised units) either way along each coordinate, against the likelihood's rise
/// `rise_limit_nats` at an interval's edge (a profile's smallest rise limit, or 0.5 nats, a
/// quadratic likelihood's rise at 1σ, for the other interval methods).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Jitter {
    pub sd_nats: f64,
    pub step_u: f64,
    pub rise_limit_nats: f64,
}

/// The cost of one simulation of the optimum at one tolerance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TolerancePoint {
    pub rtol: f64,
    pub atol: f64,
    /// The fit's cost there: the recording's NLL above the saturated model's, nats.
    pub cost_nats: f64,
    /// Stick–slip and contact transitions of the simulation.
    pub transitions: usize,
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
            | JointSignalsDropped(_)
            | CostJitter(_)
            | DriveDeparts(_)
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
            JointSignalsDropped(_) => "joint_signals_dropped",
            CostJitter(_) => "cost_jitter",
            DriveDeparts(_) => "drive_departs",
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
