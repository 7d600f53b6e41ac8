//! The Laplace interval checked against the likelihood it approximates: the NLL's rise along each
//! principal axis of the Fisher information's inverse, a few of its standard deviations out, against
//! the rise of the quadratic the interval assumes.
//!
//! Why: the Fisher information is the Gauss–Newton one, from the response's Jacobian by central
//! differences a fraction of a standard deviation wide. The stick–slip response is rough at that
//! scale, so `F` can call a direction steep along which the likelihood, read at the scale of its
//! own intervals, is nearly flat. On a development recording (docs/validation.md, "Intervals
//! against the likelihood") the truth lay 27.6 of `F⁻¹`'s standard deviations out along one axis,
//! where the quadratic rises 387 nats, and the NLL rose 0.71: the Laplace intervals excluded the
//! truth by 5–16 of their widths, and a posterior sample of the same likelihood covered it.
//!
//! The check (a secant curvature, Nocedal & Wright 2006, *Numerical Optimization*, §6.1: the
//! curvature a function shows between two points rather than at one) costs `2k` simulations. An
//! axis `i` of `F⁻¹` along which the NLL at `±r·σᵢ` rises, on average over the two sides (which
//! cancels a slope left by the search), less than a [`SECANT_FLAT_RATIO`]-th of the quadratic's
//! `r²/2` is reported: the Laplace interval does not describe the likelihood there. Stretching the
//! sandwich along such an axis by the secant's standard deviation over `F`'s does not repair it
//! (on that recording the truth stayed 6–11 of the stretched standard deviations out: the
//! likelihood is not a quadratic at any one scale), so the fit warns and names the method that
//! samples the likelihood itself.

use super::covariance::covariance_of;
use crate::job::FreeParam;
use nalgebra::DVector;

/// Radius of the probes, in standard deviations of `F⁻¹` along each principal axis: far enough
/// that the likelihood's ripples (a few hundredths of a nat, docs/validation.md, "Settling") are
/// small against the quadratic's 12.5 nats there, near enough to stay in the fit's bowl.
pub const SECANT_PROBE_SIGMA: f64 = 5.0;

/// How many times flatter than the quadratic (its rise over the measured one at the probes) an
/// axis must be before it is stretched: 4, a secant standard deviation twice `F`'s. The rough
/// response makes the rise at the probes scatter around the quadratic's by up to a factor of about
/// 3 where the intervals cover (the main job: 4.4–16.8 nats against 12.5).
pub const SECANT_FLAT_RATIO: f64 = 4.0;

/// The largest stretch of an axis: where the NLL barely rises at the probes the secant curvature
/// is not measured (the ripples dominate), and the axis is called at least this much wider.
pub const SECANT_MAX_STRETCH: f64 = 10.0;

/// What the fit's `flatter_than_curvature` warning says of a [`FlatAxis`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FlatAxisReport {
    /// The parameter the axis moves most ([`main_parameter`]).
    pub parameter: crate::model::ParamId,
    /// The NLL's mean rise at the probes, nats.
    pub rise_nats: f64,
    /// The quadratic's rise there, `r²/2` nats.
    pub quadratic_nats: f64,
    /// The axis's secant 1σ over `F⁻¹`'s.
    pub stretch: f64,
}

/// One principal axis along which the likelihood is flatter than the quadratic.
#[derive(Debug, Clone, PartialEq)]
pub struct FlatAxis {
    /// The axis's direction in the search's normalised coordinates (unit length).
    pub direction: Vec<f64>,
    /// Its standard deviation under `F⁻¹`, normalised units.
    pub fisher_sigma_u: f64,
    /// The NLL's mean rise at the two probes, nats (the quadratic's is `r²/2`).
    pub rise_nats: f64,
    /// The axis's secant 1σ over `F⁻¹`'s, `√(r²/(2·rise))`, more than [`SECANT_FLAT_RATIO`]`^½`
    /// (at most [`SECANT_MAX_STRETCH`]).
    pub stretch: f64,
}

