//! Spectral features compared by the fit: per band, the Welch PSD, its largest peak and the log-PSD
//! across the band. Measurement and model go through this same estimator at the same sampling
//! (physics.md §4, "compare like with like").

use super::SpectrumError;
use crate::Result;
use crate::spectrum::{
    Average, Detrend, Peak, Scaling, WelchConfig, Window, find_peak, welch_gappy,
};
use crate::trace::{Role, Trace};
use serde::{Deserialize, Serialize};

/// One frequency band and the Welch segment length used in it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BandSpec {
    /// Name used in reports (`low`, `high`).
    pub name: String,
    /// Band edges `[lo, hi]` in Hz.
    pub range_hz: [f64; 2],
    /// Welch segment length (samples); longer resolves low frequencies, shorter averages the
    /// stick–slip comb into its envelope.
    pub nperseg: usize,
    /// The other Welch settings, with `scipy.signal.welch`'s names and defaults: Hann window,
    /// `noverlap = nperseg/2`, `nfft = nperseg`, constant detrend, density scaling, mean average.
    #[serde(default, skip_serializing_if = "is_default")]
    pub window: Window,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noverlap: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nfft: Option<usize>,
    #[serde(default, skip_serializing_if = "is_default")]
    pub detrend: Detrend,
    #[serde(default, skip_serializing_if = "is_default")]
    pub scaling: Scaling,
    #[serde(default, skip_serializing_if = "is_default")]
    pub average: Average,
}

fn is_default<T: Default + PartialEq>(v: &T) -> bool {
    *v == T::default()
}

impl BandSpec {
    /// A band with SciPy's default Welch settings for segments of `nperseg` samples.
    pub fn new(name: impl Into<String>, range_hz: [f64; 2], nperseg: usize) -> Self {
        BandSpec {
            name: name.into(),
            range_hz,
            nperseg,
            window: Window::default(),
            noverlap: None,
            nfft: None,
            detrend: Detrend::default(),
            scaling: Scaling::default(),
            average: Average::default(),
        }
    }

    /// The band's Welch settings.
    ///
    /// # Errors
    /// A [`crate::spectrum::SpectrumError`] when `noverlap ≥ nperseg` or `nfft < nperseg`.
    pub fn welch_config(&self) -> Result<WelchConfig> {
        let mut cfg = WelchConfig::new(self.nperseg)
            .with_window(self.window)
            .with_detrend(self.detrend)
            .with_scaling(self.scaling)
            .with_average(self.average);
        if let Some(n) = self.noverlap {
            cfg = cfg.with_noverlap(n)?;
        }
        if let Some(n) = self.nfft {
            cfg = cfg.with_nfft(n)?;
        }
        cfg.validate()?;
        Ok(cfg)
    }
}

/// The default bands of the fit: low 30–300 Hz (nperseg 4096) and high 500–5000 Hz (nperseg 512).
///
/// The segment lengths suit the shipped recording at 10 kfps: with 4096 samples (2.4 Hz bins) the
/// low peak is resolved. In the high band the stick–slip comb (lines ~7 Hz apart, whose largest
/// member changes with the integration tolerance) must merge into its envelope. 2048 samples do
/// that for one simulation, but still resolve bumps ~18 Hz apart on the envelope, and the largest
/// one changes as the parameters move: the peak jumps by ~2 % between neighbouring parameter sets
/// and the cost surface gets steps. With 512 samples (19.5 Hz bins) the envelope is one hump
/// and the cost has no steps (docs/fit.md, "Restarts"), and the model-made recordings of
/// `tests/suite/fit_recovery.rs`, `shoulder_fit.rs` and `joint_fit.rs` are recovered as well or better
/// (docs/validation.md, "Spectra against tolerance"). A job that wants the finer estimate names its bands.
pub fn default_bands() -> Vec<BandSpec> {
    vec![
        BandSpec::new("low", [30.0, 300.0], 4096),
        BandSpec::new("high", [500.0, 5000.0], 512),
    ]
}

crate::names::named_enum! {
    /// Which scalar signal of a trace a fit compares: a coordinate of the model's points `head` and
    /// `tip` (a recording's points are mapped to them in `[recording.import.points]`), or their
    /// difference. `spectrum` takes any point's (`crate::spectrum::signal`). Not offered: `head_x`,
    /// the drive the model prescribes, and `tip_y`, the glass the model holds the tip on — the
    /// model has no dynamics of its own in either.
    #[derive(Default)]
    pub enum SignalKind: "signal" {
        /// Lip tip relative to head, horizontal: `tip_x − head_x` (v3 − v), m.
        #[default]
        TipRelX => "tip_rel_x",
        /// Lip tip relative to head, vertical: `tip_y − head_y` (u − (l1 + l2) in the model), m.
        TipRelY => "tip_rel_y",
        /// Head vertical position `head_y` (= −u), m.
        HeadY => "head_y",
        /// Lip tip horizontal position (v3), m.
        TipX => "tip_x",
    }
}

