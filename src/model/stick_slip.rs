//! The contract between a stick–slip model and the event-driven integrator: the contact's
//! [`Phase`], the [`Mode`] a phase runs in, the [`Contact`] forces a right-hand side reports, the
//! [`ModelFault`] it may return and the [`StickSlipModel`] trait itself.
//!
//! Models (`model::blade`, `model::belt`, `model::necklip`) implement the trait; `simulate::hybrid`
//! integrates any implementation. Both depend on this module; neither on the other.

use serde::Serialize;

/// The contact's phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Phase {
    /// Slipping with positive slip velocity.
    #[serde(rename = "slip+")]
    SlipPos,
    /// Slipping with negative slip velocity.
    #[serde(rename = "slip-")]
    SlipNeg,
    /// Sticking: slip velocity held at zero by static friction.
    #[serde(rename = "stick")]
    Stick,
}

impl Phase {
    /// Slip direction `s = ±1`, or `None` in stick.
    pub fn slip_dir(self) -> Option<f64> {
        match self {
            Phase::SlipPos => Some(1.0),
            Phase::SlipNeg => Some(-1.0),
            Phase::Stick => None,
        }
    }

    /// Slip phase for direction `s` (its sign).
    pub fn slip(s: f64) -> Phase {
        if s >= 0.0 {
            Phase::SlipPos
        } else {
            Phase::SlipNeg
        }
    }

    /// The label used in files: `slip+`, `slip-`, `stick`.
    pub fn label(self) -> &'static str {
        match self {
            Phase::SlipPos => "slip+",
            Phase::SlipNeg => "slip-",
            Phase::Stick => "stick",
        }
    }

    /// Numeric code as in the sample's `state` column: 1 = slip+, 0 = stick, −1 = slip−.
    pub fn code(self) -> i8 {
        match self {
            Phase::SlipPos => 1,
            Phase::SlipNeg => -1,
            Phase::Stick => 0,
        }
    }
}

impl std::fmt::Display for Phase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

/// A phase together with its data: in stick, `anchor` is the contact position held by the constraint;
/// `region` has bit `i` set while switching function `i` of the model is positive (see
/// [`StickSlipModel::switching_surfaces`]); the right-hand side uses it to pick its smooth branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    pub phase: Phase,
    pub anchor: f64,
    pub region: u8,
}

impl Mode {
    /// A mode in `phase` with `anchor` (used only in stick) and every switching bit clear.
    pub fn new(phase: Phase, anchor: f64) -> Mode {
        Mode {
            phase,
            anchor,
            region: 0,
        }
    }
}

/// Largest number of switching surfaces a model may declare.
pub const MAX_SWITCHING_SURFACES: usize = 2;

/// Contact forces at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Normal force N (> 0 while in contact), N.
    pub normal: f64,
    /// Friction force on the contact along +x, N.
    pub friction: f64,
    /// Static limit μ_s·N, N.
    pub limit: f64,
    /// The contact's slip velocity at the same instant (m/s), when the right-hand side computed it
    /// on the way (the friction law needs it in slip); `None` makes the event functions ask
    /// [`StickSlipModel::slip_velocity`] instead.
    pub slip_velocity: Option<f64>,
}

/// Which link model's equations a [`ModelFault`] concerns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkModel {
    /// The 2-DOF head/neck/lip blade (seed eqs. 1–5).
    Blade,
    /// The blade with neck and lip locked together (the 1-DOF head model's link).
    LockedLink,
    /// The neck/lip model driven by the tracked head.
    NeckLip,
}

impl std::fmt::Display for LinkModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LinkModel::Blade => "blade",
            LinkModel::LockedLink => "locked-link",
            LinkModel::NeckLip => "neck/lip",
        })
    }
}

/// A linear system a model solves for its accelerations and contact forces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinearSystem {
    /// The blade's 3×3 slip system (accelerations and normal force).
    BladeSlip,
    /// The blade's 4×4 stick system with the tip constraint.
    BladeStick,
    /// The Newton iteration's Jacobian for the quasi-static slip equilibrium.
    EquilibriumJacobian,
    /// The neck/lip model's slip system.
    NeckLipSlip,
    /// The neck/lip model's stick system.
    NeckLipStick,
    /// The smoothed-friction comparison model's system.
    Smoothed,
}

