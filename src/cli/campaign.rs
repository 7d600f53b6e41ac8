//! `wiperlab campaign …`: parses the subcommand, calls `crate::campaign`, prints.

use crate::Result;
use crate::campaign::Campaign;
use crate::campaign::run::{Status, describe_overrides, fit_entry, run_local};
use crate::campaign::slurm::{SlurmSettings, status, submit, write_script};
use clap::{Args, Subcommand};
use std::path::PathBuf;

/// What to do with a campaign.
#[derive(Debug, Subcommand)]
pub enum CampaignCommand {
    /// List the campaign's recordings, their overrides and condition labels.
    List {
        /// The campaign TOML (docs/campaigns.md).
        campaign: PathBuf,
    },
    /// Fit every recording on this machine, in parallel; skips recordings whose result is complete
    /// for unchanged inputs (rerun to continue after an interruption); a failed recording does not
    /// stop the others (the exit code is then 1).
    Run {
        /// The campaign TOML (docs/campaigns.md).
        campaign: PathBuf,
        /// Recordings fitted at once (each fit also uses the thread pool).
        #[arg(long, default_value_t = 1)]
        jobs: usize,
    },
    /// Fit one recording (what each Slurm array task runs).
    Task {
        /// The campaign TOML (docs/campaigns.md).
        campaign: PathBuf,
        /// Position of the recording in `campaign list` (0-based; Slurm's SLURM_ARRAY_TASK_ID).
        #[arg(long)]
        index: usize,
    },
    /// Write the Slurm job-array script (one task per recording) and, with --submit, submit it.
    Slurm {
        /// The campaign TOML (docs/campaigns.md).
        campaign: PathBuf,
        #[command(flatten)]
        settings: SlurmArgs,
        /// Submit with sbatch after writing the script.
        #[arg(long)]
        submit: bool,
    },
    /// State of each recording: done, failed, or the array task's queue state.
    Status {
        /// The campaign TOML (docs/campaigns.md).
        campaign: PathBuf,
    },
    /// Merge every result into <campaign dir>/<name>/campaign.csv and draw the campaign report
    /// page <campaign dir>/<name>/report/index.html; when the recordings carry truths, also write
    /// the calibration table calibration.md (+ CSV) (docs/campaigns.md).
    Collect {
        /// The campaign TOML (docs/campaigns.md).
        campaign: PathBuf,
    },
}

/// Slurm settings from the command line (each overrides the campaign file's `[slurm]`).
#[derive(Debug, Args)]
pub struct SlurmArgs {
    /// Partition (`sbatch --partition`; default: the campaign file's, else the cluster's default).
    #[arg(long)]
    partition: Option<String>,
    /// Time limit per task as HH:MM:SS (`sbatch --time`), e.g. 00:30:00 (default: the campaign
    /// file's, else the partition's limit).
    #[arg(long)]
    time: Option<String>,
    /// CPUs per task, also the fit's thread count (default: the campaign file's, else 2).
    #[arg(long)]
    cpus_per_task: Option<u32>,
    /// Largest number of tasks running at once (`--array=0-N%K`; default: the campaign file's,
    /// else no limit).
    #[arg(long)]
    max_parallel: Option<u32>,
}

