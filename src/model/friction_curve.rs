//! The friction law where a recording measures it: the fitted μ_d(v) over the slip speeds the
//! fitted motion covers, with a ±1σ band from the fit's covariance, and the true law when known.
//!
//! A law's coefficients extrapolate: outside the slip speeds the tip actually slips at, the
//! recording says nothing about μ_d, and two laws that agree over that range (an exponential and
//! one with a viscous rise, say) can differ widely beyond it. The curve is what a fit determines.

use serde::{Deserialize, Serialize};

use super::{FrictionLaw, ParamId};

/// Points of the curve's grid, evenly spaced over the measured range.
pub const CURVE_POINTS: usize = 50;

/// How far beyond ±1σ (a fraction of σ) the evaluated points must reach for
/// [`FrictionCurve::band_widened`]: a tenth, as a widened interval is reported.
pub const BAND_WIDENED_SIGMA: f64 = 0.1;

/// The percentiles of the slipping samples' |slip speed| that bound the measured range.
pub const RANGE_PERCENTILES: [f64; 2] = [10.0, 90.0];

/// μ_d(v) on the measured slip-speed range (docs/results.md, "The friction law where the recording
/// measures it").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrictionCurve {
    /// The slip speeds the fitted motion covers: the [`RANGE_PERCENTILES`] of |slip speed| over
    /// the slipping samples of the fitted model's simulation, m/s.
    pub measured_range_m_per_s: [f64; 2],
    /// The percentiles that bound the range.
    pub range_percentiles: [f64; 2],
    /// Slipping samples the range was read from.
    pub slip_samples: usize,
    /// The grid: [`CURVE_POINTS`] slip speeds evenly spaced over the range, m/s.
    pub speed_m_per_s: Vec<f64>,
    /// The fitted law's μ_d on the grid.
    pub mu_d: Vec<f64>,
    /// 1σ of μ_d on the grid: the delta method `σ² = gᵀ Σ g` with `g` the law's gradient in its
    /// fitted coefficients ([`FrictionLaw::mu_slip_gradient`]) and `Σ` their covariance from the
    /// fit's 1σ and correlations. Empty when no coefficient of the law was fitted or their
    /// covariance is not finite.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mu_d_sigma: Vec<f64>,
    /// The true law's μ_d on the grid (a job with a `[truth]` for the law); else empty.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mu_d_true: Vec<f64>,
    /// Root mean square over the grid of (μ_d − μ_d,true)/μ_d,true.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms_rel_diff_to_truth: Option<f64>,
    /// On each grid point, the lowest and highest μ_d among the points the fit's search evaluated
    /// whose cost lies within that speed's profile rise limit of the fit
    /// ([`FrictionCurve::with_near_best`]); empty when no such point was kept.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mu_d_near_best: Vec<[f64; 2]>,
    /// Share of the grid's points where the true μ_d lies within the band
    /// ([`FrictionCurve::band_edges`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth_within_band: Option<f64>,
    /// The models the recording does not distinguish from the chosen one, on the grid: the
    /// lowest and the highest of the fitted band and each such candidate's own band
    /// ([`FrictionCurve::with_alternatives`]). Empty when every other candidate is distinguished
    /// (or there is none): then the band alone says what the recording leaves open.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mu_d_envelope: Vec<[f64; 2]>,
    /// The laws of those candidates (each candidate's law at its own optimum).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub alternative_laws: Vec<FrictionLaw>,
    /// Share of the grid's points where the true μ_d lies within the envelope.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth_within_envelope: Option<f64>,
    /// The fitted law (its coefficients, for the curve beyond the range).
    pub fitted_law: FrictionLaw,
    /// The true law, when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub true_law: Option<FrictionLaw>,
}

/// The fitted parameters' spread: each parameter's 1σ and their correlation matrix, in one order.
#[derive(Debug, Clone, Copy)]
pub struct Spread<'a> {
    pub ids: &'a [ParamId],
    pub sigma: &'a [f64],
    /// Row-major, in the order of `ids`.
    pub corr: &'a [Vec<f64>],
}

