//! Slurm: the campaign as one `sbatch` job array, one array task per recording, each running
//! `wiperlab campaign task CAMPAIGN --index $SLURM_ARRAY_TASK_ID` (the same binary, the same
//! generated job as a local run). `--array=0-(n−1)%K` throttles the array to K tasks at a time.
//!
//! The array's state is read with `squeue` (which needs no accounting database) and the tasks'
//! own status files; `sacct` is not used.
//!
//! Reference: Slurm documentation, `sbatch` (`--array`, `--parsable`) and job arrays
//! (<https://slurm.schedmd.com/job_array.html>).

use super::Campaign;
use super::CampaignError;
use super::run::{EntryPaths, State, read_status};
use crate::io::write_atomic;
use crate::{Error, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Settings of the array job; each may also come from the command line.
#[derive(Debug, Clone, PartialEq, Eq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlurmSettings {
    /// `--partition`; default: the cluster's default partition.
    #[serde(default)]
    pub partition: Option<String>,
    /// `--time` per task, e.g. "00:30:00"; default: the partition's limit.
    #[serde(default)]
    pub time: Option<String>,
    /// `--cpus-per-task`; also the fit's thread count (RAYON_NUM_THREADS). Default 2.
    #[serde(default)]
    pub cpus_per_task: Option<u32>,
    /// Largest number of array tasks running at once (`%K`); default: no limit.
    #[serde(default)]
    pub max_parallel: Option<u32>,
}

impl SlurmSettings {
    /// `self` with every value `other` sets taking precedence.
    pub fn overridden_by(&self, other: &SlurmSettings) -> SlurmSettings {
        SlurmSettings {
            partition: other.partition.clone().or_else(|| self.partition.clone()),
            time: other.time.clone().or_else(|| self.time.clone()),
            cpus_per_task: other.cpus_per_task.or(self.cpus_per_task),
            max_parallel: other.max_parallel.or(self.max_parallel),
        }
    }
}

/// `<out dir>/slurm/`.
pub fn slurm_dir(campaign: &Campaign) -> PathBuf {
    campaign.out_dir().join("slurm")
}

/// The `sbatch` script of the campaign's job array, running `exe`.
///
/// # Errors
/// [`CampaignError`] for a campaign without recordings, `cpus_per_task` or `max_parallel` of 0, or
/// a partition or time holding whitespace or quotes.
pub fn script(campaign: &Campaign, settings: &SlurmSettings, exe: &Path) -> Result<String> {
    let n = campaign.entries.len();
    if n == 0 {
        return Err(CampaignError::NoRecordings.into());
    }
    let cpus = settings.cpus_per_task.unwrap_or(2);
    if cpus == 0 || settings.max_parallel == Some(0) {
        return Err(CampaignError::AtLeastOne {
            command: "campaign slurm",
            flags: "--cpus-per-task and --max-parallel",
        }
        .into());
    }
    for (flag, v) in [
        ("--partition", &settings.partition),
        ("--time", &settings.time),
    ] {
        if let Some(v) = v
            && (v.is_empty() || v.contains(|c: char| c.is_whitespace() || c == '"' || c == '\''))
        {
            return Err(CampaignError::NotOneWord {
                flag,
                value: v.clone(),
            }
            .into());
        }
    }
    let logs = slurm_dir(campaign).join("logs");
    let throttle = settings
        .max_parallel
        .map_or(String::new(), |k| format!("%{k}"));
    let mut s = String::from("#!/bin/bash\n");
    s.push_str(&format!(
        "# wiperlab campaign '{}': one array task per recording ({n}); written by `wiperlab campaign slurm`.\n",
        campaign.name
    ));
    s.push_str(&format!("#SBATCH --job-name=wiperlab-{}\n", campaign.name));
    s.push_str(&format!("#SBATCH --array=0-{}{throttle}\n", n - 1));
    s.push_str(&format!("#SBATCH --cpus-per-task={cpus}\n"));
    if let Some(p) = &settings.partition {
        s.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    if let Some(t) = &settings.time {
        s.push_str(&format!("#SBATCH --time={t}\n"));
    }
    s.push_str(&format!("#SBATCH --output={}/%A_%a.out\n", logs.display()));
    s.push_str("export RAYON_NUM_THREADS=\"${SLURM_CPUS_PER_TASK:-1}\"\n");
    let out_dir = campaign
        .out_dir_override
        .as_ref()
        .map_or(String::new(), |d| {
            format!(" --out-dir {}", shell_quote(&d.to_string_lossy()))
        });
    s.push_str(&format!(
        "exec {} campaign task {} --index \"$SLURM_ARRAY_TASK_ID\"{out_dir}\n",
        shell_quote(&exe.to_string_lossy()),
        shell_quote(&campaign.path.to_string_lossy())
    ));
    Ok(s)
}

/// Single-quotes `s` for a POSIX shell.
fn shell_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', "'\\''"))
}

