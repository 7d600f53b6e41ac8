//! Event-driven simulation: DOPRI5 ([`rk`]) or DOP853 ([`dop853`]) with dense output, chosen by
//! [`Method`] ([`method`]), the hybrid stick–slip driver
//! ([`hybrid`]) and the blade-specific runner ([`blade`]); the comparison methods of the
//! work–precision study (Moreau–Jean time-stepping, smoothed friction) in [`timestep`].

pub mod belt;
pub mod blade;
pub mod dop853;
pub mod error;
pub mod failure;
pub mod hybrid;
pub mod method;
pub mod rk;
pub mod timestep;

pub use error::{SettingError, SimulationError, StopCause};
pub use hybrid::{Phase, SolverOptions, Transition};
pub use method::Method;