impl SignalKind {
    /// The signal's samples from `trace` (NaN where a point is missing).
    ///
    /// # Errors
    /// [`SpectrumError::MissingPoint`] when the trace lacks a `head` or `tip` point.
    pub fn extract(self, trace: &Trace) -> Result<Vec<f64>> {
        let need = |role: Role| {
            trace.role(role).ok_or_else(|| SpectrumError::MissingPoint {
                role,
                present: trace.points.iter().map(|p| p.name.clone()).collect(),
            })
        };
        let diff = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a - b).collect();
        Ok(match self {
            SignalKind::TipRelX => diff(&need(Role::Tip)?.x_m, &need(Role::Head)?.x_m),
            SignalKind::TipRelY => diff(&need(Role::Tip)?.y_m, &need(Role::Head)?.y_m),
            SignalKind::HeadY => need(Role::Head)?.y_m.clone(),
            SignalKind::TipX => need(Role::Tip)?.x_m.clone(),
        })
    }

    /// The signal's coefficients on the tracked coordinates `[head x, head y, tip x, tip y]`: the
    /// signal is their weighted sum, so two signals share tracking noise where both weigh one
    /// coordinate.
    pub fn coordinates(self) -> [f64; 4] {
        match self {
            SignalKind::TipRelX => [-1.0, 0.0, 1.0, 0.0],
            SignalKind::TipRelY => [0.0, -1.0, 0.0, 1.0],
            SignalKind::HeadY => [0.0, 1.0, 0.0, 0.0],
            SignalKind::TipX => [0.0, 0.0, 1.0, 0.0],
        }
    }

    /// Whether `self` and `other` read a tracked coordinate in common (their tracking noises are
    /// then correlated).
    pub fn shares_coordinate(self, other: SignalKind) -> bool {
        self.coordinates()
            .iter()
            .zip(other.coordinates())
            .any(|(a, b)| *a != 0.0 && b != 0.0)
    }

    /// Label with unit for figures.
    pub fn label(self) -> &'static str {
        match self {
            SignalKind::TipRelX => "tip x − head x (m)",
            SignalKind::TipRelY => "tip y − head y (m)",
            SignalKind::HeadY => "head y (m)",
            SignalKind::TipX => "tip x (m)",
        }
    }
}

/// Features of one band.
#[derive(Debug, Clone)]
pub struct BandFeatures {
    pub spec: BandSpec,
    /// Bin frequencies inside the band, Hz.
    pub freq_hz: Vec<f64>,
    /// PSD inside the band, m²/Hz.
    pub psd: Vec<f64>,
    /// The largest local maximum in the band, if any.
    pub peak: Option<Peak>,
    /// Full PSD (all bins) for figures.
    pub full_freq_hz: Vec<f64>,
    pub full_psd: Vec<f64>,
    /// Welch segments averaged (`K`, over all finite runs of a gappy record).
    pub segments: usize,
}

/// Features of one signal over all bands.
#[derive(Debug, Clone)]
pub struct Features {
    pub bands: Vec<BandFeatures>,
    /// NaN samples filled by interpolation (gaps of ≤ `max_fill` samples).
    pub filled: usize,
}

/// Computes the features of `x` sampled at `fs_hz`. Gaps of up to `max_fill` samples are filled by
/// linear interpolation; longer gaps split the record (segments never straddle a gap).
pub fn features(x: &[f64], fs_hz: f64, bands: &[BandSpec], max_fill: usize) -> Result<Features> {
    let mut out = Vec::with_capacity(bands.len());
    let mut filled = 0;
    for b in bands {
        let cfg = b.welch_config()?;
        let (psd, rep) = welch_gappy(x, fs_hz, &cfg, max_fill)?;
        filled = filled.max(rep.filled);
        let (lo, hi) = (b.range_hz[0], b.range_hz[1]);
        let peak = find_peak(&psd.freq_hz, &psd.density, (lo, hi));
        let (freq, dens): (Vec<f64>, Vec<f64>) = psd
            .freq_hz
            .iter()
            .zip(&psd.density)
            .filter(|(f, _)| **f >= lo && **f <= hi)
            .map(|(f, p)| (*f, *p))
            .unzip();
        if freq.is_empty() {
            return Err(SpectrumError::EmptyBand {
                band: b.name.clone(),
                lo_hz: lo,
                hi_hz: hi,
                fs_hz,
                nperseg: b.nperseg,
            }
            .into());
        }
        out.push(BandFeatures {
            spec: b.clone(),
            freq_hz: freq,
            psd: dens,
            peak,
            full_freq_hz: psd.freq_hz,
            full_psd: psd.density,
            segments: rep.segments_used,
        });
    }
    Ok(Features { bands: out, filled })
}

/// What the band's peak is against the band's whole spectrum ([`crate::spectrum::harmonics`]):
/// a line of its own or a harmonic of a stronger line, and how far below the dominant line. Lines
/// are looked for from 3 Welch bins up (below, the window's main lobe around 0 Hz). `None` without
/// a peak or a spectrum (a target job's "measurement").
pub fn line_origin(b: &BandFeatures) -> Option<crate::spectrum::harmonics::LineOrigin> {
    let peak = b.peak?;
    let df = b.full_freq_hz.get(1).copied()? - b.full_freq_hz[0];
    crate::spectrum::harmonics::classify_line(&b.full_freq_hz, &b.full_psd, &peak, 3.0 * df)
}

/// Estimate of the measurement's white-noise floor (PSD units) in a band: the 10th percentile of
/// the PSD over the upper half of the band. Tracking noise is white, the model has none; adding this
/// floor to the model's PSD before comparing log-PSDs keeps the comparison like with like.
pub fn noise_floor(b: &BandFeatures) -> f64 {
    let n = b.psd.len();
    let mut upper: Vec<f64> = b.psd[n / 2..]
        .iter()
        .copied()
        .filter(|p| p.is_finite())
        .collect();
    if upper.is_empty() {
        return 0.0;
    }
    upper.sort_by(|a, b| a.total_cmp(b));
    upper[upper.len() / 10]
}
