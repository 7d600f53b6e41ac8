//! What an estimate is made of, as data: each fitted parameter with its interval and the method
//! that gave it ([`interval`]), and the warnings that qualify it ([`warning`]).
//!
//! The search, the intervals and the model choice all fill these in, so they come before those
//! stages; [`crate::fit::FitResult`] gathers them into the result file.

pub mod interval;
pub mod warning;

pub use interval::{FittedParam, Interval, IntervalMethod};
pub use warning::{End, FitWarning, LineSource, SampledReason, Severity, TolerancePoint};
