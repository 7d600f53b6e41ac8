//! Friction laws: the slip (dynamic) coefficient as a function of slip speed and the static limit.
//!
//! The contact convention used throughout wiperlab: `f` is the tangential force the surface exerts on
//! the contact point, along +x; in slip with direction `s = sign(v_rel)` it is `f = −s·μ_d(|v_rel|)·N`
//! (seed eq. 4); in stick it is whatever keeps `v_rel = 0`, limited by `|f| ≤ μ_s·N` (seed eq. 5, the
//! set-valued `Sign`).

use serde::{Deserialize, Serialize};

/// A friction law: dynamic coefficient `μ_d(|v|)` for `|v| > 0` and static coefficient `μ_s`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "snake_case", deny_unknown_fields)]
pub enum FrictionLaw {
    /// The seed's law, eq. (4)–(5): `μ_d = A·exp(−B|v|) + C`, `μ_s = A + C`.
    /// Same shape as COMSOL's "exponential dynamic Coulomb" and Modelica's Stribeck term
    /// (physics.md §1.3). `b_s_per_m` is B in s/m.
    Exponential { a: f64, b_s_per_m: f64, c: f64 },
    /// Coulomb friction with a static/kinetic jump: `μ_d = mu_k`, `μ_s = mu_s` (physics.md §3.1).
    Coulomb { mu_s: f64, mu_k: f64 },
    /// Leine et al. (1998): `μ_d = mu_s / (1 + δ|v|)`, `μ_s = mu_s` (physics.md §3.3).
    Leine { mu_s: f64, delta_s_per_m: f64 },
}

impl FrictionLaw {
    /// Dynamic coefficient at slip speed `speed_m_per_s ≥ 0` (its magnitude; the sign is the slip
    /// direction's). At `speed = 0` this is the limit from the slip side, `μ_d(0⁺)`.
    #[inline]
    pub fn mu_slip(&self, speed_m_per_s: f64) -> f64 {
        self.mu_slip_along(1.0, speed_m_per_s.abs())
    }

    /// Dynamic coefficient in the slip phase of direction `s` (±1) at slip velocity
    /// `v_m_per_s`: `μ_d(s·v)`, with the law continued smoothly to `s·v < 0`.
    ///
    /// For `s·v ≥ 0` this is [`FrictionLaw::mu_slip`]. The continuation is read only at an
    /// integrator's trial states just past the end of slip (`s·v = 0`, the event that ends the
    /// phase, is located on the dense output and the solution is cut there). With `μ_d(|v|)`
    /// instead, a step that crosses the event sees a kink in the right-hand side, and the error
    /// estimate rejects it until the step no longer crosses: the step size collapses geometrically
    /// onto every slip-to-stick transition (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.6,
    /// "discontinuous right-hand sides"). The seed's law continues analytically
    /// (`A·exp(−B·s·v) + C`), Coulomb's is constant, and Leine's `μ_s/(1 + δ·s·v)` is continued
    /// analytically down to `s·v = −1/(2δ)` (where it is `2μ_s`) and held there, far from any
    /// trial state.
    #[inline]
    pub fn mu_slip_along(&self, s: f64, v_m_per_s: f64) -> f64 {
        let u = s * v_m_per_s;
        match *self {
            FrictionLaw::Exponential { a, b_s_per_m, c } => a * (-b_s_per_m * u).exp() + c,
            FrictionLaw::Coulomb { mu_k, .. } => mu_k,
            FrictionLaw::Leine {
                mu_s,
                delta_s_per_m,
            } => mu_s / (1.0 + delta_s_per_m * u).max(0.5),
        }
    }

    /// Derivative `dμ_d/d|v|` at slip speed `speed_m_per_s` (s/m); `−A·B` at 0⁺ for the seed's law.
    #[inline]
    pub fn mu_slip_slope(&self, speed_m_per_s: f64) -> f64 {
        let v = speed_m_per_s.abs();
        match *self {
            FrictionLaw::Exponential { a, b_s_per_m, .. } => {
                -a * b_s_per_m * (-b_s_per_m * v).exp()
            }
            FrictionLaw::Coulomb { .. } => 0.0,
            FrictionLaw::Leine {
                mu_s,
                delta_s_per_m,
            } => -mu_s * delta_s_per_m / (1.0 + delta_s_per_m * v).powi(2),
        }
    }

    /// Static coefficient `μ_s`: the radius of the set-valued law at zero slip speed.
    #[inline]
    pub fn mu_static(&self) -> f64 {
        match *self {
            FrictionLaw::Exponential { a, c, .. } => a + c,
            FrictionLaw::Coulomb { mu_s, .. } | FrictionLaw::Leine { mu_s, .. } => mu_s,
        }
    }

    /// Signed dynamic coefficient of seed eq. (4): `sign(v)·μ_d(|v|)`; 0 at `v = 0` (where the law is
    /// set-valued, see [`FrictionLaw::mu_static`]).
    pub fn mu_signed(&self, v_m_per_s: f64) -> f64 {
        if v_m_per_s == 0.0 {
            0.0
        } else {
            v_m_per_s.signum() * self.mu_slip(v_m_per_s)
        }
    }

