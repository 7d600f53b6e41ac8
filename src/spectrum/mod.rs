//! Spectral estimation: Welch PSD, peak picking, spectrogram.
//!
//! One estimator serves measured and simulated traces alike (physics.md §4, "compare like with
//! like"). Conventions follow `scipy.signal.welch` exactly (see [`welch`](welch::welch) and
//! `shared/crates.md` §5), so results can be cross-checked in Python; the parity tests in
//! `tests/suite/spectrum.rs` hold to 1e-10 relative.
//!
//! * [`window`]: periodic and symmetric Hann windows, their sums.
//! * [`welch`](mod@welch): [`WelchConfig`], [`WelchPlan`] (plan once, process many), [`welch()`],
//!   NaN-aware [`welch_gappy`].
//! * [`resample`]: [`resample_uniform`] for jittered frame times, [`median_rate_hz`].
//! * [`signal`]: signals named by text (`<point>_y`, `<a>-<b>_x`), [`signal::SignalExpr`].
//! * [`peaks`]: [`find_peak`], [`top_peaks`]: largest local maximum with parabolic interpolation of
//!   the log PSD (J.O. Smith, SASP).
//! * [`stft`]: [`spectrogram()`] and its [`Spectrogram::ridge`].
//! * [`noise`]: the tracking noise's spectrum, AR(1) with white as its special case.
//! * [`stats`]: the median and linear-interpolation quantiles used across the pipeline.
//! * [`instfreq`]: instantaneous frequency (spectrogram ridge, stick-onset rate) against the lip
//!   tip's speed; NaN-aware smoothed derivative, robust noise estimate, stick detection.
//!
//! Units: frequencies in Hz, times in s, PSD in (signal units)²/Hz, one-sided.
//!
//! References: P.D. Welch, IEEE Trans. Audio Electroacoust. 15(2):70–73, 1967; SciPy
//! `scipy.signal.welch` (1.17); J.O. Smith, *Spectral Audio Signal Processing*, CCRMA.

pub mod error;
pub mod features;
pub mod harmonics;
pub mod instfreq;
pub mod noise;
pub mod peaks;
pub mod resample;
pub mod signal;
pub mod stats;
pub mod stft;
pub mod welch;
pub mod window;

pub use error::SpectrumError;
pub use peaks::{Peak, find_peak, parabolic_vertex, top_peaks};
pub use resample::{
    UniformSignals, median_rate_hz, resample_uniform, uniform_signals, uniform_signals_for,
};
pub use stft::{Spectrogram, spectrogram};
pub use welch::{
    Average, Detrend, GapReport, Psd, Scaling, WelchConfig, WelchPlan, default_nperseg,
    median_bias, welch, welch_gappy,
};
pub use window::{Window, WindowSums, hann_periodic, hann_symmetric};
