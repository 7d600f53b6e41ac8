//! Parallel tempering of the ensemble sampler ([`super::ensemble`]): one ensemble per inverse
//! temperature `β_0 = 1 > β_1 > … > β_{K−1}`, each sampling `β·ℓ(x) + π(x)` (`ℓ` the
//! log-likelihood, `π` the log-prior, which is not tempered), with swaps of whole positions between
//! neighbouring temperatures after every step (Earl & Deem 2005, *Phys. Chem. Chem. Phys.* 7:3910,
//! "Parallel tempering: theory, applications, and new perspectives", §2; the ensemble form of
//! Vousden, Farr & Mandel 2016, *MNRAS* 455:1919, §2, as ptemcee runs it).
//!
//! A hot ensemble sees a ridge of the likelihood `H` nats high as one of `β·H`: it crosses between
//! basins that the cold one, started in one of them, never leaves, and the swaps hand its points
//! down the ladder. A swap of walker `i` at `β_t` with walker `j` at `β_{t+1}` is accepted with
//! probability `min(1, exp((β_t − β_{t+1})(ℓ_j − ℓ_i)))`, which leaves the product of the
//! tempered densities invariant, so the cold ensemble (`β = 1`) still samples the posterior.
//!
//! The ladder is geometric ([`geometric_ladder`]): `β_t = r^t`. Vousden et al. (§3.1) start from a
//! ratio `1 + √(2/d)` between neighbouring temperatures for a Gaussian in `d` dimensions, the ratio
//! at which neighbouring ensembles overlap enough to swap.

use super::ensemble::{Chains, EnsembleSettings, PosteriorError, stretch_factor};
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

/// The inverse temperatures of a geometric ladder of `k` rungs for a `d`-dimensional density:
/// `β_t = (1 + √(2/d))^(−t)`, `t = 0 … k−1` (Vousden, Farr & Mandel 2016, §3.1). One rung is the
/// untempered ensemble alone.
pub fn geometric_ladder(k: usize, d: usize) -> Vec<f64> {
    let ratio = 1.0 + (2.0 / d.max(1) as f64).sqrt();
    (0..k.max(1)).map(|t| ratio.powi(-(t as i32))).collect()
}

/// What a tempered run returns: the cold ensemble's chains and how often neighbours swapped.
#[derive(Debug, Clone, PartialEq)]
pub struct TemperedChains {
    /// The `β = 1` ensemble: positions, its log densities (`ℓ + π`), its accepted stretch moves.
    /// Its `evaluations` count every log-density evaluation of every ensemble.
    pub cold: Chains,
    /// The inverse temperatures, coldest first.
    pub betas: Vec<f64>,
    /// Swaps accepted between rung `t` and `t + 1`, over all steps (one is proposed per walker
    /// and step).
    pub swaps_accepted: Vec<usize>,
}

impl TemperedChains {
    /// Accepted over proposed swaps between each pair of neighbouring rungs.
    pub fn swap_fractions(&self) -> Vec<f64> {
        let proposed = (self.cold.walkers() * self.cold.steps()).max(1) as f64;
        self.swaps_accepted
            .iter()
            .map(|&a| a as f64 / proposed)
            .collect()
    }
}

/// One walker's state: position, log-likelihood `ℓ` and log-prior `π` (both −∞ outside the support).
#[derive(Debug, Clone)]
struct Walker {
    x: Vec<f64>,
    ell: f64,
    pi: f64,
}

impl Walker {
    fn density(&self, beta: f64) -> f64 {
        if self.ell == f64::NEG_INFINITY || self.pi == f64::NEG_INFINITY {
            f64::NEG_INFINITY
        } else {
            beta * self.ell + self.pi
        }
    }
}

