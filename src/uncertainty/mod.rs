//! The uncertainty of the chosen fit: an interval for every freed parameter, by the job's method
//! (`[fit.uncertainty] method`), and the warnings that say where an interval cannot be trusted.
//!
//! * [`intervals`]: Laplace's (the sandwich covariance at the fit), the profile likelihood, the
//!   parametric bootstrap, a posterior sample (`mcmc`, or `auto` where the likelihood reaches
//!   beyond Laplace's), and the widenings to the points the search evaluated.
//! * [`climb`]: the profile climb, which walks the chosen fit's profiles before its intervals and
//!   moves the fit where a walk meets a more likely point.

pub mod climb;
pub mod intervals;

pub use intervals::{
    MIN_ESS, PROFILE_95_NATS, ProfileStart, RHAT_LIMIT, bootstrap_intervals, floored_range_95,
    identifiability_warnings, laplace_intervals, mu_d_rise_limits, posterior_tempering,
    profile_intervals_at, valley_start, wide_over_68_half_widths, widen_to_near_best,
};
/// The chosen fit's intervals by the job's method ([`intervals::intervals`]), and the friction laws
/// of the points the search evaluated near its best ([`intervals::near_best_laws`]).
pub(crate) use intervals::{intervals, near_best_laws};
