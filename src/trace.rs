//! The canonical trace: tracked points in SI units on a time axis.
//!
//! Every importer ends here (pixels, frames, y-down image coordinates never leave `import`), and the
//! simulator's output is turned into the same type, so one spectral estimator serves measurement and
//! model alike (physics.md §4, "compare like with like").
//!
//! Conventions: `t_s` in seconds, positions in metres, physical y **up**, x along the sweep.
//! Missing points are `f64::NAN`, never 0.

/// One tracked point: x and y in metres, one value per time sample (NaN = not tracked there).
#[derive(Debug, Clone, PartialEq)]
pub struct PointTrack {
    /// Name of the point as the tracking tool calls it (`pt1`, `head`, `lip_tip`, ...), or the role
    /// (`head`, `tip`) once assigned.
    pub name: String,
    pub x_m: Vec<f64>,
    pub y_m: Vec<f64>,
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
}
