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
    /// A sentence naming the first violation (point name and lengths, or the sample index and times).
    pub fn check(&self) -> Result<(), String> {
        let n = self.t_s.len();
        for p in &self.points {
            if p.x_m.len() != n || p.y_m.len() != n {
                return Err(format!(
                    "point {:?} has {} x and {} y samples, the time axis has {n}",
                    p.name,
                    p.x_m.len(),
                    p.y_m.len()
                ));
            }
        }
        if let Some(i) = self.t_s.iter().position(|t| !t.is_finite()) {
            return Err(format!("time sample {i} is {}", self.t_s[i]));
        }
        if let Some(i) = self.t_s.windows(2).position(|w| w[1] <= w[0]) {
            return Err(format!(
                "time is not strictly increasing: sample {} is {} s after {} s",
                i + 1,
                self.t_s[i + 1],
                self.t_s[i]
            ));
        }
        Ok(())
    }
}
