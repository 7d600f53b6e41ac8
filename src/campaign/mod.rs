//! Campaigns: one fit job template applied to many recordings (blade designs, compounds, wet and
//! dry glass, sweep speeds, repeats), run locally in parallel or as a Slurm job array, and
//! collected into one table.
//!
//! A campaign file (TOML) names
//! * `template`: an ordinary fit job (its `[recording] file` is replaced per recording);
//! * `recordings`: paths or glob patterns (relative to the campaign file);
//! * `conditions` (optional): a CSV table the lab already keeps, one row per recording, matched by
//!   the `recording` column (the file name). Columns named like a per-recording setting
//!   ([`Override`]: `t0_s`, `fps_hz`, `m_per_px`, `drive_a_m`, `drive_omega_rad_per_s`) override
//!   the template for that recording; two columns name per-recording input files
//!   ([`FileOverride`]: `blade_file`, the blade file in place of the template's, and `truth_json`,
//!   the `[truth]` JSON in place of the template's), relative to the table; every other column is
//!   a free-form condition label (blade, compound, wet, temperature_c, repeat, …) carried into the
//!   collected table.
//!
//! Everything the campaign writes goes to `<campaign dir>/<name>/`: `jobs/` (one generated job and
//! blade file per recording), `results/` (`<id>.result.toml` and `<id>.status.json`), `slurm/`
//! (the array script, its logs and job id) and `campaign.csv`.
//!
//! * [`Campaign::load`] reads and validates the campaign;
//! * [`run::run_local`] fits every pending recording in parallel, skipping those whose result is
//!   complete and whose inputs (recording, job and blade text, wiperlab version) hash the same;
//! * [`slurm`] writes and submits the `sbatch` array script, and reads the array's state;
//! * [`collect::collect`] merges the results into `campaign.csv`;
//! * [`calibrate::write`] tabulates, when the recordings carry truths, how the fit's intervals,
//!   search and model choice fare against them (`calibration.md`).

pub mod calibrate;
pub mod collect;
mod error;
pub mod law;
pub mod run;
pub mod slurm;

use crate::job::{FitJob, TruthSection};
use crate::model::{BladeParams, ParamId};
use crate::{Error, Result};
pub use error::CampaignError;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A campaign file as written in TOML.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignFile {
    /// Name of the campaign's output directory; default: the file stem.
    #[serde(default)]
    pub name: Option<String>,
    /// The fit job every recording is fitted with.
    pub template: PathBuf,
    /// Recording files or glob patterns (`*`, `?`, `[...]`).
    pub recordings: Vec<String>,
    /// Optional CSV table of per-recording settings and condition labels.
    #[serde(default)]
    pub conditions: Option<PathBuf>,
    /// Keys added to the template's `[truth] keys` (parameter → JSON pointer), e.g. the shoulder's
    /// `theta_c` and `k1c` when the recordings' truth files hold them and the template is a job
    /// whose own truth does not.
    #[serde(default)]
    pub truth_keys: BTreeMap<ParamId, String>,
    /// JSON pointer to each recording's true friction law (the template's `[truth]
    /// friction_law`): the fitted law is then scored as a curve over the measured slip speeds.
    #[serde(default)]
    pub truth_friction_law: Option<String>,
    /// JSON pointer to the name of each recording's true model (the template's `[truth] model`):
    /// the fit then reads the truth's cost in that model's candidate, so the search shortfall is
    /// measured on every recording, whichever model the fit chooses.
    #[serde(default)]
    pub truth_model: Option<String>,
    /// Scale the template's Welch bands to each recording's frame rate (`fps_hz` column): keep
    /// each band's bin width (nperseg, and noverlap and nfft when given, times the frame-rate
    /// ratio, rounded to a power of two as `wiperlab init` does) and clip its upper edge at the
    /// recording's Nyquist frequency.
    #[serde(default)]
    pub bands_follow_frame_rate: bool,
    /// Where the calibration table goes (`<reports_dir>/<name>/calibration.md`), relative to the
    /// campaign file; default: the campaign's `report/` directory.
    #[serde(default)]
    pub reports_dir: Option<PathBuf>,
    /// Text printed at the top of the calibration table (what the campaign is, how its seeds were
    /// chosen).
    #[serde(default)]
    pub notes: Option<String>,
    /// Defaults for `wiperlab campaign slurm`.
    #[serde(default)]
    pub slurm: slurm::SlurmSettings,
}

