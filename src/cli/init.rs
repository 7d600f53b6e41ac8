//! `wiperlab init`: a commented fit-job template for a recording.

use super::ImportArgs;
use crate::job::template::{TemplateInput, job_template};
use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// Describes `recording` (without a calibration if the flags give none), writes the job template
/// to `output` (default `<stem>.job.toml` in `out_dir`, itself by default the recording's
/// directory) and says what is still missing.
pub(super) fn run(
    recording: &Path,
    import: &ImportArgs,
    output: Option<PathBuf>,
    out_dir: Option<PathBuf>,
) -> Result<()> {
    let out = output.unwrap_or_else(|| {
        let name = format!("{}.job.toml", super::stem(recording));
        super::single_output(recording, out_dir.as_deref(), &name)
    });
    let stdout = out == Path::new("-");
    if out.exists() && !stdout {
        return Err(super::CliError::OutputExists { path: out }.into());
    }
    crate::io::refuse_overwriting_input(recording, &out)?;
    let mut spec = super::import::import_spec(import)?;
    let (_, summary) = crate::import::describe_file(recording, &spec)?;
    spec.format = summary.format;
    // `--out-dir` is created if need be; an `-o` into a missing directory is refused.
    if let Some(d) = &out_dir {
        crate::io::create_dir(d)?;
    }
    let name = plain_name(&super::stem(recording));
    let text = job_template(&TemplateInput {
        name: &name,
        recording: &if stdout {
            // Where the job will be saved is unknown: the recording's absolute path.
            std::path::absolute(recording)
                .map_err(|e| Error::io(recording, "cannot resolve the path", e))?
        } else {
            recording_as_seen_from(&out, recording)?
        },
        import: &spec,
        summary: &summary,
    })?;
    let (missing, check) = crate::job::template::count_marks(&text);
    if stdout {
        // `-o -`: the job on stdout, the count on stderr.
        print!("{text}");
        super::esay!("({missing} MISSING, {check} CHECK)");
        return Ok(());
    }
    crate::io::write_atomic(&out, text.as_bytes())?;
    println!(
        "wrote {} ({missing} MISSING, {check} CHECK); fill it in, then `wiperlab fit {}`",
        out.display(),
        out.display()
    );
    Ok(())
}

/// `stem` made a plain file stem for the job's `name` (a leading `.` dropped).
fn plain_name(stem: &str) -> String {
    let s = stem.trim_start_matches('.');
    if crate::io::is_plain_stem(s) {
        s.to_string()
    } else {
        "recording".into()
    }
}

/// The recording's path as the job at `job` should spell it: its file name when both are in one
/// directory, else the absolute path (a job's paths are relative to the job file).
fn recording_as_seen_from(job: &Path, recording: &Path) -> Result<PathBuf> {
    let dir_of = |p: &Path| -> Result<PathBuf> {
        let d = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        d.canonicalize()
            .map_err(|e| Error::io(d, "cannot resolve the directory", e))
    };
    let name = recording.file_name().map(PathBuf::from).unwrap_or_default();
    if dir_of(job)? == dir_of(recording)? {
        Ok(name)
    } else {
        Ok(dir_of(recording)?.join(name))
    }
}
