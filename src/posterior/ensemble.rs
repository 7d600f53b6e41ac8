//! The affine-invariant ensemble sampler with the stretch move (Goodman & Weare 2010, *Commun.
//! Appl. Math. Comput. Sci.* 5:1, 65–80, §3 and eq. 7–9), in the parallel form of emcee
//! (Foreman-Mackey, Hogg, Lang & Goodman 2013, *PASP* 125:306, Algorithm 3): the walkers are split
//! into two halves, and each walker of one half moves along the line through a random walker of
//! the other half, so that a half's log densities are evaluated in parallel (rayon).
//!
//! A proposal for walker `X_k` from a walker `X_j` of the other half is
//! `Y = X_j + Z·(X_k − X_j)` with `Z` drawn from `g(z) ∝ 1/√z` on `[1/a, a]` (eq. 9, `a` the
//! stretch scale, 2 by default); it is accepted with probability
//! `min(1, Z^{d−1} p(Y)/p(X_k))` (eq. 7), which leaves `p` invariant. The sampler is unchanged by
//! any affine map of the coordinates, so a correlated or badly scaled density costs it no more
//! than a round one.

use rand::{Rng, SeedableRng};

/// What the sampler cannot run with.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum PosteriorError {
    /// The stretch move needs at least two walkers per dimension, and an even number of them (two
    /// halves of equal size).
    #[error(
        "{walkers} walkers for {dim} parameters: the ensemble sampler needs an even number, at least {}",
        2 * (*dim).max(1)
    )]
    Walkers { walkers: usize, dim: usize },
    /// Fewer than half the starting points have a finite log density (e.g. their simulations
    /// failed).
    #[error(
        "{finite} of {walkers} starting points of the ensemble have a finite log density; at least half are needed"
    )]
    Start { finite: usize, walkers: usize },
    /// The stretch scale `a` must exceed 1.
    #[error("stretch scale {stretch}: it must be greater than 1")]
    Stretch { stretch: f64 },
    /// A tempering ladder's inverse temperatures must start at 1 and decrease, all above 0.
    #[error(
        "tempering ladder {betas:?}: the inverse temperatures must start at 1 and decrease, all above 0"
    )]
    Ladder { betas: Vec<f64> },
}

impl From<PosteriorError> for crate::Error {
    fn from(e: PosteriorError) -> Self {
        let input = matches!(
            e,
            PosteriorError::Walkers { .. }
                | PosteriorError::Stretch { .. }
                | PosteriorError::Ladder { .. }
        );
        crate::Error::stage(e, input)
    }
}

/// How the ensemble runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnsembleSettings {
    /// Walkers (even, at least twice the dimension).
    pub walkers: usize,
    /// Steps of every walker.
    pub steps: usize,
    /// The stretch move's scale `a` (Goodman & Weare's and emcee's default: 2).
    pub stretch: f64,
    /// Seed of the proposals and acceptances.
    pub seed: u64,
}

impl EnsembleSettings {
    /// `walkers` × `steps` with the stretch scale 2 (Goodman & Weare's and emcee's default).
    pub fn new(walkers: usize, steps: usize, seed: u64) -> Self {
        EnsembleSettings {
            walkers,
            steps,
            stretch: 2.0,
            seed,
        }
    }
}

/// The walkers' positions and log densities after each step.
#[derive(Debug, Clone, PartialEq)]
pub struct Chains {
    /// `positions[step][walker]`: the walker's point after `step + 1` steps.
    pub positions: Vec<Vec<Vec<f64>>>,
    /// `log_density[step][walker]` at that point.
    pub log_density: Vec<Vec<f64>>,
    /// Proposals accepted, over all steps.
    pub accepted: usize,
    /// Log-density evaluations (starting points included).
    pub evaluations: usize,
}

impl Chains {
    /// Steps made.
    pub fn steps(&self) -> usize {
        self.positions.len()
    }

    /// Walkers.
    pub fn walkers(&self) -> usize {
        self.positions.first().map_or(0, Vec::len)
    }

    /// Accepted over proposed (one proposal per walker and step).
    pub fn acceptance_fraction(&self) -> f64 {
        self.accepted as f64 / (self.steps() * self.walkers()).max(1) as f64
    }

    /// Coordinate `i` of every walker's chain from step `from` on: one vector per walker.
    pub fn coordinate(&self, i: usize, from: usize) -> Vec<Vec<f64>> {
        (0..self.walkers())
            .map(|w| {
                self.positions
                    .iter()
                    .skip(from)
                    .map(|step| step[w][i])
                    .collect()
            })
            .collect()
    }
}

