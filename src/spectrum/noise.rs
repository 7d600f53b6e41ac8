//! The tracking noise's spectrum: a first-order autoregressive process, white as its special case.
//!
//! A tracking tool's position error is rarely white: sub-pixel fits and autotrackers correlate
//! neighbouring frames, and DeepLabCut and SLEAP smooth their tracks. The simplest process with a
//! frame-to-frame correlation is AR(1) (Brockwell & Davis 1991, *Time Series: Theory and Methods*,
//! §3.1 and §4.4):
//!
//! `ε_t = ρ ε_{t−1} + η_t`, `η_t ~ N(0, σ²(1 − ρ²))`,
//!
//! stationary with marginal standard deviation `σ` and autocorrelation `ρ^|k|`, whose one-sided
//! power spectral density at frequency `f` sampled at `fs` is
//!
//! `S(f) = (2σ²(1 − ρ²)/fs) / (1 − 2ρ cos(2πf/fs) + ρ²)`.
//!
//! `ρ = 0` is white noise, `S = 2σ²/fs` at every frequency; `ρ > 0` raises the low frequencies by
//! `(1 + ρ)/(1 − ρ)` at 0 Hz and lowers Nyquist by `(1 − ρ)/(1 + ρ)`. A white-noise estimate from
//! second differences, `Var Δ²ε = σ²(6 − 8ρ + 2ρ²)` (Brockwell & Davis §3.1 applied to the filter
//! `1 − 2B + B²`), reads `σ√(1 − 4ρ/3 + ρ²/3)`: 0.57σ at `ρ = 0.6`.
//!
//! Units: `σ` in the signal's units (m), frequencies in Hz, PSD in units²/Hz (density scaling).

use super::welch::{Scaling, WelchConfig};
use super::window::WindowSums;
use rand_distr::Distribution;

/// Largest `|ρ|` the model takes: beyond it the process is a random walk over a recording's length
/// and its spectrum a line at 0 Hz, not a noise floor.
pub const MAX_ABS_RHO: f64 = 0.99;

/// A stationary AR(1) tracking noise: marginal standard deviation and lag-one autocorrelation.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TrackingNoise {
    /// Marginal standard deviation `σ`, signal units (m).
    pub sigma_m: f64,
    /// Lag-one autocorrelation `ρ`, `|ρ| ≤` [`MAX_ABS_RHO`]; 0 for white noise.
    pub rho: f64,
}

impl TrackingNoise {
    /// White noise of standard deviation `sigma_m`.
    pub fn white(sigma_m: f64) -> Self {
        TrackingNoise { sigma_m, rho: 0.0 }
    }

    /// AR(1) noise of marginal standard deviation `sigma_m` and lag-one autocorrelation `rho`
    /// (clamped to `±`[`MAX_ABS_RHO`]).
    pub fn ar1(sigma_m: f64, rho: f64) -> Self {
        TrackingNoise {
            sigma_m,
            rho: rho.clamp(-MAX_ABS_RHO, MAX_ABS_RHO),
        }
    }

    /// One-sided PSD density at `freq_hz` for a sampling rate `fs_hz`, units²/Hz (module docs).
    pub fn density(&self, freq_hz: f64, fs_hz: f64) -> f64 {
        self.density_at_cos((std::f64::consts::TAU * freq_hz / fs_hz).cos(), fs_hz)
    }

    /// [`TrackingNoise::density`] at the frequency whose `cos(2πf/fs)` is `cos_w`: for a bin grid
    /// whose cosines are computed once.
    pub fn density_at_cos(&self, cos_w: f64, fs_hz: f64) -> f64 {
        let r = self.rho;
        2.0 * self.sigma_m * self.sigma_m * (1.0 - r * r) / fs_hz / (1.0 - 2.0 * r * cos_w + r * r)
    }

    /// The noise's expected Welch ordinate at `freq_hz` as an estimate with settings `cfg` reads
    /// it: [`TrackingNoise::density`] times [`ordinate_per_density`]. The spectrum is taken as flat
    /// over the window's main lobe, which holds to a few per cent for `ρ ≤ 0.9` at the bins a
    /// likelihood reads (a main lobe away from 0 Hz).
    pub fn welch_ordinate(&self, freq_hz: f64, fs_hz: f64, cfg: &WelchConfig) -> f64 {
        self.density(freq_hz, fs_hz) * ordinate_per_density(fs_hz, cfg)
    }