/// Runs a campaign subcommand.
///
/// # Errors
/// Those of the campaign functions; a `task` whose fit failed returns the fit's error (after the
/// failure is recorded in the recording's status file).
pub fn run(cmd: CampaignCommand, out_dir: Option<PathBuf>) -> Result<()> {
    let load = |p: &PathBuf| Campaign::load(p)?.with_out_dir(out_dir.as_deref());
    match cmd {
        CampaignCommand::List { campaign } => list(&load(&campaign)?),
        CampaignCommand::Run { campaign, jobs } => run_all(&load(&campaign)?, jobs, super::quiet()),
        CampaignCommand::Task { campaign, index } => {
            let c = load(&campaign)?;
            let entry = c.entries.get(index).ok_or(super::CliError::IndexBeyond {
                index,
                count: c.entries.len(),
            })?;
            let s = fit_entry(&c, entry)?;
            println!("{}: done in {:.1} s", s.id, s.wall_time_s);
            Ok(())
        }
        CampaignCommand::Slurm {
            campaign,
            settings,
            submit: go,
        } => slurm(&load(&campaign)?, &settings, go),
        CampaignCommand::Status { campaign } => {
            let st = status(&load(&campaign)?);
            if let Some(id) = &st.job_id {
                println!("Slurm job {id}");
            }
            for (id, s) in &st.tasks {
                println!("  {id:<24} {s}");
            }
            let counts: Vec<String> = st
                .counts()
                .iter()
                .map(|(s, n)| format!("{n} {s}"))
                .collect();
            println!("{}", counts.join(", "));
            Ok(())
        }
        CampaignCommand::Collect { campaign } => {
            let command = match &out_dir {
                Some(d) => format!(
                    "wiperlab campaign collect {} --out-dir {}",
                    campaign.display(),
                    d.display()
                ),
                None => format!("wiperlab campaign collect {}", campaign.display()),
            };
            let c = load(&campaign)?;
            let (table, path) = crate::campaign::collect::collect(&c)?;
            let outliers = crate::campaign::collect::outliers(&table);
            let page = crate::report::campaign::write_campaign_report(
                &c.out_dir().join("report"),
                &c.name,
                &table,
                &outliers,
            )?;
            let done = table.rows.iter().filter(|r| r.state == "done").count();
            println!(
                "{done} of {} recordings collected into {}; report page {}",
                table.rows.len(),
                path.display(),
                page.display()
            );
            for o in &outliers {
                println!(
                    "  outlier {}: {} = {:.6} (robust z {:.1})",
                    o.id, o.param, o.value, o.robust_z
                );
            }
            for r in table.rows.iter().filter(|r| r.state != "done") {
                println!("  {}: {} {}", r.id, r.state, r.reason);
            }
            if let Some((cal, md)) = crate::campaign::calibrate::write(&c, &command)? {
                let (known, over, _) = cal.shortfalls();
                println!(
                    "calibration table {} ({} parameters scored; {over} of {known} searches short of the truth)",
                    md.display(),
                    cal.overall.len()
                );
            }
            Ok(())
        }
    }
}

fn list(c: &Campaign) -> Result<()> {
    println!(
        "campaign '{}': {} recordings, template {}, outputs in {}",
        c.name,
        c.entries.len(),
        c.template_path.display(),
        c.out_dir().display()
    );
    for (i, e) in c.entries.iter().enumerate() {
        let labels: Vec<String> = e.labels.iter().map(|(k, v)| format!("{k}={v}")).collect();
        println!(
            "  {i:>4} {:<24} {} [{}] {}",
            e.id,
            labels.join(" "),
            describe_overrides(e),
            e.recording.display()
        );
    }
    Ok(())
}

fn run_all(c: &Campaign, jobs: usize, quiet: bool) -> Result<()> {
    let report = move |id: &str, r: &Result<Status>, n: usize, total: usize| {
        if quiet {
            return;
        }
        match r {
            Ok(s) => eprintln!("[{n}/{total}] {id}: done in {:.1} s", s.wall_time_s),
            Err(e) => eprintln!("[{n}/{total}] {id}: FAILED: {e}"),
        }
    };
    let s = run_local(c, jobs, &report)?;
    println!(
        "campaign '{}': {} fitted, {} skipped (complete, inputs unchanged), {} failed",
        c.name,
        s.fitted.len(),
        s.skipped.len(),
        s.failed.len()
    );
    for (id, why) in &s.failed {
        println!("  failed {id}: {why}");
    }
    if s.failed.is_empty() {
        Ok(())
    } else {
        Err(super::CliError::RecordingsFailed {
            failed: s.failed.len(),
            total: c.entries.len(),
        }
        .into())
    }
}

fn slurm(c: &Campaign, a: &SlurmArgs, go: bool) -> Result<()> {
    let cli = SlurmSettings {
        partition: a.partition.clone(),
        time: a.time.clone(),
        cpus_per_task: a.cpus_per_task,
        max_parallel: a.max_parallel,
    };
    let settings = c.file.slurm.overridden_by(&cli);
    let exe = std::env::current_exe().map_err(super::CliError::CurrentExe)?;
    let script = write_script(c, &settings, &exe)?;
    println!("wrote {}", script.display());
    if go {
        let id = submit(c, &script)?;
        println!(
            "submitted Slurm job {id} ({} array tasks); follow it with `wiperlab campaign status {}`",
            c.entries.len(),
            c.path.display()
        );
    } else {
        println!(
            "submit it with `sbatch {}` or rerun with --submit",
            script.display()
        );
    }
    Ok(())
}
