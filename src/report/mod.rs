//! Report stage: figures from results computed upstream; it computes nothing.
//!
//! * [`plot`]: SVG line charts (traces, PSDs with peak markers) and spectrogram heat maps.
//! * [`figures`]: which figures each command writes.
//! * [`html`]: the report page `reports/<job>/index.html`.
//! * [`summary`]: the report page's opening summary.
//! * [`warning`]: the page's warnings, by severity, with a headline and the full sentence.
//! * [`campaign`]: a campaign's report page, `<campaign dir>/<name>/report/index.html`.

pub mod campaign;
mod error;
pub mod explore;
pub mod figures;
pub mod html;
pub mod plot;
pub mod summary;
pub mod warning;

pub use error::{HeatmapProblem, ReportError};