/// The NLL's mean rise above `cost` at `u ± r·v` (one side where the other leaves the box or its
/// simulation fails); `None` where neither side can be read.
fn mean_rise<F>(cost_at: &F, u: &[f64], step: &DVector<f64>, cost: f64) -> Option<f64>
where
    F: Fn(&[f64]) -> Option<f64> + Sync,
{
    use rayon::prelude::*;
    let rises: Vec<f64> = [1.0, -1.0]
        .par_iter()
        .filter_map(|sign| {
            let p: Vec<f64> = u
                .iter()
                .zip(step.iter())
                .map(|(a, s)| a + sign * s)
                .collect();
            if p.iter().any(|x| !(0.0..=1.0).contains(x)) {
                return None;
            }
            cost_at(&p).map(|c| c - cost)
        })
        .collect();
    (!rises.is_empty()).then(|| rises.iter().sum::<f64>() / rises.len() as f64)
}

/// The stretch of an axis whose probes at `r` standard deviations rose `rise` nats on average:
/// 1 unless the axis is [`SECANT_FLAT_RATIO`] times flatter than the quadratic.
pub fn stretch_of(rise: f64, r: f64) -> f64 {
    let quadratic = 0.5 * r * r;
    if rise * SECANT_FLAT_RATIO >= quadratic {
        return 1.0;
    }
    (quadratic / rise.max(0.0)).sqrt().min(SECANT_MAX_STRETCH)
}

/// The principal axes of `F⁻¹` (1σ `fisher.0`, correlations `fisher.1`) along which the NLL
/// `cost_at` (nats; `None`: a failed simulation) at the fit `u` (cost `cost`) is
/// [`SECANT_FLAT_RATIO`] times flatter than the Laplace quadratic ([`stretch_of`]); empty where
/// every axis rises as the quadratic or faster, or where `F⁻¹` has no finite positive 1σ (a
/// parameter the likelihood does not inform is reported as such elsewhere). `2k` evaluations of
/// `cost_at`, two at a time in parallel.
pub fn flat_axes<F>(
    cost_at: F,
    u: &[f64],
    cost: f64,
    fisher: (&[f64], &[Vec<f64>]),
) -> Vec<FlatAxis>
where
    F: Fn(&[f64]) -> Option<f64> + Sync,
{
    if !fisher.0.iter().all(|x| x.is_finite() && *x > 0.0) {
        return Vec::new();
    }
    let eig = covariance_of(fisher.0, fisher.1).symmetric_eigen();
    (0..u.len())
        .filter_map(|i| {
            let sd = eig.eigenvalues[i].max(0.0).sqrt();
            let v = eig.eigenvectors.column(i).into_owned();
            let rise = mean_rise(&cost_at, u, &(&v * (SECANT_PROBE_SIGMA * sd)), cost)?;
            let stretch = stretch_of(rise, SECANT_PROBE_SIGMA);
            (sd > 0.0 && stretch > 1.0).then(|| FlatAxis {
                direction: v.iter().copied().collect(),
                fisher_sigma_u: sd,
                rise_nats: rise,
                stretch,
            })
        })
        .collect()
}

