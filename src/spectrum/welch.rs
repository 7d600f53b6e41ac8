//! Welch's averaged-periodogram PSD estimate, with SciPy's conventions.
//!
//! P.D. Welch, "The use of fast Fourier transform for the estimation of power spectra: a method based
//! on time averaging over short, modified periodograms", IEEE Trans. Audio Electroacoust. 15(2):70–73,
//! 1967.
//!
//! [`welch`] reproduces `scipy.signal.welch(x, fs, window, nperseg, noverlap, nfft, detrend, scaling,
//! average)` with SciPy's names and defaults (`window='hann'`, `noverlap=nperseg//2`,
//! `nfft=nperseg`, `detrend='constant'`, `scaling='density'`, `average='mean'`; SciPy 1.17; checked
//! against fixtures to 1e-10 relative in `tests/suite/spectrum.rs`, for every window, both scalings and
//! both averages):
//!
//! * **Window**: periodic Hann of length `nperseg` by default ([`Window`]: also Hamming, Blackman,
//!   boxcar, as `scipy.signal.get_window(name, nperseg)`).
//! * **Segments**: start at `0, step, 2·step, …` with `step = nperseg − noverlap`; only full segments
//!   are used, so `n_segments = (len − noverlap) / step` and trailing samples are dropped.
//! * **Detrend** per segment before windowing ([`Detrend`]).
//! * **FFT** of length `nfft ≥ nperseg`; the windowed segment is zero-padded at the end.
//! * **Scaling** ([`Scaling`]) `'density'`: `|X_k|² / (fs·Σw²)`, so the PSD is in units²/Hz;
//!   `'spectrum'`: `|X_k|² / (Σw)²`, units².
//! * **One-sided**: bins `1..nfft/2` (exclusive) are doubled for even `nfft` (DC and Nyquist are not);
//!   bins `1..=nfft/2` for odd `nfft`.
//! * **Average** ([`Average`]): arithmetic mean over segments, or their median divided by
//!   [`median_bias`].
//! * **Frequencies**: `f_k = k·fs/nfft`, `k = 0..=nfft/2`, computed as NumPy's `rfftfreq` does
//!   (`k · (1/(nfft·(1/fs)))`) so they agree bit for bit.
//!
//! With these conventions, `Σ_k density_k · Δf` equals the window-weighted mean square of the
//! detrended segments (Parseval), i.e. the signal's power: `A²/2` for a sinusoid of amplitude `A`.
//!
//! Where SciPy warns and shrinks `nperseg` to a short record, we return [`SpectrumError::TooShort`] instead.
//!
//! For plan-once/process-many use (the fit evaluates spectra hundreds of times) build a
//! [`WelchPlan`] once and call [`WelchPlan::process`] or [`WelchPlan::process_into`].

use std::fmt;
use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{RealFftPlanner, RealToComplex};

use super::error::SpectrumError;
use super::window::{Window, WindowSums};
use crate::Result;

/// What is subtracted from each segment before windowing (`scipy.signal.welch`'s `detrend`).
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "snake_case")]
pub enum Detrend {
    /// Nothing (`detrend=False`).
    None,
    /// The segment mean (`detrend='constant'`, SciPy's default).
    #[default]
    Constant,
    /// The least-squares straight line through the segment (`detrend='linear'`).
    Linear,
}

impl fmt::Display for Detrend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Detrend::None => "none",
            Detrend::Constant => "constant",
            Detrend::Linear => "linear",
        })
    }
}

/// Segmenting and FFT settings of a Welch estimate. All lengths are in samples.
///
/// Invariants (checked by [`WelchConfig::validate`], the `with_*` setters and every estimator):
/// `nperseg ≥ 2`, `noverlap < nperseg`, `nfft ≥ nperseg`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WelchConfig {
    /// Segment length (and Hann window length). The bin width is `fs/nfft`, the resolution ≈ 1.5
    /// bins of `fs/nperseg` (Hann ENBW).
    pub nperseg: usize,
    /// Samples shared by consecutive segments; SciPy's default is `nperseg/2` (50 %).
    pub noverlap: usize,
    /// FFT length; `nfft > nperseg` zero-pads each windowed segment (finer bin spacing, same
    /// resolution).
    pub nfft: usize,
    /// Per-segment detrending.
    pub detrend: Detrend,
    /// Taper of each segment.
    pub window: Window,
    /// Density (units²/Hz) or power spectrum (units²).
    pub scaling: Scaling,
    /// How the segments' periodograms are combined.
    pub average: Average,
}

/// `scipy.signal.welch`'s `scaling`.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "snake_case")]
pub enum Scaling {
    /// Power spectral density `|X_k|²/(fs·Σw²)`, units²/Hz (SciPy's default).
    #[default]
    Density,
    /// Power spectrum `|X_k|²/(Σw)²`, units²: a sinusoid of amplitude A on a bin shows A²/2.
    Spectrum,
}

/// `scipy.signal.welch`'s `average`.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "snake_case")]
pub enum Average {
    /// Arithmetic mean over segments (SciPy's default; Welch 1967).
    #[default]
    Mean,
    /// Median over segments divided by SciPy's bias `1 + Σ_{i=1}^{⌊(n−1)/2⌋} (1/(2i+1) − 1/(2i))`
    /// for `n` segments (the median of χ²₂ periodogram ordinates; Allen et al., Phys. Rev. D 85,
    /// 122006 (2012), appendix B): robust to a few segments spoiled by glitches.
    Median,
}

impl fmt::Display for Scaling {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Scaling::Density => "density",
            Scaling::Spectrum => "spectrum",
        })
    }
}

impl fmt::Display for Average {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Average::Mean => "mean",
            Average::Median => "median",
        })
    }
}

