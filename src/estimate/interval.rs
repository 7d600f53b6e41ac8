//! A fitted parameter's interval and how it was obtained ([`Interval`], [`IntervalMethod`]), and the
//! fitted parameter that carries it ([`FittedParam`]): what the intervals compute and a fit's result
//! reports.

use crate::model::ParamId;
use serde::{Deserialize, Serialize};

/// A confidence interval of one fitted parameter, in the parameter's own unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    pub lo: f64,
    pub hi: f64,
    /// Coverage probability, e.g. 0.68 for a 1σ-equivalent interval.
    pub level: f64,
    /// How it was obtained.
    pub method: IntervalMethod,
    /// `[lo, hi]` of the method alone, when the interval was then widened to points the fit
    /// evaluated inside the parameter's profile region (the search's own near-best points,
    /// [`crate::uncertainty::widen_to_near_best`], or the shoulder's contact-moment ridge); absent when
    /// it was not widened.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub widened_from: Option<[f64; 2]>,
    /// `[lo, hi]` of the same method's 95 % interval, where it gives one: a profile walked on to
    /// the 95 % rise ([`crate::uncertainty::PROFILE_95_NATS`]·μ, widened alike to the search's
    /// points within it), a posterior sample's 2.5 % and 97.5 % quantiles. It contains `[lo, hi]`.
    /// Absent for Laplace and bootstrap intervals, whose 95 % interval is ±1.96σ of theirs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range_95: Option<[f64; 2]>,
}

/// How a confidence interval was obtained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum IntervalMethod {
    /// Profile likelihood ([`crate::uncertainty::profile_intervals_at`]): where the NLL, minimised over
    /// the other parameters, has risen by `rise_limit_nats` from the fit.
    Profile {
        /// The rise at the interval's ends, nats: 0.5·σ²_sandwich/σ²_Fisher of the parameter (0 in
        /// results that did not record it).
        #[serde(default)]
        rise_limit_nats: f64,
    },
    /// Basic parametric bootstrap ([`crate::uncertainty::bootstrap_intervals`]).
    Bootstrap {
        replicates: usize,
        /// White-noise σ added to each recording (the best-fit model's signal plus this noise),
        /// in the signal's unit, m; one per recording.
        noise_sigma_m: Vec<f64>,
        /// Each replicate re-ran the whole estimator (else: a Nelder–Mead polish from the optimum).
        full_refit: bool,
    },
    /// From the cost's curvature at the optimum.
    Curvature,
    /// The 15.87 % and 84.13 % quantiles of a posterior sample (`[fit.uncertainty] method = "mcmc"`,
    /// docs/uncertainty.md, "Uncertainty"; the sample and its diagnostics are the result's `posterior`).
    Mcmc {
        walkers: usize,
        steps: usize,
        burn_in: usize,
        /// The factor the log-likelihood was multiplied by.
        tempering: f64,
        /// Rungs of the parallel-tempering ladder (1: the plain ensemble).
        #[serde(default = "one_rung")]
        temperatures: usize,
    },
    /// Laplace's approximation: ±1σ of the estimate's sandwich covariance `F⁻¹ V F⁻¹` at the fit,
    /// with `F` the Fisher information of the recording's likelihood and `V` the variance of its
    /// gradient under the recording's noise ([`crate::search::evidence::at_fit`]), mapped through
    /// the search's coordinates.
    Laplace {
        /// Central-difference step of the Fisher information, normalised coordinates.
        fisher_step_u: f64,
        /// Noise replicates `V` was estimated from (0 when the result has none: `F⁻¹` alone).
        #[serde(default)]
        noise_replicates: usize,
        /// Half-span, in the whitened coordinates of `F⁻¹`, of the points whose Jacobians `F` and
        /// `V` average (0 when the result has none: the Jacobian at the fit alone).
        #[serde(default)]
        span_sigma: f64,
    },
}

impl IntervalMethod {
    /// Whether intervals of this method are widened to the points the search evaluated
    /// ([`crate::uncertainty::widen_to_near_best`]): Laplace and profile intervals; a posterior sample
    /// and a bootstrap cover the region themselves.
    pub fn widens_to_near_best(&self) -> bool {
        matches!(
            self,
            IntervalMethod::Laplace { .. } | IntervalMethod::Profile { .. }
        )
    }
}

