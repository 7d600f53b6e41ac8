//! The drive read back from the tracked head.
//!
//! The model prescribes the head's horizontal motion, `v = a(1 − cos ωt) + (h·a/2)·sin 2ωt`
//! (seed eq. 5 with a second harmonic of the speed; docs/blade.md), and the camera films it: the
//! tracked head x is that drive plus the camera's origin and tracking noise. A linear least-squares
//! fit of the head x to `x₀ + β₁ cos ωt + β₂ sin ωt + β₃ sin 2ωt`, with the blade file's ω, reads
//! back `a = −β₁`, `h = −2β₃/β₁` and the clock offset `δ = −β₂/(β₁ω)` (`v(t + δ) ≈ v(t) + δ·aω
//! sin ωt`), so the fit can check the blade file's drive against the recording, or take its second
//! harmonic from it (`[fit] drive = "recording"`).
//!
//! Standard errors are the regression's (`σ²(XᵀX)⁻¹`, σ² from the residuals), each variance
//! multiplied by `(1 + ρ)/(1 − ρ)`, never less than 1, for the residuals' lag-one correlation ρ
//! over consecutive tracked frames (tracking noise that is correlated from frame to frame carries
//! less information per frame: the AR(1) variance inflation, Bartlett 1946; Box, Jenkins &
//! Reinsel, *Time Series Analysis*, §2.1.5), and `h`'s and `δ`'s by the delta method.

use nalgebra::{DMatrix, DVector, Matrix4, Vector3};
use serde::{Deserialize, Serialize};

/// Fewer tracked head samples than this cannot separate the four terms from the noise.
pub const MIN_DRIVE_SAMPLES: usize = 16;

/// The drive's terms as read from the tracked head x ([`read_drive`]), with their standard errors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DriveReading {
    /// Drive amplitude a, m (negative: the camera's x runs against the sweep).
    pub amplitude_m: f64,
    /// Its standard error, m.
    pub amplitude_se_m: f64,
    /// Second harmonic of the drive speed h, a fraction of the peak speed aω
    /// ([`crate::model::BladeParams::drive_speed_harmonic`]).
    pub speed_harmonic: f64,
    /// Its standard error.
    pub speed_harmonic_se: f64,
    /// Clock offset δ, s: the head is where the blade's drive puts it δ later (the import's
    /// `t0_s` is δ early).
    pub clock_offset_s: f64,
    /// Its standard error, s.
    pub clock_offset_se_s: f64,
    /// RMS of the residuals, m: the tracking noise, if the drive form holds.
    pub residual_rms_m: f64,
    /// Lag-one correlation of the residuals.
    pub residual_lag_one: f64,
    /// Tracked samples read (frames where the head was lost are skipped).
    pub samples: usize,
}

/// A reading departs from the drive the fit used only beyond this many standard errors.
pub const DEPARTURE_Z: f64 = 4.0;

/// A second harmonic departs when it differs from the fit's by at least this fraction of the
/// drive's peak speed aω (and by [`DEPARTURE_Z`] standard errors).
pub const HARMONIC_TOLERANCE: f64 = 0.01;

/// An amplitude departs when it differs from the blade file's by at least this fraction (and by
/// [`DEPARTURE_Z`] standard errors).
pub const AMPLITUDE_TOLERANCE: f64 = 0.01;

/// The drive the fit used beside the one the tracked head shows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DriveCheck {
    /// The drive read from the tracked head x.
    pub reading: DriveReading,
    /// The blade file's drive amplitude a, m.
    pub blade_amplitude_m: f64,
    /// The blade file's second harmonic h.
    pub blade_speed_harmonic: f64,
    /// The second harmonic the fit used: the blade file's, or the reading's with `[fit] drive =
    /// "recording"`.
    pub fitted_speed_harmonic: f64,
}

impl DriveCheck {
    /// The reading's second harmonic lies beyond [`DEPARTURE_Z`] standard errors and
    /// [`HARMONIC_TOLERANCE`] of the one the fit used.
    pub fn harmonic_departs(&self) -> bool {
        let r = &self.reading;
        let d = (r.speed_harmonic - self.fitted_speed_harmonic).abs();
        d >= HARMONIC_TOLERANCE && d > DEPARTURE_Z * r.speed_harmonic_se
    }

