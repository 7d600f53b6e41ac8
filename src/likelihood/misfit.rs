//! Where a misfit lives: the bins of a band that carry its excess negative log-likelihood, as
//! frequency ranges a reader can look up on the spectrum.
//!
//! A Welch ordinate `P̂` with expectation `S` and `ν` equivalent degrees of freedom is
//! `S·χ²_ν/ν`, i.e. Gamma with shape `α = ν/2` and mean `S` ([`super::WelchLikelihood`]). Its NLL
//! above the saturated model (`S = P̂`) is the Whittle deviance of the bin,
//!
//! `d = α (r − 1 − ln r) / φ`, `r = P̂/S`,
//!
//! (`φ` the band's variance-inflation factor of correlated bins), whose expectation where the model
//! is right is `α (ln α − ψ(α)) / φ`, because `E[r] = 1` and `E[ln r] = ψ(α) − ln α` for a
//! Gamma(α, 1/α) variable (Johnson, Kotz & Balakrishnan 1994, *Continuous Univariate
//! Distributions* vol. 1, §17.8). A bin's **excess** is `d` minus that expectation: zero on
//! average under noise alone, large where the recording and the model disagree.
//!
//! The excess has variance `α²(ψ′(α) − 1/α)/φ²` per bin under the model (`Var r = 1/α`,
//! `Var ln r = ψ′(α)`, `Cov(r, ln r) = 1/α`; same source). [`band_misfit`] sums a band's excess and
//! names where it sits: the bins where the excess averaged over [`SMOOTH_BINS`] neighbours stands
//! [`THRESHOLD_SD`] standard deviations above zero, joined into ranges across gaps of up to
//! [`MERGE_GAP_BINS`] and trimmed to bins of positive excess at their ends, the largest
//! [`MAX_REGIONS`] kept, each with the ratio of the recording's power to the model's over it. A
//! raised floor is one broad range; lines the model misses, or lines it puts where the recording
//! has none, are narrow ones.

use super::{LikelihoodError, Result, WelchLikelihood};
use statrs::function::gamma::digamma;

/// Bins the excess is averaged over to find where it sits: a Hann window's main lobe.
pub const SMOOTH_BINS: usize = 5;

/// Standard deviations of the averaged excess under the model above which a bin carries the
/// misfit: one-sided 3·10⁻⁵, so that a band of a few thousand bins under the model rarely shows
/// one.
pub const THRESHOLD_SD: f64 = 4.0;

/// Bins between two carrying runs across which they are one range.
pub const MERGE_GAP_BINS: usize = 2;

/// Ranges listed per band, the largest excess first.
pub const MAX_REGIONS: usize = 3;

/// A frequency range of a band that carries a share of its excess NLL.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MisfitRegion {
    /// Lowest and highest bin frequency of the range, Hz.
    pub freq_lo_hz: f64,
    pub freq_hi_hz: f64,
    /// The range's excess NLL above its expectation under the model, nats.
    pub excess_nats: f64,
    /// The recording's power over the range divided by the model's (simulation plus tracking
    /// noise): above 1 the recording holds power the model lacks, below 1 the reverse.
    pub power_ratio: f64,
}

/// One band's share of a misfit.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BandMisfit {
    /// The band's name (`[[spectrum.bands]] name`).
    pub band: String,
    /// The band's NLL above the saturated model minus its expectation under the model, nats.
    pub excess_nats: f64,
    /// The ranges that carry half of the band's positive excess, the largest first.
    pub regions: Vec<MisfitRegion>,
}

impl WelchLikelihood {
    /// Each bin's Whittle deviance above the saturated model, nats (module docs): the terms whose
    /// sum is [`WelchLikelihood::nll`] minus its value at `model = measured`.
    ///
    /// # Errors
    /// As [`WelchLikelihood::nll`].
    pub fn bin_deviance(&self, measured: &[f64], model: &[f64]) -> Result<Vec<f64>> {
        self.nll(measured, model)?; // the same checks of lengths and values
        let alpha = self.dof / 2.0;
        Ok(measured
            .iter()
            .zip(model)
            .map(|(&p, &s)| {
                let r = p / s;
                alpha * (r - 1.0 - r.ln()) / self.bin_factor
            })
            .collect())
    }

    /// The standard deviation of one bin's deviance where the model is right, nats (module docs).
    pub fn bin_deviance_sd(&self) -> f64 {
        let alpha = self.dof / 2.0;
        alpha * (trigamma(alpha) - 1.0 / alpha).max(0.0).sqrt() / self.bin_factor
    }

