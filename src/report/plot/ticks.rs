//! Axis tick positions and labels, computed by us rather than by plotters.
//!
//! Why: plotters 0.3.7's `LogCoord` skips every key point below `f64::EPSILON` (its `is_inf` test
//! compares against machine epsilon), so a PSD in m²/Hz (≈ 1e-20) loses its tick labels; and its
//! linear key points can print rounding noise (`-1.36e-20` instead of `0`). Ticks here are exact
//! multiples of a 1-2-2.5-5 step (linear) or powers of ten (log), and log axes are drawn as linear
//! axes over `log10` of the data.

use std::ops::Range;

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;

/// Tick marks of one axis, in the plotted plane (`log10` of the data for a log axis).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ticks {
    /// Labelled ticks (bold grid lines).
    pub bold: Vec<f64>,
    /// Unlabelled minor grid lines.
    pub light: Vec<f64>,
    labels: Labels,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Labels {
    /// Fixed-point with this many decimals.
    Fixed(usize),
    /// Scientific with this many mantissa decimals (`1.5e-4`).
    Sci(usize),
    /// The plane value is `log10` of the data: print `10^v` compactly.
    Log,
}

impl Ticks {
    /// The label of tick `v` (a plane coordinate).
    pub fn label(&self, v: f64) -> String {
        match self.labels {
            Labels::Fixed(d) => {
                if v == 0.0 {
                    "0".into()
                } else {
                    format!("{v:.d$}")
                }
            }
            Labels::Sci(d) => {
                if v == 0.0 {
                    "0".into()
                } else {
                    sci(v, d)
                }
            }
            Labels::Log => compact(10f64.powf(v)),
        }
    }
}

/// A linear plotters axis over `range` whose key points are our [`Ticks`]. (plotters'
/// `WithKeyPoints<RangedCoordf64>` would do, but it lacks the `ValueFormatter` impl that
/// `configure_mesh` requires; labels come from [`Ticks::label`] via a label formatter anyway.)
pub(crate) struct TickAxis {
    inner: RangedCoordf64,
    bold: Vec<f64>,
    light: Vec<f64>,
}

impl TickAxis {
    pub fn new(range: Range<f64>, ticks: &Ticks) -> Self {
        TickAxis {
            inner: range.into(),
            bold: ticks.bold.clone(),
            light: ticks.light.clone(),
        }
    }
}

impl Ranged for TickAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.inner.range()
    }
}

/// `v` in scientific notation with `d` mantissa decimals, trailing zeros trimmed: `1.50e-4` →
/// `1.5e-4`, `5.0e3` → `5e3`.
fn sci(v: f64, d: usize) -> String {
    let s = format!("{v:.d$e}");
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => s,
    }
}

