//! Hann windows and their power sums.
//!
//! Two variants of the same raised cosine:
//!
//! * [`hann_periodic`] (DFT-even), `w[n] = 0.5 − 0.5·cos(2πn/N)`, `n = 0..N`: what
//!   `scipy.signal.get_window('hann', N)` returns (its default `fftbins=True`) and hence what
//!   `scipy.signal.welch(..., window='hann')` uses. Every spectral estimator in this crate uses it.
//! * [`hann_symmetric`], `w[n] = 0.5 − 0.5·cos(2πn/(N−1))`: `numpy.hanning(N)`, kept for reference
//!   (the independent estimator behind `shared/sample/truth.json` uses it).
//!
//! For `N ≤ 1` both return `[1.0; N]`, as SciPy and NumPy do.
//!
//! The density scaling of a Welch PSD needs `Σw²` and amplitude scaling needs `Σw`; [`WindowSums`]
//! carries both (F.J. Harris, "On the use of windows for harmonic analysis with the discrete Fourier
//! transform", Proc. IEEE 66(1), 1978; SciPy `_spectral_helper`).

use std::f64::consts::PI;

/// The periodic (DFT-even) Hann window of length `n`: `w[k] = 0.5 − 0.5·cos(2πk/n)`.
///
/// Equal to `scipy.signal.get_window('hann', n)` up to rounding (SciPy evaluates
/// `0.5 + 0.5·cos(−π + 2πk/n)`, which differs in the last bit at most). `w[0] = 0`, the last sample
/// is not zero; the window is symmetric about `n/2`. Returns `[1.0]` for `n = 1` and an empty vector
/// for `n = 0`.
pub fn hann_periodic(n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![1.0; n];
    }
    let nf = n as f64;
    (0..n)
        .map(|k| 0.5 - 0.5 * (2.0 * PI * k as f64 / nf).cos())
        .collect()
}

/// The symmetric Hann window of length `n`: `w[k] = 0.5 − 0.5·cos(2πk/(n−1))` (`numpy.hanning`).
///
/// Both end samples are zero. Returns `[1.0]` for `n = 1` and an empty vector for `n = 0`.
pub fn hann_symmetric(n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![1.0; n];
    }
    let d = (n - 1) as f64;
    (0..n)
        .map(|k| 0.5 - 0.5 * (2.0 * PI * k as f64 / d).cos())
        .collect()
}

/// The window a Welch estimate tapers each segment with: the periodic (DFT-even) variant of each,
/// as `scipy.signal.get_window(name, n)` returns by default (`fftbins=True`). All are generalised
/// cosine windows `w[k] = Σ_j (−1)^j a_j cos(2πjk/n)` (Harris 1978, §4; SciPy
/// `signal.windows.general_cosine`), except the rectangular one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
#[derive(clap::ValueEnum)]
pub enum Window {
    /// Hann, `a = [0.5, 0.5]`: SciPy's `welch` default; ENBW 1.5 bins, sidelobes −31 dB.
    #[default]
    Hann,
    /// Hamming, `a = [0.54, 0.46]`: sidelobes −43 dB, ENBW 1.36 bins.
    Hamming,
    /// Blackman, `a = [0.42, 0.50, 0.08]`: sidelobes −58 dB, ENBW 1.73 bins.
    Blackman,
    /// Rectangular (`'boxcar'`): no taper, the narrowest main lobe and the highest leakage.
    Boxcar,
}

impl Window {
    /// Every window, for listings.
    pub const ALL: [Window; 4] = [
        Window::Hann,
        Window::Hamming,
        Window::Blackman,
        Window::Boxcar,
    ];

    /// SciPy's name of the window (`'hann'`, `'hamming'`, `'blackman'`, `'boxcar'`).
    pub fn scipy_name(self) -> &'static str {
        match self {
            Window::Hann => "hann",
            Window::Hamming => "hamming",
            Window::Blackman => "blackman",
            Window::Boxcar => "boxcar",
        }
    }

    /// The window from SciPy's name, if it is one of these.
    pub fn from_scipy_name(name: &str) -> Option<Window> {
        Window::ALL.into_iter().find(|w| w.scipy_name() == name)
    }

    /// The periodic window of length `n` (`[1.0]` for `n = 1`, empty for `n = 0`).
    pub fn periodic(self, n: usize) -> Vec<f64> {
        let a: &[f64] = match self {
            Window::Hann => return hann_periodic(n),
            Window::Hamming => &[0.54, 0.46],
            Window::Blackman => &[0.42, 0.50, 0.08],
            Window::Boxcar => return vec![1.0; n],
        };
        if n <= 1 {
            return vec![1.0; n];
        }
        let nf = n as f64;
        (0..n)
            .map(|k| {
                a.iter()
                    .enumerate()
                    .map(|(j, aj)| {
                        let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
                        sign * aj * (2.0 * PI * (j * k) as f64 / nf).cos()
                    })
                    .sum()
            })
            .collect()
    }
}

