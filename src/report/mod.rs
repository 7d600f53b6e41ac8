//! Report stage: figures (and later tables) from results computed upstream; it computes nothing.
//!
//! * [`plot`]: SVG line charts (traces, PSDs with peak markers) and spectrogram heat maps.

pub mod plot;
