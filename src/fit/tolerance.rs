//! Whether a fit's optimum is resolved by its integrator: the likelihood at the chosen optimum
//! again at tenfold and hundredfold tighter solver tolerances ([`ToleranceCheck`]).
//!
//! A smooth trajectory converges as the tolerance tightens, and so does the cost (the main job's
//! optimum on the shipped recording does). A motion
//! whose stick–slip sequence hangs on grazing events (a stick the lip's slip speed only just
//! reaches, a shoulder the neck only just touches) does not: an event that appears at one
//! tolerance and not at the next changes the rest of the window, and with it the spectra (the
//! confusion table's often-crossed 0.12 rad shoulder is such a motion). The cost surface is then
//! rough at that depth: a search that keeps its lowest
//! evaluation keeps a ripple the integrator's rounding happened to put low, cost differences
//! smaller than the spread do not tell parameter sets apart, and intervals read from the local
//! curvature at the 0.5-nat scale understate the uncertainty. The check costs two simulations.

use super::FitWarning;
pub use crate::estimate::TolerancePoint;
use crate::model::BladeParams;
use crate::search::FAILED_COST;
use crate::search::jitter::RoundingJitter;
use crate::search::strategy::CandidateFit;
use crate::search::{SpectralProblem, interrupt};
use serde::{Deserialize, Serialize};

/// Factors by which the probes divide the job's `rtol` and `atol`.
pub const PROBE_DIVISORS: [f64; 2] = [10.0, 100.0];

/// Tightest relative tolerance a probe uses: below it a Runge–Kutta pair in double precision
/// (unit roundoff 1.1e-16) spends its steps on rounding (Hairer, Nørsett & Wanner, *Solving
/// Ordinary Differential Equations I*, 2nd ed., §II.4).
pub const MIN_PROBE_RTOL: f64 = 1e-13;

/// Factor on the job's `max_steps` for a probe: a fifth-order pair takes `100^(1/5)` ≈ 2.5 times
/// the steps at a hundredfold tighter tolerance.
const PROBE_MAX_STEPS_FACTOR: usize = 4;

/// The spread above which a fit is not resolved by its integrator, nats: 0.5, the rise of a
/// quadratic negative log-likelihood at one standard deviation, the scale its intervals are read
/// at.
pub const SPREAD_WARN_NATS: f64 = 0.5;

/// What a [`ToleranceCheck`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The costs agree to within [`SPREAD_WARN_NATS`].
    Resolved,
    /// They spread by more.
    Unresolved,
    /// Every probe failed: there is nothing to compare.
    NotProbed,
}

/// The chosen optimum's cost at the job's tolerance and at each probe's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ToleranceCheck {
    /// The job's tolerance first, then each probe that ran, tightest last.
    pub points: Vec<TolerancePoint>,
    /// Largest minus smallest cost over `points`, nats.
    pub spread_nats: f64,
    /// Probes whose simulation failed, and why.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failed: Vec<String>,
    /// The cost's jitter at the job's tolerance under rounding-level steps
    /// ([`crate::search::jitter`]): set for the chosen optimum.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jitter: Option<RoundingJitter>,
}

impl ToleranceCheck {
    /// The check at the parameters `params` of `problem`, whose cost there at the job's
    /// tolerance is `cost_nats` with `transitions` transitions. `None` when the cost is not the
    /// recording's NLL (a target job, the features objective) or the fit is joint (its other
    /// recordings' costs are not re-run). Each probe counts as a model evaluation of `problem`,
    /// and a failed one as a failed evaluation.
    pub fn run(
        problem: &SpectralProblem,
        params: &BladeParams,
        (cost_nats, transitions): (f64, usize),
    ) -> Option<ToleranceCheck> {
        let tightest = problem.solver.rtol / PROBE_DIVISORS[0];
        if !problem.cost_is_nll() || !problem.others.is_empty() || tightest < MIN_PROBE_RTOL {
            return None;
        }
        let job = problem.solver;
        let mut points = vec![TolerancePoint {
            rtol: job.rtol,
            atol: job.atol,
            cost_nats,
            transitions,
        }];
        let mut failed = Vec::new();
        for divisor in PROBE_DIVISORS {
            let rtol = job.rtol / divisor;
            if rtol < MIN_PROBE_RTOL {
                break;
            }
            let solver = crate::simulate::SolverOptions {
                rtol,
                atol: job.atol / divisor,
                max_steps: job.max_steps.saturating_mul(PROBE_MAX_STEPS_FACTOR),
                ..job
            };
            match problem.params_cost_with_solver(params, &solver) {
                Ok((cost_nats, transitions)) => points.push(TolerancePoint {
                    rtol,
                    atol: solver.atol,
                    cost_nats,
                    transitions,
                }),
                Err(e) => failed.push(format!("rtol {rtol:e}: {e}")),
            }
        }
        Some(ToleranceCheck::of(points, failed))
    }

