//! What a band's line is: a line of its own, or a harmonic of a stronger line elsewhere in the
//! spectrum, and how far below the spectrum's dominant line it lies.
//!
//! A stick–slip cycle is periodic but far from sinusoidal, so its spectrum is a comb: the cycle's
//! fundamental `f₀` and lines at `n·f₀`. A band that starts above `f₀` then reports a harmonic as
//! its "peak" (on the seed experiment's blade the 30–300 Hz band picked the 2nd harmonic of a 26 Hz
//! cycle, and its 3rd sits at 78–80 Hz). [`classify_line`] tells: a line at `f` is called harmonic
//! `n ≥ 2` of a fundamental `f₀` when
//!
//! - `f₀` is a local maximum of the PSD at least as strong as the line and at least
//!   [`MIN_PROMINENCE`] × its local floor (the peak module's prominence: a line, not a noise bump),
//! - `|f − n·f₀| ≤ max(2 bins, 2 % of f)` for the integer `n = round(f/f₀)` (the tolerance covers
//!   the interpolated frequencies' error and a comb whose spacing drifts a little over the window),
//! - that tolerance is under a quarter of `f₀` (else a coarse band's bins span several lines of
//!   the comb and the multiple is ambiguous),
//! - and the largest such `f₀` is taken (the lowest order `n` that explains the line).
//!
//! The spectrum's **dominant line** is its largest local maximum with that prominence at or above
//! `min_freq_hz` (the
//! lowest frequency the caller trusts: a few Welch bins up from 0 Hz, where detrending and the
//! window's main lobe leave no line). Units: Hz, and the PSD's own units (ratios are of powers).

use super::peaks::{Peak, top_peaks};
use serde::{Deserialize, Serialize};

/// Prominence (power over the local median floor) a line needs to count as a fundamental.
pub const MIN_PROMINENCE: f64 = 5.0;

/// How many of the spectrum's largest local maxima are tried as fundamentals.
const CANDIDATES: usize = 24;

/// The line a band's line is a harmonic of.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Fundamental {
    /// Its frequency, Hz.
    pub freq_hz: f64,
    /// Harmonic number of the band's line, `round(f/f₀) ≥ 2`.
    pub order: u32,
    /// Its PSD level over the band line's (≥ 1: the fundamental is the stronger).
    pub level_ratio: f64,
}

/// What a line is ([`classify_line`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineOrigin {
    /// The line's frequency, Hz.
    pub freq_hz: f64,
    /// Its prominence over the local floor (power ratio; [`Peak::prominence`]).
    pub prominence: f64,
    /// The stronger line it is a harmonic of, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub harmonic_of: Option<Fundamental>,
    /// The spectrum's dominant line, Hz.
    pub dominant_hz: f64,
    /// The dominant line's level over this line's (1 when it is the dominant one).
    pub below_dominant: f64,
}

impl LineOrigin {
    /// One sentence for a warning when the line is a harmonic, stands less than
    /// [`MIN_PROMINENCE`]× over its local floor (or its floor cannot be measured), or lies more than
    /// 100× below the spectrum's dominant line; `None` otherwise. `what` names the line, e.g. "the
    /// model's line in band 'low'".
    pub fn concern(&self, what: &str) -> Option<String> {
        let mut parts = Vec::new();
        if self.prominence.is_nan() {
            parts.push(
                "has no measurable prominence (the band's Welch bins are too coarse for a floor within ±30 % of the line, more than 3 bins from it)"
                    .to_string(),
            );
        } else if self.prominence < MIN_PROMINENCE {
            parts.push(format!(
                "stands only {:.1}× over its local floor (a prominent line needs {MIN_PROMINENCE}×)",
                self.prominence
            ));
        }
        if let Some(h) = self.harmonic_of {
            parts.push(format!(
                "is harmonic {} of a line at {:.2} Hz that is {:.1}× stronger (a stick–slip comb: the band sees a harmonic, not the cycle's fundamental)",
                h.order, h.freq_hz, h.level_ratio
            ));
        }
        if self.below_dominant > 100.0 {
            parts.push(format!(
                "lies {:.3e}× below the spectrum's dominant line at {:.2} Hz",
                self.below_dominant, self.dominant_hz
            ));
        }
        (!parts.is_empty())
            .then(|| format!("{what} at {:.2} Hz {}", self.freq_hz, parts.join(", and ")))
    }
}

