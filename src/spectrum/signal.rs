//! Scalar signals of a trace named by text, as `wiperlab spectrum --signal` takes them: a point's
//! coordinate `<point>_x`, `<point>_y`, the difference of two points `<a>-<b>_x`, `<a>-<b>_y`
//! (e.g. `wstL-shdL_y`, wrist y − shoulder y), or `tip_rel_x` / `tip_rel_y` (`tip-head_x`, `_y`).
//! Point names may themselves contain `-` and `_`: a name is split where the trace's points say.

use crate::trace::{Role, Trace};

/// A signal name that does not resolve against a trace's points ([`SignalExpr::resolve`]);
/// `points` lists the trace's points, comma-separated.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SignalError {
    /// Not `<point>_x`, `<point>_y`, `<a>-<b>_x` or `<a>-<b>_y`.
    #[error("expected <point>_x, <point>_y, <a>-<b>_x or <a>-<b>_y (points: {points})")]
    Form { points: String },
    /// No point of that name, nor two points joined by `-` in it.
    #[error("no point {name:?} and no two points joined by '-' in it (points: {points})")]
    NoPoint { name: String, points: String },
}

/// Which coordinate of a point a signal takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Horizontal, m.
    X,
    /// Vertical (y up), m.
    Y,
}

/// A resolved signal: `a`'s coordinate, minus `b`'s when given, in m.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SignalExpr {
    /// The name given (used for columns and files).
    pub name: String,
    pub a: String,
    pub b: Option<String>,
    pub axis: Axis,
}

impl SignalExpr {
    /// Resolves `text` against the points of `trace`.
    ///
    /// # Errors
    /// [`SignalError`], listing the trace's points, when `text` does not end in `_x` or `_y`, or
    /// names no point (or pair of points joined by `-`) of the trace.
    pub fn resolve(text: &str, trace: &Trace) -> Result<SignalExpr, SignalError> {
        let known = || {
            trace
                .points
                .iter()
                .map(|p| p.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let (stem, axis) = if let Some(s) = text.strip_suffix("_x") {
            (s, Axis::X)
        } else if let Some(s) = text.strip_suffix("_y") {
            (s, Axis::Y)
        } else {
            return Err(SignalError::Form { points: known() });
        };
        let has = |n: &str| trace.point(n).is_some();
        let (a, b) = if stem == "tip_rel" && !has("tip_rel") {
            (
                Role::Tip.name().to_string(),
                Some(Role::Head.name().to_string()),
            )
        } else if has(stem) {
            (stem.to_string(), None)
        } else {
            let split = stem
                .match_indices('-')
                .map(|(i, _)| (&stem[..i], &stem[i + 1..]))
                .find(|(a, b)| has(a) && has(b))
                .ok_or_else(|| SignalError::NoPoint {
                    name: stem.to_string(),
                    points: known(),
                })?;
            (split.0.to_string(), Some(split.1.to_string()))
        };
        for p in std::iter::once(&a).chain(&b) {
            if !has(p) {
                return Err(SignalError::NoPoint {
                    name: p.clone(),
                    points: known(),
                });
            }
        }
        Ok(SignalExpr {
            name: text.to_string(),
            a,
            b,
            axis,
        })
    }

    /// The signal's samples from `trace` (NaN where a point is missing); a point the trace lacks
    /// (not the trace it was resolved against) gives all NaN.
    pub fn extract(&self, trace: &Trace) -> Vec<f64> {
        let coord = |name: &str| -> Vec<f64> {
            match (trace.point(name), self.axis) {
                (Some(p), Axis::X) => p.x_m.clone(),
                (Some(p), Axis::Y) => p.y_m.clone(),
                (None, _) => vec![f64::NAN; trace.t_s.len()],
            }
        };
        let a = coord(&self.a);
        match &self.b {
            None => a,
            Some(b) => a.iter().zip(coord(b)).map(|(x, y)| x - y).collect(),
        }
    }

    /// The signals `spectrum` analyses by default: every point's x and y, and `tip_rel_x` when
    /// the trace has a head and a tip.
    pub fn defaults(trace: &Trace) -> Vec<SignalExpr> {
        let mut out = Vec::new();
        for p in &trace.points {
            for (suffix, axis) in [("_x", Axis::X), ("_y", Axis::Y)] {
                out.push(SignalExpr {
                    name: format!("{}{suffix}", p.name),
                    a: p.name.clone(),
                    b: None,
                    axis,
                });
            }
        }
        if trace.role(Role::Head).is_some() && trace.role(Role::Tip).is_some() {
            out.push(SignalExpr {
                name: "tip_rel_x".into(),
                a: Role::Tip.name().into(),
                b: Some(Role::Head.name().into()),
                axis: Axis::X,
            });
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::PointTrack;

    fn trace() -> Trace {
        let p = |name: &str, x: f64, y: f64| PointTrack {
            name: name.into(),
            x_m: vec![x, f64::NAN],
            y_m: vec![y, 1.0],
        };
        Trace {
            t_s: vec![0.0, 1.0],
            points: vec![
                p("head", 1.0, 2.0),
                p("tip", 5.0, 7.0),
                p("left-wrist", 10.0, 20.0),
                p("shd_L", 3.0, 4.0),
            ],
        }
    }

    #[test]
    fn names_resolve_to_points_and_differences() {
        let t = trace();
        let get = |s: &str| SignalExpr::resolve(s, &t).unwrap().extract(&t);
        assert_eq!(get("tip_x")[0], 5.0);
        assert_eq!(get("shd_L_y"), [4.0, 1.0]);
        assert_eq!(get("left-wrist-shd_L_y"), [16.0, 0.0]);
        assert_eq!(get("tip-head_y"), [5.0, 0.0]);
        assert_eq!(get("tip_rel_x")[0], 4.0);
        assert!(get("tip_rel_x")[1].is_nan());
        assert_eq!(get("tip_rel_y")[0], 5.0);
    }

    #[test]
    fn unknown_points_are_named_with_the_known_ones() {
        let t = trace();
        let points = "head, tip, left-wrist, shd_L".to_string();
        assert_eq!(
            SignalExpr::resolve("wrist-shoulder_y", &t),
            Err(SignalError::NoPoint {
                name: "wrist-shoulder".into(),
                points: points.clone(),
            })
        );
        let e = SignalExpr::resolve("tip_z", &t).unwrap_err();
        assert_eq!(e, SignalError::Form { points });
        assert!(e.to_string().contains("expected <point>_x"), "{e}");
    }
}
