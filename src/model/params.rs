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
        /// Viscous coefficient D of the `exponential_viscous` law, s/m.
        D => "D",
        /// Head damper c0, N·s/m.
        C0 => "c0",
        /// Neck damper c1, N·m·s/rad.
        C1 => "c1",
        /// Lip damper c2, N·m·s/rad.
        C2 => "c2",
        /// Shape exponent δ of the `stribeck` law, 1.
        Delta => "delta",
        /// Preload compression h_d, m.
        Hd => "hd",
        /// Head mass M, kg, with the head's natural frequency held (k0 follows).
        HeadMass => "head_mass",
        /// Head spring k0, N/m.
        K0 => "k0",
        /// Neck stiffness k1, N·m/rad.
        K1 => "k1",
        /// Neck stiffness while touching the shoulder, N·m/rad.
        K1c => "k1c",
        /// Lip stiffness k2, N·m/rad.
        K2 => "k2",
        /// Lip length l2, m, the lip scaled as a rod of the same mass (d2 and J2 follow).
        L2 => "l2",
        /// Lip mass m2, kg, with the head's and the free neck's natural frequencies held.
        LipMass => "lip_mass",
        /// Preload N0 = k0·h_d, N, set through h_d (k0 as the other freed parameters leave it).
        Preload => "preload",
        /// Shoulder contact angle, rad.
        ThetaC => "theta_c",
        /// Stribeck speed v_s of the `stribeck` law, m/s.
        Vs => "v_s",
    }
}

