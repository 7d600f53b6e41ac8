//! How much each recording's cost jitters at its truth under rounding-level steps
//! ([`wiperlab::search::jitter::RoundingJitter`], docs/likelihood.md, "Jitter"), read with the
//! fit's own signal alone and with each further signal beside it (`[fit.likelihood]
//! joint_signals`).
//!
//! With `--fisher` it also prints the Fisher information's 1σ at the truth and at steps of
//! 1e-12: where the cost jitters, whether the information's finite differences move with it.
//!
//! The jitter bounds what a cost difference can say: a search's shortfall, a likelihood ratio at
//! the truth or a profile's rise smaller than it are read through it. The truth's parameters are
//! the job's `[truth]`, in its true model (`[truth] model`, or `--model`).
//!
//! ```sh
//! cargo run --release --example cost_jitter -- \
//!     --campaign campaigns/calibration_development.toml --out-dir target/jitter --joint head_y
//! ```

use clap::Parser;
#[path = "common/campaign.rs"]
mod campaign;
use campaign::{JobSource, truth_u};
use std::path::Path;

use wiperlab::job::{Candidate, LoadedJob};
use wiperlab::model::ParamId;
use wiperlab::search::evidence::curvature_at;
use wiperlab::search::jitter::RoundingJitter;
use wiperlab::search::problem_for;
use wiperlab::spectrum::features::SignalKind;

#[derive(Parser)]
struct Args {
    #[command(flatten)]
    source: JobSource,
    /// Signals read beside the fit's own, one configuration each (the fit's own alone always;
    /// `--joint ''` for that alone).
    #[arg(long, value_delimiter = ',', default_value = "head_y")]
    joint: Vec<String>,
    /// Scale true values before the check, `NAME=FACTOR` (e.g. `B=2`: the Stribeck slope `−A·B`
    /// at zero slip speed doubled), to see which of them the jitter follows.
    #[arg(long, value_delimiter = ',')]
    scale: Vec<String>,
    /// Also the Fisher information's 1σ (`curvature_at`, normalised units) at the truth and at
    /// steps of +1e-12, +2e-12 and −1e-12 along the first coordinate: where the cost jitters, how
    /// far the finite differences of the information move with it (a `#`-line per job).
    #[arg(long)]
    fisher: bool,
    /// Also the Fisher information's 1σ with central differences of steps 1e-3, 3e-3, 1e-2,
    /// 3e-2 and 1e-1 (normalised units; the fits' own is 3e-3): where the response jitters, the
    /// differences read the jitter over the step, and the 1σ grows with it.
    #[arg(long)]
    fisher_steps: bool,
    /// Read each job's fit from `<DIR>/<job stem>.result.toml` (a campaign's `results/`) and
    /// check there instead of at the truth: whether the search's optimum is a draw that suits the
    /// recording (its cost below the mean of its neighbours' draws). A job whose result chose
    /// another model than the candidate is skipped.
    #[arg(long, value_name = "DIR")]
    fitted: Option<std::path::PathBuf>,
}

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Fallible<()> {
    let args = Args::parse();
    let jobs = args.source.paths()?;
    let joint: Vec<SignalKind> = args
        .joint
        .iter()
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<SignalKind>())
        .collect::<Result<_, _>>()?;
    println!("job,model,at,signals,jitter_sd_nats,mean_nats,costs");
    for path in &jobs {
        if let Err(e) = jitters(&args, &joint, path) {
            let e: String = e.to_string().chars().take(300).collect();
            println!("# {}: skipped: {e}", path.display());
        }
    }
    Ok(())
}