/// Runs `betas.len()` ensembles of `settings.walkers` walkers each for `settings.steps` steps, every
/// one starting from `start`, on `β·ℓ + π` with `(ℓ, π) = log_parts(x)` (NaN counts as −∞), with a
/// round of swaps between neighbouring rungs after every step. `betas` must start at 1 and
/// decrease. `on_step(step)` is called after each step; `false` ends the run there.
///
/// Deterministic for a seed whatever the number of threads: proposals, acceptances and swaps are
/// drawn serially; the log densities of a half-step of every rung are evaluated in parallel.
///
/// # Errors
/// [`PosteriorError`] as [`super::sample`], and [`PosteriorError::Ladder`] for a ladder that does
/// not start at 1 or does not decrease.
pub fn sample_tempered<F>(
    log_parts: F,
    start: Vec<Vec<f64>>,
    settings: &EnsembleSettings,
    betas: &[f64],
    mut on_step: impl FnMut(usize) -> bool,
) -> Result<TemperedChains, PosteriorError>
where
    F: Fn(&[f64]) -> (f64, f64) + Sync,
{
    let n = start.len();
    let d = start.first().map_or(0, Vec::len);
    if n % 2 == 1 || n < 2 * d.max(1) || n != settings.walkers {
        return Err(PosteriorError::Walkers {
            walkers: n.max(settings.walkers),
            dim: d,
        });
    }
    let a = settings.stretch;
    if a.is_nan() || a <= 1.0 {
        return Err(PosteriorError::Stretch { stretch: a });
    }
    let ladder_ok = betas.first() == Some(&1.0)
        && betas.windows(2).all(|w| w[1] < w[0])
        && betas.iter().all(|b| *b > 0.0);
    if !ladder_ok {
        return Err(PosteriorError::Ladder {
            betas: betas.to_vec(),
        });
    }
    let eval = |x: &[f64]| {
        let (ell, pi) = log_parts(x);
        let clean = |v: f64| if v.is_nan() { f64::NEG_INFINITY } else { v };
        (clean(ell), clean(pi))
    };
    let first = start_walkers(&eval, start)?;
    let k = betas.len();
    let mut rungs: Vec<Vec<Walker>> = vec![first; k];
    let mut cold = Chains {
        positions: Vec::with_capacity(settings.steps),
        log_density: Vec::with_capacity(settings.steps),
        accepted: 0,
        evaluations: n,
    };
    let mut swaps_accepted = vec![0; k - 1];
    let mut rng = rand::rngs::StdRng::seed_from_u64(settings.seed);
    let half = n / 2;
    for step in 0..settings.steps {
        for (moving, other) in [(0..half, half..n), (half..n, 0..half)] {
            let proposals: Vec<(usize, usize, f64, Vec<f64>)> = (0..k)
                .flat_map(|t| moving.clone().map(move |w| (t, w)))
                .map(|(t, w)| {
                    let j = rng.random_range(other.clone());
                    let z = stretch_factor(a, rng.random::<f64>());
                    let (xj, xw) = (&rungs[t][j].x, &rungs[t][w].x);
                    let y = xj.iter().zip(xw).map(|(p, q)| p + z * (q - p)).collect();
                    (t, w, z, y)
                })
                .collect();
            let parts: Vec<(f64, f64)> = proposals.par_iter().map(|(.., y)| eval(y)).collect();
            cold.evaluations += proposals.len();
            for ((t, w, z, y), (ell, pi)) in proposals.into_iter().zip(parts) {
                let new = Walker { x: y, ell, pi };
                let (lq, lp) = (new.density(betas[t]), rungs[t][w].density(betas[t]));
                let log_ratio = (d as f64 - 1.0) * z.ln() + lq - lp;
                let u: f64 = rng.random();
                if lq.is_finite() && u.ln() < log_ratio {
                    rungs[t][w] = new;
                    if t == 0 {
                        cold.accepted += 1;
                    }
                }
            }
        }
        swap_round(&mut rungs, betas, &mut rng, &mut swaps_accepted);
        cold.positions
            .push(rungs[0].iter().map(|w| w.x.clone()).collect());
        cold.log_density
            .push(rungs[0].iter().map(|w| w.density(1.0)).collect());
        if !on_step(step) {
            break;
        }
    }
    Ok(TemperedChains {
        cold,
        betas: betas.to_vec(),
        swaps_accepted,
    })
}

