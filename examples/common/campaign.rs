//! What the examples that read a campaign's recordings share: its jobs, written as `wiperlab
//! campaign` writes them.

use std::path::PathBuf;

/// Writes the job and blade file of every recording of the campaign at `path` (output directory
/// `out_dir`, else the campaign's own) and returns the jobs' paths.
pub fn campaign_jobs(
    path: &std::path::Path,
    out_dir: Option<&std::path::Path>,
) -> Result<Vec<PathBuf>, Box<dyn std::error::Error>> {
    use wiperlab::campaign::{
        Campaign,
        run::{EntryPaths, generate},
    };
    let campaign = Campaign::load(path)?.with_out_dir(out_dir)?;
    let mut jobs = Vec::new();
    for entry in &campaign.entries {
        let paths = EntryPaths::new(&campaign.out_dir(), entry);
        let g = generate(&campaign, entry, &paths)?;
        std::fs::create_dir_all(paths.job.parent().unwrap_or(std::path::Path::new(".")))?;
        wiperlab::io::write_atomic(&paths.blade, g.blade_text.as_bytes())?;
        wiperlab::io::write_atomic(&paths.job, g.job_text.as_bytes())?;
        jobs.push(paths.job);
    }
    Ok(jobs)
}
