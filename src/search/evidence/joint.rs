//! Several tracked signals read together: each band's Welch cross-spectral matrices of the fit's
//! signal and the `[fit.likelihood] joint_signals` through the multivariate Whittle likelihood
//! ([`crate::likelihood::multivariate`]; docs/likelihood.md, "Several signals").
//!
//! - **Expected matrices.** Per band and bin, the simulation's cross-spectral matrix of the same
//!   signals, with the recording's missing samples and short gaps filled as the recording's
//!   ([`WelchPlan::cross_spectra_gappy`]), plus each signal's tracking-noise ordinate on the
//!   diagonal. Each signal's noise is estimated as the fit's one signal's is (its own σ̂ from
//!   second differences, or the `ar1` profile against its own ordinates,
//!   [`RecordingLikelihood::noise_for`]); signals of separate tracked coordinates have
//!   independent noises, so the noise adds nothing off the diagonal.
//! - **Fisher information.** The Gauss–Newton form of the complex-Wishart likelihood at the fit's
//!   expected matrices `S₀ = L Lᴴ`: `(n/φ)·Σ_k Re tr(S₀⁻¹ ∂_i S S₀⁻¹ ∂_j S)` (Whittle 1953) is
//!   `(n/φ)·Σ ∂_i w · ∂_j w` over the real entries `w` of the whitened matrix `L⁻¹ S L⁻ᴴ` (its
//!   diagonal, and √2 times the real and imaginary parts above it), so the response is those
//!   entries and every weight is `n/φ`: for one signal, `S/S₀`, whose derivative at the fit is
//!   `∂ ln S`, the one-signal response. The score of a noise replicate is the same sum with the
//!   whitened `S − P̂` as the residual ([`MultivariateWhittle::score`]).

use super::{BandTerm, RecordingLikelihood, SpectralProblem};
use crate::Result;
use crate::likelihood::multivariate::MultivariateWhittle;
use crate::likelihood::{self, LikelihoodError};
use crate::simulate::blade::BladeSimulation;
use crate::spectrum::features::SignalKind;
use crate::spectrum::noise::TrackingNoise;
use crate::spectrum::welch::{WelchConfig, WelchPlan};
use crate::trace::Trace;
use nalgebra::{Complex, DMatrix};

/// One band's cross-spectral matrices, one per bin, row-major `p × p` entries.
pub(super) type Matrices = Vec<Vec<Complex<f64>>>;

/// One band's measured side.
struct JointBand {
    cfg: WelchConfig,
    /// The FFT bins of the band's interior bins ([`BandTerm`]'s).
    fft_bins: Vec<usize>,
    lik: MultivariateWhittle,
    measured: Matrices,
}

/// The measured side of the signals read together, built once per fit.
pub(super) struct JointSignals {
    /// The signals, the fit's own first.
    pub(super) kinds: Vec<SignalKind>,
    /// Each signal's white-noise σ̂ from its second differences, m.
    pub(super) sigma_m: Vec<f64>,
    /// The measured signals, NaN where any of them is missing or the problem masks.
    measured_x: Vec<Vec<f64>>,
    bands: Vec<JointBand>,
    /// Each signal's measured ordinates per band: the matrices' diagonals, `[signal][band][bin]`.
    diag: Vec<Vec<Vec<f64>>>,
    /// The bands' NLL at `S = P̂`, nats.
    saturated_nats: f64,
}

/// The whitening of every bin at the fit's expected matrices: `L⁻¹` per bin, bands in order.
pub(super) struct Metric {
    inverse_factors: Vec<DMatrix<Complex<f64>>>,
}