impl Spread<'_> {
    /// 1σ of `μ_d(v)` of `law` by the delta method over the fitted coefficients of `law`; `None`
    /// when the fit freed none of them or a needed 1σ or correlation is not finite.
    pub fn mu_sigma(&self, law: &FrictionLaw, speed_m_per_s: f64) -> Option<f64> {
        let terms: Vec<(usize, f64)> = law
            .mu_slip_gradient(speed_m_per_s)
            .into_iter()
            .filter_map(|(id, g)| Some((self.ids.iter().position(|i| *i == id)?, g)))
            .collect();
        if terms.is_empty() {
            return None;
        }
        let mut s2 = 0.0;
        for &(i, gi) in &terms {
            for &(j, gj) in &terms {
                let c = self.sigma[i] * self.sigma[j] * *self.corr.get(i)?.get(j)?;
                if !c.is_finite() {
                    return None;
                }
                s2 += gi * c * gj;
            }
        }
        Some(s2.max(0.0).sqrt())
    }
}

/// The `p`-th percentile (0–100) of `sorted` (ascending, not empty), linearly interpolated between
/// order statistics at rank `p/100·(n − 1)` (NumPy's default, Hyndman & Fan 1996 type 7).
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    let rank = p / 100.0 * (sorted.len() - 1) as f64;
    let (lo, frac) = (rank.floor() as usize, rank.fract());
    match sorted.get(lo + 1) {
        Some(next) => sorted[lo] + frac * (next - sorted[lo]),
        None => sorted[lo],
    }
}

impl FrictionCurve {
    /// The curve of the fitted `law` over the range that `slip_speeds` (|slip speed| of every
    /// slipping sample, m/s) covers, its band from `spread`, and `truth` on the same grid. `None`
    /// without a finite slip speed.
    pub fn new(
        law: FrictionLaw,
        slip_speeds: &[f64],
        spread: Option<Spread<'_>>,
        truth: Option<FrictionLaw>,
    ) -> Option<FrictionCurve> {
        let mut sorted: Vec<f64> = slip_speeds
            .iter()
            .map(|v| v.abs())
            .filter(|v| v.is_finite())
            .collect();
        if sorted.is_empty() {
            return None;
        }
        sorted.sort_by(f64::total_cmp);
        let range = RANGE_PERCENTILES.map(|p| percentile(&sorted, p));
        let step = (range[1] - range[0]) / (CURVE_POINTS - 1) as f64;
        let speed: Vec<f64> = (0..CURVE_POINTS)
            .map(|i| range[0] + i as f64 * step)
            .collect();
        let (mu_d, mu_d_sigma) = law_on_grid(&law, &speed, spread);
        let mu_d_true: Vec<f64> = truth
            .map(|t| speed.iter().map(|&v| t.mu_slip(v)).collect())
            .unwrap_or_default();
        let rms_rel_diff_to_truth = (!mu_d_true.is_empty()).then(|| {
            let ss: f64 = mu_d
                .iter()
                .zip(&mu_d_true)
                .map(|(m, t)| ((m - t) / t).powi(2))
                .sum();
            (ss / CURVE_POINTS as f64).sqrt()
        });
        Some(
            FrictionCurve {
                measured_range_m_per_s: range,
                range_percentiles: RANGE_PERCENTILES,
                slip_samples: sorted.len(),
                speed_m_per_s: speed,
                mu_d,
                mu_d_sigma,
                mu_d_true,
                rms_rel_diff_to_truth,
                mu_d_near_best: Vec::new(),
                truth_within_band: None,
                mu_d_envelope: Vec::new(),
                alternative_laws: Vec::new(),
                truth_within_envelope: None,
                fitted_law: law,
                true_law: truth,
            }
            .with_truth_in_band(),
        )
    }

    /// [`FrictionCurve::truth_within_band`] from the band's present edges.
    fn with_truth_in_band(mut self) -> FrictionCurve {
        self.truth_within_band = self
            .band_edges()
            .filter(|_| !self.mu_d_true.is_empty())
            .map(|[lo, hi]| share_within(&lo, &hi, &self.mu_d_true));
        self
    }

