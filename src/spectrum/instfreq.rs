//! Instantaneous frequency against the lip tip's speed, for a measured trace or a simulation.
//!
//! The seed (Unno et al., §2, last paragraph) reports that the high-frequency component of the
//! blade's vibration "is not constant and varies from 359 Hz to 692 Hz depending on the velocity of
//! the lip tip v̇3". Two independent estimators of that frequency are offered here, each paired with
//! a speed of the lip tip relative to the glass:
//!
//! * **Spectrogram ridge** ([`ridge_vs_speed`]): the peak of each short-time PSD slice inside a band
//!   (default the high band, 500–5000 Hz), kept only where it stands `min_snr` times above the
//!   slice's median PSD in the band (plus an optional external noise floor), paired with the tip's
//!   mean speed over the same segment.
//! * **Stick-onset rate** ([`onset_rate_vs_speed`]): `1/(t_{i+1} − t_i)` for successive slip→stick
//!   transitions, paired with the tip's mean speed over that interval. Onsets come from a
//!   simulation's transition list or, for a measurement, from [`detect_stick_onsets`].
//!
//! # Which speed
//! The speed paired with a time interval `[t_a, t_b]` is the tip's **mean velocity over it**,
//! `|v3(t_b) − v3(t_a)|/(t_b − t_a)` ([`mean_speed`]), i.e. the mean of `dv3/dt` over the interval:
//! a smoothed derivative at the scale of the interval. It equals the mean of `|dv3/dt|` whenever the
//! tip does not reverse inside the interval (stick phases have `dv3/dt = 0`, so stick–slip motion
//! in one direction qualifies); inside a reversal it is the net speed. It is the speed relative to
//! the glass (the seed's v̇3), not relative to the head. End positions come from a local
//! least-squares line over `±half_width` samples ([`local_line`]), which skips NaN and averages the
//! tracking noise; with noise σ per sample the speed's error is about
//! `σ·√(2/(2h+1))/(t_b − t_a)` (1.5 µm, h = 3 and a 25.6 ms segment: 0.03 mm/s).
//!
//! # Stick detection on a measured trace
//! See [`detect_stick_onsets`]: the tip's velocity is a 7-point (`half_width` 3) least-squares slope;
//! the tracking noise σ is estimated from the median absolute deviation of the second differences,
//! `σ̂ = 1.4826·MAD(Δ²x)/√6` (white noise of variance σ² gives `Var Δ²x = 6σ²`; a locally linear
//! motion gives Δ²x ≈ 0, and the median ignores the stick–slip kinks); the slope's noise is then
//! `σ_v = σ̂·fs/√(Σk²)`, `Σk² = h(h+1)(2h+1)/3`. A stick episode starts where `|v̇3|` falls below
//! `enter_sigmas·σ_v` (default 2) and ends where it rises above `leave_sigmas·σ_v` (default 4); the
//! hysteresis stops noise from splitting one long stick into many. On the shipped sample (σ = 0.1 px
//! = 1.5 µm) this gives σ̂ = 1.49 µm, thresholds of 5.6 (enter) and 11.3 mm/s (leave), and finds most true onsets within
//! ±0.3 ms; the numbers are measured in `tests/suite/instfreq.rs` and stated in docs/spectra.md. Two kinds of
//! onset are missed. One is an onset entered below the threshold (the long stick through the
//! reversal). The other is a stick much shorter than the 7-sample slope window (0.7 ms at 10 kfps)
//! between fast slips, which the slope averages away; most misses on the sample are of this kind,
//! after the reversal.
//!
//! Units: seconds, metres, m/s, Hz. Samples are uniform at `fs_hz`; NaN marks a missing sample.

use super::SpectrumError;
use super::stats::median_in_place;
use super::stft::spectrogram;
use crate::Result;

/// One instantaneous-frequency estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreqSpeedPoint {
    /// Centre of the interval the estimate belongs to, s (on the caller's clock).
    pub t_s: f64,
    /// Mean speed of the lip tip over that interval, m/s (see the module docs).
    pub speed_m_per_s: f64,
    /// Instantaneous frequency, Hz.
    pub freq_hz: f64,
}

