//! Dormand–Prince 5(4) (DOPRI5) with step-size control and its 4th-order continuous extension.
//!
//! Coefficients and the dense-output formula are those of Hairer, Nørsett & Wanner, *Solving Ordinary
//! Differential Equations I* (2nd ed., Springer 1993), §II.5 Table 5.2 and §II.6 (the `CONTD5`
//! interpolant of their DOPRI5 code). The state is a fixed-size array `[f64; N]`, so a step allocates
//! nothing.

/// Butcher tableau of DOPRI5 (Dormand & Prince 1980).
mod tab {
    pub const C2: f64 = 1.0 / 5.0;
    pub const C3: f64 = 3.0 / 10.0;
    pub const C4: f64 = 4.0 / 5.0;
    pub const C5: f64 = 8.0 / 9.0;
    pub const A21: f64 = 1.0 / 5.0;
    pub const A31: f64 = 3.0 / 40.0;
    pub const A32: f64 = 9.0 / 40.0;
    pub const A41: f64 = 44.0 / 45.0;
    pub const A42: f64 = -56.0 / 15.0;
    pub const A43: f64 = 32.0 / 9.0;
    pub const A51: f64 = 19372.0 / 6561.0;
    pub const A52: f64 = -25360.0 / 2187.0;
    pub const A53: f64 = 64448.0 / 6561.0;
    pub const A54: f64 = -212.0 / 729.0;
    pub const A61: f64 = 9017.0 / 3168.0;
    pub const A62: f64 = -355.0 / 33.0;
    pub const A63: f64 = 46732.0 / 5247.0;
    pub const A64: f64 = 49.0 / 176.0;
    pub const A65: f64 = -5103.0 / 18656.0;
    pub const A71: f64 = 35.0 / 384.0;
    pub const A73: f64 = 500.0 / 1113.0;
    pub const A74: f64 = 125.0 / 192.0;
    pub const A75: f64 = -2187.0 / 6784.0;
    pub const A76: f64 = 11.0 / 84.0;
    // Error coefficients: 5th-order weights minus the embedded 4th-order ones.
    pub const E1: f64 = 71.0 / 57600.0;
    pub const E3: f64 = -71.0 / 16695.0;
    pub const E4: f64 = 71.0 / 1920.0;
    pub const E5: f64 = -17253.0 / 339200.0;
    pub const E6: f64 = 22.0 / 525.0;
    pub const E7: f64 = -1.0 / 40.0;
    // Dense output (Hairer's CONTD5).
    pub const D1: f64 = -12715105075.0 / 11282082432.0;
    pub const D3: f64 = 87487479700.0 / 32700410799.0;
    pub const D4: f64 = -10690763975.0 / 1880347072.0;
    pub const D5: f64 = 701980252875.0 / 199316789632.0;
    pub const D6: f64 = -1453857185.0 / 822651844.0;
    pub const D7: f64 = 69997945.0 / 29380423.0;
}

/// The continuous extension of one accepted step on `[t, t + h]`.
#[derive(Debug, Clone, Copy)]
pub struct Dense<const N: usize> {
    pub t: f64,
    pub h: f64,
    r: [[f64; N]; 5],
}

impl<const N: usize> Dense<N> {
    /// State at `t_eval ∈ [t, t + h]` (4th-order accurate; exact at both ends).
    #[inline]
    pub fn eval(&self, t_eval: f64) -> [f64; N] {
        let s = (t_eval - self.t) / self.h;
        let s1 = 1.0 - s;
        let mut y = [0.0; N];
        for (i, yi) in y.iter_mut().enumerate() {
            *yi = self.r[0][i]
                + s * (self.r[1][i] + s1 * (self.r[2][i] + s * (self.r[3][i] + s1 * self.r[4][i])));
        }
        y
    }

    /// End time of the step.
    pub fn t_end(&self) -> f64 {
        self.t + self.h
    }
}

/// Result of an attempted step.
pub struct Attempt<const N: usize> {
    pub y_new: [f64; N],
    /// Derivative at the new point (FSAL: the 7th stage).
    pub f_new: [f64; N],
    /// Weighted RMS error norm (≤ 1 means accept).
    pub err: f64,
    pub dense: Dense<N>,
}

