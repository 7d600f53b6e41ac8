//! Spectral peak picking with quadratic interpolation on the log spectrum.
//!
//! A peak is a **local maximum** of the PSD (`X_k > X_{k−1}` and `X_k ≥ X_{k+1}`), the same rule as the
//! independent estimator described in `shared/sample/truth.json` (`estimator.description`). Its
//! frequency and level are refined by fitting a parabola through `ln X` at bins `k−1, k, k+1`
//! (J.O. Smith, *Spectral Audio Signal Processing*, CCRMA, "Quadratic Interpolation of Spectral
//! Peaks", <https://ccrma.stanford.edu/~jos/sasp/Quadratic_Interpolation_Spectral_Peaks.html>):
//!
//! ```text
//! a, b, c = ln X_{k−1}, ln X_k, ln X_{k+1}
//! p = ½ (a − c) / (a − 2b + c)          ∈ [−½, ½] bins
//! f = f_k + p·Δf,   ln level = b − ¼ (a − c) p
//! ```
//!
//! Because `ln PSD = 2 ln|X| + const`, `p` is the same whether the parabola is fitted to the PSD, to
//! `|X|` or to dB. The estimate is biased except at bin centres and bin midpoints; for a Hann window
//! without zero-padding the bias is below 0.02 bin (measured in `tests/suite/spectrum.rs`), and it shrinks
//! roughly tenfold per doubling of `nfft` (Smith, "Bias of Parabolic Peak Interpolation").

/// One interpolated spectral peak.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Peak {
    /// Interpolated peak frequency in Hz.
    pub freq_hz: f64,
    /// PSD at the parabola's vertex, `exp(ln level)`, in the PSD's units (units²/Hz).
    pub level: f64,
    /// Index of the local-maximum bin `k`.
    pub bin: usize,
    /// `X_k` divided by the median PSD over `[f/1.3, 1.3 f]` excluding bins `k−3..=k+3`. It is a
    /// ratio of **powers**: the truth file's magnitude ratio `r` corresponds to `r²` here. `+∞` if
    /// that median is 0, NaN if no bin is left to take it over.
    pub prominence: f64,
}

/// The largest local maximum of `psd` whose bin frequency lies in `band_hz = (lo, hi)` (inclusive),
/// refined by parabolic interpolation of `ln psd`.
///
/// `freq_hz` must be the uniform bin grid of `psd` (same length). Bins that are NaN, ±∞ or ≤ 0 are
/// never peaks; if a neighbour of the peak is 0 or not finite (so `ln` is undefined) the bin itself is
/// returned uninterpolated (`p = 0`, `level = X_k`). Returns `None` if the lengths differ, the band
/// is empty or holds no local maximum (the first and last bins cannot be local maxima).
///
/// ```
/// use wiperlab::spectrum::find_peak;
/// let f = [0.0, 1.0, 2.0, 3.0, 4.0];
/// let p = [1.0, 2.0, 8.0, 2.0, 1.0];
/// let pk = find_peak(&f, &p, (0.5, 3.5)).unwrap();
/// assert_eq!(pk.bin, 2);
/// assert!((pk.freq_hz - 2.0).abs() < 1e-12);
/// ```
pub fn find_peak(freq_hz: &[f64], psd: &[f64], band_hz: (f64, f64)) -> Option<Peak> {
    top_peaks(freq_hz, psd, band_hz, 1).into_iter().next()
}

/// The `n` largest local maxima (by bin value `X_k`) in `band_hz`, largest first, each interpolated
/// as in [`find_peak`]. Fewer are returned if the band holds fewer local maxima.
pub fn top_peaks(freq_hz: &[f64], psd: &[f64], band_hz: (f64, f64), n: usize) -> Vec<Peak> {
    if freq_hz.len() != psd.len() || psd.len() < 3 || n == 0 {
        return Vec::new();
    }
    let (lo, hi) = band_hz;
    let mut cand: Vec<usize> = (1..psd.len() - 1)
        .filter(|&k| {
            let x = psd[k];
            freq_hz[k] >= lo
                && freq_hz[k] <= hi
                && x.is_finite()
                && x > 0.0
                && x > psd[k - 1]
                && x >= psd[k + 1]
        })
        .collect();
    // Stable sort: equal peaks keep ascending-bin order.
    cand.sort_by(|&a, &b| psd[b].total_cmp(&psd[a]));
    cand.truncate(n);
    cand.into_iter()
        .map(|k| interpolate(freq_hz, psd, k))
        .collect()
}

/// Vertex of the parabola through `(−1, a), (0, b), (1, c)`: `(p, value)`, with `p` in bins relative
/// to the centre. Returns `None` unless all three are finite and the parabola is concave
/// (`a − 2b + c < 0`).
pub fn parabolic_vertex(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    let den = a - 2.0 * b + c;
    if !(a.is_finite() && b.is_finite() && c.is_finite()) || den >= 0.0 {
        return None;
    }
    let p = 0.5 * (a - c) / den;
    Some((p, b - 0.25 * (a - c) * p))
}