/// Least-squares line through the finite samples `x[i−h ..= i+h]` (clipped to the record):
/// `(value at i, slope per sample)`. `None` when fewer than `max(2, h + 1)` finite samples are in the
/// window (so at least half the window is data) or, for `h = 0`, when `x[i]` is NaN (slope 0 then).
pub fn local_line(x: &[f64], i: usize, half_width: usize) -> Option<(f64, f64)> {
    if i >= x.len() {
        return None;
    }
    if half_width == 0 {
        return x[i].is_finite().then_some((x[i], 0.0));
    }
    let lo = i.saturating_sub(half_width);
    let hi = (i + half_width).min(x.len() - 1);
    let (mut n, mut sk, mut skk, mut sx, mut skx) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (j, v) in x.iter().enumerate().take(hi + 1).skip(lo) {
        if v.is_finite() {
            let k = j as f64 - i as f64;
            n += 1.0;
            sk += k;
            skk += k * k;
            sx += v;
            skx += k * v;
        }
    }
    if n < (half_width as f64 + 1.0).max(2.0) {
        return None;
    }
    let det = n * skk - sk * sk;
    if det <= 0.0 {
        return None;
    }
    let slope = (n * skx - sk * sx) / det;
    let value = (sx - slope * sk) / n;
    Some((value, slope))
}

/// NaN-aware smoothed derivative of `x` sampled at `fs_hz`: the slope of [`local_line`] over
/// `±half_width` samples, in units of x per second (m/s for positions in m). One value per sample;
/// NaN where the window holds too few finite samples. `half_width ≥ 1`.
///
/// This is the Savitzky–Golay first-derivative filter of order 1 (A. Savitzky, M.J.E. Golay, Anal.
/// Chem. 36(8):1627, 1964); with white noise σ its output noise is `σ·fs/√(Σk²)`,
/// `Σk² = h(h+1)(2h+1)/3`.
pub fn smoothed_derivative(x: &[f64], fs_hz: f64, half_width: usize) -> Vec<f64> {
    let h = half_width.max(1);
    (0..x.len())
        .map(|i| local_line(x, i, h).map_or(f64::NAN, |(_, s)| s * fs_hz))
        .collect()
}

/// Robust white-noise standard deviation of `x` (its units): `1.4826·MAD(Δ²x)/√6`, from the finite
/// second differences (see the module docs). NaN if there are fewer than 8 of them.
pub fn noise_sigma(x: &[f64]) -> f64 {
    let mut d2: Vec<f64> = x
        .windows(3)
        .map(|w| w[2] - 2.0 * w[1] + w[0])
        .filter(|v| v.is_finite())
        .collect();
    if d2.len() < 8 {
        return f64::NAN;
    }
    let med = median_in_place(&mut d2);
    let mut dev: Vec<f64> = d2.iter().map(|v| (v - med).abs()).collect();
    1.4826 * median_in_place(&mut dev) / 6f64.sqrt()
}

/// Mean speed `|x(b) − x(a)|·fs/(b − a)` between samples `a < b` of `x` (positions, m → m/s), with
/// the end positions from [`local_line`] over `±half_width` samples. NaN if either end has too few
/// finite samples or `a ≥ b`.
pub fn mean_speed(x: &[f64], fs_hz: f64, a: usize, b: usize, half_width: usize) -> f64 {
    if a >= b {
        return f64::NAN;
    }
    match (local_line(x, a, half_width), local_line(x, b, half_width)) {
        (Some((xa, _)), Some((xb, _))) => (xb - xa).abs() * fs_hz / (b - a) as f64,
        _ => f64::NAN,
    }
}

/// Settings of [`ridge_vs_speed`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RidgeConfig {
    /// Band searched for the ridge, Hz.
    pub band_hz: (f64, f64),
    /// Spectrogram segment length, samples (Hann, constant detrend; see [`spectrogram`]).
    pub nperseg: usize,
    /// Overlap of successive segments, samples.
    pub noverlap: usize,
    /// FFT length (zero padding), samples.
    pub nfft: usize,
    /// A slice's ridge point is kept when its peak PSD is at least `min_snr` times the slice's
    /// median PSD in the band plus the caller's noise floor (plus a rounding floor
    /// `(1e-12·max|x|)²/fs`, so a signal constant to rounding has no ridge).
    pub min_snr: f64,
    /// Gaps (NaN runs) of up to this many samples are filled by linear interpolation; slices that
    /// would straddle a longer gap are skipped.
    pub max_fill: usize,
    /// Half-width (samples) of the local line giving the tip position at segment ends.
    pub half_width: usize,
}