/// The parameter an axis moves most (largest component of `direction` in physical units relative
/// to the search box: the normalised coordinates already are).
pub fn main_parameter<'a>(free: &'a [FreeParam], axis: &FlatAxis) -> &'a FreeParam {
    let i = axis
        .direction
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map_or(0, |(i, _)| i);
    &free[i]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quadratic's own rise (r²/2 at r σ) leaves an axis alone, and so does a rise down to a
    /// quarter of it; below, the stretch is the secant's σ over F's, √(quadratic/rise), capped.
    #[test]
    fn an_axis_is_stretched_only_where_the_likelihood_is_four_times_flatter() {
        let r = SECANT_PROBE_SIGMA;
        let q = 0.5 * r * r;
        assert_eq!(stretch_of(q, r), 1.0);
        assert_eq!(stretch_of(q / SECANT_FLAT_RATIO, r), 1.0);
        let s = stretch_of(q / 9.0, r);
        assert!((s - 3.0).abs() < 1e-12, "{s}");
        assert_eq!(stretch_of(0.0, r), SECANT_MAX_STRETCH);
        assert_eq!(stretch_of(-0.3, r), SECANT_MAX_STRETCH);
    }

    /// The 1σ and correlation of a 2-D covariance.
    fn fisher_of(s: [f64; 2], rho: f64) -> (Vec<f64>, Vec<Vec<f64>>) {
        (s.to_vec(), vec![vec![1.0, rho], vec![rho, 1.0]])
    }

    /// A likelihood that is the quadratic of `F` (a rotated, correlated bowl) has no flat axis,
    /// whatever slope the fit is left on (the two sides' mean cancels it).
    #[test]
    fn the_quadratic_of_f_itself_has_no_flat_axis() {
        let (s, c) = fisher_of([0.02, 0.05], 0.8);
        let cov = covariance_of(&s, &c);
        let inv = cov.try_inverse().expect("positive definite");
        let u0 = [0.4, 0.6];
        let slope = [30.0, -10.0];
        let nll = |u: &[f64]| {
            let d = DVector::from_iterator(2, u.iter().zip(&u0).map(|(a, b)| a - b));
            Some(0.5 * (d.transpose() * &inv * &d)[(0, 0)] + slope[0] * d[0] + slope[1] * d[1])
        };
        assert!(flat_axes(nll, &u0, 0.0, (&s, &c)).is_empty());
    }

    /// Along an axis where the likelihood is 9 times flatter than `F` says (in variance: 3 in σ),
    /// the check reports that axis, its 1σ under `F⁻¹` and the stretch 3 (closed form
    /// √(r²/2 / (r²/18)) = 3); the other axis, as steep as `F` says, is left alone.
    #[test]
    fn an_axis_nine_times_flatter_is_reported_with_its_stretch() {
        let (s, c) = fisher_of([0.01, 0.03], 0.0);
        let nll = |u: &[f64]| {
            let (x, y) = (u[0] - 0.5, u[1] - 0.5);
            Some(0.5 * (x / 0.01).powi(2) + 0.5 * (y / 0.09).powi(2))
        };
        let axes = flat_axes(nll, &[0.5, 0.5], 0.0, (&s, &c));
        assert_eq!(axes.len(), 1, "{axes:?}");
        let a = &axes[0];
        assert!(
            (a.direction[0].abs() - 0.0).abs() < 1e-12
                && (a.direction[1].abs() - 1.0).abs() < 1e-12
        );
        assert!((a.fisher_sigma_u - 0.03).abs() < 1e-12, "{a:?}");
        assert!((a.stretch - 3.0).abs() < 1e-9, "{a:?}");
        assert!((a.rise_nats - 0.5 * 25.0 / 9.0).abs() < 1e-9, "{a:?}");
    }

    /// A probe that leaves the box or whose simulation fails is not read; an axis with neither
    /// side read is not reported.
    #[test]
    fn probes_outside_the_box_or_failed_are_skipped() {
        let (s, c) = fisher_of([0.2, 0.01], 0.0);
        // Flat everywhere: every readable axis would be reported.
        let flat = |_: &[f64]| Some(0.0);
        // At u = (0.05, 0.5) the first axis's probes (±1.0) both leave the box.
        let axes = flat_axes(flat, &[0.05, 0.5], 0.0, (&s, &c));
        assert_eq!(axes.len(), 1, "{axes:?}");
        assert!((axes[0].fisher_sigma_u - 0.01).abs() < 1e-12);
        let failed = |_: &[f64]| None;
        assert!(flat_axes(failed, &[0.5, 0.5], 0.0, (&s, &c)).is_empty());
    }
}