impl ParamId {
    /// What the parameter is, with its unit, for help texts and reports.
    pub fn meaning(self) -> &'static str {
        match self {
            ParamId::A => "friction A (seed eq. 4), 1",
            ParamId::B => "friction B, s/m",
            ParamId::C => "friction C, 1",
            ParamId::D => {
                "friction viscous coefficient D, s/m (needs law = \"exponential_viscous\")"
            }
            ParamId::Delta => "friction Stribeck exponent δ, 1 (needs law = \"stribeck\")",
            ParamId::Vs => "friction Stribeck speed v_s, m/s (needs law = \"stribeck\")",
            ParamId::C0 => "head damper c0, N·s/m",
            ParamId::C1 => "neck damper c1, N·m·s/rad",
            ParamId::C2 => "lip damper c2, N·m·s/rad",
            ParamId::Hd => "preload compression h_d, m",
            ParamId::HeadMass => {
                "head mass M, kg (k0 follows: the head's natural frequency is held)"
            }
            ParamId::K0 => "head spring k0, N/m",
            ParamId::K1 => "neck stiffness k1, N·m/rad",
            ParamId::K1c => {
                "neck stiffness touching the shoulder, N·m/rad (needs a [shoulder] in the blade)"
            }
            ParamId::K2 => "lip stiffness k2, N·m/rad",
            ParamId::L2 => "lip length l2, m (its centre of mass and inertia scale with it)",
            ParamId::LipMass => {
                "lip mass m2, kg (its inertia scales with it; k0 and k1 follow: head and free neck frequencies held)"
            }
            ParamId::Preload => {
                "preload N0 = k0·h_d, N (h_d follows, after the head mass, lip mass or k0 have set k0)"
            }
            ParamId::ThetaC => "shoulder contact angle, rad (needs a [shoulder] in the blade)",
        }
    }

    /// The unit as it follows a number: `" s/m"`, or nothing for a pure number.
    pub fn unit_suffix(self) -> String {
        match self.unit() {
            "-" => String::new(),
            u => format!(" {u}"),
        }
    }

    /// The parameter's SI unit (`-` for a pure number).
    pub fn unit(self) -> &'static str {
        match self {
            ParamId::A | ParamId::C | ParamId::Delta => "-",
            ParamId::B | ParamId::D => "s/m",
            ParamId::Vs => "m/s",
            ParamId::C0 => "N·s/m",
            ParamId::C1 | ParamId::C2 => "N·m·s/rad",
            ParamId::Hd | ParamId::L2 => "m",
            ParamId::HeadMass | ParamId::LipMass => "kg",
            ParamId::K0 => "N/m",
            ParamId::Preload => "N",
            ParamId::K1 | ParamId::K1c | ParamId::K2 => "N·m/rad",
            ParamId::ThetaC => "rad",
        }
    }

    /// A figure's axis label: what the parameter is and its unit, e.g. `"neck stiffness k1
    /// [N·m/rad]"`.
    pub fn axis_label(self) -> String {
        let what = self.meaning().split(", ").next().unwrap_or(self.name());
        format!("{what} [{}]", self.unit())
    }

    /// Whether the parameter is a coefficient of the friction law (A, B, C, D, v_s, δ).
    pub fn is_friction(self) -> bool {
        matches!(
            self,
            ParamId::A | ParamId::B | ParamId::C | ParamId::D | ParamId::Delta | ParamId::Vs
        )
    }

    /// The friction laws (their names in a blade file) that have the friction parameter `self`;
    /// empty for a parameter that is not the friction law's.
    pub fn friction_laws(self) -> &'static [&'static str] {
        match self {
            ParamId::A | ParamId::C => &["exponential", "exponential_viscous", "stribeck"],
            ParamId::B => &["exponential", "exponential_viscous"],
            ParamId::D => &["exponential_viscous"],
            ParamId::Delta | ParamId::Vs => &["stribeck"],
            _ => &[],
        }
    }

    /// Whether the parameter belongs to the shoulder contact ([`super::Shoulder`]).
    pub fn is_shoulder(self) -> bool {
        matches!(self, ParamId::K1c | ParamId::ThetaC)
    }

    /// Whether the parameter is a mass or a length of the blade (set by [`ParamId::set`] with what
    /// a measurement of the blade fixes held; see there).
    pub fn is_geometry(self) -> bool {
        matches!(self, ParamId::HeadMass | ParamId::L2 | ParamId::LipMass)
    }

    /// Whether the parameter must be strictly positive (a mass, a length, a spring the model divides
    /// by or the preload), not merely non-negative.
    pub fn strictly_positive(self) -> bool {
        self.is_geometry()
            || matches!(
                self,
                ParamId::K0
                    | ParamId::K1
                    | ParamId::Hd
                    | ParamId::Preload
                    | ParamId::Vs
                    | ParamId::Delta
            )
    }

    /// The freed parameters that `self` moves when set ([`ParamId::set`]), and that a job therefore
    /// cannot free beside it: the lip mass holds the head's and the free neck's frequencies through
    /// k0 and k1, the preload is set through h_d.
    pub fn holds(self) -> &'static [ParamId] {
        match self {
            ParamId::LipMass => &[ParamId::K0, ParamId::K1],
            ParamId::Preload => &[ParamId::Hd],
            _ => &[],
        }
    }

    /// The parameter's value in `p`: `None` when `p` has no such parameter (a shoulder parameter
    /// without a shoulder, a friction coefficient the blade's law does not have).
    pub fn get(self, p: &BladeParams) -> Option<f64> {
        Some(match self {
            ParamId::A | ParamId::B | ParamId::C | ParamId::D | ParamId::Delta | ParamId::Vs => {
                *friction_slot(self, &mut p.friction.clone())?
            }
            ParamId::C0 => p.c0_ns_per_m,
            ParamId::C1 => p.c1_nms_per_rad,
            ParamId::C2 => p.c2_nms_per_rad,
            ParamId::Hd => p.hd_m,
            ParamId::HeadMass => p.head_mass_kg,
            ParamId::K0 => p.k0_n_per_m,
            ParamId::K1 => p.k1_nm_per_rad,
            ParamId::K1c => p.shoulder?.k1_contact_nm_per_rad,
            ParamId::K2 => p.k2_nm_per_rad,
            ParamId::L2 => p.l2_m,
            ParamId::LipMass => p.lip_mass_kg,
            ParamId::Preload => p.k0_n_per_m * p.hd_m,
            ParamId::ThetaC => p.shoulder?.contact_angle_rad,
        })
    }

    /// Sets the parameter in `p` to `v`; false (and `p` unchanged) when `p` has no such parameter.
    ///
    /// A geometry parameter keeps what a measurement of the real blade fixes (the seed measured the
    /// head's and the free neck's frequencies, not the masses behind them):
    /// - `head_mass`: k0 = M_t (2π f_head)² with f_head = [`BladeParams::head_freq_hz`] before the
    ///   change (M_t = M + m1 + m2);
    /// - `lip_mass`: the lip's inertia J2 scales with m2 (the same shape), and k0 and k1 follow so
    ///   that f_head and the free neck's [`BladeParams::neck_freq_hz`] stay;
    /// - `l2`: the lip's centre of mass d2 scales with l2 and J2 with l2² (the same rod, longer);
    ///   its mass stays;
    /// - `preload`: h_d = N0 / k0 with the k0 `p` has, so a job sets it after the parameters that
    ///   move k0 (the freed parameters are set in [`ParamId`]'s order, and `preload` comes after
    ///   `head_mass`, `k0` and `lip_mass`).
    pub fn set(self, p: &mut BladeParams, v: f64) -> bool {
        let slot: &mut f64 = match self {
            ParamId::A | ParamId::B | ParamId::C | ParamId::D | ParamId::Delta | ParamId::Vs => {
                match friction_slot(self, &mut p.friction) {
                    Some(slot) => slot,
                    None => return false,
                }
            }
            ParamId::C0 => &mut p.c0_ns_per_m,
            ParamId::C1 => &mut p.c1_nms_per_rad,
            ParamId::C2 => &mut p.c2_nms_per_rad,
            ParamId::Hd => &mut p.hd_m,
            ParamId::Preload => {
                p.hd_m = v / p.k0_n_per_m;
                return true;
            }
            ParamId::K0 => &mut p.k0_n_per_m,
            ParamId::K1 => &mut p.k1_nm_per_rad,
            ParamId::K1c | ParamId::ThetaC => match &mut p.shoulder {
                Some(sh) if self == ParamId::K1c => &mut sh.k1_contact_nm_per_rad,
                Some(sh) => &mut sh.contact_angle_rad,
                None => return false,
            },
            ParamId::K2 => &mut p.k2_nm_per_rad,
            ParamId::HeadMass | ParamId::L2 | ParamId::LipMass => {
                set_geometry(self, p, v);
                return true;
            }
        };
        *slot = v;
        true
    }
}

