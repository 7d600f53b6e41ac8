//! Importers: tracking-tool exports → [`Trace`] (SI units, physical y up, NaN = missing).
//!
//! Pixels, frame numbers, image y-down coordinates and tool-specific units end here; everything
//! downstream sees seconds and metres only (STYLE.md rule 2).
//!
//! Supported inputs (layouts described in `shared/realdata/FORMATS.md`):
//! * [`Format::Dltdv`] — DLTdv5–8 `*xypts.csv` (FORMATS.md §3): pixels, one row per frame, no time
//!   column; needs [`ImportSpec::fps_hz`] and [`ImportSpec::m_per_px`]. Reader: [`dltdv`].
//! * [`Format::Tracker`] — Open Source Physics Tracker "Export Data" / "Copy Data" text
//!   (FORMATS.md §1): a `t` column in seconds and calibrated x, y per track. Reader: [`tracker`].
//!
//! The canonical CSV that wiperlab itself writes and reads back is in [`canonical`].
//!
//! # Roles
//! The model needs two points, the blade **head** and the **lip tip**. [`ImportSpec::points`] maps a
//! role (`head`, `tip`, or any other name) to the name the file uses (`pt1`, `lip_tip`, …). The
//! returned [`Trace`] calls mapped points by their role and keeps the remaining points under their
//! own names (role-mapped points first: `head`, `tip`, then other roles alphabetically, then the
//! unmapped points in file order).
//!
//! # Example
//! ```
//! # fn main() -> wiperlab::Result<()> {
//! use wiperlab::import::{read_trace, Format, ImportSpec};
//! let path = std::env::temp_dir().join(format!("wiperlab_doc_{}_xypts.csv", std::process::id()));
//! std::fs::write(&path, "pt1_cam1_X,pt1_cam1_Y\n210.0,290.0\nNaN,NaN\n").unwrap();
//! let spec: ImportSpec = toml::from_str(
//!     "fps_hz = 1000.0\nm_per_px = 1e-4\norigin_px = [200.0, 300.0]\n[points]\nhead = \"pt1\"\n",
//! ).unwrap();
//! assert_eq!(Format::detect(&path)?, Format::Dltdv);
//! let trace = read_trace(&path, &spec)?;
//! let head = trace.point("head").unwrap();
//! assert_eq!(trace.t_s, [0.0, 1e-3]);
//! assert!((head.x_m[0] - 1e-3).abs() < 1e-15); // 10 px right of the origin
//! assert!((head.y_m[0] - 1e-3).abs() < 1e-15); // 10 px above it (image y is down)
//! assert!(head.x_m[1].is_nan()); // a dropped point stays NaN, never 0
//! # std::fs::remove_file(&path).ok();
//! # Ok(())
//! # }
//! ```

pub mod canonical;
pub mod dltdv;
pub mod tracker;

use std::collections::BTreeMap;
use std::fmt;
use std::io::Read;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::trace::{PointTrack, Trace};

/// The tracking-tool export layouts wiperlab reads. Serialised in lowercase (`"dltdv"`,
/// `"tracker"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// DLTdv `*xypts.csv` (FORMATS.md §3).
    Dltdv,
    /// Tracker data export (FORMATS.md §1).
    Tracker,
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Dltdv => "dltdv",
            Format::Tracker => "tracker",
        })
    }
}

/// How many bytes [`Format::detect`] reads from the start of a file.
const SNIFF_BYTES: u64 = 64 * 1024;