impl JointSignals {
    /// The signals `kinds` (the fit's own first) of the recording `trace`, read in the bands of
    /// `lik` (the fit's one-signal likelihood, whose interior bins they share).
    ///
    /// # Errors
    /// A signal the trace cannot give, the cross-spectra's errors,
    /// [`LikelihoodError::TooFewSegmentsForSignals`] for a band whose segments cannot carry the
    /// signals' matrix, and a signal without an estimable noise.
    pub(super) fn new(
        lik: &RecordingLikelihood,
        problem: &SpectralProblem,
        trace: &Trace,
        kinds: Vec<SignalKind>,
    ) -> Result<Self> {
        let mut x: Vec<Vec<f64>> = kinds
            .iter()
            .map(|k| k.extract(trace))
            .collect::<Result<_>>()?;
        let missing: Vec<bool> = (0..x[0].len())
            .map(|t| {
                problem.nan_mask.get(t).copied().unwrap_or(false)
                    || x.iter().any(|s| !s[t].is_finite())
            })
            .collect();
        for s in &mut x {
            for (v, m) in s.iter_mut().zip(&missing) {
                if *m {
                    *v = f64::NAN;
                }
            }
        }
        let sigma_m = x
            .iter()
            .map(|s| likelihood::tracking_noise_sigma(s))
            .collect::<std::result::Result<Vec<f64>, _>>()?;
        let mut bands = Vec::with_capacity(lik.bands.len());
        for (term, spec) in lik.bands.iter().zip(&problem.bands) {
            let cfg = spec.welch_config()?;
            let fft_bins: Vec<usize> = term
                .freq_hz
                .iter()
                .map(|f| (f * cfg.nfft as f64 / problem.fs_hz).round() as usize)
                .collect();
            let refs: Vec<&[f64]> = x.iter().map(Vec::as_slice).collect();
            let c = WelchPlan::new(cfg)?.cross_spectra_gappy(
                &refs,
                problem.fs_hz,
                &fft_bins,
                problem.max_fill,
            )?;
            bands.push(JointBand {
                lik: MultivariateWhittle::new(&cfg, c.n_segments, fft_bins.len(), kinds.len())?,
                cfg,
                fft_bins,
                measured: c.matrices,
            });
        }
        let mut joint = JointSignals {
            diag: Vec::new(),
            kinds,
            sigma_m,
            measured_x: x,
            bands,
            saturated_nats: 0.0,
        };
        joint.diag = joint.diagonals(&joint.measured());
        joint.saturated_nats = joint
            .bands
            .iter()
            .map(|b| b.lik.nll(&b.measured, &b.measured))
            .sum::<std::result::Result<f64, _>>()?;
        Ok(joint)
    }

    /// Signals read together, `p`.
    fn p(&self) -> usize {
        self.kinds.len()
    }

    /// The measured matrices of every band.
    fn measured(&self) -> Vec<Matrices> {
        self.bands.iter().map(|b| b.measured.clone()).collect()
    }

    /// Each signal's ordinates per band, the diagonals of `m` (`[signal][band][bin]`).
    fn diagonals(&self, m: &[Matrices]) -> Vec<Vec<Vec<f64>>> {
        let p = self.p();
        (0..p)
            .map(|a| {
                m.iter()
                    .map(|band| band.iter().map(|s| s[a * p + a].re).collect())
                    .collect()
            })
            .collect()
    }

    /// The cross-spectral matrices of `signals` (the signals' samples in order, NaN where
    /// missing) in every band.
    fn spectra_of(&self, signals: &[Vec<f64>], problem: &SpectralProblem) -> Result<Vec<Matrices>> {
        let refs: Vec<&[f64]> = signals.iter().map(Vec::as_slice).collect();
        self.bands
            .iter()
            .map(|b| {
                Ok(WelchPlan::new(b.cfg)?
                    .cross_spectra_gappy(&refs, problem.fs_hz, &b.fft_bins, problem.max_fill)?
                    .matrices)
            })
            .collect()
    }

    /// The simulation's signals at the recording's samples, NaN where the recording's are.
    pub(super) fn model_signals(&self, sim: &BladeSimulation) -> Result<Vec<Vec<f64>>> {
        let trace = sim.to_trace();
        self.kinds
            .iter()
            .zip(&self.measured_x)
            .map(|(k, d)| {
                let mut x = k.extract(&trace)?;
                for (v, d) in x.iter_mut().zip(d) {
                    if !d.is_finite() {
                        *v = f64::NAN;
                    }
                }
                Ok(x)
            })
            .collect()
    }

    /// The simulation's own matrices (no noise) of every band.
    pub(super) fn sim_matrices(
        &self,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
    ) -> Result<Vec<Matrices>> {
        self.spectra_of(&self.model_signals(sim)?, problem)
    }

