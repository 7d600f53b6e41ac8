//! Sines and cosines of the model's angles and of the drive phase, from the `libm` crate (the
//! Rust port of musl's libm: the same FreeBSD/Sun kernels, within 1 ulp of the exact value like
//! the platform's).
//!
//! They run in every right-hand side, event function and output sample of a simulation. glibc's
//! `sin`, `cos` and `sincos` save and restore the floating-point rounding mode on each call, which
//! made them about a quarter of a simulation's time; `libm`'s do not, and take about half as long
//! ([reports/bench/trig.md](../../reports/bench/trig.md)). [`sin_cos`] agrees bitwise with [`sin`]
//! and [`cos`] (one argument reduction and the same kernels), which the shared kinematics of
//! [`crate::model::Blade`] rely on.

/// `(sin x, cos x)`, `x` in rad.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    libm::sincos(x)
}

/// `sin x`, `x` in rad.
#[inline]
pub fn sin(x: f64) -> f64 {
    libm::sin(x)
}

/// `cos x`, `x` in rad.
#[inline]
pub fn cos(x: f64) -> f64 {
    libm::cos(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `sin_cos` gives bitwise what `sin` and `cos` give, over the link angles' range and the
    /// drive phase's (and powers of two from 2⁻³⁰ to 2³⁰), and agrees with the platform's to
    /// within 2 ulp (both are within 1 ulp of the exact value).
    #[test]
    fn sin_cos_agrees_with_sin_and_cos_and_the_platform() {
        let args = (0..40_000)
            .map(|i| -20.0 + 1e-3 * f64::from(i))
            .chain((-30..30).map(|e| 1.37 * 2f64.powi(e)));
        for x in args {
            let (s, c) = sin_cos(x);
            assert_eq!(s.to_bits(), sin(x).to_bits(), "sin {x}");
            assert_eq!(c.to_bits(), cos(x).to_bits(), "cos {x}");
            for (ours, platform) in [(s, x.sin()), (c, x.cos())] {
                let ulp = f64::EPSILON * platform.abs().max(f64::MIN_POSITIVE);
                assert!(
                    (ours - platform).abs() <= 2.0 * ulp,
                    "{x}: {ours} vs {platform}"
                );
            }
        }
    }
}