impl Default for RidgeConfig {
    /// High band 500–5000 Hz, nperseg 256 with 75 % overlap, nfft 1024, min_snr 20, max_fill 5,
    /// half_width 3. At 10 kfps a segment is 25.6 ms (≈ 22 cycles at 870 Hz, bins 39 Hz apart
    /// before interpolation); the drive speed changes by at most 7 mm/s within one.
    fn default() -> Self {
        RidgeConfig {
            band_hz: (500.0, 5000.0),
            nperseg: 256,
            noverlap: 192,
            nfft: 1024,
            min_snr: 20.0,
            max_fill: 5,
            half_width: 3,
        }
    }
}

/// Linear interpolation over NaN runs of at most `max_fill` samples with finite neighbours on both
/// sides; longer runs and runs at the ends stay NaN.
pub fn fill_short_gaps(x: &[f64], max_fill: usize) -> Vec<f64> {
    let mut y = x.to_vec();
    let mut i = 0;
    while i < y.len() {
        if y[i].is_finite() {
            i += 1;
            continue;
        }
        let start = i;
        while i < y.len() && !y[i].is_finite() {
            i += 1;
        }
        if start > 0 && i < y.len() && i - start <= max_fill {
            let (a, b) = (y[start - 1], y[i]);
            let n = (i - start + 1) as f64;
            for (k, v) in y[start..i].iter_mut().enumerate() {
                *v = a + (b - a) * (k + 1) as f64 / n;
            }
        }
    }
    y
}

/// Median PSD in `cfg.band_hz` over all slices of the spectrogram of `signal` (its units²/Hz): the
/// noise floor to pass to [`ridge_vs_speed`] for a noise-free model when comparing it with this
/// (noisy) measurement. NaN if no slice fits.
///
/// # Errors
/// As [`ridge_vs_speed`].
pub fn band_floor(signal: &[f64], fs_hz: f64, cfg: &RidgeConfig) -> Result<f64> {
    let mut all = Vec::new();
    for_each_slice(signal, fs_hz, cfg, |_, freq, row| {
        all.extend(in_band(freq, row, cfg.band_hz).map(|(_, p)| p));
    })?;
    Ok(median_in_place(&mut all))
}

fn in_band<'a>(
    freq: &'a [f64],
    row: &'a [f64],
    band: (f64, f64),
) -> impl Iterator<Item = (f64, f64)> + 'a {
    freq.iter()
        .zip(row)
        .filter(move |(f, _)| **f >= band.0 && **f <= band.1)
        .map(|(f, p)| (*f, *p))
}

/// Calls `f(first_sample, freq_hz, psd_row)` for every spectrogram slice of the gap-filled signal
/// that lies inside one finite run.
fn for_each_slice(
    signal: &[f64],
    fs_hz: f64,
    cfg: &RidgeConfig,
    mut f: impl FnMut(usize, &[f64], &[f64]),
) -> Result<()> {
    let valid = cfg.band_hz.0 >= 0.0 && cfg.band_hz.0 < cfg.band_hz.1 && cfg.min_snr >= 0.0;
    if !valid {
        return Err(SpectrumError::RidgeSettings {
            band_hz: cfg.band_hz,
            min_snr: cfg.min_snr,
        }
        .into());
    }
    let x = fill_short_gaps(signal, cfg.max_fill);
    let step = cfg.nperseg.saturating_sub(cfg.noverlap).max(1);
    let mut i = 0;
    while i < x.len() {
        if !x[i].is_finite() {
            i += 1;
            continue;
        }
        let start = i;
        while i < x.len() && x[i].is_finite() {
            i += 1;
        }
        if i - start < cfg.nperseg {
            continue;
        }
        let sg = spectrogram(&x[start..i], fs_hz, cfg.nperseg, cfg.noverlap, cfg.nfft)?;
        for (s, row) in sg.density.iter().enumerate() {
            f(start + s * step, &sg.freq_hz, row);
        }
    }
    Ok(())
}