    /// Each signal's tracking noise beside the simulation's matrices `sim`, read from the
    /// ordinates `measured_diag` (`[signal][band][bin]`) with white-noise σ̂ `white_sigma_m`.
    fn noises(
        &self,
        lik: &RecordingLikelihood,
        sim: &[Matrices],
        measured_diag: &[Vec<Vec<f64>>],
        white_sigma_m: &[f64],
    ) -> Vec<TrackingNoise> {
        let sim_diag = self.diagonals(sim);
        sim_diag
            .iter()
            .zip(measured_diag)
            .zip(white_sigma_m)
            .map(|((s, d), sigma)| {
                let views: Vec<&[f64]> = d.iter().map(Vec::as_slice).collect();
                lik.noise_for(s, &views, *sigma)
            })
            .collect()
    }

    /// The expected matrices: `sim` plus each signal's noise ordinates on the diagonal.
    fn expected(
        &self,
        lik: &RecordingLikelihood,
        sim: &[Matrices],
        noises: &[TrackingNoise],
    ) -> Vec<Matrices> {
        let p = self.p();
        sim.iter()
            .zip(&lik.bands)
            .map(|(band, term): (&Matrices, &BandTerm)| {
                let ordinates: Vec<Vec<f64>> = noises
                    .iter()
                    .map(|n| term.noise_ordinates(n, lik.fs_hz))
                    .collect();
                band.iter()
                    .enumerate()
                    .map(|(k, m)| {
                        let mut m = m.clone();
                        for (a, o) in ordinates.iter().enumerate() {
                            m[a * p + a] += o[k];
                        }
                        m
                    })
                    .collect()
            })
            .collect()
    }

    /// The model's expected matrices at the simulation `sim`, the recording's noise estimates.
    ///
    /// # Errors
    /// The simulation's signals' and cross-spectra's errors.
    pub(super) fn model(
        &self,
        lik: &RecordingLikelihood,
        problem: &SpectralProblem,
        sim: &BladeSimulation,
    ) -> Result<Vec<Matrices>> {
        let s = self.sim_matrices(problem, sim)?;
        let noises = self.recording_noises(lik, &s);
        Ok(self.expected(lik, &s, &noises))
    }

    /// Each band's NLL, nats, of the recording's matrices given `expected`.
    pub(super) fn nll(&self, expected: &[Matrices]) -> Result<Vec<f64>> {
        self.bands
            .iter()
            .zip(expected)
            .map(|(b, s)| Ok(b.lik.nll(&b.measured, s)?))
            .collect()
    }

    /// The bands' NLL at `S = P̂`, nats.
    pub(super) fn saturated_nats(&self) -> f64 {
        self.saturated_nats
    }

    /// The bands' effectively independent bins.
    pub(super) fn effective_bins(&self) -> f64 {
        self.bands
            .iter()
            .map(|b| b.lik.welch.effective_bins())
            .sum()
    }

    /// Components of the spectral response: `p²` per bin.
    pub(super) fn response_len(&self) -> usize {
        let p = self.p();
        self.bands.iter().map(|b| b.fft_bins.len() * p * p).sum()
    }

    /// The spectral response's weights, `n/φ` per component (module docs).
    pub(super) fn weights(&self) -> Vec<f64> {
        let p = self.p();
        self.bands
            .iter()
            .flat_map(|b| {
                std::iter::repeat_n(
                    b.lik.welch.dof / 2.0 / b.lik.welch.bin_factor,
                    b.fft_bins.len() * p * p,
                )
            })
            .collect()
    }

    /// The real entries of every band's matrices `m` in the response's order ([`entries`]).
    pub(super) fn entries(&self, m: &[Matrices]) -> Vec<f64> {
        entries(self.p(), m.iter().flatten())
    }

    /// The whitening at the expected matrices `expected` ([`metric`]).
    ///
    /// # Errors
    /// [`LikelihoodError::NonPositivePsd`] for a matrix that is not positive definite.
    pub(super) fn metric(&self, expected: &[Matrices]) -> Result<Metric> {
        Ok(metric(self.p(), expected.iter().flatten())?)
    }

    /// The entries `v` whitened by `metric` ([`whiten`]).
    pub(super) fn whiten(&self, metric: &Metric, v: &[f64]) -> Vec<f64> {
        whiten(self.p(), metric, v)
    }

