//! Convergence diagnostics of a set of chains (an ensemble's walkers after burn-in): the split
//! potential scale reduction R̂ and the integrated autocorrelation time, whence the effective
//! sample size.

/// Split R̂ (Gelman et al. 2013, *Bayesian Data Analysis*, 3rd ed., §11.4, eq. 11.1–11.4): each
/// chain is cut into halves, giving `m` chains of `n` draws; with `B` the between-chain and `W` the
/// mean within-chain variance, `var⁺ = (n − 1)/n·W + B/n` and `R̂ = √(var⁺/W)`. Near 1 when the
/// chains sample the same distribution; larger when they have not mixed (the halves tell a drift
/// within a chain). NaN with fewer than two draws per half or no within-chain variance.
pub fn split_rhat(chains: &[&[f64]]) -> f64 {
    let n = chains.iter().map(|c| c.len()).min().unwrap_or(0) / 2;
    if n < 2 {
        return f64::NAN;
    }
    let halves: Vec<&[f64]> = chains
        .iter()
        .flat_map(|c| {
            let c = &c[c.len() - 2 * n..];
            [&c[..n], &c[n..]]
        })
        .collect();
    let m = halves.len() as f64;
    let nf = n as f64;
    let means: Vec<f64> = halves.iter().map(|h| h.iter().sum::<f64>() / nf).collect();
    let grand = means.iter().sum::<f64>() / m;
    let b = nf / (m - 1.0) * means.iter().map(|x| (x - grand).powi(2)).sum::<f64>();
    let w = halves
        .iter()
        .zip(&means)
        .map(|(h, mu)| h.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / (nf - 1.0))
        .sum::<f64>()
        / m;
    if w <= 0.0 {
        return f64::NAN;
    }
    (((nf - 1.0) / nf * w + b / nf) / w).sqrt()
}

/// The window constant of [`integrated_autocorr_time`]: the sum stops at the first lag
/// `M ≥ c·τ(M)` (Sokal 1997, "Monte Carlo methods in statistical mechanics", §3; emcee's default).
pub const AUTOCORR_WINDOW_C: f64 = 5.0;

/// The integrated autocorrelation time `τ = 1 + 2 Σ_{t=1}^{M} ρ(t)` of chains of one coordinate,
/// steps: `ρ` the autocorrelation averaged over the chains (each about its own mean, as emcee
/// does for an ensemble: Foreman-Mackey et al. 2013, §4; Goodman & Weare 2010, §5), the window `M`
/// chosen automatically as the first lag with `M ≥ `[`AUTOCORR_WINDOW_C`]`·τ(M)` (Sokal 1997).
/// The chains then hold about `n/τ` independent draws each. At least 1; NaN for chains shorter
/// than two steps or without variance. An estimate from chains shorter than about 50 τ is
/// itself uncertain (emcee's advice).
pub fn integrated_autocorr_time(chains: &[&[f64]]) -> f64 {
    let n = chains.iter().map(|c| c.len()).min().unwrap_or(0);
    if n < 2 {
        return f64::NAN;
    }
    let centred: Vec<Vec<f64>> = chains
        .iter()
        .map(|c| {
            let mu = c[..n].iter().sum::<f64>() / n as f64;
            c[..n].iter().map(|x| x - mu).collect()
        })
        .collect();
    let acov = |c: &[f64], t: usize| {
        c[..n - t]
            .iter()
            .zip(&c[t..])
            .map(|(a, b)| a * b)
            .sum::<f64>()
            / n as f64
    };
    let var: Vec<f64> = centred.iter().map(|c| acov(c, 0)).collect();
    let used: Vec<(&Vec<f64>, f64)> = centred.iter().zip(var).filter(|(_, v)| *v > 0.0).collect();
    if used.is_empty() {
        return f64::NAN;
    }
    let mut tau = 1.0;
    for t in 1..n {
        let rho = used.iter().map(|(c, v)| acov(c, t) / v).sum::<f64>() / used.len() as f64;
        tau += 2.0 * rho;
        if t as f64 >= AUTOCORR_WINDOW_C * tau {
            break;
        }
    }
    tau.max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn split_rhat_matches_a_hand_computation() {
        // Chains [1, 2, 3, 4] and [2, 2, 2, 2] split into [1, 2], [3, 4], [2, 2], [2, 2]: n = 2,
        // m = 4, means 1.5, 3.5, 2, 2 (grand 2.25), B = 2/3·2.25 = 1.5, W = (0.5 + 0.5)/4 = 0.25,
        // var⁺ = 0.5·0.25 + 1.5/2 = 0.875, R̂ = √3.5.
        let r = split_rhat(&[&[1.0, 2.0, 3.0, 4.0], &[2.0, 2.0, 2.0, 2.0]]);
        assert!((r - 3.5f64.sqrt()).abs() < 1e-12, "{r}");
        assert!(split_rhat(&[&[1.0, 2.0, 3.0]]).is_nan());
    }

    /// `chains` AR(1) chains `x_t = φ x_{t−1} + e_t` of `n` steps from their stationary law.
    fn ar1(phi: f64, chains: usize, n: usize, offsets: &[f64]) -> Vec<Vec<f64>> {
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        (0..chains)
            .map(|c| {
                let mut x: f64 =
                    rng.sample::<f64, _>(rand_distr::StandardNormal) / (1.0 - phi * phi).sqrt();
                (0..n)
                    .map(|_| {
                        x = phi * x + rng.sample::<f64, _>(rand_distr::StandardNormal);
                        x + offsets[c % offsets.len()]
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn an_ar1_chain_has_its_closed_form_autocorrelation_time() {
        // Closed form: AR(1) with coefficient φ has ρ(t) = φ^t, so τ = (1 + φ)/(1 − φ): 3 for
        // φ = 0.5, 19 for φ = 0.9. The windowed estimate is within a few per cent on 32 × 4000
        // steps (its truncation bias is O(φ^M), its noise about √(2(2M+1)/N)·τ, Sokal 1997).
        for (phi, want) in [(0.5, 3.0), (0.9, 19.0)] {
            let c = ar1(phi, 32, 4000, &[0.0]);
            let s: Vec<&[f64]> = c.iter().map(Vec::as_slice).collect();
            let tau = integrated_autocorr_time(&s);
            assert!(
                (tau / want - 1.0).abs() < 0.06,
                "φ {phi}: τ {tau}, want {want}"
            );
            // Well-mixed chains of one law: R̂ within 1.01 of 1.
            let r = split_rhat(&s);
            assert!((r - 1.0).abs() < 0.01, "R̂ {r}");
        }
        // Independent draws: τ = 1.
        let c = ar1(0.0, 16, 2000, &[0.0]);
        let s: Vec<&[f64]> = c.iter().map(Vec::as_slice).collect();
        assert!((integrated_autocorr_time(&s) - 1.0).abs() < 0.1);
    }

    #[test]
    fn chains_stuck_apart_have_a_large_rhat() {
        // Half the chains offset by 2. Closed form for long chains: W is the AR(1) variance
        // 1/(1 − φ²) = 4/3; the 32 half-chains' means lie ±1 from the grand mean, so
        // B/n = 32/31; R̂ = √((W + B/n)/W) = √(1 + 0.774) = 1.332.
        let c = ar1(0.5, 16, 2000, &[0.0, 2.0]);
        let s: Vec<&[f64]> = c.iter().map(Vec::as_slice).collect();
        let r = split_rhat(&s);
        assert!((r - 1.332).abs() < 0.03, "R̂ {r}");
    }
}
