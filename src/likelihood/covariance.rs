//! The spread of an estimate from a likelihood's information: the covariance `F⁺` from a Fisher
//! information (its pseudo-inverse over the directions the data inform), the sandwich
//! `F⁺ V F⁺` with the variability `V` of the score, the sample covariance `V` is estimated with,
//! and the Cholesky factor that maps whitened coordinates onto the estimate's. The fit reads them
//! at its optimum ([`crate::search::evidence`]).

use nalgebra::DMatrix;

/// The sample covariance (divisor `n − 1`) of the vectors `x`.
pub fn sample_covariance(x: &[Vec<f64>]) -> DMatrix<f64> {
    let (n, k) = (x.len(), x.first().map_or(0, Vec::len));
    let mean: Vec<f64> = (0..k)
        .map(|i| x.iter().map(|v| v[i]).sum::<f64>() / n as f64)
        .collect();
    DMatrix::from_fn(k, k, |i, j| {
        x.iter()
            .map(|v| (v[i] - mean[i]) * (v[j] - mean[j]))
            .sum::<f64>()
            / (n.max(2) - 1) as f64
    })
}

/// The covariance matrix with 1σ `sigma` and correlations `corr` (the inverse of [`covariance`]'s
/// split).
pub fn covariance_of(sigma: &[f64], corr: &[Vec<f64>]) -> DMatrix<f64> {
    let k = sigma.len();
    DMatrix::from_fn(k, k, |i, j| corr[i][j] * sigma[i] * sigma[j])
}

/// The lower Cholesky factor `L` of the covariance with 1σ `sigma` and correlations `corr`
/// (`LLᵀ = Σ`; `u + L z` maps whitened coordinates `z` to normalised ones). `None` where a 1σ is
/// not finite (a coordinate without information) or the covariance is not positive definite.
pub fn cholesky_of_covariance(sigma: &[f64], corr: &[Vec<f64>]) -> Option<DMatrix<f64>> {
    if sigma.iter().any(|s| !s.is_finite()) {
        return None;
    }
    Some(covariance_of(sigma, corr).cholesky()?.l())
}

/// Covariance of the normalised coordinates from a Fisher information `f` (its pseudo-inverse over
/// the directions the data inform): per parameter the standard deviation (∞ where the parameter
/// loads on a direction with no information) and the correlation matrix (NaN there).
pub fn covariance(f: &DMatrix<f64>) -> (Vec<f64>, Vec<Vec<f64>>) {
    let (pinv, uninformed) = pseudo_inverse(f);
    spread(&pinv, &uninformed)
}

/// The sandwich covariance `F⁺ V F⁺` of the normalised coordinates for a Fisher information (the
/// NLL's expected Hessian) `f` and a variability (the variance of the NLL's gradient) `v`, with
/// `F⁺` the pseudo-inverse over the directions `f` informs (see [`crate::search::evidence::at_fit`] for why): per
/// parameter the standard deviation (∞ where the parameter loads on a direction with no
/// information) and the correlation matrix (NaN there). With `v = f` it is `F⁺`.
pub fn sandwich_covariance(f: &DMatrix<f64>, v: &DMatrix<f64>) -> (Vec<f64>, Vec<Vec<f64>>) {
    let (pinv, uninformed) = pseudo_inverse(f);
    spread(&(&pinv * v * &pinv), &uninformed)
}

/// Takeuchi's effective number of parameters `tr(F⁺V)` for a Fisher information (the NLL's
/// expected Hessian) `f` and a variability (the variance of the NLL's gradient) `v`: the bias of the
/// maximised log-likelihood as an estimate of the expected log-likelihood of new data, so that
/// `TIC = 2·NLL + 2·tr(F⁺V)` compares models whose likelihood is misspecified or composite
/// (Takeuchi 1976, *Suri-Kagaku* 153:12; Konishi & Kitagawa 2008, *Information Criteria and
/// Statistical Modeling*, §3.4.3, eq. 3.112). Where the likelihood is right, `V = F` and the trace
/// is the number of informed directions (Akaike's `k`); a direction `f` does not inform (a
/// parameter the recording leaves flat) adds nothing, since the fit cannot tune it to the noise.
pub fn effective_parameters(f: &DMatrix<f64>, v: &DMatrix<f64>) -> f64 {
    let (pinv, _) = pseudo_inverse(f);
    (&pinv * v).trace()
}

/// The pseudo-inverse of a symmetric positive semi-definite `f` over its informed directions
/// (eigenvalues above 1e-12 of the largest), and per coordinate whether it loads on an
/// uninformed direction.
fn pseudo_inverse(f: &DMatrix<f64>) -> (DMatrix<f64>, Vec<bool>) {
    let k = f.nrows();
    let eig = f.clone().symmetric_eigen();
    let max = eig.eigenvalues.iter().fold(0.0_f64, |a, b| a.max(*b));
    let informed = |l: f64| l > 1e-12 * max && max > 0.0;
    let uninformed = (0..k)
        .map(|i| {
            (0..k).any(|j| !informed(eig.eigenvalues[j]) && eig.eigenvectors[(i, j)].powi(2) > 1e-6)
        })
        .collect();
    let pinv = DMatrix::from_fn(k, k, |i, j| {
        (0..k)
            .filter(|&m| informed(eig.eigenvalues[m]))
            .map(|m| eig.eigenvectors[(i, m)] * eig.eigenvectors[(j, m)] / eig.eigenvalues[m])
            .sum::<f64>()
    });
    (pinv, uninformed)
}

