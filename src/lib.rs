//! # wiperlab
//!
//! A windshield-wiper blade's measured motion beside a physical model of it.
//!
//! Data flow: [`import`] (tracking-tool exports → [`trace::Trace`]) → [`spectrum`] (Welch PSD, peaks,
//! spectrogram) → [`model`] + [`simulate`] (the 2-DOF head/neck/lip link model with stick–slip
//! friction, event-driven) → [`fit`] (friction law A, B, C and neck stiffness with `argmin`) →
//! [`report`] (SVG figures).
//!
//! The model is that of the seed paper (Unno et al., "Investigation of the dynamics of the wiper blade
//! around the reversal"; journal version J. Sound Vib. 393 (2017) 76), equations (1)–(5), written in SI
//! units (see `model::blade`).

pub mod bench;
pub mod cli;
pub mod error;
pub mod fit;
pub mod import;
pub mod model;
pub mod report;
pub mod simulate;
pub mod spectrum;
pub mod trace;

pub use error::{Error, Result};
