//! What the fit's particle swarm sees against what the likelihood says, for one candidate of a job
//! with a `[truth]`:
//!
//! 1. **At named points** (the truth, and the fitted point of each `--result` whose model is the
//!    candidate): the recording's NLL (the polish's cost) and the feature cost (what the swarm ranks
//!    its particles by) at rtol 1e-6, 1e-8 and 1e-10 (atol scaled with rtol, as `[fit] swarm_rtol`
//!    scales it).
//! 2. **Over the box** (`--samples N`): N points of a scrambled Sobol sequence in the fit's
//!    normalised coordinates (seed 1, as `wiperlab explore`), each simulated at the swarm's
//!    tolerance (feature cost) and at the job's (NLL): how many lie below the truth by each cost,
//!    and the lowest few by each.
//!
//! ```sh
//! cargo run --release --example search_landscape -- JOB.toml --model blade2dof \
//!     --result JOB.result.toml --samples 256
//! ```

use clap::Parser;
use rayon::prelude::*;
use std::path::PathBuf;
use wiperlab::job::{Candidate, LoadedJob};
use wiperlab::search::{SpectralProblem, problem_for};
use wiperlab::simulate::SolverOptions;

#[derive(Parser)]
struct Args {
    /// The fit job (with `[truth]` for every freed parameter of the candidate).
    job: PathBuf,
    /// The candidate model (`blade2dof`, `head1dof`, `blade2dof+shoulder`, ...).
    #[arg(long)]
    model: String,
    /// Results whose fitted point is read (each must have fitted `--model`).
    #[arg(long)]
    result: Vec<PathBuf>,
    /// Sobol points over the box (0: none).
    #[arg(long, default_value_t = 0)]
    samples: usize,
    /// Also read the NLL at the truth moved along each coordinate by these normalised steps
    /// (each ±), and why a run fails.
    #[arg(long, value_delimiter = ',')]
    around: Vec<f64>,
}

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

/// `solver` at relative tolerance `rtol`, atol scaled with it.
fn at_rtol(solver: &SolverOptions, rtol: f64) -> SolverOptions {
    SolverOptions {
        rtol,
        atol: solver.atol * rtol / solver.rtol,
        ..*solver
    }
}

/// (NLL, feature cost) at `u`, simulated with `p`'s solver; NaN where the run fails.
fn costs(p: &SpectralProblem, u: &[f64]) -> (f64, f64) {
    let params = p.params_at(u);
    let Ok(sim) = p.simulate(&params) else {
        return (f64::NAN, f64::NAN);
    };
    let nll = p.total_cost(&sim).unwrap_or(f64::NAN) + p.prior.nats(&params);
    let features = p
        .model_features(&sim)
        .map(|f| p.cost_of(&f))
        .unwrap_or(f64::NAN);
    (nll, features)
}

/// The NLL at `centre` moved along each coordinate by ±each of `steps`, at `p`'s solver; a failed
/// run prints its cause.
fn around(p: &SpectralProblem, centre: &[f64], steps: &[f64]) {
    for (i, f) in p.free.iter().enumerate() {
        for &d in steps {
            for sign in [-1.0, 1.0] {
                let mut u = centre.to_vec();
                u[i] = (u[i] + sign * d).clamp(0.0, 1.0);
                let params = p.params_at(&u);
                let what = match p.simulate(&params) {
                    Ok(sim) => match p.total_cost(&sim) {
                        Ok(c) => {
                            let f = p.model_features(&sim).map_or(f64::NAN, |f| p.cost_of(&f));
                            format!("NLL {c:.2}, feature cost {f:.3}")
                        }
                        Err(e) => format!("no cost: {e}"),
                    },
                    Err(e) => {
                        let e = e.to_string();
                        format!("fails: {}", &e[..e.len().min(400)])
                    }
                };
                println!("  {} {:+.3} (u {:.4}): {what}", f.name, sign * d, u[i]);
            }
        }
    }
}