/// Writes the array script to `<out dir>/slurm/array.sh` (and creates the log directory).
///
/// # Errors
/// Those of [`script`]; [`Error::Io`] when the files cannot be written.
pub fn write_script(campaign: &Campaign, settings: &SlurmSettings, exe: &Path) -> Result<PathBuf> {
    let text = script(campaign, settings, exe)?;
    let dir = slurm_dir(campaign);
    let logs = dir.join("logs");
    std::fs::create_dir_all(&logs).map_err(|e| Error::io(&logs, "cannot create directory", e))?;
    let path = dir.join("array.sh");
    write_atomic(&path, text.as_bytes())?;
    Ok(path)
}

/// Submits `script` with `sbatch --parsable` and records the job id in `<out dir>/slurm/job_id`.
///
/// # Errors
/// [`Error::Input`] naming the script when `sbatch` cannot be started
/// or refuses the job (its stderr is quoted).
pub fn submit(campaign: &Campaign, script: &Path) -> Result<String> {
    let out = Command::new("sbatch")
        .arg("--parsable")
        .arg(script)
        .output()
        .map_err(|e| {
            Error::input(
                script,
                format!("cannot run sbatch: {e} (is Slurm installed and on PATH?)"),
            )
        })?;
    if !out.status.success() {
        return Err(Error::input(
            script,
            format!(
                "sbatch refused the job: {}",
                String::from_utf8_lossy(&out.stderr).trim()
            ),
        ));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let id = text
        .trim()
        .split(';')
        .next()
        .unwrap_or_default()
        .to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(Error::input(
            script,
            format!("sbatch --parsable printed {text:?}, expected a job id"),
        ));
    }
    write_atomic(&slurm_dir(campaign).join("job_id"), id.as_bytes())?;
    Ok(id)
}

/// The state of each recording of a submitted campaign.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArrayStatus {
    /// The array's job id, if the campaign was submitted.
    pub job_id: Option<String>,
    /// Per recording (in array order): its id and state: `done`, `failed`, or the queue's state
    /// (`PENDING`, `RUNNING`, …), or `not queued`.
    pub tasks: Vec<(String, String)>,
}

impl ArrayStatus {
    /// Counts of each state, in first-seen order.
    pub fn counts(&self) -> Vec<(String, usize)> {
        let mut out: Vec<(String, usize)> = Vec::new();
        for (_, s) in &self.tasks {
            match out.iter_mut().find(|(k, _)| k == s) {
                Some((_, n)) => *n += 1,
                None => out.push((s.clone(), 1)),
            }
        }
        out
    }

    /// True when every recording is done or failed.
    pub fn finished(&self) -> bool {
        self.tasks.iter().all(|(_, s)| s == "done" || s == "failed")
    }
}

/// Reads the campaign's state: each recording's status file, and for the others the array task's
/// state from `squeue -h -r -j <job id> -o "%K %T"` (an absent `squeue` leaves them `not queued`).
pub fn status(campaign: &Campaign) -> ArrayStatus {
    let job_id = std::fs::read_to_string(slurm_dir(campaign).join("job_id"))
        .ok()
        .map(|s| s.trim().to_string());
    let queued = job_id.as_deref().map(queue_states).unwrap_or_default();
    let out = campaign.out_dir();
    let tasks = campaign
        .entries
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let state = match read_status(&EntryPaths::new(&out, e)) {
                Some(s) if s.state == State::Done => "done".to_string(),
                Some(_) => "failed".to_string(),
                None => queued
                    .iter()
                    .find(|(k, _)| *k == i)
                    .map_or_else(|| "not queued".to_string(), |(_, s)| s.clone()),
            };
            (e.id.clone(), state)
        })
        .collect();
    ArrayStatus { job_id, tasks }
}

/// `(array index, state)` of the array's tasks still known to the queue.
fn queue_states(job_id: &str) -> Vec<(usize, String)> {
    let Ok(out) = Command::new("squeue")
        .args(["-h", "-r", "-j", job_id, "-o", "%K %T"])
        .output()
    else {
        return Vec::new();
    };
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| {
            let mut it = l.split_whitespace();
            let k = it.next()?.parse().ok()?;
            Some((k, it.next()?.to_string()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoting_survives_quotes_and_spaces() {
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), "'it'\\''s'");
    }

    #[test]
    fn command_line_settings_take_precedence() {
        let file = SlurmSettings {
            partition: Some("long".into()),
            cpus_per_task: Some(4),
            ..Default::default()
        };
        let cli = SlurmSettings {
            cpus_per_task: Some(8),
            max_parallel: Some(3),
            ..Default::default()
        };
        let s = file.overridden_by(&cli);
        assert_eq!(s.partition.as_deref(), Some("long"));
        assert_eq!(s.cpus_per_task, Some(8));
        assert_eq!(s.max_parallel, Some(3));
    }
}
