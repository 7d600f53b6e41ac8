//! Report stage: figures from results computed upstream; it computes nothing.
//!
//! * [`plot`]: SVG line charts (traces, PSDs with peak markers) and spectrogram heat maps.
//! * [`figures`]: which figures each command writes.
//! * [`html`]: the report page `reports/<job>/index.html`.

pub mod figures;
pub mod html;
pub mod plot;