    /// The curve with its band widened to the points the fit's search evaluated that are about as
    /// likely as the fit, as the parameters' intervals are: `points` holds each evaluated point's
    /// cost above the fit's (nats) and its friction law, `rise_limit_nats` the profile rise limit
    /// of μ_d on each grid point (the 68.27 % bound of μ_d(v)'s profile likelihood). A point
    /// within that limit lies inside μ_d(v)'s 68.27 % profile-likelihood region: the profile at
    /// its μ_d(v) is at most its cost, the other directions held instead of re-optimised (Pawitan
    /// 2001, *In All Likelihood*, §2.6). Where the likelihood is flat along a direction the
    /// curvature at the fit does not see, the search's own simulations outline it. Unchanged when
    /// no point lies within a limit or `rise_limit_nats` does not match the grid.
    pub fn with_near_best(
        mut self,
        points: &[(f64, FrictionLaw)],
        rise_limit_nats: &[f64],
    ) -> Self {
        if let Some(ranges) = near_best_ranges(&self.speed_m_per_s, points, rise_limit_nats) {
            self.mu_d_near_best = ranges;
            self = self.with_truth_in_band();
        }
        self
    }

    /// Another candidate's `law` on this curve's grid, with its band made as this curve's is: ±1σ
    /// by the delta method from `spread`, widened to the candidate's own evaluated `points` within
    /// `rise_limit_nats` ([`FrictionCurve::with_near_best`]). Without a spread or such points the
    /// band is the law's μ_d alone.
    pub fn alternative(
        &self,
        law: FrictionLaw,
        spread: Option<Spread<'_>>,
        points: &[(f64, FrictionLaw)],
        rise_limit_nats: &[f64],
    ) -> Alternative {
        let speeds = &self.speed_m_per_s;
        let (mu, sigma) = law_on_grid(&law, speeds, spread);
        let near = near_best_ranges(speeds, points, rise_limit_nats).unwrap_or_default();
        let band = band_edges(&mu, &sigma, &near).unwrap_or_else(|| [mu.clone(), mu]);
        Alternative { law, band }
    }

    /// The curve with the envelope of `others`, the candidates the recording does not distinguish
    /// from the chosen one (docs/model-choice.md), each on this curve's grid
    /// ([`FrictionCurve::alternative`]): on every grid point the lowest and highest of this
    /// curve's band (μ_d alone without one) and of each candidate's band. Model choice reports the
    /// simplest of those candidates (Burnham & Anderson 2002, §2.6), so its band alone is
    /// conditional on a choice the recording did not make; each candidate's band is what the
    /// recording leaves open within it, and the envelope is their union. Unchanged when `others`
    /// is empty or a band does not match the grid.
    pub fn with_alternatives(mut self, others: &[Alternative]) -> FrictionCurve {
        let n = self.speed_m_per_s.len();
        if others.is_empty() || others.iter().any(|a| a.band.iter().any(|e| e.len() != n)) {
            return self;
        }
        let [band_lo, band_hi] = self
            .band_edges()
            .unwrap_or_else(|| [self.mu_d.clone(), self.mu_d.clone()]);
        self.mu_d_envelope = (0..n)
            .map(|i| {
                (others.iter()).fold([band_lo[i], band_hi[i]], |[lo, hi], a| {
                    [lo.min(a.band[0][i]), hi.max(a.band[1][i])]
                })
            })
            .collect();
        self.alternative_laws = others.iter().map(|a| a.law).collect();
        self.truth_within_envelope = (!self.mu_d_true.is_empty()).then(|| {
            let [lo, hi] = self.envelope_edges().unwrap_or_default();
            share_within(&lo, &hi, &self.mu_d_true)
        });
        self
    }

    /// The band's lower and upper edges on the grid: μ_d ∓ σ, widened to
    /// [`FrictionCurve::mu_d_near_best`] where that reaches further; `None` without either.
    pub fn band_edges(&self) -> Option<[Vec<f64>; 2]> {
        band_edges(&self.mu_d, &self.mu_d_sigma, &self.mu_d_near_best)
    }