impl Format {
    /// Guess the format of `path` from its first lines (content, not the file name).
    ///
    /// * DLTdv: the first line's first comma-separated field is `pt{i}_cam{j}_X` or `_Y`.
    /// * Tracker: the first line is `#multi:`, or one of the first four non-blank lines is a column
    ///   row whose first field is `t` (subscripts like `t_{1}` allowed; TAB, `;`, `,` or space
    ///   delimited) — see [`tracker`] for the full layout.
    ///
    /// # Errors
    /// [`Error::Io`] if the file cannot be opened or read; [`Error::Input`] naming the file and
    /// quoting its first line if it looks like neither format.
    pub fn detect(path: &Path) -> Result<Format> {
        let file = std::fs::File::open(path).map_err(|e| Error::io(path, "open", e))?;
        let mut head = Vec::new();
        file.take(SNIFF_BYTES)
            .read_to_end(&mut head)
            .map_err(|e| Error::io(path, "read", e))?;
        let text = String::from_utf8_lossy(&head);
        Format::detect_text(&text).ok_or_else(|| {
            let first = text
                .trim_start_matches('\u{feff}')
                .lines()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("");
            let first: String = first.chars().take(80).collect();
            Error::input(
                path,
                format!(
                    "unknown tracking-file format: expected a DLTdv xypts header \
                     (pt1_cam1_X,pt1_cam1_Y,...) or a Tracker export (optional `#multi:` and \
                     track-name row, then a column row `t x y ...`); first line is {first:?}; \
                     set `format` in the import spec if the file is one of these"
                ),
            )
        })
    }

    /// Content sniffing on the start of a file; `None` when neither format matches.
    fn detect_text(text: &str) -> Option<Format> {
        let text = text.trim_start_matches('\u{feff}');
        let lines: Vec<&str> = text
            .lines()
            .map(|l| l.trim_end_matches('\r'))
            .filter(|l| !l.trim().is_empty())
            .take(6)
            .collect();
        let first = lines.first()?;
        if first.trim_start().starts_with("#multi") {
            return Some(Format::Tracker);
        }
        let f0 = first.split(',').next().unwrap_or("").trim();
        if dltdv::parse_header_name(f0).is_some() {
            return Some(Format::Dltdv);
        }
        if tracker::find_column_row(&lines).is_some() {
            return Some(Format::Tracker);
        }
        None
    }
}

/// How to read one tracking file: format, time base, scale, origin and point roles.
///
/// Meant to live in a TOML job or a sidecar next to the data (`deny_unknown_fields`, every field
/// optional). Defaults: see [`ImportSpec::default`]. Which fields apply to which format:
///
/// | field | DLTdv | Tracker |
/// |---|---|---|
/// | `fps_hz` | required: t = `t0_s` + (frame − 1)/`fps_hz` | optional check of the `t` column's median step (±1 %) |
/// | `m_per_px` | required | must be absent (Tracker is calibrated) |
/// | `origin_px` | subtracted from pixel coordinates | must be [0, 0] |
/// | `y_down` | default true: y_m = −(y_px − origin_y)·`m_per_px` | default false; true flips y |
/// | `units_to_m` | must be 1 | calibrated unit → m (cm: 0.01) |
/// | `camera` | which `cam{j}` columns | must be 1 |
/// | `decimal_comma` | must be false | `1,5` means 1.5 (not with a `,` delimiter) |
/// | `t0_s` | time of frame 1 | added to the `t` column |
///
/// ```toml
/// format = "dltdv"            # optional, detected from content when absent
/// fps_hz = 10000.0
/// m_per_px = 1.5e-5
/// origin_px = [200.0, 300.0]
/// [points]
/// head = "pt1"
/// tip = "pt2"
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ImportSpec {
    /// File layout; `None` = [`Format::detect`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub format: Option<Format>,
    /// Camera frame rate in Hz (frames per second), finite and > 0. Required for DLTdv (no time
    /// column); for Tracker only a consistency check of the time column.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fps_hz: Option<f64>,
    /// Image scale in metres per pixel, finite and > 0. Required for DLTdv; not allowed for Tracker.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub m_per_px: Option<f64>,
    /// Pixel coordinates `[x, y]` of the physical origin (DLTdv only), default `[0, 0]`.
    pub origin_px: [f64; 2],
    /// Whether the file's y axis points down. `None` = the format's convention: DLTdv `true`
    /// (image rows, origin top-left), Tracker `false` (world coordinates, y up).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub y_down: Option<bool>,
    /// Tracker only: metres per calibrated unit of the file (m: 1, cm: 0.01), finite and > 0;
    /// default 1.
    pub units_to_m: f64,
    /// DLTdv only: 1-based camera index `j` of the `pt{i}_cam{j}_*` columns to read; default 1.
    pub camera: usize,
    /// Time of the first frame in seconds (DLTdv), or offset added to Tracker's `t` column; default 0.
    pub t0_s: f64,
    /// Tracker only: the file writes decimal commas (`0,125`), usually with a `;` delimiter;
    /// default false.
    pub decimal_comma: bool,
    /// Role → point name in the file, e.g. `head = "pt1"`, `tip = "pt2"` (DLTdv) or
    /// `head = "head"`, `tip = "lip_tip"` (Tracker). Empty = keep the file's names.
    pub points: BTreeMap<String, String>,
}

