//! Physical models: the friction law (and its curve over a measured slip-speed range), the blade
//! link model, the belt-oscillator benchmarks.

pub mod belt;
pub mod benchmarks;
pub mod blade;
pub mod drive;
mod error;
pub mod friction;
pub mod friction_curve;
pub mod modes;
pub mod necklip;
pub mod params;
pub mod stick_slip;
pub mod trig;

pub use blade::{Blade, BladeParams, Shoulder, StickForm};
pub use error::{FrictionTableError, ParamError, TrackError};
pub use friction::{FrictionLaw, LawKind};
pub use params::ParamId;