    /// Whether the points the search evaluated reach beyond μ_d ± 1σ at some grid point by more
    /// than [`BAND_WIDENED_SIGMA`] of σ: the band is then wider than the delta method's.
    pub fn band_widened(&self) -> bool {
        let reach = 1.0 + BAND_WIDENED_SIGMA;
        (0..self.mu_d_near_best.len()).any(|i| {
            let s = self.mu_d_sigma.get(i).copied().unwrap_or(0.0);
            let [lo, hi] = self.mu_d_near_best[i];
            lo < self.mu_d[i] - reach * s || hi > self.mu_d[i] + reach * s
        })
    }

    /// The envelope's lower and upper edges on the grid; `None` without an envelope.
    pub fn envelope_edges(&self) -> Option<[Vec<f64>; 2]> {
        if self.mu_d_envelope.is_empty() {
            return None;
        }
        let edge = |i: usize| self.mu_d_envelope.iter().map(|e| e[i]).collect();
        Some([edge(0), edge(1)])
    }

    /// How much of μ_d the recording leaves open: the median over the grid of the envelope's
    /// half-width (the band's where there is no envelope) relative to the fitted μ_d; `None`
    /// without either.
    pub fn open_rel_half_width(&self) -> Option<f64> {
        let [lo, hi] = self.envelope_edges().or_else(|| self.band_edges())?;
        let mut rel: Vec<f64> = (0..self.mu_d.len())
            .map(|i| 0.5 * (hi[i] - lo[i]) / self.mu_d[i].abs())
            .collect();
        rel.sort_by(f64::total_cmp);
        Some(percentile(&rel, 50.0))
    }

    /// Whether `speed_m_per_s` lies inside the measured range.
    pub fn measures(&self, speed_m_per_s: f64) -> bool {
        let [lo, hi] = self.measured_range_m_per_s;
        (lo..=hi).contains(&speed_m_per_s)
    }
}

/// A candidate the recording does not distinguish from the chosen one, on the chosen curve's
/// grid ([`FrictionCurve::alternative`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Alternative {
    /// The candidate's law at its own optimum.
    pub law: FrictionLaw,
    /// Its band's lower and upper edges on the grid.
    pub band: [Vec<f64>; 2],
}

/// `law`'s μ_d on `speeds` and its 1σ there by the delta method from `spread` (empty without one,
/// or where [`Spread::mu_sigma`] has none).
fn law_on_grid(
    law: &FrictionLaw,
    speeds: &[f64],
    spread: Option<Spread<'_>>,
) -> (Vec<f64>, Vec<f64>) {
    let mu = speeds.iter().map(|&v| law.mu_slip(v)).collect();
    let sigma = spread
        .and_then(|s| speeds.iter().map(|&v| s.mu_sigma(law, v)).collect())
        .unwrap_or_default();
    (mu, sigma)
}

/// On each of `speeds`, the lowest and highest μ_d of the `points` (cost above the fit's, nats;
/// law) whose rise is within that speed's `rise_limit_nats`; `None` when the limits do not match
/// the speeds or a speed has no such point.
fn near_best_ranges(
    speeds: &[f64],
    points: &[(f64, FrictionLaw)],
    rise_limit_nats: &[f64],
) -> Option<Vec<[f64; 2]>> {
    if rise_limit_nats.len() != speeds.len() {
        return None;
    }
    (speeds.iter().zip(rise_limit_nats))
        .map(|(&v, &limit)| {
            (points.iter())
                .filter(|(rise, _)| *rise <= limit)
                .map(|(_, law)| law.mu_slip(v))
                .filter(|m| m.is_finite())
                .fold(None, |r: Option<[f64; 2]>, m| {
                    Some(r.map_or([m, m], |[lo, hi]| [lo.min(m), hi.max(m)]))
                })
        })
        .collect()
}

