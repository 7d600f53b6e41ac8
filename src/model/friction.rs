//! Friction laws: the slip (dynamic) coefficient as a function of slip speed and the static limit.
//!
//! The contact convention used throughout wiperlab: `f` is the tangential force the surface exerts on
//! the contact point, along +x; in slip with direction `s = sign(v_rel)` it is `f = −s·μ_d(|v_rel|)·N`
//! (seed eq. 4); in stick it is whatever keeps `v_rel = 0`, limited by `|f| ≤ μ_s·N` (seed eq. 5, the
//! set-valued `Sign`).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::ParamId;
use super::error::FrictionTableError;

/// A friction law: dynamic coefficient `μ_d(|v|)` for `|v| > 0` and static coefficient `μ_s`.
///
/// A blade file names the law with `law = "..."` and gives its coefficients under the keys of
/// [`FrictionLaw::LAWS`] (docs/blade.md, "[friction]").
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "law", rename_all = "snake_case")]
pub enum FrictionLaw {
    /// The seed's law, eq. (4)–(5): `μ_d = A·exp(−B|v|) + C`, `μ_s = A + C`.
    /// Same shape as COMSOL's "exponential dynamic Coulomb" and Modelica's Stribeck term
    /// (physics.md §1.3). `b_s_per_m` is B in s/m.
    Exponential { a: f64, b_s_per_m: f64, c: f64 },
    /// The seed's law with a viscous term: `μ_d = A·exp(−B|v|) + C + D|v|`, `μ_s = A + C`
    /// (the Stribeck curve's rise at speed, Armstrong-Hélouvry, Dupont & Canudas de Wit 1994,
    /// Automatica 30(7), §2). `d_s_per_m` is D in s/m; D = 0 is [`FrictionLaw::Exponential`].
    ExponentialViscous {
        a: f64,
        b_s_per_m: f64,
        c: f64,
        d_s_per_m: f64,
    },
    /// Stribeck's curve with a shape exponent (Armstrong-Hélouvry, Dupont & Canudas de Wit 1994,
    /// Automatica 30(7), §2): `μ_d = C + A·exp(−(|v|/v_s)^δ)`, `μ_s = A + C`, with the Stribeck
    /// speed `v_s` in m/s and the exponent δ > 0. δ = 1 is [`FrictionLaw::Exponential`] with
    /// B = 1/v_s; δ = 2 is the Gaussian form; δ < 1 starts with an infinite slope at `0⁺`.
    Stribeck {
        a: f64,
        c: f64,
        v_s_m_per_s: f64,
        delta: f64,
    },
    /// Coulomb friction with a static/kinetic jump: `μ_d = mu_k`, `μ_s = mu_s` (physics.md §3.1).
    Coulomb { mu_s: f64, mu_k: f64 },
    /// Leine et al. (1998): `μ_d = mu_s / (1 + δ|v|)`, `μ_s = mu_s` (physics.md §3.3).
    Leine { mu_s: f64, delta_s_per_m: f64 },
}