/// A per-recording setting a conditions column may override.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Override {
    /// `[recording.import] t0_s`: frame 1 on the model clock, s.
    T0S,
    /// `[recording.import] fps_hz`: camera frame rate, Hz.
    FpsHz,
    /// `[recording.import] m_per_px`: image scale, m per pixel.
    MPerPx,
    /// Blade `drive_a_m`: drive amplitude, m.
    DriveAM,
    /// Blade `drive_omega_rad_per_s`: drive angular frequency, rad/s.
    DriveOmegaRadPerS,
}

impl Override {
    /// Every override, in column order.
    pub const ALL: [Override; 5] = [
        Override::T0S,
        Override::FpsHz,
        Override::MPerPx,
        Override::DriveAM,
        Override::DriveOmegaRadPerS,
    ];

    /// The column (and field) name.
    pub fn column(self) -> &'static str {
        match self {
            Override::T0S => "t0_s",
            Override::FpsHz => "fps_hz",
            Override::MPerPx => "m_per_px",
            Override::DriveAM => "drive_a_m",
            Override::DriveOmegaRadPerS => "drive_omega_rad_per_s",
        }
    }

    /// The column's unit, for a figure's axis.
    pub fn unit(self) -> &'static str {
        match self {
            Override::T0S => "s",
            Override::FpsHz => "Hz",
            Override::MPerPx => "m/px",
            Override::DriveAM => "m",
            Override::DriveOmegaRadPerS => "rad/s",
        }
    }

    /// The override whose column is `name`.
    pub fn from_column(name: &str) -> Option<Override> {
        Override::ALL.into_iter().find(|o| o.column() == name)
    }

    /// True for settings of the blade file (the drive), false for the import settings.
    pub fn is_blade(self) -> bool {
        matches!(self, Override::DriveAM | Override::DriveOmegaRadPerS)
    }
}

/// A per-recording input file a conditions column may name in place of the template's: a path
/// relative to the conditions table, checked when the campaign is loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum FileOverride {
    /// The blade file (TOML with the blade's parameters), in place of the template's `blade`; the
    /// drive overrides still apply on top of it.
    BladeFile,
    /// The `[truth]` JSON, in place of the template's `[truth] json`; read with the template's
    /// `[truth] keys`, so every key must hold a number in it.
    TruthJson,
}

impl FileOverride {
    /// Every file override, in column order.
    pub const ALL: [FileOverride; 2] = [FileOverride::BladeFile, FileOverride::TruthJson];

    /// The column name.
    pub fn column(self) -> &'static str {
        match self {
            FileOverride::BladeFile => "blade_file",
            FileOverride::TruthJson => "truth_json",
        }
    }

    /// The override whose column is `name`.
    pub fn from_column(name: &str) -> Option<FileOverride> {
        FileOverride::ALL.into_iter().find(|o| o.column() == name)
    }
}

/// One recording of a campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// Identifier: the recording's file stem (unique within the campaign).
    pub id: String,
    /// The recording file (absolute).
    pub recording: PathBuf,
    /// Settings that differ from the template.
    pub overrides: BTreeMap<Override, f64>,
    /// Input files that replace the template's (absolute, checked to exist and parse).
    pub files: BTreeMap<FileOverride, PathBuf>,
    /// Condition labels (column → value), in the table's column order.
    pub labels: Vec<(String, String)>,
}