/// Classifies `line`, a peak of the one-sided PSD `psd` at frequencies `freq_hz`, against the whole
/// spectrum from `min_freq_hz` up (module docs). `None` when the spectrum has no local maximum
/// there.
pub fn classify_line(
    freq_hz: &[f64],
    psd: &[f64],
    line: &Peak,
    min_freq_hz: f64,
) -> Option<LineOrigin> {
    let top_hz = freq_hz.last().copied()?;
    let mut peaks = top_peaks(freq_hz, psd, (min_freq_hz, top_hz), CANDIDATES);
    peaks.first()?;
    for p in &mut peaks {
        p.prominence = prominence(psd, p);
    }
    // The dominant line: the largest prominent local maximum (a leakage shoulder near 0 Hz is no
    // line), else the line itself.
    let dominant = peaks
        .iter()
        .find(|p| p.prominence >= MIN_PROMINENCE)
        .unwrap_or(line);
    let bin = if freq_hz.len() > 1 {
        freq_hz[1] - freq_hz[0]
    } else {
        f64::INFINITY
    };
    let tolerance = (2.0 * bin).max(0.02 * line.freq_hz);
    let harmonic_of = peaks
        .iter()
        .filter(|p| {
            p.level >= line.level
                && p.prominence >= MIN_PROMINENCE
                && p.freq_hz <= line.freq_hz / 1.5
                && p.freq_hz > 0.0
        })
        // Only where the tolerance is under a quarter of the comb's spacing is the multiple
        // unambiguous (a coarse band's 2 bins can span several lines of a dense comb).
        .filter(|p| tolerance < 0.25 * p.freq_hz)
        .filter_map(|p| {
            let n = (line.freq_hz / p.freq_hz).round();
            (n >= 2.0 && (line.freq_hz - n * p.freq_hz).abs() <= tolerance).then_some(Fundamental {
                freq_hz: p.freq_hz,
                order: n as u32,
                level_ratio: p.level / line.level,
            })
        })
        .max_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    Some(LineOrigin {
        freq_hz: line.freq_hz,
        prominence: line.prominence,
        harmonic_of,
        dominant_hz: dominant.freq_hz,
        below_dominant: (dominant.level / line.level).max(1.0),
    })
}