/// `walkers` points `center + L·z`, `z` standard normal (seeded by `seed`), each pulled halfway
/// back to `center` (up to 30 times) until `inside` holds: the usual start of an ensemble, a
/// Gaussian ball around an optimum with the spread `L Lᵀ`.
pub fn gaussian_ball_with(
    center: &[f64],
    l: &nalgebra::DMatrix<f64>,
    walkers: usize,
    seed: u64,
    inside: impl Fn(&[f64]) -> bool,
) -> Vec<Vec<f64>> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let d = center.len();
    (0..walkers)
        .map(|_| {
            let z = nalgebra::DVector::from_fn(d, |_, _| rng.sample(rand_distr::StandardNormal));
            let mut offset = l * z;
            let mut x: Vec<f64> = center
                .iter()
                .zip(offset.iter())
                .map(|(c, o)| c + o)
                .collect();
            for _ in 0..30 {
                if inside(&x) {
                    break;
                }
                offset /= 2.0;
                x = center
                    .iter()
                    .zip(offset.iter())
                    .map(|(c, o)| c + o)
                    .collect();
            }
            x
        })
        .collect()
}

/// [`gaussian_ball_with`] of radius (1σ) `radius` in every coordinate, no constraint.
pub fn ball(center: &[f64], radius: f64, walkers: usize, seed: u64) -> Vec<Vec<f64>> {
    let l = nalgebra::DMatrix::identity(center.len(), center.len()) * radius;
    gaussian_ball_with(center, &l, walkers, seed, |_| true)
}

/// Draws from `g(z) ∝ 1/√z` on `[1/a, a]` by inverting its distribution function:
/// `z = ((a − 1)·r + 1)²/a`, `r` uniform on `[0, 1)` (Goodman & Weare 2010, eq. 9).
pub(super) fn stretch_factor(a: f64, r: f64) -> f64 {
    ((a - 1.0) * r + 1.0).powi(2) / a
}