/// SciPy's `_median_bias(n)`: the expected sample median of `n` exponential (χ²₂/2) variables of
/// mean 1, which tends to ln 2 for large `n`; 1 for `n ≤ 2`.
pub fn median_bias(n: usize) -> f64 {
    let m = (n.saturating_sub(1)) / 2;
    1.0 + (1..=m)
        .map(|i| {
            let ii = 2.0 * i as f64;
            1.0 / (ii + 1.0) - 1.0 / ii
        })
        .sum::<f64>()
}

impl WelchConfig {
    /// SciPy's defaults for a given `nperseg`: `noverlap = nperseg/2` (integer division),
    /// `nfft = nperseg`, [`Detrend::Constant`]. Call [`validate`](Self::validate) (or use an
    /// estimator, which does) to reject `nperseg < 2`.
    pub fn new(nperseg: usize) -> Self {
        WelchConfig {
            nperseg,
            noverlap: nperseg / 2,
            nfft: nperseg,
            detrend: Detrend::Constant,
            window: Window::Hann,
            scaling: Scaling::Density,
            average: Average::Mean,
        }
    }

    /// Sets the window (any value is valid).
    pub fn with_window(mut self, window: Window) -> Self {
        self.window = window;
        self
    }

    /// Sets the scaling (any value is valid).
    pub fn with_scaling(mut self, scaling: Scaling) -> Self {
        self.scaling = scaling;
        self
    }

    /// Sets the averaging (any value is valid).
    pub fn with_average(mut self, average: Average) -> Self {
        self.average = average;
        self
    }

    /// Sets `noverlap`; [`SpectrumError`] unless `noverlap < nperseg`.
    pub fn with_noverlap(mut self, noverlap: usize) -> Result<Self> {
        self.noverlap = noverlap;
        self.validate()?;
        Ok(self)
    }

    /// Sets `nfft`; [`SpectrumError`] unless `nfft ≥ nperseg`.
    pub fn with_nfft(mut self, nfft: usize) -> Result<Self> {
        self.nfft = nfft;
        self.validate()?;
        Ok(self)
    }

    /// Sets the detrending (any value is valid).
    pub fn with_detrend(mut self, detrend: Detrend) -> Self {
        self.detrend = detrend;
        self
    }

    /// [`SpectrumError`] unless `nperseg ≥ 2`, `noverlap < nperseg` and `nfft ≥ nperseg`.
    pub fn validate(&self) -> Result<()> {
        if self.nperseg < 2 {
            return Err(SpectrumError::NpersegTooSmall {
                nperseg: self.nperseg,
            }
            .into());
        }
        if self.noverlap >= self.nperseg {
            return Err(SpectrumError::OverlapTooLarge {
                noverlap: self.noverlap,
                nperseg: self.nperseg,
            }
            .into());
        }
        if self.nfft < self.nperseg {
            return Err(SpectrumError::NfftTooSmall {
                nfft: self.nfft,
                nperseg: self.nperseg,
            }
            .into());
        }
        Ok(())
    }

    /// Hop between segment starts, `nperseg − noverlap` samples.
    pub fn step(&self) -> usize {
        self.nperseg - self.noverlap
    }

    /// Number of full segments in a record of `len` samples (0 if `len < nperseg`).
    pub fn n_segments(&self, len: usize) -> usize {
        if len < self.nperseg || self.nperseg <= self.noverlap {
            0
        } else {
            (len - self.nperseg) / self.step() + 1
        }
    }

    /// Number of one-sided frequency bins, `nfft/2 + 1`.
    pub fn n_freqs(&self) -> usize {
        self.nfft / 2 + 1
    }

    /// Bin spacing `fs/nfft` in Hz.
    pub fn bin_width_hz(&self, fs_hz: f64) -> f64 {
        fs_hz / self.nfft as f64
    }
}

/// A one-sided power spectral density on the grid `f_k = k·fs/nfft`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Psd {
    /// Bin frequencies in Hz, `nfft/2 + 1` of them, from 0 to `fs/2` (even `nfft`) or just below.
    pub freq_hz: Vec<f64>,
    /// One-sided PSD in (signal units)²/Hz, same length as `freq_hz`.
    pub density: Vec<f64>,
    /// Number of segments averaged.
    pub n_segments: usize,
    /// Sampling rate in Hz.
    pub fs_hz: f64,
}

impl Psd {
    /// Bin spacing in Hz (`fs/nfft`), or 0 for fewer than two bins.
    pub fn bin_width_hz(&self) -> f64 {
        if self.freq_hz.len() < 2 {
            0.0
        } else {
            self.freq_hz[1] - self.freq_hz[0]
        }
    }

    /// `Σ_k density_k · Δf` over all bins, in units²: the mean square of the detrended signal
    /// (Parseval for density scaling), `A²/2` for a sinusoid of amplitude `A`.
    pub fn total_power(&self) -> f64 {
        self.density.iter().sum::<f64>() * self.bin_width_hz()
    }

    /// `Σ density_k · Δf` over bins with `lo ≤ f_k ≤ hi` (Hz), in units².
    pub fn band_power(&self, band_hz: (f64, f64)) -> f64 {
        let df = self.bin_width_hz();
        self.freq_hz
            .iter()
            .zip(&self.density)
            .filter(|(f, _)| **f >= band_hz.0 && **f <= band_hz.1)
            .map(|(_, p)| p)
            .sum::<f64>()
            * df
    }
}