/// Standard deviations (∞ for an uninformed coordinate) and correlations (NaN there) of a
/// covariance matrix.
fn spread(cov: &DMatrix<f64>, uninformed: &[bool]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let k = cov.nrows();
    let sd: Vec<f64> = (0..k)
        .map(|i| {
            if uninformed[i] {
                f64::INFINITY
            } else {
                cov[(i, i)].max(0.0).sqrt()
            }
        })
        .collect();
    let corr = (0..k)
        .map(|i| {
            (0..k)
                .map(|j| {
                    if sd[i].is_finite() && sd[j].is_finite() {
                        cov[(i, j)] / (sd[i] * sd[j])
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        })
        .collect();
    (sd, corr)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A positive definite 3×3 information.
    fn info() -> DMatrix<f64> {
        DMatrix::from_row_slice(3, 3, &[4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0])
    }

    #[test]
    fn takeuchi_trace_is_akaikes_k_where_the_likelihood_is_right() {
        // V = F: tr(F⁻¹F) = k (Konishi & Kitagawa 2008, §3.4.3).
        let f = info();
        assert!((effective_parameters(&f, &f) - 3.0).abs() < 1e-12);
        // V = cF (a likelihood whose scale is off by c): c·k.
        assert!((effective_parameters(&f, &(0.3 * &f)) - 0.9).abs() < 1e-12);
    }

    #[test]
    fn takeuchi_trace_counts_only_informed_directions() {
        // A parameter with no information (its row and column zero): rank 2, so 2 with V = F.
        let mut f = info();
        for k in 0..3 {
            f[(2, k)] = 0.0;
            f[(k, 2)] = 0.0;
        }
        assert!((effective_parameters(&f, &f) - 2.0).abs() < 1e-12);
        // Diagonal F and V: Σ v_i/f_i over the informed ones.
        let f = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![2.0, 5.0, 0.0]));
        let v = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 1.0, 7.0]));
        assert!((effective_parameters(&f, &v) - (0.5 + 0.2)).abs() < 1e-12);
    }

    #[test]
    fn sandwich_of_a_diagonal_information_matches_the_hand_product() {
        // F = diag(4, 1), V = [[1, 0.5], [0.5, 4]]: F⁻¹VF⁻¹ = [[1/16, 1/8], [1/8, 4]], so
        // σ = (1/4, 2) and the correlation (1/8)/(1/4·2) = 1/4.
        let f = DMatrix::from_row_slice(2, 2, &[4.0, 0.0, 0.0, 1.0]);
        let v = DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.5, 4.0]);
        let (sd, corr) = sandwich_covariance(&f, &v);
        assert!(
            (sd[0] - 0.25).abs() < 1e-12 && (sd[1] - 2.0).abs() < 1e-12,
            "{sd:?}"
        );
        assert!((corr[0][1] - 0.25).abs() < 1e-12, "{corr:?}");
        // With V = F the sandwich is F⁻¹: σ = (1/2, 1), uncorrelated.
        let (sd, corr) = sandwich_covariance(&f, &f);
        assert!(
            (sd[0] - 0.5).abs() < 1e-12 && (sd[1] - 1.0).abs() < 1e-12,
            "{sd:?}"
        );
        assert!(corr[0][1].abs() < 1e-12);
    }

    #[test]
    fn sample_covariance_of_two_points_is_half_their_squared_difference() {
        // Two vectors (0, 0) and (2, 4): mean (1, 2), divisor n − 1 = 1, so the covariance is
        // [[2, 4], [4, 8]].
        let c = sample_covariance(&[vec![0.0, 0.0], vec![2.0, 4.0]]);
        assert_eq!(c, DMatrix::from_row_slice(2, 2, &[2.0, 4.0, 4.0, 8.0]));
    }

    #[test]
    fn covariance_of_a_diagonal_information_is_its_inverse() {
        // Independent parameters: Var = 1/F_ii, correlation 0.
        let f = DMatrix::from_row_slice(2, 2, &[4.0, 0.0, 0.0, 100.0]);
        let (sd, corr) = covariance(&f);
        assert!((sd[0] - 0.5).abs() < 1e-12 && (sd[1] - 0.1).abs() < 1e-12);
        assert!(corr[0][1].abs() < 1e-12);
    }

    #[test]
    fn covariance_of_a_correlated_pair_matches_the_2x2_inverse() {
        // F = [[a, b], [b, c]]: Var_0 = c/(ac − b²), corr = −b/√(ac).
        let (a, b, c) = (3.0, 1.5, 2.0);
        let f = DMatrix::from_row_slice(2, 2, &[a, b, b, c]);
        let (sd, corr) = covariance(&f);
        let det: f64 = a * c - b * b;
        assert!((sd[0] - (c / det).sqrt()).abs() < 1e-12);
        assert!((sd[1] - (a / det).sqrt()).abs() < 1e-12);
        assert!((corr[0][1] + b / (a * c).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn a_parameter_without_information_is_undetermined() {
        // The second parameter does not move the likelihood: infinite spread, NaN correlation,
        // and the first keeps its own.
        let f = DMatrix::from_row_slice(2, 2, &[4.0, 0.0, 0.0, 0.0]);
        let (sd, corr) = covariance(&f);
        assert!((sd[0] - 0.5).abs() < 1e-12);
        assert!(sd[1].is_infinite());
        assert!(corr[0][1].is_nan());
    }
}
