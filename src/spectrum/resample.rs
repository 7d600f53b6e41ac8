//! Non-uniform → uniform time base.
//!
//! Real camera frame times jitter (Tracker exports the times it was given), while Welch and the
//! spectrogram assume uniform sampling. [`resample_uniform`] puts a record on the grid
//! `t0 + k/fs` by linear interpolation, keeping NaN (missing samples) as NaN so that
//! [`welch_gappy`](super::welch_gappy) can still see the gaps. [`median_rate_hz`] gives the robust
//! nominal rate to resample at.
//!
//! Accuracy: linear interpolation over an interval `h` errs by at most `h²·max|x''|/8`, i.e.
//! `A·(2πf·h)²/8` for a sinusoid of amplitude `A` and frequency `f`; keep the frame rate well above
//! the highest frequency of interest.

use super::SpectrumError;
use crate::Result;

/// The median sampling rate `1/median(Δt)` in Hz of the time stamps `t_s` (seconds).
///
/// Only finite, positive intervals count, so a repeated or missing (NaN) stamp does not distort the
/// result. Returns NaN if there is no such interval (fewer than two finite, increasing stamps).
pub fn median_rate_hz(t_s: &[f64]) -> f64 {
    let mut dt: Vec<f64> = t_s
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| d.is_finite() && *d > 0.0)
        .collect();
    1.0 / super::stats::median_in_place(&mut dt)
}