/// What [`welch_gappy`] did with missing (non-finite) samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GapReport {
    /// Interior NaN samples filled by linear interpolation (runs of at most `max_fill`).
    pub filled: usize,
    /// NaN samples not filled: leading and trailing ones and interior runs longer than `max_fill`.
    pub dropped: usize,
    /// Welch segments averaged, over all runs.
    pub segments_used: usize,
    /// Finite runs the record was split into (after filling), including runs shorter than
    /// `nperseg` that contribute no segment.
    pub runs: usize,
}

/// A Welch estimator planned for one [`WelchConfig`]: owns the real FFT plan, the Hann window and
/// every scratch buffer, so repeated calls allocate only the output (or nothing, with
/// [`process_into`](Self::process_into)).
pub struct WelchPlan {
    cfg: WelchConfig,
    r2c: Arc<dyn RealToComplex<f64>>,
    window: Vec<f64>,
    sums: WindowSums,
    /// FFT input, `nfft` long (realfft uses it as scratch).
    buf: Vec<f64>,
    /// FFT output, `nfft/2 + 1` long.
    spec: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
    /// Σ over segments of |X_k|², `nfft/2 + 1` long.
    acc: Vec<f64>,
    /// With [`Average::Median`]: every segment's |X_k|², segment after segment.
    segments: Vec<f64>,
}

impl fmt::Debug for WelchPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("WelchPlan")
            .field("cfg", &self.cfg)
            .finish_non_exhaustive()
    }
}

impl WelchPlan {
    /// Plans the FFT and window for `cfg`; [`SpectrumError`] if `cfg` is invalid.
    pub fn new(cfg: WelchConfig) -> Result<Self> {
        cfg.validate()?;
        let r2c = RealFftPlanner::<f64>::new().plan_fft_forward(cfg.nfft);
        let window = cfg.window.periodic(cfg.nperseg);
        let sums = WindowSums::of(&window);
        Ok(WelchPlan {
            buf: r2c.make_input_vec(),
            spec: r2c.make_output_vec(),
            scratch: r2c.make_scratch_vec(),
            acc: vec![0.0; cfg.n_freqs()],
            segments: Vec::new(),
            cfg,
            r2c,
            window,
            sums,
        })
    }

    /// The configuration this plan was built for.
    pub fn config(&self) -> &WelchConfig {
        &self.cfg
    }

    /// The periodic window in use (`nperseg` samples).
    pub fn window(&self) -> &[f64] {
        &self.window
    }

    /// Welch PSD of `x` sampled at `fs_hz`; see the module docs for the conventions.
    ///
    /// Errors: [`SpectrumError::SamplingRate`] if `fs_hz` is not finite and positive; [`SpectrumError`] if `x`
    /// has fewer than `nperseg` samples or holds a non-finite value (use
    /// [`process_gappy`](Self::process_gappy) for records with gaps).
    pub fn process(&mut self, x: &[f64], fs_hz: f64) -> Result<Psd> {
        let mut out = Psd::default();
        self.process_into(x, fs_hz, &mut out)?;
        Ok(out)
    }

    /// As [`process`](Self::process), writing into `out` and reusing its vectors (no allocation
    /// once `out` has been used with this plan).
    pub fn process_into(&mut self, x: &[f64], fs_hz: f64, out: &mut Psd) -> Result<()> {
        check_fs(fs_hz)?;
        check_finite(x)?;
        if x.len() < self.cfg.nperseg {
            return Err(SpectrumError::TooShort {
                len: x.len(),
                nperseg: self.cfg.nperseg,
            }
            .into());
        }
        self.acc.fill(0.0);
        self.segments.clear();
        let n_seg = self.accumulate_run(x);
        self.finish_into(fs_hz, n_seg, out);
        Ok(())
    }

    /// NaN-aware Welch PSD; see [`welch_gappy`].
    pub fn process_gappy(
        &mut self,
        x: &[f64],
        fs_hz: f64,
        max_fill: usize,
    ) -> Result<(Psd, GapReport)> {
        check_fs(fs_hz)?;
        let Filled {
            y,
            runs,
            mut report,
        } = fill_and_split(x, max_fill, self.cfg.nperseg)?;
        self.acc.fill(0.0);
        self.segments.clear();
        let mut n_seg = 0;
        for &(s, e) in &runs {
            if e - s >= self.cfg.nperseg {
                n_seg += self.accumulate_run(&y[s..e]);
            }
        }
        if n_seg == 0 {
            let longest = runs.iter().map(|(s, e)| e - s).max().unwrap_or(0);
            return Err(SpectrumError::NoFiniteRun {
                nperseg: self.cfg.nperseg,
                longest,
                len: x.len(),
                runs: runs.len(),
                max_fill,
            }
            .into());
        }
        report.segments_used = n_seg;
        let mut out = Psd::default();
        self.finish_into(fs_hz, n_seg, &mut out);
        Ok((out, report))
    }

    /// Adds `|X_k|²` of every full segment of `x` (finite, `len ≥ nperseg`) into `acc`; returns the
    /// number of segments.
    fn accumulate_run(&mut self, x: &[f64]) -> usize {
        let n_seg = self.cfg.n_segments(x.len());
        let step = self.cfg.step();
        for s in 0..n_seg {
            let start = s * step;
            self.segment_power(&x[start..start + self.cfg.nperseg]);
            match self.cfg.average {
                Average::Mean => {
                    for (a, c) in self.acc.iter_mut().zip(&self.spec) {
                        *a += c.norm_sqr();
                    }
                }
                Average::Median => self.segments.extend(self.spec.iter().map(|c| c.norm_sqr())),
            }
        }
        n_seg
    }