/// The starting walkers: `start` evaluated, points without a finite density replaced by copies
/// of finite ones in turn (as [`super::sample`] does).
fn start_walkers(
    eval: &(impl Fn(&[f64]) -> (f64, f64) + Sync),
    start: Vec<Vec<f64>>,
) -> Result<Vec<Walker>, PosteriorError> {
    let n = start.len();
    let mut walkers: Vec<Walker> = start
        .into_par_iter()
        .map(|x| {
            let (ell, pi) = eval(&x);
            Walker { x, ell, pi }
        })
        .collect();
    let finite: Vec<usize> = (0..n)
        .filter(|&w| walkers[w].density(1.0).is_finite())
        .collect();
    if 2 * finite.len() < n {
        return Err(PosteriorError::Start {
            finite: finite.len(),
            walkers: n,
        });
    }
    let infinite: Vec<usize> = (0..n)
        .filter(|&w| !walkers[w].density(1.0).is_finite())
        .collect();
    for (m, w) in infinite.into_iter().enumerate() {
        walkers[w] = walkers[finite[m % finite.len()]].clone();
    }
    Ok(walkers)
}

/// One round of swaps, from the hottest pair of rungs down to the coldest: each walker of rung
/// `t + 1` is paired with a walker of rung `t` (a random permutation) and the two exchange
/// places with probability `min(1, exp((β_t − β_{t+1})(ℓ_{t+1} − ℓ_t)))`.
fn swap_round(
    rungs: &mut [Vec<Walker>],
    betas: &[f64],
    rng: &mut impl Rng,
    accepted: &mut [usize],
) {
    let n = rungs.first().map_or(0, Vec::len);
    for t in (0..rungs.len().saturating_sub(1)).rev() {
        let mut partner: Vec<usize> = (0..n).collect();
        // Fisher–Yates, drawn from the run's generator so that the run stays reproducible.
        for i in (1..n).rev() {
            partner.swap(i, rng.random_range(0..=i));
        }
        let d_beta = betas[t] - betas[t + 1];
        let (cold, hot) = rungs.split_at_mut(t + 1);
        let (cold, hot) = (&mut cold[t], &mut hot[0]);
        for (i, &j) in partner.iter().enumerate() {
            let log_ratio = d_beta * (hot[i].ell - cold[j].ell);
            let u: f64 = rng.random();
            if log_ratio.is_nan() || u.ln() >= log_ratio {
                continue;
            }
            std::mem::swap(&mut hot[i], &mut cold[j]);
            accepted[t] += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::posterior::ensemble::ball;

    fn settings(walkers: usize, steps: usize, seed: u64) -> EnsembleSettings {
        EnsembleSettings::new(walkers, steps, seed)
    }

    /// A mixture of two unit-variance Gaussians at x = ∓8 in the first coordinate, weights
    /// `w_left` and `1 − w_left`, a standard normal in the second: a ridge of about
    /// 32 nats (= 8²/2) between two basins. `(ℓ, π)` with a flat prior.
    fn two_basins(w_left: f64) -> impl Fn(&[f64]) -> (f64, f64) + Sync {
        move |x: &[f64]| {
            let g = |m: f64| (-(x[0] - m).powi(2) / 2.0).exp();
            let ell = (w_left * g(-8.0) + (1.0 - w_left) * g(8.0)).ln() - x[1] * x[1] / 2.0;
            (ell, 0.0)
        }
    }

    /// Share of the cold ensemble's points after `burn_in` in the left basin (x < 0).
    fn left_share(c: &Chains, burn_in: usize) -> f64 {
        let xs: Vec<f64> = c.coordinate(0, burn_in).concat();
        xs.iter().filter(|x| **x < 0.0).count() as f64 / xs.len() as f64
    }

    #[test]
    fn the_ladder_is_geometric_with_the_overlap_ratio() {
        // Closed form: d = 2 gives the ratio 1 + √(2/2) = 2: β = 1, 1/2, 1/4.
        assert_eq!(geometric_ladder(3, 2), vec![1.0, 0.5, 0.25]);
        assert_eq!(geometric_ladder(1, 4), vec![1.0]);
        let l = geometric_ladder(5, 4);
        assert!((l[1] - 1.0 / (1.0 + 0.5f64.sqrt())).abs() < 1e-15, "{l:?}");
    }

    #[test]
    fn tempering_finds_both_basins_with_their_weights() {
        // Closed form: the left basin holds w_left = 0.3 of the mass. Every walker starts in the
        // right basin; the untempered ensemble stays there (its share of the left basin is 0 to
        // within a few points), the tempered one reaches the weight within its Monte-Carlo error.
        let start = ball(&[8.0, 0.0], 0.5, 16, 3);
        let (steps, burn) = (4000, 1000);
        let plain = crate::posterior::sample(
            |x: &[f64]| two_basins(0.3)(x).0,
            start.clone(),
            &settings(16, steps, 11),
            |_| true,
        )
        .unwrap();
        assert!(
            left_share(&plain, burn) < 0.02,
            "{}",
            left_share(&plain, burn)
        );
        let betas = geometric_ladder(6, 2);
        let pt = sample_tempered(
            two_basins(0.3),
            start,
            &settings(16, steps, 11),
            &betas,
            |_| true,
        )
        .unwrap();
        let share = left_share(&pt.cold, burn);
        // The share's Monte-Carlo error: the basin label's autocorrelation time from the chains.
        let labels: Vec<Vec<f64>> = pt
            .cold
            .coordinate(0, burn)
            .into_iter()
            .map(|w| w.iter().map(|x| f64::from(u8::from(*x < 0.0))).collect())
            .collect();
        let slices: Vec<&[f64]> = labels.iter().map(Vec::as_slice).collect();
        let tau = crate::posterior::diagnostics::integrated_autocorr_time(&slices);
        let ess = (16 * (steps - burn)) as f64 / tau;
        let se = (0.3 * 0.7 / ess).sqrt();
        assert!((share - 0.3).abs() < 4.0 * se, "share {share}, ESS {ess}");
        assert!(
            pt.swap_fractions().iter().all(|f| *f > 0.1),
            "{:?}",
            pt.swap_fractions()
        );
        assert_eq!(pt.cold.evaluations, 16 + 6 * 16 * steps);
    }

    #[test]
    fn one_rung_is_the_plain_ensemble_and_bad_ladders_are_refused() {
        let gauss = |x: &[f64]| (-x.iter().map(|v| v * v).sum::<f64>() / 2.0, 0.0);
        let start = ball(&[0.0; 2], 1.0, 8, 4);
        let pt =
            sample_tempered(gauss, start.clone(), &settings(8, 200, 4), &[1.0], |_| true).unwrap();
        assert!(pt.swaps_accepted.is_empty());
        let again =
            sample_tempered(gauss, start.clone(), &settings(8, 200, 4), &[1.0], |_| true).unwrap();
        assert_eq!(pt, again);
        for bad in [
            vec![0.5, 0.25],
            vec![1.0, 1.0],
            vec![1.0, 0.5, 0.7],
            vec![1.0, 0.0],
        ] {
            let err = sample_tempered(gauss, start.clone(), &settings(8, 10, 4), &bad, |_| true);
            assert_eq!(err, Err(PosteriorError::Ladder { betas: bad.clone() }));
        }
    }

    #[test]
    fn the_prior_is_not_tempered() {
        // Closed form: a flat likelihood (ℓ = 0) under a N(2, 1) prior: every rung samples the
        // prior itself, so the cold ensemble's mean is 2 and its variance 1 whatever the ladder.
        let parts = |x: &[f64]| (0.0, -(x[0] - 2.0).powi(2) / 2.0);
        let pt = sample_tempered(
            parts,
            ball(&[2.0], 0.5, 8, 1),
            &settings(8, 3000, 2),
            &geometric_ladder(3, 1),
            |_| true,
        )
        .unwrap();
        let xs: Vec<f64> = pt.cold.coordinate(0, 500).concat();
        let n = xs.len() as f64;
        let mean = xs.iter().sum::<f64>() / n;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        assert!((mean - 2.0).abs() < 0.1, "{mean}");
        assert!((var - 1.0).abs() < 0.15, "{var}");
    }
}
