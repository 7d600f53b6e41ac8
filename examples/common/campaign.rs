//! What the examples that read jobs at their truths share: the jobs named on the command line or
//! written for a campaign's recordings as `wiperlab campaign` writes them, the candidate to read
//! each in, and the truth in the search's normalised coordinates.

use std::path::{Path, PathBuf};
use wiperlab::job::{Candidate, LoadedJob};
use wiperlab::search::SpectralProblem;

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

/// The jobs an example reads and the model it reads them in.
#[derive(clap::Args)]
pub struct JobSource {
    /// Fit jobs (each with `[truth]` for every freed parameter of the candidate).
    pub jobs: Vec<PathBuf>,
    /// Also every recording of this campaign: its jobs are generated as `wiperlab campaign`
    /// generates them, into `<--out-dir>/jobs/`.
    #[arg(long)]
    pub campaign: Option<PathBuf>,
    /// The campaign's output directory (as `wiperlab campaign --out-dir`).
    #[arg(long)]
    pub out_dir: Option<PathBuf>,
    /// The candidate model (`blade2dof`, `head1dof`, `blade2dof+shoulder`, ...); default: each
    /// job's true model (`[truth] model`).
    #[arg(long)]
    pub model: Option<String>,
}

impl JobSource {
    /// The jobs named, then the campaign's (written into its output directory).
    pub fn paths(&self) -> Fallible<Vec<PathBuf>> {
        let mut jobs = self.jobs.clone();
        if let Some(path) = &self.campaign {
            jobs.extend(campaign_jobs(path, self.out_dir.as_deref())?);
        }
        Ok(jobs)
    }

    /// The candidate to read `job` (loaded from `path`) in: `--model`, else its true model.
    pub fn candidate(&self, job: &LoadedJob, path: &Path) -> Fallible<Candidate> {
        match (&self.model, job.truth_model) {
            (Some(m), _) => Ok(m.parse()?),
            (None, Some(m)) => Ok(m),
            (None, None) => {
                Err(format!("{}: no --model and no [truth] model", path.display()).into())
            }
        }
    }
}

/// The job's truth in `problem`'s normalised coordinates (an error naming a freed parameter
/// without a truth).
pub fn truth_u(job: &LoadedJob, problem: &SpectralProblem) -> Fallible<Vec<f64>> {
    Ok(problem
        .free
        .iter()
        .map(|f| {
            job.truth
                .get(&f.name)
                .map(|t| f.u_of(*t))
                .ok_or(format!("no truth for {}", f.name))
        })
        .collect::<Result<_, _>>()?)
}

/// Writes the job and blade file of every recording of the campaign at `path` (output directory
/// `out_dir`, else the campaign's own) and returns the jobs' paths.
fn campaign_jobs(path: &Path, out_dir: Option<&Path>) -> Fallible<Vec<PathBuf>> {
    use wiperlab::campaign::{
        Campaign,
        run::{EntryPaths, generate},
    };
    let campaign = Campaign::load(path)?.with_out_dir(out_dir)?;
    let mut jobs = Vec::new();
    for entry in &campaign.entries {
        let paths = EntryPaths::new(&campaign.out_dir(), entry);
        let g = generate(&campaign, entry, &paths)?;
        std::fs::create_dir_all(paths.job.parent().unwrap_or(Path::new(".")))?;
        wiperlab::io::write_atomic(&paths.blade, g.blade_text.as_bytes())?;
        wiperlab::io::write_atomic(&paths.job, g.job_text.as_bytes())?;
        jobs.push(paths.job);
    }
    Ok(jobs)
}