impl std::fmt::Display for LinearSystem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LinearSystem::BladeSlip => "slip system",
            LinearSystem::BladeStick => "stick constraint system",
            LinearSystem::EquilibriumJacobian => "equilibrium Jacobian",
            LinearSystem::NeckLipSlip => "neck/lip slip system",
            LinearSystem::NeckLipStick => "neck/lip stick system",
            LinearSystem::Smoothed => "smoothed-friction system",
        })
    }
}

/// The angle a stick constraint solves for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConstraintAngle {
    /// The lip angle φ (the blade's stick constraint).
    Lip,
    /// The link angle θ (the locked link's stick constraint).
    Link,
}

impl std::fmt::Display for ConstraintAngle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ConstraintAngle::Lip => "lip",
            ConstraintAngle::Link => "link",
        })
    }
}

/// Why a model could not evaluate its right-hand side or build a consistent state. Each variant
/// carries the numbers that show why (angles in rad, forces in N, lengths in m, times in s).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelFault {
    /// The slip equations have no unique solution: the determinant with friction has the opposite
    /// sign to the frictionless one (a Painlevé-type inconsistency; physics.md §1.4).
    #[error(
        "{model} slip equations singular (Painlevé-type): det with friction {det_with_friction:.3e}, frictionless {det_frictionless:.3e}, μ = {mu:.4}"
    )]
    Painleve {
        model: LinkModel,
        det_with_friction: f64,
        det_frictionless: f64,
        mu: f64,
    },
    /// A linear system of the model is singular.
    #[error("{system} is singular")]
    Singular { system: LinearSystem },
    /// The stick constraint has no solution: the head moved beyond the reach of the link.
    #[error(
        "stick constraint has no {angle} angle: sine = {sine:.6} (the head moved beyond the link's reach)"
    )]
    NoStickAngle { angle: ConstraintAngle, sine: f64 },
    /// Newton's iteration found no quasi-static slip equilibrium to start from.
    #[error(
        "no quasi-static slip equilibrium of the {model} found at t = {t_s} s (largest residual acceleration {residual_rad_per_s2:.3e} rad/s²)"
    )]
    NoEquilibrium {
        model: LinkModel,
        t_s: f64,
        residual_rad_per_s2: f64,
    },
    /// The neck/lip model needs the recording's lean track to start a segment.
    #[error("neck/lip model: no lean track to start a segment from")]
    NoLeanTrack,
    /// The tracked lean is longer than neck and lip together.
    #[error(
        "neck/lip model: lean d = {lean_m:.6e} m at t = {t_s:.6} s is beyond the reach {reach_m:.6e} m"
    )]
    LeanBeyondReach { t_s: f64, lean_m: f64, reach_m: f64 },
    /// Neck and lip are aligned, so the tracks do not determine the angular rates.
    #[error(
        "neck/lip model: at t = {t_s:.6} s neck and lip are aligned (θ = {theta_rad:.3e}, φ = {phi_rad:.3e} rad), so the rates cannot be taken from the tracks"
    )]
    AlignedLinks {
        t_s: f64,
        theta_rad: f64,
        phi_rad: f64,
    },
    /// The head-height constraint degenerates near upright, where the normal force is undetermined.
    #[error(
        "neck/lip model: the head-height constraint degenerates near upright (θ = {theta_rad:.3e}, φ = {phi_rad:.3e} rad), where the normal force is undetermined; this model cannot pass the blade's flip at the reversal: use a window before or after it, or blade2dof"
    )]
    UprightDegenerate { theta_rad: f64, phi_rad: f64 },
    /// The normal force is not positive: the lip tip left the glass.
    #[error("contact lost: normal force {normal_n:.3e} N <= 0")]
    ContactLost { normal_n: f64 },
    /// No consistent starting state was found near a segment's start.
    #[error("no consistent start within {search_s} s of the segment's start: {last}")]
    NoConsistentStart {
        search_s: f64,
        /// The last attempt's fault.
        last: Box<ModelFault>,
    },
}