    /// The check of `points` (the job's tolerance first) with the probes that `failed`.
    pub fn of(points: Vec<TolerancePoint>, failed: Vec<String>) -> ToleranceCheck {
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.cost_nats), hi.max(p.cost_nats))
            });
        let spread_nats = if points.len() > 1 { hi - lo } else { 0.0 };
        ToleranceCheck {
            points,
            spread_nats,
            failed,
            jitter: None,
        }
    }

    /// What the check found.
    pub fn verdict(&self) -> Verdict {
        if self.points.len() < 2 {
            Verdict::NotProbed
        } else if self.spread_nats <= SPREAD_WARN_NATS {
            Verdict::Resolved
        } else {
            Verdict::Unresolved
        }
    }

    /// Whether a probe ran, so that the spread compares tolerances.
    pub fn probed(&self) -> bool {
        self.verdict() != Verdict::NotProbed
    }

    /// Whether a probe ran and the cost agrees across tolerances to within [`SPREAD_WARN_NATS`].
    pub fn resolved(&self) -> bool {
        self.verdict() == Verdict::Resolved
    }

    /// The `cost_jitter` warning of intervals that are not a profile's (a profile warns at its own
    /// rise limits): the optimum's cost jitters by more than
    /// [`crate::uncertainty::intervals::PROFILE_68_NATS`], the rise at a quadratic likelihood's
    /// 1σ, so the curvature those intervals read is drawn from the jitter.
    pub fn jitter_warning(&self) -> Option<FitWarning> {
        use crate::uncertainty::intervals::PROFILE_68_NATS;
        self.jitter.as_ref()?.warning_above(PROFILE_68_NATS)
    }

    /// The check with the cost's jitter at `u` (`problem`'s normalised coordinates of the point it
    /// checks; none where that point lies outside the search box).
    pub fn with_jitter(self, problem: &SpectralProblem, u: Option<&[f64]>) -> ToleranceCheck {
        ToleranceCheck {
            jitter: u.and_then(|u| RoundingJitter::at(problem, u)),
            ..self
        }
    }

    /// The warning of an optimum the integrator does not resolve, or whose probes all failed;
    /// `None` when it is resolved.
    pub fn warning(&self) -> Option<FitWarning> {
        match self.verdict() {
            Verdict::Resolved => None,
            Verdict::NotProbed => Some(FitWarning::ToleranceNotProbed {
                failures: self.failed.clone(),
            }),
            Verdict::Unresolved => Some(FitWarning::ToleranceUnresolved {
                points: self.points.clone(),
                spread_nats: self.spread_nats,
            }),
        }
    }
}

/// The cost spread by which `check` leaves its optimum unresolved, nats: its spread when the
/// verdict is [`Verdict::Unresolved`], else 0 (a spread within [`SPREAD_WARN_NATS`] is the
/// integrator resolving the optimum; an unprobed one has no spread to widen a margin by).
pub fn unresolved_spread(check: Option<&ToleranceCheck>) -> f64 {
    check
        .filter(|c| c.verdict() == Verdict::Unresolved)
        .map_or(0.0, |c| c.spread_nats)
}