impl std::fmt::Display for IntervalMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IntervalMethod::Profile { rise_limit_nats } if *rise_limit_nats > 0.0 => write!(
                f,
                "profile likelihood: where the NLL, minimised over the other parameters, has risen \
                 {rise_limit_nats:.3} nats from the fit (0.5·σ²_sandwich/σ²_Fisher)"
            ),
            IntervalMethod::Profile { .. } => f.write_str("profile likelihood"),
            IntervalMethod::Curvature => f.write_str("curvature"),
            IntervalMethod::Mcmc {
                walkers,
                steps,
                burn_in,
                tempering,
                temperatures,
            } => {
                write!(
                    f,
                    "posterior quantiles 15.87–84.13 % of an affine-invariant ensemble sample \
                     ({walkers} walkers × {steps} steps, {burn_in} burn-in) of the likelihood \
                     raised to the power {tempering:.3} (k/tr(F⁻¹V)), flat on the search's coordinates"
                )?;
                if *temperatures > 1 {
                    write!(f, ", parallel-tempered over {temperatures} temperatures")?;
                }
                Ok(())
            }
            IntervalMethod::Laplace {
                fisher_step_u,
                noise_replicates: 0,
                ..
            } => write!(
                f,
                "Laplace: ±1σ of the inverse Fisher information of the recording's likelihood alone (Gauss–Newton, central differences of {fisher_step_u} in the normalised coordinates)"
            ),
            IntervalMethod::Laplace {
                fisher_step_u,
                noise_replicates,
                span_sigma,
            } => {
                write!(
                    f,
                    "Laplace: ±1σ of the sandwich F⁻¹VF⁻¹ (F the Gauss–Newton Fisher information of the recording's likelihood, central differences of {fisher_step_u} in the normalised coordinates"
                )?;
                if *span_sigma > 0.0 {
                    write!(
                        f,
                        ", averaged with those at the 2k points u ± {span_sigma}·L eᵢ, L the Cholesky factor of F⁻¹"
                    )?;
                }
                write!(
                    f,
                    "; V the variance of its gradient over {noise_replicates} replicates of the recording's tracking noise)"
                )
            }
            IntervalMethod::Bootstrap {
                replicates,
                noise_sigma_m,
                full_refit,
            } => write!(
                f,
                "basic parametric bootstrap, {replicates} replicates (best-fit model + white noise σ = {} from the measured floor{}; {})",
                noise_sigma_m
                    .iter()
                    .map(|s| format!("{s:.3e}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                if noise_sigma_m.len() > 1 {
                    "s of the recordings"
                } else {
                    ""
                },
                if *full_refit {
                    "full refit"
                } else {
                    "Nelder–Mead polish from the optimum"
                }
            ),
        }
    }
}

/// A fitted parameter with its uncertainty and, for synthetic data, the truth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedParam {
    pub name: ParamId,
    pub value: f64,
    pub lower: f64,
    pub upper: f64,
    /// 1σ of the estimate: with a likelihood, from the sandwich covariance of
    /// [`crate::search::evidence::at_fit`]; for a target job, from the cost's curvature (indicative).
    pub std_error: f64,
    /// 1σ from the likelihood's Fisher information alone (`F⁻¹`, the width of the likelihood's
    /// bowl), when the fit has a likelihood; `std_error` is the estimate's spread, the sandwich
    /// `F⁻¹ V F⁻¹` (docs/uncertainty.md, "Uncertainty").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fisher_std_error: Option<f64>,
    /// `std_error` over the sandwich's 1σ with the tracking noise's variability alone: how much
    /// the trajectory's sensitivity to rounding widens the spread (1 where the motion does not
    /// depend on rounding; docs/uncertainty.md, "Jitter").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rounding_widening: Option<f64>,
    /// False when the data do not pin the parameter down (1σ wider than 10 % of its search range,
    /// or no positive curvature).
    pub determined: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub true_value: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rel_error: Option<f64>,
    /// Confidence interval, when the fit computed one (profile, bootstrap or curvature).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interval: Option<Interval>,
}

/// A result written before parallel tempering sampled with one rung.
fn one_rung() -> usize {
    1
}