impl Default for ImportSpec {
    /// No format (detect), no fps, no scale, origin `[0, 0]`, format's y convention, units 1 m,
    /// camera 1, t0 0 s, decimal point, no roles.
    fn default() -> Self {
        ImportSpec {
            format: None,
            fps_hz: None,
            m_per_px: None,
            origin_px: [0.0, 0.0],
            y_down: None,
            units_to_m: 1.0,
            camera: 1,
            t0_s: 0.0,
            decimal_comma: false,
            points: BTreeMap::new(),
        }
    }
}

impl ImportSpec {
    /// Check the settings that do not depend on the file: ranges, and fields that make no sense for
    /// `format` (e.g. a pixel scale for a calibrated Tracker file).
    ///
    /// # Errors
    /// [`Error::Config`] naming the field and the allowed range.
    pub fn validate(&self, format: Format) -> Result<()> {
        fn positive(name: &str, v: f64) -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::Config(format!(
                    "import: {name} must be finite and > 0, got {v}"
                )))
            }
        }
        if let Some(fps) = self.fps_hz {
            positive("fps_hz", fps)?;
        }
        if let Some(s) = self.m_per_px {
            positive("m_per_px", s)?;
        }
        positive("units_to_m", self.units_to_m)?;
        if !self.origin_px.iter().all(|v| v.is_finite()) {
            return Err(Error::Config(format!(
                "import: origin_px must be finite, got {:?}",
                self.origin_px
            )));
        }
        if !self.t0_s.is_finite() {
            return Err(Error::Config(format!(
                "import: t0_s must be finite, got {}",
                self.t0_s
            )));
        }
        let mut seen: BTreeMap<&str, &str> = BTreeMap::new();
        for (role, name) in &self.points {
            if role.trim().is_empty() || name.trim().is_empty() {
                return Err(Error::Config(format!(
                    "import: points: role and point name must not be empty (got {role:?} = {name:?})"
                )));
            }
            if let Some(other) = seen.insert(name, role) {
                return Err(Error::Config(format!(
                    "import: points: roles {other:?} and {role:?} both map to point {name:?}"
                )));
            }
        }
        let not_for = |field: &str, hint: &str| {
            Err(Error::Config(format!(
                "import: {field} does not apply to {format} files; {hint}"
            )))
        };
        match format {
            Format::Dltdv => {
                if self.camera == 0 {
                    return Err(Error::Config(
                        "import: camera is 1-based (cam1, cam2, ...), got 0".into(),
                    ));
                }
                if self.units_to_m != 1.0 {
                    return not_for("units_to_m", "DLTdv is in pixels: set m_per_px");
                }
                if self.decimal_comma {
                    return not_for("decimal_comma", "DLTdv always writes a decimal point");
                }
            }
            Format::Tracker => {
                if self.m_per_px.is_some() {
                    return not_for(
                        "m_per_px",
                        "Tracker writes calibrated units: set units_to_m (1 for m, 0.01 for cm)",
                    );
                }
                if self.origin_px != [0.0, 0.0] {
                    return not_for("origin_px", "Tracker coordinates are already calibrated");
                }
                if self.camera != 1 {
                    return not_for("camera", "a Tracker export holds one video");
                }
            }
        }
        Ok(())
    }
}