    /// The expectation of one bin's deviance where the model is right, nats (module docs).
    pub fn expected_bin_deviance(&self) -> f64 {
        let alpha = self.dof / 2.0;
        alpha * (alpha.ln() - digamma(alpha)) / self.bin_factor
    }
}

/// Where the band `band`'s misfit sits: the recording's ordinates `measured` against the model's
/// `model` at the bin frequencies `freq_hz` (Hz), read with the band's likelihood `lik` (module
/// docs).
///
/// # Errors
/// [`LikelihoodError::LengthMismatch`] when `freq_hz` and the ordinates differ in length, and
/// those of [`WelchLikelihood::bin_deviance`].
pub fn band_misfit(
    band: &str,
    lik: &WelchLikelihood,
    freq_hz: &[f64],
    measured: &[f64],
    model: &[f64],
) -> Result<BandMisfit> {
    if freq_hz.len() != measured.len() {
        return Err(LikelihoodError::LengthMismatch {
            measured: measured.len(),
            model: freq_hz.len(),
        });
    }
    let expected = lik.expected_bin_deviance();
    let excess: Vec<f64> = lik
        .bin_deviance(measured, model)?
        .into_iter()
        .map(|d| d - expected)
        .collect();
    // The mean of SMOOTH_BINS correlated bins has the variance of SMOOTH_BINS/φ independent ones.
    let smooth_sd = lik.bin_deviance_sd() * (lik.bin_factor / SMOOTH_BINS as f64).sqrt();
    let regions = carrying_ranges(&excess, THRESHOLD_SD * smooth_sd)
        .into_iter()
        .map(|r| MisfitRegion {
            freq_lo_hz: freq_hz[*r.start()],
            freq_hi_hz: freq_hz[*r.end()],
            excess_nats: excess[r.clone()].iter().sum(),
            power_ratio: measured[r.clone()].iter().sum::<f64>() / model[r].iter().sum::<f64>(),
        })
        .collect();
    Ok(BandMisfit {
        band: band.to_string(),
        excess_nats: excess.iter().sum(),
        regions,
    })
}

/// A misfit's shape in words, for a warning or a report: the band that carries most of the excess
/// with the others' shares, then the ranges of every band holding at least a quarter of the
/// positive excess, each with the recording's power against the model's. `None` when no band
/// has a positive excess.
pub fn describe(bands: &[BandMisfit]) -> Option<String> {
    let total: f64 = bands.iter().map(|b| b.excess_nats.max(0.0)).sum();
    let mut order: Vec<&BandMisfit> = bands.iter().collect();
    order.sort_by(|a, b| b.excess_nats.total_cmp(&a.excess_nats));
    let top = order.first().filter(|b| b.excess_nats > 0.0)?;
    let mut text = format!(
        "the excess lies in the {} band ({:.0} of {:.0} nats above what the noise gives",
        top.band, top.excess_nats, total
    );
    for b in &order[1..] {
        text.push_str(&format!("; {} band {:.0}", b.band, b.excess_nats));
    }
    text.push(')');
    let ranges: Vec<String> = order
        .iter()
        .filter(|b| b.excess_nats >= 0.25 * total)
        .flat_map(|b| &b.regions)
        .map(|r| {
            let at = if r.freq_hi_hz > r.freq_lo_hz {
                format!("{:.0}–{:.0} Hz", r.freq_lo_hz, r.freq_hi_hz)
            } else {
                format!("{:.0} Hz", r.freq_lo_hz)
            };
            format!(
                "at {at} the recording holds {:.2} times the model's power",
                r.power_ratio
            )
        })
        .collect();
    if ranges.is_empty() {
        text.push_str(", spread over the band rather than in one range");
    } else {
        text.push_str(": ");
        text.push_str(&ranges.join(", "));
    }
    Some(text)
}

/// The bin ranges where `excess` averaged over [`SMOOTH_BINS`] exceeds `threshold`, joined,
/// trimmed and ordered as the module docs say.
fn carrying_ranges(excess: &[f64], threshold: f64) -> Vec<std::ops::RangeInclusive<usize>> {
    let n = excess.len();
    let half = SMOOTH_BINS / 2;
    let flagged = (0..n).filter(|&k| {
        let window = &excess[k.saturating_sub(half)..(k + half + 1).min(n)];
        window.iter().sum::<f64>() / window.len() as f64 > threshold
    });
    let mut ranges: Vec<std::ops::RangeInclusive<usize>> = Vec::new();
    for k in flagged {
        match ranges.last_mut() {
            Some(r) if k - r.end() <= MERGE_GAP_BINS + 1 => *r = *r.start()..=k,
            _ => ranges.push(k..=k),
        }
    }
    let sum = |r: &std::ops::RangeInclusive<usize>| excess[r.clone()].iter().sum::<f64>();
    let mut ranges: Vec<_> = ranges
        .into_iter()
        .filter_map(|r| {
            let lo = r.clone().find(|&k| excess[k] > 0.0)?;
            let hi = r.rev().find(|&k| excess[k] > 0.0)?;
            Some(lo..=hi)
        })
        .filter(|r| sum(r) > 0.0)
        .collect();
    ranges.sort_by(|a, b| sum(b).total_cmp(&sum(a)));
    ranges.truncate(MAX_REGIONS);
    ranges
}