    /// Checks that the coefficients are finite and physical (`μ_s > 0`, `μ_d ≥ 0`, rates ≥ 0).
    pub fn validate(&self) -> Result<(), super::ParamError> {
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        match *self {
            FrictionLaw::Exponential { a, b_s_per_m, c } => {
                if !(ok(a) && ok(b_s_per_m) && ok(c) && a + c > 0.0) {
                    return Err(super::ParamError::Exponential { a, b_s_per_m, c });
                }
            }
            FrictionLaw::Coulomb { mu_s, mu_k } => {
                if !(ok(mu_s) && ok(mu_k) && mu_s > 0.0 && mu_k <= mu_s) {
                    return Err(super::ParamError::Coulomb { mu_s, mu_k });
                }
            }
            FrictionLaw::Leine {
                mu_s,
                delta_s_per_m,
            } => {
                if !(ok(mu_s) && ok(delta_s_per_m) && mu_s > 0.0) {
                    return Err(super::ParamError::Leine {
                        mu_s,
                        delta_s_per_m,
                    });
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The continued law is the slip law on its side of zero, and past zero it continues with
    /// the value and the slope of the law at `0⁺` (one-sided difference quotients; the slope at 0
    /// is `−A·B` for the seed's law, `−μ_s·δ` for Leine's, physics.md §2.2, §3.3).
    #[test]
    fn continued_slip_law_is_smooth_through_zero_slip_speed() {
        let laws = [
            FrictionLaw::Exponential {
                a: 0.8,
                b_s_per_m: 10.0,
                c: 0.2,
            },
            FrictionLaw::Coulomb {
                mu_s: 0.6,
                mu_k: 0.4,
            },
            FrictionLaw::Leine {
                mu_s: 1.0,
                delta_s_per_m: 3.0,
            },
        ];
        for law in laws {
            for s in [1.0, -1.0] {
                for v in [0.0, 1e-3, 0.05, 0.3] {
                    assert_eq!(law.mu_slip_along(s, s * v), law.mu_slip(v), "{law:?}");
                }
                let d = 1e-7;
                let at0 = law.mu_slip_along(s, 0.0);
                let below = (at0 - law.mu_slip_along(s, -s * d)) / d;
                let above = (law.mu_slip_along(s, s * d) - at0) / d;
                let slope = law.mu_slip_slope(0.0);
                assert!(
                    (below - slope).abs() < 1e-4 * slope.abs().max(1.0),
                    "{law:?}"
                );
                assert!(
                    (above - slope).abs() < 1e-4 * slope.abs().max(1.0),
                    "{law:?}"
                );
                // The kinked law this replaces has the opposite slope past zero.
                if slope != 0.0 {
                    let kinked = (at0 - law.mu_slip(d)) / d;
                    assert!((kinked + slope).abs() < 1e-4 * slope.abs(), "{law:?}");
                }
            }
        }
        // Leine's continuation is held at 2·μ_s from s·v = −1/(2δ) on, finite everywhere.
        let leine = laws[2];
        assert_eq!(leine.mu_slip_along(1.0, -10.0), 2.0);
    }

    /// Values from physics.md §2.2 for the candidate wet law A = 0.8, B = 10 s/m, C = 0.2:
    /// μ(0) = 1.00, μ(0.05) = 0.69, μ(0.1) = 0.49, μ(0.3) = 0.24 (two decimals), slope −A·B = −8.
    #[test]
    fn seed_law_matches_physics_notes_table() {
        let law = FrictionLaw::Exponential {
            a: 0.8,
            b_s_per_m: 10.0,
            c: 0.2,
        };
        assert_eq!(law.mu_static(), 1.0);
        assert!((law.mu_slip(0.0) - 1.0).abs() < 1e-15);
        for (v, mu) in [(0.05, 0.69), (0.1, 0.49), (0.3, 0.24)] {
            assert!(
                (law.mu_slip(v) - mu).abs() < 0.005,
                "mu({v}) = {}",
                law.mu_slip(v)
            );
        }
        // Closed form: 0.8·e^{-0.5} + 0.2 = 0.685224527...
        assert!((law.mu_slip(0.05) - (0.8 * (-0.5f64).exp() + 0.2)).abs() < 1e-15);
        assert!((law.mu_slip_slope(0.0) + 8.0).abs() < 1e-12);
        // Eq. (4): odd in v, continuous with μ_s at 0⁺ (no static/kinetic jump in the seed's law).
        assert_eq!(law.mu_signed(-0.1), -law.mu_signed(0.1));
        assert_eq!(law.mu_signed(0.0), 0.0);
        // High-speed asymptote is C.
        assert!((law.mu_slip(10.0) - 0.2).abs() < 1e-12);
    }

    #[test]
    fn slope_matches_finite_difference() {
        let law = FrictionLaw::Leine {
            mu_s: 1.0,
            delta_s_per_m: 3.0,
        };
        let h = 1e-6;
        let fd = (law.mu_slip(0.2 + h) - law.mu_slip(0.2 - h)) / (2.0 * h);
        assert!((fd - law.mu_slip_slope(0.2)).abs() < 1e-8);
    }

    #[test]
    fn validation_rejects_unphysical() {
        assert!(
            FrictionLaw::Exponential {
                a: -1.0,
                b_s_per_m: 1.0,
                c: 0.1
            }
            .validate()
            .is_err()
        );
        assert!(
            FrictionLaw::Coulomb {
                mu_s: 0.5,
                mu_k: 0.6
            }
            .validate()
            .is_err()
        );
    }
}