    /// A noise replicate's spectral residuals in the response's order, whitened by `metric`: the
    /// expected matrices from the simulation's `sim` and the replicate's own noise estimates,
    /// minus the replicate's Welch matrices. `signals`: the replicate's signals.
    ///
    /// # Errors
    /// The cross-spectra's and the noise estimates' errors.
    pub(super) fn replicate_residuals(
        &self,
        lik: &RecordingLikelihood,
        problem: &SpectralProblem,
        sim: &[Matrices],
        signals: &[Vec<f64>],
        metric: &Metric,
    ) -> Result<Vec<f64>> {
        let measured = self.spectra_of(signals, problem)?;
        let sigma = signals
            .iter()
            .map(|s| likelihood::tracking_noise_sigma(s))
            .collect::<std::result::Result<Vec<f64>, _>>()?;
        let noises = self.noises(lik, sim, &self.diagonals(&measured), &sigma);
        let expected = self.entries(&self.expected(lik, sim, &noises));
        let measured = self.entries(&measured);
        let residual: Vec<f64> = expected.iter().zip(&measured).map(|(s, p)| s - p).collect();
        Ok(self.whiten(metric, &residual))
    }

    /// The noises the recording's likelihood reads at the simulation matrices `sim`.
    pub(super) fn recording_noises(
        &self,
        lik: &RecordingLikelihood,
        sim: &[Matrices],
    ) -> Vec<TrackingNoise> {
        self.noises(lik, sim, &self.diag, &self.sigma_m)
    }
}

/// The real entries of `p × p` Hermitian matrices (row-major entries) in the response's order:
/// per matrix the diagonal, then the real and imaginary parts above it (`p²` numbers).
fn entries<'a>(p: usize, m: impl Iterator<Item = &'a Vec<Complex<f64>>>) -> Vec<f64> {
    let mut out = Vec::new();
    for s in m {
        out.extend((0..p).map(|a| s[a * p + a].re));
        for a in 0..p {
            for b in a + 1..p {
                out.push(s[a * p + b].re);
                out.push(s[a * p + b].im);
            }
        }
    }
    out
}

/// `L⁻¹` of the Cholesky factor `S = L Lᴴ` of each `p × p` matrix of `expected`.
///
/// # Errors
/// [`LikelihoodError::NonPositivePsd`] for a matrix that is not positive definite (its place as
/// the index).
fn metric<'a>(
    p: usize,
    expected: impl Iterator<Item = &'a Vec<Complex<f64>>>,
) -> std::result::Result<Metric, LikelihoodError> {
    let inverse_factors = expected
        .enumerate()
        .map(|(index, s)| {
            let l = DMatrix::from_row_slice(p, p, s).cholesky().ok_or(
                LikelihoodError::NonPositivePsd {
                    side: likelihood::Side::Model,
                    index,
                    value: s[0].re,
                },
            )?;
            Ok(l.l()
                .solve_lower_triangular(&DMatrix::identity(p, p))
                .expect("a Cholesky factor has a non-zero diagonal"))
        })
        .collect::<std::result::Result<_, _>>()?;
    Ok(Metric { inverse_factors })
}

