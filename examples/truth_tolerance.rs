//! Does the fit's integrator reproduce a model-made recording at its true parameters? The cost of
//! the truth (a job's `[truth]`, in the model `[truth] model` names, else `--model`) at the job's
//! own solver, at tenfold and hundredfold tighter tolerances, and with DOP853 at rtol 1e-10 and
//! 1e-12 (the calibration recordings are made with DOP853 at 1e-10); with a result, the fitted
//! point's cost at the same solvers beside it.
//!
//! A truth whose cost falls by more than the likelihood's resolution (a few tenths of a nat) as the
//! tolerance tightens is one the fit's tolerance prices wrongly: its excess over the fit is then
//! the integrator's, not the noise's, and intervals calibrated on the noise cannot cover it
//! (docs/validation.md, "Calibration by simulation").
//!
//! ```sh
//! cargo run --release --example truth_tolerance -- JOB.toml [RESULT.toml] [--model NAME]
//! ```

use clap::Parser;
use std::path::PathBuf;
use wiperlab::fit::result::FitResult;
use wiperlab::job::{Candidate, LoadedJob};
use wiperlab::model::ParamId;
use wiperlab::search::problem_for;
use wiperlab::simulate::{Method, SolverOptions};

#[derive(Parser)]
struct Args {
    /// The fit job (with `[truth]` for every freed parameter of the model).
    job: PathBuf,
    /// The result the job's fit wrote: its fitted point is priced beside the truth.
    result: Option<PathBuf>,
    /// The model to price the truth in (default: `[truth] model`, else the result's, else the
    /// job's first candidate).
    #[arg(long)]
    model: Option<Candidate>,
}

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

/// The solvers the truth is priced at: the job's, its tenfold and hundredfold tighter
/// tolerances, and DOP853 at 1e-10 and 1e-12 (atol a hundredth of rtol).
fn solvers(job: &SolverOptions) -> Vec<(String, SolverOptions)> {
    let mut out = vec![(format!("job ({} {:.0e})", job.method, job.rtol), *job)];
    for d in [10.0, 100.0] {
        let s = SolverOptions {
            rtol: job.rtol / d,
            atol: job.atol / d,
            max_steps: job.max_steps * 4,
            ..*job
        };
        out.push((format!("{} {:.0e}", s.method, s.rtol), s));
    }
    for rtol in [1e-10, 1e-12] {
        let s = SolverOptions {
            rtol,
            atol: rtol / 100.0,
            method: Method::Dop853,
            max_steps: job.max_steps * 8,
            ..*job
        };
        out.push((format!("dop853 {rtol:.0e}"), s));
    }
    out
}

/// The problem's base parameters with every freed one set to `value(its name)` as given, as the
/// fit prices a truth or a result's values; `Err` names the first freed parameter without a value.
/// Taken through the normalised coordinates and back the values change in the last bits, and the
/// cost by up to the likelihood's ripple (0.08 nats at the main job's fit, 0.015 at its truth).
fn at_values(
    problem: &wiperlab::search::SpectralProblem,
    value: impl Fn(ParamId) -> Option<f64>,
) -> Result<wiperlab::model::BladeParams, ParamId> {
    let mut at = problem.base;
    for fp in &problem.free {
        fp.name.set(&mut at, value(fp.name).ok_or(fp.name)?);
    }
    Ok(at)
}

fn main() -> Fallible<()> {
    let args = Args::parse();
    let job = LoadedJob::load(&args.job)?;
    let result = args.result.as_deref().map(FitResult::read).transpose()?;
    let result_model = result.as_ref().map(|r| r.model);
    let candidate = (args.model)
        .or(job.truth_model)
        .or(result_model)
        .unwrap_or(job.candidates()[0]);
    let problem = problem_for(&job, candidate)?;
    let truth = at_values(&problem, |name| job.truth.get(&name).copied())
        .map_err(|name| format!("the truth has no value for {}", name.name()))?;
    let fit = result
        .as_ref()
        .filter(|_| result_model == Some(candidate))
        .and_then(|r| {
            at_values(&problem, |name| {
                let p = r.parameters.iter().find(|p| p.name == name)?;
                Some(p.value)
            })
            .ok()
        });
    println!(
        "{}: truth priced in {candidate}{}",
        args.job.display(),
        if fit.is_some() {
            ", beside the fit"
        } else {
            ""
        }
    );
    println!("solver             truth (nats)  transitions   fit (nats)   truth − fit");
    for (name, s) in solvers(&problem.solver) {
        let t = problem.params_cost_with_solver(&truth, &s).ok();
        let f = fit
            .as_ref()
            .map(|p| problem.params_cost_with_solver(p, &s).ok());
        let show = |c: Option<(f64, usize)>| c.map_or("failed".into(), |c| format!("{:.3}", c.0));
        println!(
            "{name:<18} {:>12} {:>12} {:>12} {:>12}",
            show(t),
            t.map_or("-".into(), |c| c.1.to_string()),
            f.map_or("-".into(), show),
            match (t, f.flatten()) {
                (Some(t), Some(f)) => format!("{:+.3}", t.0 - f.0),
                _ => "-".into(),
            }
        );
    }
    Ok(())
}