/// A peak's prominence, or where the peak module's ±30 % frequency window holds no bin beyond its
/// ±3-bin exclusion (a line a few bins above 0 Hz), the same ratio over the 24 bins on either side.
fn prominence(psd: &[f64], p: &Peak) -> f64 {
    if p.prominence.is_finite() || p.prominence == f64::INFINITY {
        return p.prominence;
    }
    let k = p.bin;
    let mut v: Vec<f64> = (k.saturating_sub(24)..(k + 25).min(psd.len()))
        .filter(|j| j.abs_diff(k) > 3 && psd[*j].is_finite())
        .map(|j| psd[j])
        .collect();
    if v.is_empty() {
        return f64::NAN;
    }
    let med = super::stats::median_in_place(&mut v);
    if med > 0.0 {
        psd[k] / med
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::{WelchConfig, find_peak, welch};

    /// A square-ish wave: odd harmonics of `f0` with amplitudes 1/n (a square wave's Fourier series,
    /// 4/π · Σ sin(2π n f0 t)/n), sampled at 10 kHz, 4 s.
    fn square(f0: f64) -> (Vec<f64>, Vec<f64>) {
        let fs = 1e4;
        let x: Vec<f64> = (0..40_000)
            .map(|i| {
                let t = i as f64 / fs;
                (1..=15)
                    .step_by(2)
                    .map(|n| (2.0 * std::f64::consts::PI * n as f64 * f0 * t).sin() / n as f64)
                    .sum()
            })
            .collect();
        let p = welch(&x, fs, &WelchConfig::new(4096)).unwrap();
        (p.freq_hz, p.density)
    }

    #[test]
    fn a_band_above_the_fundamental_sees_its_third_harmonic() {
        // Fundamental 26 Hz; a band from 30 Hz finds the 3rd harmonic at 78 Hz (power 1/9 of the
        // fundamental's: amplitudes 1/3).
        let (f, p) = square(26.0);
        let line = find_peak(&f, &p, (30.0, 300.0)).unwrap();
        assert!((line.freq_hz - 78.0).abs() < 0.5, "{}", line.freq_hz);
        let o = classify_line(&f, &p, &line, 5.0).unwrap();
        let h = o.harmonic_of.expect("a harmonic");
        assert_eq!(h.order, 3);
        assert!((h.freq_hz - 26.0).abs() < 0.5, "{h:?}");
        // Level ratio 9 (amplitude ratio 3, squared), within the window's scalloping.
        assert!((h.level_ratio - 9.0).abs() < 1.5, "{h:?}");
        assert!((o.dominant_hz - 26.0).abs() < 0.5);
        assert!(o.concern("the line").unwrap().contains("harmonic 3"));
    }

    #[test]
    fn the_fundamental_itself_is_no_harmonic() {
        let (f, p) = square(26.0);
        let line = find_peak(&f, &p, (10.0, 40.0)).unwrap();
        let o = classify_line(&f, &p, &line, 5.0).unwrap();
        assert!(o.harmonic_of.is_none(), "{o:?}");
        assert_eq!(o.below_dominant, 1.0);
        // At 4096 points and 10 kHz the bins are 2.44 Hz apart: ±30 % of 26 Hz (20–34 Hz) holds
        // bins 9–13, all within 3 bins of the line's bin 11, so the line has no floor to stand
        // over, and that is the only concern.
        assert!(o.prominence.is_nan(), "{o:?}");
        let c = o.concern("the line").expect("no floor");
        assert!(c.contains("no measurable prominence"), "{c}");
        assert!(!c.contains("harmonic") && !c.contains("below"), "{c}");
    }

    #[test]
    fn a_line_barely_over_its_floor_is_flagged() {
        // The threshold is MIN_PROMINENCE = 5 (a power ratio): 4.9 is flagged, 5 is not; a NaN
        // prominence (no floor bins, peaks::prominence) is flagged as unmeasurable.
        let line = |prominence: f64| LineOrigin {
            freq_hz: 900.0,
            prominence,
            harmonic_of: None,
            dominant_hz: 900.0,
            below_dominant: 1.0,
        };
        let weak = line(4.9).concern("the line").expect("a weak line");
        assert!(weak.contains("only 4.9×"), "{weak}");
        assert!(line(5.0).concern("the line").is_none());
        assert!(line(f64::INFINITY).concern("the line").is_none());
        let nan = line(f64::NAN).concern("the line").expect("no floor");
        assert!(nan.contains("no measurable prominence"), "{nan}");
    }

    #[test]
    fn a_weak_line_far_below_the_dominant_one_is_flagged() {
        // Two unrelated sines, 50 Hz and 317 Hz, the second 1e-3 of the first's amplitude (1e-6 in
        // power): no harmonic relation, but 1e6 below the dominant line.
        let fs = 1e4;
        let x: Vec<f64> = (0..40_000)
            .map(|i| {
                let t = i as f64 / fs;
                (2.0 * std::f64::consts::PI * 50.0 * t).sin()
                    + 1e-3 * (2.0 * std::f64::consts::PI * 317.0 * t).sin()
            })
            .collect();
        let p = welch(&x, fs, &WelchConfig::new(4096)).unwrap();
        let line = find_peak(&p.freq_hz, &p.density, (200.0, 400.0)).unwrap();
        let o = classify_line(&p.freq_hz, &p.density, &line, 5.0).unwrap();
        assert!(o.harmonic_of.is_none(), "{o:?}");
        assert!(o.below_dominant > 1e5, "{o:?}");
        assert!(
            o.concern("the line")
                .unwrap()
                .contains("below the spectrum")
        );
    }
}
