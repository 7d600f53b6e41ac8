//! Search variants on one candidate of a job (docs/validation.md, "A local CMA-ES stage"): per
//! restart, a particle swarm ranked by the likelihood of a coarsened spectrum (every band's Welch
//! segment divided by `--coarsest`; 1: the job's own) or, with `--features`, by the feature cost
//! at rtol 1e-6; then optionally a local CMA-ES run on the job's likelihood (`--cmaes N`
//! evaluations, step `--sigma` box widths); then Nelder–Mead polishes down the ladder of
//! resolutions to the job's own. Prints each stage's end and, with a `[truth]`, the truth's cost
//! at every resolution.
//!
//! ```sh
//! cargo run --release --example search_ladder -- JOB.toml --model blade2dof --coarsest 1 --cmaes 1000
//! ```

use argmin::core::{CostFunction, Executor, State};
use argmin::solver::neldermead::NelderMead;
use argmin::solver::particleswarm::ParticleSwarm;
use clap::Parser;
use rand::SeedableRng;
use std::path::PathBuf;
use std::sync::Arc;
use wiperlab::job::{Candidate, LoadedJob};
use wiperlab::search::{SpectralProblem, problem_for};

#[derive(Parser)]
struct Args {
    job: PathBuf,
    #[arg(long)]
    model: String,
    #[arg(long, default_value_t = 8)]
    coarsest: usize,
    #[arg(long, default_value_t = 5)]
    restarts: usize,
    #[arg(long, default_value_t = 24)]
    particles: usize,
    #[arg(long, default_value_t = 25)]
    iterations: u64,
    #[arg(long, default_value_t = 60)]
    polish: u64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Rank the swarm's particles by the feature cost at rtol 1e-6 (as the fit does).
    #[arg(long)]
    features: bool,
    /// Local stage: a CMA-ES run of this many evaluations from the swarm's best (0: Nelder–Mead).
    #[arg(long, default_value_t = 0)]
    cmaes: usize,
    #[arg(long, default_value_t = 0.1)]
    sigma: f64,
}

#[derive(Clone)]
struct Features(Arc<SpectralProblem>);

impl CostFunction for Features {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, u: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        let p = &self.0;
        if u.iter().any(|x| !(0.0..=1.0).contains(x)) {
            return Ok(1e9);
        }
        let params = p.params_at(u);
        Ok(p.simulate(&params)
            .ok()
            .and_then(|s| p.model_features(&s).ok())
            .map_or(1e9, |f| p.cost_of(&f)))
    }
    fn parallelize(&self) -> bool {
        true
    }
}

fn mirror(x: f64) -> f64 {
    let t = x.rem_euclid(2.0);
    if t <= 1.0 { t } else { 2.0 - t }
}

fn local_cmaes(
    p: &Arc<SpectralProblem>,
    start: &[f64],
    budget: usize,
    sigma: f64,
    seed: u64,
) -> (Vec<f64>, f64) {
    use cmaes::{CMAESOptions, DVector};
    let objective = |x: &DVector<f64>| {
        let u: Vec<f64> = x.iter().map(|&v| mirror(v)).collect();
        let c = p.cost_at(&u);
        if c.is_nan() { f64::INFINITY } else { c }
    };
    let mut cma = CMAESOptions::new(start.to_vec(), sigma)
        .seed(seed)
        .tol_fun(0.05)
        .tol_x(1e-4)
        .max_function_evals(budget)
        .build(objective)
        .expect("cmaes");
    let _ = cma.run_parallel();
    let b = cma.overall_best_individual().expect("best");
    (b.point.iter().map(|&v| mirror(v)).collect(), b.value)
}

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

#[derive(Clone)]
struct Cost(Arc<SpectralProblem>);

impl CostFunction for Cost {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, u: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        Ok(self.0.cost_at(u))
    }
    fn parallelize(&self) -> bool {
        true
    }
}