/// Read a tracking export into a [`Trace`] in SI units with roles assigned.
///
/// Steps: format from `spec.format` or [`Format::detect`]; [`ImportSpec::validate`]; the format's
/// reader ([`dltdv::read`] or [`tracker::read`]); then roles from [`ImportSpec::points`] (see the
/// module docs). Returns N ≥ 1 samples, `t_s` strictly increasing, every point with N samples,
/// positions in metres with y up, NaN where a point was not tracked.
///
/// # Errors
/// * [`Error::Io`] — the file cannot be opened/read (names the file);
/// * [`Error::Parse`] — a bad cell or header (`file:line:column: field ...: expected ..., found ...`);
/// * [`Error::Input`] — unknown format, no data rows, DLTdv without `fps_hz`/`m_per_px`, a mapped
///   point that is not in the file (the message lists the points that are);
/// * [`Error::Config`] — a setting out of range or not applicable to the format.
pub fn read_trace(path: &Path, spec: &ImportSpec) -> Result<Trace> {
    read_trace_with_summary(path, spec).map(|(trace, _)| trace)
}

/// [`read_trace`], plus the [`ImportSummary`] of the result (with the format filled in).
///
/// # Errors
/// As [`read_trace`].
pub fn read_trace_with_summary(path: &Path, spec: &ImportSpec) -> Result<(Trace, ImportSummary)> {
    let format = match spec.format {
        Some(f) => f,
        None => Format::detect(path)?,
    };
    spec.validate(format)?;
    let raw = match format {
        Format::Dltdv => dltdv::read(path, spec)?,
        Format::Tracker => tracker::read(path, spec)?,
    };
    let trace = assign_roles(path, raw, &spec.points)?;
    // The readers guarantee this; checked once more because t0_s is added to every time.
    trace
        .check()
        .map_err(|m| Error::input(path, format!("imported trace is inconsistent: {m}")))?;
    let mut summary = describe(&trace);
    summary.format = Some(format);
    Ok((trace, summary))
}

/// Conventional role order: these first, then other roles alphabetically.
const ROLE_ORDER: [&str; 2] = ["head", "tip"];

/// Rename mapped points to their roles and order them (see the module docs).
fn assign_roles(path: &Path, trace: Trace, roles: &BTreeMap<String, String>) -> Result<Trace> {
    if roles.is_empty() {
        return Ok(trace);
    }
    let Trace { t_s, points } = trace;
    let mut slots: Vec<Option<PointTrack>> = points.into_iter().map(Some).collect();
    let available = slots
        .iter()
        .flatten()
        .map(|p| p.name.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    let mut ordered: Vec<(&String, &String)> = roles.iter().collect();
    ordered.sort_by_key(|(role, _)| {
        let rank = ROLE_ORDER
            .iter()
            .position(|r| *r == role.as_str())
            .unwrap_or(ROLE_ORDER.len());
        (rank, role.as_str())
    });
    let mut out = Vec::with_capacity(slots.len());
    for (role, name) in ordered {
        let Some(i) = slots
            .iter()
            .position(|p| p.as_ref().is_some_and(|p| &p.name == name))
        else {
            return Err(Error::input(
                path,
                format!(
                    "point {name:?} (mapped to role {role:?}) is not in the file; points in the \
                     file: {}",
                    available
                ),
            ));
        };
        if let Some(mut p) = slots[i].take() {
            p.name = role.clone();
            out.push(p);
        }
    }
    for p in slots.into_iter().flatten() {
        if roles.contains_key(&p.name) {
            return Err(Error::input(
                path,
                format!(
                    "the file has an unmapped point named {:?}, which is also a role name \
                     (mapped to {:?}); map that point to a role too",
                    p.name, roles[&p.name]
                ),
            ));
        }
        out.push(p);
    }
    Ok(Trace { t_s, points: out })
}

/// What an import produced: sizes, time axis, missing samples per point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImportSummary {
    /// The format read, when known (set by [`read_trace_with_summary`], `None` from [`describe`]).
    pub format: Option<Format>,
    /// Number of time samples (frames).
    pub n_frames: usize,
    /// `(point name, NaN samples)` in trace order; a sample counts as NaN when x or y is NaN.
    pub points: Vec<(String, usize)>,
    /// First sample time in s (NaN for an empty trace).
    pub t_first_s: f64,
    /// Last sample time in s (NaN for an empty trace).
    pub t_last_s: f64,
    /// Median time step in s (NaN with fewer than 2 samples).
    pub dt_median_s: f64,
    /// Smallest time step in s (NaN with fewer than 2 samples).
    pub dt_min_s: f64,
    /// Largest time step in s (NaN with fewer than 2 samples).
    pub dt_max_s: f64,
}

