//! The search: the optimum of each candidate model's cost over its freed parameters.
//!
//! * [`problem`]: the cost of one parameter set ([`SpectralProblem`]): simulate, measure the
//!   model's spectra as the recording's, compare (features or the recording's likelihood).
//! * [`evidence`]: the recording's likelihood at a point of the search, the settling of its
//!   optimum at the intervals' scale and the sandwich covariance there.
//! * [`strategy`]: each candidate searched (particle swarm or IPOP CMA-ES, restarts that confirm
//!   their ends, Nelder–Mead polishes, nested and warm starts) into a
//!   [`strategy::CandidateFit`], with its history and progress reported through argmin observers.
//! * [`ipop`]: CMA-ES with restarts of increasing population over the unit box.
//! * [`jitter`]: how much the cost moves under steps far below any physical scale.
//! * [`scan`]: the contact-angle scan of a shoulder candidate.
//! * [`history`]: the stages of the optimiser and the best cost after each iteration.
//! * [`interrupt`]: SIGINT/SIGTERM stop a running search, which keeps its best point.
//! * [`error`]: what can go wrong in a fit ([`FitError`]).
//!
//! The features cost (per band `b`, measured `d`, model `m`, model PSD plus the measurement's noise
//! floor): `w_peak·(ln f_m/f_d / 0.01)² + w_level·(ln L_m/L_d / ln 2)² + w_shape·mean_k (ln P_m,k −
//! ln P_d,k)²`. Two peak frequencies alone cannot pin down four parameters, hence the level and
//! shape terms; the result still says which parameters the data leave undetermined (from the
//! cost's curvature). With a recording, the default cost is its likelihood ([`evidence`]).
//!
//! Parameters are searched in normalised coordinates `u ∈ [0, 1]` (logarithmic for bounds spanning
//! a factor ≥ 10).

pub mod error;
pub mod evidence;
pub mod history;
pub mod interrupt;
pub mod ipop;
pub mod jitter;
pub mod problem;
pub mod scan;
pub mod strategy;

pub use error::{FitError, NoEvidence, NoLikelihood};
pub use problem::{FAILED_COST, SpectralProblem, target_cost};
pub use strategy::{NESTED_GLOBAL_GAIN_NATS, problem_for};