    /// The reading's amplitude lies beyond [`DEPARTURE_Z`] standard errors and
    /// [`AMPLITUDE_TOLERANCE`] of the blade file's.
    pub fn amplitude_departs(&self) -> bool {
        let r = &self.reading;
        let d = (r.amplitude_m - self.blade_amplitude_m).abs();
        d >= AMPLITUDE_TOLERANCE * self.blade_amplitude_m.abs()
            && d > DEPARTURE_Z * r.amplitude_se_m
    }
}

/// Why the drive could not be read back.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DriveReadingError {
    /// Too few tracked head samples.
    #[error(
        "the head is tracked in {samples} frames, fewer than the {MIN_DRIVE_SAMPLES} the drive's four terms need"
    )]
    TooFewSamples { samples: usize },
    /// The window does not separate the terms (a window much shorter than the drive's period).
    #[error(
        "the recording's window does not separate the drive's terms (its least-squares system is singular)"
    )]
    Singular,
}

/// Reads the drive's amplitude, second harmonic and clock offset from the head's tracked x
/// (`head_x_m`, m, NaN where lost) at times `t_s` (s, on the model clock), for the drive's angular
/// frequency `omega_rad_per_s` (rad/s, the blade file's `v_max/a`).
///
/// # Errors
/// [`DriveReadingError::TooFewSamples`] below [`MIN_DRIVE_SAMPLES`] tracked samples;
/// [`DriveReadingError::Singular`] when the window cannot separate the terms.
pub fn read_drive(
    t_s: &[f64],
    head_x_m: &[f64],
    omega_rad_per_s: f64,
) -> Result<DriveReading, DriveReadingError> {
    let (rows, x): (Vec<[f64; 4]>, Vec<f64>) = (t_s.iter().zip(head_x_m))
        .filter(|(t, x)| t.is_finite() && x.is_finite())
        .map(|(&t, &x)| {
            let w = omega_rad_per_s * t;
            ([1.0, w.cos(), w.sin(), (2.0 * w).sin()], x)
        })
        .unzip();
    let n = rows.len();
    if n < MIN_DRIVE_SAMPLES {
        return Err(DriveReadingError::TooFewSamples { samples: n });
    }
    let design = DMatrix::from_fn(n, 4, |i, j| rows[i][j]);
    let y = DVector::from_vec(x);
    let svd = design.clone().svd(true, true);
    let sv = &svd.singular_values;
    if sv.min() <= 1e-12 * sv.max() {
        return Err(DriveReadingError::Singular);
    }
    let beta = svd
        .solve(&y, 0.0)
        .map_err(|_| DriveReadingError::Singular)?;
    let residual = &y - &design * &beta;
    let rss = residual.norm_squared();
    let lag_one = lag_one_correlation(residual.as_slice());
    let inflation = ((1.0 + lag_one) / (1.0 - lag_one)).max(1.0);
    // (XᵀX)⁻¹ = V Σ⁻² Vᵀ from the decomposition the solution came from.
    let v_t = svd.v_t.as_ref().ok_or(DriveReadingError::Singular)?;
    let cov: Matrix4<f64> =
        (v_t.transpose() * DMatrix::from_diagonal(&sv.map(|s| s.powi(-2))) * v_t)
            .fixed_view::<4, 4>(0, 0)
            .scale(rss / (n - 4) as f64 * inflation);
    let (b1, b2, b3) = (beta[1], beta[2], beta[3]);
    if b1 == 0.0 {
        return Err(DriveReadingError::Singular);
    }
    // h = −2β₃/β₁ and δ = −β₂/(β₁ω): gradients for the delta method over (β₁, β₂, β₃).
    let block = cov.fixed_view::<3, 3>(1, 1);
    let var = |g: Vector3<f64>| g.dot(&(block * g)).max(0.0);
    let h_grad = Vector3::new(2.0 * b3 / (b1 * b1), 0.0, -2.0 / b1);
    let w = omega_rad_per_s;
    let d_grad = Vector3::new(b2 / (b1 * b1 * w), -1.0 / (b1 * w), 0.0);
    Ok(DriveReading {
        amplitude_m: -b1,
        amplitude_se_m: cov[(1, 1)].max(0.0).sqrt(),
        speed_harmonic: -2.0 * b3 / b1,
        speed_harmonic_se: var(h_grad).sqrt(),
        clock_offset_s: -b2 / (b1 * w),
        clock_offset_se_s: var(d_grad).sqrt(),
        residual_rms_m: (rss / n as f64).sqrt(),
        residual_lag_one: lag_one,
        samples: n,
    })
}

