//! CMA-ES with restarts of increasing population (IPOP) over the unit box `[0, 1]^n`: the global
//! search of `[fit.search] method = "cmaes"`.
//!
//! Each run is the `cmaes` crate's CMA-ES (active covariance update; Hansen 2016, "The CMA
//! Evolution Strategy: A Tutorial", arXiv:1604.00772) from a mean drawn uniformly in the box with
//! step size [`SIGMA0`]; run `r` samples `λ₀·2^r` points per generation (Auger & Hansen 2005,
//! "A restart CMA evolution strategy with increasing population size", CEC). The runs go on until
//! `restarts + 1` runs are done or the evaluation budget is spent, and the lowest point of all is
//! kept. A run ends on CMA-ES's own criteria or when its best cost has fallen by no more than
//! `tol_fun` over its last `10 + ⌈30 n / λ⌉` generations ([`stagnated`]).
//!
//! **Bounds.** CMA-ES samples the whole of ℝⁿ; the cost is read at the point mirrored into the box
//! ([`mirror`]: each coordinate reflected at 0 and 1, periodically). The search then sees a
//! continuous cost with no flat penalty region, and a minimum on a bound stays a minimum (the
//! mirrored copies meet there).

use cmaes::{CMAESOptions, DVector, TerminationReason};
use rand::{Rng, SeedableRng};

/// The first step size of every run, in units of the box's width: a run's first generation spreads
/// over most of the box (±1σ covers 60 %), as IPOP's restarts start anew.
pub const SIGMA0: f64 = 0.3;

/// A run ends when its distribution's standard deviation is below this in every coordinate (box
/// units): far below any interval the fit reports.
pub const TOL_X: f64 = 1e-4;

/// `x` reflected into `[0, 1]`: the identity inside, mirrored at each bound, with period 2.
pub fn mirror(x: f64) -> f64 {
    let t = x.rem_euclid(2.0);
    if t <= 1.0 { t } else { 2.0 - t }
}

/// The budget and stopping of an IPOP search.
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    /// The first run's population λ₀.
    pub population: usize,
    /// Restarts after the first run, at most.
    pub restarts: usize,
    /// Cost evaluations over all runs, at most: a run is cut short when it would pass them.
    pub max_evaluations: usize,
    /// A run ends when its last generation's costs, and its best cost over the last
    /// `10 + ⌈30 n / λ⌉` generations, each span less than this (CMA-ES's TolFun).
    pub tol_fun: f64,
    /// Seed of the runs' starting means and their samples.
    pub seed: u64,
}

/// One generation of a run, as the observer sees it.
#[derive(Debug, Clone, Copy)]
pub struct Generation<'a> {
    /// The run, from 0.
    pub run: usize,
    /// Its population λ.
    pub population: usize,
    /// The generation, from 1.
    pub generation: u64,
    /// The run's lowest cost so far and where (box coordinates).
    pub best_cost: f64,
    pub best_u: &'a [f64],
    /// The run's evaluations so far.
    pub run_evaluations: usize,
    /// The search's evaluations so far (all runs).
    pub evaluations: usize,
}

/// The end of one run.
#[derive(Debug, Clone)]
pub struct RunEnd {
    pub population: usize,
    pub cost: f64,
    pub evaluations: usize,
    pub generations: u64,
}

/// What the search found: the lowest point of all runs, and each run's end.
#[derive(Debug, Clone)]
pub struct Found {
    pub u: Vec<f64>,
    pub cost: f64,
    pub runs: Vec<RunEnd>,
    pub evaluations: usize,
}

/// The IPOP search of `cost` over `[0, 1]^n` (`cost` evaluated in parallel, each generation's
/// points at once). `observe` sees every generation and stops the search by returning `false`.
/// `None` when no generation finished (stopped before the first).
pub fn search(
    n: usize,
    cost: &(dyn Fn(&[f64]) -> f64 + Sync),
    settings: &Settings,
    observe: &mut dyn FnMut(Generation) -> bool,
) -> Option<Found> {
    let mut best: Option<(Vec<f64>, f64)> = None;
    let mut runs = Vec::new();
    let mut evaluations = 0;
    for run in 0..=settings.restarts {
        let remaining = settings.max_evaluations.saturating_sub(evaluations);
        let population = settings.population.max(2).saturating_mul(1 << run.min(20));
        if remaining < population {
            break;
        }
        let run_seed = settings.seed ^ (run as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let mut rng = rand::rngs::StdRng::seed_from_u64(run_seed);
        let mean: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..=1.0)).collect();
        let start = Start {
            run,
            mean,
            sigma: SIGMA0,
            population,
            budget: remaining,
            tol_fun: settings.tol_fun,
            seed: run_seed,
            evaluations_before: evaluations,
        };
        let (end, stopped) = one_run(start, cost, observe);
        if let Some((u, c, run_end)) = end {
            evaluations += run_end.evaluations;
            runs.push(run_end);
            if best.as_ref().is_none_or(|b| c < b.1) {
                best = Some((u, c));
            }
        }
        if stopped {
            break;
        }
    }
    best.map(|(u, cost)| Found {
        u,
        cost,
        runs,
        evaluations,
    })
}

