//! Frequency against tip speed in the fit: the estimators of [`crate::spectrum::instfreq`] applied
//! to a measured trace and to a simulation alike, the optional cost terms built on them, and the
//! comparison the `freq_vs_speed.svg` figure draws ([`compare_freq_speed`]).
//!
//! * [`measured_freq_speed`] / [`model_freq_speed`]: spectrogram ridge of the job's signal and
//!   stick-onset rate, each against the lip tip's mean speed (see the estimator module for the
//!   definitions). The model's ridge is tested for SNR against the measurement's noise floor
//!   ([`band_floor`]); its stick onsets come from the simulation's exact transition list, the
//!   measurement's from [`detect_stick_onsets`].
//! * [`TimeTargets`]: the two optional cost terms of a fit job, `[fit.weights] freq_speed` and
//!   `trace` (both default 0, so a job without them costs exactly as before):
//!   - `freq_speed · mean_b (ln f_m,b / f_d,b / 0.01)²` over the speed bins `b` in which the
//!     measurement has ridge points ([`SPEED_BINS`] equal bins from 0 to its fastest ridge point;
//!     `f` the bin's median ridge frequency; a bin the model leaves empty counts 100, like a 10 %
//!     error), i.e. the same 1 %-unit as the peak term;
//!   - `trace · Σ((m − m̄) − (d − d̄))² / Σ(d − d̄)²` over the samples where both are finite: the
//!     time-domain error of the job's signal, means removed (camera and model frames differ), as a
//!     fraction of the measurement's variance (1 = no better than a constant).
//!
//! Units: s, m, m/s, Hz.

use super::MeasureError;
use crate::Result;
use crate::job::Weights;
use crate::simulate::blade::BladeSimulation;
use crate::simulate::hybrid::Phase;
use crate::spectrum::SpectrumError;
use crate::spectrum::features::SignalKind;
use crate::spectrum::instfreq::{
    FreqSpeedPoint, RidgeConfig, StickDetector, band_floor, bin_by_speed, detect_stick_onsets,
    onset_rate_vs_speed, ridge_vs_speed,
};
use crate::trace::{Role, Trace};

/// Number of equal speed bins of the `freq_speed` cost term.
pub const SPEED_BINS: usize = 8;

/// Instantaneous-frequency estimates of one trace.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FreqSpeed {
    /// Spectrogram ridge points (one per kept slice).
    pub ridge: Vec<FreqSpeedPoint>,
    /// Inverse stick-onset intervals.
    pub onsets: Vec<FreqSpeedPoint>,
    /// Why the onset estimate is empty, when it is (e.g. a noise-free trace).
    pub note: Option<String>,
}

fn tip_x(trace: &Trace) -> Result<&[f64]> {
    trace
        .role(Role::Tip)
        .map(|p| p.x_m.as_slice())
        .ok_or_else(|| MeasureError::NoTip.into())
}

/// Ridge and stick-onset rate of a measured, uniformly sampled trace (`fs_hz`, first frame at
/// `trace.t_s[0]`); `signal` is analysed for the ridge, the `tip` point's x gives the speed and the
/// stick onsets.
///
/// # Errors
/// [`MeasureError::NoTip`] / [`crate::spectrum::SpectrumError`] for a trace without `tip` (or `head` when `signal` needs it) or bad settings.
/// A trace whose noise cannot be estimated gives no onsets and a [`FreqSpeed::note`], not an error.
pub fn measured_freq_speed(
    trace: &Trace,
    fs_hz: f64,
    signal: SignalKind,
    cfg: &RidgeConfig,
    det: &StickDetector,
) -> Result<FreqSpeed> {
    let x = signal.extract(trace)?;
    let tip = tip_x(trace)?;
    let t0 = trace.t_s.first().copied().unwrap_or(0.0);
    let ridge = ridge_vs_speed(t0, fs_hz, &x, tip, cfg, 0.0)?;
    let (onsets, note) = match detect_stick_onsets(t0, fs_hz, tip, det) {
        Ok(d) => (
            onset_rate_vs_speed(&d.onsets_s, t0, fs_hz, tip, det.half_width),
            None,
        ),
        Err(e)
            if matches!(
                SpectrumError::of(&e),
                Some(SpectrumError::NoNoiseEstimate { .. })
            ) =>
        {
            (Vec::new(), Some(e.to_string()))
        }
        Err(e) => return Err(e),
    };
    Ok(FreqSpeed {
        ridge,
        onsets,
        note,
    })
}