impl ImportSummary {
    /// Frame rate implied by the median step, 1/`dt_median_s` in Hz (NaN if unknown).
    pub fn fps_median_hz(&self) -> f64 {
        1.0 / self.dt_median_s
    }
}

/// Summarise a trace: frame count, time range and steps, NaN samples per point. Never fails; an
/// empty trace gives NaN times.
pub fn describe(trace: &Trace) -> ImportSummary {
    let t = &trace.t_s;
    let mut dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    dt.sort_by(f64::total_cmp);
    let dt_median_s = match dt.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => dt[n / 2],
        n => 0.5 * (dt[n / 2 - 1] + dt[n / 2]),
    };
    ImportSummary {
        format: None,
        n_frames: t.len(),
        points: trace
            .points
            .iter()
            .map(|p| (p.name.clone(), p.nan_samples()))
            .collect(),
        t_first_s: t.first().copied().unwrap_or(f64::NAN),
        t_last_s: t.last().copied().unwrap_or(f64::NAN),
        dt_median_s,
        dt_min_s: dt.first().copied().unwrap_or(f64::NAN),
        dt_max_s: dt.last().copied().unwrap_or(f64::NAN),
    }
}

impl fmt::Display for ImportSummary {
    /// A header line (format, frames, time range, steps), then one line per point.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(format) = self.format {
            write!(f, "{format}: ")?;
        }
        writeln!(
            f,
            "{} frames, t = {} … {} s, dt median {} s ({:.6} fps), min {} s, max {} s",
            self.n_frames,
            self.t_first_s,
            self.t_last_s,
            self.dt_median_s,
            self.fps_median_hz(),
            self.dt_min_s,
            self.dt_max_s
        )?;
        for (name, nan) in &self.points {
            let pct = if self.n_frames > 0 {
                100.0 * *nan as f64 / self.n_frames as f64
            } else {
                0.0
            };
            writeln!(
                f,
                "  {name}: {} tracked, {nan} NaN ({pct:.2} %)",
                self.n_frames - nan
            )?;
        }
        Ok(())
    }
}

/// Read a whole file as text: BOM removed, invalid UTF-8 replaced (only names can be non-ASCII).
pub(crate) fn read_text(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, "read", e))?;
    let text = match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    };
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_owned(),
        None => text,
    })
}