/// The step size of a local run ([`local`]), in units of the box's width: ±1σ spans a fifth of
/// the box, wide enough to step over the ripples and low ridges of a stick–slip likelihood that
/// stop a simplex, narrow enough to stay in the basin a swarm found.
pub const LOCAL_SIGMA: f64 = 0.1;

/// One CMA-ES run of `cost` from `start` (box coordinates) with step size [`LOCAL_SIGMA`] and
/// CMA-ES's default population for `start.len()` parameters, over at most `max_evaluations`:
/// the local stage after a swarm (`[fit.search] local = "cmaes"`). Stops as every run of
/// [`search`] does (CMA-ES's criteria, stagnation by `tol_fun`, `observe` returning `false`).
pub fn local(
    start: &[f64],
    cost: &(dyn Fn(&[f64]) -> f64 + Sync),
    max_evaluations: usize,
    tol_fun: f64,
    seed: u64,
    observe: &mut dyn FnMut(Generation) -> bool,
) -> Option<Found> {
    let n = start.len();
    let population = crate::job::default_population(n);
    let run = Start {
        run: 0,
        mean: start.to_vec(),
        sigma: LOCAL_SIGMA,
        population,
        budget: max_evaluations.max(population),
        tol_fun,
        seed,
        evaluations_before: 0,
    };
    let (end, _) = one_run(run, cost, observe);
    end.map(|(u, cost, run_end)| Found {
        u,
        cost,
        evaluations: run_end.evaluations,
        runs: vec![run_end],
    })
}

/// Where and how one CMA-ES run starts.
struct Start {
    /// The run's index (for the observer).
    run: usize,
    mean: Vec<f64>,
    sigma: f64,
    population: usize,
    /// Evaluations the run may spend (rounded down to whole generations).
    budget: usize,
    tol_fun: f64,
    seed: u64,
    /// Evaluations of earlier runs (for the observer's total).
    evaluations_before: usize,
}

/// One CMA-ES run: its lowest point, cost and end (`None` when no generation finished or the
/// options are refused), and whether the search must stop (the observer said so, or a cost was
/// invalid).
fn one_run(
    start: Start,
    cost: &(dyn Fn(&[f64]) -> f64 + Sync),
    observe: &mut dyn FnMut(Generation) -> bool,
) -> (Option<(Vec<f64>, f64, RunEnd)>, bool) {
    let n = start.mean.len();
    let objective = |x: &DVector<f64>| {
        let u: Vec<f64> = x.iter().map(|&v| mirror(v)).collect();
        let c = cost(&u);
        if c.is_nan() { f64::INFINITY } else { c }
    };
    let population = start.population;
    let options = CMAESOptions::new(start.mean, start.sigma)
        .population_size(population)
        .seed(start.seed)
        .tol_fun(start.tol_fun)
        .tol_fun_hist(start.tol_fun)
        .tol_x(TOL_X)
        .max_function_evals(start.budget - start.budget % population);
    let Ok(mut cma) = options.build(objective) else {
        return (None, true);
    };
    let mut run_best: Option<(Vec<f64>, f64)> = None;
    let mut generations = 0;
    // The run's best cost after each generation, for its stagnation.
    let mut bests: Vec<f64> = Vec::new();
    let window = stagnation_window(n, population);
    let mut stopped = false;
    let run_evaluations = loop {
        let end = cma.next_parallel();
        generations += 1;
        if let Some(b) = cma.overall_best_individual() {
            let u: Vec<f64> = b.point.iter().map(|&v| mirror(v)).collect();
            run_best = Some((u, b.value));
            bests.push(b.value);
        }
        let done = cma.function_evals();
        if let Some((u, c)) = &run_best {
            let go_on = observe(Generation {
                run: start.run,
                population,
                generation: generations,
                best_cost: *c,
                best_u: u,
                run_evaluations: done,
                evaluations: start.evaluations_before + done,
            });
            if !go_on {
                stopped = true;
                break done;
            }
        }
        match end {
            Some(t) if t.reasons.contains(&TerminationReason::InvalidFunctionValue) => {
                stopped = true;
                break done;
            }
            Some(_) => break done,
            None if stagnated(&bests, window, start.tol_fun) => break done,
            None => {}
        }
    };
    let end = run_best.map(|(u, c)| {
        let run_end = RunEnd {
            population,
            cost: c,
            evaluations: run_evaluations,
            generations,
        };
        (u, c, run_end)
    });
    (end, stopped)
}