/// The job's signal of a simulation with the measurement's NaN mask applied (`mask[i]` true → NaN).
fn masked_signal(sim: &BladeSimulation, signal: SignalKind, mask: &[bool]) -> Result<Vec<f64>> {
    let mut x = signal.extract(&sim.to_trace())?;
    for (xi, m) in x.iter_mut().zip(mask) {
        if *m {
            *xi = f64::NAN;
        }
    }
    Ok(x)
}

/// Ridge and stick-onset rate of a simulation sampled at `fs_hz`: the ridge of `signal` (NaN where
/// `nan_mask` is true, as in the measurement) with `noise_floor` added in the SNR test (the
/// measurement's [`band_floor`]), and the onset rate from the exact slip→stick transitions.
///
/// # Errors
/// As [`ridge_vs_speed`].
pub fn model_freq_speed(
    sim: &BladeSimulation,
    fs_hz: f64,
    signal: SignalKind,
    cfg: &RidgeConfig,
    noise_floor: f64,
    nan_mask: &[bool],
) -> Result<FreqSpeed> {
    let x = masked_signal(sim, signal, nan_mask)?;
    let t0 = sim.t_s.first().copied().unwrap_or(0.0);
    let ridge = ridge_vs_speed(t0, fs_hz, &x, &sim.v3_m, cfg, noise_floor)?;
    let on: Vec<f64> = sim
        .transitions
        .iter()
        .filter(|t| t.to == Phase::Stick)
        .map(|t| t.t_s)
        .collect();
    Ok(FreqSpeed {
        ridge,
        onsets: onset_rate_vs_speed(&on, t0, fs_hz, &sim.v3_m, 0),
        note: None,
    })
}

/// Time-domain fit targets built once from the measurement (see the module docs).
#[derive(Debug, Clone)]
pub struct TimeTargets {
    weights: Weights,
    cfg: RidgeConfig,
    fs_hz: f64,
    signal: SignalKind,
    /// The measured signal (NaN = missing).
    measured: Vec<f64>,
    /// The measurement's median band PSD, added to the model's in the ridge SNR test.
    floor: f64,
    max_speed_m_per_s: f64,
    /// Median measured ridge frequency per speed bin (NaN = no measured point).
    measured_bins: Vec<(f64, f64)>,
}

impl TimeTargets {
    /// The targets of a job with `weights`, or `None` when both `freq_speed` and `trace` are 0
    /// (nothing is computed then). `x` is the job's signal of `trace`, sampled at `fs_hz`.
    ///
    /// # Errors
    /// [`MeasureError`] for a negative weight, a trace without `tip` when `freq_speed > 0`, or no
    /// ridge point in the measurement (the term would have nothing to compare).
    pub fn for_job(
        weights: &Weights,
        trace: &Trace,
        x: &[f64],
        fs_hz: f64,
        signal: SignalKind,
    ) -> Result<Option<TimeTargets>> {
        if !(weights.freq_speed >= 0.0 && weights.trace >= 0.0) {
            return Err(MeasureError::NegativeWeights {
                freq_speed: weights.freq_speed,
                trace: weights.trace,
            }
            .into());
        }
        if weights.freq_speed == 0.0 && weights.trace == 0.0 {
            return Ok(None);
        }
        let cfg = RidgeConfig::default();
        let mut t = TimeTargets {
            weights: *weights,
            cfg,
            fs_hz,
            signal,
            measured: x.to_vec(),
            floor: 0.0,
            max_speed_m_per_s: 0.0,
            measured_bins: Vec::new(),
        };
        if weights.freq_speed > 0.0 {
            let tip = tip_x(trace)?;
            let t0 = trace.t_s.first().copied().unwrap_or(0.0);
            let ridge = ridge_vs_speed(t0, fs_hz, x, tip, &cfg, 0.0)?;
            let vmax = ridge.iter().map(|p| p.speed_m_per_s).fold(0.0, f64::max);
            if ridge.is_empty() || vmax <= 0.0 {
                return Err(MeasureError::NoRidgePoint {
                    signal: signal.label(),
                    band_hz: cfg.band_hz,
                    min_snr: cfg.min_snr,
                }
                .into());
            }
            t.floor = band_floor(x, fs_hz, &cfg)?;
            t.max_speed_m_per_s = vmax;
            t.measured_bins = bin_by_speed(&ridge, vmax, SPEED_BINS);
        }
        Ok(Some(t))
    }