    /// Detrends and windows `seg` (`nperseg` samples) into the zero-padded FFT buffer and transforms
    /// it into `self.spec`.
    fn segment_power(&mut self, seg: &[f64]) {
        let n = self.cfg.nperseg;
        debug_assert_eq!(seg.len(), n);
        let (head, tail) = self.buf.split_at_mut(n);
        match self.cfg.detrend {
            Detrend::None => {
                for ((b, x), w) in head.iter_mut().zip(seg).zip(&self.window) {
                    *b = x * w;
                }
            }
            Detrend::Constant => {
                let mean = seg.iter().sum::<f64>() / n as f64;
                for ((b, x), w) in head.iter_mut().zip(seg).zip(&self.window) {
                    *b = (x - mean) * w;
                }
            }
            Detrend::Linear => {
                // Least-squares line on a centred abscissa c_i = i − (n−1)/2 (orthogonal to the
                // constant): intercept = mean, slope = Σ c_i x_i / Σ c_i².
                let mean = seg.iter().sum::<f64>() / n as f64;
                let mid = (n as f64 - 1.0) / 2.0;
                let (mut sxy, mut sxx) = (0.0, 0.0);
                for (i, x) in seg.iter().enumerate() {
                    let c = i as f64 - mid;
                    sxy += c * (x - mean);
                    sxx += c * c;
                }
                let slope = sxy / sxx;
                for (i, ((b, x), w)) in head.iter_mut().zip(seg).zip(&self.window).enumerate() {
                    *b = (x - mean - slope * (i as f64 - mid)) * w;
                }
            }
        }
        tail.fill(0.0);
        // Lengths are fixed by construction, so realfft cannot fail here.
        self.r2c
            .process_with_scratch(&mut self.buf, &mut self.spec, &mut self.scratch)
            .expect("realfft buffer lengths match the plan");
    }

    /// One-sided density scaling of the squared-magnitude sum `acc` as one segment's spectrum
    /// (`n_seg = 1`) or the mean of `n_seg`; writes frequencies and density into `out`.
    fn finish_into(&mut self, fs_hz: f64, n_seg: usize, out: &mut Psd) {
        fill_freqs(&mut out.freq_hz, self.cfg.nfft, fs_hz);
        out.density.clear();
        let divisor = match self.cfg.average {
            Average::Mean => {
                out.density.extend_from_slice(&self.acc);
                n_seg as f64
            }
            Average::Median => {
                let nf = self.cfg.n_freqs();
                let mut column = Vec::with_capacity(n_seg);
                for k in 0..nf {
                    column.clear();
                    column.extend((0..n_seg).map(|s| self.segments[s * nf + k]));
                    out.density.push(median_of(&mut column));
                }
                median_bias(n_seg)
            }
        };
        let norm = self.norm(fs_hz);
        scale_one_sided(&mut out.density, self.cfg.nfft, 1.0 / divisor, norm);
        out.n_segments = n_seg;
        out.fs_hz = fs_hz;
    }

    /// One segment's one-sided density (`nfft/2 + 1` values, units²/Hz) into `row`; used by the
    /// spectrogram. `seg` must be `nperseg` finite samples.
    pub(crate) fn segment_density(&mut self, seg: &[f64], fs_hz: f64, row: &mut Vec<f64>) {
        self.segment_power(seg);
        row.clear();
        row.extend(self.spec.iter().map(|c| c.norm_sqr()));
        let norm = self.norm(fs_hz);
        scale_one_sided(row, self.cfg.nfft, 1.0, norm);
    }

    /// The Welch cross-spectral matrices of several signals recorded together: at each bin `k` of
    /// `bins` (indices into the `nfft/2 + 1` frequencies), the mean over the segments of
    /// `X_k X_kᴴ`, `X_k` the column of the signals' detrended, windowed segment transforms, scaled
    /// as [`process`](Self::process) scales `|X_k|²` (so the diagonal is each signal's Welch PSD at
    /// those bins and entry `(a, b)` the cross-spectrum of signal `a` with signal `b`, `S_ab =
    /// E[X_a X_b*]`; Bendat & Piersol, *Random Data*, 4th ed. 2010, §11.5.2). Mean average only.
    ///
    /// Errors: [`SpectrumError::SamplingRate`] if `fs_hz` is not finite and positive;
    /// [`SpectrumError::TooShort`] if the signals are shorter than `nperseg`;
    /// [`SpectrumError::UnequalLengths`] for signals of different lengths;
    /// [`SpectrumError::NonFinite`] for a non-finite sample;
    /// [`SpectrumError::BinOutOfRange`] for a bin past `nfft/2`;
    /// [`SpectrumError::MedianCrossSpectra`] with the median average.
    pub fn cross_spectra(
        &mut self,
        signals: &[&[f64]],
        fs_hz: f64,
        bins: &[usize],
    ) -> Result<CrossSpectra> {
        check_fs(fs_hz)?;
        self.check_cross(signals, bins)?;
        let len = signals.first().map_or(0, |x| x.len());
        if len < self.cfg.nperseg {
            return Err(SpectrumError::TooShort {
                len,
                nperseg: self.cfg.nperseg,
            }
            .into());
        }
        for x in signals {
            check_finite(x)?;
        }
        let starts: Vec<usize> = (0..self.cfg.n_segments(len))
            .map(|s| s * self.cfg.step())
            .collect();
        Ok(self.cross_spectra_at(signals, &starts, fs_hz, bins))
    }