/// Runs the ensemble from `start` (one point per walker) for `settings.steps` steps on
/// `log_density` (NaN counts as −∞: a point outside the support, a failed simulation). Starting
/// points without a finite log density are replaced by copies of finite ones, in turn (the copies
/// part at their first accepted move). `on_step(step)` is called after each step; returning
/// `false` ends the run there (the chains hold the steps made).
///
/// Deterministic for a seed whatever the number of threads: proposals and acceptances are drawn
/// serially, only the log densities are evaluated in parallel.
///
/// # Errors
/// [`PosteriorError`] for an odd or too small ensemble, a stretch scale ≤ 1, or fewer than half
/// the starting points finite.
pub fn sample<F>(
    log_density: F,
    start: Vec<Vec<f64>>,
    settings: &EnsembleSettings,
    on_step: impl FnMut(usize) -> bool,
) -> Result<Chains, PosteriorError>
where
    F: Fn(&[f64]) -> f64 + Sync,
{
    // One rung of the tempering ladder at β = 1 is this ensemble: β·ℓ + 0 = ℓ exactly, and a
    // single rung draws no swaps.
    let parts = |x: &[f64]| (log_density(x), 0.0);
    super::tempering::sample_tempered(parts, start, settings, &[1.0], on_step).map(|r| r.cold)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(walkers: usize, steps: usize, seed: u64) -> EnsembleSettings {
        EnsembleSettings::new(walkers, steps, seed)
    }

    /// Mean and covariance of all walkers' points after `burn_in`.
    fn moments(c: &Chains, burn_in: usize) -> (Vec<f64>, Vec<Vec<f64>>) {
        let pts: Vec<&Vec<f64>> = c.positions[burn_in..].iter().flatten().collect();
        let d = pts[0].len();
        let n = pts.len() as f64;
        let mean: Vec<f64> = (0..d)
            .map(|i| pts.iter().map(|p| p[i]).sum::<f64>() / n)
            .collect();
        let cov = (0..d)
            .map(|i| {
                (0..d)
                    .map(|j| {
                        pts.iter()
                            .map(|p| (p[i] - mean[i]) * (p[j] - mean[j]))
                            .sum::<f64>()
                            / (n - 1.0)
                    })
                    .collect()
            })
            .collect();
        (mean, cov)
    }

    #[test]
    fn the_stretch_factor_has_the_density_one_over_root_z() {
        // Closed form: g(z) ∝ 1/√z on [1/a, a] has CDF (√z − 1/√a)/(√a − 1/√a), so the
        // inverse maps r = 0, 1/2, 1 to 1/a, ((a + 1)/2)²/a, a.
        let a: f64 = 2.0;
        assert!((stretch_factor(a, 0.0) - 0.5).abs() < 1e-15);
        assert!((stretch_factor(a, 1.0) - 2.0).abs() < 1e-15);
        let mid = stretch_factor(a, 0.5);
        let cdf = (mid.sqrt() - 1.0 / a.sqrt()) / (a.sqrt() - 1.0 / a.sqrt());
        assert!((cdf - 0.5).abs() < 1e-15, "{cdf}");
    }

    #[test]
    fn a_correlated_gaussian_is_sampled_with_its_mean_and_covariance() {
        // Closed form: N(μ, Σ) with μ = (1, −2), σ = (1, 3), ρ = 0.9, badly scaled and
        // correlated (the sampler is affine-invariant, so this costs it nothing).
        let (mu, s, rho) = ([1.0, -2.0], [1.0, 3.0], 0.9);
        let det = 1.0 - rho * rho;
        let log_p = |x: &[f64]| {
            let (a, b) = ((x[0] - mu[0]) / s[0], (x[1] - mu[1]) / s[1]);
            -(a * a - 2.0 * rho * a * b + b * b) / (2.0 * det)
        };
        let c = sample(
            log_p,
            ball(&[0.0, 0.0], 0.1, 32, 1),
            &settings(32, 3000, 5),
            |_| true,
        )
        .unwrap();
        let burn = 500;
        let (mean, cov) = moments(&c, burn);
        // Monte-Carlo error of each mean: σ/√ESS, the ESS from the chains' own autocorrelation.
        for i in 0..2 {
            let walks = c.coordinate(i, burn);
            let slices: Vec<&[f64]> = walks.iter().map(Vec::as_slice).collect();
            let tau = crate::posterior::diagnostics::integrated_autocorr_time(&slices);
            let ess = (32 * (3000 - burn)) as f64 / tau;
            assert!(ess > 1000.0, "ESS {ess}");
            assert!(
                (mean[i] - mu[i]).abs() < 4.0 * s[i] / ess.sqrt(),
                "mean {mean:?}, ESS {ess}"
            );
            // The variance's relative MC error is about √(2/ESS).
            let rel = cov[i][i] / (s[i] * s[i]) - 1.0;
            assert!(rel.abs() < 4.0 * (2.0 / ess).sqrt(), "cov {cov:?}");
        }
        let r = cov[0][1] / (cov[0][0] * cov[1][1]).sqrt();
        assert!((r - rho).abs() < 0.02, "ρ {r}");
        let f = c.acceptance_fraction();
        assert!((0.2..0.9).contains(&f), "acceptance {f}");
    }

    #[test]
    fn a_banana_density_has_its_known_marginals() {
        // x ~ N(0, 1), y | x ~ N(b·x², 0.5²) with b = 1: a curved ridge. Closed-form marginals:
        // x is N(0, 1) (quantiles 15.87/84.13 % at ∓1); y has mean b·E[x²] = 1 and variance
        // b²·Var(x²) + 0.25 = 2 + 0.25.
        let log_p = |v: &[f64]| -v[0] * v[0] / 2.0 - (v[1] - v[0] * v[0]).powi(2) / (2.0 * 0.25);
        let c = sample(
            log_p,
            ball(&[0.0, 0.0], 0.1, 40, 2),
            &settings(40, 5000, 9),
            |_| true,
        )
        .unwrap();
        let burn = 1000;
        let mut xs: Vec<f64> = c.coordinate(0, burn).concat();
        xs.sort_by(f64::total_cmp);
        let q = |p: f64| crate::spectrum::stats::quantile_sorted(&xs, p);
        assert!((q(0.158_655) + 1.0).abs() < 0.08, "{}", q(0.158_655));
        assert!((q(0.841_345) - 1.0).abs() < 0.08, "{}", q(0.841_345));
        let (mean, cov) = moments(&c, burn);
        assert!((mean[1] - 1.0).abs() < 0.1, "{mean:?}");
        assert!((cov[1][1] / 2.25 - 1.0).abs() < 0.15, "{cov:?}");
    }

    #[test]
    fn runs_are_reproducible_and_stoppable_and_bad_ensembles_are_refused() {
        let log_p = |x: &[f64]| -x.iter().map(|v| v * v).sum::<f64>() / 2.0;
        let run = |steps| {
            sample(
                log_p,
                ball(&[0.0; 3], 1.0, 8, 4),
                &settings(8, 50, 4),
                |s| s + 1 < steps,
            )
        };
        let (a, b) = (run(50).unwrap(), run(50).unwrap());
        assert_eq!(a, b);
        assert_eq!(run(20).unwrap().steps(), 20);
        assert_eq!(a.evaluations, 8 + 50 * 8);
        let err = sample(
            log_p,
            ball(&[0.0; 3], 1.0, 5, 4),
            &settings(5, 10, 4),
            |_| true,
        );
        assert_eq!(err, Err(PosteriorError::Walkers { walkers: 5, dim: 3 }));
        // A point outside the support at the start is replaced by a finite one.
        let positive = |x: &[f64]| if x[0] > 0.0 { 0.0 } else { f64::NEG_INFINITY };
        let mut start = ball(&[1.0], 0.1, 4, 1);
        start[1] = vec![-1.0];
        let c = sample(positive, start.clone(), &settings(4, 10, 1), |_| true).unwrap();
        assert!(c.positions.iter().flatten().all(|p| p[0] > 0.0));
        start[0] = vec![-1.0];
        start[2] = vec![-1.0];
        let err = sample(positive, start, &settings(4, 10, 1), |_| true);
        assert_eq!(
            err,
            Err(PosteriorError::Start {
                finite: 1,
                walkers: 4
            })
        );
    }
}