fn interpolate(freq_hz: &[f64], psd: &[f64], k: usize) -> Peak {
    let (xa, xb, xc) = (psd[k - 1], psd[k], psd[k + 1]);
    let half_span = 0.5 * (freq_hz[k + 1] - freq_hz[k - 1]);
    let (freq, level) = if xa > 0.0 && xc > 0.0 {
        match parabolic_vertex(xa.ln(), xb.ln(), xc.ln()) {
            Some((p, y)) => (freq_hz[k] + p * half_span, y.exp()),
            None => (freq_hz[k], xb),
        }
    } else {
        (freq_hz[k], xb)
    };
    Peak {
        freq_hz: freq,
        level,
        bin: k,
        prominence: prominence(freq_hz, psd, k, freq),
    }
}

/// `X_k / median(X_j : f_j ∈ [f/1.3, 1.3 f], |j − k| > 3, X_j finite)`.
fn prominence(freq_hz: &[f64], psd: &[f64], k: usize, f: f64) -> f64 {
    let (lo, hi) = (f / 1.3, f * 1.3);
    let mut v: Vec<f64> = freq_hz
        .iter()
        .zip(psd)
        .enumerate()
        .filter(|(j, (fj, x))| **fj >= lo && **fj <= hi && j.abs_diff(k) > 3 && x.is_finite())
        .map(|(_, (_, x))| *x)
        .collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len();
    let med = if m % 2 == 1 {
        v[m / 2]
    } else {
        0.5 * (v[m / 2 - 1] + v[m / 2])
    };
    if med > 0.0 {
        psd[k] / med
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_of_exact_parabola() {
        // y = −(x − 0.3)² + 2 at x = −1, 0, 1 → vertex (0.3, 2) exactly (hand algebra).
        let y = |x: f64| -(x - 0.3) * (x - 0.3) + 2.0;
        let (p, v) = parabolic_vertex(y(-1.0), y(0.0), y(1.0)).unwrap();
        assert!((p - 0.3).abs() < 1e-14);
        assert!((v - 2.0).abs() < 1e-14);
        assert!(parabolic_vertex(1.0, 1.0, 1.0).is_none());
        assert!(parabolic_vertex(f64::NEG_INFINITY, 1.0, 0.0).is_none());
    }

    #[test]
    fn gaussian_peak_is_exact_on_log_scale() {
        // ln of a Gaussian is a parabola, so interpolation on ln X is exact: peak at 10.37 Hz.
        let f: Vec<f64> = (0..40).map(|k| k as f64 * 0.5).collect();
        let x: Vec<f64> = f
            .iter()
            .map(|f| 5.0 * (-(f - 10.37) * (f - 10.37) / 2.0).exp() + 0.0)
            .collect();
        let pk = find_peak(&f, &x, (5.0, 15.0)).unwrap();
        assert!((pk.freq_hz - 10.37).abs() < 1e-12, "{pk:?}");
        assert!((pk.level - 5.0).abs() < 1e-12);
        assert_eq!(pk.bin, 21);
    }

    #[test]
    fn guards_zero_nan_and_empty() {
        let f = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        // Neighbour 0: ln undefined → bin frequency, bin level.
        let x = [0.0, 0.0, 3.0, 1.0, f64::NAN, 0.5];
        let pk = find_peak(&f, &x, (0.0, 5.0)).unwrap();
        assert_eq!((pk.bin, pk.freq_hz, pk.level), (2, 2.0, 3.0));
        // All NaN or all zero: no local maximum.
        assert!(find_peak(&f, &[f64::NAN; 6], (0.0, 5.0)).is_none());
        assert!(find_peak(&f, &[0.0; 6], (0.0, 5.0)).is_none());
        // Band outside, reversed band, length mismatch, too short.
        assert!(find_peak(&f, &x, (10.0, 20.0)).is_none());
        assert!(find_peak(&f, &x, (4.0, 1.0)).is_none());
        assert!(find_peak(&f[..5], &x, (0.0, 5.0)).is_none());
        assert!(find_peak(&[], &[], (0.0, 5.0)).is_none());
    }

    #[test]
    fn top_peaks_orders_by_height() {
        let f: Vec<f64> = (0..12).map(|k| k as f64).collect();
        let x = [1.0, 5.0, 1.0, 1.0, 9.0, 1.0, 1.0, 7.0, 1.0, 1.0, 1.0, 1.0];
        let p = top_peaks(&f, &x, (0.0, 11.0), 5);
        let bins: Vec<usize> = p.iter().map(|p| p.bin).collect();
        assert_eq!(bins, vec![4, 7, 1]);
        assert_eq!(find_peak(&f, &x, (6.0, 11.0)).unwrap().bin, 7);
        // Prominence: the window [f/1.3, 1.3f] around bin 4 minus ±3 bins is empty → NaN; around
        // bin 7 (f ∈ [5.4, 9.1]) minus bins 4..=10 is empty too; at bin 1 neighbours are excluded.
        assert!(p[0].prominence.is_nan());
    }

    #[test]
    fn prominence_over_flat_floor() {
        // Floor 1, line of 100 at 50 Hz (1 Hz bins): median over [38.5, 65] Hz without 47..=53 is 1.
        let f: Vec<f64> = (0..100).map(|k| k as f64).collect();
        let mut x = vec![1.0; 100];
        x[50] = 100.0;
        x[49] = 2.0;
        x[51] = 2.0;
        let pk = find_peak(&f, &x, (10.0, 90.0)).unwrap();
        assert_eq!(pk.bin, 50);
        assert!((pk.freq_hz - 50.0).abs() < 1e-12);
        assert!((pk.prominence - 100.0).abs() < 1e-12);
    }
}
