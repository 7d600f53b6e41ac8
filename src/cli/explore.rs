//! `wiperlab explore`: samples a job's freed parameters and writes the reachability map.

use crate::Result;
use crate::explore::{explore, simulations};
use crate::job::LoadedJob;
use crate::report::explore::{SAMPLES_CSV, summary, write_exploration};
use std::path::{Path, PathBuf};

/// Loads the job, samples it, writes the tables and the map into `out` (default the job's
/// `<reports_dir>/explore/<job name>/`, `reports/` beside the job unless the job says otherwise)
/// and prints the summary.
pub(super) fn run(job: &Path, samples: usize, seed: u32, out: Option<PathBuf>) -> Result<()> {
    let loaded = LoadedJob::load(job)?;
    if samples == 0 || samples > crate::explore::MAX_SAMPLES {
        let max = crate::explore::MAX_SAMPLES;
        return Err(crate::fit::FitError::Samples { samples, max }.into());
    }
    let dir = out.unwrap_or_else(|| loaded.reports_dir().join("explore").join(&loaded.name));
    crate::io::check_creatable_dir(&dir)?;
    let previous = dir.join(SAMPLES_CSV);
    if previous.exists() {
        super::esay!(
            "note: replacing the exploration in {} (its {} and the other tables and map)",
            dir.display(),
            SAMPLES_CSV
        );
    }
    let pb = (!super::quiet()).then(|| {
        let pb = indicatif::ProgressBar::new(simulations(samples, loaded.free.len()));
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "explore [{bar:32}] {pos}/{len} model runs, {elapsed} (eta {eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        pb
    });
    let e = explore(&loaded, samples, seed, pb.as_ref())?;
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    let written = write_exploration(&dir, &e)?;
    print!("{}", summary(&e));
    for p in written {
        println!("wrote {}", p.display());
    }
    Ok(())
}
