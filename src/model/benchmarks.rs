//! The belt-oscillator benchmark problems of physics.md §3 and their reference values: one place for
//! the fixtures that `wiperlab bench` and the tests share.
//!
//! | problem | physics.md | reference |
//! |---|---|---|
//! | undamped Coulomb belt | §3.1 | closed form ([`CoulombBelt::closed_form`]) |
//! | damped Coulomb belt (ζ = 0.05) | §3.2 | [`DAMPED_COULOMB_REFERENCE`] (§0.4 row 3, semi-analytic) |
//! | Leine's block on a belt | §3.3 | [`LEINE_REFERENCE`] (§0.4, SciPy, 7–8 digits) |
//! | the seed's friction law on a belt | §3.4 | [`SEED_LAW_REFERENCE`] (§0.4, SciPy) |
//!
//! Units: kg, N/m, N·s/m, m/s, s, m.

use super::belt::Belt;
use super::friction::FrictionLaw;
use std::f64::consts::PI;

/// Durations and stick position of one stick–slip limit cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleReference {
    /// Duration of the slip phase, s.
    pub t_slip_s: f64,
    /// Duration of the stick phase, s.
    pub t_stick_s: f64,
    /// Position at the slip→stick transition (x_e in physics.md §3.1), m.
    pub x_stick_onset_m: f64,
}

impl CycleReference {
    /// The cycle's period, s.
    pub fn period_s(&self) -> f64 {
        self.t_slip_s + self.t_stick_s
    }
}

/// The undamped block on a belt with Coulomb friction of physics.md §3.1: `m ẍ + k x = F_f`, normal
/// force 1 N, so that the friction coefficients are forces in N.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoulombBelt {
    pub mass_kg: f64,
    pub k_n_per_m: f64,
    pub v_belt_m_per_s: f64,
    /// Static friction force F_s = μ_s·N, N.
    pub mu_s: f64,
    /// Kinetic friction force F_k = μ_k·N < F_s, N.
    pub mu_k: f64,
}

impl CoulombBelt {
    /// physics.md §3.1's first case: m = 1, k = 4π² (1 Hz), v_b = 0.1, F_s = 1, F_k = 0.6.
    pub const ONE_HZ: CoulombBelt = CoulombBelt {
        mass_kg: 1.0,
        k_n_per_m: 4.0 * PI * PI,
        v_belt_m_per_s: 0.1,
        mu_s: 1.0,
        mu_k: 0.6,
    };

    /// The model (no damping).
    pub fn belt(&self) -> Belt {
        Belt {
            mass_kg: self.mass_kg,
            k_n_per_m: self.k_n_per_m,
            c_ns_per_m: 0.0,
            v_belt_m_per_s: self.v_belt_m_per_s,
            normal_n: 1.0,
            law: FrictionLaw::Coulomb {
                mu_s: self.mu_s,
                mu_k: self.mu_k,
            },
        }
    }

    /// Closed form of physics.md §3.1: `t_slip = (2/ω)(π − atan(ωΔ/v_b))` with `Δ = (F_s − F_k)/k`,
    /// `t_stick = 2(F_s − F_k)/(k v_b)`, `x_e = (2F_k − F_s)/k`.
    pub fn closed_form(&self) -> CycleReference {
        let w = (self.k_n_per_m / self.mass_kg).sqrt();
        let delta = (self.mu_s - self.mu_k) / self.k_n_per_m;
        CycleReference {
            t_slip_s: 2.0 / w * (PI - (w * delta / self.v_belt_m_per_s).atan()),
            t_stick_s: 2.0 * (self.mu_s - self.mu_k) / (self.k_n_per_m * self.v_belt_m_per_s),
            x_stick_onset_m: (2.0 * self.mu_k - self.mu_s) / self.k_n_per_m,
        }
    }

    /// Time of the first stick onset when started in stick at x = 0, ẋ = v_b: the departure at
    /// `x_s/v_b = F_s/(k v_b)` (stick is exact) plus the closed-form slip duration.
    pub fn first_stick_onset_s(&self) -> f64 {
        self.mu_s / self.k_n_per_m / self.v_belt_m_per_s + self.closed_form().t_slip_s
    }
}

/// Leine's block on a belt (physics.md §3.3): m = k = F_s = 1, δ = 3 s/m, v_b = 0.2, undamped,
/// `F = −F_s sgn(γ)/(1 + δ|γ|)`.
pub fn leine_belt() -> Belt {
    Belt {
        mass_kg: 1.0,
        k_n_per_m: 1.0,
        c_ns_per_m: 0.0,
        v_belt_m_per_s: 0.2,
        normal_n: 1.0,
        law: FrictionLaw::Leine {
            mu_s: 1.0,
            delta_s_per_m: 3.0,
        },
    }
}

/// physics.md §0.4 (SciPy, 7–8 digits) for [`leine_belt`].
pub const LEINE_REFERENCE: CycleReference = CycleReference {
    t_slip_s: 4.2959995,
    t_stick_s: 7.7050318,
    x_stick_onset_m: -0.5410064,
};

/// The seed's friction law `μ_d = A e^(−B|v|) + C` on a belt (physics.md §3.4): m = k = N = 1,
/// A = C = 0.5, v_b = 0.2, undamped, with `b_s_per_m` (3 in the reference case).
pub fn seed_law_belt(b_s_per_m: f64) -> Belt {
    Belt {
        mass_kg: 1.0,
        k_n_per_m: 1.0,
        c_ns_per_m: 0.0,
        v_belt_m_per_s: 0.2,
        normal_n: 1.0,
        law: FrictionLaw::Exponential {
            a: 0.5,
            b_s_per_m,
            c: 0.5,
        },
    }
}

/// physics.md §0.4 (SciPy) for [`seed_law_belt`] with B = 3 s/m.
pub const SEED_LAW_REFERENCE: CycleReference = CycleReference {
    t_slip_s: 4.5590598,
    t_stick_s: 4.9039561,
    x_stick_onset_m: 0.0192088,
};

/// The damped Coulomb belt of physics.md §3.2: [`CoulombBelt::ONE_HZ`] with damping ratio 0.05
/// (c = 2ζ√(km)) at belt speed `v_belt_m_per_s` (0.05 in the reference case; at 0.1 it slides
/// steadily without sticking).
pub fn damped_coulomb_belt(v_belt_m_per_s: f64) -> Belt {
    let base = CoulombBelt::ONE_HZ;
    Belt {
        c_ns_per_m: 2.0 * 0.05 * (base.k_n_per_m * base.mass_kg).sqrt(),
        v_belt_m_per_s,
        ..base.belt()
    }
}

/// physics.md §0.4 row 3 (semi-analytic, 7 digits) for [`damped_coulomb_belt`] at v_b = 0.05: the
/// slip and stick durations and the stick position x_e.
pub const DAMPED_COULOMB_REFERENCE: CycleReference = CycleReference {
    t_slip_s: 0.7581836,
    t_stick_s: 0.3128486,
    x_stick_onset_m: 0.0088921,
};

#[cfg(test)]
mod tests {
    use super::*;

    /// physics.md §0.4 tabulates the 1 Hz Coulomb belt's period as 1.0221888 s (7 digits).
    #[test]
    fn coulomb_closed_form_matches_the_tabulated_period() {
        let r = CoulombBelt::ONE_HZ.closed_form();
        assert!((r.period_s() - 1.0221888).abs() < 1e-7, "{r:?}");
    }
}