/// Compact label for a value of any size (3 significant digits): `0.01`, `250`, `1e-9`, `2.5e6`.
pub(crate) fn compact(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return sci(v, 2);
    }
    let decimals = (2 - a.log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A "nice" step (1, 2, 2.5 or 5 × 10^e) giving about `target` intervals over `span`; returns the
/// step and its mantissa.
fn nice_step(span: f64, target: usize) -> (f64, f64) {
    let raw = span / target.max(1) as f64;
    let e = raw.log10().floor();
    let base = 10f64.powf(e);
    let m = raw / base;
    let nm = if m <= 1.0 {
        1.0
    } else if m <= 2.0 {
        2.0
    } else if m <= 2.5 {
        2.5
    } else if m <= 5.0 {
        5.0
    } else {
        10.0
    };
    if nm == 10.0 {
        (base * 10.0, 1.0)
    } else {
        (nm * base, nm)
    }
}

/// Multiples `k·step` inside `[lo, hi]` (exact 0 at k = 0).
fn multiples(lo: f64, hi: f64, step: f64) -> impl Iterator<Item = (i64, f64)> {
    let k0 = (lo / step - 1e-9).ceil() as i64;
    let k1 = (hi / step + 1e-9).floor() as i64;
    (k0..=k1).map(move |k| (k, k as f64 * step))
}

/// Linear ticks over `[lo, hi]` (`lo < hi`, finite), about `target` intervals.
pub(crate) fn linear(lo: f64, hi: f64, target: usize) -> Ticks {
    let (step, m) = nice_step(hi - lo, target);
    let bold: Vec<f64> = multiples(lo, hi, step).map(|(_, v)| v).collect();
    let div = if m == 2.0 { 4 } else { 5 };
    let light: Vec<f64> = multiples(lo, hi, step / div as f64)
        .filter(|(k, _)| k % div != 0)
        .map(|(_, v)| v)
        .collect();
    let extra = usize::from(m == 2.5);
    let step_exp = step.log10().floor() as i32;
    let max_abs = lo.abs().max(hi.abs());
    let labels = if !(1e-3..1e5).contains(&max_abs) {
        let d = (max_abs.log10().floor() as i32 - step_exp).clamp(0, 6) as usize + extra;
        Labels::Sci(d)
    } else {
        Labels::Fixed((-step_exp).max(0) as usize + extra)
    };
    Ticks {
        bold,
        light,
        labels,
    }
}

/// Log ticks over the plane range `[a, b]` = `[log10 lo, log10 hi]`: decades (every k-th if there
/// are many), with 2× and 5× added when fewer than two decades are in range.
pub(crate) fn log(a: f64, b: f64) -> Ticks {
    let k0 = (a - 1e-9).ceil() as i64;
    let k1 = (b + 1e-9).floor() as i64;
    let n = (k1 - k0 + 1).max(0);
    let inside = |v: f64| v >= a - 1e-9 && v <= b + 1e-9;
    let sub = |ms: &[f64]| -> Vec<f64> {
        ((a.floor() as i64)..=(b.ceil() as i64))
            .flat_map(|k| ms.iter().map(move |m| k as f64 + m.log10()))
            .filter(|v| inside(*v))
            .collect()
    };
    let (bold, light) = if n >= 2 {
        let stride = (n as usize).div_ceil(8).max(1) as i64;
        let bold: Vec<f64> = (k0..=k1)
            .filter(|k| k.rem_euclid(stride) == 0)
            .map(|k| k as f64)
            .collect();
        let light = if stride == 1 {
            sub(&[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
        } else {
            (k0..=k1)
                .filter(|k| k.rem_euclid(stride) != 0)
                .map(|k| k as f64)
                .collect()
        };
        (bold, light)
    } else {
        let bold = sub(&[1.0, 2.0, 5.0]);
        let light = sub(&[3.0, 4.0, 6.0, 7.0, 8.0, 9.0]);
        (bold, light)
    };
    if bold.len() >= 2 {
        return Ticks {
            bold,
            light,
            labels: Labels::Log,
        };
    }
    // Less than a factor 2.5 of range: linear ticks in value space, placed on the log plane.
    let lin = linear(10f64.powf(a), 10f64.powf(b), 5);
    Ticks {
        bold: lin.bold.iter().map(|v| v.log10()).collect(),
        light: lin.light.iter().map(|v| v.log10()).collect(),
        labels: Labels::Log,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_ticks_are_exact_and_labelled_cleanly() {
        let t = linear(-1.4e-4, 1.4e-4, 6);
        assert!(t.bold.contains(&0.0));
        let labels: Vec<String> = t.bold.iter().map(|v| t.label(*v)).collect();
        assert_eq!(labels, ["-1e-4", "-5e-5", "0", "5e-5", "1e-4"]);
        let t = linear(0.0, 0.4, 8);
        let labels: Vec<String> = t.bold.iter().map(|v| t.label(*v)).collect();
        assert_eq!(
            labels,
            [
                "0", "0.05", "0.10", "0.15", "0.20", "0.25", "0.30", "0.35", "0.40"
            ]
        );
        let t = linear(0.0, 10.0, 4);
        assert_eq!(t.bold, [0.0, 2.5, 5.0, 7.5, 10.0]);
        assert_eq!(t.label(2.5), "2.5");
        let t = linear(1000.0, 1000.5, 5);
        assert_eq!(t.label(t.bold[1]), "1000.1");
    }

    #[test]
    fn log_ticks_survive_tiny_values() {
        // A PSD from 1e-21 to 1e-8 m²/Hz: every decade labelled or strided, never dropped.
        let t = log(-21.0, -8.0);
        assert!(t.bold.len() >= 5);
        assert!(t.bold.contains(&-20.0));
        assert_eq!(t.label(-20.0), "1e-20");
        let t = log(1.0, 3.5);
        assert_eq!(t.bold, [1.0, 2.0, 3.0]);
        assert_eq!(t.label(2.0), "100");
        // Under one decade: 2× and 5× appear.
        let t = log(1.1, 1.9);
        let labels: Vec<String> = t.bold.iter().map(|v| t.label(*v)).collect();
        assert_eq!(labels, ["20", "50"]);
        // A factor 1.2: falls back to linear ticks.
        let t = log(0.0, 0.08);
        assert!(t.bold.len() >= 2);
    }

    #[test]
    fn compact_labels() {
        assert_eq!(compact(0.0), "0");
        assert_eq!(compact(100.0), "100");
        assert_eq!(compact(0.25), "0.25");
        assert_eq!(compact(1e-6), "1e-6");
        assert_eq!(compact(2.5e6), "2.5e6");
        assert_eq!(compact(10f64.powf(-9.0)), "1e-9");
    }
}