    /// The weighted sum of both terms for a simulation sampled at the recording's times.
    ///
    /// # Errors
    /// As [`model_freq_speed`].
    pub fn cost(&self, sim: &BladeSimulation) -> Result<f64> {
        let mask: Vec<bool> = self.measured.iter().map(|v| !v.is_finite()).collect();
        let mut total = 0.0;
        if self.weights.freq_speed > 0.0 {
            let m = model_freq_speed(sim, self.fs_hz, self.signal, &self.cfg, self.floor, &mask)?;
            let model_bins = bin_by_speed(&m.ridge, self.max_speed_m_per_s, SPEED_BINS);
            let (mut s, mut n) = (0.0, 0usize);
            for ((_, fd), (_, fm)) in self.measured_bins.iter().zip(&model_bins) {
                if !fd.is_finite() {
                    continue;
                }
                n += 1;
                s += if fm.is_finite() {
                    ((fm / fd).ln() / 0.01).powi(2)
                } else {
                    100.0
                };
            }
            total += self.weights.freq_speed * s / n.max(1) as f64;
        }
        if self.weights.trace > 0.0 {
            let model = masked_signal(sim, self.signal, &mask)?;
            total += self.weights.trace * trace_error(&self.measured, &model);
        }
        Ok(total)
    }
}

/// Relative time-domain error `Σ((m − m̄) − (d − d̄))² / Σ(d − d̄)²` of `model` against `measured`
/// over the samples where both are finite (means over those samples). NaN when fewer than two
/// such samples or the measurement is constant there.
pub fn trace_error(measured: &[f64], model: &[f64]) -> f64 {
    let pairs: Vec<(f64, f64)> = measured
        .iter()
        .zip(model)
        .filter(|(d, m)| d.is_finite() && m.is_finite())
        .map(|(d, m)| (*d, *m))
        .collect();
    if pairs.len() < 2 {
        return f64::NAN;
    }
    let n = pairs.len() as f64;
    let dm = pairs.iter().map(|p| p.0).sum::<f64>() / n;
    let mm = pairs.iter().map(|p| p.1).sum::<f64>() / n;
    let (mut num, mut den) = (0.0, 0.0);
    for (d, m) in pairs {
        num += ((m - mm) - (d - dm)).powi(2);
        den += (d - dm).powi(2);
    }
    if den > 0.0 { num / den } else { f64::NAN }
}

/// Measured and model frequency-against-speed estimates of a fit, for `freq_vs_speed.svg`.
#[derive(Debug, Clone, PartialEq)]
pub struct FreqSpeedComparison {
    pub measured: FreqSpeed,
    pub model: FreqSpeed,
    /// The ridge's search band, Hz: points outside it are not drawn.
    pub band_hz: (f64, f64),
}

