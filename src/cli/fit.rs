//! `wiperlab fit` and `wiperlab report`: a fit job's result, figures and report page.

use crate::job::LoadedJob;
use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// Fits the job, writes the result and figures (in `out_dir`, default the job's
/// `<reports_dir>/<name>/`), and prints the summary (or the JSON result).
pub(super) fn fit(job: &Path, json: bool, quiet: bool, out_dir: Option<PathBuf>) -> Result<()> {
    let loaded = LoadedJob::load(job)?;
    let report_dir = out_dir.unwrap_or_else(|| report_dir(&loaded));
    let (result, result_path) = fit_and_write(&loaded, &report_dir, !quiet && !json)?;
    // Each warning once, on stderr (also in the result file and on the report page): `warning:`
    // when it needs attention, `note:` when it is normal on a good fit.
    for w in &result.warnings {
        eprintln!("{}: {w}", severity_prefix(w.severity()));
    }
    if json {
        println!(
            "{}",
            serde_json::to_string(&result).map_err(|e| Error::write("stdout", "JSON", e))?
        );
        return Ok(());
    }
    print!("{}", crate::report::figures::fit_summary(&result));
    println!(
        "wrote {} and figures in {}",
        result_path.display(),
        report_dir.display()
    );
    println!(
        "report page: `wiperlab report {}` writes {}",
        job.display(),
        report_dir.join(crate::report::html::INDEX).display()
    );
    Ok(())
}

/// Writes the report page from the job's result into `out_dir` (default the job's
/// `<reports_dir>/<name>/`, where the fit put its figures); `refit` fits first. Without a result
/// (and without `refit`) it is an input error (exit 2) that says how to get one.
pub(super) fn report(job: &Path, refit: bool, quiet: bool, out_dir: Option<PathBuf>) -> Result<()> {
    let loaded = LoadedJob::load(job)?;
    let result_path = result_path(&loaded);
    let report_dir = out_dir.unwrap_or_else(|| report_dir(&loaded));
    let result = if refit {
        fit_and_write(&loaded, &report_dir, !quiet)?.0
    } else if !result_path.exists() {
        return Err(Error::input(
            &result_path,
            format!(
                "no fit result: run `wiperlab fit {0}` first, or `wiperlab report {0} --refit`",
                job.display()
            ),
        ));
    } else {
        crate::fit::FitResult::read(&result_path)?
    };
    let summary = crate::report::html::write_report(
        &result,
        &crate::report::html::ReportPaths {
            job: job.to_path_buf(),
            result: result_path,
            recording: loaded.recording_path.clone(),
            dir: report_dir,
        },
    )?;
    for w in &summary.warnings {
        eprintln!("{}: {w}", severity_prefix(w.severity()));
    }
    println!(
        "wrote {} ({} figures); open it in a browser",
        summary.path.display(),
        summary.figures.len()
    );
    Ok(())
}

/// How stderr marks a warning of `severity`.
fn severity_prefix(severity: crate::fit::Severity) -> &'static str {
    match severity {
        crate::fit::Severity::Attention => "warning",
        crate::fit::Severity::Information => "note",
    }
}

/// `<job dir>/<name>.result.toml`.
fn result_path(job: &LoadedJob) -> PathBuf {
    job.dir().join(format!("{}.result.toml", job.name))
}

/// `<job dir>/<reports_dir>/<name>/` (default `<job dir>/reports/<name>/`), wherever the command
/// runs.
fn report_dir(job: &LoadedJob) -> PathBuf {
    job.reports_dir().join(&job.name)
}

/// Where `wiperlab fit` puts a job's figures by default: `<job dir>/<reports_dir>/<name>/`.
pub fn default_fit_dir(job: &LoadedJob) -> PathBuf {
    report_dir(job)
}

/// `<job dir>/<name>.interrupted.result.toml`: where an interrupted fit's result goes, so that a
/// previous complete result stays in place.
fn interrupted_path(job: &LoadedJob) -> PathBuf {
    job.dir()
        .join(format!("{}.interrupted.result.toml", job.name))
}

/// Runs the fit, writes the result TOML and the fit's figures in `report_dir`; returns the result
/// and the result's path.
/// SIGINT or SIGTERM stops the fit: the best result so far is written to
/// `<name>.interrupted.result.toml` and the error is [`Error::Interrupted`] (exit code 130).
fn fit_and_write(
    job: &LoadedJob,
    report_dir: &Path,
    progress: bool,
) -> Result<(crate::fit::FitResult, PathBuf)> {
    crate::search::interrupt::install_signal_handler()?;
    fit_files(job, report_dir, progress)
}

/// What `wiperlab fit` writes, without installing a signal handler: a caller that has its own
/// (the Python package) stops the fit with [`crate::search::interrupt::request_stop`], and gets
/// [`Error::Interrupted`] naming the best-so-far result as the command does. `report_dir`:
/// [`default_fit_dir`] unless the caller chooses another.
pub fn fit_files(
    job: &LoadedJob,
    report_dir: &Path,
    progress: bool,
) -> Result<(crate::fit::FitResult, PathBuf)> {
    // Outputs that cannot be written are found now, not after the whole fit.
    crate::io::check_writable_file(&result_path(job))?;
    crate::io::check_writable_file(&interrupted_path(job))?;
    crate::io::check_creatable_dir(report_dir)?;
    let mut outcome = match crate::fit::run_fit(job, progress) {
        Err(_) if crate::search::interrupt::stop_requested() => {
            return Err(Error::Interrupted { written: None });
        }
        other => other?,
    };
    if outcome.result.interrupted {
        let path = interrupted_path(job);
        crate::io::write_atomic(&path, outcome.result.to_toml()?.as_bytes())?;
        return Err(Error::Interrupted {
            written: Some(path),
        });
    }
    crate::io::create_dir(report_dir)?;
    outcome.result.data_files = crate::report::figures::fit_data_files(report_dir, &outcome)?;
    let result_path = result_path(job);
    let toml_text = outcome.result.to_toml()?;
    crate::io::write_atomic(&result_path, toml_text.as_bytes())?;
    let freq_speed = crate::likelihood::instfreq::compare_freq_speed(
        &outcome.measured_trace,
        &outcome.best_sim,
        outcome.fs_hz,
        outcome.signal,
    )?;
    crate::report::figures::fit_figures(report_dir, &outcome, freq_speed.as_ref())?;
    Ok((outcome.result, result_path))
}
