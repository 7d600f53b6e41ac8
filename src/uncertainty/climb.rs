//! The profile climb: the chosen candidate's profile likelihood walked before its intervals, and
//! the fit moved on where a walk meets a point more likely than the search's end.
//!
//! Why: a walk re-polishes the other parameters at every step of one parameter
//! ([`super::intervals::profile_intervals_at`]), so it follows the likelihood's valleys out to
//! where the interval ends, and it crosses the low ridges between shallow basins of a stick–slip
//! likelihood that a search's polish stops in front of. On a calibration recording whose search
//! ended 2.4 nats short of the truth's own cost, with B 41 % off and every Laplace interval but A's
//! excluding the truth, the profile walks met points 3.0–3.1 nats more likely than the fit
//! (docs/validation.md, "The profile climb"). A fit that reports such a point's neighbour as its
//! estimate has failed its search; the climb continues the search from the best point a walk met
//! (a Nelder–Mead polish, then the settling every search end gets) and walks again, at most
//! [`PROFILE_CLIMBS`] times. The last walk, at the optimum the fit reports, is kept for the
//! profile intervals ([`ProfileWalk`]), so a fit that does not move pays for one walk.

use super::intervals::{ProfileStart, profile_walk};
use crate::Result;
use crate::job;
use crate::search::interrupt;
use crate::search::strategy::{
    CONFIRM_NATS, CandidateFit, Optimised, POLISH_STEP_U, ProfileWalk, Reporting, VALLEY_GAIN_NATS,
    add_note, keep_nested_above, polish, settle_anew,
};

/// The most times the climb moves the fit: each move costs a polish, a settling and a walk.
pub const PROFILE_CLIMBS: usize = 3;

/// The profile climb on the chosen candidate `fits[chosen]` (`[fit.uncertainty] method =
/// "profile"`): walks its profile; where a walk met a point more than [`CONFIRM_NATS`] more likely
/// than the fit, polishes from the best one, settles anew and walks again (at most
/// [`PROFILE_CLIMBS`] moves, each kept only when it lowers the cost by more than
/// [`VALLEY_GAIN_NATS`]). Candidates nested on a moved one keep at least its likelihood. The last
/// walk is kept in the fit for its intervals. Returns whether the chosen candidate moved (the
/// choice is then made again by the caller).
///
/// # Errors
/// The polish's, the settling's and the walk's (a walk's failed simulations count as an infinite
/// rise, not an error).
pub(crate) fn climb_chosen(
    job: &job::LoadedJob,
    fits: &mut Vec<CandidateFit>,
    chosen: usize,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<bool> {
    if !fits[chosen].problem.cost_is_nll() || fits[chosen].evidence.is_err() {
        return Ok(false);
    }
    let started = std::time::Instant::now();
    let mut moves = 0;
    let mut gain = 0.0;
    let moved = loop {
        let walk = walk(&fits[chosen], job.job.fit.polish_iterations, pb)?;
        let f = &mut fits[chosen];
        // Kept unless the fit moves (settling anew makes a fit without a walk).
        f.profile_walk = walk;
        let start = {
            let near = f.problem.near_best.lock();
            let near = near.unwrap_or_else(|e| e.into_inner());
            near.lowest_point_below(f.cost - CONFIRM_NATS)
                .map(<[f64]>::to_vec)
        };
        let Some(start) = start.filter(|_| moves < PROFILE_CLIMBS && !interrupt::stop_requested())
        else {
            break moves > 0;
        };
        let reporting = Reporting::continuing(f, pb);
        reporting.stage(format_args!("profile climb {}", moves + 1));
        let (u, polish_iters, cost) = polish(
            &f.problem,
            &start,
            POLISH_STEP_U,
            job.job.fit.polish_iterations,
            None,
        )?;
        if f.cost - cost <= VALLEY_GAIN_NATS {
            break moves > 0;
        }
        let before = f.cost;
        let found = Optimised {
            u,
            swarm_iters: f.swarm_iters,
            polish_iters: f.polish_iters + polish_iters,
            cost,
            unconfirmed_ends: None,
        };
        let wall_time_s = f.wall_time_s;
        settle_anew(f, found, &reporting, pb)?;
        f.wall_time_s = wall_time_s;
        gain += before - f.cost;
        moves += 1;
    };
    let f = &mut fits[chosen];
    f.wall_time_s += started.elapsed().as_secs_f64();
    if moved {
        add_note(&mut f.search_note, climb_note(moves, gain));
        keep_nested_above(fits, chosen, pb)?;
    }
    Ok(moved)
}

/// What [`climb_chosen`] did, for the candidate's search note.
fn climb_note(moves: usize, gain_nats: f64) -> String {
    format!(
        "profile climb: the profile walks met a more likely point, the fit moved {moves} time{} and is {gain_nats:.3} nats lower",
        if moves == 1 { "" } else { "s" }
    )
}

/// The profile walk of `f` at its optimum, with the 1σ of the spread its intervals report
/// ([`crate::search::evidence::at_fit_smoothed`]); `None` after an interrupt or where that spread fails.
fn walk(
    f: &CandidateFit,
    polish_iterations: u64,
    pb: &Option<indicatif::ProgressBar>,
) -> Result<Option<ProfileWalk>> {
    if interrupt::stop_requested() {
        return Ok(None);
    }
    let Ok(spread) = crate::search::evidence::at_fit_smoothed(&f.problem, &f.best_u) else {
        return Ok(None);
    };
    let at = ProfileStart {
        u: &f.best_u,
        cost_nats: f.cost,
        sigma_u: &spread.sigma_u,
        fisher_sigma_u: &spread.curvature_sigma_u,
        fisher_corr: Some(&spread.curvature_corr),
    };
    let (intervals, warnings) = profile_walk(f, at, polish_iterations, pb)?;
    Ok(Some(ProfileWalk {
        at_u: f.best_u.clone(),
        spread,
        intervals,
        warnings,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::search::problem::EvaluatedNearBest;

    /// The climb starts from the lowest point kept, and only when it lies more than the margin
    /// below the fit: a fit at 10 nats with points kept at 9.7, 9.2 and 9.4 nats climbs from the
    /// 9.2-nat point past a 0.5-nat margin, and not past a 1-nat one.
    #[test]
    fn the_climb_starts_from_the_lowest_point_beyond_the_margin() {
        let mut near = EvaluatedNearBest::default();
        near.record(&[0.1, 0.1], 9.7);
        near.record(&[0.2, 0.3], 9.2);
        near.record(&[0.4, 0.5], 9.4);
        assert_eq!(
            near.lowest_point_below(10.0 - CONFIRM_NATS),
            Some([0.2, 0.3].as_slice())
        );
        assert_eq!(near.lowest_point_below(10.0 - 1.0), None);
        assert_eq!(EvaluatedNearBest::default().lowest_point_below(10.0), None);
    }
}