/// Attempts one DOPRI5 step of size `h` from `(t, y)` with derivative `f0 = f(t, y)`.
///
/// `rhs(t, y, dy)` returns `Err(e)` when the derivative cannot be evaluated there (the caller
/// shrinks the step). Uses 6 new right-hand-side evaluations.
#[inline]
pub fn attempt<const N: usize, E>(
    rhs: &mut impl FnMut(f64, &[f64; N], &mut [f64; N]) -> Result<(), E>,
    t: f64,
    y: &[f64; N],
    f0: &[f64; N],
    h: f64,
    rtol: f64,
    atol: f64,
) -> Result<Attempt<N>, E> {
    use tab::*;
    let mut k2 = [0.0; N];
    let mut k3 = [0.0; N];
    let mut k4 = [0.0; N];
    let mut k5 = [0.0; N];
    let mut k6 = [0.0; N];
    let mut k7 = [0.0; N];
    let mut tmp = [0.0; N];
    let k1 = f0;
    for i in 0..N {
        tmp[i] = y[i] + h * A21 * k1[i];
    }
    rhs(t + C2 * h, &tmp, &mut k2)?;
    for i in 0..N {
        tmp[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
    }
    rhs(t + C3 * h, &tmp, &mut k3)?;
    for i in 0..N {
        tmp[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
    }
    rhs(t + C4 * h, &tmp, &mut k4)?;
    for i in 0..N {
        tmp[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
    }
    rhs(t + C5 * h, &tmp, &mut k5)?;
    for i in 0..N {
        tmp[i] = y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
    }
    rhs(t + h, &tmp, &mut k6)?;
    let mut y_new = [0.0; N];
    for i in 0..N {
        y_new[i] = y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
    }
    rhs(t + h, &y_new, &mut k7)?;
    let mut sum = 0.0;
    for i in 0..N {
        let e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        let sc = atol + rtol * y[i].abs().max(y_new[i].abs());
        sum += (e / sc) * (e / sc);
    }
    let err = (sum / N as f64).sqrt();
    let mut r = [[0.0; N]; 5];
    for i in 0..N {
        let dy = y_new[i] - y[i];
        let bspl = h * k1[i] - dy;
        r[0][i] = y[i];
        r[1][i] = dy;
        r[2][i] = bspl;
        r[3][i] = dy - h * k7[i] - bspl;
        r[4][i] = h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
    }
    Ok(Attempt {
        y_new,
        f_new: k7,
        err: if err.is_finite() { err } else { f64::INFINITY },
        dense: Dense { t, h, r },
    })
}

/// New step size from the error norm (Hairer's controller with safety 0.9, growth limits [0.2, 10]).
#[inline]
pub fn next_step(h: f64, err: f64) -> f64 {
    let fac = if err == 0.0 {
        10.0
    } else {
        (0.9 * err.powf(-0.2)).clamp(0.2, 10.0)
    };
    h * fac
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Harmonic oscillator y'' = −y: exact solution (cos t, −sin t). Checks the tableau (global error
    /// at rtol 1e-10 small) and the dense output (error between steps of the 4th-order order of the
    /// step's local error).
    #[test]
    fn harmonic_oscillator_and_dense_output() {
        let mut rhs = |_t: f64, y: &[f64; 2], dy: &mut [f64; 2]| -> Result<(), ()> {
            dy[0] = y[1];
            dy[1] = -y[0];
            Ok(())
        };
        let (rtol, atol) = (1e-10, 1e-12);
        let mut t = 0.0;
        let mut y = [1.0, 0.0];
        let mut f = [0.0, -1.0];
        let mut h: f64 = 1e-3;
        let mut max_dense_err: f64 = 0.0;
        while t < 10.0 {
            h = h.min(10.0 - t);
            let a = attempt(&mut rhs, t, &y, &f, h, rtol, atol).unwrap();
            if a.err <= 1.0 {
                for k in 1..4 {
                    let te = t + h * k as f64 / 4.0;
                    let yd = a.dense.eval(te);
                    max_dense_err = max_dense_err.max((yd[0] - te.cos()).abs());
                }
                t += h;
                y = a.y_new;
                f = a.f_new;
            }
            h = next_step(h, a.err);
        }
        assert!((y[0] - 10f64.cos()).abs() < 1e-8, "{}", y[0] - 10f64.cos());
        assert!((y[1] + 10f64.sin()).abs() < 1e-8);
        assert!(max_dense_err < 1e-8, "dense error {max_dense_err}");
    }

    fn oscillator(_t: f64, y: &[f64; 2], dy: &mut [f64; 2]) -> Result<(), ()> {
        dy[0] = y[1];
        dy[1] = -y[0];
        Ok(())
    }

    /// One-period error of `n` fixed steps on y'' = −y (exact: back to (1, 0)).
    fn one_period_error(n: usize) -> f64 {
        let h = 2.0 * std::f64::consts::PI / n as f64;
        let (mut y, mut t) = ([1.0, 0.0], 0.0);
        let mut rhs = oscillator;
        for _ in 0..n {
            let mut f = [0.0; 2];
            oscillator(t, &y, &mut f).unwrap();
            y = attempt(&mut rhs, t, &y, &f, h, 1.0, 1.0).unwrap().y_new;
            t += h;
        }
        (y[0] - 1.0).abs().max(y[1].abs())
    }

    /// Order check: halving a fixed step divides the one-period error by ≈ 2⁵ = 32.
    #[test]
    fn fifth_order_convergence() {
        let order = (one_period_error(50) / one_period_error(100)).log2();
        assert!((order - 5.0).abs() < 0.3, "observed order {order}");
    }
}