/// The trigamma function ψ′(x) for x > 0: the recurrence ψ′(x) = ψ′(x + 1) + 1/x² up to x ≥ 10,
/// then the asymptotic series 1/x + 1/(2x²) + 1/(6x³) − 1/(30x⁵) + 1/(42x⁷) (Abramowitz & Stegun
/// 1964, 6.4.6 and 6.4.12), whose next term is below 1e-10 there.
fn trigamma(mut x: f64) -> f64 {
    let mut sum = 0.0;
    while x < 10.0 {
        sum += 1.0 / (x * x);
        x += 1.0;
    }
    let x2 = x * x;
    sum + 1.0 / x + 1.0 / (2.0 * x2) + 1.0 / (6.0 * x2 * x) - 1.0 / (30.0 * x2 * x2 * x)
        + 1.0 / (42.0 * x2 * x2 * x2 * x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::welch::WelchConfig;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Gamma};

    fn likelihood(n_bins: usize) -> WelchLikelihood {
        WelchLikelihood::new(&WelchConfig::new(256), 20, n_bins).unwrap()
    }

    /// Under the model, the bins' mean excess is zero: the expectation `α(ln α − ψ(α))/φ` is the
    /// Monte Carlo mean of the deviance of Gamma(α, 1/α) ordinates within 4 standard errors.
    #[test]
    fn the_expected_deviance_is_the_mean_under_the_model() {
        let lik = likelihood(50_000);
        let alpha = lik.dof / 2.0;
        let gamma = Gamma::new(alpha, 1.0 / alpha).unwrap();
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let model = vec![2.0; lik.n_bins];
        let measured: Vec<f64> = model.iter().map(|s| s * gamma.sample(&mut rng)).collect();
        let d = lik.bin_deviance(&measured, &model).unwrap();
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let e = lik.expected_bin_deviance();
        assert!(
            (mean - e).abs() < 4.0 * sd / n.sqrt(),
            "mean {mean} against {e} (se {})",
            sd / n.sqrt()
        );
    }

    /// ψ′(1) = π²/6 and ψ′(1/2) = π²/2 (Abramowitz & Stegun 6.4.2, 6.4.4); the deviance's
    /// standard deviation is the Monte Carlo one within 5 %.
    #[test]
    fn trigamma_and_the_deviance_sd_match_closed_forms() {
        use std::f64::consts::PI;
        assert!((trigamma(1.0) - PI * PI / 6.0).abs() < 1e-9);
        assert!((trigamma(0.5) - PI * PI / 2.0).abs() < 1e-9);
        let lik = likelihood(20_000);
        let alpha = lik.dof / 2.0;
        let gamma = Gamma::new(alpha, 1.0 / alpha).unwrap();
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let model = vec![1.0; lik.n_bins];
        let measured: Vec<f64> = model.iter().map(|_| gamma.sample(&mut rng)).collect();
        let d = lik.bin_deviance(&measured, &model).unwrap();
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        assert!(
            (sd / lik.bin_deviance_sd() - 1.0).abs() < 0.05,
            "{sd} against {}",
            lik.bin_deviance_sd()
        );
    }

    /// A band of ordinates drawn from the model itself shows no range.
    #[test]
    fn a_band_under_the_model_has_no_range() {
        let lik = likelihood(2000);
        let alpha = lik.dof / 2.0;
        let gamma = Gamma::new(alpha, 1.0 / alpha).unwrap();
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        let model = vec![3.0; lik.n_bins];
        let measured: Vec<f64> = model.iter().map(|s| s * gamma.sample(&mut rng)).collect();
        let freq: Vec<f64> = (0..lik.n_bins).map(|k| k as f64).collect();
        let m = band_misfit("b", &lik, &freq, &measured, &model).unwrap();
        assert!(m.regions.is_empty(), "{m:?}");
    }

    /// The deviance sums to the band's NLL above its saturated value.
    #[test]
    fn the_deviance_sums_to_the_nll_above_saturation() {
        let lik = likelihood(6);
        let measured = [1.0, 2.0, 0.5, 3.0, 1.5, 0.8];
        let model = [1.2, 1.0, 0.9, 2.0, 1.5, 1.1];
        let d: f64 = lik.bin_deviance(&measured, &model).unwrap().iter().sum();
        let nll = lik.nll(&measured, &model).unwrap() - lik.nll(&measured, &measured).unwrap();
        assert!((d - nll).abs() < 1e-12 * nll.abs(), "{d} against {nll}");
    }

    /// A band whose recording holds ten times the model's power over five bins names those bins,
    /// their frequencies and the ratio, and their excess is the closed-form deviance of `r = 10`.
    #[test]
    fn a_raised_range_is_found_with_its_ratio() {
        let n = 64;
        let lik = likelihood(n);
        let freq: Vec<f64> = (0..n).map(|k| 100.0 + 10.0 * k as f64).collect();
        let model = vec![1.0; n];
        let mut measured = model.clone();
        for p in &mut measured[20..25] {
            *p = 10.0;
        }
        let m = band_misfit("low", &lik, &freq, &measured, &model).unwrap();
        assert_eq!(m.regions.len(), 1, "{m:?}");
        let r = &m.regions[0];
        assert_eq!((r.freq_lo_hz, r.freq_hi_hz), (300.0, 340.0));
        assert!((r.power_ratio - 10.0).abs() < 1e-12);
        let alpha = lik.dof / 2.0;
        let per_bin = alpha * (10.0 - 1.0 - 10f64.ln()) / lik.bin_factor;
        let e = lik.expected_bin_deviance();
        assert!((r.excess_nats - 5.0 * (per_bin - e)).abs() < 1e-9 * per_bin);
        assert!((m.excess_nats - (5.0 * per_bin - n as f64 * e)).abs() < 1e-9 * per_bin);
    }

    /// Two raised ranges are listed largest first; a model above the recording gives a ratio
    /// below 1; two raised bins with two bins between them are one range (the raised bins' excess
    /// outweighs the two between).
    #[test]
    fn ranges_are_ordered_merged_and_signed() {
        let n = 80;
        let lik = likelihood(n);
        let freq: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let mut model = vec![1.0; n];
        let mut measured = model.clone();
        measured[10] = 6.0;
        measured[13] = 6.0; // two bins apart from 10: one range
        for s in &mut model[50..60] {
            *s = 8.0; // the model has power the recording lacks
        }
        let m = band_misfit("high", &lik, &freq, &measured, &model).unwrap();
        assert_eq!(m.regions.len(), 2, "{m:?}");
        assert_eq!(
            (m.regions[0].freq_lo_hz, m.regions[0].freq_hi_hz),
            (50.0, 59.0)
        );
        assert!(m.regions[0].power_ratio < 1.0);
        assert!(
            m.regions
                .iter()
                .any(|r| (r.freq_lo_hz, r.freq_hi_hz) == (10.0, 13.0)),
            "{m:?}"
        );
    }

    /// The words name the carrying band first, the others' shares, and each range with its ratio.
    #[test]
    fn the_shape_in_words() {
        let region = |lo, hi, ratio| MisfitRegion {
            freq_lo_hz: lo,
            freq_hi_hz: hi,
            excess_nats: 100.0,
            power_ratio: ratio,
        };
        let bands = [
            BandMisfit {
                band: "low".into(),
                excess_nats: 40.0,
                regions: vec![],
            },
            BandMisfit {
                band: "high".into(),
                excess_nats: 1650.0,
                regions: vec![region(610.0, 690.0, 3.1), region(1230.0, 1230.0, 0.4)],
            },
        ];
        assert_eq!(
            describe(&bands).unwrap(),
            "the excess lies in the high band (1650 of 1690 nats above what the noise gives; \
             low band 40): at 610–690 Hz the recording holds 3.10 times the model's power, at \
             1230 Hz the recording holds 0.40 times the model's power"
        );
        let flat = [BandMisfit {
            band: "low".into(),
            excess_nats: 80.0,
            regions: vec![],
        }];
        assert!(
            describe(&flat)
                .unwrap()
                .ends_with("spread over the band rather than in one range")
        );
        let none = [BandMisfit {
            band: "low".into(),
            excess_nats: -3.0,
            regions: vec![],
        }];
        assert_eq!(describe(&none), None);
    }

    #[test]
    fn no_excess_no_regions() {
        let lik = likelihood(8);
        let x = vec![1.0; 8];
        let freq: Vec<f64> = (0..8).map(f64::from).collect();
        assert!(
            band_misfit("b", &lik, &freq, &x, &x)
                .unwrap()
                .regions
                .is_empty()
        );
        assert!(band_misfit("b", &lik, &freq[..7], &x, &x).is_err());
    }
}
