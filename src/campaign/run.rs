//! Fitting a campaign's recordings: the generated job of each recording, one recording's fit (what
//! a Slurm array task runs), and the local parallel run with skipping of finished recordings.

use super::CampaignError;
use super::{Campaign, Entry, FileOverride, Override};
use crate::io::sha256_hex;
use crate::io::write_atomic;
use crate::job::LoadedJob;
use crate::spectrum::features::BandSpec;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Where a recording's fit stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum State {
    /// The result file is complete.
    Done,
    /// The fit failed; the status names why.
    Failed,
}

/// `results/<id>.status.json`: written (atomically) when a recording's fit ends.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Status {
    pub id: String,
    pub state: State,
    /// SHA-256 of the recording, the generated job and blade files and the wiperlab version.
    pub input_sha256: String,
    /// Why the fit failed (the error message), when it did.
    #[serde(default)]
    pub reason: Option<String>,
    pub wall_time_s: f64,
}

/// The files of one recording inside the campaign's output directory.
#[derive(Debug, Clone, PartialEq)]
pub struct EntryPaths {
    pub job: PathBuf,
    pub blade: PathBuf,
    pub result: PathBuf,
    pub status: PathBuf,
}

impl EntryPaths {
    /// The paths of `entry` under `out_dir`.
    pub fn new(out_dir: &Path, entry: &Entry) -> EntryPaths {
        let jobs = out_dir.join("jobs");
        let results = out_dir.join("results");
        EntryPaths {
            job: jobs.join(format!("{}.toml", entry.id)),
            blade: jobs.join(format!("{}.blade.toml", entry.id)),
            result: results.join(format!("{}.result.toml", entry.id)),
            status: results.join(format!("{}.status.json", entry.id)),
        }
    }
}

/// The job and blade file texts generated for `entry`, and the hash of everything the fit reads.
#[derive(Debug, Clone, PartialEq)]
pub struct Generated {
    pub job_text: String,
    pub blade_text: String,
    pub input_sha256: String,
}

/// Generates `entry`'s job from the template: `name` = the entry id, `[recording] file` = the
/// recording, the template's other paths made absolute, the import overrides set, `blade`
/// pointing to a copy of the template's blade file (or the entry's `blade_file`) with the drive
/// overrides, and `[truth] json` the entry's `truth_json` when it has one. The input hash covers
/// the truth file's bytes too (a changed truth changes what the result reports).
///
/// # Errors
/// [`Error::Io`] for an unreadable blade or recording file; [`Error::Input`] when the template's
/// TOML does not have the expected shape.
pub fn generate(campaign: &Campaign, entry: &Entry, paths: &EntryPaths) -> Result<Generated> {
    let tpl = &campaign.template_path;
    let tpl_dir = tpl.parent().unwrap_or(Path::new("."));
    let mut job: toml::Table = toml::from_str(&campaign.template_text)
        .map_err(|e| Error::input(tpl, format!("template: {e}")))?;
    let blade_src = match entry.files.get(&FileOverride::BladeFile) {
        Some(p) => p.clone(),
        None => tpl_dir.join(str_at(&job, tpl, "blade")?),
    };
    let mut blade: toml::Table = toml::from_str(&read(&blade_src)?)
        .map_err(|e| Error::input(&blade_src, format!("blade file: {e}")))?;
    job.insert("name".into(), entry.id.clone().into());
    job.insert("blade".into(), path_value(&paths.blade));
    absolutise(&mut job, tpl_dir, &["truth", "json"]);
    if let Some(truth) = entry.files.get(&FileOverride::TruthJson) {
        table_at(&mut job, tpl, "truth")?.insert("json".into(), path_value(truth));
    }
    if !campaign.file.truth_keys.is_empty() {
        let keys = table_at(table_at(&mut job, tpl, "truth")?, tpl, "keys")?;
        for (k, ptr) in &campaign.file.truth_keys {
            keys.insert(k.name().into(), ptr.clone().into());
        }
    }
    if let Some(ptr) = &campaign.file.truth_friction_law {
        table_at(&mut job, tpl, "truth")?.insert("friction_law".into(), ptr.clone().into());
    }
    if let Some(ptr) = &campaign.file.truth_model {
        table_at(&mut job, tpl, "truth")?.insert("model".into(), ptr.clone().into());
    }
    if campaign.file.bands_follow_frame_rate {
        follow_frame_rate(campaign, entry, &mut job)?;
    }
    let truth_bytes = match job
        .get("truth")
        .and_then(|t| t.get("json"))
        .and_then(toml::Value::as_str)
    {
        Some(p) => Some(std::fs::read(p).map_err(|e| Error::io(Path::new(p), "cannot read", e))?),
        None => None,
    };
    let recording = table_at(&mut job, tpl, "recording")?;
    recording.insert("file".into(), path_value(&entry.recording));
    let import = table_at(recording, tpl, "import")?;
    for (o, v) in &entry.overrides {
        if o.is_blade() {
            blade.insert(o.column().into(), (*v).into());
        } else {
            import.insert(o.column().into(), (*v).into());
        }
    }
    let job_text = format!(
        "# Generated by `wiperlab campaign` from {} for {}: edit the template, not this file.\n{}",
        tpl.display(),
        entry.recording.display(),
        toml::to_string(&job).map_err(|e| Error::input(tpl, e.to_string()))?
    );
    let blade_text =
        toml::to_string(&blade).map_err(|e| Error::input(&blade_src, e.to_string()))?;
    let recording_bytes = std::fs::read(&entry.recording)
        .map_err(|e| Error::io(&entry.recording, "cannot read", e))?;
    let mut hashed = recording_bytes;
    for part in [job_text.as_bytes(), blade_text.as_bytes()] {
        hashed.extend_from_slice(&[0]);
        hashed.extend_from_slice(part);
    }
    if let Some(bytes) = &truth_bytes {
        hashed.extend_from_slice(&[0]);
        hashed.extend_from_slice(bytes);
    }
    hashed.extend_from_slice(env!("CARGO_PKG_VERSION").as_bytes());
    Ok(Generated {
        job_text,
        blade_text,
        input_sha256: sha256_hex(&hashed),
    })
}

