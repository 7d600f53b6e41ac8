//! The Runge–Kutta pair that integrates each smooth phase, chosen by [`Method`]: DOPRI5
//! ([`super::rk`]) or DOP853 ([`super::dop853`]). Both give an accepted step's end state, the
//! derivative there and a continuous extension ([`Dense`]) on which events are located.

use super::{dop853, rk};
use crate::names::named_enum;

named_enum! {
    /// The integrator of the smooth phases (`method` in `[solver]`, `--method` of `simulate`).
    pub enum Method: "method" {
        /// Dormand–Prince 5(4) with 4th-order dense output: 6 evaluations per step.
        Dopri5 => "dopri5",
        /// Dormand–Prince 8(5,3) with 7th-order dense output: 15 evaluations per accepted step,
        /// 11 per rejected one.
        Dop853 => "dop853",
    }
}

/// The continuous extension of one accepted step of either method.
#[derive(Debug, Clone, Copy)]
pub enum Dense<const N: usize> {
    Dopri5(rk::Dense<N>),
    Dop853(dop853::Dense<N>),
}

impl<const N: usize> Dense<N> {
    /// State at `t_eval` inside the step (exact at both ends).
    #[inline]
    pub fn eval(&self, t_eval: f64) -> [f64; N] {
        match self {
            Dense::Dopri5(d) => d.eval(t_eval),
            Dense::Dop853(d) => d.eval(t_eval),
        }
    }
}

/// An accepted step: end state, derivative there, error norm and continuous extension.
pub struct Step<const N: usize> {
    pub y_new: [f64; N],
    pub f_new: [f64; N],
    pub err: f64,
    pub dense: Dense<N>,
}

/// The outcome of one attempted step.
pub enum Outcome<const N: usize> {
    /// The error norm was ≤ 1: the finished step.
    Accepted(Step<N>),
    /// The error norm `err` was > 1, or not finite (also when the new state is not finite).
    Rejected { err: f64 },
}

impl Method {
    /// Attempts one step of size `h` from `(t, y)` with derivative `f0 = f(t, y)`, and finishes it
    /// when its error norm is ≤ 1. `rhs` fails (`Err`) where the derivative cannot be evaluated.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn attempt<const N: usize, E>(
        self,
        rhs: &mut impl FnMut(f64, &[f64; N], &mut [f64; N]) -> Result<(), E>,
        t: f64,
        y: &[f64; N],
        f0: &[f64; N],
        h: f64,
        rtol: f64,
        atol: f64,
    ) -> Result<Outcome<N>, E> {
        match self {
            Method::Dopri5 => {
                let a = rk::attempt(rhs, t, y, f0, h, rtol, atol)?;
                let finite = a.y_new.iter().all(|v| v.is_finite());
                Ok(if a.err <= 1.0 && finite {
                    Outcome::Accepted(Step {
                        y_new: a.y_new,
                        f_new: a.f_new,
                        err: a.err,
                        dense: Dense::Dopri5(a.dense),
                    })
                } else {
                    Outcome::Rejected {
                        err: if finite { a.err } else { f64::INFINITY },
                    }
                })
            }
            Method::Dop853 => {
                let trial = dop853::attempt(rhs, t, y, f0, h, rtol, atol)?;
                if trial.err > 1.0 {
                    return Ok(Outcome::Rejected { err: trial.err });
                }
                let a = trial.finish(rhs)?;
                Ok(Outcome::Accepted(Step {
                    y_new: a.y_new,
                    f_new: a.f_new,
                    err: a.err,
                    dense: Dense::Dop853(a.dense),
                }))
            }
        }
    }

    /// The step size after a step with error norm `err` (each method's own controller).
    #[inline]
    pub fn next_step(self, h: f64, err: f64) -> f64 {
        match self {
            Method::Dopri5 => rk::next_step(h, err),
            Method::Dop853 => dop853::next_step(h, err),
        }
    }

    /// The step size after an accepted step with error norm `err`; `after_reject` when the attempt
    /// before it was rejected. DOP853 then does not grow the step (`dop853.f`); DOPRI5 keeps its
    /// controller unchanged.
    #[inline]
    pub fn next_step_after(self, h: f64, err: f64, after_reject: bool) -> f64 {
        let h_new = self.next_step(h, err);
        if after_reject && self == Method::Dop853 {
            h_new.min(h)
        } else {
            h_new
        }
    }
}
