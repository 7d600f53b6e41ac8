//! Spectrogram (short-time PSD) and its ridge, for the non-stationary burst around reversal.
//!
//! # Conventions (ours, stated explicitly)
//!
//! `scipy.signal.spectrogram` defaults to a Tukey(0.25) window and `noverlap = nperseg/8`; we do
//! **not** inherit those. Every slice here is computed exactly like one segment of
//! [`welch`](fn@super::welch):
//!
//! * periodic Hann window of length `nperseg` ([`hann_periodic`](super::hann_periodic));
//! * segments start every `nperseg − noverlap` samples; only full segments are used;
//! * the segment mean is subtracted (constant detrend);
//! * zero-padded FFT of length `nfft ≥ nperseg`;
//! * one-sided density scaling `|X_k|²/(fs·Σw²)`, doubled except DC (and Nyquist for even `nfft`),
//!   in units²/Hz;
//! * the time of a slice is its segment centre `(start + nperseg/2)/fs` seconds after `x[0]`
//!   (SciPy's convention, `nperseg/2` as a real number).
//!
//! This equals `scipy.signal.spectrogram(x, fs, window='hann', nperseg, noverlap, nfft,
//! detrend='constant', scaling='density', mode='psd')` (checked against a fixture in
//! `tests/suite/spectrum.rs`), transposed to `[time][freq]`.

use super::SpectrumError;
use super::peaks::find_peak;
use super::welch::{WelchConfig, WelchPlan, check_fs, fill_freqs};
use crate::Result;

/// A one-sided spectrogram: `density[i][k]` is the PSD (units²/Hz) of the segment centred at
/// `t_s[i]` at frequency `freq_hz[k]`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Spectrogram {
    /// Segment centres in seconds, measured from the first sample of the input.
    pub t_s: Vec<f64>,
    /// Bin frequencies `k·fs/nfft` in Hz, `nfft/2 + 1` of them.
    pub freq_hz: Vec<f64>,
    /// `[time][freq]`: `t_s.len()` rows of `freq_hz.len()` values, units²/Hz.
    pub density: Vec<Vec<f64>>,
    /// Segment length in samples.
    pub nperseg: usize,
}

impl Spectrogram {
    /// Number of time slices.
    pub fn n_times(&self) -> usize {
        self.t_s.len()
    }

    /// Number of frequency bins.
    pub fn n_freqs(&self) -> usize {
        self.freq_hz.len()
    }

    /// The peak frequency (Hz) of every time slice within `band_hz`: the largest local maximum,
    /// parabolic-interpolated on the log PSD ([`find_peak`]). NaN for a slice with no local maximum
    /// in the band. One value per entry of `t_s`.
    pub fn ridge(&self, band_hz: (f64, f64)) -> Vec<f64> {
        self.density
            .iter()
            .map(|row| {
                find_peak(&self.freq_hz, row, band_hz)
                    .map(|p| p.freq_hz)
                    .unwrap_or(f64::NAN)
            })
            .collect()
    }
}

/// Spectrogram of the uniformly sampled `x` at `fs_hz` with the conventions of the module docs.
///
/// Lengths are in samples: `nperseg ≥ 2`, `noverlap < nperseg`, `nfft ≥ nperseg`
/// ([`SpectrumError`], a setting, otherwise, also for a non-positive `fs_hz`).
/// [`SpectrumError::SpectrogramTooShort`] / [`SpectrumError::SpectrogramNonFinite`] if `x` is
/// shorter than `nperseg` or holds NaN/±∞ (resample and fill gaps first).
pub fn spectrogram(
    x: &[f64],
    fs_hz: f64,
    nperseg: usize,
    noverlap: usize,
    nfft: usize,
) -> Result<Spectrogram> {
    let cfg = WelchConfig {
        noverlap,
        nfft,
        ..WelchConfig::new(nperseg)
    };
    cfg.validate()?;
    check_fs(fs_hz)?;
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(SpectrumError::SpectrogramNonFinite {
            index: i,
            len: x.len(),
            value: x[i],
        }
        .into());
    }
    if x.len() < nperseg {
        return Err(SpectrumError::SpectrogramTooShort {
            len: x.len(),
            nperseg,
        }
        .into());
    }
    let mut plan = WelchPlan::new(cfg)?;
    let n_seg = cfg.n_segments(x.len());
    let step = cfg.step();
    let mut out = Spectrogram {
        t_s: Vec::with_capacity(n_seg),
        freq_hz: Vec::new(),
        density: Vec::with_capacity(n_seg),
        nperseg,
    };
    fill_freqs(&mut out.freq_hz, nfft, fs_hz);
    for s in 0..n_seg {
        let start = s * step;
        let mut row = Vec::with_capacity(cfg.n_freqs());
        plan.segment_density(&x[start..start + nperseg], fs_hz, &mut row);
        out.density.push(row);
        out.t_s.push((start as f64 + nperseg as f64 / 2.0) / fs_hz);
    }
    Ok(out)
}