/// Replaces the job's `[[spectrum.bands]]` by the template's bands scaled to `entry`'s frame rate
/// (the `bands_follow_frame_rate` rule: [`scaled_band`]); the template's bands are its own or the
/// defaults, and its frame rate is its `[recording.import] fps_hz`.
fn follow_frame_rate(campaign: &Campaign, entry: &Entry, job: &mut toml::Table) -> Result<()> {
    let tpl = &campaign.template_path;
    let template: crate::job::FitJob = toml::from_str(&campaign.template_text)
        .map_err(|e| Error::input(tpl, format!("template: {e}")))?;
    let Some(fps_tpl) = template
        .recording
        .as_ref()
        .and_then(|r| r.import.fps_hz)
        .filter(|f| f.is_finite() && *f > 0.0)
    else {
        return Err(Error::input(
            &campaign.path,
            format!(
                "bands_follow_frame_rate: the template {} gives no [recording.import] fps_hz to scale its bands from",
                tpl.display()
            ),
        ));
    };
    let fps = entry
        .overrides
        .get(&Override::FpsHz)
        .copied()
        .unwrap_or(fps_tpl);
    let mut bands = Vec::with_capacity(template.spectrum.bands.len());
    for b in &template.spectrum.bands {
        let scaled = scaled_band(b, fps_tpl, fps).ok_or_else(|| {
            Error::input(
                &campaign.path,
                format!(
                    "bands_follow_frame_rate: band '{}' ({}–{} Hz) starts above the Nyquist frequency {} Hz of recording {} (fps_hz = {fps})",
                    b.name,
                    b.range_hz[0],
                    b.range_hz[1],
                    0.5 * fps,
                    entry.id
                ),
            )
        })?;
        bands.push(scaled);
    }
    let value = toml::Value::try_from(&bands).map_err(|e| Error::input(tpl, e.to_string()))?;
    let spectrum = job
        .entry("spectrum")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    match spectrum.as_table_mut() {
        Some(t) => {
            t.insert("bands".into(), value);
            Ok(())
        }
        None => Err(Error::input(tpl, "template: expected a [spectrum] table")),
    }
}

/// `band` of a recording at `fps_from` moved to one at `fps_to` with the same bin width: nperseg
/// (and noverlap and nfft when given) times `fps_to/fps_from`, nperseg rounded to the nearest power
/// of two (at least 8) as `wiperlab init`'s band rule does, the others scaled with it; the upper
/// edge clipped at the Nyquist frequency `fps_to/2`. `None` when the band starts at or above it.
pub fn scaled_band(band: &BandSpec, fps_from: f64, fps_to: f64) -> Option<BandSpec> {
    let nyquist = 0.5 * fps_to;
    if band.range_hz[0] >= nyquist {
        return None;
    }
    let mut b = band.clone();
    b.range_hz[1] = b.range_hz[1].min(nyquist);
    if fps_to != fps_from {
        let exact = (band.nperseg as f64 * fps_to / fps_from).max(8.0);
        b.nperseg = 2f64.powf(exact.log2().round()) as usize;
        let ratio = b.nperseg as f64 / band.nperseg as f64;
        let scale = |n: usize| ((n as f64 * ratio).round() as usize).max(1);
        b.noverlap = band.noverlap.map(|n| scale(n).min(b.nperseg - 1));
        b.nfft = band.nfft.map(|n| scale(n).max(b.nperseg));
    }
    Some(b)
}

fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| Error::io(path, "cannot read", e))
}

fn path_value(p: &Path) -> toml::Value {
    p.to_string_lossy().into_owned().into()
}

fn str_at<'a>(t: &'a toml::Table, file: &Path, key: &str) -> Result<&'a str> {
    t.get(key)
        .and_then(toml::Value::as_str)
        .ok_or_else(|| Error::input(file, format!("template: expected a string field {key:?}")))
}

fn table_at<'a>(t: &'a mut toml::Table, file: &Path, key: &str) -> Result<&'a mut toml::Table> {
    t.get_mut(key)
        .and_then(toml::Value::as_table_mut)
        .ok_or_else(|| Error::input(file, format!("template: expected a [{key}] table")))
}

/// Makes the relative path at `keys` (a table path) absolute against `dir`, if present.
fn absolutise(t: &mut toml::Table, dir: &Path, keys: &[&str]) {
    let (last, parents) = keys.split_last().expect("non-empty key path");
    let mut cur = t;
    for k in parents {
        match cur.get_mut(*k).and_then(toml::Value::as_table_mut) {
            Some(next) => cur = next,
            None => return,
        }
    }
    if let Some(rel) = cur.get(*last).and_then(toml::Value::as_str) {
        let abs = dir.join(rel);
        cur.insert((*last).into(), path_value(&abs));
    }
}

/// The status of `entry` when its result is complete for exactly the current inputs.
pub fn finished_status(paths: &EntryPaths, input_sha256: &str) -> Option<Status> {
    let text = std::fs::read_to_string(&paths.status).ok()?;
    let status: Status = serde_json::from_str(&text).ok()?;
    (status.state == State::Done && status.input_sha256 == input_sha256 && paths.result.is_file())
        .then_some(status)
}

/// Reads `results/<id>.status.json`, if there is one.
pub fn read_status(paths: &EntryPaths) -> Option<Status> {
    let text = std::fs::read_to_string(&paths.status).ok()?;
    serde_json::from_str(&text).ok()
}

/// Fits one recording (what a Slurm array task runs): generates its job, fits it, writes the result
/// and the status. A failed fit is recorded in the status (state `failed` and the reason) and
/// returned as the error.
///
/// # Errors
/// Those of [`generate`]; the fit's own error after it is recorded; [`Error::Io`] when the result
/// or status cannot be written.
pub fn fit_entry(campaign: &Campaign, entry: &Entry) -> Result<Status> {
    let paths = EntryPaths::new(&campaign.out_dir(), entry);
    let g = generate(campaign, entry, &paths)?;
    for f in [&paths.blade, &paths.status] {
        crate::io::create_dir(f.parent().unwrap_or(Path::new(".")))?;
    }
    write_atomic(&paths.blade, g.blade_text.as_bytes())?;
    write_atomic(&paths.job, g.job_text.as_bytes())?;
    let started = Instant::now();
    let outcome = LoadedJob::load(&paths.job).and_then(|job| crate::fit::run_fit(&job, false));
    let wall_time_s = started.elapsed().as_secs_f64();
    let (status, result) = match outcome {
        Ok(o) => {
            write_atomic(&paths.result, o.result.to_toml()?.as_bytes())?;
            let s = Status {
                id: entry.id.clone(),
                state: State::Done,
                input_sha256: g.input_sha256,
                reason: None,
                wall_time_s,
            };
            (s.clone(), Ok(s))
        }
        Err(e) => (
            Status {
                id: entry.id.clone(),
                state: State::Failed,
                input_sha256: g.input_sha256,
                reason: Some(e.to_string()),
                wall_time_s,
            },
            Err(e),
        ),
    };
    let json = serde_json::to_string_pretty(&status)
        .map_err(|e| Error::write(paths.status.display(), "JSON", e))?;
    write_atomic(&paths.status, json.as_bytes())?;
    result
}