/// A loaded, validated campaign.
#[derive(Debug, Clone)]
pub struct Campaign {
    /// The campaign file (absolute).
    pub path: PathBuf,
    pub name: String,
    pub file: CampaignFile,
    /// The template job file (absolute) and its text.
    pub template_path: PathBuf,
    pub template_text: String,
    /// Recordings in a fixed order (by id): a Slurm array index is a position in this list.
    pub entries: Vec<Entry>,
    /// The condition label columns, in the table's order.
    pub label_columns: Vec<String>,
    /// `--out-dir` (absolute): where everything the campaign writes goes instead of
    /// `<campaign dir>/<name>/`.
    pub out_dir_override: Option<PathBuf>,
}

impl Campaign {
    /// Reads the campaign at `path`, its template job and its conditions table, and resolves the
    /// recordings.
    ///
    /// # Errors
    /// [`Error::Io`] for unreadable files; [`Error::Parse`] (file, line, column) for TOML or CSV
    /// problems, a conditions row naming a recording the patterns do not find, a value that is
    /// not a positive finite number, or a `blade_file`/`truth_json` cell whose file is missing,
    /// does not parse, or (a truth) lacks one of the template's `[truth] keys`, or a `truth_json`
    /// column with a template without `[truth]`; [`Error::Input`] for a pattern that matches nothing, a
    /// recording without a conditions row, two recordings with the same file stem, or a template
    /// that is not a fit job with a `[recording]`.
    pub fn load(path: &Path) -> Result<Campaign> {
        let path = absolute(path)?;
        let text = read(&path)?;
        let file: CampaignFile = toml::from_str(&text).map_err(|e| toml_error(&path, &text, &e))?;
        let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        let name = match &file.name {
            Some(n) => n.clone(),
            None => stem(&path),
        };
        check_plain_name(&path, &name)?;
        let template_path = dir.join(&file.template);
        let template_text = read(&template_path)?;
        let template: FitJob = toml::from_str(&template_text)
            .map_err(|e| toml_error(&template_path, &template_text, &e))?;
        if template.recording.is_none() {
            return Err(Error::input(
                &template_path,
                "a campaign template must be a fit job with a [recording] section (its file is replaced per recording)",
            ));
        }
        if (!file.truth_keys.is_empty()
            || file.truth_friction_law.is_some()
            || file.truth_model.is_some())
            && template.truth.is_none()
        {
            return Err(Error::input(
                &path,
                format!(
                    "truth_keys, truth_friction_law and truth_model add to the template's [truth], but the template {} has no [truth] section",
                    template_path.display()
                ),
            ));
        }
        let recordings = resolve_recordings(&path, &dir, &file.recordings)?;
        let (entries, label_columns) = match &file.conditions {
            Some(table) => with_conditions(
                &path,
                &dir.join(table),
                &template_path,
                merged_truth(template.truth, &file.truth_keys).as_ref(),
                recordings,
            )?,
            None => (
                recordings
                    .into_iter()
                    .map(|(id, recording)| Entry {
                        id,
                        recording,
                        overrides: BTreeMap::new(),
                        files: BTreeMap::new(),
                        labels: Vec::new(),
                    })
                    .collect(),
                Vec::new(),
            ),
        };
        Ok(Campaign {
            path,
            name,
            file,
            template_path,
            template_text,
            entries,
            label_columns,
            out_dir_override: None,
        })
    }

    /// The campaign with everything it writes in `dir` (made absolute) instead of
    /// `<campaign dir>/<name>/`; `None` keeps the default.
    ///
    /// # Errors
    /// [`Error::Io`] when the path cannot be made absolute.
    pub fn with_out_dir(mut self, dir: Option<&Path>) -> Result<Campaign> {
        self.out_dir_override = dir.map(absolute).transpose()?;
        Ok(self)
    }

    /// Where the calibration table goes: `<reports_dir>/<name>/` when the campaign file sets
    /// `reports_dir`, else `<out dir>/report/`.
    pub fn calibration_dir(&self) -> PathBuf {
        match &self.file.reports_dir {
            Some(r) => self
                .path
                .parent()
                .unwrap_or(Path::new("."))
                .join(r)
                .join(&self.name),
            None => self.out_dir().join("report"),
        }
    }