/// Spectrogram ridge of `signal` in `cfg.band_hz`, paired with the tip's mean speed over each slice.
///
/// * `t0_s`: time of sample 0; `fs_hz`: sampling rate.
/// * `signal`: the analysed signal (e.g. tip x − head x, m), NaN = missing.
/// * `tip_x_m`: the tip's horizontal position relative to the glass, m, same length.
/// * `noise_floor`: added to each slice's median band PSD in the SNR test; 0 for a measurement, the
///   measurement's [`band_floor`] for a noise-free model (compare like with like).
///
/// Returns one [`FreqSpeedPoint`] per kept slice (time = segment centre), in time order; slices
/// without a local maximum in the band, below `min_snr`, or without a finite speed are left out.
///
/// # Errors
/// [`SpectrumError`] (a setting) for invalid settings (band, `min_snr`, segment lengths, `fs_hz`) or
/// `signal`/`tip_x_m` of different lengths.
pub fn ridge_vs_speed(
    t0_s: f64,
    fs_hz: f64,
    signal: &[f64],
    tip_x_m: &[f64],
    cfg: &RidgeConfig,
    noise_floor: f64,
) -> Result<Vec<FreqSpeedPoint>> {
    if signal.len() != tip_x_m.len() {
        return Err(SpectrumError::LengthMismatch {
            signal: signal.len(),
            tip: tip_x_m.len(),
        }
        .into());
    }
    let mut out = Vec::new();
    let floor = if noise_floor.is_finite() {
        noise_floor.max(0.0)
    } else {
        0.0
    };
    for_each_slice(signal, fs_hz, cfg, |start, freq, row| {
        let Some(peak) = super::peaks::find_peak(freq, row, cfg.band_hz) else {
            return;
        };
        let mut band: Vec<f64> = in_band(freq, row, cfg.band_hz).map(|(_, p)| p).collect();
        let peak_psd = band.iter().copied().fold(0.0, f64::max);
        let med = median_in_place(&mut band);
        // Rounding floor: a signal that is constant up to f64 rounding (relative 1e-12 of its
        // magnitude) has no ridge, however its rounding residue is shaped.
        let scale = signal[start..start + cfg.nperseg]
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0, |m: f64, v| m.max(v.abs()));
        let rounding = (1e-12 * scale).powi(2) / fs_hz;
        let strong = peak_psd > 0.0 && peak_psd >= cfg.min_snr * (med + floor + rounding);
        if !strong {
            return;
        }
        // Segment [start, start + nperseg): its centre is the slice time; the speed is taken
        // between the first sample and the one after the last (the last one at the record's end).
        let end = (start + cfg.nperseg).min(tip_x_m.len() - 1);
        let speed = mean_speed(tip_x_m, fs_hz, start, end, cfg.half_width);
        if speed.is_finite() {
            out.push(FreqSpeedPoint {
                t_s: t0_s + (start as f64 + cfg.nperseg as f64 / 2.0) / fs_hz,
                speed_m_per_s: speed,
                freq_hz: peak.freq_hz,
            });
        }
    })?;
    Ok(out)
}

/// Settings of [`detect_stick_onsets`] (see the module docs for the threshold's derivation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StickDetector {
    /// Half-width of the least-squares slope giving the tip's velocity, samples (default 3).
    pub half_width: usize,
    /// A stick episode starts when `|v̇3| < enter_sigmas·σ_v` (default 2).
    pub enter_sigmas: f64,
    /// It ends when `|v̇3| > leave_sigmas·σ_v` (default 4); `leave_sigmas ≥ enter_sigmas`.
    pub leave_sigmas: f64,
}

impl Default for StickDetector {
    fn default() -> Self {
        StickDetector {
            half_width: 3,
            enter_sigmas: 2.0,
            leave_sigmas: 4.0,
        }
    }
}

