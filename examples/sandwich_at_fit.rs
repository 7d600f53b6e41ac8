//! The sandwich spread at each fit of a campaign's results against the truth of its recording:
//! per parameter, the 1σ ([`at_fit_smoothed`], normalised units), the truth's distance from the
//! fit in those 1σ (`z`), and how much the rounding's draws widen the 1σ. It reads each fit's
//! optimum as written, so changes to the spread's estimate can be measured on fits whose search
//! took minutes without running the searches again (docs/validation.md, "Jitter").
//!
//! ```sh
//! cargo run --release --example sandwich_at_fit -- --campaign campaigns/calibration.toml \
//!     --out-dir DIR --fitted DIR/results
//! ```

use clap::Parser;
#[path = "common/campaign.rs"]
mod campaign;
use campaign::{JobSource, truth_u};
use std::path::{Path, PathBuf};

use wiperlab::fit::FitResult;
use wiperlab::job::LoadedJob;
use wiperlab::search::evidence::at_fit_smoothed;
use wiperlab::search::problem_for;

#[derive(Parser)]
struct Args {
    #[command(flatten)]
    source: JobSource,
    /// The campaign's `results/` directory: each job's fit is `<DIR>/<job stem>.result.toml`.
    #[arg(long, value_name = "DIR")]
    fitted: PathBuf,
}

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Fallible<()> {
    let args = Args::parse();
    println!("job,model,param,sigma_u,z,rounding_widening");
    for path in args.source.paths()? {
        if let Err(e) = spread(&args, &path) {
            let e: String = e.to_string().chars().take(300).collect();
            println!("# {}: skipped: {e}", path.display());
        }
    }
    Ok(())
}

/// One row per parameter of the fit of the job at `path`, when it chose the candidate (the true
/// model unless `--model`).
fn spread(args: &Args, path: &Path) -> Fallible<()> {
    let job = LoadedJob::load(path)?;
    let candidate = args.source.candidate(&job, path)?;
    let stem = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let result_path = args.fitted.join(format!("{stem}.result.toml"));
    let text = std::fs::read_to_string(&result_path)
        .map_err(|e| format!("{}: {e}", result_path.display()))?;
    let result: FitResult = toml::from_str(&text)?;
    if result.model != candidate {
        return Err(format!("the fit chose {}", result.model).into());
    }
    let problem = problem_for(&job, result.model)?;
    let truth = truth_u(&job, &problem)?;
    let fit: Vec<f64> = problem
        .free
        .iter()
        .map(|f| {
            result
                .parameters
                .iter()
                .find(|p| p.name == f.name)
                .map(|p| f.u_of(p.value))
                .ok_or(format!("the result has no {}", f.name))
        })
        .collect::<Result<_, _>>()?;
    let local = at_fit_smoothed(&problem, &fit)?;
    for (i, f) in problem.free.iter().enumerate() {
        let s = local.sigma_u[i];
        println!(
            "{stem},{},{},{s:.3e},{:.2},{:.2}",
            result.model,
            f.name,
            (truth[i] - fit[i]) / s,
            local.rounding_widening[i]
        );
    }
    Ok(())
}
