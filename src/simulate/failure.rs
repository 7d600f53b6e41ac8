//! Why a simulation (or the features read from it) gave no lines: [`FailureCause`], the
//! classification the fit counts per failed evaluation and the exploration per failed sample.

use crate::Error;
use crate::model::stick_slip::ModelFault;
use crate::names::named_enum;
use crate::simulate::error::{SimulationError, StopCause};

named_enum! {
    /// Why a sample gave no lines.
    pub enum FailureCause: "failure cause" {
        /// The lip tip left the glass (normal force N ≤ 0).
        ContactLoss => "contact_loss",
        /// The slip equations became singular (Painlevé-type).
        Painleve => "painleve",
        /// Another model fault: a singular system, no stick angle, no starting equilibrium.
        ModelFault => "model_fault",
        /// The adaptive step collapsed, or the step or transition budget ran out (Zeno).
        StepBudget => "step_budget",
        /// A band of the simulated signal holds no local maximum.
        NoLine => "no_line",
        /// Anything else (the message says what).
        Other => "other",
    }
}

impl FailureCause {
    /// The cause of a failed simulation or feature computation.
    pub fn of(e: &Error) -> FailureCause {
        match SimulationError::of(e).map(|s| &s.cause) {
            Some(StopCause::ContactLost { .. }) => FailureCause::ContactLoss,
            Some(StopCause::Model(ModelFault::Painleve { .. })) => FailureCause::Painleve,
            Some(StopCause::Model(_)) => FailureCause::ModelFault,
            Some(
                StopCause::StepSizeCollapse { .. }
                | StopCause::StepBudget { .. }
                | StopCause::TooManyTransitions { .. }
                | StopCause::Zeno { .. },
            ) => FailureCause::StepBudget,
            _ => FailureCause::Other,
        }
    }
}