impl std::fmt::Display for Window {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.scipy_name())
    }
}

/// Power sums of a window, used for PSD normalisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowSums {
    /// `Σ w[n]` (coherent gain × N). For the periodic Hann window this is `N/2`.
    pub sum: f64,
    /// `Σ w[n]²` (the density normalisation `1/(fs·Σw²)` uses it). For the periodic Hann window this
    /// is `3N/8` for `N ≥ 3`.
    pub sum_sq: f64,
}

impl WindowSums {
    /// Sums of `w`.
    pub fn of(w: &[f64]) -> Self {
        WindowSums {
            sum: w.iter().sum(),
            sum_sq: w.iter().map(|v| v * v).sum(),
        }
    }

    /// Equivalent noise bandwidth in bins, `N·Σw²/(Σw)²` (1.5 for Hann). `n` is the window length.
    pub fn enbw_bins(&self, n: usize) -> f64 {
        n as f64 * self.sum_sq / (self.sum * self.sum)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periodic_hann_values_and_sums() {
        // N = 4: 0.5 − 0.5 cos(πk/2) = [0, 0.5, 1, 0.5] (hand computed).
        let w = hann_periodic(4);
        let want = [0.0, 0.5, 1.0, 0.5];
        for (a, b) in w.iter().zip(want) {
            assert!((a - b).abs() < 1e-15);
        }
        // Closed forms: Σw = N/2 (N ≥ 2) and Σw² = 3N/8 (N ≥ 3: Σcos(4πn/N) vanishes unless N | 2)
        // for the periodic Hann window; ENBW = 1.5 bins.
        for n in [3usize, 7, 64, 255] {
            let s = WindowSums::of(&hann_periodic(n));
            assert!((s.sum - n as f64 / 2.0).abs() < 1e-12, "n = {n}");
            assert!((s.sum_sq - 3.0 * n as f64 / 8.0).abs() < 1e-12, "n = {n}");
            assert!((s.enbw_bins(n) - 1.5).abs() < 1e-12);
        }
        // N = 2: w = [0, 1].
        assert_eq!(WindowSums::of(&hann_periodic(2)).sum_sq, 1.0);
    }

    /// Closed forms of the cosine windows' sums over a whole period: `Σw = n·a_0` and
    /// `Σw² = n·(a_0² + Σ_{j≥1} a_j²/2)` (the cross terms vanish for `n > 2·order`).
    #[test]
    fn cosine_window_sums() {
        for (w, a) in [
            (Window::Hamming, vec![0.54, 0.46]),
            (Window::Blackman, vec![0.42, 0.50, 0.08]),
            (Window::Hann, vec![0.5, 0.5]),
        ] {
            let n = 64;
            let s = WindowSums::of(&w.periodic(n));
            let sq = a[0] * a[0] + a[1..].iter().map(|x| x * x / 2.0).sum::<f64>();
            assert!((s.sum - n as f64 * a[0]).abs() < 1e-12, "{w}");
            assert!((s.sum_sq - n as f64 * sq).abs() < 1e-12, "{w}");
        }
        assert_eq!(Window::Boxcar.periodic(3), vec![1.0; 3]);
        assert_eq!(Window::from_scipy_name("blackman"), Some(Window::Blackman));
        assert_eq!(Window::from_scipy_name("kaiser"), None);
    }

    #[test]
    fn symmetric_hann_matches_numpy_definition() {
        // numpy.hanning(5) = [0, 0.5, 1, 0.5, 0].
        let w = hann_symmetric(5);
        let want = [0.0, 0.5, 1.0, 0.5, 0.0];
        for (a, b) in w.iter().zip(want) {
            assert!((a - b).abs() < 1e-15);
        }
        assert_eq!(hann_symmetric(1), vec![1.0]);
        assert_eq!(hann_periodic(1), vec![1.0]);
        assert!(hann_periodic(0).is_empty());
    }
}
