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
        "stick detector: cannot estimate the tracking noise of the tip trace (σ̂ = {sigma_m} m from {samples} samples); it needs a noisy trace with at least 10 samples"
    )]
    NoNoiseEstimate { sigma_m: f64, samples: usize },
}

impl SpectrumError {
    /// True for errors in the settings (segment length, overlap, FFT length, sampling rate), which
    /// come from the user's input; false for samples a spectrum cannot be estimated from.
    pub fn is_setting(&self) -> bool {
        matches!(
            self,
            SpectrumError::NpersegTooSmall { .. }
                | SpectrumError::OverlapTooLarge { .. }
                | SpectrumError::NfftTooSmall { .. }
                | SpectrumError::SamplingRate { .. }
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
