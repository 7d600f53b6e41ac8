//! The belt oscillator's limit cycle, measured from an event-driven run (physics.md §3.1–3.4): the
//! durations the benchmark tests compare with closed forms and tabulated references.

use super::hybrid::{Mode, Phase, SolverOptions, integrate};
use crate::Result;
use crate::model::belt::Belt;

/// Durations of one limit cycle of the belt oscillator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeltCycle {
    pub t_slip_s: f64,
    pub t_stick_s: f64,
    pub period_s: f64,
    /// Position at the slip→stick transition (x_e in physics.md §3.1).
    pub x_stick_onset_m: f64,
    /// Number of transitions located.
    pub transitions: usize,
}

/// Simulates `belt` from stick at `x0_m` over `[0, t_end_s]` and returns the durations of the last
/// complete stick–slip cycle (slip→stick to slip→stick). Returns `Ok(None)` when fewer than two
/// stick onsets occur: the motion does not stick–slip (the steady-sliding case of physics.md
/// §3.2).
///
/// # Errors
/// Those of [`integrate`].
pub fn limit_cycle(
    belt: &Belt,
    x0_m: f64,
    t_end_s: f64,
    opts: &SolverOptions,
) -> Result<Option<BeltCycle>> {
    let mode = Mode::new(Phase::Stick, x0_m);
    let y0 = [x0_m, belt.v_belt_m_per_s];
    let run = integrate(belt, 0.0, y0, mode, t_end_s, &[], opts)?;
    let tr = &run.transitions;
    let onsets: Vec<usize> = (0..tr.len())
        .filter(|&i| tr[i].to == Phase::Stick)
        .collect();
    if onsets.len() < 2 {
        return Ok(None);
    }
    let i1 = onsets[onsets.len() - 1];
    let i0 = onsets[onsets.len() - 2];
    let departure = tr[i0 + 1].t_s;
    Ok(Some(BeltCycle {
        t_slip_s: tr[i1].t_s - departure,
        t_stick_s: departure - tr[i0].t_s,
        period_s: tr[i1].t_s - tr[i0].t_s,
        x_stick_onset_m: run.transition_states[i1][0],
        transitions: tr.len(),
    }))
}