fn main() -> Fallible<()> {
    let args = Args::parse();
    let job = LoadedJob::load(&args.job)?;
    let candidate: Candidate = args.model.parse()?;
    let base = problem_for(&job, candidate)?;
    let job_solver = base.solver;
    let mut at: Vec<(f64, SpectralProblem)> = Vec::new();
    for rtol in [1e-6, 1e-8, 1e-10] {
        let mut p = problem_for(&job, candidate)?;
        p.solver = at_rtol(&job_solver, rtol);
        at.push((rtol, p));
    }
    let names: Vec<String> = base.free.iter().map(|f| f.name.to_string()).collect();
    let mut points: Vec<(String, Vec<f64>)> = Vec::new();
    let truth: Option<Vec<f64>> = base
        .free
        .iter()
        .map(|f| job.truth.get(&f.name).map(|t| f.u_of(*t)))
        .collect();
    if let Some(t) = truth.clone() {
        points.push(("truth".into(), t));
    }
    for path in &args.result {
        let result: toml::Value = toml::from_str(&std::fs::read_to_string(path)?)?;
        let params = result["parameters"]
            .as_array()
            .ok_or("result without parameters")?;
        let u: Option<Vec<f64>> = base
            .free
            .iter()
            .map(|f| {
                let name = f.name.to_string();
                params
                    .iter()
                    .find(|q| q["name"].as_str() == Some(name.as_str()))
                    .and_then(|q| q["value"].as_float())
                    .map(|v| f.u_of(v))
            })
            .collect();
        let u = u.ok_or(format!("{}: not a fit of {candidate}", path.display()))?;
        points.push((format!("fit {}", path.display()), u));
    }
    println!("candidate {candidate}, parameters {}", names.join(", "));
    for (name, u) in &points {
        let values: Vec<String> = base
            .free
            .iter()
            .zip(u)
            .map(|(f, u)| format!("{} {:.5}", f.name, f.value(*u)))
            .collect();
        println!("{name}: {}", values.join(", "));
        for (rtol, p) in &at {
            let (nll, feat) = costs(p, u);
            println!("  rtol {rtol:.0e}: NLL {nll:.3} nats, feature cost {feat:.4}");
        }
    }
    if let Some(t) = &truth {
        around(&at[1].1, t, &args.around);
    }
    if args.samples == 0 {
        return Ok(());
    }
    let swarm = &at[0].1;
    let polish = &at[1].1;
    let dims = base.free.len();
    let rows: Vec<(Vec<f64>, f64, f64)> = (0..args.samples)
        .into_par_iter()
        .map(|i| {
            let u: Vec<f64> = (0..dims)
                .map(|d| f64::from(sobol_burley::sample(i as u32, d as u32, 1)))
                .collect();
            let feat = costs(swarm, &u).1;
            let nll = costs(polish, &u).0;
            (u, feat, nll)
        })
        .collect();
    let ok: Vec<&(Vec<f64>, f64, f64)> = rows
        .iter()
        .filter(|r| r.1.is_finite() && r.2.is_finite())
        .collect();
    println!(
        "{} Sobol points, {} simulated at both tolerances",
        rows.len(),
        ok.len()
    );
    if let Some(t) = &truth {
        let (t_nll, _) = costs(polish, t);
        let (_, t_feat) = costs(swarm, t);
        let below_feat = ok.iter().filter(|r| r.1 < t_feat).count();
        let below_nll = ok.iter().filter(|r| r.2 < t_nll).count();
        println!(
            "below the truth: {below_feat} by the feature cost ({t_feat:.4} at rtol 1e-6), {below_nll} by the NLL ({t_nll:.3} at the job's rtol)"
        );
    }
    let rank = |key: usize| {
        let mut v = ok.clone();
        v.sort_by(|a, b| {
            let (x, y) = if key == 1 { (a.1, b.1) } else { (a.2, b.2) };
            x.total_cmp(&y)
        });
        v
    };
    for (key, what) in [(1, "feature cost"), (2, "NLL")] {
        println!("lowest 8 by the {what}:");
        for r in rank(key).iter().take(8) {
            let values: Vec<String> = base
                .free
                .iter()
                .zip(&r.0)
                .map(|(f, u)| format!("{} {:.4}", f.name, f.value(*u)))
                .collect();
            println!(
                "  feature {:.4}, NLL {:.2}: {}",
                r.1,
                r.2,
                values.join(", ")
            );
        }
    }
    Ok(())
}