    /// [`cross_spectra`](Self::cross_spectra) of signals tracked together with gaps (NaN): a
    /// sample missing in one signal is dropped from all, gaps of at most `max_fill` samples are
    /// filled linearly in each signal, and the segments are taken from the finite runs between
    /// longer gaps, as [`process_gappy`](Self::process_gappy) takes them (so for one signal the
    /// diagonal is its gappy Welch PSD).
    ///
    /// Errors: those of [`cross_spectra`](Self::cross_spectra) but
    /// [`SpectrumError::NonFinite`]; [`SpectrumError::AllMissing`] and
    /// [`SpectrumError::NoFiniteRun`] as [`process_gappy`](Self::process_gappy).
    pub fn cross_spectra_gappy(
        &mut self,
        signals: &[&[f64]],
        fs_hz: f64,
        bins: &[usize],
        max_fill: usize,
    ) -> Result<CrossSpectra> {
        check_fs(fs_hz)?;
        self.check_cross(signals, bins)?;
        let len = signals.first().map_or(0, |x| x.len());
        let missing: Vec<bool> = (0..len)
            .map(|t| signals.iter().any(|x| !x[t].is_finite()))
            .collect();
        let filled: Vec<Filled> = signals
            .iter()
            .map(|x| {
                let masked: Vec<f64> = x
                    .iter()
                    .zip(&missing)
                    .map(|(v, m)| if *m { f64::NAN } else { *v })
                    .collect();
                fill_and_split(&masked, max_fill, self.cfg.nperseg)
            })
            .collect::<Result<_>>()?;
        // Every signal has the same missing samples, so the same runs.
        let runs = &filled[0].runs;
        let cfg = self.cfg;
        let starts: Vec<usize> = runs
            .iter()
            .flat_map(|&(s, e)| (0..cfg.n_segments(e - s)).map(move |k| s + k * cfg.step()))
            .collect();
        if starts.is_empty() {
            return Err(SpectrumError::NoFiniteRun {
                nperseg: self.cfg.nperseg,
                longest: runs.iter().map(|(s, e)| e - s).max().unwrap_or(0),
                len,
                runs: runs.len(),
                max_fill,
            }
            .into());
        }
        let ys: Vec<&[f64]> = filled.iter().map(|f| f.y.as_slice()).collect();
        Ok(self.cross_spectra_at(&ys, &starts, fs_hz, bins))
    }

    /// The settings' and the arguments' errors of the cross-spectra: median average, a bin out
    /// of range, signals of different lengths.
    fn check_cross(&self, signals: &[&[f64]], bins: &[usize]) -> Result<()> {
        if self.cfg.average == Average::Median {
            return Err(SpectrumError::MedianCrossSpectra.into());
        }
        let nf = self.cfg.n_freqs();
        if let Some(&bin) = bins.iter().find(|&&k| k >= nf) {
            return Err(SpectrumError::BinOutOfRange { bin, n_freqs: nf }.into());
        }
        let len = signals.first().map_or(0, |x| x.len());
        if signals.iter().any(|x| x.len() != len) {
            return Err(SpectrumError::UnequalLengths {
                lengths: signals.iter().map(|x| x.len()).collect(),
            }
            .into());
        }
        Ok(())
    }

    /// The cross-spectral matrices at `bins` averaged over the segments starting at `starts`
    /// (finite samples, `nperseg` from each start).
    fn cross_spectra_at(
        &mut self,
        signals: &[&[f64]],
        starts: &[usize],
        fs_hz: f64,
        bins: &[usize],
    ) -> CrossSpectra {
        let p = signals.len();
        let mut sum = vec![vec![Complex::new(0.0, 0.0); p * p]; bins.len()];
        let mut column = vec![Complex::new(0.0, 0.0); p * bins.len()];
        for &start in starts {
            for (a, x) in signals.iter().enumerate() {
                self.segment_power(&x[start..start + self.cfg.nperseg]);
                for (j, &k) in bins.iter().enumerate() {
                    column[j * p + a] = self.spec[k];
                }
            }
            for (j, m) in sum.iter_mut().enumerate() {
                let xk = &column[j * p..(j + 1) * p];
                for a in 0..p {
                    for b in 0..p {
                        m[a * p + b] += xk[a] * xk[b].conj();
                    }
                }
            }
        }
        let n_seg = starts.len();
        let norm = self.norm(fs_hz) / n_seg as f64;
        let last = self.cfg.n_freqs() - 1;
        let matrices = sum
            .into_iter()
            .zip(bins)
            .map(|(m, &k)| {
                let one_sided = if k > 0 && (self.cfg.nfft % 2 == 1 || k < last) {
                    2.0
                } else {
                    1.0
                };
                m.into_iter().map(|c| c * (norm * one_sided)).collect()
            })
            .collect();
        let mut freq_hz = Vec::new();
        fill_freqs(&mut freq_hz, self.cfg.nfft, fs_hz);
        CrossSpectra {
            freq_hz: bins.iter().map(|&k| freq_hz[k]).collect(),
            signals: p,
            matrices,
            n_segments: n_seg,
        }
    }

    /// The factor on one segment's `|X_k|²`: `1/(fs·Σw²)` for density, `1/(Σw)²` for spectrum.
    fn norm(&self, fs_hz: f64) -> f64 {
        match self.cfg.scaling {
            Scaling::Density => 1.0 / (fs_hz * self.sums.sum_sq),
            Scaling::Spectrum => 1.0 / (self.sums.sum * self.sums.sum),
        }
    }
}

/// Welch cross-spectral matrices of `signals` signals at chosen bins ([`WelchPlan::cross_spectra`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CrossSpectra {
    /// The bins' frequencies, Hz.
    pub freq_hz: Vec<f64>,
    /// Signals, `p`.
    pub signals: usize,
    /// Per bin, the `p × p` Hermitian matrix in row-major order (entry `(a, b)` at `a·p + b`),
    /// (signal units)²/Hz with density scaling.
    pub matrices: Vec<Vec<Complex<f64>>>,
    /// Segments averaged.
    pub n_segments: usize,
}

