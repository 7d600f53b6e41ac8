//! Where a Nelder–Mead polish on the cost averaged over rounding draws ends, started from a
//! campaign's fits: whether a search on that cost would leave the draws that suit the recording
//! (docs/validation.md, "Jitter").
//!
//! The averaged cost at a point is the mean of the cost at it and at steps of 1e-12 either way
//! along each coordinate (`2k + 1` simulations, [`wiperlab::search::jitter::rounding_points`]).
//! For each job the example prints the averaged cost at the fit, at the polish's end and at the
//! truth, and each parameter's relative error at the fit and at the polish's end.
//!
//! ```sh
//! cargo run --release --example averaged_polish -- JOBS --fitted DIR
//! ```

use argmin::core::{CostFunction, Executor};
use argmin::solver::neldermead::NelderMead;
use clap::Parser;
#[path = "common/campaign.rs"]
mod campaign;
#[path = "common/fitted.rs"]
mod fitted;
use std::path::Path;
use wiperlab::search::SpectralProblem;
use wiperlab::search::jitter::rounding_points;

#[derive(Parser)]
struct Args {
    /// The jobs and the campaign results whose fits the polish starts from.
    #[command(flatten)]
    fits: fitted::FittedSource,
    /// The polish's iterations at the most.
    #[arg(long, default_value_t = 60)]
    iterations: u64,
    /// The initial simplex's edge, normalised units.
    #[arg(long, default_value_t = 0.02)]
    step: f64,
}

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

/// The cost averaged over the rounding draws at a point.
struct Averaged<'a>(&'a SpectralProblem);

impl Averaged<'_> {
    fn at(&self, u: &[f64]) -> f64 {
        use rayon::prelude::*;
        let costs: Vec<f64> = rounding_points(u)
            .par_iter()
            .map(|p| self.0.cost_at(p))
            .collect();
        costs.iter().sum::<f64>() / costs.len() as f64
    }
}

impl CostFunction for Averaged<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, u: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        Ok(self.at(u))
    }
}

fn main() -> Fallible<()> {
    let args = Args::parse();
    println!("job,at_fit,polished,at_truth,evaluations,rel_err_fit,rel_err_polished");
    for path in args.fits.source.paths()? {
        if let Err(e) = one(&args, &path) {
            println!("# {}: skipped: {e}", path.display());
        }
    }
    Ok(())
}

fn one(args: &Args, path: &Path) -> Fallible<()> {
    let fitted::Fitted {
        name,
        problem,
        fit_u: uf,
        truth_u: ut,
    } = fitted::read(&args.fits, path)?;
    let avg = Averaged(&problem);
    let simplex: Vec<Vec<f64>> = std::iter::once(uf.clone())
        .chain((0..uf.len()).map(|i| {
            let mut v = uf.clone();
            v[i] = if v[i] + args.step <= 1.0 {
                v[i] + args.step
            } else {
                v[i] - args.step
            };
            v
        }))
        .collect();
    let before = problem
        .evaluations
        .load(std::sync::atomic::Ordering::Relaxed);
    let res = Executor::new(
        Averaged(&problem),
        NelderMead::new(simplex).with_sd_tolerance(0.1)?,
    )
    .configure(|s| s.max_iters(args.iterations))
    .run()?;
    let up: Vec<f64> = res
        .state()
        .best_param
        .clone()
        .unwrap_or(uf.clone())
        .iter()
        .map(|x| x.clamp(0.0, 1.0))
        .collect();
    let evaluations = problem
        .evaluations
        .load(std::sync::atomic::Ordering::Relaxed)
        - before;
    let rel = |u: &[f64]| {
        (problem.free.iter().zip(u).zip(&ut))
            .map(|((f, a), t)| {
                format!(
                    "{}{:+.1}%",
                    f.name,
                    100.0 * (f.value(*a) / f.value(*t) - 1.0)
                )
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    println!(
        "{name},{:.2},{:.2},{:.2},{evaluations},{},{}",
        avg.at(&uf),
        avg.at(&up),
        avg.at(&ut),
        rel(&uf),
        rel(&up)
    );
    Ok(())
}