/// A band's lower and upper edges: `mu` ∓ `sigma`, widened to `near` where that reaches further
/// (either may be empty), the lower edge no lower than zero, since a friction coefficient is not
/// negative (a coefficient the recording leaves undetermined has a σ beyond μ_d itself); `None`
/// when both are empty.
fn band_edges(mu: &[f64], sigma: &[f64], near: &[[f64; 2]]) -> Option<[Vec<f64>; 2]> {
    if sigma.is_empty() && near.is_empty() {
        return None;
    }
    let edge = |sign: f64| -> Vec<f64> {
        (0..mu.len())
            .map(|i| {
                let m = mu[i];
                let s = sigma.get(i).map_or(m, |s| m + sign * s);
                match near.get(i) {
                    Some([lo, _]) if sign < 0.0 => s.min(*lo).max(0.0),
                    Some([_, hi]) => s.max(*hi),
                    None if sign < 0.0 => s.max(0.0),
                    None => s,
                }
            })
            .collect()
    };
    Some([edge(-1.0), edge(1.0)])
}

/// The share of `truth`'s points that lie within `[lo, hi]` point by point.
fn share_within(lo: &[f64], hi: &[f64], truth: &[f64]) -> f64 {
    let inside = (0..truth.len())
        .filter(|&i| (lo[i]..=hi[i]).contains(&truth[i]))
        .count();
    inside as f64 / truth.len().max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    const LAW: FrictionLaw = FrictionLaw::Exponential {
        a: 0.8,
        b_s_per_m: 10.0,
        c: 0.2,
    };

    /// Slip speeds 0, 0.001, …, 0.100 m/s (101 samples, in a shuffled order and with signs, as a
    /// simulation's slip velocities come): rank 0.1·100 = 10 and 0.9·100 = 90 give the range
    /// [0.010, 0.090] m/s exactly, the grid steps (0.09 − 0.01)/49, and the curve is the closed
    /// form 0.8 e^(−10 v) + 0.2 there.
    #[test]
    fn the_curve_spans_the_slip_speeds_percentiles_with_the_laws_values() {
        let speeds: Vec<f64> = (0..=100)
            .map(|i| (((i * 37) % 101) as f64) * 0.001 * if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let c = FrictionCurve::new(LAW, &speeds, None, None).unwrap();
        assert_eq!(c.slip_samples, 101);
        assert!((c.measured_range_m_per_s[0] - 0.010).abs() < 1e-15);
        assert!((c.measured_range_m_per_s[1] - 0.090).abs() < 1e-15);
        assert_eq!(c.speed_m_per_s.len(), CURVE_POINTS);
        for (i, (&v, &mu)) in c.speed_m_per_s.iter().zip(&c.mu_d).enumerate() {
            let v_ref = 0.010 + i as f64 * 0.080 / 49.0;
            assert!((v - v_ref).abs() < 1e-15, "{i}: {v}");
            assert!((mu - (0.8 * (-10.0 * v_ref).exp() + 0.2)).abs() < 1e-14);
        }
        assert!(c.mu_d_sigma.is_empty() && c.mu_d_true.is_empty());
        assert!(c.measures(0.05) && !c.measures(0.005) && !c.measures(0.095));
        // Interpolation between order statistics: the 25th percentile of [1, 2, 4, 8] is at rank
        // 0.75, 1 + 0.75·(2 − 1).
        assert_eq!(percentile(&[1.0, 2.0, 4.0, 8.0], 25.0), 1.75);
        assert_eq!(percentile(&[3.0], 90.0), 3.0);
        assert!(FrictionCurve::new(LAW, &[f64::NAN], None, None).is_none());
    }

    /// The band by the delta method against closed forms for the exponential law (σ² = gᵀΣg with
    /// g = (e^(−Bv), −A v e^(−Bv), 1)); a fitted parameter outside the law (k1) does not enter;
    /// the truth's rms relative difference is that of a law 2 % above everywhere.
    #[test]
    fn the_band_and_the_truths_difference_follow_their_closed_forms() {
        let speeds: Vec<f64> = (0..=100).map(|i| i as f64 * 0.001).collect();
        let ids = [ParamId::A, ParamId::C, ParamId::K1];
        let sigma = [0.01, 0.05, 1e-3];
        // A and C anti-correlated with equal σ: σ_μ = 0.01·(1 − e^(−Bv)) when σ_C = σ_A.
        let anti = vec![
            vec![1.0, -1.0, 0.5],
            vec![-1.0, 1.0, 0.5],
            vec![0.5, 0.5, 1.0],
        ];
        let same_sigma = [0.01, 0.01, 1e-3];
        let spread = Spread {
            ids: &ids,
            sigma: &same_sigma,
            corr: &anti,
        };
        let c = FrictionCurve::new(LAW, &speeds, Some(spread), None).unwrap();
        for (v, s) in c.speed_m_per_s.iter().zip(&c.mu_d_sigma) {
            assert!(
                (s - 0.01 * (1.0 - (-10.0 * v).exp())).abs() < 1e-15,
                "{v}: {s}"
            );
        }
        // Uncorrelated A and C: σ_μ² = (0.01 e^(−Bv))² + 0.05².
        let eye = vec![
            vec![1.0, 0.0, 0.0],
            vec![0.0, 1.0, 0.0],
            vec![0.0, 0.0, 1.0],
        ];
        let spread = Spread {
            ids: &ids,
            sigma: &sigma,
            corr: &eye,
        };
        let truth = FrictionLaw::Exponential {
            a: 0.8 / 1.02,
            b_s_per_m: 10.0,
            c: 0.2 / 1.02,
        };
        let c = FrictionCurve::new(LAW, &speeds, Some(spread), Some(truth)).unwrap();
        for (v, s) in c.speed_m_per_s.iter().zip(&c.mu_d_sigma) {
            let e = 0.01 * (-10.0 * v).exp();
            assert!((s - (e * e + 0.05 * 0.05).sqrt()).abs() < 1e-15);
        }
        assert!((c.rms_rel_diff_to_truth.unwrap() - 0.02).abs() < 1e-12);
        // The truth is 2 % (≤ 0.02) below a μ_d ≤ 1 with σ ≥ 0.05: inside the band everywhere.
        assert_eq!(c.truth_within_band, Some(1.0));
        // No fitted coefficient of the law, or a NaN correlation: no band.
        let k1_only = Spread {
            ids: &[ParamId::K1],
            sigma: &[1e-3],
            corr: &[vec![1.0]],
        };
        let c = FrictionCurve::new(LAW, &speeds, Some(k1_only), Some(truth)).unwrap();
        assert!(c.mu_d_sigma.is_empty() && c.truth_within_band.is_none());
        let nan = vec![
            vec![1.0, f64::NAN, 0.0],
            vec![f64::NAN, 1.0, 0.0],
            vec![0.0, 0.0, 1.0],
        ];
        let spread = Spread {
            ids: &ids,
            sigma: &sigma,
            corr: &nan,
        };
        assert!(
            FrictionCurve::new(LAW, &speeds, Some(spread), None)
                .unwrap()
                .mu_d_sigma
                .is_empty()
        );
    }

    /// [`LAW`] times `f` at every slip speed.
    fn scaled(f: f64) -> FrictionLaw {
        FrictionLaw::Exponential {
            a: 0.8 * f,
            b_s_per_m: 10.0,
            c: 0.2 * f,
        }
    }

    /// The envelope of two other laws against closed forms: a law 10 % above the fitted one
    /// everywhere and one 10 % below it bound the envelope with the ±1σ band inside; the truth 5 %
    /// above lies inside it everywhere, and outside a band of 1 %.
    #[test]
    fn the_envelope_spans_the_laws_the_recording_does_not_distinguish() {
        let speeds: Vec<f64> = (0..=100).map(|i| i as f64 * 0.001).collect();
        let ids = [ParamId::C];
        let spread = Spread {
            ids: &ids,
            sigma: &[0.002],
            corr: &[vec![1.0]],
        };
        let c = FrictionCurve::new(LAW, &speeds, Some(spread), Some(scaled(1.05))).unwrap();
        assert_eq!(c.truth_within_band, Some(0.0));
        assert!(c.clone().with_alternatives(&[]) == c && c.mu_d_envelope.is_empty());
        let others = [scaled(1.1), scaled(0.9)].map(|l| c.alternative(l, None, &[], &[]));
        let c = c.with_alternatives(&others);
        for (i, [lo, hi]) in c.mu_d_envelope.iter().enumerate() {
            assert!((lo - 0.9 * c.mu_d[i]).abs() < 1e-15 && (hi - 1.1 * c.mu_d[i]).abs() < 1e-15);
        }
        assert_eq!(c.truth_within_envelope, Some(1.0));
        assert_eq!(c.alternative_laws.len(), 2);
        let [lo, hi] = c.envelope_edges().unwrap();
        assert!(lo[7] == c.mu_d_envelope[7][0] && hi[7] == c.mu_d_envelope[7][1]);
        let [lo, hi] = c.band_edges().unwrap();
        assert!(lo[7] == c.mu_d[7] - 0.002 && hi[7] == c.mu_d[7] + 0.002);
        let text = toml::to_string_pretty(&c).unwrap();
        assert_eq!(toml::from_str::<FrictionCurve>(&text).unwrap(), c);
    }

    /// An alternative's own band against closed forms: a law 10 % below the fitted one with
    /// σ_C = 0.004 and an evaluated point 20 % below it, 0.2 nats above that candidate's fit
    /// within a 0.3-nat limit, gives a band from 0.8·μ_d up to 0.9·μ_d + 0.004. The envelope with
    /// the fitted ±0.002 band then runs from 0.8·μ_d to μ_d + 0.002 (μ_d ≥ 0.49 here), and holds
    /// a truth 15 % below the fit that a point-only alternative at 0.9·μ_d would leave out. A band
    /// off the grid leaves the curve as it was, and no band's lower edge falls below zero.
    #[test]
    fn an_alternatives_envelope_holds_its_own_band() {
        let speeds: Vec<f64> = (0..=100).map(|i| i as f64 * 0.001).collect();
        let spread = Spread {
            ids: &[ParamId::C],
            sigma: &[0.002],
            corr: &[vec![1.0]],
        };
        let c = FrictionCurve::new(LAW, &speeds, Some(spread), Some(scaled(0.85))).unwrap();
        let wide = Spread {
            sigma: &[0.004],
            ..spread
        };
        let limits = [0.3; CURVE_POINTS];
        let points = [(0.2, scaled(0.8))];
        let alt = c.alternative(scaled(0.9), Some(wide), &points, &limits);
        for i in 0..CURVE_POINTS {
            let m = c.mu_d[i];
            assert!((alt.band[0][i] - 0.8 * m).abs() < 1e-15, "{i}");
            assert!((alt.band[1][i] - (0.9 * m + 0.004)).abs() < 1e-15, "{i}");
        }
        // A σ of 2 (an undetermined coefficient) reaches below zero: the lower edge stops there.
        let loose = Spread {
            sigma: &[2.0],
            ..spread
        };
        let undetermined = c.alternative(scaled(0.9), Some(loose), &[], &[]);
        assert!(undetermined.band[0].iter().all(|&lo| lo == 0.0));
        assert!((undetermined.band[1][0] - (0.9 * c.mu_d[0] + 2.0)).abs() < 1e-15);
        let point_only = c.alternative(scaled(0.9), None, &[], &[]);
        assert_eq!(point_only.band[0], point_only.band[1]);
        assert_eq!(
            (c.clone().with_alternatives(&[point_only])).truth_within_envelope,
            Some(0.0)
        );
        let e = c.clone().with_alternatives(std::slice::from_ref(&alt));
        assert_eq!(e.truth_within_envelope, Some(1.0));
        // Open: half of (μ_d + 0.002 − 0.8·μ_d) over μ_d, 0.1 + 0.001/μ_d point by point, at the
        // median over the grid; the band alone leaves 0.002/μ_d open.
        let median_of = |f: &dyn Fn(f64) -> f64| {
            let mut m: Vec<f64> = c.mu_d.iter().map(|&m| f(m)).collect();
            m.sort_by(f64::total_cmp);
            percentile(&m, 50.0)
        };
        let open = e.open_rel_half_width().unwrap();
        assert!(
            (open - median_of(&|m| 0.1 + 0.001 / m)).abs() < 1e-12,
            "{open}"
        );
        let open = c.open_rel_half_width().unwrap();
        assert!((open - median_of(&|m| 0.002 / m)).abs() < 1e-12, "{open}");
        for (i, [lo, hi]) in e.mu_d_envelope.iter().enumerate() {
            assert!((lo - 0.8 * e.mu_d[i]).abs() < 1e-15 && *hi == e.mu_d[i] + 0.002);
        }
        let short = Alternative {
            band: [vec![0.0; 3], vec![1.0; 3]],
            ..alt
        };
        assert_eq!(c.clone().with_alternatives(&[short]), c);
    }

    /// The band widened to evaluated points against closed forms: a law 3 % above the fitted one
    /// 0.2 nats above the fit, and one 10 % below it 0.4 nats above. With a rise limit of 0.3
    /// nats at the slower half of the grid and 0.5 at the faster, the band runs to 1.03·μ_d above
    /// everywhere and down to 0.9·μ_d only where the limit admits the lower law; the truth 5 %
    /// below is then inside it on the faster half alone. A limit below every point's rise, or
    /// limits that do not match the grid, leave the curve as it was.
    #[test]
    fn the_band_reaches_the_evaluated_points_within_each_speeds_rise_limit() {
        let speeds: Vec<f64> = (0..=100).map(|i| i as f64 * 0.001).collect();
        let spread = Spread {
            ids: &[ParamId::C],
            sigma: &[0.002],
            corr: &[vec![1.0]],
        };
        let c = FrictionCurve::new(LAW, &speeds, Some(spread), Some(scaled(0.95))).unwrap();
        assert_eq!(c.truth_within_band, Some(0.0));
        let points = [(0.2, scaled(1.03)), (0.4, scaled(0.9))];
        let half = CURVE_POINTS / 2;
        let limits: Vec<f64> = (0..CURVE_POINTS)
            .map(|i| if i < half { 0.3 } else { 0.5 })
            .collect();
        let w = c.clone().with_near_best(&points, &limits);
        assert!(w.band_widened());
        let [lo, hi] = w.band_edges().unwrap();
        for i in 0..CURVE_POINTS {
            let m = w.mu_d[i];
            assert!((hi[i] - 1.03 * m).abs() < 1e-15, "{i}");
            let want_lo = if i < half { m - 0.002 } else { 0.9 * m };
            assert!(
                (lo[i] - want_lo).abs() < 1e-15,
                "{i}: {} against {want_lo}",
                lo[i]
            );
        }
        assert_eq!(w.truth_within_band, Some(0.5));
        // The envelope starts from the widened band.
        let e = (w.clone()).with_alternatives(&[w.alternative(scaled(1.01), None, &[], &[])]);
        assert_eq!(e.envelope_edges().unwrap(), [lo, hi]);
        assert_eq!(c.clone().with_near_best(&points, &[0.1; CURVE_POINTS]), c);
        assert_eq!(c.clone().with_near_best(&points, &[0.5; 3]), c);
        let text = toml::to_string_pretty(&w).unwrap();
        assert_eq!(toml::from_str::<FrictionCurve>(&text).unwrap(), w);
    }

    /// The curve as the result file holds it reads back the same.
    #[test]
    fn the_curve_round_trips_through_toml() {
        let speeds: Vec<f64> = (0..=20).map(|i| i as f64 * 0.01).collect();
        let truth = FrictionLaw::ExponentialViscous {
            a: 0.8,
            b_s_per_m: 10.0,
            c: 0.2,
            d_s_per_m: 0.1,
        };
        let c = FrictionCurve::new(LAW, &speeds, None, Some(truth)).unwrap();
        let text = toml::to_string_pretty(&c).unwrap();
        let back: FrictionCurve = toml::from_str(&text).unwrap();
        assert_eq!(back, c);
    }
}