/// A record with short gaps filled: the samples from its first to its last finite one, gaps of
/// at most `max_fill` samples linearly interpolated, and the finite runs between longer gaps
/// (`[start, end)` into `y`).
struct Filled {
    y: Vec<f64>,
    runs: Vec<(usize, usize)>,
    report: GapReport,
}

/// Fills the short gaps of `x` and splits it at the long ones ([`Filled`]).
/// [`SpectrumError::AllMissing`] when no sample is finite.
fn fill_and_split(x: &[f64], max_fill: usize, nperseg: usize) -> Result<Filled> {
    let (Some(first), Some(last)) = (
        x.iter().position(|v| v.is_finite()),
        x.iter().rposition(|v| v.is_finite()),
    ) else {
        return Err(SpectrumError::AllMissing {
            len: x.len(),
            nperseg,
        }
        .into());
    };
    let mut report = GapReport {
        dropped: first + (x.len() - 1 - last),
        ..GapReport::default()
    };
    let mut y = x[first..=last].to_vec();
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut run_start = 0;
    let mut i = 0;
    while i < y.len() {
        if y[i].is_finite() {
            i += 1;
            continue;
        }
        // y[0] and y[len-1] are finite, so the gap [i, j) has finite neighbours.
        let mut j = i;
        while !y[j].is_finite() {
            j += 1;
        }
        let gap = j - i;
        if gap <= max_fill {
            let (a, b) = (y[i - 1], y[j]);
            let denom = (gap + 1) as f64;
            for m in 0..gap {
                y[i + m] = a + (b - a) * ((m + 1) as f64 / denom);
            }
            report.filled += gap;
        } else {
            runs.push((run_start, i));
            run_start = j;
            report.dropped += gap;
        }
        i = j;
    }
    runs.push((run_start, y.len()));
    report.runs = runs.len();
    Ok(Filled { y, runs, report })
}

/// `f_k = k·(1/(nfft·(1/fs)))`, exactly as `numpy.fft.rfftfreq(nfft, 1/fs)`.
pub(crate) fn fill_freqs(freq: &mut Vec<f64>, nfft: usize, fs_hz: f64) {
    let val = 1.0 / (nfft as f64 * (1.0 / fs_hz));
    freq.clear();
    freq.extend((0..nfft / 2 + 1).map(|k| k as f64 * val));
}

/// NumPy's median of `v` (the mean of the two middle values for an even count); `v` is reordered.
fn median_of(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Scales by `inv_n` (the averaging: 1/segments, or 1/median bias) and `norm` (the density or
/// spectrum factor) and doubles the one-sided bins (SciPy's rule).
fn scale_one_sided(p: &mut [f64], nfft: usize, inv_n: f64, norm: f64) {
    let last = p.len() - 1;
    for (k, v) in p.iter_mut().enumerate() {
        let mut d = *v * inv_n * norm;
        // Even nfft: the Nyquist bin (k = nfft/2) has no mirror image and is not doubled.
        if k > 0 && (nfft % 2 == 1 || k < last) {
            d *= 2.0;
        }
        *v = d;
    }
}

/// [`SpectrumError::NonFinite`] at the first non-finite sample of `x`.
fn check_finite(x: &[f64]) -> Result<()> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(SpectrumError::NonFinite {
            index: i,
            len: x.len(),
            value: x[i],
        }
        .into()),
        None => Ok(()),
    }
}

pub(crate) fn check_fs(fs_hz: f64) -> Result<()> {
    if fs_hz.is_finite() && fs_hz > 0.0 {
        Ok(())
    } else {
        Err(SpectrumError::SamplingRate { fs_hz }.into())
    }
}

/// The default Welch segment length for `n` samples: the largest power of two (at least 8) that
/// leaves at least four segments, `nperseg ≤ n/4` (with 50 % overlap, seven averaged segments).
pub fn default_nperseg(n: usize) -> usize {
    let mut p = 8usize;
    while p * 2 <= n / 4 {
        p *= 2;
    }
    p
}

/// Welch PSD of the uniformly sampled `x` at `fs_hz` (Hz): `scipy.signal.welch(x, fs,
/// window='hann', nperseg, noverlap, nfft, detrend, scaling='density', average='mean')`.
///
/// Returns `nfft/2 + 1` bins in units²/Hz. Errors: [`SpectrumError`] (a setting) for an invalid
/// `cfg` or `fs_hz`; [`SpectrumError::TooShort`] / [`SpectrumError::NonFinite`] if `x` is shorter than `nperseg` or contains NaN/±∞.
///
/// ```
/// use wiperlab::spectrum::{welch, WelchConfig};
/// let fs = 1000.0;
/// let x: Vec<f64> = (0..4000)
///     .map(|n| (2.0 * std::f64::consts::PI * 125.0 * n as f64 / fs).sin())
///     .collect();
/// let psd = welch(&x, fs, &WelchConfig::new(256))?;
/// assert_eq!(psd.freq_hz.len(), 129);
/// assert!((psd.total_power() - 0.5).abs() < 1e-3); // A²/2
/// # Ok::<(), wiperlab::Error>(())
/// ```
pub fn welch(x: &[f64], fs_hz: f64, cfg: &WelchConfig) -> Result<Psd> {
    WelchPlan::new(*cfg)?.process(x, fs_hz)
}