fn polish(p: &Arc<SpectralProblem>, start: &[f64], iters: u64) -> Fallible<(Vec<f64>, f64)> {
    let mut simplex = vec![start.to_vec()];
    for i in 0..start.len() {
        let mut v = start.to_vec();
        v[i] = if v[i] + 0.05 <= 1.0 {
            v[i] + 0.05
        } else {
            v[i] - 0.05
        };
        simplex.push(v);
    }
    let nm = NelderMead::new(simplex).with_sd_tolerance(0.05)?;
    let res = Executor::new(Cost(p.clone()), nm)
        .configure(|s| s.max_iters(iters))
        .run()?;
    let u: Vec<f64> = res
        .state()
        .get_best_param()
        .cloned()
        .unwrap_or_else(|| start.to_vec())
        .iter()
        .map(|x| x.clamp(0.0, 1.0))
        .collect();
    Ok((u, res.state().get_best_cost()))
}

fn main() -> Fallible<()> {
    let args = Args::parse();
    let job = LoadedJob::load(&args.job)?;
    let candidate: Candidate = args.model.parse()?;
    let mut levels: Vec<(usize, Arc<SpectralProblem>)> = Vec::new();
    let mut div = args.coarsest.max(1);
    loop {
        let mut j = job.clone();
        for b in &mut j.job.spectrum.bands {
            b.nperseg = (b.nperseg / div).max(32);
        }
        levels.push((div, Arc::new(problem_for(&j, candidate)?)));
        if div == 1 {
            break;
        }
        div /= 2;
    }
    let fine = &levels.last().ok_or("no level")?.1;
    let n = fine.free.len();
    let truth: Option<Vec<f64>> = fine
        .free
        .iter()
        .map(|f| job.truth.get(&f.name).map(|t| f.u_of(*t)))
        .collect();
    if let Some(t) = &truth {
        let c: Vec<String> = levels
            .iter()
            .map(|(d, p)| format!("/{d} {:.2}", p.cost_at(t)))
            .collect();
        println!("truth: {}", c.join(", "));
    }
    let mut best = f64::INFINITY;
    for r in 0..args.restarts {
        let seed = args.seed ^ (r as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let pso = ParticleSwarm::new((vec![0.0; n], vec![1.0; n]), args.particles)
            .with_rng_generator(rand::rngs::StdRng::seed_from_u64(seed));
        let res = if args.features {
            let mut q = problem_for(&job, candidate)?;
            q.solver.atol *= 1e-6 / q.solver.rtol;
            q.solver.rtol = 1e-6;
            let res = Executor::new(Features(Arc::new(q)), pso)
                .configure(|s| s.max_iters(args.iterations))
                .run()?;
            let b = res.state().get_best_param().ok_or("no particle")?;
            (b.position.clone(), res.state().get_best_cost())
        } else {
            let res = Executor::new(Cost(levels[0].1.clone()), pso)
                .configure(|s| s.max_iters(args.iterations))
                .run()?;
            let b = res.state().get_best_param().ok_or("no particle")?;
            (b.position.clone(), res.state().get_best_cost())
        };
        let mut u = res.0;
        let mut line = format!(
            "restart {r}: swarm {:.2} (NLL {:.2})",
            res.1,
            fine.cost_at(&u)
        );
        if args.cmaes > 0 {
            let (v, c) = local_cmaes(fine, &u, args.cmaes, args.sigma, seed);
            u = v;
            line += &format!(", cmaes {c:.2}");
        }
        for (d, p) in &levels {
            let (v, c) = polish(p, &u, args.polish)?;
            u = v;
            line += &format!(", /{d} {c:.2}");
        }
        let end = fine.cost_at(&u);
        best = best.min(end);
        let vals: Vec<String> = fine
            .free
            .iter()
            .zip(&u)
            .map(|(f, x)| format!("{} {:.4}", f.name, f.value(*x)))
            .collect();
        println!("{line}  [{}]", vals.join(", "));
    }
    println!(
        "best end {best:.2} nats, {} evaluations",
        levels
            .iter()
            .map(|(_, p)| p.evaluations.load(std::sync::atomic::Ordering::Relaxed))
            .sum::<usize>()
    );
    Ok(())
}
