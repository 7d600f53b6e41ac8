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
#[path = "common/fitted.rs"]
mod fitted;
use std::path::Path;
use wiperlab::search::evidence::at_fit_smoothed;

#[derive(Parser)]
struct Args {
    #[command(flatten)]
    fits: fitted::FittedSource,
}

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Fallible<()> {
    let args = Args::parse();
    println!("job,model,param,sigma_u,z,rounding_widening");
    for path in args.fits.source.paths()? {
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
    let f = fitted::read(&args.fits, path)?;
    let local = at_fit_smoothed(&f.problem, &f.fit_u)?;
    for (i, p) in f.problem.free.iter().enumerate() {
        let s = local.sigma_u[i];
        println!(
            "{},{},{},{s:.3e},{:.2},{:.2}",
            f.name,
            f.problem.model,
            p.name,
            (f.truth_u[i] - f.fit_u[i]) / s,
            local.rounding_widening[i]
        );
    }
    Ok(())
}