    /// `n` samples of the stationary process (the first drawn from the marginal law), from `rng`.
    ///
    /// # Panics
    /// Never for a finite `σ ≥ 0`; a NaN or negative `σ` is no normal distribution's and gives NaN
    /// samples.
    pub fn sample(&self, n: usize, rng: &mut impl rand::Rng) -> Vec<f64> {
        let unit = rand_distr::StandardNormal;
        let innovation = self.sigma_m * (1.0 - self.rho * self.rho).sqrt();
        let mut out = Vec::with_capacity(n);
        let mut e = 0.0;
        for i in 0..n {
            let z: f64 = unit.sample(rng);
            e = if i == 0 {
                self.sigma_m * z
            } else {
                self.rho * e + innovation * z
            };
            out.push(e);
        }
        out
    }
}

/// What a Welch estimate with settings `cfg` reads for a flat density of 1 unit²/Hz: 1 for density
/// scaling, the window's equivalent noise bandwidth `fs·Σh²/(Σh)²` (Hz) for spectrum scaling.
pub fn ordinate_per_density(fs_hz: f64, cfg: &WelchConfig) -> f64 {
    match cfg.scaling {
        Scaling::Density => 1.0,
        Scaling::Spectrum => {
            let s = WindowSums::of(&cfg.window.periodic(cfg.nperseg));
            fs_hz * s.sum_sq / (s.sum * s.sum)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn white_density_is_two_sigma_squared_over_fs() {
        // ρ = 0: S = 2σ²/fs at every frequency (one-sided density of white noise).
        let n = TrackingNoise::white(2.0);
        for f in [0.0, 100.0, 2500.0, 5000.0] {
            assert!((n.density(f, 10_000.0) - 8.0 / 10_000.0).abs() < 1e-18);
        }
    }

    #[test]
    fn ar1_density_integrates_to_the_variance_and_has_its_end_ratios() {
        // ∫_0^{fs/2} S df = σ² (Parseval); S(0)/S_white = (1+ρ)/(1−ρ), S(fs/2)/S_white = (1−ρ)/(1+ρ).
        let (fs, sigma, rho) = (10_000.0, 1.5, 0.6);
        let n = TrackingNoise::ar1(sigma, rho);
        let m = 200_000;
        let df = fs / 2.0 / m as f64;
        let integral: f64 = (0..m)
            .map(|i| n.density((i as f64 + 0.5) * df, fs) * df)
            .sum();
        assert!(
            (integral / (sigma * sigma) - 1.0).abs() < 1e-6,
            "{integral}"
        );
        let white = 2.0 * sigma * sigma / fs;
        assert!((n.density(0.0, fs) / white - 4.0).abs() < 1e-12);
        assert!((n.density(fs / 2.0, fs) / white - 0.25).abs() < 1e-12);
    }

    #[test]
    fn samples_have_the_marginal_variance_and_lag_one_correlation() {
        // 200k samples: the sample variance and lag-one correlation within 5 standard errors of σ²
        // and ρ (the variance of an AR(1) sample variance is ≈ 2σ⁴(1+ρ²)/((1−ρ²)n)).
        let (sigma, rho, n) = (0.3, 0.8, 200_000);
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let x = TrackingNoise::ar1(sigma, rho).sample(n, &mut rng);
        let var = x.iter().map(|v| v * v).sum::<f64>() / n as f64;
        let lag1 = x.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (n - 1) as f64;
        let se_var =
            sigma * sigma * (2.0 * (1.0 + rho * rho) / ((1.0 - rho * rho) * n as f64)).sqrt();
        assert!((var - sigma * sigma).abs() < 5.0 * se_var, "{var}");
        assert!((lag1 / var - rho).abs() < 5.0 * (1.0 - rho * rho) / (n as f64).sqrt() * 3.0);
    }
}
