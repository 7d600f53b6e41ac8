//! What a search records as it goes: the stage of the optimiser an evaluation belongs to
//! ([`SearchStage`]) and the best cost after each iteration ([`HistoryPoint`]), which a fit's result
//! keeps and its report draws.

use crate::names::named_enum;
use serde::{Deserialize, Serialize};

named_enum! {
    /// A stage of the optimiser. The swarm may simulate at a looser tolerance (`[fit] swarm_rtol`)
    /// than the polish and everything after it.
    pub enum SearchStage: "search stage" {
        /// The global particle swarm.
        Swarm => "swarm",
        /// The Nelder–Mead polish from the swarm's best particle.
        Polish => "polish",
        /// A CMA-ES run (`[fit.search] method = "cmaes"`), on the recording's likelihood at the
        /// job's tolerance.
        Cmaes => "cmaes",
        /// The local CMA-ES run from a swarm's best particle (`[fit.search] local = "cmaes"`),
        /// before its Nelder–Mead polish.
        Local => "local",
        /// In a fit that reads further signals (`[fit.likelihood] joint_signals`), the second
        /// local CMA-ES run from the same particle as `Local`, on the measured signal's own
        /// likelihood: its basins are wider than the joint likelihood's.
        SignalLocal => "signal_local",
        /// The Nelder–Mead polish, on the joint likelihood, from the end of `SignalLocal`.
        SignalPolish => "signal_polish",
    }
}

/// Best cost after each iteration of each stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistoryPoint {
    pub stage: SearchStage,
    /// Which of the fit's independent swarm-and-polish runs (`[fit] restarts`), or which CMA-ES
    /// run (`[fit.search] restarts`), from 0; 0 in results written before this field.
    #[serde(default)]
    pub restart: usize,
    pub iteration: u64,
    pub best_cost: f64,
    /// Model evaluations of this restart so far (its swarm and polish).
    pub evaluations: usize,
}