/// The entries `v` ([`entries`]' order) whitened by `metric`: per matrix `X`, `L⁻¹ X L⁻ᴴ`'s
/// diagonal, then √2 times the real and imaginary parts above it, so that the dot product of two
/// whitened vectors is `Σ Re tr(S⁻¹ X S⁻¹ Y)` (module docs). Linear in `v`.
fn whiten(p: usize, metric: &Metric, v: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(v.len());
    for (chunk, linv) in v.chunks(p * p).zip(&metric.inverse_factors) {
        let mut x = DMatrix::<Complex<f64>>::zeros(p, p);
        for a in 0..p {
            x[(a, a)] = Complex::new(chunk[a], 0.0);
        }
        let mut i = p;
        for a in 0..p {
            for b in a + 1..p {
                let z = Complex::new(chunk[i], chunk[i + 1]);
                x[(a, b)] = z;
                x[(b, a)] = z.conj();
                i += 2;
            }
        }
        let w = linv * x * linv.adjoint();
        out.extend((0..p).map(|a| w[(a, a)].re));
        for a in 0..p {
            for b in a + 1..p {
                out.push(std::f64::consts::SQRT_2 * w[(a, b)].re);
                out.push(std::f64::consts::SQRT_2 * w[(a, b)].im);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::welch::WelchConfig;
    use rand::{Rng, SeedableRng};

    /// A random `p × p` Hermitian matrix, positive definite when `pd`.
    fn hermitian(p: usize, rng: &mut impl Rng, pd: bool) -> Vec<Complex<f64>> {
        let a = DMatrix::<Complex<f64>>::from_fn(p, p, |_, _| {
            Complex::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
        });
        let h = if pd {
            &a * a.adjoint() + DMatrix::identity(p, p) * Complex::new(0.1, 0.0)
        } else {
            &a + a.adjoint()
        };
        (0..p * p).map(|i| h[(i / p, i % p)]).collect()
    }

    #[test]
    fn whitened_entries_give_the_complex_wishart_fisher_information_and_score() {
        // Reference: MultivariateWhittle::fisher and ::score, which evaluate the trace formula
        // (n/φ)·Σ Re tr(S⁻¹ ∂_i S S⁻¹ ∂_j S) and (n/φ)·Σ Re tr(S⁻¹ ∂_i S S⁻¹ (S − P̂)) directly
        // with complex matrix products (Whittle 1953). The whitened entries' dot products, with
        // weight n/φ, must agree to rounding for p = 1, 2, 3.
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let cfg = WelchConfig::new(64);
        for p in 1..=3 {
            let bins = 5;
            let w = MultivariateWhittle::new(&cfg, 40, bins, p).unwrap();
            let model: Matrices = (0..bins).map(|_| hermitian(p, &mut rng, true)).collect();
            let measured: Matrices = (0..bins).map(|_| hermitian(p, &mut rng, true)).collect();
            let derivs: Vec<Matrices> = (0..3)
                .map(|_| (0..bins).map(|_| hermitian(p, &mut rng, false)).collect())
                .collect();
            let m = metric(p, model.iter()).unwrap();
            let weight = w.welch.dof / 2.0 / w.welch.bin_factor;
            let cols: Vec<Vec<f64>> = derivs
                .iter()
                .map(|d| whiten(p, &m, &entries(p, d.iter())))
                .collect();
            let f = w.fisher(&model, &derivs).unwrap();
            let dot =
                |a: &[f64], b: &[f64]| weight * a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
            for i in 0..3 {
                for j in 0..3 {
                    let got = dot(&cols[i], &cols[j]);
                    assert!(
                        (got - f[(i, j)]).abs() <= 1e-10 * f[(i, i)].abs().max(1.0),
                        "p {p} F[{i},{j}] {got} vs {}",
                        f[(i, j)]
                    );
                }
            }
            let residual: Vec<f64> = entries(p, model.iter())
                .iter()
                .zip(entries(p, measured.iter()))
                .map(|(s, q)| s - q)
                .collect();
            let r = whiten(p, &m, &residual);
            let score = w.score(&measured, &model, &derivs).unwrap();
            for (i, c) in cols.iter().enumerate() {
                let got = dot(c, &r);
                assert!(
                    (got - score[i]).abs() <= 1e-10 * score[i].abs().max(1.0),
                    "p {p} score[{i}] {got} vs {}",
                    score[i]
                );
            }
        }
    }

    #[test]
    fn one_signal_whitens_to_the_relative_change_and_a_singular_matrix_is_refused() {
        // p = 1: L⁻¹ X L⁻ᴴ = X/S₀, the derivative of ln S at S₀ (the one-signal response).
        let s0 = [vec![Complex::new(4.0, 0.0)]];
        let m = metric(1, s0.iter()).unwrap();
        assert_eq!(whiten(1, &m, &[2.0]), vec![0.5]);
        // A rank-one 2 × 2 matrix has no Cholesky factor: a typed error, no NaN.
        let one = Complex::new(1.0, 0.0);
        let singular = [vec![one, one, one, one]];
        assert!(matches!(
            metric(2, singular.iter()),
            Err(LikelihoodError::NonPositivePsd { .. })
        ));
    }
}
