//! A campaign's fit read back at its optimum beside its recording's truth, for the examples that
//! re-examine fits without running their searches again.

use super::campaign::{JobSource, truth_u};
use std::path::{Path, PathBuf};
use wiperlab::fit::FitResult;
use wiperlab::job::LoadedJob;
use wiperlab::search::{SpectralProblem, problem_for};

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

/// The jobs and the campaign results their fits are read from.
#[derive(clap::Args)]
pub struct FittedSource {
    #[command(flatten)]
    pub source: JobSource,
    /// The campaign's results: each job's fit is `<DIR>/<job stem>.result.toml`.
    #[arg(long, value_name = "DIR")]
    pub fitted: PathBuf,
}

/// One fit: its job's name, the candidate's problem, and the fit's and the truth's normalised
/// coordinates.
pub struct Fitted {
    pub name: String,
    pub problem: SpectralProblem,
    pub fit_u: Vec<f64>,
    pub truth_u: Vec<f64>,
}

/// The fit of the job at `path` from `<fitted>/<job stem>.result.toml`; an error when it chose
/// another model than the candidate (`--model`, else the true model).
pub fn read(fits: &FittedSource, path: &Path) -> Fallible<Fitted> {
    let job = LoadedJob::load(path)?;
    let candidate = fits.source.candidate(&job, path)?;
    let name = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let file = fits.fitted.join(format!("{name}.result.toml"));
    let text = std::fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
    let result: FitResult = toml::from_str(&text)?;
    if result.model != candidate {
        return Err(format!("the fit chose {}", result.model).into());
    }
    let problem = problem_for(&job, candidate)?;
    let truth_u = truth_u(&job, &problem)?;
    let fit_u = (problem.free.iter())
        .map(|f| {
            let p = result.parameters.iter().find(|p| p.name == f.name);
            p.map(|p| f.u_of(p.value))
                .ok_or(format!("the result has no {}", f.name))
        })
        .collect::<Result<_, _>>()?;
    Ok(Fitted {
        name,
        problem,
        fit_u,
        truth_u,
    })
}