/// One CSV row per configuration of the job at `path`: its own signal alone, then with each of
/// `joint` beside it.
fn jitters(args: &Args, joint: &[SignalKind], path: &Path) -> Fallible<()> {
    let mut job = LoadedJob::load(path)?;
    for pair in &args.scale {
        let (name, factor) = pair
            .split_once('=')
            .ok_or(format!("--scale {pair}: expected NAME=FACTOR"))?;
        let factor: f64 = factor.parse().map_err(|e| format!("--scale {pair}: {e}"))?;
        let id: ParamId = name.parse()?;
        *job.truth
            .get_mut(&id)
            .ok_or(format!("--scale {pair}: the job has no truth for {name}"))? *= factor;
    }
    let candidate = args.source.candidate(&job, path)?;
    let name = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let at = match &args.fitted {
        Some(dir) => {
            put_fit(
                &mut job,
                &dir.join(format!("{name}.result.toml")),
                candidate,
            )?;
            "fit"
        }
        None => "truth",
    };
    let own = job.job.spectrum.signal;
    let configs: Vec<Vec<SignalKind>> = std::iter::once(Vec::new())
        .chain(joint.iter().map(|s| vec![*s]))
        .collect();
    for extra in configs {
        job.job.fit.likelihood.joint_signals = extra.clone();
        let problem = problem_for(&job, candidate)?;
        let u = truth_u(&job, &problem)?;
        let signals: Vec<String> = std::iter::once(own)
            .chain(extra)
            .map(|s| s.to_string())
            .collect();
        match RoundingJitter::at(&problem, &u) {
            Some(j) => {
                let costs: Vec<String> = j.costs_nats.iter().map(|c| format!("{c:.3}")).collect();
                let mean = j.mean_nats();
                println!(
                    "{name},{candidate},{at},{},{:.4},{mean:.3},{}",
                    signals.join("+"),
                    j.sd_nats,
                    costs.join(" ")
                );
            }
            None => println!(
                "{name},{candidate},{at},{},,,fewer than three runs simulated",
                signals.join("+")
            ),
        }
        if args.fisher_steps {
            println!(
                "# steps {name} {}: {}",
                signals.join("+"),
                fisher_by_step(&problem, &u)
            );
        }
        if args.fisher {
            println!(
                "# {name} {}: {}",
                signals.join("+"),
                fisher_sigmas(&problem, &u)
            );
        }
    }
    Ok(())
}

/// Puts the fitted values of the result at `path` in the job's truth, so that the checks read the
/// fit; an error when the result chose another model than `candidate`.
fn put_fit(job: &mut LoadedJob, path: &Path, candidate: Candidate) -> Fallible<()> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let result: wiperlab::fit::FitResult =
        toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    if result.model != candidate {
        return Err(format!("{}: the fit chose {}", path.display(), result.model).into());
    }
    for p in &result.parameters {
        job.truth.insert(p.name, p.value);
    }
    Ok(())
}

/// The Fisher 1σ of each coordinate at `u` and at rounding-level steps along the first one, each
/// set in brackets.
fn fisher_sigmas(problem: &wiperlab::search::SpectralProblem, u: &[f64]) -> String {
    [0.0, 1e-12, 2e-12, -1e-12]
        .iter()
        .map(|d| {
            let mut v = u.to_vec();
            v[0] += d;
            match curvature_at(problem, &v) {
                Ok((sigma, _)) => {
                    let s: Vec<String> = sigma.iter().map(|x| format!("{x:.2e}")).collect();
                    format!("[{}]", s.join(" "))
                }
                Err(e) => format!("[{e}]"),
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The Fisher 1σ of each coordinate at `u` with central differences of several steps, each set
/// in brackets after its step.
fn fisher_by_step(problem: &wiperlab::search::SpectralProblem, u: &[f64]) -> String {
    let Ok(lik) = problem.likelihood.as_ref() else {
        return "no likelihood".into();
    };
    let parts = match problem
        .simulate(&problem.params_at(u))
        .and_then(|sim| lik.nll(problem, &sim))
    {
        Ok(p) => p,
        Err(e) => return format!("{e}"),
    };
    [1e-3, 3e-3, 1e-2, 3e-2, 1e-1]
        .iter()
        .map(|h| match lik.fisher_with_step(problem, u, &parts, *h) {
            Ok(f) => {
                let (sigma, _) = wiperlab::likelihood::covariance::covariance(&f);
                let s: Vec<String> = sigma.iter().map(|x| format!("{x:.2e}")).collect();
                format!("{h:e} [{}]", s.join(" "))
            }
            Err(e) => format!("{h:e} [{e}]"),
        })
        .collect::<Vec<_>>()
        .join(" ")
}
