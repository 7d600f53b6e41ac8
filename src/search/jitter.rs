//! How much a candidate's cost jitters under steps far below any physical scale
//! ([`RoundingJitter`]).
//!
//! A lip whose friction falls with slip speed (`dμ_d/dv < 0`, the Stribeck branch of seed eq. 4)
//! adds negative damping to the blade's modes while it slips slowly, as it does on either side of
//! the reversal; where that damping exceeds the structure's, the slip is unstable and an
//! oscillation grows from whatever perturbation the motion carries (the mode-coupling and
//! negative-slope mechanisms of friction-induced vibration: Ibrahim 1994, *Appl. Mech. Rev.*
//! 47:7; Hoffmann & Gaul 2003, *ZAMM* 83:8). In a simulation that perturbation is the
//! integrator's own error, so when the oscillation grows out of it and where it saturates into
//! stick–slip is set by rounding, and the jitter grows with the law's slope at zero slip speed
//! (docs/validation.md, "Jitter"). The cost inherits that jitter wherever a spectrum sees the
//! growing oscillation's timing: tip − head x hardly, head y's low band, which sees the squared
//! angles' envelope, much more (docs/likelihood.md, "Jitter").
//!
//! The check costs `2k + 1` simulations at the job's tolerance: the optimum and a step of
//! [`JITTER_STEP_U`] either way along each coordinate.

use super::SpectralProblem;
use super::problem::FAILED_COST;
use crate::estimate::warning::{FitWarning, Jitter};
use serde::{Deserialize, Serialize};

/// The step of the jitter check, normalised units: four orders above the coordinates' rounding
/// (unit roundoff 1.1e-16 on values of order one), twelve below any interval, so the likelihood's
/// bowl moves the cost by nothing measurable and any change is the trajectory's sensitivity.
pub const JITTER_STEP_U: f64 = 1e-12;

/// `u` and the `2k` points [`JITTER_STEP_U`] away from it either way along each coordinate (a
/// step that would leave the unit box goes the other way: outside it the box's penalty, not the
/// jitter, would move the cost).
pub fn rounding_points(u: &[f64]) -> Vec<Vec<f64>> {
    let mut points = vec![u.to_vec()];
    for i in 0..u.len() {
        for side in [1.0, -1.0] {
            let mut p = u.to_vec();
            p[i] = if (0.0..=1.0).contains(&(p[i] + side * JITTER_STEP_U)) {
                p[i] + side * JITTER_STEP_U
            } else {
                p[i] - side * JITTER_STEP_U
            };
            points.push(p);
        }
    }
    points
}

/// The cost at a point and at [`JITTER_STEP_U`] steps around it, at the job's tolerance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RoundingJitter {
    /// The step, normalised units.
    pub step_u: f64,
    /// The costs that did not fail, the point's first, nats.
    pub costs_nats: Vec<f64>,
    /// Their sample standard deviation, nats.
    pub sd_nats: f64,
}

impl RoundingJitter {
    /// The check at `u` (normalised coordinates) of `problem`'s cost; `None` when fewer than
    /// three of its simulations succeed. The probes count as evaluations of `problem` but are not
    /// kept among the points near the best (they are not steps of a search). A second check at
    /// the same point reads the first's.
    pub fn at(problem: &SpectralProblem, u: &[f64]) -> Option<RoundingJitter> {
        let last = || {
            problem
                .last_jitter
                .lock()
                .unwrap_or_else(|e| e.into_inner())
        };
        if let Some((_, j)) = last().as_ref().filter(|(at, _)| at.as_slice() == u) {
            return j.clone();
        }
        let j = Self::probe(problem, u);
        *last() = Some((u.to_vec(), j.clone()));
        j
    }

    /// The `cost_jitter` warning when the jitter exceeds `rise_limit_nats`, the likelihood's rise
    /// at the edge of the intervals it is read against.
    pub fn warning_above(&self, rise_limit_nats: f64) -> Option<FitWarning> {
        (self.sd_nats > rise_limit_nats).then_some(FitWarning::CostJitter(Jitter {
            sd_nats: self.sd_nats,
            step_u: self.step_u,
            rise_limit_nats,
        }))
    }

    /// The mean of the costs, nats: the cost averaged over the point's rounding draws.
    pub fn mean_nats(&self) -> f64 {
        self.costs_nats.iter().sum::<f64>() / self.costs_nats.len() as f64
    }

    /// The check at `u` without reading or keeping the problem's last check ([`RoundingJitter::at`]
    /// caches through it): for probes at many points, such as a profile's steps
    /// ([`crate::uncertainty::profile_intervals_at`]).
    pub fn probe(problem: &SpectralProblem, u: &[f64]) -> Option<RoundingJitter> {
        use rayon::prelude::*;
        let costs_nats: Vec<f64> = rounding_points(u)
            .par_iter()
            .map(|p| problem.unrecorded_cost_at(p))
            .collect::<Vec<_>>()
            .into_iter()
            .filter(|c| c.is_finite() && *c < FAILED_COST)
            .collect();
        Self::of(costs_nats)
    }

    /// The jitter of the costs `costs_nats`; `None` for fewer than three.
    pub fn of(costs_nats: Vec<f64>) -> Option<RoundingJitter> {
        let n = costs_nats.len();
        if n < 3 {
            return None;
        }
        let mean = costs_nats.iter().sum::<f64>() / n as f64;
        let var = costs_nats.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        Some(RoundingJitter {
            step_u: JITTER_STEP_U,
            costs_nats,
            sd_nats: var.sqrt(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_jitter_is_the_sample_standard_deviation_of_the_costs() {
        // Costs 1, 2, 3: mean 2, sample variance (1 + 0 + 1)/2 = 1.
        let j = RoundingJitter::of(vec![1.0, 2.0, 3.0]).unwrap();
        assert!((j.sd_nats - 1.0).abs() < 1e-15);
        assert!(RoundingJitter::of(vec![1.0, 2.0]).is_none());
    }
}
