//! A posterior sample of a fit's parameters: the affine-invariant ensemble sampler
//! ([`ensemble`], Goodman & Weare 2010), its convergence diagnostics ([`diagnostics`]: split R̂,
//! integrated autocorrelation time, effective sample size) and the summary a fit reports
//! ([`PosteriorSummary`]: quantile intervals, diagnostics, thinned draws for the corner plot).
//!
//! The sampler is generic over a log-density closure on `ℝᵈ`; what density the fit samples (its
//! likelihood, tempered, on the search's normalised coordinates) is the fit's business
//! (`crate::fit`, docs/uncertainty.md, "Uncertainty").

pub mod diagnostics;
pub mod ensemble;
pub mod tempering;

use crate::model::ParamId;
use crate::spectrum::stats::quantile_sorted;
use serde::{Deserialize, Serialize};

pub use ensemble::{Chains, EnsembleSettings, PosteriorError, sample};

/// The posterior's probability levels of each parameter's quantiles: the 95 % and the 68.27 %
/// central intervals and the median.
pub const QUANTILES: [f64; 5] = [0.025, 0.158_655, 0.5, 0.841_345, 0.975];

/// Above this fraction of its search range (normalised coordinates) a parameter's 95 % posterior
/// interval says the recording does not determine it: the posterior spans most of the range the
/// job allows, so the interval is the job's bounds, not the recording's information.
pub const UNDETERMINED_SPAN: f64 = 0.5;

/// Most draws a summary keeps for the corner plot (the chains are thinned evenly to this).
pub const MAX_KEPT_DRAWS: usize = 1000;

/// One parameter's posterior.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamPosterior {
    pub name: ParamId,
    /// The posterior's quantiles at [`QUANTILES`] (2.5, 15.87, 50, 84.13, 97.5 %), in the
    /// parameter's unit.
    pub quantiles: [f64; 5],
    /// Split R̂ over the walkers after burn-in ([`diagnostics::split_rhat`]).
    pub r_hat: f64,
    /// Integrated autocorrelation time of the walkers' chains, steps
    /// ([`diagnostics::integrated_autocorr_time`]).
    pub autocorr_steps: f64,
    /// Effective sample size: walkers × steps kept / autocorrelation time.
    pub ess: f64,
    /// Width of the 95 % interval as a fraction of the search range, in the search's normalised
    /// coordinates (log scale where the search's is).
    pub span_fraction: f64,
    /// False when `span_fraction` exceeds [`UNDETERMINED_SPAN`]: the recording does not
    /// determine the parameter within its bounds.
    pub determined: bool,
}

/// What a fit reports of its posterior sample.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PosteriorSummary {
    /// Walkers of the ensemble (its chains).
    pub walkers: usize,
    /// Steps each walker made, burn-in included.
    pub steps: usize,
    /// Steps discarded at the start of each chain.
    pub burn_in: usize,
    /// Accepted proposals over all proposals, burn-in included.
    pub acceptance_fraction: f64,
    /// The factor the log-likelihood was multiplied by before sampling
    /// (docs/uncertainty.md, "Posterior sample").
    pub tempering: f64,
    /// Log-density evaluations (model simulations), of every rung of a tempering ladder.
    pub evaluations: usize,
    /// The inverse temperatures of a parallel-tempered sample ([`tempering`]), coldest (1) first;
    /// empty for the plain ensemble. The quantiles are the β = 1 ensemble's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ladder: Vec<f64>,
    /// Accepted over proposed swaps between neighbouring rungs of the ladder.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub swap_fractions: Vec<f64>,
    pub parameters: Vec<ParamPosterior>,
    /// Up to [`MAX_KEPT_DRAWS`] draws after burn-in, thinned evenly, each in the parameters'
    /// order and units: the corner plot's points.
    pub draws: Vec<Vec<f64>>,
}

