//! The sentence each of a fit's warnings renders ([`std::fmt::Display`] for [`FitWarning`], the
//! data type of [`crate::estimate::warning`]), beside the thresholds of the search, the intervals
//! and the model choice it quotes, and the result file's form of a fit's warnings ([`Warnings`]).
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
pub use crate::estimate::warning::{
    End, FAILED_ATTENTION_FRACTION, FAILED_WARN_FRACTION, FitWarning, Jitter, JointDropped,
    LineSource, SampledReason, Severity,
};
use crate::job::Candidate;
use crate::job::UncertaintyMethod;
use crate::likelihood::GoodnessOfFit;
use crate::likelihood::prior::PriorsReport;
use crate::likelihood::secant::FlatAxisReport;
use crate::model::ParamId;
use crate::spectrum::harmonics::LineOrigin;
use crate::uncertainty::intervals::{PROFILE_68_NATS, PROFILE_MAX_STEPS};
use serde::{Deserialize, Serialize};
use std::fmt;

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
            NoBladeModes { reason } => no_blade_modes(f, reason),
            JointSignalsDropped(d) => d.fmt(f),
            CostJitter(j) => j.fmt(f),
            DriveDeparts(c) => drive_departs(f, c),
            PriorConflict(c) => c.fmt(f),
            RigCurveConflict(c) => c.fmt(f),
            Text { text } => f.write_str(text),
        }
    }
}

/// [`FitWarning::DriveDeparts`]'s sentence: what departs, by how much, and what to do.
fn drive_departs(f: &mut fmt::Formatter<'_>, c: &crate::model::drive::DriveCheck) -> fmt::Result {
    let r = &c.reading;
    f.write_str("the tracked head departs from the drive the fit used:")?;
    let mut sep = " ";
    if c.harmonic_departs() {
        write!(
            f,
            "{sep}its speed's second harmonic is h = {:+.4} ± {} of aω against the fit's {:+.4}",
            r.speed_harmonic,
            crate::names::significant(r.speed_harmonic_se, 2),
            c.fitted_speed_harmonic
        )?;
        sep = "; ";
    }
    if c.amplitude_departs() {
        write!(
            f,
            "{sep}its amplitude is a = {:.4} ± {} mm against the blade file's {:.4} mm ({:+.1} %)",
            1e3 * r.amplitude_m,
            crate::names::significant(1e3 * r.amplitude_se_m, 2),
            1e3 * c.blade_amplitude_m,
            100.0 * (r.amplitude_m / c.blade_amplitude_m - 1.0)
        )?;
    }
    f.write_str(
        ": the model moves the head otherwise than the camera saw, and the friction law and the \
         neck absorb the difference; `[fit] drive = \"recording\"` takes the harmonic from the \
         recording, the blade file's `drive_a_m` and `drive_omega_rad_per_s` set the rest \
         (docs/fit.md, \"The drive\")",
    )
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
        crate::uncertainty::RHAT_LIMIT,
        crate::uncertainty::MIN_ESS
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

impl fmt::Display for JointDropped {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "[fit.likelihood] joint_signals were not read: a band's {} segments between lost \
             frames give ν/2 = {:.2} degrees of freedom, fewer than the {} signals' cross-spectral \
             matrix needs, so the fit reads its own signal alone (docs/likelihood.md, \"Several \
             signals\")",
            self.n_segments, self.half_dof, self.signals
        )
    }
}

/// [`FitWarning::NoBladeModes`]'s sentence.
fn no_blade_modes(f: &mut fmt::Formatter<'_>, reason: &str) -> fmt::Result {
    write!(f, "no blade modes at the fitted parameters: {reason}")
}

impl fmt::Display for Jitter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the cost at the optimum jitters by {:.2} nats (standard deviation) under steps of \
             {:e} in the normalised coordinates, more than the {:.2} nats the likelihood rises by \
             at an interval's edge: the slip grows an oscillation out of the integrator's \
             rounding, whose timing the spectra see, so the intervals and cost differences within \
             that jitter are read through it (a profile reads its rises between costs averaged \
             over each point's rounding draws; docs/likelihood.md, \"Jitter\")",
            self.sd_nats, self.step_u, self.rise_limit_nats
        )
    }
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
    use crate::likelihood::prior::ParamConflict;
    use crate::simulate::failure::FailureCause;
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

    /// A drive the head contradicts needs attention and says what departs and what to do: a
    /// second harmonic of −0.0436 of aω read to 6.9e-7 (dep_009's, docs/validation.md, "The drive
    /// read from the head") against the fit's 0; an amplitude 2 % off beside it. A harmonic
    /// 0.5 % off is within `HARMONIC_TOLERANCE` and says nothing.
    #[test]
    fn a_drive_the_head_contradicts_says_what_departs() {
        use crate::model::drive::{DriveCheck, DriveReading};
        let reading = DriveReading {
            amplitude_m: 0.102,
            amplitude_se_m: 4.2e-8,
            speed_harmonic: -0.043_624,
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
        assert!(check.harmonic_departs() && check.amplitude_departs());
        let w = FitWarning::DriveDeparts(check);
        assert_eq!(w.severity(), Severity::Attention);
        assert_eq!(w.kind(), "drive_departs");
        let text = w.to_string();
        for part in [
            "second harmonic is h = -0.0436 ± 6.9e-7 of aω against the fit's +0.0000",
            "amplitude is a = 102.0000 ± 4.2e-5 mm against the blade file's 100.0000 mm (+2.0 %)",
            "`[fit] drive = \"recording\"`",
        ] {
            assert!(text.contains(part), "{part} not in: {text}");
        }
        let small = DriveCheck {
            reading: DriveReading {
                speed_harmonic: -0.005,
                amplitude_m: 0.1,
                ..reading
            },
            ..check
        };
        assert!(!small.harmonic_departs() && !small.amplitude_departs());
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