/// The overview spectrogram `wiperlab spectrum` draws for one signal: the finite samples of `x`
/// (gaps dropped), segments of about a sixteenth of the record rounded up to a power of two in
/// [16, 1024] samples, 75 % overlap, no zero padding. `None` for fewer than 32 finite samples.
///
/// # Errors
/// Those of [`spectrogram`] (e.g. a non-positive `fs_hz`).
pub fn overview_spectrogram(x: &[f64], fs_hz: f64) -> Result<Option<Spectrogram>> {
    let finite: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.len() < 32 {
        return Ok(None);
    }
    let nper = (finite.len() / 16)
        .clamp(16, 1024)
        .next_power_of_two()
        .min(finite.len());
    spectrogram(&finite, fs_hz, nper, nper * 3 / 4, nper).map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::welch;

    #[test]
    fn mean_of_slices_is_welch() {
        // Averaging the slices gives the Welch estimate with the same settings (same definition).
        let x: Vec<f64> = (0..700)
            .map(|n| (0.3 * n as f64).sin() + 0.01 * ((n * 7919) % 101) as f64)
            .collect();
        let sg = spectrogram(&x, 200.0, 64, 48, 128).unwrap();
        let cfg = WelchConfig::new(64)
            .with_noverlap(48)
            .unwrap()
            .with_nfft(128)
            .unwrap();
        let w = welch(&x, 200.0, &cfg).unwrap();
        assert_eq!(sg.n_times(), w.n_segments);
        assert_eq!(sg.freq_hz, w.freq_hz);
        for k in 0..sg.n_freqs() {
            let m: f64 = sg.density.iter().map(|r| r[k]).sum::<f64>() / sg.n_times() as f64;
            assert!((m - w.density[k]).abs() <= 1e-12 * w.density[k].abs().max(1e-300));
        }
        assert!((sg.t_s[0] - 32.0 / 200.0).abs() < 1e-15);
        assert!((sg.t_s[1] - 48.0 / 200.0).abs() < 1e-15);
    }

    #[test]
    fn errors() {
        assert!(matches!(
            spectrogram(&[0.0; 10], 1.0, 16, 8, 16),
            Err(ref e) if matches!(crate::spectrum::SpectrumError::of(e), Some(crate::spectrum::SpectrumError::SpectrogramTooShort { len: 10, nperseg: 16 }))
        ));
        assert!(matches!(
            spectrogram(&[0.0; 100], 1.0, 16, 16, 16),
            Err(ref e) if matches!(crate::spectrum::SpectrumError::of(e), Some(crate::spectrum::SpectrumError::OverlapTooLarge {
                    noverlap: 16,
                    nperseg: 16
                }))
        ));
        assert!(matches!(
            spectrogram(&[f64::NAN; 100], 1.0, 16, 8, 16),
            Err(ref e) if matches!(crate::spectrum::SpectrumError::of(e), Some(crate::spectrum::SpectrumError::SpectrogramNonFinite { index: 0, .. }))
        ));
        // A constant signal: no local maximum → NaN ridge.
        let sg = spectrogram(&[1.0; 100], 1.0, 16, 8, 16).unwrap();
        assert!(sg.ridge((0.0, 0.5)).iter().all(|f| f.is_nan()));
    }
}
