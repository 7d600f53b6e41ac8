//! The blade parameters a fit may free, as typed ids with one name each.

use super::{BladeParams, FrictionLaw};
use crate::names::named_enum;

named_enum! {
    /// A blade parameter that a fit job may free (`[fit.parameters]`). Declared in the byte order
    /// of the names, so that a map keyed by `ParamId` iterates as one keyed by the name would.
    pub enum ParamId: "parameter" {
        /// Friction law A of seed eq. (4), 1.
        A => "A",
        /// Friction law B, s/m.
        B => "B",
        /// Friction law C, 1.
        C => "C",
        /// Head damper c0, N·s/m.
        C0 => "c0",
        /// Neck damper c1, N·m·s/rad.
        C1 => "c1",
        /// Lip damper c2, N·m·s/rad.
        C2 => "c2",
        /// Preload compression h_d, m.
        Hd => "hd",
        /// Head spring k0, N/m.
        K0 => "k0",
        /// Neck stiffness k1, N·m/rad.
        K1 => "k1",
        /// Neck stiffness while touching the shoulder, N·m/rad.
        K1c => "k1c",
        /// Lip stiffness k2, N·m/rad.
        K2 => "k2",
        /// Shoulder contact angle, rad.
        ThetaC => "theta_c",
    }
}

impl ParamId {
    /// What the parameter is, with its unit, for help texts and reports.
    pub fn meaning(self) -> &'static str {
        match self {
            ParamId::A => "friction A (seed eq. 4), 1",
            ParamId::B => "friction B, s/m",
            ParamId::C => "friction C, 1",
            ParamId::C0 => "head damper c0, N·s/m",
            ParamId::C1 => "neck damper c1, N·m·s/rad",
            ParamId::C2 => "lip damper c2, N·m·s/rad",
            ParamId::Hd => "preload compression h_d, m",
            ParamId::K0 => "head spring k0, N/m",
            ParamId::K1 => "neck stiffness k1, N·m/rad",
            ParamId::K1c => {
                "neck stiffness touching the shoulder, N·m/rad (needs a [shoulder] in the blade)"
            }
            ParamId::K2 => "lip stiffness k2, N·m/rad",
            ParamId::ThetaC => "shoulder contact angle, rad (needs a [shoulder] in the blade)",
        }
    }

    /// Whether the parameter belongs to the shoulder contact ([`super::Shoulder`]).
    pub fn is_shoulder(self) -> bool {
        matches!(self, ParamId::K1c | ParamId::ThetaC)
    }

    /// The parameter's value in `p`: `None` when `p` has no such parameter (a shoulder parameter
    /// without a shoulder, a friction coefficient of a law other than the exponential one).
    pub fn get(self, p: &BladeParams) -> Option<f64> {
        let friction = match p.friction {
            FrictionLaw::Exponential { a, b_s_per_m, c } => Some((a, b_s_per_m, c)),
            _ => None,
        };
        Some(match self {
            ParamId::A => friction?.0,
            ParamId::B => friction?.1,
            ParamId::C => friction?.2,
            ParamId::C0 => p.c0_ns_per_m,
            ParamId::C1 => p.c1_nms_per_rad,
            ParamId::C2 => p.c2_nms_per_rad,
            ParamId::Hd => p.hd_m,
            ParamId::K0 => p.k0_n_per_m,
            ParamId::K1 => p.k1_nm_per_rad,
            ParamId::K1c => p.shoulder?.k1_contact_nm_per_rad,
            ParamId::K2 => p.k2_nm_per_rad,
            ParamId::ThetaC => p.shoulder?.contact_angle_rad,
        })
    }

    /// Sets the parameter in `p` to `v`; false (and `p` unchanged) when `p` has no such parameter.
    pub fn set(self, p: &mut BladeParams, v: f64) -> bool {
        let slot: &mut f64 = match self {
            ParamId::A | ParamId::B | ParamId::C => match &mut p.friction {
                FrictionLaw::Exponential { a, b_s_per_m, c } => match self {
                    ParamId::A => a,
                    ParamId::B => b_s_per_m,
                    _ => c,
                },
                _ => return false,
            },
            ParamId::C0 => &mut p.c0_ns_per_m,
            ParamId::C1 => &mut p.c1_nms_per_rad,
            ParamId::C2 => &mut p.c2_nms_per_rad,
            ParamId::Hd => &mut p.hd_m,
            ParamId::K0 => &mut p.k0_n_per_m,
            ParamId::K1 => &mut p.k1_nm_per_rad,
            ParamId::K1c | ParamId::ThetaC => match &mut p.shoulder {
                Some(sh) if self == ParamId::K1c => &mut sh.k1_contact_nm_per_rad,
                Some(sh) => &mut sh.contact_angle_rad,
                None => return false,
            },
            ParamId::K2 => &mut p.k2_nm_per_rad,
        };
        *slot = v;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declaration_order_is_the_names_byte_order() {
        let mut sorted = ParamId::NAMES.to_vec();
        sorted.sort_unstable();
        assert_eq!(sorted, ParamId::NAMES);
    }
}
