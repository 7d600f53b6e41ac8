//! Order statistics shared by the pipeline: the median and linear-interpolation quantiles.

/// Median of `v`, which is sorted in place (IEEE total order, so NaN sorts last and counts):
/// the middle value, or the mean of the two middle values for an even length. NaN when empty.
pub fn median_in_place(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let m = v.len();
    if m == 0 {
        f64::NAN
    } else if m % 2 == 1 {
        v[m / 2]
    } else {
        0.5 * (v[m / 2 - 1] + v[m / 2])
    }
}

/// Quantile of ascending `v` at fraction `q` ∈ [0, 1] by linear interpolation between the closest
/// ranks (NumPy's default `method="linear"`, Hyndman & Fan 1996 type 7). NaN when empty.
pub fn quantile_sorted(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let pos = q * (v.len() - 1) as f64;
    let (i, f) = (pos.floor() as usize, pos.fract());
    if i + 1 < v.len() {
        v[i] + f * (v[i + 1] - v[i])
    } else {
        v[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_and_quantiles_match_numpy() {
        // numpy.median([3, 1, 2]) = 2, numpy.median([4, 1, 3, 2]) = 2.5.
        assert_eq!(median_in_place(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median_in_place(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median_in_place(&mut []).is_nan());
        // numpy.quantile([1, 2, 3, 4, 5], [0, 0.1, 0.5, 0.875, 1]) = [1, 1.4, 3, 4.5, 5].
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        for (q, want) in [(0.0, 1.0), (0.1, 1.4), (0.5, 3.0), (0.875, 4.5), (1.0, 5.0)] {
            assert!((quantile_sorted(&v, q) - want).abs() < 1e-15, "q {q}");
        }
        assert!(quantile_sorted(&[], 0.5).is_nan());
    }
}
