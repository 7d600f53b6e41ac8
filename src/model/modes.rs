//! Linearised modes of the blade in stick and in steady slip.
//!
//! The right-hand side `ẋ = F(x)` of a phase is linearised numerically by central differences,
//! `J_ij ≈ (F_i(x + h_j e_j) − F_i(x − h_j e_j)) / 2h_j`, around a quasi-static state; the complex
//! eigenvalues λ of `J` (nalgebra's Schur-based eigen decomposition) give the undamped natural
//! frequency `|λ|/2π` (Hz) and the damping ratio `ζ = −Re λ / |λ|` (negative: self-excited, e.g. on
//! the falling branch of the friction law, whose slope dμ/dv enters the slip Jacobian through the
//! tip velocity). Overdamped (real) eigenvalues are not oscillatory modes and are left out.
//!
//! Slip: state `[θ, φ, θ̇, φ̇]` of [`Blade::slip_dynamics`] (eqs. 1–4 of the seed paper) around
//! [`Blade::slip_equilibrium`] at the drive instant whose head speed equals the slip speed (in that
//! equilibrium θ̇ = φ̇ = 0, so the tip slips at the head speed). Stick: the tip held, the constraint
//! removes one DOF; state `[θ, θ̇]` with φ, φ̇ from [`Blade::constrained_lip`] (the drift-free reduced
//! form, physics.md §1.4) around upright at `t = 0`, where the head is at rest. The head's vertical
//! motion is not a DOF of its own: it follows the link (u = l1(1 − cos θ) + l2(1 − cos φ)), its mass
//! and k0 enter through eq. 3.

use nalgebra::{Complex, DMatrix};
use serde::Serialize;

use super::blade::Blade;
use super::stick_slip::ModelFault;

/// Why the modes could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModesError {
    /// The model failed at a linearisation point (no equilibrium, singular system).
    #[error("linearisation failed: {0}")]
    Model(#[from] ModelFault),
    /// The drive never reaches the requested slip speed (its peak head speed is `aω`).
    #[error(
        "slip speed {speed_m_per_s} m/s is not reached by the drive (head speed at most {max_m_per_s} m/s)"
    )]
    SpeedOutOfReach {
        speed_m_per_s: f64,
        max_m_per_s: f64,
    },
}

/// The state of the stick–slip cycle the blade is linearised about (written as its `phase`:
/// `stick` or `slip`). The contact phases the integrator switches between are
/// [`crate::model::stick_slip::Phase`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
#[serde(tag = "phase", rename_all = "snake_case")]
pub enum OperatingPoint {
    /// Tip held on the glass.
    Stick,
    /// Steady slip at `speed_m_per_s`.
    Slip { speed_m_per_s: f64 },
}

impl std::fmt::Display for OperatingPoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OperatingPoint::Stick => write!(f, "stick"),
            OperatingPoint::Slip { speed_m_per_s } => write!(f, "slip at {speed_m_per_s} m/s"),
        }
    }
}

/// One oscillatory mode (eigenmode) of a linear(ised) first-order system. The discrete modes of the
/// stick–slip integrator are [`crate::model::stick_slip::Mode`].
#[derive(Debug, Clone, PartialEq)]
pub struct Eigenmode {
    /// Undamped natural frequency |λ|/2π, Hz.
    pub freq_hz: f64,
    /// Damping ratio −Re λ/|λ| (negative: self-excited).
    pub damping_ratio: f64,
    /// Eigenvector (the eigenvalue with positive imaginary part).
    pub shape: Vec<Complex<f64>>,
}

/// How much each physical coordinate moves in a blade mode, normalised so the largest is 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct Participation {
    /// Head vertical drop δu = l1 sin θ δθ + l2 sin φ δφ, as an angle δu/(l1 + l2).
    pub head: f64,
    /// Neck angle relative to the head, δθ.
    pub head_link: f64,
    /// Lip angle relative to the neck, δφ − δθ.
    pub neck_lip: f64,
}

