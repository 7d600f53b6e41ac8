//! Event-driven simulation: DOPRI5 with dense output ([`rk`]), the hybrid stick–slip driver
//! ([`hybrid`]) and the blade-specific runner ([`blade`]).

pub mod blade;
pub mod hybrid;
pub mod rk;
pub mod timestep;

pub use hybrid::{Phase, SolverOptions, Transition};