/// The coefficient of `law` that the friction parameter `id` names, if the law has it: A and C
/// in the exponential law, its viscous form and Stribeck's; B in the first two; D in the viscous
/// form; v_s and δ in Stribeck's.
fn friction_slot(id: ParamId, law: &mut FrictionLaw) -> Option<&mut f64> {
    match (id, law) {
        (ParamId::A, FrictionLaw::Exponential { a, .. })
        | (ParamId::A, FrictionLaw::ExponentialViscous { a, .. })
        | (ParamId::A, FrictionLaw::Stribeck { a, .. })
        | (ParamId::B, FrictionLaw::Exponential { b_s_per_m: a, .. })
        | (ParamId::B, FrictionLaw::ExponentialViscous { b_s_per_m: a, .. })
        | (ParamId::C, FrictionLaw::Exponential { c: a, .. })
        | (ParamId::C, FrictionLaw::ExponentialViscous { c: a, .. })
        | (ParamId::C, FrictionLaw::Stribeck { c: a, .. })
        | (ParamId::D, FrictionLaw::ExponentialViscous { d_s_per_m: a, .. })
        | (ParamId::Vs, FrictionLaw::Stribeck { v_s_m_per_s: a, .. })
        | (ParamId::Delta, FrictionLaw::Stribeck { delta: a, .. }) => Some(a),
        _ => None,
    }
}