    /// `<campaign dir>/<name>/` (or `--out-dir`): everything the campaign writes.
    pub fn out_dir(&self) -> PathBuf {
        match &self.out_dir_override {
            Some(d) => d.clone(),
            None => self
                .path
                .parent()
                .unwrap_or(Path::new("."))
                .join(&self.name),
        }
    }

    /// The entry with identifier `id`.
    pub fn entry(&self, id: &str) -> Option<&Entry> {
        self.entries.iter().find(|e| e.id == id)
    }

    /// The `[truth]` of `entry`'s fit: the template's keys and the campaign's `truth_keys`, read
    /// from the entry's `truth_json` (absolute) or else the template's own JSON (made absolute);
    /// `None` when the template has no `[truth]`.
    pub fn truth_of(&self, entry: &Entry) -> Option<TruthSection> {
        let template: FitJob = toml::from_str(&self.template_text).ok()?;
        let mut truth = merged_truth(template.truth, &self.file.truth_keys)?;
        if let Some(ptr) = &self.file.truth_friction_law {
            truth.friction_law = Some(ptr.clone());
        }
        if let Some(ptr) = &self.file.truth_model {
            truth.model = Some(ptr.clone());
        }
        truth.json = match entry.files.get(&FileOverride::TruthJson) {
            Some(p) => p.clone(),
            None => self
                .template_path
                .parent()
                .unwrap_or(Path::new("."))
                .join(&truth.json),
        };
        Some(truth)
    }
}

/// The template's `[truth]` with the campaign's `truth_keys` added (the campaign's win).
fn merged_truth(
    truth: Option<TruthSection>,
    extra: &BTreeMap<ParamId, String>,
) -> Option<TruthSection> {
    let mut t = truth?;
    t.keys.extend(extra.iter().map(|(k, v)| (*k, v.clone())));
    Some(t)
}

fn absolute(path: &Path) -> Result<PathBuf> {
    std::path::absolute(path).map_err(|e| Error::io(path, "cannot resolve the path", e))
}

fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| Error::io(path, "cannot read", e))
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// A TOML error with the line and column of its span.
fn toml_error(path: &Path, text: &str, e: &toml::de::Error) -> Error {
    let (line, column) = match e.span() {
        Some(span) => line_column(text, span.start),
        None => (0, 0),
    };
    Error::parse(path, line, column, e.message().trim().to_string())
}

/// 1-based line and column of byte `offset` in `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// A campaign name is used as a directory name beside the campaign file: a plain file stem.
fn check_plain_name(path: &Path, name: &str) -> Result<()> {
    if crate::io::is_plain_stem(name) {
        Ok(())
    } else {
        Err(Error::input(
            path,
            format!("name = {name:?} must be a plain file stem (no '/', '\\' or leading '.')"),
        ))
    }
}

/// The recordings the patterns match, as `(id, absolute path)` sorted by id.
fn resolve_recordings(
    path: &Path,
    dir: &Path,
    patterns: &[String],
) -> Result<Vec<(String, PathBuf)>> {
    if patterns.is_empty() {
        return Err(Error::input(path, "recordings = [] names no recording"));
    }
    let mut found = BTreeMap::<String, PathBuf>::new();
    for pattern in patterns {
        let full = dir.join(pattern);
        let matches: Vec<PathBuf> = glob::glob(&full.to_string_lossy())
            .map_err(|e| Error::input(path, format!("recordings: pattern {pattern:?}: {e}")))?
            .filter_map(std::result::Result::ok)
            .filter(|p| p.is_file())
            .collect();
        if matches.is_empty() {
            return Err(Error::input(
                path,
                format!(
                    "recordings: {pattern:?} matches no file (looked for {})",
                    full.display()
                ),
            ));
        }
        for m in matches {
            let id = stem(&m);
            if let Some(prev) = found.get(&id)
                && *prev != m
            {
                return Err(Error::input(
                    path,
                    format!(
                        "recordings {} and {} have the same file stem {id:?}; a campaign names results by it",
                        prev.display(),
                        m.display()
                    ),
                ));
            }
            found.insert(id, m);
        }
    }
    Ok(found.into_iter().collect())
}