/// Stick episodes found in a measured tip trace.
#[derive(Debug, Clone, PartialEq)]
pub struct StickDetection {
    /// Times of the detected slip→stick transitions, s: where the speed falls through the entry
    /// threshold after a slip, linearly interpolated between frames (the true onset lies within a
    /// few samples; see the module docs).
    pub onsets_s: Vec<f64>,
    /// Estimated tracking noise σ̂ of the tip position, m.
    pub noise_m: f64,
    /// Noise of the velocity estimate σ_v, m/s.
    pub speed_noise_m_per_s: f64,
    /// Entry threshold `enter_sigmas·σ_v`, m/s.
    pub threshold_m_per_s: f64,
}

/// Detects stick episodes of the lip tip (speed relative to the glass below a noise-based
/// threshold) in `tip_x_m` sampled at `t0_s + k/fs_hz`; see the module docs.
///
/// A sample whose velocity cannot be estimated (NaN window) leaves the state unchanged. The record
/// starts in slip, and only an entry into stick after at least one slip sample counts as an onset.
///
/// # Errors
/// [`SpectrumError::DetectorSettings`] for `half_width = 0`, non-positive `fs_hz` or thresholds with
/// `0 < enter ≤ leave` violated; [`SpectrumError::NoNoiseEstimate`] when the noise cannot be estimated (fewer than
/// 8 finite second differences) or is zero (a noise-free trace: use the transition list instead).
pub fn detect_stick_onsets(
    t0_s: f64,
    fs_hz: f64,
    tip_x_m: &[f64],
    det: &StickDetector,
) -> Result<StickDetection> {
    if det.half_width == 0
        || !(fs_hz.is_finite() && fs_hz > 0.0)
        || !(det.enter_sigmas > 0.0 && det.leave_sigmas >= det.enter_sigmas)
    {
        return Err(SpectrumError::DetectorSettings {
            half_width: det.half_width,
            enter_sigmas: det.enter_sigmas,
            leave_sigmas: det.leave_sigmas,
            fs_hz,
        }
        .into());
    }
    let sigma = noise_sigma(tip_x_m);
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(super::SpectrumError::NoNoiseEstimate {
            sigma_m: sigma,
            samples: tip_x_m.len(),
        }
        .into());
    }
    let h = det.half_width as f64;
    let sum_k2 = h * (h + 1.0) * (2.0 * h + 1.0) / 3.0;
    let sv = sigma * fs_hz / sum_k2.sqrt();
    let (enter, leave) = (det.enter_sigmas * sv, det.leave_sigmas * sv);
    let vel = smoothed_derivative(tip_x_m, fs_hz, det.half_width);
    let mut stick = false;
    let mut slipped = false;
    let mut onsets = Vec::new();
    let mut prev: Option<(usize, f64)> = None; // last finite (index, speed)
    for (i, v) in vel.iter().enumerate() {
        let s = v.abs();
        if !s.is_finite() {
            continue;
        }
        if stick {
            if s > leave {
                stick = false;
                slipped = true;
            }
        } else if s < enter {
            if slipped {
                // Sub-frame time: the speed's linear crossing of the threshold between the
                // previous finite sample and this one (frames alone would quantise 1/Δt in steps
                // of ~9 % at 900 Hz and 10 kfps).
                let u = match prev {
                    Some((j, sp)) if sp > enter => j as f64 + (sp - enter) / (sp - s),
                    _ => i as f64,
                };
                onsets.push(t0_s + u / fs_hz);
            }
            stick = true;
        } else {
            slipped = true;
        }
        prev = Some((i, s));
    }
    Ok(StickDetection {
        onsets_s: onsets,
        noise_m: sigma,
        speed_noise_m_per_s: sv,
        threshold_m_per_s: enter,
    })
}

