//! What can go wrong in the spectrum stage: [`SpectrumError`], each variant with its numbers.

/// A spectral estimate that cannot be made from the given settings or samples.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SpectrumError {
    /// Welch needs segments of at least two samples.
    #[error("Welch nperseg = {nperseg} must be at least 2")]
    NpersegTooSmall { nperseg: usize },
    /// Overlap at least as long as a segment.
    #[error("Welch noverlap = {noverlap} must be less than nperseg = {nperseg}")]
    OverlapTooLarge { noverlap: usize, nperseg: usize },
    /// FFT shorter than a segment.
    #[error("Welch nfft = {nfft} must be at least nperseg = {nperseg}")]
    NfftTooSmall { nfft: usize, nperseg: usize },
    /// A sampling rate that is not finite and positive.
    #[error("sampling rate fs = {fs_hz} Hz must be finite and positive")]
    SamplingRate { fs_hz: f64 },
    /// A non-finite sample where every sample must be finite.
    #[error(
        "Welch PSD: sample {index} of {len} is {value} (expected finite samples; use welch_gappy for records with gaps)"
    )]
    NonFinite {
        index: usize,
        len: usize,
        value: f64,
    },
    /// Fewer samples than one segment.
    #[error("Welch PSD: record has {len} samples, expected at least nperseg = {nperseg}")]
    TooShort { len: usize, nperseg: usize },
    /// Every sample missing.
    #[error(
        "Welch PSD: all {len} samples are NaN or non-finite (expected at least nperseg = {nperseg} consecutive finite samples)"
    )]
    AllMissing { len: usize, nperseg: usize },
    /// No run of finite samples (after filling short gaps) as long as a segment.
    #[error(
        "Welch PSD: no finite run of at least nperseg = {nperseg} samples (longest run {longest} samples of {len}; {runs} runs after filling NaN gaps of up to {max_fill} samples)"
    )]
    NoFiniteRun {
        nperseg: usize,
        longest: usize,
        len: usize,
        runs: usize,
        max_fill: usize,
    },
    /// The tracking noise of a trace cannot be estimated (too few samples, or a noise-free trace).
    #[error(
        "stick detector: cannot estimate the tracking noise of the tip trace (σ̂ = {} from {samples} samples); it needs a noisy trace with at least 10 samples",
        crate::names::quantity(*sigma_m, "m")
    )]
    NoNoiseEstimate { sigma_m: f64, samples: usize },
    /// Ridge settings out of range: the band must satisfy 0 ≤ low < high and `min_snr` ≥ 0.
    #[error(
        "instantaneous frequency: need 0 <= band low < band high and min_snr >= 0 (got band {band_hz:?} Hz, min_snr {min_snr})"
    )]
    RidgeSettings { band_hz: (f64, f64), min_snr: f64 },
    /// The analysed signal and the tip position differ in length.
    #[error(
        "instantaneous frequency: signal has {signal} samples but the tip position {tip} (expected equal lengths)"
    )]
    LengthMismatch { signal: usize, tip: usize },
    /// Stick-detector settings out of range.
    #[error(
        "stick detector: need half_width >= 1, fs_hz > 0 and 0 < enter_sigmas <= leave_sigmas (got half_width {half_width}, enter_sigmas {enter_sigmas}, leave_sigmas {leave_sigmas}, fs {fs_hz} Hz)"
    )]
    DetectorSettings {
        half_width: usize,
        enter_sigmas: f64,
        leave_sigmas: f64,
        fs_hz: f64,
    },
    /// A signal needs a tracked point the trace does not have; `present` lists the trace's points.
    #[error(
        "signal needs a tracked point with role '{role}' (map it in [recording.import.points]); the trace has: {}",
        present.join(", ")
    )]
    MissingPoint {
        role: crate::trace::Role,
        present: Vec<String>,
    },
    /// A feature band that holds no frequency bin of the spectrum.
    #[error(
        "band '{band}' [{lo_hz}, {hi_hz}] Hz holds no frequency bin at fs = {} Hz, nperseg = {nperseg} (Nyquist {} Hz)",
        crate::names::significant(*fs_hz, 6),
        crate::names::significant(fs_hz / 2.0, 6)
    )]
    EmptyBand {
        band: String,
        lo_hz: f64,
        hi_hz: f64,
        fs_hz: f64,
        nperseg: usize,
    },
    /// Resampling: time stamps and samples differ in number.
    #[error("resample: {times} time stamps but {samples} samples (expected one stamp per sample)")]
    ResampleLengths { times: usize, samples: usize },
    /// Resampling an empty record.
    #[error("resample: empty record (expected at least one sample)")]
    ResampleEmpty,
    /// Resampling: a time stamp that is not finite.
    #[error("resample: time stamp {index} is {t_s} (expected finite times)")]
    ResampleTime { index: usize, t_s: f64 },
    /// Resampling: time stamps that do not increase at `index`.
    #[error(
        "resample: time stamps not strictly increasing at index {index} ({before_s} s then {after_s} s)"
    )]
    ResampleOrder {
        index: usize,
        before_s: f64,
        after_s: f64,
    },
    /// Spectrogram: a non-finite sample.
    #[error("spectrogram: sample {index} of {len} is {value} (expected finite samples)")]
    SpectrogramNonFinite {
        index: usize,
        len: usize,
        value: f64,
    },
    /// Spectrogram: fewer samples than one segment.
    #[error("spectrogram: record has {len} samples, expected at least nperseg = {nperseg}")]
    SpectrogramTooShort { len: usize, nperseg: usize },
    /// Cross-spectra: signals of different lengths.
    #[error("cross-spectra: signals of {lengths:?} samples (expected one length for every signal)")]
    UnequalLengths { lengths: Vec<usize> },
    /// Cross-spectra: a bin past the last frequency.
    #[error("cross-spectra: bin {bin} requested of {n_freqs} (expected bins below nfft/2 + 1)")]
    BinOutOfRange { bin: usize, n_freqs: usize },
    /// Cross-spectra with the median average, which has no cross-spectral counterpart.
    #[error(
        "cross-spectra: the median average has no cross-spectral form (expected average = \"mean\")"
    )]
    MedianCrossSpectra,
}

impl SpectrumError {
    /// True for errors in the settings (segment length, overlap, FFT length, sampling rate, ridge
    /// and detector settings, bands, the points a signal needs), which come from the user's input;
    /// false for samples a spectrum cannot be estimated from.
    pub fn is_setting(&self) -> bool {
        matches!(
            self,
            SpectrumError::NpersegTooSmall { .. }
                | SpectrumError::OverlapTooLarge { .. }
                | SpectrumError::NfftTooSmall { .. }
                | SpectrumError::SamplingRate { .. }
                | SpectrumError::RidgeSettings { .. }
                | SpectrumError::LengthMismatch { .. }
                | SpectrumError::DetectorSettings { .. }
                | SpectrumError::MissingPoint { .. }
                | SpectrumError::EmptyBand { .. }
                | SpectrumError::BinOutOfRange { .. }
                | SpectrumError::MedianCrossSpectra
        )
    }
}

impl From<SpectrumError> for crate::Error {
    fn from(e: SpectrumError) -> Self {
        let input = e.is_setting();
        crate::Error::stage(e, input)
    }
}

impl SpectrumError {
    /// The spectrum stage's error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&SpectrumError> {
        e.stage_error()
    }
}