/// Parse a finite decimal number (`1.5`, `-3.4E-6`, `.5`); `None` for anything else, including
/// `inf` and `NaN` (callers decide what text means "missing").
pub(crate) fn parse_finite(s: &str) -> Option<f64> {
    let s = s.trim();
    // Rust also accepts "inf", "infinity", "nan": only digits, sign, point and exponent are numbers.
    if s.is_empty()
        || !s
            .bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E'))
    {
        return None;
    }
    s.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Quote a cell for an error message, shortened to 40 characters.
pub(crate) fn quote_cell(s: &str) -> String {
    if s.chars().count() > 40 {
        let short: String = s.chars().take(40).collect();
        format!("{:?}…", short)
    } else {
        format!("{s:?}")
    }
}

/// Turns a `csv` crate error into ours: I/O errors name `action`, others give the line (and the
/// field for invalid UTF-8).
pub(crate) fn csv_error(path: &Path, action: &'static str, e: csv::Error) -> Error {
    let line = e.position().map_or(0, |p| p.line() as usize);
    match e.into_kind() {
        csv::ErrorKind::Io(io) => Error::io(path, action, io),
        csv::ErrorKind::Utf8 { err, .. } => Error::parse(
            path,
            line,
            err.field() + 1,
            format!("invalid UTF-8 in field {}", err.field() + 1),
        ),
        other => Error::parse(path, line, 0, format!("{other:?}")),
    }
}

/// The 1-based file line of a data record (`fallback_line` when the reader does not know it),
/// after checking that it has `n_fields` fields like the header.
pub(crate) fn record_line(
    path: &Path,
    record: &csv::StringRecord,
    fallback_line: usize,
    n_fields: usize,
) -> Result<usize> {
    let line = record
        .position()
        .map_or(fallback_line, |p| p.line() as usize);
    if record.len() != n_fields {
        return Err(Error::parse(
            path,
            line,
            0,
            format!(
                "expected {n_fields} fields like the header, found {}",
                record.len()
            ),
        ));
    }
    Ok(line)
}

/// A file in the temp directory that removes itself, for the readers' unit tests.
#[cfg(test)]
pub(crate) struct TempFile(pub std::path::PathBuf);

#[cfg(test)]
impl TempFile {
    /// `wiperlab_<pid>_<file_name>` in the temp directory, not yet written.
    pub(crate) fn at(file_name: &str) -> TempFile {
        TempFile(std::env::temp_dir().join(format!("wiperlab_{}_{file_name}", std::process::id())))
    }

    /// The same, written with `content`.
    pub(crate) fn new(file_name: &str, content: &str) -> TempFile {
        let f = TempFile::at(file_name);
        std::fs::write(&f.0, content).expect("write temp file");
        f
    }
}

#[cfg(test)]
impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(name: &str) -> PointTrack {
        PointTrack {
            name: name.into(),
            x_m: vec![1.0],
            y_m: vec![f64::NAN],
        }
    }

    fn trace(names: &[&str]) -> Trace {
        Trace {
            t_s: vec![0.0],
            points: names.iter().map(|n| point(n)).collect(),
        }
    }

    fn roles(pairs: &[(&str, &str)]) -> BTreeMap<String, String> {
        pairs
            .iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect()
    }

    #[test]
    fn detect_text_recognises_both_layouts() {
        assert_eq!(
            Format::detect_text("pt1_cam1_X,pt1_cam1_Y\n1,2\n"),
            Some(Format::Dltdv)
        );
        assert_eq!(
            Format::detect_text("#multi:\r\n\thead\t\t\r\nt\tx\ty\t\r\n"),
            Some(Format::Tracker)
        );
        assert_eq!(
            Format::detect_text("mass_B\r\nt\tx\ty\tfunc\r\n0.0\t1\t2\t3\r\n"),
            Some(Format::Tracker)
        );
        assert_eq!(
            Format::detect_text("\u{feff}t_{1};x_{1};y_{1}\n0,0;1,5;2\n"),
            Some(Format::Tracker)
        );
        assert_eq!(Format::detect_text("t x y\n0 1 2\n"), Some(Format::Tracker));
        assert_eq!(Format::detect_text("time,x,y\n0,1,2\n"), None);
        assert_eq!(Format::detect_text(""), None);
    }

    #[test]
    fn defaults_and_toml() {
        let spec: ImportSpec = toml::from_str("").unwrap();
        assert_eq!(spec, ImportSpec::default());
        assert_eq!(spec.units_to_m, 1.0);
        assert_eq!(spec.camera, 1);
        let spec: ImportSpec = toml::from_str(
            "format = \"tracker\"\nunits_to_m = 0.01\n[points]\nhead = \"mass A\"\n",
        )
        .unwrap();
        assert_eq!(spec.format, Some(Format::Tracker));
        assert_eq!(spec.points["head"], "mass A");
        let err = toml::from_str::<ImportSpec>("fps = 10.0\n").unwrap_err();
        assert!(err.to_string().contains("unknown field"), "{err}");
        let err = toml::from_str::<ImportSpec>("format = \"kinovea\"\n").unwrap_err();
        assert!(err.to_string().contains("unknown variant"), "{err}");
        // Serialise → deserialise is the identity (resolved configs are written beside artefacts).
        let spec = ImportSpec {
            fps_hz: Some(48.0),
            m_per_px: Some(1.0),
            ..ImportSpec::default()
        };
        let back: ImportSpec = toml::from_str(&toml::to_string(&spec).unwrap()).unwrap();
        assert_eq!(back, spec);
    }

    #[test]
    fn validate_rejects_bad_settings() {
        let bad = |spec: ImportSpec, format, needle: &str| {
            let msg = spec.validate(format).unwrap_err().to_string();
            assert!(msg.contains(needle), "{msg:?} lacks {needle:?}");
        };
        let base = ImportSpec::default();
        bad(
            ImportSpec {
                fps_hz: Some(0.0),
                ..base.clone()
            },
            Format::Dltdv,
            "fps_hz must be finite and > 0",
        );
        bad(
            ImportSpec {
                m_per_px: Some(f64::NAN),
                ..base.clone()
            },
            Format::Dltdv,
            "m_per_px",
        );
        bad(
            ImportSpec {
                units_to_m: -1.0,
                ..base.clone()
            },
            Format::Tracker,
            "units_to_m",
        );
        bad(
            ImportSpec {
                m_per_px: Some(1e-5),
                ..base.clone()
            },
            Format::Tracker,
            "units_to_m",
        );
        bad(
            ImportSpec {
                camera: 0,
                ..base.clone()
            },
            Format::Dltdv,
            "1-based",
        );
        bad(
            ImportSpec {
                points: roles(&[("head", "pt1"), ("tip", "pt1")]),
                ..base.clone()
            },
            Format::Dltdv,
            "both map to point \"pt1\"",
        );
        assert!(base.validate(Format::Tracker).is_ok());
    }

    #[test]
    fn roles_rename_and_order() {
        let t = assign_roles(
            Path::new("f"),
            trace(&["a", "lip_tip", "b", "head_pt"]),
            &roles(&[("tip", "lip_tip"), ("head", "head_pt")]),
        )
        .unwrap();
        let names: Vec<_> = t.points.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["head", "tip", "a", "b"]);
    }

    #[test]
    fn unknown_point_lists_available() {
        let err = assign_roles(
            Path::new("f.csv"),
            trace(&["pt1", "pt2"]),
            &roles(&[("head", "pt1"), ("tip", "pt9")]),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("\"pt9\""), "{err}");
        assert!(err.contains("points in the file: pt1, pt2"), "{err}");
    }

    #[test]
    fn role_name_clash_is_an_error() {
        let err = assign_roles(
            Path::new("f"),
            trace(&["tip", "pt2"]),
            &roles(&[("tip", "pt2")]),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("also a role name"), "{err}");
    }

    #[test]
    fn numbers() {
        assert_eq!(
            parse_finite(" -3.401361196808672E-6 "),
            Some(-3.401361196808672E-6)
        );
        assert_eq!(parse_finite("1.000000E0"), Some(1.0));
        assert_eq!(parse_finite(".5"), Some(0.5));
        for bad in ["", "inf", "NaN", "1,5", "abc", "1e400", "--1", "0x10"] {
            assert_eq!(parse_finite(bad), None, "{bad}");
        }
    }

    #[test]
    fn describe_counts_and_steps() {
        let t = Trace {
            t_s: vec![0.0, 0.1, 0.2, 0.4],
            points: vec![PointTrack {
                name: "head".into(),
                x_m: vec![0.0, f64::NAN, 1.0, 1.0],
                y_m: vec![0.0, f64::NAN, f64::NAN, 1.0],
            }],
        };
        let s = describe(&t);
        assert_eq!(s.n_frames, 4);
        assert_eq!(s.points, vec![("head".to_string(), 2)]);
        assert_eq!(s.t_last_s, 0.4);
        assert!((s.dt_median_s - 0.1).abs() < 1e-12);
        let text = s.to_string();
        assert_eq!(text.lines().count(), 2, "{text}");
        assert!(text.contains("head: 2 tracked, 2 NaN (50.00 %)"), "{text}");
        let empty = describe(&Trace::default());
        assert!(empty.t_first_s.is_nan() && empty.dt_median_s.is_nan());
    }
}