/// The tolerance checks a model choice reads ([`super::select::margin`]): the chosen candidate's
/// (`chosen_check`, at index `chosen`), and those of the candidates with fewer freed parameters
/// that have a model, which a margin widened by an unresolved spread could report instead, each
/// from a simulation at the job's tolerance and the probes (three simulations, counted as that
/// candidate's evaluations). `None` for the others: a candidate with as many parameters or more
/// is reported only for a lower TIC, which no margin changes.
pub(super) fn checks_for_choice(
    fits: &[CandidateFit],
    chosen: usize,
    chosen_check: Option<ToleranceCheck>,
) -> Vec<Option<ToleranceCheck>> {
    let k = fits[chosen].free.len();
    let mut checks: Vec<Option<ToleranceCheck>> = vec![None; fits.len()];
    for (i, f) in fits.iter().enumerate() {
        if f.free.len() >= k || f.cost >= FAILED_COST || interrupt::stop_requested() {
            continue;
        }
        let params = f.problem.params_at(&f.best_u);
        if let Ok(at_job) = f
            .problem
            .params_cost_with_solver(&params, &f.problem.solver)
        {
            checks[i] = ToleranceCheck::run(&f.problem, &params, at_job);
        }
    }
    checks[chosen] = chosen_check;
    checks
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_jitter_beyond_half_a_nat_warns_for_intervals_read_from_the_curvature() {
        // 0.5 nats: a quadratic likelihood's rise at 1σ (PROFILE_68_NATS).
        let with = |sd: Option<f64>| ToleranceCheck {
            jitter: sd.and_then(|sd| RoundingJitter::of(vec![10.0 - sd, 10.0, 10.0 + sd])),
            ..ToleranceCheck::of(Vec::new(), Vec::new())
        };
        match with(Some(0.7)).jitter_warning() {
            Some(FitWarning::CostJitter(j)) => {
                assert!((j.sd_nats - 0.7).abs() < 1e-12, "{}", j.sd_nats);
                assert_eq!(j.rise_limit_nats, 0.5);
            }
            other => panic!("expected cost_jitter, got {other:?}"),
        }
        assert_eq!(with(Some(0.3)).jitter_warning(), None);
        assert_eq!(with(None).jitter_warning(), None);
    }

    fn point(rtol: f64, cost_nats: f64, transitions: usize) -> TolerancePoint {
        TolerancePoint {
            rtol,
            atol: rtol * 1e-2,
            cost_nats,
            transitions,
        }
    }

    /// The check of costs and transitions at rtol 1e-8, 1e-9 and 1e-10.
    fn three(costs: [(f64, usize); 3]) -> ToleranceCheck {
        let rtols = [1e-8, 1e-9, 1e-10];
        let points = rtols.iter().zip(costs);
        ToleranceCheck::of(points.map(|(r, (c, n))| point(*r, c, n)).collect(), vec![])
    }

    #[test]
    fn the_spread_is_the_range_of_the_costs_and_warns_above_half_a_nat() {
        let close = three([(78.317, 160), (78.318, 160), (78.320, 160)]);
        assert!((close.spread_nats - 0.003).abs() < 1e-9);
        assert!(close.resolved() && close.warning().is_none());
        let apart = three([(66.83, 168), (67.03, 170), (69.03, 170)]);
        assert!((apart.spread_nats - 2.2).abs() < 1e-9);
        let w = apart.warning().expect("a 2.2-nat spread warns");
        assert!(
            matches!(&w, FitWarning::ToleranceUnresolved { points, spread_nats }
                if points.len() == 3 && (spread_nats - 2.2).abs() < 1e-9),
            "{w:?}"
        );
        let text = w.to_string();
        assert!(
            text.contains("66.830 nats at rtol 1e-8 (168 transitions)"),
            "{text}"
        );
        assert!(text.contains("2.20 nats apart"), "{text}");
    }

    #[test]
    fn only_an_unresolved_check_has_a_spread_to_widen_a_margin_by() {
        let apart = three([(66.83, 168), (67.03, 170), (69.03, 170)]);
        assert!((unresolved_spread(Some(&apart)) - 2.2).abs() < 1e-9);
        let close = three([(78.317, 160), (78.318, 160), (78.320, 160)]);
        assert_eq!(unresolved_spread(Some(&close)), 0.0);
        let alone = ToleranceCheck::of(vec![point(1e-8, 5.0, 3)], vec!["rtol 1e-9: x".into()]);
        assert_eq!(unresolved_spread(Some(&alone)), 0.0);
        assert_eq!(unresolved_spread(None), 0.0);
    }

    #[test]
    fn a_check_whose_probes_all_failed_has_no_spread_and_is_not_resolved() {
        let alone = ToleranceCheck::of(vec![point(1e-8, 5.0, 3)], vec!["rtol 1e-9: x".into()]);
        assert_eq!(alone.spread_nats, 0.0);
        assert!(!alone.resolved());
        let w = alone.warning().expect("an unchecked optimum warns");
        assert_eq!(
            w,
            FitWarning::ToleranceNotProbed {
                failures: vec!["rtol 1e-9: x".into()]
            }
        );
        assert!(w.to_string().contains("did not run"), "{w}");
    }
}