/// `1/(t_{i+1} − t_i)` for successive stick onsets (ascending times, s), paired with the tip's mean
/// speed over `[t_i, t_{i+1}]`; the time of a point is the interval's centre.
///
/// Positions at the onset times are interpolated linearly between the [`local_line`] values
/// (`±half_width` samples; 0 for a noise-free simulation) of the neighbouring samples of `tip_x_m`,
/// sampled at `t0_s + k/fs_hz`. Intervals with an end outside the record or next to missing data get
/// no point. Non-increasing onset pairs are skipped.
pub fn onset_rate_vs_speed(
    onsets_s: &[f64],
    t0_s: f64,
    fs_hz: f64,
    tip_x_m: &[f64],
    half_width: usize,
) -> Vec<FreqSpeedPoint> {
    let pos = |t: f64| -> f64 {
        let u = (t - t0_s) * fs_hz;
        let inside = u >= 0.0 && u <= (tip_x_m.len().saturating_sub(1)) as f64;
        if !inside {
            return f64::NAN;
        }
        let j = (u.floor() as usize).min(tip_x_m.len().saturating_sub(2));
        let w = u - j as f64;
        match (
            local_line(tip_x_m, j, half_width),
            local_line(tip_x_m, j + 1, half_width),
        ) {
            (Some((a, _)), Some((b, _))) => a + w * (b - a),
            _ => f64::NAN,
        }
    };
    onsets_s
        .windows(2)
        .filter(|w| w[1] > w[0])
        .filter_map(|w| {
            let dt = w[1] - w[0];
            let speed = (pos(w[1]) - pos(w[0])).abs() / dt;
            speed.is_finite().then_some(FreqSpeedPoint {
                t_s: 0.5 * (w[0] + w[1]),
                speed_m_per_s: speed,
                freq_hz: 1.0 / dt,
            })
        })
        .collect()
}