/// One mode of the blade at an operating point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
pub struct BladeMode {
    #[serde(flatten)]
    pub phase: OperatingPoint,
    pub freq_hz: f64,
    pub damping_ratio: f64,
    pub participation: Participation,
}

/// Central-difference Jacobian of `f` at `x0`; step `h_j = 1e-6·max(|x0_j|, 1e-3)`. Returns an
/// `n×n` matrix for `f: ℝⁿ → ℝⁿ`.
///
/// # Errors
/// Whatever `f` returns.
pub fn jacobian_central<E>(
    mut f: impl FnMut(&[f64]) -> Result<Vec<f64>, E>,
    x0: &[f64],
) -> Result<DMatrix<f64>, E> {
    let n = x0.len();
    let mut j = DMatrix::zeros(n, n);
    let mut x = x0.to_vec();
    for col in 0..n {
        let h = 1e-6 * x0[col].abs().max(1e-3);
        x[col] = x0[col] + h;
        let fp = f(&x)?;
        x[col] = x0[col] - h;
        let fm = f(&x)?;
        x[col] = x0[col];
        for row in 0..n {
            j[(row, col)] = (fp[row] - fm[row]) / (2.0 * h);
        }
    }
    Ok(j)
}

/// Oscillatory modes of `ẋ = A x`, sorted by frequency (one per conjugate pair).
pub fn modes_of_system(a: &DMatrix<f64>) -> Vec<Eigenmode> {
    let n = a.nrows();
    let ac: DMatrix<Complex<f64>> = a.map(|v| Complex::new(v, 0.0));
    let eig = a.complex_eigenvalues();
    let scale = eig.iter().map(|l| l.norm()).fold(0.0, f64::max).max(1e-300);
    let mut modes: Vec<Eigenmode> = eig
        .iter()
        .filter(|l| l.im > 1e-9 * scale)
        .map(|&l| Eigenmode {
            freq_hz: l.norm() / (2.0 * std::f64::consts::PI),
            damping_ratio: -l.re / l.norm(),
            shape: null_vector(&(ac.clone() - DMatrix::identity(n, n) * l)),
        })
        .collect();
    modes.sort_by(|x, y| x.freq_hz.total_cmp(&y.freq_hz));
    modes
}

/// A unit vector spanning (numerically) the null space of `m`: the right singular vector of the
/// smallest singular value.
fn null_vector(m: &DMatrix<Complex<f64>>) -> Vec<Complex<f64>> {
    let svd = m.clone().svd(false, true);
    let v_t = svd.v_t.expect("requested");
    let k = (0..svd.singular_values.len())
        .min_by(|&a, &b| svd.singular_values[a].total_cmp(&svd.singular_values[b]))
        .unwrap_or(0);
    v_t.row(k).iter().map(|c| c.conj()).collect()
}

/// The slip speeds, as fractions of the drive's peak head speed `aω`, at which
/// [`Blade::window_modes`] linearises: the reversal window runs from the fastest forward sweep
/// through rest to the fastest backward sweep, so its slip speeds span (0, aω].
pub const WINDOW_SPEED_FRACTIONS: [f64; 3] = [0.25, 0.5, 1.0];

impl Blade {
    /// Modes in stick and in steady slip at the window's speeds ([`WINDOW_SPEED_FRACTIONS`] of the
    /// drive's peak head speed `aω`).
    ///
    /// # Errors
    /// As [`Blade::modes`].
    pub fn window_modes(&self) -> Result<Vec<BladeMode>, ModesError> {
        let peak = self.params.drive_a_m * self.params.drive_omega_rad_per_s;
        let speeds: Vec<f64> = WINDOW_SPEED_FRACTIONS.iter().map(|f| f * peak).collect();
        self.modes(&speeds)
    }

