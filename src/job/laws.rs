//! Friction laws compared as candidates (`[fit] laws`, docs/job.md): which coefficients a
//! candidate's law frees, with which bounds, and where its search starts.
//!
//! A candidate with law L frees the job's non-friction parameters, the friction coefficients of
//! `[fit.parameters]` that L has, and L's own coefficients beyond the exponential law's (D of the
//! viscous form, δ of Stribeck's; Stribeck's v_s stands for the exponential law's B). Those the job
//! does not bound get [`D_BOUNDS_S_PER_M`], [`DELTA_BOUNDS`], and for v_s the job's bounds on B
//! inverted. The base law is the blade file's written as L ([`FrictionLaw::as_kind`]): D = 0, or
//! δ = 1 with v_s = 1/B, the exponential law itself.

use super::FreeParam;
use crate::model::{FrictionLaw, LawKind, ParamId};

/// Default bounds of the viscous coefficient D (s/m) when `[fit.parameters]` gives none: from 0
/// (the exponential law) to 2 s/m. At the upper bound D·|v| adds 0.6 to μ_d at 0.3 m/s, the top of
/// the slip speeds near reversal where stick–slip lives; that is the whole fall of a wet
/// rubber-on-glass Stribeck curve from its boundary to its mixed regime (μ ≈ 0.8–1.2 down to
/// 0.1–0.3, physics.md §2.2), so a rise beyond it is no longer the gentle viscous branch
/// Armstrong-Hélouvry, Dupont & Canudas de Wit (1994, *Automatica* 30(7), §2) describe.
pub const D_BOUNDS_S_PER_M: [f64; 2] = [0.0, 2.0];

/// Default bounds of Stribeck's shape exponent δ when `[fit.parameters]` gives none: 0.5 to 2,
/// the exponents the friction survey reports (Armstrong-Hélouvry, Dupont & Canudas de Wit 1994,
/// *Automatica* 30(7), §2: Bo & Pavelescu's 0.5–1 and the Gaussian form's 2), with the exponential
/// law's δ = 1 inside.
pub const DELTA_BOUNDS: [f64; 2] = [0.5, 2.0];

/// The freed parameters of a candidate fitted with `law`, from the job's `free` (every parameter
/// of `[fit.parameters]`, in [`ParamId`] order), in [`ParamId`] order: the job's parameters that
/// are not friction coefficients or are `law`'s, then `law`'s coefficients beyond the exponential
/// law's that the job does not bound ([`D_BOUNDS_S_PER_M`], [`DELTA_BOUNDS`]), and Stribeck's v_s
/// from the job's bounds on B (v_s = 1/B) when the job frees B but not v_s.
pub fn law_free(free: &[(ParamId, f64, f64)], law: LawKind) -> Vec<FreeParam> {
    let has = |id: ParamId| free.iter().any(|f| f.0 == id);
    let mut out: Vec<(ParamId, f64, f64)> = free
        .iter()
        .copied()
        .filter(|(id, ..)| !id.is_friction() || law.coefficients().contains(id))
        .collect();
    for (id, [lo, hi]) in [
        (ParamId::D, D_BOUNDS_S_PER_M),
        (ParamId::Delta, DELTA_BOUNDS),
    ] {
        if law.coefficients().contains(&id) && !has(id) {
            out.push((id, lo, hi));
        }
    }
    if law.coefficients().contains(&ParamId::Vs)
        && !has(ParamId::Vs)
        && let Some(&(_, b_lo, b_hi)) = free.iter().find(|f| f.0 == ParamId::B)
    {
        out.push((ParamId::Vs, 1.0 / b_hi, 1.0 / b_lo));
    }
    out.sort_by_key(|f| f.0);
    out.into_iter()
        .map(|(id, lo, hi)| FreeParam::new(id, lo, hi))
        .collect()
}

/// Why the friction parameter `id` of `[fit.parameters]` belongs to none of `laws`, or `None`
/// when one of them has it (or it is not a friction coefficient). Stribeck's law takes its v_s
/// from B's bounds, so B may be bounded for it.
pub fn no_listed_law_has(id: ParamId, laws: &[LawKind]) -> Option<String> {
    let stribeck_b = id == ParamId::B && laws.contains(&LawKind::Stribeck);
    if !id.is_friction() || stribeck_b || laws.iter().any(|l| l.coefficients().contains(&id)) {
        return None;
    }
    let listed: Vec<String> = laws
        .iter()
        .map(|l| format!("{l} ({})", crate::names::join(l.coefficients(), ", ")))
        .collect();
    Some(format!(
        "[fit.parameters]: '{id}' ({}) is a coefficient of none of the laws in [fit] laws: {}; \
         it needs law {}",
        id.axis_label(),
        listed.join(", "),
        id.friction_laws()
            .iter()
            .map(|l| format!("\"{l}\""))
            .collect::<Vec<_>>()
            .join(" or ")
    ))
}