impl FrictionLaw {
    /// Every law's name in a blade file (`law = "..."`) and the coefficient keys it needs, in the
    /// order docs/blade.md lists them.
    pub const LAWS: [(&'static str, &'static [&'static str]); 5] = [
        ("exponential", &["a", "b_s_per_m", "c"]),
        ("exponential_viscous", &["a", "b_s_per_m", "c", "d_s_per_m"]),
        ("stribeck", &["a", "c", "v_s_m_per_s", "delta"]),
        ("coulomb", &["mu_s", "mu_k"]),
        ("leine", &["mu_s", "delta_s_per_m"]),
    ];

    /// The law's name in a blade file.
    pub fn name(&self) -> &'static str {
        match self {
            FrictionLaw::Exponential { .. } => "exponential",
            FrictionLaw::ExponentialViscous { .. } => "exponential_viscous",
            FrictionLaw::Stribeck { .. } => "stribeck",
            FrictionLaw::Coulomb { .. } => "coulomb",
            FrictionLaw::Leine { .. } => "leine",
        }
    }

    /// The law called `law` with the coefficients `values` (keyed as in a blade file).
    ///
    /// # Errors
    /// [`FrictionTableError`] naming the laws and their keys for an unknown law, and the keys the
    /// law needs for a missing or unknown key.
    pub fn from_coefficients(
        law: &str,
        values: &BTreeMap<String, f64>,
    ) -> Result<FrictionLaw, FrictionTableError> {
        let Some(&(name, keys)) = Self::LAWS.iter().find(|(n, _)| *n == law) else {
            return Err(FrictionTableError::UnknownLaw { law: law.into() });
        };
        let missing: Vec<&'static str> = keys
            .iter()
            .copied()
            .filter(|k| !values.contains_key(*k))
            .collect();
        if let Some(extra) = values.keys().find(|k| !keys.contains(&k.as_str())) {
            return Err(FrictionTableError::UnknownKey {
                law: name,
                key: extra.clone(),
                known: keys.to_vec(),
                missing,
            });
        }
        if !missing.is_empty() {
            return Err(FrictionTableError::MissingKeys {
                law: name,
                known: keys.to_vec(),
                missing,
            });
        }
        let v = |k: &str| values[k];
        Ok(match name {
            "exponential" => FrictionLaw::Exponential {
                a: v("a"),
                b_s_per_m: v("b_s_per_m"),
                c: v("c"),
            },
            "exponential_viscous" => FrictionLaw::ExponentialViscous {
                a: v("a"),
                b_s_per_m: v("b_s_per_m"),
                c: v("c"),
                d_s_per_m: v("d_s_per_m"),
            },
            "stribeck" => FrictionLaw::Stribeck {
                a: v("a"),
                c: v("c"),
                v_s_m_per_s: v("v_s_m_per_s"),
                delta: v("delta"),
            },
            "coulomb" => FrictionLaw::Coulomb {
                mu_s: v("mu_s"),
                mu_k: v("mu_k"),
            },
            _ => FrictionLaw::Leine {
                mu_s: v("mu_s"),
                delta_s_per_m: v("delta_s_per_m"),
            },
        })
    }

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
    /// "discontinuous right-hand sides"). The seed's law and its viscous form continue
    /// analytically (`A·exp(−B·s·v) + C + D·s·v`), Coulomb's is constant, Stribeck's continues
    /// with the exponent odd in `s·v` (`C + A·exp(−sign(u)(|u|/v_s)^δ)`, `u = s·v`: value and
    /// slope continuous for δ ≥ 1, the seed's continuation at δ = 1), and Leine's
    /// `μ_s/(1 + δ·s·v)` is continued analytically down to `s·v = −1/(2δ)` (where it is `2μ_s`)
    /// and held there, far from any trial state.
    #[inline]
    pub fn mu_slip_along(&self, s: f64, v_m_per_s: f64) -> f64 {
        let u = s * v_m_per_s;
        match *self {
            FrictionLaw::Exponential { a, b_s_per_m, c } => a * (-b_s_per_m * u).exp() + c,
            FrictionLaw::ExponentialViscous {
                a,
                b_s_per_m,
                c,
                d_s_per_m,
            } => a * (-b_s_per_m * u).exp() + c + d_s_per_m * u,
            FrictionLaw::Stribeck {
                a,
                c,
                v_s_m_per_s,
                delta,
            } => c + a * (-u.signum() * (u.abs() / v_s_m_per_s).powf(delta)).exp(),
            FrictionLaw::Coulomb { mu_k, .. } => mu_k,
            FrictionLaw::Leine {
                mu_s,
                delta_s_per_m,
            } => mu_s / (1.0 + delta_s_per_m * u).max(0.5),
        }
    }

    /// Derivative `dμ_d/d|v|` at slip speed `speed_m_per_s` (s/m); `−A·B` at 0⁺ for the seed's law,
    /// `−A·B + D` for its viscous form; Stribeck's is `−A/v_s` at 0⁺ for δ = 1, 0 for δ > 1 and
    /// −∞ for δ < 1.
    #[inline]
    pub fn mu_slip_slope(&self, speed_m_per_s: f64) -> f64 {
        let v = speed_m_per_s.abs();
        match *self {
            FrictionLaw::Exponential { a, b_s_per_m, .. } => {
                -a * b_s_per_m * (-b_s_per_m * v).exp()
            }
            FrictionLaw::ExponentialViscous {
                a,
                b_s_per_m,
                d_s_per_m,
                ..
            } => -a * b_s_per_m * (-b_s_per_m * v).exp() + d_s_per_m,
            FrictionLaw::Stribeck {
                a,
                v_s_m_per_s,
                delta,
                ..
            } => {
                let x = v / v_s_m_per_s;
                -a * delta / v_s_m_per_s * x.powf(delta - 1.0) * (-x.powf(delta)).exp()
            }
            FrictionLaw::Coulomb { .. } => 0.0,
            FrictionLaw::Leine {
                mu_s,
                delta_s_per_m,
            } => -mu_s * delta_s_per_m / (1.0 + delta_s_per_m * v).powi(2),
        }
    }

    /// The derivatives `∂μ_d/∂θ` of the dynamic coefficient at slip speed `speed_m_per_s` with
    /// respect to each of the law's coefficients θ that a fit can free, by their [`ParamId`]
    /// (closed forms; empty for Coulomb's and Leine's laws, which a fit does not free).
    pub fn mu_slip_gradient(&self, speed_m_per_s: f64) -> Vec<(ParamId, f64)> {
        let v = speed_m_per_s.abs();
        match *self {
            FrictionLaw::Exponential { a, b_s_per_m, .. } => {
                let e = (-b_s_per_m * v).exp();
                vec![(ParamId::A, e), (ParamId::B, -a * v * e), (ParamId::C, 1.0)]
            }
            FrictionLaw::ExponentialViscous { a, b_s_per_m, .. } => {
                let e = (-b_s_per_m * v).exp();
                vec![
                    (ParamId::A, e),
                    (ParamId::B, -a * v * e),
                    (ParamId::C, 1.0),
                    (ParamId::D, v),
                ]
            }
            FrictionLaw::Stribeck {
                a,
                v_s_m_per_s,
                delta,
                ..
            } => {
                // With x = v/v_s and E = exp(−x^δ): ∂/∂v_s = A·E·δ·x^δ/v_s, ∂/∂δ = −A·E·x^δ·ln x
                // (0 at x = 0, where x^δ·ln x → 0 for δ > 0).
                let x = v / v_s_m_per_s;
                let xd = x.powf(delta);
                let e = (-xd).exp();
                let x_ln_x = if x > 0.0 { xd * x.ln() } else { 0.0 };
                vec![
                    (ParamId::A, e),
                    (ParamId::C, 1.0),
                    (ParamId::Delta, -a * e * x_ln_x),
                    (ParamId::Vs, a * e * delta * xd / v_s_m_per_s),
                ]
            }
            FrictionLaw::Coulomb { .. } | FrictionLaw::Leine { .. } => Vec::new(),
        }
    }

    /// Static coefficient `μ_s`: the radius of the set-valued law at zero slip speed.
    #[inline]
    pub fn mu_static(&self) -> f64 {
        match *self {
            FrictionLaw::Exponential { a, c, .. }
            | FrictionLaw::ExponentialViscous { a, c, .. }
            | FrictionLaw::Stribeck { a, c, .. } => a + c,
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

    /// Checks that the coefficients are finite and physical (`μ_s > 0`, `μ_d ≥ 0`, rates ≥ 0,
    /// Stribeck's speed and exponent > 0).
    pub fn validate(&self) -> Result<(), super::ParamError> {
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        let positive = |x: f64| x.is_finite() && x > 0.0;
        match *self {
            FrictionLaw::Exponential { a, b_s_per_m, c } => {
                if !(ok(a) && ok(b_s_per_m) && ok(c) && a + c > 0.0) {
                    return Err(super::ParamError::Exponential { a, b_s_per_m, c });
                }
            }
            FrictionLaw::ExponentialViscous {
                a,
                b_s_per_m,
                c,
                d_s_per_m,
            } => {
                if !(ok(a) && ok(b_s_per_m) && ok(c) && ok(d_s_per_m) && a + c > 0.0) {
                    return Err(super::ParamError::ExponentialViscous {
                        a,
                        b_s_per_m,
                        c,
                        d_s_per_m,
                    });
                }
            }
            FrictionLaw::Stribeck {
                a,
                c,
                v_s_m_per_s,
                delta,
            } => {
                if !(ok(a) && ok(c) && positive(v_s_m_per_s) && positive(delta) && a + c > 0.0) {
                    return Err(super::ParamError::Stribeck {
                        a,
                        c,
                        v_s_m_per_s,
                        delta,
                    });
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

crate::names::named_enum! {
    /// The friction laws a fit can free and compare as candidates (`[fit] laws`, docs/job.md):
    /// the kinds of [`FrictionLaw`] whose coefficients a fit can move. Declared nested first: the
    /// exponential law is the viscous form at D = 0 and Stribeck's at δ = 1, v_s = 1/B.
    pub enum LawKind: "friction law" {
        /// [`FrictionLaw::Exponential`].
        Exponential => "exponential",
        /// [`FrictionLaw::ExponentialViscous`].
        ExponentialViscous => "exponential_viscous",
        /// [`FrictionLaw::Stribeck`].
        Stribeck => "stribeck",
    }
}

impl LawKind {
    /// The law's coefficients a fit can free, in [`ParamId`] order.
    pub fn coefficients(self) -> &'static [ParamId] {
        match self {
            LawKind::Exponential => &[ParamId::A, ParamId::B, ParamId::C],
            LawKind::ExponentialViscous => &[ParamId::A, ParamId::B, ParamId::C, ParamId::D],
            LawKind::Stribeck => &[ParamId::A, ParamId::C, ParamId::Delta, ParamId::Vs],
        }
    }

    /// Whether the law contains `smaller` as a special case (the viscous form at D = 0 and
    /// Stribeck's at δ = 1 contain the exponential law); a law does not contain itself.
    pub fn contains(self, smaller: LawKind) -> bool {
        smaller == LawKind::Exponential && self != LawKind::Exponential
    }
}

impl FrictionLaw {
    /// The law's kind, when a fit can free its coefficients (not Coulomb's or Leine's).
    pub fn kind(&self) -> Option<LawKind> {
        match self {
            FrictionLaw::Exponential { .. } => Some(LawKind::Exponential),
            FrictionLaw::ExponentialViscous { .. } => Some(LawKind::ExponentialViscous),
            FrictionLaw::Stribeck { .. } => Some(LawKind::Stribeck),
            FrictionLaw::Coulomb { .. } | FrictionLaw::Leine { .. } => None,
        }
    }

    /// This law written as a law of kind `kind`, with the same μ_s, C and A: the exponential law
    /// becomes the viscous form with D = 0 and Stribeck's with δ = 1, v_s = 1/B (the same curve,
    /// [`LawKind::contains`]); from a larger law the extra term is dropped (D, or δ with
    /// B = 1/v_s). `None` for Coulomb's and Leine's laws.
    pub fn as_kind(&self, kind: LawKind) -> Option<FrictionLaw> {
        let (a, b_s_per_m, c) = match *self {
            FrictionLaw::Exponential { a, b_s_per_m, c }
            | FrictionLaw::ExponentialViscous {
                a, b_s_per_m, c, ..
            } => (a, b_s_per_m, c),
            FrictionLaw::Stribeck {
                a, c, v_s_m_per_s, ..
            } => (a, 1.0 / v_s_m_per_s, c),
            FrictionLaw::Coulomb { .. } | FrictionLaw::Leine { .. } => return None,
        };
        if self.kind() == Some(kind) {
            return Some(*self);
        }
        Some(match kind {
            LawKind::Exponential => FrictionLaw::Exponential { a, b_s_per_m, c },
            LawKind::ExponentialViscous => FrictionLaw::ExponentialViscous {
                a,
                b_s_per_m,
                c,
                d_s_per_m: 0.0,
            },
            LawKind::Stribeck => FrictionLaw::Stribeck {
                a,
                c,
                v_s_m_per_s: 1.0 / b_s_per_m,
                delta: 1.0,
            },
        })
    }
}

/// Reads a `[friction]` table: `law = "..."` and the law's coefficients as numbers, with errors
/// that name the keys each law needs ([`FrictionLaw::from_coefficients`]).
impl<'de> Deserialize<'de> for FrictionLaw {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Table;
        impl<'de> serde::de::Visitor<'de> for Table {
            type Value = FrictionLaw;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a friction table: law = \"...\" and the law's coefficients")
            }
            fn visit_map<M: serde::de::MapAccess<'de>>(
                self,
                mut map: M,
            ) -> Result<FrictionLaw, M::Error> {
                use serde::de::Error;
                let mut law: Option<String> = None;
                let mut values = BTreeMap::new();
                while let Some(key) = map.next_key::<String>()? {
                    if key == "law" {
                        law = Some(map.next_value()?);
                    } else {
                        let v: f64 = map.next_value()?;
                        if values.insert(key.clone(), v).is_some() {
                            return Err(M::Error::custom(format!("duplicate key `{key}`")));
                        }
                    }
                }
                let Some(law) = law else {
                    return Err(M::Error::custom(format!(
                        "the friction table needs law = \"...\" (known: {})",
                        FrictionLaw::LAWS.map(|(n, _)| n).join(", ")
                    )));
                };
                FrictionLaw::from_coefficients(&law, &values).map_err(M::Error::custom)
            }
        }
        d.deserialize_map(Table)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The continued law is the slip law on its side of zero, and past zero it continues with
    /// the value and the slope of the law at `0⁺` (one-sided difference quotients; the slope at 0
    /// is `−A·B` for the seed's law, `−μ_s·δ` for Leine's, physics.md §2.2, §3.3; `−A·B + D` with the
    /// viscous term; `−A/v_s` for Stribeck's with δ = 1 and 0 with δ = 2).
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
            FrictionLaw::ExponentialViscous {
                a: 0.8,
                b_s_per_m: 10.0,
                c: 0.2,
                d_s_per_m: 0.3,
            },
            FrictionLaw::Stribeck {
                a: 0.8,
                c: 0.2,
                v_s_m_per_s: 0.1,
                delta: 1.0,
            },
            FrictionLaw::Stribeck {
                a: 0.8,
                c: 0.2,
                v_s_m_per_s: 0.1,
                delta: 2.0,
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

    /// Stribeck's law with δ = 1 is the seed's law with B = 1/v_s (the same closed form), to the
    /// rounding of B·v against v/v_s: value, continuation on both sides, slope and μ_s.
    #[test]
    fn stribeck_with_unit_exponent_is_the_exponential_law() {
        let (a, c, v_s) = (0.8, 0.2, 0.07);
        let stribeck = FrictionLaw::Stribeck {
            a,
            c,
            v_s_m_per_s: v_s,
            delta: 1.0,
        };
        let exponential = FrictionLaw::Exponential {
            a,
            b_s_per_m: 1.0 / v_s,
            c,
        };
        assert_eq!(stribeck.mu_static(), exponential.mu_static());
        for v in [0.0, 1e-4, 0.01, 0.05, 0.1, 0.3, 1.0] {
            assert!((stribeck.mu_slip(v) - exponential.mu_slip(v)).abs() < 1e-15);
            for s in [1.0, -1.0] {
                let (x, y) = (
                    stribeck.mu_slip_along(s, -s * v),
                    exponential.mu_slip_along(s, -s * v),
                );
                assert!((x - y).abs() < 1e-15 * y, "{v}: {x} against {y}");
            }
            let (x, y) = (stribeck.mu_slip_slope(v), exponential.mu_slip_slope(v));
            assert!((x - y).abs() < 1e-14 * y.abs(), "{v}: {x} against {y}");
        }
    }

    /// The viscous form with D = 0 is the seed's law exactly (the same floating-point operations
    /// plus 0); with D > 0 it adds D|v| (closed form 0.8·e^{−0.5} + 0.2 + 0.3·0.05 at 5 cm/s).
    #[test]
    fn viscous_law_adds_its_linear_term() {
        let exponential = FrictionLaw::Exponential {
            a: 0.8,
            b_s_per_m: 10.0,
            c: 0.2,
        };
        let viscous = |d_s_per_m| FrictionLaw::ExponentialViscous {
            a: 0.8,
            b_s_per_m: 10.0,
            c: 0.2,
            d_s_per_m,
        };
        for v in [0.0, 0.01, 0.05, 0.3, 2.0] {
            assert_eq!(viscous(0.0).mu_slip(v), exponential.mu_slip(v));
            assert_eq!(viscous(0.0).mu_slip_slope(v), exponential.mu_slip_slope(v));
            assert_eq!(
                viscous(0.0).mu_slip_along(-1.0, v),
                exponential.mu_slip_along(-1.0, v)
            );
        }
        let law = viscous(0.3);
        assert_eq!(law.mu_static(), 1.0);
        let closed = 0.8 * (-0.5f64).exp() + 0.2 + 0.3 * 0.05;
        assert!((law.mu_slip(0.05) - closed).abs() < 1e-15);
        assert!((law.mu_slip_slope(0.0) - (-8.0 + 0.3)).abs() < 1e-12);
        // Past the minimum the coefficient rises again: at 1 m/s it is 0.8·e^{−10} + 0.2 + 0.3.
        assert!((law.mu_slip(1.0) - (0.8 * (-10.0f64).exp() + 0.5)).abs() < 1e-15);
    }

    /// The exponential law written as each law a fit compares ([`FrictionLaw::as_kind`]) is the
    /// same curve: the viscous form at D = 0 bitwise (the same operations plus 0), Stribeck's at
    /// δ = 1, v_s = 1/B to round-off (B·v against v/(1/B)); back to the exponential law it is the
    /// law it came from. A larger law drops its extra term; Coulomb's law has no such form.
    #[test]
    fn nested_laws_reduce_to_the_exponential_law() {
        let exponential = FrictionLaw::Exponential {
            a: 0.88,
            b_s_per_m: 69.7,
            c: 0.56,
        };
        let viscous = exponential.as_kind(LawKind::ExponentialViscous).unwrap();
        let stribeck = exponential.as_kind(LawKind::Stribeck).unwrap();
        assert_eq!(viscous.kind(), Some(LawKind::ExponentialViscous));
        assert_eq!(stribeck.kind(), Some(LawKind::Stribeck));
        for v in [0.0, 1e-3, 0.0386, 0.1, 0.168, 0.5] {
            assert_eq!(viscous.mu_slip(v), exponential.mu_slip(v));
            let (x, y) = (stribeck.mu_slip(v), exponential.mu_slip(v));
            assert!(
                (x - y).abs() <= 2.0 * f64::EPSILON * y,
                "{v}: {x} against {y}"
            );
        }
        for law in [viscous, stribeck, exponential] {
            let back = law.as_kind(LawKind::Exponential).unwrap();
            assert_eq!(back.kind(), Some(LawKind::Exponential));
            assert_eq!(back.mu_static(), exponential.mu_static());
            assert!(
                (back.mu_slip(0.1) - exponential.mu_slip(0.1)).abs() < 1e-15,
                "{law:?}"
            );
        }
        let with_d = FrictionLaw::ExponentialViscous {
            a: 0.88,
            b_s_per_m: 69.7,
            c: 0.56,
            d_s_per_m: 0.36,
        };
        assert_eq!(with_d.as_kind(LawKind::Exponential), Some(exponential));
        assert_eq!(with_d.as_kind(LawKind::ExponentialViscous), Some(with_d));
        let coulomb = FrictionLaw::Coulomb {
            mu_s: 0.6,
            mu_k: 0.4,
        };
        assert_eq!(coulomb.as_kind(LawKind::Exponential), None);
        assert_eq!(coulomb.kind(), None);
        assert!(LawKind::Stribeck.contains(LawKind::Exponential));
        assert!(!LawKind::Exponential.contains(LawKind::Exponential));
        assert!(!LawKind::Stribeck.contains(LawKind::ExponentialViscous));
    }

    /// Stribeck's law at its speed v_s is C + A/e for every δ (closed form), falls to C at speed
    /// (to e^{−√1000} at 100 m/s for the smallest δ), and its slope at 0⁺ is 0 for δ > 1, −A/v_s for
    /// δ = 1, −∞ for δ < 1.
    #[test]
    fn stribeck_law_matches_its_closed_form() {
        let law = |delta| FrictionLaw::Stribeck {
            a: 0.8,
            c: 0.2,
            v_s_m_per_s: 0.1,
            delta,
        };
        for delta in [0.5, 1.0, 2.0, 3.5] {
            let l = law(delta);
            assert_eq!(l.mu_static(), 1.0);
            assert!((l.mu_slip(0.0) - 1.0).abs() < 1e-15);
            assert!((l.mu_slip(0.1) - (0.2 + 0.8 / std::f64::consts::E)).abs() < 1e-15);
            assert!((l.mu_slip(100.0) - 0.2).abs() < 1e-12);
        }
        // δ = 2 at v = 0.05: 0.2 + 0.8·e^{−0.25}.
        assert!((law(2.0).mu_slip(0.05) - (0.2 + 0.8 * (-0.25f64).exp())).abs() < 1e-15);
        assert_eq!(law(2.0).mu_slip_slope(0.0), 0.0);
        assert!((law(1.0).mu_slip_slope(0.0) + 8.0).abs() < 1e-12);
        assert_eq!(law(0.5).mu_slip_slope(0.0), f64::NEG_INFINITY);
    }

    /// The slope of every law against a central difference of its value (step 1e-6 m/s: truncation
    /// O(h²) and rounding O(1e-16/h) both far below the tolerance), at slip speeds across the
    /// falling and rising branches.
    #[test]
    fn slopes_match_central_differences() {
        let laws = [
            FrictionLaw::Exponential {
                a: 0.8,
                b_s_per_m: 10.0,
                c: 0.2,
            },
            FrictionLaw::ExponentialViscous {
                a: 0.8,
                b_s_per_m: 10.0,
                c: 0.2,
                d_s_per_m: 0.3,
            },
            FrictionLaw::Stribeck {
                a: 0.8,
                c: 0.2,
                v_s_m_per_s: 0.1,
                delta: 0.6,
            },
            FrictionLaw::Stribeck {
                a: 0.8,
                c: 0.2,
                v_s_m_per_s: 0.1,
                delta: 1.0,
            },
            FrictionLaw::Stribeck {
                a: 0.8,
                c: 0.2,
                v_s_m_per_s: 0.1,
                delta: 2.0,
            },
            FrictionLaw::Leine {
                mu_s: 1.0,
                delta_s_per_m: 3.0,
            },
        ];
        let h = 1e-6;
        for law in laws {
            for v in [0.01, 0.05, 0.1, 0.2, 0.5] {
                let fd = (law.mu_slip(v + h) - law.mu_slip(v - h)) / (2.0 * h);
                let slope = law.mu_slip_slope(v);
                assert!(
                    (fd - slope).abs() < 1e-7 * slope.abs().max(1.0),
                    "{law:?} at {v}: {fd} against {slope}"
                );
            }
        }
    }

    /// Each coefficient's derivative against a central difference in that coefficient (set
    /// through [`ParamId::set`] on a blade carrying the law; relative step 1e-6), for every law a
    /// fit can free, at rest and across the falling branch; exactly the laws' coefficients appear.
    #[test]
    fn coefficient_gradients_match_central_differences() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/data/paper/seed_experiment_blade.toml"
        );
        let blade: super::super::BladeParams =
            toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let laws = [
            FrictionLaw::Exponential {
                a: 0.8,
                b_s_per_m: 10.0,
                c: 0.2,
            },
            FrictionLaw::ExponentialViscous {
                a: 0.8,
                b_s_per_m: 10.0,
                c: 0.2,
                d_s_per_m: 0.3,
            },
            FrictionLaw::Stribeck {
                a: 0.8,
                c: 0.2,
                v_s_m_per_s: 0.1,
                delta: 1.7,
            },
        ];
        for law in laws {
            let mut p = blade;
            p.friction = law;
            let ids: Vec<ParamId> = law.mu_slip_gradient(0.1).iter().map(|g| g.0).collect();
            let has: Vec<ParamId> = ParamId::ALL
                .iter()
                .copied()
                .filter(|id| id.is_friction() && id.get(&p).is_some())
                .collect();
            assert_eq!(ids, has, "{law:?}");
            for v in [0.0, 0.02, 0.1, 0.3] {
                for (id, g) in law.mu_slip_gradient(v) {
                    let x = id.get(&p).unwrap();
                    let h = 1e-6 * x.abs();
                    let at = |y: f64| {
                        let mut q = p;
                        id.set(&mut q, y);
                        q.friction.mu_slip(v)
                    };
                    let fd = (at(x + h) - at(x - h)) / (2.0 * h);
                    assert!(
                        (fd - g).abs() < 1e-7 * g.abs().max(1.0),
                        "{law:?}, {id} at {v}: {fd} against {g}"
                    );
                }
            }
        }
    }

    /// A blade file's `[friction]` table: every law reads back what it wrote, and a missing key, an
    /// unknown key or an unknown law is named together with the keys the law needs.
    #[test]
    fn friction_tables_read_with_errors_naming_the_keys() {
        let laws = [
            FrictionLaw::Exponential {
                a: 0.8,
                b_s_per_m: 10.0,
                c: 0.2,
            },
            FrictionLaw::ExponentialViscous {
                a: 0.8,
                b_s_per_m: 10.0,
                c: 0.2,
                d_s_per_m: 0.3,
            },
            FrictionLaw::Stribeck {
                a: 0.8,
                c: 0.2,
                v_s_m_per_s: 0.1,
                delta: 2.0,
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
            let text = toml::to_string(&law).unwrap();
            assert!(
                text.contains(&format!("law = \"{}\"", law.name())),
                "{text}"
            );
            let back: FrictionLaw = toml::from_str(&text).unwrap();
            assert_eq!(back, law);
        }
        let read = |text: &str| toml::from_str::<FrictionLaw>(text).unwrap_err().to_string();
        let e = read("law = \"stribeck\"\na = 0.8\nc = 0.2\ndelta = 2\n");
        assert!(
            e.contains("needs a, c, v_s_m_per_s, delta; missing v_s_m_per_s"),
            "{e}"
        );
        let e = read("law = \"exponential\"\na = 0.8\nb_s_per_m = 10\nc = 0.2\nd_s_per_m = 1\n");
        assert!(
            e.contains("no key `d_s_per_m` (known: a, b_s_per_m, c)"),
            "{e}"
        );
        let e = read("law = \"stribek\"\na = 0.8\n");
        assert!(
            e.contains("stribeck (a, c, v_s_m_per_s, delta)") && e.contains("`stribek`"),
            "{e}"
        );
        let e = read("a = 0.8\n");
        assert!(e.contains("needs law ="), "{e}");
        // Integers are numbers too.
        let law: FrictionLaw = toml::from_str("law = \"coulomb\"\nmu_s = 1\nmu_k = 0.5\n").unwrap();
        assert_eq!(law.mu_static(), 1.0);
    }

    #[test]
    fn validation_rejects_unphysical() {
        for bad in [
            FrictionLaw::ExponentialViscous {
                a: 0.8,
                b_s_per_m: 10.0,
                c: 0.2,
                d_s_per_m: -0.1,
            },
            FrictionLaw::Stribeck {
                a: 0.8,
                c: 0.2,
                v_s_m_per_s: 0.0,
                delta: 1.0,
            },
            FrictionLaw::Stribeck {
                a: 0.8,
                c: 0.2,
                v_s_m_per_s: 0.1,
                delta: 0.0,
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
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