/// What a local run did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunSummary {
    /// Recordings fitted in this run.
    pub fitted: Vec<String>,
    /// Recordings skipped: their result was complete for the same inputs.
    pub skipped: Vec<String>,
    /// Recordings whose fit failed, with the reason.
    pub failed: Vec<(String, String)>,
}

/// Called as each recording of a local run ends: `(id, status or error, finished, total)`.
pub type OnDone<'a> = dyn Fn(&str, &Result<Status>, usize, usize) + Sync + 'a;

/// Fits every recording of `campaign` whose result is not complete for its current inputs, `jobs`
/// recordings at a time (each fit also uses the rayon pool), and keeps going when one fails.
/// `on_done(id, status or error, finished, total)` is called as each recording ends (for progress).
///
/// # Errors
/// [`CampaignError::AtLeastOne`] for `jobs == 0`; errors generating a job (bad template, unreadable recording)
/// end the run, since they concern every recording alike.
pub fn run_local(campaign: &Campaign, jobs: usize, on_done: &OnDone) -> Result<RunSummary> {
    if jobs == 0 {
        return Err(CampaignError::AtLeastOne {
            command: "campaign run",
            flags: "--jobs",
        }
        .into());
    }
    let out = campaign.out_dir();
    let mut summary = RunSummary::default();
    let mut pending = Vec::new();
    for entry in &campaign.entries {
        let paths = EntryPaths::new(&out, entry);
        let g = generate(campaign, entry, &paths)?;
        if finished_status(&paths, &g.input_sha256).is_some() {
            summary.skipped.push(entry.id.clone());
        } else {
            pending.push(entry);
        }
    }
    let next = AtomicUsize::new(0);
    let finished = AtomicUsize::new(0);
    let total = pending.len();
    let results = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..jobs.min(total.max(1)) {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(entry) = pending.get(i) else { break };
                    let r = fit_entry(campaign, entry);
                    let n = finished.fetch_add(1, Ordering::Relaxed) + 1;
                    on_done(&entry.id, &r, n, total);
                    results
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .push((entry.id.clone(), r));
                }
            });
        }
    });
    let mut results = results.into_inner().unwrap_or_else(|e| e.into_inner());
    results.sort_by(|a, b| a.0.cmp(&b.0));
    for (id, r) in results {
        match r {
            Ok(_) => summary.fitted.push(id),
            Err(e) => summary.failed.push((id, e.to_string())),
        }
    }
    Ok(summary)
}

/// The overrides of `entry` as `column = value` text, for listings.
pub fn describe_overrides(entry: &Entry) -> String {
    Override::ALL
        .iter()
        .filter_map(|o| {
            entry
                .overrides
                .get(o)
                .map(|v| format!("{} = {v}", o.column()))
        })
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The main job's bands (10,000 frames/s) at 5,000 and 20,000 frames/s keep their bin widths
    /// (fs/nperseg = 2.44 and 19.5 Hz), and the high band stops at the slower camera's Nyquist.
    #[test]
    fn bands_keep_their_bin_width_and_stop_at_nyquist() {
        let low = BandSpec::new("low", [30.0, 300.0], 4096);
        let high = BandSpec::new("high", [500.0, 5000.0], 512);
        let slow = scaled_band(&high, 10_000.0, 5_000.0).expect("500 Hz < 2500 Hz");
        assert_eq!((slow.nperseg, slow.range_hz), (256, [500.0, 2500.0]));
        let fast = scaled_band(&high, 10_000.0, 20_000.0).expect("band");
        assert_eq!((fast.nperseg, fast.range_hz), (1024, [500.0, 5000.0]));
        assert_eq!(scaled_band(&low, 10_000.0, 5_000.0).unwrap().nperseg, 2048);
        // 13 kHz: 4096·1.3 = 5325, nearest power of two 4096 (log2 12.38 rounds to 12).
        assert_eq!(scaled_band(&low, 10_000.0, 13_000.0).unwrap().nperseg, 4096);
        // 15 kHz: 6144, log2 12.58 rounds to 13.
        assert_eq!(scaled_band(&low, 10_000.0, 15_000.0).unwrap().nperseg, 8192);
        let mut overlapped = high.clone();
        overlapped.noverlap = Some(384);
        overlapped.nfft = Some(1024);
        let o = scaled_band(&overlapped, 10_000.0, 20_000.0).unwrap();
        assert_eq!((o.noverlap, o.nfft), (Some(768), Some(2048)));
        assert!(
            scaled_band(&high, 10_000.0, 900.0).is_none(),
            "Nyquist 450 Hz"
        );
        assert_eq!(scaled_band(&high, 10_000.0, 10_000.0).unwrap(), high);
    }
}
