//! Profile-likelihood intervals at a fit's optimum with other rise limits than the fit's, against
//! the truth of a model-made recording: how the profile interval's threshold decides coverage.
//!
//! At the fitted point of a result (the job's `[truth]` for every freed parameter of the chosen
//! model), the tool walks each parameter's profile ([`profile_intervals_at`], the fit's own walk)
//! with three limits on the NLL's rise:
//!
//! - `sandwich`: `0.5·σ²_sandwich/σ²_Fisher` nats, the fit's own (the composite likelihood's
//!   magnitude adjustment at the optimum: Kent 1982; Varin, Reid & Firth 2011);
//! - `wilks68`: 0.5 nats, the 68.27 % point of χ²₁/2 for a likelihood taken at face value;
//! - `wilks95`: 1.92 nats, its 95 % point;
//! - `no-valley`: the fit's own limit, each step's polish started where the previous one ended
//!   instead of on the valley of `F⁻¹` ([`wiperlab::uncertainty::valley_start`]): what the
//!   predictor step changes.
//!
//! For each it prints every parameter's interval and whether it contains the truth, and the NLL at
//! the truth above the fit (the likelihood-ratio statistic the thresholds are compared with). The
//! development set's fits read by it choose the threshold (docs/validation.md, "Calibration by
//! simulation").
//!
//! ```sh
//! cargo run --release --example interval_variants -- JOB.toml JOB.result.toml
//! ```

use clap::Parser;
use std::path::PathBuf;
use std::sync::Arc;
use wiperlab::fit::result::FitResult;
use wiperlab::job::LoadedJob;
use wiperlab::search::evidence::at_fit_smoothed;
use wiperlab::search::problem_for;
use wiperlab::uncertainty::{ProfileStart, profile_intervals_at};

#[derive(Parser)]
struct Args {
    /// The fit job (with `[truth]` for every freed parameter of the chosen model).
    job: PathBuf,
    /// The result the job's fit wrote.
    result: PathBuf,
}

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

/// The rise limits compared: name and the factor on `σ²_Fisher/σ²_sandwich` that gives it (so
/// that `0.5·(σ_s/σ_f)²·factor` is the limit), or a fixed limit in nats.
enum Limit {
    Sandwich,
    Fixed(f64),
}

/// The walks: name, limit, and whether each step's polish may start on the valley of `F⁻¹`.
const LIMITS: [(&str, Limit, bool); 4] = [
    ("sandwich", Limit::Sandwich, true),
    ("no-valley", Limit::Sandwich, false),
    ("wilks68", Limit::Fixed(0.5), true),
    ("wilks95", Limit::Fixed(1.920_729_410_347_062), true),
];

fn main() -> Fallible<()> {
    let args = Args::parse();
    let job = LoadedJob::load(&args.job)?;
    let result = FitResult::read(&args.result)?;
    let model = result.model;
    let p = Arc::new(problem_for(&job, model)?);
    let mut u_fit = Vec::new();
    let mut truth = Vec::new();
    for fp in &p.free {
        let name = fp.name;
        let fitted = result.parameters.iter().find(|q| q.name == name);
        u_fit.push(fp.u_of(fitted.ok_or(format!("no fitted {name}"))?.value));
        truth.push(*job.truth.get(&name).ok_or(format!("no true {name}"))?);
    }
    let u_true: Vec<f64> = p
        .free
        .iter()
        .zip(&truth)
        .map(|(fp, t)| fp.u_of(*t))
        .collect();
    let cost = p.cost_at(&u_fit);
    println!(
        "{}: {model}, cost at the fit {cost:.3} nats, at the truth {:+.3} above it",
        args.job.display(),
        p.cost_at(&u_true) - cost
    );
    let lf = at_fit_smoothed(&p, &u_fit)?;
    for (name, limit, valley) in LIMITS {
        // `profile_rise_limit` is 0.5·(σ_s/σ_f)²: a Fisher 1σ of σ_s·√(0.5/limit) gives `limit`.
        let fisher: Vec<f64> = match limit {
            Limit::Sandwich => lf.curvature_sigma_u.clone(),
            Limit::Fixed(l) => lf.sigma_u.iter().map(|s| s * (0.5 / l).sqrt()).collect(),
        };
        let at = ProfileStart {
            u: &u_fit,
            cost_nats: cost,
            sigma_u: &lf.sigma_u,
            fisher_sigma_u: &fisher,
            fisher_corr: valley.then_some(lf.curvature_corr.as_slice()),
        };
        let (intervals, _) = profile_intervals_at(&p, at, job.job.fit.polish_iterations)?;
        let cells: Vec<String> = p
            .free
            .iter()
            .zip(&intervals)
            .zip(&truth)
            .map(|((fp, iv), t)| {
                let inside = (iv.lo..=iv.hi).contains(t);
                format!(
                    "{} [{:.4e}, {:.4e}] {}",
                    fp.name,
                    iv.lo,
                    iv.hi,
                    if inside { "in" } else { "OUT" }
                )
            })
            .collect();
        println!("{name:>9}: {}", cells.join("  "));
    }
    Ok(())
}