/// Matches the conditions table's rows to the recordings by file name.
fn with_conditions(
    campaign: &Path,
    table: &Path,
    template_path: &Path,
    truth: Option<&TruthSection>,
    recordings: Vec<(String, PathBuf)>,
) -> Result<(Vec<Entry>, Vec<String>)> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(table)
        .map_err(|e| csv_error(table, &e))?;
    let headers = reader.headers().map_err(|e| csv_error(table, &e))?.clone();
    let Some(key) = headers.iter().position(|h| h == "recording") else {
        return Err(Error::parse(
            table,
            1,
            0,
            "expected a column named 'recording' (the recording's file name)",
        ));
    };
    let label_columns: Vec<String> = headers
        .iter()
        .enumerate()
        .filter(|(i, h)| {
            *i != key
                && Override::from_column(h).is_none()
                && FileOverride::from_column(h).is_none()
        })
        .map(|(_, h)| h.to_string())
        .collect();
    if let Some(i) = headers
        .iter()
        .position(|h| h == FileOverride::TruthJson.column())
        && truth.is_none()
    {
        return Err(Error::parse(
            table,
            1,
            i + 1,
            format!(
                "column {}: the template {} has no [truth] section (json and keys) for the truth files to be read with",
                FileOverride::TruthJson.column(),
                template_path.display()
            ),
        ));
    }
    let files = Files { table, truth };
    let mut rows = BTreeMap::<String, Entry>::new();
    for record in reader.records() {
        let record = record.map_err(|e| csv_error(table, &e))?;
        let line = record.position().map_or(0, |p| p.line() as usize);
        let file_name = record.get(key).unwrap_or_default();
        let Some((id, recording)) = recordings.iter().find(|(_, p)| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy() == file_name)
        }) else {
            return Err(Error::parse(
                table,
                line,
                key + 1,
                format!(
                    "recording {file_name:?} is not among the campaign's recordings ({})",
                    campaign.display()
                ),
            ));
        };
        let entry = row_entry(&files, line, &headers, &record, key, id, recording)?;
        if rows.insert(id.clone(), entry).is_some() {
            return Err(Error::parse(
                table,
                line,
                key + 1,
                format!("recording {file_name:?} has a second row"),
            ));
        }
    }
    let mut entries = Vec::with_capacity(recordings.len());
    for (id, recording) in recordings {
        match rows.remove(&id) {
            Some(e) => entries.push(e),
            None => {
                return Err(Error::input(
                    table,
                    format!(
                        "recording {} has no row (add one with recording = {:?})",
                        recording.display(),
                        recording.file_name().unwrap_or_default()
                    ),
                ));
            }
        }
    }
    Ok((entries, label_columns))
}

/// What a conditions row's file cells are checked against: the table (paths are relative to its
/// directory) and the template's `[truth]` (whose keys a truth file must hold).
struct Files<'a> {
    table: &'a Path,
    truth: Option<&'a TruthSection>,
}