/// Median frequency of `points` in `n_bins` equal speed bins over `[0, max_speed_m_per_s]`:
/// `(bin centre speed, median frequency or NaN for an empty bin)`. Points faster than the range
/// are left out.
pub fn bin_by_speed(
    points: &[FreqSpeedPoint],
    max_speed_m_per_s: f64,
    n_bins: usize,
) -> Vec<(f64, f64)> {
    let w = max_speed_m_per_s / n_bins.max(1) as f64;
    let mut bins: Vec<Vec<f64>> = vec![Vec::new(); n_bins];
    for p in points {
        let k = (p.speed_m_per_s / w).floor();
        if k >= 0.0 && (k as usize) < n_bins && p.freq_hz.is_finite() {
            bins[k as usize].push(p.freq_hz);
        } else if p.speed_m_per_s == max_speed_m_per_s && n_bins > 0 {
            bins[n_bins - 1].push(p.freq_hz);
        }
    }
    bins.into_iter()
        .enumerate()
        .map(|(k, mut b)| ((k as f64 + 0.5) * w, median_in_place(&mut b)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn local_line_is_exact_on_lines_and_skips_nan() {
        let x: Vec<f64> = (0..20).map(|k| 2.0 + 0.5 * k as f64).collect();
        let (v, s) = local_line(&x, 7, 3).unwrap();
        assert!((v - 5.5).abs() < 1e-12 && (s - 0.5).abs() < 1e-12);
        let mut y = x.clone();
        y[6] = f64::NAN;
        y[8] = f64::NAN;
        let (v, s) = local_line(&y, 7, 3).unwrap();
        assert!((v - 5.5).abs() < 1e-12 && (s - 0.5).abs() < 1e-12);
        // Edge: window clipped, still exact.
        let (v, _) = local_line(&x, 0, 3).unwrap();
        assert!((v - 2.0).abs() < 1e-12);
        // Too few finite samples.
        let z = [f64::NAN, f64::NAN, 1.0, f64::NAN, f64::NAN];
        assert!(local_line(&z, 2, 2).is_none());
        assert!(local_line(&x, 99, 2).is_none());
    }

    #[test]
    fn derivative_of_a_parabola() {
        // x = t², fs = 100: the centred least-squares slope of a parabola is exact (odd moments
        // vanish), 2t, away from the edges.
        let fs = 100.0;
        let x: Vec<f64> = (0..50).map(|k| (k as f64 / fs).powi(2)).collect();
        let d = smoothed_derivative(&x, fs, 3);
        for (k, dv) in d.iter().enumerate().take(46).skip(3) {
            assert!((dv - 2.0 * k as f64 / fs).abs() < 1e-10, "{k}: {dv}");
        }
    }

    #[test]
    fn noise_sigma_of_gaussian_noise_on_a_ramp() {
        // Deterministic Box–Muller noise, σ = 0.3, on a ramp: σ̂ within 5 % (n = 20000: the MAD
        // estimator's relative standard error is about 1.1/√n ≈ 0.8 %).
        let mut s: u64 = 12345;
        let mut u = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let x: Vec<f64> = (0..20000)
            .map(|k| {
                let (a, b) = (u(), u());
                0.01 * k as f64
                    + 0.3 * (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
            })
            .collect();
        let sg = noise_sigma(&x);
        assert!((sg / 0.3 - 1.0).abs() < 0.05, "{sg}");
        assert!(noise_sigma(&[1.0, 2.0]).is_nan());
    }

    #[test]
    fn gaps_filled_only_when_short() {
        let x = [
            0.0,
            f64::NAN,
            f64::NAN,
            3.0,
            f64::NAN,
            f64::NAN,
            f64::NAN,
            7.0,
            f64::NAN,
        ];
        let y = fill_short_gaps(&x, 2);
        assert_eq!(&y[..4], &[0.0, 1.0, 2.0, 3.0]);
        assert!(y[4].is_nan() && y[5].is_nan() && y[6].is_nan() && y[8].is_nan());
    }

    #[test]
    fn onset_rate_of_a_regular_stick_slip() {
        // Onsets every 1.25 ms (800 Hz) on a tip moving at 10 mm/s: 800 Hz at 10 mm/s.
        let fs = 1e4;
        let x: Vec<f64> = (0..1000).map(|k| 0.01 * k as f64 / fs).collect();
        let on: Vec<f64> = (1..20).map(|k| 0.003 + k as f64 * 1.25e-3).collect();
        let p = onset_rate_vs_speed(&on, 0.0, fs, &x, 0);
        assert_eq!(p.len(), 18);
        for q in &p {
            assert!((q.freq_hz - 800.0).abs() < 1e-6);
            assert!((q.speed_m_per_s - 0.01).abs() < 1e-9);
        }
        // Outside the record: no point.
        assert!(onset_rate_vs_speed(&[0.5, 0.6], 0.0, fs, &x, 0).is_empty());
    }

    #[test]
    fn binning() {
        let p = |s: f64, f: f64| FreqSpeedPoint {
            t_s: 0.0,
            speed_m_per_s: s,
            freq_hz: f,
        };
        let b = bin_by_speed(
            &[
                p(0.1, 1.0),
                p(0.2, 3.0),
                p(0.15, 2.0),
                p(0.9, 9.0),
                p(2.0, 1.0),
            ],
            1.0,
            4,
        );
        assert_eq!(b.len(), 4);
        assert!((b[0].0 - 0.125).abs() < 1e-12 && b[0].1 == 2.0);
        assert!(b[1].1.is_nan() && b[2].1.is_nan());
        assert_eq!(b[3].1, 9.0);
    }

    #[test]
    fn bad_settings_are_errors() {
        let x = vec![0.0; 600];
        let cfg = RidgeConfig {
            band_hz: (100.0, 50.0),
            ..RidgeConfig::default()
        };
        assert!(matches!(
            ridge_vs_speed(0.0, 1e4, &x, &x, &cfg, 0.0),
            Err(ref e) if matches!(SpectrumError::of(e), Some(SpectrumError::RidgeSettings { .. }))
        ));
        assert!(matches!(
            ridge_vs_speed(0.0, 1e4, &x, &x[..10], &RidgeConfig::default(), 0.0),
            Err(ref e) if matches!(SpectrumError::of(e), Some(SpectrumError::LengthMismatch { signal: 600, tip: 10 }))
        ));
        // A noise-free trace has no noise to set the stick threshold.
        assert!(matches!(
            detect_stick_onsets(0.0, 1e4, &x, &StickDetector::default()),
            Err(ref e) if matches!(crate::spectrum::SpectrumError::of(e), Some(crate::spectrum::SpectrumError::NoNoiseEstimate { .. }))
        ));
        let bad = StickDetector {
            enter_sigmas: 3.0,
            leave_sigmas: 2.0,
            ..StickDetector::default()
        };
        assert!(matches!(
            detect_stick_onsets(0.0, 1e4, &x, &bad),
            Err(ref e) if matches!(SpectrumError::of(e), Some(SpectrumError::DetectorSettings { .. }))
        ));
    }
}