/// NaN-aware Welch PSD.
///
/// Non-finite samples (NaN, ±∞) are missing. Leading and trailing ones are dropped. An interior run of
/// at most `max_fill` missing samples is filled by linear interpolation between its finite
/// neighbours; a longer run splits the record. Welch segments are then taken within each finite run
/// only (a segment never straddles a gap), and the mean is over all segments of all runs. A record
/// without missing samples gives exactly (bit for bit) the result of [`welch`].
///
/// Errors: as [`welch`], and [`SpectrumError::AllMissing`] / [`SpectrumError::NoFiniteRun`] if every sample is missing or no finite run (after
/// filling) has `nperseg` samples; the message gives the longest run.
pub fn welch_gappy(
    x: &[f64],
    fs_hz: f64,
    cfg: &WelchConfig,
    max_fill: usize,
) -> Result<(Psd, GapReport)> {
    WelchPlan::new(*cfg)?.process_gappy(x, fs_hz, max_fill)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` samples of white Gaussian noise of standard deviation `sigma`, seeded.
    fn white(n: usize, sigma: f64, seed: u64) -> Vec<f64> {
        use rand::SeedableRng;
        use rand_distr::Distribution;
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let normal = rand_distr::Normal::new(0.0, sigma).expect("a positive sigma");
        (0..n).map(|_| normal.sample(&mut rng)).collect()
    }

    #[test]
    fn cross_spectra_hold_each_psd_on_the_diagonal_and_the_transfer_off_it() {
        // y = g·x(t − d) + e with x, e white and independent: S_yx = g·e^{−2πi f d/fs}·S_xx and
        // S_yy = g²·S_xx + S_ee, with the one-sided white density S = 2σ²/fs (Bendat & Piersol
        // 2010, §6.1.4 and §11.5.2).
        let (fs, n, g, d) = (1000.0, 1 << 17, 0.5, 3);
        let x = white(n + d, 1.0, 11);
        let e = white(n, 0.3, 12);
        let y: Vec<f64> = (0..n).map(|t| g * x[t] + e[t]).collect();
        let x = &x[d..];
        let cfg = WelchConfig::new(256);
        let mut plan = WelchPlan::new(cfg).unwrap();
        let bins: Vec<usize> = (8..120).collect();
        let c = plan.cross_spectra(&[x, &y], fs, &bins).unwrap();
        assert_eq!((c.signals, c.matrices.len()), (2, bins.len()));
        // The diagonal is the Welch PSD itself.
        let px = plan.process(x, fs).unwrap();
        let py = plan.process(&y, fs).unwrap();
        for (m, &k) in c.matrices.iter().zip(&bins) {
            assert!((m[0].re - px.density[k]).abs() <= 1e-12 * px.density[k]);
            assert!((m[3].re - py.density[k]).abs() <= 1e-12 * py.density[k]);
            assert!(m[0].im.abs() < 1e-12 * px.density[k]);
            // Hermitian.
            assert!((m[1] - m[2].conj()).norm() <= 1e-12 * px.density[k]);
        }
        // Averaged over the bins, the ratios to their expectations are 1 within a few standard
        // errors (about 510 segments per bin, 112 bins).
        let s_xx = 2.0 / fs;
        let mean = |f: &dyn Fn(&[Complex<f64>], f64) -> f64| {
            c.matrices
                .iter()
                .zip(&c.freq_hz)
                .map(|(m, &f_hz)| f(m, f_hz))
                .sum::<f64>()
                / bins.len() as f64
        };
        let yy = mean(&|m, _| m[3].re / ((g * g + 0.09) * s_xx));
        assert!((yy - 1.0).abs() < 0.01, "S_yy ratio {yy}");
        // x here leads y by d samples: x(t) = x₀(t + d), so S_xy = E[X Y*] = g·S_xx·e^{+2πi f d/fs}.
        let along = mean(&|m, f| {
            let w = std::f64::consts::TAU * f * d as f64 / fs;
            (m[1] * Complex::new(w.cos(), -w.sin())).re / (g * s_xx)
        });
        let across = mean(&|m, f| {
            let w = std::f64::consts::TAU * f * d as f64 / fs;
            (m[1] * Complex::new(w.cos(), -w.sin())).im / (g * s_xx)
        });
        // A delay of 3 of 256 samples loses about 3/256 of the coherent product to the taper.
        assert!((along - 1.0).abs() < 0.03, "in phase {along}");
        assert!(across.abs() < 0.02, "in quadrature {across}");
    }

    #[test]
    fn gappy_cross_spectra_drop_a_sample_missing_in_any_signal() {
        // Lost frames: a short gap in x (filled) and a long one in y (split); the diagonal is each
        // signal's gappy Welch PSD with the other's missing samples dropped too.
        let (fs, n) = (500.0, 4000);
        let mut x = white(n, 1.0, 21);
        let mut y = white(n, 2.0, 22);
        x[1000..1003].fill(f64::NAN);
        y[2500..2700].fill(f64::NAN);
        let union = |v: &[f64]| -> Vec<f64> {
            (0..n)
                .map(|t| {
                    if x[t].is_finite() && y[t].is_finite() {
                        v[t]
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        };
        let cfg = WelchConfig::new(128);
        let mut plan = WelchPlan::new(cfg).unwrap();
        let bins: Vec<usize> = (3..60).collect();
        let c = plan.cross_spectra_gappy(&[&x, &y], fs, &bins, 5).unwrap();
        let (px, rx) = plan.process_gappy(&union(&x), fs, 5).unwrap();
        let (py, _) = plan.process_gappy(&union(&y), fs, 5).unwrap();
        assert_eq!(c.n_segments, rx.segments_used);
        assert_eq!(rx.runs, 2);
        for (m, &k) in c.matrices.iter().zip(&bins) {
            assert!((m[0].re - px.density[k]).abs() <= 1e-12 * px.density[k]);
            assert!((m[3].re - py.density[k]).abs() <= 1e-12 * py.density[k]);
        }
        // Without a gap it is the plain estimate.
        let z = white(n, 1.0, 23);
        let plain = plan.cross_spectra(&[&z], fs, &bins).unwrap();
        let gappy = plan.cross_spectra_gappy(&[&z], fs, &bins, 5).unwrap();
        assert_eq!(plain, gappy);
    }

    #[test]
    fn cross_spectra_say_what_they_cannot_read() {
        let mut plan = WelchPlan::new(WelchConfig::new(16)).unwrap();
        let x = vec![0.0; 64];
        let err = |r: Result<CrossSpectra>| match r {
            Err(e) => crate::spectrum::SpectrumError::of(&e).cloned(),
            Ok(_) => None,
        };
        assert!(matches!(
            err(plan.cross_spectra(&[&x, &x[..63]], 1.0, &[1])),
            Some(SpectrumError::UnequalLengths { .. })
        ));
        assert!(matches!(
            err(plan.cross_spectra(&[&x, &x], 1.0, &[9])),
            Some(SpectrumError::BinOutOfRange { bin: 9, n_freqs: 9 })
        ));
        let mut y = x.clone();
        y[5] = f64::NAN;
        assert!(matches!(
            err(plan.cross_spectra(&[&x, &y], 1.0, &[1])),
            Some(SpectrumError::NonFinite { index: 5, .. })
        ));
        let mut median =
            WelchPlan::new(WelchConfig::new(16).with_average(Average::Median)).unwrap();
        assert!(matches!(
            err(median.cross_spectra(&[&x, &x], 1.0, &[1])),
            Some(SpectrumError::MedianCrossSpectra)
        ));
    }

    #[test]
    fn config_defaults_are_scipys() {
        // scipy.signal.welch docs: window='hann', noverlap = nperseg // 2, nfft = nperseg,
        // detrend='constant', scaling='density', average='mean'.
        let c = WelchConfig::new(255);
        assert_eq!(
            c,
            WelchConfig {
                nperseg: 255,
                noverlap: 127,
                nfft: 255,
                detrend: Detrend::Constant,
                window: Window::Hann,
                scaling: Scaling::Density,
                average: Average::Mean,
            }
        );
        assert_eq!(c.step(), 128);
        assert_eq!(c.n_segments(254), 0);
        assert_eq!(c.n_segments(255), 1);
        assert_eq!(c.n_segments(255 + 128), 2);
        assert_eq!(c.n_freqs(), 128);
        // The median bias: 1 for one or two segments, 1 + 1/3 − 1/2 for three, → ln 2.
        assert_eq!(median_bias(1), 1.0);
        assert_eq!(median_bias(2), 1.0);
        assert!((median_bias(3) - (1.0 + 1.0 / 3.0 - 0.5)).abs() < 1e-15);
        assert!((median_bias(100_001) - std::f64::consts::LN_2).abs() < 1e-5);
    }

    #[test]
    fn config_validation() {
        assert!(matches!(
            WelchConfig::new(1).validate(),
            Err(ref e) if matches!(crate::spectrum::SpectrumError::of(e), Some(SpectrumError::NpersegTooSmall {
                nperseg: 1
            }))
        ));
        assert!(WelchConfig::new(2).validate().is_ok());
        assert!(WelchConfig::new(64).with_noverlap(64).is_err());
        assert!(WelchConfig::new(64).with_noverlap(63).is_ok());
        assert!(WelchConfig::new(64).with_nfft(63).is_err());
        assert!(WelchConfig::new(64).with_nfft(100).is_ok());
        assert!(WelchPlan::new(WelchConfig::new(0)).is_err());
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let cfg = WelchConfig::new(16);
        for x in [vec![], vec![1.0; 15]] {
            let e = welch(&x, 100.0, &cfg).unwrap_err();
            assert!(
                matches!(
                    crate::spectrum::SpectrumError::of(&e),
                    Some(SpectrumError::TooShort { nperseg: 16, .. })
                ) && e.to_string().contains("nperseg = 16"),
                "{e}"
            );
        }
        let mut x = vec![0.5; 64];
        x[10] = f64::NAN;
        assert!(matches!(
            welch(&x, 100.0, &cfg),
            Err(ref e) if matches!(crate::spectrum::SpectrumError::of(e), Some(SpectrumError::NonFinite { index: 10, .. }))
        ));
        let e = welch(&[0.0; 64], 0.0, &cfg).unwrap_err();
        assert!(matches!(
            crate::spectrum::SpectrumError::of(&e),
            Some(SpectrumError::SamplingRate { .. })
        ));
        assert!(e.is_input_error());
        assert!(matches!(
            welch(&[0.0; 64], f64::NAN, &cfg),
            Err(ref e) if matches!(crate::spectrum::SpectrumError::of(e), Some(SpectrumError::SamplingRate { .. }))
        ));
    }

    #[test]
    fn white_noise_level_and_dc_rejection() {
        // A constant signal has zero PSD after constant detrending (to rounding).
        let psd = welch(&[3.0; 256], 10.0, &WelchConfig::new(32)).unwrap();
        assert!(psd.density.iter().all(|v| v.abs() < 1e-28));
        assert_eq!(psd.n_segments, 15);
    }

    #[test]
    fn plan_reuse_is_deterministic() {
        let x: Vec<f64> = (0..1000).map(|n| ((n * n) % 17) as f64 - 8.0).collect();
        let cfg = WelchConfig::new(100).with_nfft(128).unwrap();
        let mut plan = WelchPlan::new(cfg).unwrap();
        let a = plan.process(&x, 50.0).unwrap();
        let mut b = Psd::default();
        plan.process_into(&x[..500], 50.0, &mut b).unwrap();
        plan.process_into(&x, 50.0, &mut b).unwrap();
        assert_eq!(a, b);
        assert_eq!(a, welch(&x, 50.0, &cfg).unwrap());
    }
}
