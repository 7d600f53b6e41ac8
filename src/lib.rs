//! # wiperlab
//!
//! A windshield-wiper blade's measured motion beside a physical model of it.
//!
//! The module tree is the pipeline; a stage uses only the stages before it (checked by
//! `tests/suite/architecture.rs`):
//!
//! Pipeline order: `error` → `names` → `io` → `trace` → `import` → `spectrum` → `model` → `simulate` → `job` → `likelihood` → `posterior` → `estimate` → `search` → `uncertainty` → `fit` → `explore` → `campaign` → `report` → `bench` → `cli`.
//!
//! * [`error`]: the crate's error type, shared by every stage.
//! * [`names`]: typed names (model kinds, parameter ids, ...), each spelled once.
//! * [`io`]: atomic file writes ([`io::write_atomic`]) and the never-over-an-input check.
//! * [`trace`]: the canonical [`trace::Trace`] (SI, y up, NaN = missing), the type every stage
//!   downstream reads.
//! * [`import`]: tracking-tool exports → [`trace::Trace`] (pixels and frames end here).
//! * [`spectrum`]: Welch PSD, peaks, spectrogram, instantaneous frequency.
//! * [`model`]: the friction law, the 2-DOF head/neck/lip link model, the belt benchmarks, and the
//!   contract between a stick–slip model and the integrator ([`model::stick_slip`]).
//! * [`simulate`]: the event-driven integrator and the blade runner (a simulation becomes a
//!   [`trace::Trace`] like a measurement).
//! * [`job`]: the fit job file (TOML) read and checked, its candidate models, and the template
//!   `wiperlab init` writes.
//! * [`likelihood`]: the recording measured as the job asks (features per band, noise floors,
//!   frequency against tip speed) and the calibrated likelihood that reads its spectra.
//! * [`posterior`]: the affine-invariant ensemble sampler, its convergence diagnostics and the
//!   posterior summary a fit reports.
//! * [`estimate`]: what an estimate is made of, as data: each fitted parameter's interval and its
//!   method, and the warnings that qualify a fit (their sentences are written in [`fit`]).
//! * [`search`]: the optimum of each candidate model's cost: the cost of one parameter set
//!   ([`search::SpectralProblem`]), the optimisers (particle swarm, IPOP CMA-ES, Nelder–Mead) and
//!   the strategy that restarts, confirms and polishes them.
//! * [`uncertainty`]: the chosen fit's intervals (Laplace, profile likelihood, parametric
//!   bootstrap, posterior sample) and the profile climb that walks them.
//! * [`fit`]: a fit job run: its candidates searched, the model chosen (TIC), the chosen optimum
//!   checked (solver tolerance, the job's truth), its intervals and warnings, and the result.
//! * [`explore`]: where a job's freed parameters can take the model's lines (`wiperlab explore`).
//! * [`campaign`]: one fit job over many recordings, locally in parallel or as a Slurm job array,
//!   collected into one table.
//! * [`report`]: SVG figures and the HTML report page, drawn from values computed upstream.
//! * [`bench`]: the work–precision study behind `wiperlab bench`.
//! * [`cli`]: argument parsing and dispatch for the `wiperlab` binary.
//!
//! The model is that of the seed paper (Unno et al., "Investigation of the dynamics of the wiper blade
//! around the reversal"; journal version J. Sound Vib. 393 (2017) 76), equations (1)–(5), written in SI
//! units (see `model::blade`).

pub mod bench;
pub mod campaign;
pub mod cli;
pub mod error;
pub mod estimate;
pub mod explore;
pub mod fit;
pub mod import;
pub mod io;
pub mod job;
pub mod likelihood;
pub mod model;
pub mod names;
pub mod posterior;
pub mod report;
pub mod search;
pub mod simulate;
pub mod spectrum;
pub mod trace;
pub mod uncertainty;

pub use error::{Error, Result};
