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

/// Why a model could not evaluate its right-hand side.
#[derive(Debug, Clone)]
pub enum ModelFault {
    /// The slip equations have no unique solution (Painlevé-type inconsistency) or the constraint
    /// system is singular.
    Singular(String),
    /// The geometry left the model's domain (e.g. the stick constraint has no solution).
    Geometry(String),
}

impl std::fmt::Display for ModelFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ModelFault::Singular(s) | ModelFault::Geometry(s) => f.write_str(s),
        }
    }
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
