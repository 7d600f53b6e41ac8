//! The canonical trace: tracked points in SI units on a time axis.
//!
//! Every importer ends here (pixels, frames, y-down image coordinates never leave `import`), and the
//! simulator's output is turned into the same type, so one spectral estimator serves measurement and
//! model alike (physics.md §4, "compare like with like").
//!
//! Conventions: `t_s` in seconds, positions in metres, physical y **up**, x along the sweep.
//! Missing points are `f64::NAN`, never 0.

crate::names::named_enum! {
    /// The roles the model gives tracked points. An import renames the points mapped in
    /// `[recording.import.points]` (or by `--head`, `--tip`) to their role; the fit, the default
    /// signals and the figures read the points called by these names.
    pub enum Role: "point role" {
        /// The blade's head, which the drive moves.
        Head => "head",
        /// The lip's tip on the glass.
        Tip => "tip",
    }
}

/// One tracked point: x and y in metres, one value per time sample (NaN = not tracked there).
#[derive(Debug, Clone, PartialEq)]
pub struct PointTrack {
    /// Name of the point as the tracking tool calls it (`pt1`, `head`, `lip_tip`, ...), or the role
    /// (`head`, `tip`) once assigned.
    pub name: String,
    pub x_m: Vec<f64>,
    pub y_m: Vec<f64>,
}

impl PointTrack {
    /// Number of samples where x or y is NaN (the point was not tracked there).
    pub fn nan_samples(&self) -> usize {
        self.x_m
            .iter()
            .zip(&self.y_m)
            .filter(|(x, y)| x.is_nan() || y.is_nan())
            .count()
    }
}

/// A set of tracked points sharing one time axis.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trace {
    /// Sample times in seconds, strictly increasing. Real frame times are kept as they are (Tracker's
    /// jitter included); uniform resampling is an explicit later step.
    pub t_s: Vec<f64>,
    /// Tracked points; each has `t_s.len()` samples.
    pub points: Vec<PointTrack>,
}

impl Trace {
    /// Number of time samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// The point called `name`, if any.
    pub fn point(&self, name: &str) -> Option<&PointTrack> {
        self.points.iter().find(|p| p.name == name)
    }

    /// The point that plays `role` (the one called by the role's name), if any.
    pub fn role(&self, role: Role) -> Option<&PointTrack> {
        self.point(role.name())
    }

    /// Number of NaN coordinates over all points.
    pub fn nan_count(&self) -> usize {
        self.points
            .iter()
            .map(|p| {
                p.x_m.iter().filter(|v| v.is_nan()).count()
                    + p.y_m.iter().filter(|v| v.is_nan()).count()
            })
            .sum()
    }

    /// Check the invariants stated on the fields: every point has `len()` samples in x and y, and
    /// `t_s` is finite and strictly increasing.
    ///
    /// # Errors
    /// The first violation ([`TraceError`]: the point and its lengths, or the sample and its times).
    pub fn check(&self) -> Result<(), TraceError> {
        let n = self.t_s.len();
        for p in &self.points {
            if p.x_m.len() != n || p.y_m.len() != n {
                return Err(TraceError::Lengths {
                    point: p.name.clone(),
                    x: p.x_m.len(),
                    y: p.y_m.len(),
                    times: n,
                });
            }
        }
        if let Some(i) = self.t_s.iter().position(|t| !t.is_finite()) {
            return Err(TraceError::TimeNotFinite {
                sample: i,
                t_s: self.t_s[i],
            });
        }
        if let Some(i) = self.t_s.windows(2).position(|w| w[1] <= w[0]) {
            return Err(TraceError::TimeNotIncreasing {
                sample: i + 1,
                t_s: self.t_s[i + 1],
                before_s: self.t_s[i],
            });
        }
        Ok(())
    }
}

/// A trace that breaks the invariants stated on [`Trace`]'s fields ([`Trace::check`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TraceError {
    /// A point whose x or y samples are not one per time sample.
    #[error("point {point:?} has {x} x and {y} y samples, the time axis has {times}")]
    Lengths {
        point: String,
        x: usize,
        y: usize,
        times: usize,
    },
    /// A time that is not finite.
    #[error("time sample {sample} is {t_s}")]
    TimeNotFinite { sample: usize, t_s: f64 },
    /// A time not after the one before it.
    #[error("time is not strictly increasing: sample {sample} is {t_s} s after {before_s} s")]
    TimeNotIncreasing {
        sample: usize,
        t_s: f64,
        before_s: f64,
    },
}