impl PosteriorSummary {
    /// The summary of `chains` after `burn_in` steps: each parameter's quantiles (mapped to its unit
    /// by `to_unit(i, x)`, which must be increasing in `x`), diagnostics, span of its 95 % interval
    /// over a search range of width `range_width` in the sampled coordinates, and thinned draws.
    /// `tempering` is recorded as given.
    pub fn new(
        names: &[ParamId],
        chains: &Chains,
        burn_in: usize,
        range_width: f64,
        tempering: f64,
        to_unit: impl Fn(usize, f64) -> f64,
    ) -> PosteriorSummary {
        let kept = chains.steps().saturating_sub(burn_in);
        let parameters = names
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let walks = chains.coordinate(i, burn_in);
                let mut all: Vec<f64> = walks.iter().flatten().copied().collect();
                all.sort_by(f64::total_cmp);
                let q = QUANTILES.map(|p| quantile_sorted(&all, p));
                let slices: Vec<&[f64]> = walks.iter().map(Vec::as_slice).collect();
                let tau = diagnostics::integrated_autocorr_time(&slices);
                let span_fraction = (q[4] - q[0]) / range_width;
                ParamPosterior {
                    name: *name,
                    quantiles: q.map(|x| to_unit(i, x)),
                    r_hat: diagnostics::split_rhat(&slices),
                    autocorr_steps: tau,
                    ess: (chains.walkers() * kept) as f64 / tau,
                    span_fraction,
                    determined: span_fraction <= UNDETERMINED_SPAN,
                }
            })
            .collect();
        let total = kept * chains.walkers();
        let stride = total.div_ceil(MAX_KEPT_DRAWS).max(1);
        let draws = (0..total)
            .step_by(stride)
            .map(|n| {
                let (step, walker) = (burn_in + n / chains.walkers(), n % chains.walkers());
                chains.positions[step][walker]
                    .iter()
                    .enumerate()
                    .map(|(i, x)| to_unit(i, *x))
                    .collect()
            })
            .collect();
        PosteriorSummary {
            walkers: chains.walkers(),
            steps: chains.steps(),
            burn_in,
            acceptance_fraction: chains.acceptance_fraction(),
            tempering,
            evaluations: chains.evaluations,
            ladder: Vec::new(),
            swap_fractions: Vec::new(),
            parameters,
            draws,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_density_over_the_box_is_not_determined_and_a_narrow_one_is() {
        // A uniform density on [0, 1]²: its 95 % interval is [0.025, 0.975] (span 0.95 > 0.5);
        // a Gaussian of σ 0.02 has span 4·0.0196·… ≈ 0.078.
        let settings = EnsembleSettings {
            walkers: 16,
            steps: 3000,
            stretch: 2.0,
            seed: 3,
        };
        let inside = |x: &[f64]| x.iter().all(|v| (0.0..=1.0).contains(v));
        let flat = |x: &[f64]| if inside(x) { 0.0 } else { f64::NEG_INFINITY };
        let start = ensemble::ball(&[0.5, 0.5], 0.01, 16, 1);
        let chains = sample(flat, start.clone(), &settings, |_| true).unwrap();
        let names = [ParamId::A, ParamId::C];
        let s = PosteriorSummary::new(&names, &chains, 500, 1.0, 1.0, |_, x| 10.0 * x);
        for p in &s.parameters {
            assert!(!p.determined, "{p:?}");
            // Uniform quantiles (×10 by `to_unit`): 0.25, 1.59, 5, 8.41, 9.75, within 4 of their
            // Monte-Carlo errors √(q(1 − q)/ESS)/f, f = 1 the uniform density.
            for (got, q) in p.quantiles.iter().zip(QUANTILES) {
                let se = 10.0 * (q * (1.0 - q) / p.ess).sqrt();
                assert!((got - 10.0 * q).abs() < 4.0 * se, "{p:?}");
            }
            assert!(p.ess > 300.0, "{p:?}");
        }
        assert!(s.draws.len() <= MAX_KEPT_DRAWS && s.draws.len() > 900);
        assert_eq!((s.walkers, s.steps, s.burn_in), (16, 3000, 500));
        let narrow = |x: &[f64]| {
            if inside(x) {
                -x.iter().map(|v| (v - 0.5).powi(2)).sum::<f64>() / (2.0 * 0.02 * 0.02)
            } else {
                f64::NEG_INFINITY
            }
        };
        let chains = sample(narrow, start, &settings, |_| true).unwrap();
        let s = PosteriorSummary::new(&names, &chains, 500, 1.0, 1.0, |_, x| x);
        for p in &s.parameters {
            assert!(
                p.determined && (p.span_fraction - 0.0784).abs() < 0.015,
                "{p:?}"
            );
        }
    }
}