    /// Modes in stick and in steady slip at each of `speeds_m_per_s` (m/s, > 0).
    ///
    /// # Errors
    /// [`ModesError::SpeedOutOfReach`] if a speed exceeds the drive's peak `aω`, or the model's
    /// fault at a linearisation point.
    pub fn modes(&self, speeds_m_per_s: &[f64]) -> Result<Vec<BladeMode>, ModesError> {
        let mut out = self.stick_modes()?;
        for &v in speeds_m_per_s {
            out.extend(self.slip_modes(v)?);
        }
        Ok(out)
    }

    /// Slip modes at slip speed `speed_m_per_s` (see the module docs).
    pub fn slip_modes(&self, speed_m_per_s: f64) -> Result<Vec<BladeMode>, ModesError> {
        let (a, w) = (self.params.drive_a_m, self.params.drive_omega_rad_per_s);
        let max = a * w;
        if !(speed_m_per_s > 0.0 && speed_m_per_s <= max) {
            return Err(ModesError::SpeedOutOfReach {
                speed_m_per_s,
                max_m_per_s: max,
            });
        }
        let t = (speed_m_per_s / max).asin() / w;
        let y0 = self.slip_equilibrium(t)?;
        let touching = self.params.touches_shoulder(y0[0]);
        let rhs = |x: &[f64]| -> Result<Vec<f64>, ModelFault> {
            let d = self.slip_dynamics_on(1.0, t, &[x[0], x[1], x[2], x[3]], touching)?;
            Ok(vec![x[2], x[3], d.theta_dd, d.phi_dd])
        };
        let jac = jacobian_central(rhs, &y0)?;
        let phase = OperatingPoint::Slip { speed_m_per_s };
        Ok(modes_of_system(&jac)
            .iter()
            .map(|m| self.blade_mode(phase, m, &y0, m.shape[0], m.shape[1]))
            .collect())
    }

    /// Stick modes (tip held), see the module docs.
    pub fn stick_modes(&self) -> Result<Vec<BladeMode>, ModesError> {
        let t = 0.0;
        let anchor = self.tip_position(t, &[0.0; 4]);
        let touching = self.params.touches_shoulder(0.0);
        let rhs = |x: &[f64]| -> Result<Vec<f64>, ModelFault> {
            let (ph, phd) = self.constrained_lip(t, x[0], x[1], anchor)?;
            let d = self.stick_dynamics_on(t, &[x[0], ph, x[1], phd], anchor, 0.0, touching)?;
            Ok(vec![x[1], d.theta_dd])
        };
        let jac = jacobian_central(rhs, &[0.0, 0.0])?;
        let (l1, l2) = (self.params.l1_m, self.params.l2_m);
        // Linearised constraint at upright: l1 δθ + l2 δφ = 0.
        Ok(modes_of_system(&jac)
            .iter()
            .map(|m| {
                let dth = m.shape[0];
                self.blade_mode(OperatingPoint::Stick, m, &[0.0; 4], dth, dth * (-l1 / l2))
            })
            .collect())
    }

    fn blade_mode(
        &self,
        phase: OperatingPoint,
        m: &Eigenmode,
        y0: &[f64],
        dth: Complex<f64>,
        dph: Complex<f64>,
    ) -> BladeMode {
        let (l1, l2) = (self.params.l1_m, self.params.l2_m);
        let du = (dth * (l1 * y0[0].sin()) + dph * (l2 * y0[1].sin())) / (l1 + l2);
        let raw = [du.norm(), dth.norm(), (dph - dth).norm()];
        let big = raw.iter().copied().fold(0.0, f64::max).max(1e-300);
        BladeMode {
            phase,
            freq_hz: m.freq_hz,
            damping_ratio: m.damping_ratio,
            participation: Participation {
                head: raw[0] / big,
                head_link: raw[1] / big,
                neck_lip: raw[2] / big,
            },
        }
    }
}