/// Linear interpolation of `x(t_s)` onto the uniform grid `t0 + k/fs_hz`, `t0 = t_s[0]`, for every
/// `k` with `t0 + k/fs ≤ t_s.last()` (a relative tolerance of 1e-9 sample covers rounding).
///
/// Returns `(t0, samples)`. NaN is preserved: a grid point that falls strictly between two stamps,
/// either of which is NaN, is NaN; a grid point that coincides with a stamp takes that sample.
///
/// Errors: [`SpectrumError`] (`Resample*`) if `t_s` and `x` differ in length, are empty, or the
/// times are not finite and strictly increasing; [`SpectrumError::SamplingRate`] if `fs_hz` is not
/// finite and positive.
pub fn resample_uniform(t_s: &[f64], x: &[f64], fs_hz: f64) -> Result<(f64, Vec<f64>)> {
    super::welch::check_fs(fs_hz)?;
    if t_s.len() != x.len() {
        return Err(SpectrumError::ResampleLengths {
            times: t_s.len(),
            samples: x.len(),
        }
        .into());
    }
    if t_s.is_empty() {
        return Err(SpectrumError::ResampleEmpty.into());
    }
    if let Some(i) = t_s.iter().position(|t| !t.is_finite()) {
        return Err(SpectrumError::ResampleTime {
            index: i,
            t_s: t_s[i],
        }
        .into());
    }
    if let Some(i) = t_s.windows(2).position(|w| w[1] <= w[0]) {
        return Err(SpectrumError::ResampleOrder {
            index: i + 1,
            before_s: t_s[i],
            after_s: t_s[i + 1],
        }
        .into());
    }
    let t0 = t_s[0];
    let last = t_s.len() - 1;
    let span = t_s[last] - t0;
    let n_out = (span * fs_hz + 1e-9).floor() as usize + 1;
    let mut out = Vec::with_capacity(n_out);
    let mut j = 0; // invariant: t_s[j] ≤ t (for t within the record)
    for k in 0..n_out {
        let t = t0 + k as f64 / fs_hz;
        while j < last && t_s[j + 1] <= t {
            j += 1;
        }
        let v = if j == last || t == t_s[j] {
            x[j]
        } else {
            let (ta, tb) = (t_s[j], t_s[j + 1]);
            let (a, b) = (x[j], x[j + 1]);
            if a.is_nan() || b.is_nan() {
                f64::NAN
            } else {
                a + (b - a) * ((t - ta) / (tb - ta))
            }
        };
        out.push(v);
    }
    Ok((t0, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_rate_ignores_bad_intervals() {
        let t = [0.0, 0.001, 0.002, 0.002, f64::NAN, 0.004, 0.005];
        assert!((median_rate_hz(&t) - 1000.0).abs() < 1e-9);
        assert!(median_rate_hz(&[1.0]).is_nan());
        assert!(median_rate_hz(&[]).is_nan());
    }

    #[test]
    fn exact_on_uniform_and_linear_data() {
        let t: Vec<f64> = (0..11).map(|k| 2.0 + k as f64 * 0.1).collect();
        let x: Vec<f64> = t.iter().map(|t| 3.0 * t - 1.0).collect();
        let (t0, y) = resample_uniform(&t, &x, 20.0).unwrap();
        assert_eq!(t0, 2.0);
        assert_eq!(y.len(), 21);
        for (k, v) in y.iter().enumerate() {
            let tk = 2.0 + k as f64 / 20.0;
            assert!((v - (3.0 * tk - 1.0)).abs() < 1e-12);
        }
    }

    #[test]
    fn nan_is_preserved_and_bad_input_rejected() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let x = [0.0, f64::NAN, 2.0, 3.0];
        let (_, y) = resample_uniform(&t, &x, 2.0).unwrap();
        // grid 0, .5, 1, 1.5, 2, 2.5, 3
        assert_eq!(y[0], 0.0);
        assert!(y[1].is_nan() && y[2].is_nan() && y[3].is_nan());
        assert_eq!(y[4], 2.0);
        assert_eq!(y[5], 2.5);
        assert_eq!(y[6], 3.0);
        assert!(resample_uniform(&t, &x[..3], 2.0).is_err());
        assert!(resample_uniform(&[], &[], 2.0).is_err());
        assert!(resample_uniform(&[0.0, 0.0], &[1.0, 1.0], 2.0).is_err());
        assert!(resample_uniform(&t, &x, 0.0).is_err());
    }
}

/// Every coordinate of a trace on one uniform time grid, ready for Welch.
#[derive(Debug, Clone)]
pub struct UniformSignals {
    /// Sampling rate of the grid, Hz: the median frame rate of the trace.
    pub fs_hz: f64,
    /// False when the frame times were uniform already (within 1e-6 of a step) and the samples
    /// are the trace's own; true when they were linearly interpolated onto the grid.
    pub resampled: bool,
    /// `(name, samples)` per signal (`<point>_x`, `<point>_y`, `tip_rel_x`, `<a>-<b>_y`, ...), in m,
    /// NaN where missing.
    pub signals: Vec<(String, Vec<f64>)>,
}

/// Every tracked coordinate of `trace` (and the tip relative to the head, when both are tracked)
/// on a uniform grid at the median frame rate ([`uniform_signals_for`] with
/// [`SignalExpr::defaults`](super::signal::SignalExpr::defaults)).
///
/// # Errors
/// As [`resample_uniform`].
pub fn uniform_signals(trace: &crate::trace::Trace) -> Result<UniformSignals> {
    uniform_signals_for(trace, &super::signal::SignalExpr::defaults(trace))
}

/// The signals `exprs` of `trace` on a uniform grid at the median frame rate. Frame-indexed files
/// (t = frame/fps) are uniform already: resampling them would only smear each NaN over its
/// neighbours through the rounding of the grid, so their samples are taken as they are.
///
/// # Errors
/// As [`resample_uniform`].
pub fn uniform_signals_for(
    trace: &crate::trace::Trace,
    exprs: &[super::signal::SignalExpr],
) -> Result<UniformSignals> {
    let fs = median_rate_hz(&trace.t_s);
    let t0 = trace.t_s.first().copied().unwrap_or(0.0);
    let already_uniform = trace
        .t_s
        .iter()
        .enumerate()
        .all(|(k, t)| (t - (t0 + k as f64 / fs)).abs() <= 1e-6 / fs);
    let uniform = |x: &[f64]| -> Result<Vec<f64>> {
        if already_uniform {
            return Ok(x.to_vec());
        }
        Ok(resample_uniform(&trace.t_s, x, fs)?.1)
    };
    let mut signals = Vec::new();
    for e in exprs {
        signals.push((e.name.clone(), uniform(&e.extract(trace))?));
    }
    Ok(UniformSignals {
        fs_hz: fs,
        resampled: !already_uniform,
        signals,
    })
}