/// Lag-one autocorrelation of `r` (mean removed), 0 for fewer than three samples.
fn lag_one_correlation(r: &[f64]) -> f64 {
    if r.len() < 3 {
        return 0.0;
    }
    let mean = r.iter().sum::<f64>() / r.len() as f64;
    let var: f64 = r.iter().map(|v| (v - mean).powi(2)).sum();
    if var == 0.0 {
        return 0.0;
    }
    let cov: f64 = r.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum();
    (cov / var).clamp(-0.99, 0.99)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_distr::{Distribution, Normal};

    /// A head x made by the drive's own formula over the reversal window (ωt from π/2 to 3π/2),
    /// with an origin offset, a clock offset δ and white noise of σ.
    fn head_x(a: f64, h: f64, delta: f64, sigma: f64, seed: u64) -> (Vec<f64>, Vec<f64>, f64) {
        let w = 2.0 * std::f64::consts::PI * 0.8;
        let fs = 10_000.0;
        let (t0, t1) = (
            0.5 * std::f64::consts::PI / w,
            1.5 * std::f64::consts::PI / w,
        );
        let n = ((t1 - t0) * fs) as usize;
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let noise = Normal::new(0.0, sigma).expect("sigma");
        let t: Vec<f64> = (0..n).map(|i| t0 + i as f64 / fs).collect();
        let x = t
            .iter()
            .map(|&t| {
                let s = w * (t + delta);
                0.003 + a * (1.0 - s.cos()) + 0.5 * h * a * (2.0 * s).sin() + noise.sample(&mut rng)
            })
            .collect();
        (t, x, w)
    }

    /// The drive's own terms come back: a and h exactly without noise, and the clock offset to
    /// the first order of its expansion (δ = 0.1 ms is ωδ = 5e-4 rad: second-order terms ~1e-7).
    #[test]
    fn reads_back_the_drive_it_was_made_with() {
        let (t, x, w) = head_x(0.05, -0.044, 0.0, 0.0, 1);
        let r = read_drive(&t, &x, w).expect("reading");
        assert!((r.amplitude_m - 0.05).abs() < 1e-12, "{r:?}");
        assert!((r.speed_harmonic + 0.044).abs() < 1e-12, "{r:?}");
        assert!(r.clock_offset_s.abs() < 1e-12, "{r:?}");
        let (t, x, w) = head_x(0.05, 0.03, 1e-4, 0.0, 1);
        let r = read_drive(&t, &x, w).expect("reading");
        assert!((r.clock_offset_s - 1e-4).abs() < 1e-7, "{r:?}");
        assert!((r.speed_harmonic - 0.03).abs() < 1e-3, "{r:?}");
    }

    /// Under white noise the standard errors are the spread of the estimates: over 200 noise
    /// draws the z-scores of h have a standard deviation within 0.8–1.2 (the 99 % band of a
    /// sample standard deviation of 200 normal draws is about ±0.13).
    #[test]
    fn standard_errors_match_the_spread_under_noise() {
        let z: Vec<f64> = (0..200)
            .map(|seed| {
                let (t, x, w) = head_x(0.05, 0.02, 0.0, 2e-6, seed);
                let r = read_drive(&t, &x, w).expect("reading");
                (r.speed_harmonic - 0.02) / r.speed_harmonic_se
            })
            .collect();
        let mean = z.iter().sum::<f64>() / z.len() as f64;
        let sd = (z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (z.len() - 1) as f64).sqrt();
        assert!((0.8..1.2).contains(&sd), "sd of z {sd}");
        assert!(mean.abs() < 0.25, "mean of z {mean}");
    }

    /// Lost frames are skipped; too few tracked frames is an error that says how many.
    #[test]
    fn lost_frames_are_skipped_and_too_few_is_an_error() {
        let (t, mut x, w) = head_x(0.05, 0.0, 0.0, 0.0, 1);
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        for v in x.iter_mut() {
            if rng.random::<f64>() < 0.3 {
                *v = f64::NAN;
            }
        }
        let r = read_drive(&t, &x, w).expect("reading");
        assert!((r.amplitude_m - 0.05).abs() < 1e-12 && r.samples < t.len());
        let err = read_drive(&t[..10], &x[..10], w).unwrap_err();
        assert!(
            matches!(err, DriveReadingError::TooFewSamples { .. }),
            "{err}"
        );
    }
}
