//! The mass-on-a-moving-belt stick–slip oscillator: the benchmark family with closed-form or
//! tabulated reference solutions (physics.md §3.1–3.4, reference numbers in §0.4).
//!
//! `m ẍ + c ẋ + k x = f`, slip velocity `γ = ẋ − v_b`; slip friction `f = −sign(γ) μ_d(|γ|) N`, stick
//! `ẋ = v_b` with `|f| ≤ μ_s N`. It implements the same [`StickSlipModel`] as the blade, so the
//! benchmarks exercise exactly the blade's event machinery. State `[x, ẋ]` (m, m/s).

use super::friction::FrictionLaw;
use super::stick_slip::{Contact, Mode, ModelFault, StickSlipModel};

/// A block on a belt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Belt {
    pub mass_kg: f64,
    pub k_n_per_m: f64,
    pub c_ns_per_m: f64,
    pub v_belt_m_per_s: f64,
    pub normal_n: f64,
    pub law: FrictionLaw,
}

impl StickSlipModel<2> for Belt {
    #[inline]
    fn rhs(
        &self,
        mode: &Mode,
        _t: f64,
        y: &[f64; 2],
        dy: &mut [f64; 2],
    ) -> std::result::Result<Contact, ModelFault> {
        let spring = -self.k_n_per_m * y[0] - self.c_ns_per_m * y[1];
        let limit = self.law.mu_static() * self.normal_n;
        dy[0] = y[1];
        match mode.phase.slip_dir() {
            Some(s) => {
                let v_slip = y[1] - self.v_belt_m_per_s;
                let f = -s * self.law.mu_slip_along(s, v_slip) * self.normal_n;
                dy[1] = (spring + f) / self.mass_kg;
                Ok(Contact {
                    normal: self.normal_n,
                    friction: f,
                    limit,
                    slip_velocity: Some(v_slip),
                })
            }
            None => {
                // ẍ = 0: friction balances the spring and damper.
                dy[1] = 0.0;
                Ok(Contact {
                    normal: self.normal_n,
                    friction: -spring,
                    limit,
                    slip_velocity: None,
                })
            }
        }
    }

    fn slip_velocity(&self, _t: f64, y: &[f64; 2]) -> f64 {
        y[1] - self.v_belt_m_per_s
    }

    fn contact_position(&self, t: f64, y: &[f64; 2]) -> f64 {
        y[0] - self.v_belt_m_per_s * t
    }

    fn enter_stick(&self, _t: f64, y: &mut [f64; 2], _anchor: f64) {
        y[1] = self.v_belt_m_per_s;
    }

    fn describe(&self, _t: f64, y: &[f64; 2]) -> String {
        format!("x = {:.9e} m, ẋ = {:.9e} m/s", y[0], y[1])
    }
}
