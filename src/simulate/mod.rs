//! Event-driven simulation: DOPRI5 with dense output ([`rk`]), the hybrid stick–slip driver
//! ([`hybrid`]) and the blade-specific runner ([`blade`]); the comparison methods of the
//! work–precision study (Moreau–Jean time-stepping, smoothed friction) in [`timestep`].

pub mod belt;
pub mod blade;
pub mod error;
pub mod hybrid;
pub mod rk;
pub mod timestep;

pub use error::{SimulationError, StopCause};
pub use hybrid::{Phase, SolverOptions, Transition};