/// [`ParamId::set`] for the geometry parameters ([`ParamId::is_geometry`]).
fn set_geometry(id: ParamId, p: &mut BladeParams, v: f64) {
    let (f_head_hz, f_neck_hz) = (p.head_freq_hz(), p.neck_freq_hz());
    let ratio = |old: f64| if old > 0.0 { v / old } else { 1.0 };
    match id {
        ParamId::HeadMass => p.head_mass_kg = v,
        ParamId::L2 => {
            let r = ratio(p.l2_m);
            p.lip_com_m *= r;
            p.lip_inertia_kg_m2 *= r * r;
            p.l2_m = v;
        }
        _ => {
            p.lip_inertia_kg_m2 *= ratio(p.lip_mass_kg);
            p.lip_mass_kg = v;
        }
    }
    let m = p.mass_coefficients();
    let w = |f_hz: f64| (std::f64::consts::TAU * f_hz).powi(2);
    if id != ParamId::L2 {
        p.k0_n_per_m = m.mt * w(f_head_hz);
    }
    if id == ParamId::LipMass {
        p.k1_nm_per_rad = m.mth * w(f_neck_hz);
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

    fn experiment_blade() -> BladeParams {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/data/paper/seed_experiment_blade.toml"
        );
        toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    /// The geometry parameters hold what they say, checked against the closed forms
    /// f_head = √(k0/M_t)/2π and f_neck = √(k1/m_θ)/2π (with m_θ = J1 + m1 d1² + m2 l1²) and a uniform
    /// rod's d2 = l2/2, J2 = m2 l2²/12 (the experiment blade's lip is one).
    #[test]
    fn geometry_parameters_hold_the_measured_frequencies() {
        let base = experiment_blade();
        let (f_head, f_neck) = (base.head_freq_hz(), base.neck_freq_hz());
        assert!((f_head - 20.0).abs() < 1e-9 && (f_neck - 195.0).abs() < 1e-9);
        let mut p = base;
        assert!(ParamId::HeadMass.set(&mut p, 0.005));
        let mt = 0.005 + p.neck_mass_kg + p.lip_mass_kg;
        assert!((p.k0_n_per_m - mt * (std::f64::consts::TAU * 20.0).powi(2)).abs() < 1e-9);
        assert_eq!(p.k1_nm_per_rad, base.k1_nm_per_rad);
        let mut p = base;
        assert!(ParamId::LipMass.set(&mut p, 2.0 * base.lip_mass_kg));
        let l1 = p.l1_m;
        let mth =
            p.neck_inertia_kg_m2 + p.neck_mass_kg * p.neck_com_m.powi(2) + p.lip_mass_kg * l1 * l1;
        let w_neck = (std::f64::consts::TAU * 195.0).powi(2);
        assert!((p.k1_nm_per_rad / (mth * w_neck) - 1.0).abs() < 1e-12);
        assert!((p.head_freq_hz() - 20.0).abs() < 1e-9);
        assert!(
            (p.lip_inertia_kg_m2 / (p.lip_mass_kg * p.l2_m.powi(2) / 12.0) - 1.0).abs() < 1e-12
        );
        let mut p = base;
        assert!(ParamId::L2.set(&mut p, 0.006));
        assert!((p.lip_com_m - 0.003).abs() < 1e-15);
        assert!(
            (p.lip_inertia_kg_m2 / (p.lip_mass_kg * 0.006f64.powi(2) / 12.0) - 1.0).abs() < 1e-12
        );
        assert_eq!(
            (p.k0_n_per_m, p.k1_nm_per_rad),
            (base.k0_n_per_m, base.k1_nm_per_rad)
        );
        for id in [
            ParamId::HeadMass,
            ParamId::L2,
            ParamId::LipMass,
            ParamId::Preload,
        ] {
            let v = id.get(&base).unwrap();
            let mut p = base;
            id.set(&mut p, 0.5 * v);
            let got = id.get(&p).unwrap();
            assert!(
                (got / (0.5 * v) - 1.0).abs() < 1e-12,
                "{id}: {got} against {}",
                0.5 * v
            );
        }
    }

    /// Each friction parameter reads and sets the coefficient of the laws that have it
    /// ([`ParamId::friction_laws`]) and is absent from the others.
    #[test]
    fn friction_parameters_belong_to_their_laws() {
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
        ];
        let friction_ids: Vec<ParamId> = ParamId::ALL
            .iter()
            .copied()
            .filter(|id| id.is_friction())
            .collect();
        assert_eq!(friction_ids.len(), 6);
        for law in laws {
            let mut p = experiment_blade();
            p.friction = law;
            for &id in &friction_ids {
                let has = id.friction_laws().contains(&law.name());
                assert_eq!(id.get(&p).is_some(), has, "{id} in {law:?}");
                let mut q = p;
                assert_eq!(id.set(&mut q, 0.125), has, "{id} in {law:?}");
                if has {
                    assert_eq!(id.get(&q), Some(0.125));
                    // Only that coefficient moved.
                    for &other in friction_ids.iter().filter(|&&o| o != id) {
                        assert_eq!(other.get(&q), other.get(&p), "{other} after {id}");
                    }
                } else {
                    assert_eq!(q, p);
                }
            }
        }
        let mut p = experiment_blade();
        p.friction = laws[2];
        ParamId::Vs.set(&mut p, 0.05);
        ParamId::Delta.set(&mut p, 1.5);
        assert_eq!(
            p.friction,
            FrictionLaw::Stribeck {
                a: 0.8,
                c: 0.2,
                v_s_m_per_s: 0.05,
                delta: 1.5
            }
        );
    }

    /// The preload set after the head mass is k0·h_d with the new head's k0: the experiment blade
    /// (head 20 Hz) with a 10 g head and 1.5 N needs k0 = M_t (2π 20 Hz)², h_d = 1.5 N / k0.
    #[test]
    fn preload_follows_the_head_mass_it_is_set_after() {
        let base = experiment_blade();
        let reconstruction = base.k0_n_per_m * base.hd_m;
        assert!(
            (reconstruction - 1.1124336838764888).abs() < 1e-12,
            "{reconstruction}"
        );
        let mut p = base;
        assert!(ParamId::HeadMass.set(&mut p, 0.010));
        assert!(ParamId::Preload.set(&mut p, 1.5));
        let mt = 0.010 + p.neck_mass_kg + p.lip_mass_kg;
        let k0 = mt * (std::f64::consts::TAU * 20.0).powi(2);
        assert!(
            (p.hd_m - 1.5 / k0).abs() < 1e-15,
            "{} against {}",
            p.hd_m,
            1.5 / k0
        );
        assert!(ParamId::HeadMass < ParamId::Preload && ParamId::LipMass < ParamId::Preload);
        assert_eq!(ParamId::Preload.holds(), &[ParamId::Hd]);
    }
}
