//! A parameter the job frees ([`FreeParam`]): which, its bounds, and the normalised coordinate
//! `u ∈ [0, 1]` the search runs in (logarithmic for bounds spanning a factor ≥ 10).

use crate::model::ParamId;
use serde::Serialize;

/// One freed parameter: which, bounds, and whether it is searched on a log scale.
#[derive(Debug, Clone, Serialize)]
pub struct FreeParam {
    pub name: ParamId,
    pub lower: f64,
    pub upper: f64,
    pub log: bool,
}

impl FreeParam {
    /// The parameter `name` freed within `[lower, upper]`, searched on a log scale when the
    /// bounds are positive and span a factor of 10 or more.
    pub fn new(name: ParamId, lower: f64, upper: f64) -> Self {
        FreeParam {
            name,
            lower,
            upper,
            log: lower > 0.0 && upper / lower >= 10.0,
        }
    }
    /// Physical value at normalised coordinate `u` (clamped to [0, 1]).
    pub fn value(&self, u: f64) -> f64 {
        self.value_unclamped(u.clamp(0.0, 1.0))
    }
    /// [`FreeParam::value`] without the clamp: the same map extended beyond the box (for interval
    /// ends).
    pub fn value_unclamped(&self, u: f64) -> f64 {
        if self.log {
            (self.lower.ln() + u * (self.upper / self.lower).ln()).exp()
        } else {
            self.lower + u * (self.upper - self.lower)
        }
    }
    /// Normalised coordinate of `value` (the inverse of [`FreeParam::value`], clamped to [0, 1]).
    pub fn u_of(&self, value: f64) -> f64 {
        let u = if self.log {
            (value / self.lower).ln() / (self.upper / self.lower).ln()
        } else {
            (value - self.lower) / (self.upper - self.lower)
        };
        u.clamp(0.0, 1.0)
    }
    /// d(value)/du at `u`.
    pub fn slope(&self, u: f64) -> f64 {
        if self.log {
            self.value(u) * (self.upper / self.lower).ln()
        } else {
            self.upper - self.lower
        }
    }
}