/// The generations over which a run's best cost must fall by more than `tol_fun` to go on:
/// `10 + ⌈30 n / λ⌉`, the history CMA-ES's own TolFun reads (Hansen 2016, appendix B.3).
fn stagnation_window(n: usize, population: usize) -> usize {
    10 + (30 * n).div_ceil(population.max(1))
}

/// Whether a run whose best cost after each generation is `bests` has stagnated: its best fell by
/// no more than `tol` over the last `window` generations. CMA-ES's own TolFun also asks that one
/// generation's costs span less than `tol`, which a cost with failed evaluations (a fixed high
/// cost) or ripples deeper than `tol` never meets, so a run in a basin it cannot leave would go on
/// until its spread shrinks to [`TOL_X`]; a new run of twice the population does more with those
/// evaluations.
fn stagnated(bests: &[f64], window: usize, tol: f64) -> bool {
    bests.len() > window && bests[bests.len() - 1 - window] - bests[bests.len() - 1] <= tol
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rastrigin's function on x = 10·u − 5.12 (u ∈ [0, 1]^n, x ∈ [−5.12, 4.88]^n):
    /// `10 n + Σ (x² − 10 cos 2πx)`, whose global minimum is 0 at x = 0, i.e. u = 0.512 in every
    /// coordinate, among ~10ⁿ local minima near the integer points (closed form).
    fn rastrigin(u: &[f64]) -> f64 {
        u.iter()
            .map(|&u| {
                let x = 10.0 * u - 5.12;
                x * x - 10.0 * (2.0 * std::f64::consts::PI * x).cos() + 10.0
            })
            .sum()
    }

    fn settings(seed: u64) -> Settings {
        Settings {
            population: 8,
            restarts: 6,
            max_evaluations: 60_000,
            tol_fun: 1e-9,
            seed,
        }
    }

    #[test]
    fn ipop_finds_rastrigins_global_minimum_in_four_dimensions() {
        for seed in 1..=3 {
            let found = search(4, &rastrigin, &settings(seed), &mut |_| true).expect("runs");
            // The nearest other minima (one coordinate at x = ±1) cost 0.99; a run stops once its
            // spread is below TOL_X (x within ~1e-3 of 0, cost ~1e-4).
            assert!(
                found.cost < 1e-3,
                "seed {seed}: ended at {} after {} runs ({:?})",
                found.cost,
                found.runs.len(),
                found.runs
            );
            for u in &found.u {
                assert!((u - 0.512).abs() < 1e-3, "seed {seed}: {:?}", found.u);
            }
            assert!(found.evaluations <= 60_000);
        }
    }

    /// Two Gaussian basins in [0, 1]²: a wide, shallow one at (0.25, 0.25) (depth 1, width 0.2)
    /// and a narrower, deeper one at (0.9, 0.8) (depth 2, width `NARROW`); the minimum is the
    /// narrower one's, −2 at (0.9, 0.8) up to the other's tail (1.2e-4 there, closed form).
    const NARROW: f64 = 0.1;

    fn two_basins(u: &[f64]) -> f64 {
        let d2 = |c: [f64; 2]| (u[0] - c[0]).powi(2) + (u[1] - c[1]).powi(2);
        -(-d2([0.25, 0.25]) / (2.0 * 0.2f64.powi(2))).exp()
            - 2.0 * (-d2([0.9, 0.8]) / (2.0 * NARROW.powi(2))).exp()
    }

    #[test]
    fn ipop_finds_the_narrow_deeper_basin() {
        for seed in 1..=5 {
            let found = search(2, &two_basins, &settings(seed), &mut |_| true).expect("runs");
            assert!(found.cost < -1.999, "seed {seed}: {found:?}");
            let off = (found.u[0] - 0.9).hypot(found.u[1] - 0.8);
            assert!(off < 1e-3, "seed {seed}: {found:?}");
        }
    }

    /// A minimum on a bound: (u₀ + 1)² + (u₁ − 0.3)² has its box minimum 1 at (0, 0.3), where the
    /// mirrored cost meets its reflection.
    #[test]
    fn a_minimum_on_a_bound_is_found_through_the_mirror() {
        let f = |u: &[f64]| (u[0] + 1.0).powi(2) + (u[1] - 0.3).powi(2);
        let found = search(2, &f, &settings(2), &mut |_| true).expect("runs");
        assert!((found.cost - 1.0).abs() < 1e-8, "{found:?}");
        assert!(
            found.u[0] < 1e-4 && (found.u[1] - 0.3).abs() < 1e-4,
            "{found:?}"
        );
    }

    /// A local run descends into the basin it starts in: from (0.8, 0.7), 1.4 widths from the
    /// narrow basin's centre, to its minimum −2 at (0.9, 0.8); from (0.35, 0.3) on the wide
    /// basin's slope to the wide basin's minimum −1 at (0.25, 0.25) (the narrow one's tail there
    /// is below 1e-13), though the narrow basin is deeper: the stage refines a swarm's basin and
    /// leaves the global search to the swarms.
    #[test]
    fn a_local_run_descends_into_the_basin_it_starts_in() {
        let found = local(&[0.8, 0.7], &two_basins, 2000, 1e-9, 1, &mut |_| true).expect("run");
        assert!(found.cost < -1.999, "{found:?}");
        assert!(
            (found.u[0] - 0.9).hypot(found.u[1] - 0.8) < 1e-3,
            "{found:?}"
        );
        let found = local(&[0.35, 0.3], &two_basins, 2000, 1e-9, 1, &mut |_| true).expect("run");
        assert!((found.cost + 1.0).abs() < 1e-6, "{found:?}");
        assert!(
            (found.u[0] - 0.25).hypot(found.u[1] - 0.25) < 1e-3,
            "{found:?}"
        );
        assert_eq!(found.runs.len(), 1);
    }

    #[test]
    fn a_local_run_keeps_to_its_budget() {
        // Population 4 + ⌊3 ln 4⌋ = 8: 100 evaluations are twelve whole generations (96).
        let found = local(&[0.3; 4], &rastrigin, 100, 1e-12, 3, &mut |_| true).expect("run");
        assert!(found.evaluations <= 100, "{}", found.evaluations);
        assert_eq!(found.runs[0].population, 8);
    }

    #[test]
    fn the_budget_and_the_observer_stop_the_search() {
        let s = Settings {
            max_evaluations: 500,
            ..settings(1)
        };
        let found = search(4, &rastrigin, &s, &mut |_| true).expect("runs");
        assert!(found.evaluations <= 500, "{}", found.evaluations);
        let mut generations = 0;
        let stopped = search(4, &rastrigin, &settings(1), &mut |_| {
            generations += 1;
            generations < 3
        })
        .expect("one generation");
        assert_eq!(stopped.runs.len(), 1);
        assert_eq!(stopped.evaluations, 3 * 8);
    }

    #[test]
    fn a_run_stagnates_when_its_best_stops_falling() {
        // Window 3: the best 10 → 9.96 over the last three generations is no fall beyond 0.05.
        assert!(stagnated(&[12.0, 10.0, 9.99, 9.98, 9.96], 3, 0.05));
        assert!(!stagnated(&[12.0, 10.0, 9.99, 9.98, 9.94], 3, 0.05));
        assert!(
            !stagnated(&[10.0, 10.0, 10.0], 3, 0.05),
            "too short to tell"
        );
        assert_eq!(stagnation_window(4, 8), 25);
        assert_eq!(stagnation_window(6, 9), 30);
    }

    #[test]
    fn mirror_reflects_into_the_box() {
        for (x, u) in [
            (0.3, 0.3),
            (-0.2, 0.2),
            (1.25, 0.75),
            (2.1, 0.1),
            (-1.5, 0.5),
        ] {
            assert!((mirror(x) - u).abs() < 1e-12, "{x}");
        }
    }
}