/// The measured and fitted-model instantaneous frequency against lip-tip speed of a fit outcome
/// (the recording `measured_trace` at `fs_hz`, the best fit's simulation `best_sim`, the job's
/// `signal`), with the default ridge and stick-detector settings. `None` when the recording has no
/// `tip` point or neither estimator finds a point in the band.
///
/// # Errors
/// Those of [`measured_freq_speed`] and [`model_freq_speed`].
pub fn compare_freq_speed(
    measured_trace: &Trace,
    best_sim: &BladeSimulation,
    fs_hz: f64,
    signal: SignalKind,
) -> Result<Option<FreqSpeedComparison>> {
    if measured_trace.role(Role::Tip).is_none() {
        return Ok(None);
    }
    let cfg = RidgeConfig::default();
    let stick = StickDetector::default();
    let measured = measured_freq_speed(measured_trace, fs_hz, signal, &cfg, &stick)?;
    let x = signal.extract(measured_trace)?;
    let mask: Vec<bool> = x.iter().map(|v| !v.is_finite()).collect();
    let floor = band_floor(&x, fs_hz, &cfg)?;
    let model = model_freq_speed(best_sim, fs_hz, signal, &cfg, floor, &mask)?;
    let in_band = |p: &[FreqSpeedPoint]| {
        p.iter()
            .any(|q| q.freq_hz >= cfg.band_hz.0 && q.freq_hz <= cfg.band_hz.1)
    };
    if [
        &measured.ridge,
        &measured.onsets,
        &model.ridge,
        &model.onsets,
    ]
    .iter()
    .all(|p| !in_band(p))
    {
        return Ok(None);
    }
    Ok(Some(FreqSpeedComparison {
        measured,
        model,
        band_hz: cfg.band_hz,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trace_error_is_zero_for_a_shifted_copy_and_one_for_a_constant() {
        let d: Vec<f64> = (0..100).map(|k| (0.1 * k as f64).sin()).collect();
        let shifted: Vec<f64> = d.iter().map(|v| v + 3.0).collect();
        assert!(trace_error(&d, &shifted).abs() < 1e-12);
        assert!((trace_error(&d, &[5.0; 100]) - 1.0).abs() < 1e-12);
        let mut gappy = shifted.clone();
        gappy[10] = f64::NAN;
        assert!(trace_error(&d, &gappy).abs() < 1e-12);
        assert!(trace_error(&[1.0], &[1.0]).is_nan());
    }

    #[test]
    fn noise_free_trace_gives_a_note_not_an_error() {
        use crate::trace::PointTrack;
        // A tip held exactly still (no tracking noise, not even rounding: Δ²x = 0): no ridge (no
        // high-frequency content) and no stick detection (the noise threshold cannot be set),
        // said in the note. (A moving float trace has rounding noise, which sets a tiny threshold.)
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 / 1e4).collect();
        let tr = Trace {
            t_s: t.clone(),
            points: vec![
                PointTrack {
                    name: Role::Head.name().into(),
                    x_m: t.iter().map(|t| 0.01 * t).collect(),
                    y_m: vec![0.0; n],
                },
                PointTrack {
                    name: Role::Tip.name().into(),
                    x_m: vec![0.05; n],
                    y_m: vec![0.0; n],
                },
            ],
        };
        let fsp = measured_freq_speed(
            &tr,
            1e4,
            SignalKind::TipX,
            &RidgeConfig::default(),
            &StickDetector::default(),
        )
        .unwrap();
        assert!(fsp.ridge.is_empty() && fsp.onsets.is_empty());
        assert!(fsp.note.as_deref().unwrap_or("").contains("noise"));
        // Without a tip point it is a configuration error naming the role.
        let no_tip = Trace {
            t_s: t,
            points: vec![tr.points[0].clone()],
        };
        let e = measured_freq_speed(
            &no_tip,
            1e4,
            SignalKind::HeadY,
            &RidgeConfig::default(),
            &StickDetector::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("'tip'"), "{e}");
    }

    #[test]
    fn zero_weights_build_nothing() {
        let tr = Trace {
            t_s: vec![0.0, 1.0],
            points: vec![],
        };
        let w = Weights::default();
        assert!(
            TimeTargets::for_job(&w, &tr, &[0.0, 0.0], 1.0, SignalKind::TipX)
                .unwrap()
                .is_none()
        );
        let bad = Weights {
            trace: -1.0,
            ..Weights::default()
        };
        assert!(TimeTargets::for_job(&bad, &tr, &[0.0, 0.0], 1.0, SignalKind::TipX).is_err());
    }
}