/// A blade file's friction law that `[fit] laws` cannot write as one of its laws (Coulomb's and
/// Leine's laws have no coefficient a fit frees).
#[derive(Debug, thiserror::Error)]
#[error(
    "[fit] laws: the blade file's law `{law}` cannot be fitted as `{kind}`; give the blade an {} law",
    crate::names::join(LawKind::ALL, ", ")
)]
pub struct LawNotFittable {
    /// The blade file's law.
    pub law: &'static str,
    /// The law the job lists.
    pub kind: LawKind,
}

/// The blade file's `law` written as `kind` ([`FrictionLaw::as_kind`]).
///
/// # Errors
/// [`LawNotFittable`] when it cannot be.
pub fn base_law(law: &FrictionLaw, kind: LawKind) -> Result<FrictionLaw, LawNotFittable> {
    law.as_kind(kind).ok_or(LawNotFittable {
        law: law.name(),
        kind,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The main job's freed parameters (A, B, C, k1) as each law frees them.
    #[test]
    fn each_law_frees_its_own_coefficients_with_default_bounds() {
        let free = [
            (ParamId::A, 0.2, 1.5),
            (ParamId::B, 10.0, 300.0),
            (ParamId::C, 0.1, 1.0),
            (ParamId::K1, 0.005, 0.15),
        ];
        let names = |law| -> Vec<(ParamId, f64, f64)> {
            law_free(&free, law)
                .iter()
                .map(|f| (f.name, f.lower, f.upper))
                .collect()
        };
        assert_eq!(names(LawKind::Exponential), free.to_vec());
        let mut viscous = free.to_vec();
        viscous.push((ParamId::D, 0.0, 2.0));
        viscous.sort_by_key(|f| f.0);
        assert_eq!(names(LawKind::ExponentialViscous), viscous);
        // Stribeck: B's bounds inverted for v_s (1/300 to 1/10 m/s), δ in [0.5, 2].
        let stribeck = names(LawKind::Stribeck);
        let ids: Vec<ParamId> = stribeck.iter().map(|f| f.0).collect();
        let mut want = vec![
            ParamId::A,
            ParamId::C,
            ParamId::K1,
            ParamId::Delta,
            ParamId::Vs,
        ];
        want.sort();
        assert_eq!(ids, want);
        let vs = stribeck.iter().find(|f| f.0 == ParamId::Vs).unwrap();
        assert_eq!((vs.1, vs.2), (1.0 / 300.0, 0.1));
        let delta = stribeck.iter().find(|f| f.0 == ParamId::Delta).unwrap();
        assert_eq!((delta.1, delta.2), (0.5, 2.0));
        // A bound the job gives wins over the default.
        let mut given = free.to_vec();
        given.push((ParamId::D, 0.0, 0.5));
        let d = law_free(&given, LawKind::ExponentialViscous)
            .into_iter()
            .find(|f| f.name == ParamId::D)
            .unwrap();
        assert_eq!((d.lower, d.upper), (0.0, 0.5));
        // ... and a law that lacks it leaves it out.
        assert_eq!(names(LawKind::Exponential), free.to_vec());
        assert!(
            law_free(&given, LawKind::Exponential)
                .iter()
                .all(|f| f.name != ParamId::D)
        );
    }

    #[test]
    fn a_parameter_no_listed_law_has_is_named_with_the_laws() {
        let laws = [LawKind::Exponential, LawKind::ExponentialViscous];
        assert_eq!(no_listed_law_has(ParamId::D, &laws), None);
        assert_eq!(no_listed_law_has(ParamId::K1, &laws), None);
        let e = no_listed_law_has(ParamId::Delta, &laws).unwrap();
        assert!(
            e.contains("'delta'")
                && e.contains("exponential (A, B, C)")
                && e.contains("\"stribeck\""),
            "{e}"
        );
        assert_eq!(no_listed_law_has(ParamId::B, &[LawKind::Stribeck]), None);
        assert!(no_listed_law_has(ParamId::D, &[LawKind::Stribeck]).is_some());
    }
}