/// A mechanical system with one frictional contact, integrated as a hybrid system.
///
/// `N` is the length of the state vector, the same in every phase. A phase may leave some
/// components un-integrated (their derivative 0) and fill them in [`StickSlipModel::complete`]
/// (the drift-free stick form does this).
pub trait StickSlipModel<const N: usize>: Sync {
    /// Derivative `dy` at `(t, y)` in `mode`, and the contact forces there.
    fn rhs(
        &self,
        mode: &Mode,
        t: f64,
        y: &[f64; N],
        dy: &mut [f64; N],
    ) -> std::result::Result<Contact, ModelFault>;

    /// Slip velocity of the contact at `(t, y)`.
    fn slip_velocity(&self, t: f64, y: &[f64; N]) -> f64;

    /// Position of the contact along the slip direction (becomes the stick anchor).
    fn contact_position(&self, t: f64, y: &[f64; N]) -> f64;

    /// Makes `y` consistent with stick at `anchor` at time `t` (slip velocity exactly 0).
    fn enter_stick(&self, t: f64, y: &mut [f64; N], anchor: f64);

    /// Fills the components `mode` does not integrate. Default: nothing.
    fn complete(
        &self,
        _mode: &Mode,
        _t: f64,
        _y: &mut [f64; N],
    ) -> std::result::Result<(), ModelFault> {
        Ok(())
    }

    /// A one-line description of the state for error messages.
    fn describe(&self, t: f64, y: &[f64; N]) -> String;

    /// Number of switching surfaces (at most [`MAX_SWITCHING_SURFACES`]): places where the
    /// right-hand side changes formula without a change of phase, e.g. a kink in a stiffness
    /// (the neck touching its shoulder). Default 0.
    ///
    /// The integrator keeps each surface's side in [`Mode::region`] (bit `i` set while
    /// [`StickSlipModel::switching_function`] `i` is positive), never lets a step straddle a surface
    /// (the right-hand side keeps using the current branch's formula, extended, until the crossing
    /// is located on the dense output like a phase event), and restarts the step there on the other
    /// branch. Crossings are listed in the integrator's run record (`simulate::hybrid::Run::switches`).
    fn switching_surfaces(&self) -> usize {
        0
    }

    /// Switching function `i` at `(t, y)`: positive on one side of the surface, negative on the other.
    fn switching_function(&self, _i: usize, _t: f64, _y: &[f64; N]) -> f64 {
        0.0
    }
}

/// The region bits of `model` at `(t, y)`: bit `i` set where switching function `i` is positive.
pub fn region_of<M: StickSlipModel<N>, const N: usize>(model: &M, t: f64, y: &[f64; N]) -> u8 {
    let mut r = 0u8;
    for i in 0..model.switching_surfaces().min(MAX_SWITCHING_SURFACES) {
        if model.switching_function(i, t, y) > 0.0 {
            r |= 1 << i;
        }
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fault's message names what failed and carries its numbers, and a nested fault keeps them.
    #[test]
    fn faults_carry_their_numbers() {
        let p = ModelFault::Painleve {
            model: LinkModel::Blade,
            det_with_friction: -2.5e-3,
            det_frictionless: 1.0e-2,
            mu: 1.25,
        };
        let m = p.to_string();
        assert!(
            m.contains("blade slip equations") && m.contains("Painlevé"),
            "{m}"
        );
        assert!(
            m.contains("-2.500e-3") && m.contains("1.000e-2") && m.contains("1.2500"),
            "{m}"
        );
        let nested = ModelFault::NoConsistentStart {
            search_s: 0.01,
            last: Box::new(ModelFault::ContactLost { normal_n: -0.5 }),
        };
        assert!(
            nested
                .to_string()
                .ends_with("contact lost: normal force -5.000e-1 N <= 0")
        );
    }
}