impl Files<'_> {
    /// The file `value` of column `which` (line `line`, 1-based column `column`) resolved against
    /// the table's directory, read and parsed as that column's kind of file.
    fn check(
        &self,
        which: FileOverride,
        line: usize,
        column: usize,
        value: &str,
    ) -> Result<PathBuf> {
        let table = self.table;
        let name = which.column();
        let dir = table.parent().unwrap_or(Path::new("."));
        let path = dir.join(value);
        let at = |message: String| Error::parse(table, line, column, message);
        let text = std::fs::read_to_string(&path).map_err(|e| {
            at(format!(
                "column {name}: cannot read {} ({e}; paths are relative to the table's directory)",
                path.display()
            ))
        })?;
        match which {
            FileOverride::BladeFile => {
                let blade: BladeParams = toml::from_str(&text).map_err(|e| {
                    at(format!(
                        "column {name}: {} is not a blade file: {}",
                        path.display(),
                        e.message().trim()
                    ))
                })?;
                blade
                    .validate()
                    .map_err(|e| at(format!("column {name}: {}: {e}", path.display())))?;
            }
            FileOverride::TruthJson => {
                let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
                    at(format!(
                        "column {name}: {} is not valid JSON: {e}",
                        path.display()
                    ))
                })?;
                for (k, ptr) in self.truth.map(|t| &t.keys).into_iter().flatten() {
                    // A number, or null for a parameter the true model lacks (job::TruthSection).
                    if json
                        .pointer(ptr)
                        .is_none_or(|v| !(v.is_f64() || v.is_i64() || v.is_u64() || v.is_null()))
                    {
                        return Err(at(format!(
                            "column {name}: {} has no number (or null) at JSON pointer {ptr} (the template's [truth] key for '{k}')",
                            path.display()
                        )));
                    }
                }
            }
        }
        absolute(&path)
    }
}

/// One conditions row as an entry: overrides parsed as positive finite numbers, file cells checked
/// ([`Files::check`]), the rest labels.
fn row_entry(
    files: &Files,
    line: usize,
    headers: &csv::StringRecord,
    record: &csv::StringRecord,
    key: usize,
    id: &str,
    recording: &Path,
) -> Result<Entry> {
    let table = files.table;
    let mut overrides = BTreeMap::new();
    let mut file_overrides = BTreeMap::new();
    let mut labels = Vec::new();
    for (i, (h, v)) in headers.iter().zip(record.iter()).enumerate() {
        if i == key {
            continue;
        }
        if let Some(f) = FileOverride::from_column(h) {
            // An empty cell keeps the template's file.
            if !v.is_empty() {
                file_overrides.insert(f, files.check(f, line, i + 1, v)?);
            }
            continue;
        }
        match Override::from_column(h) {
            Some(o) if v.is_empty() => {
                let _ = o; // an empty cell keeps the template's value
            }
            Some(o) => {
                let x: f64 = v
                    .parse()
                    .ok()
                    .filter(|x: &f64| x.is_finite())
                    .ok_or_else(|| {
                        Error::parse(
                            table,
                            line,
                            i + 1,
                            format!("column {h}: expected a number, found {v:?}"),
                        )
                    })?;
                if o != Override::T0S && x <= 0.0 {
                    return Err(Error::parse(
                        table,
                        line,
                        i + 1,
                        format!("column {h}: expected a positive number, found {x}"),
                    ));
                }
                overrides.insert(o, x);
            }
            None => labels.push((h.to_string(), v.to_string())),
        }
    }
    Ok(Entry {
        id: id.to_string(),
        recording: recording.to_path_buf(),
        overrides,
        files: file_overrides,
        labels,
    })
}

fn csv_error(table: &Path, e: &csv::Error) -> Error {
    match e.kind() {
        csv::ErrorKind::Io(_) => Error::input(table, format!("cannot read: {e}")),
        _ => {
            let line = e.position().map_or(0, |p| p.line() as usize);
            Error::parse(table, line, 0, e.to_string())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_of_an_offset() {
        let text = "a = 1\nbb = x\n";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 11), (2, 6));
    }

    #[test]
    fn campaign_names_must_be_plain_stems() {
        let p = Path::new("c.toml");
        assert!(check_plain_name(p, "speeds").is_ok());
        for bad in ["../x", "/abs", "a/b", ".hidden", "", ".."] {
            assert!(check_plain_name(p, bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn override_columns_round_trip() {
        for o in Override::ALL {
            assert_eq!(Override::from_column(o.column()), Some(o));
            assert_eq!(FileOverride::from_column(o.column()), None);
        }
        for f in FileOverride::ALL {
            assert_eq!(FileOverride::from_column(f.column()), Some(f));
            assert_eq!(Override::from_column(f.column()), None);
        }
        assert_eq!(Override::from_column("temperature_c"), None);
        assert_eq!(FileOverride::from_column("blade"), None);
    }
}
