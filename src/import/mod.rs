//! Importers: tracking-tool exports → [`Trace`] (SI units, physical y up, NaN = missing).
//!
//! Pixels, frame numbers, image y-down coordinates and tool-specific units end here; everything
//! downstream sees seconds and metres only (STYLE.md rule 2).
//!
//! Supported inputs (layouts described in `shared/realdata/FORMATS.md`):
//! * [`Format::Dltdv`] — DLTdv5–8 `*xypts.csv` (FORMATS.md §3): pixels, one row per frame, no time
//!   column; needs [`ImportSpec::fps_hz`] and [`ImportSpec::m_per_px`]. Reader: [`dltdv`].
//!   [`Format::DltdvSparse`] — the sparse `*xypts.tsv` save: [`dltdv_sparse`].
//! * [`Format::Tracker`] — Open Source Physics Tracker "Export Data" / "Copy Data" text
//!   (FORMATS.md §1): a `t` column in seconds and calibrated x, y per track. Reader: [`tracker`].
//! * [`Format::KinoveaCsv`], [`Format::KinoveaTxt`], [`Format::KinoveaKinematics`] — Kinovea
//!   trajectory CSV/TXT and kinematics CSV (§2): [`kinovea`].
//! * [`Format::Deeplabcut`] (§4): [`deeplabcut`]; [`Format::Sleap`] (§5): [`sleap`];
//!   [`Format::Trackmate`] (§6): [`trackmate`].
//! * [`Format::Generic`] — any delimited table or JSON row array with user-mapped columns:
//!   [`generic`].
//!
//! The readers other than DLTdv and Tracker return a [`common::RawTrace`] in file units;
//! [`common::calibrate`] applies the time base (file times, or frame / `fps_hz`), the scale
//! (`m_per_px`, two scale points, or `units_to_m`), origin and y flip in one place. Then every
//! format gets roles ([`ImportSpec::points`]) and the optional rotation to the sweep
//! (`sweep_angle_deg` / `sweep_from_head`). Text is UTF-8, or Windows-1252 when not UTF-8
//! ([`common::decode`]).
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
//! use wiperlab::trace::Role;
//! let path = std::env::temp_dir().join(format!("wiperlab_doc_{}_xypts.csv", std::process::id()));
//! std::fs::write(&path, "pt1_cam1_X,pt1_cam1_Y\n210.0,290.0\nNaN,NaN\n").unwrap();
//! let spec: ImportSpec = toml::from_str(
//!     "fps_hz = 1000.0\nm_per_px = 1e-4\norigin_px = [200.0, 300.0]\n[points]\nhead = \"pt1\"\n",
//! ).unwrap();
//! assert_eq!(Format::detect(&path)?, Format::Dltdv);
//! let trace = read_trace(&path, &spec)?;
//! let head = trace.role(Role::Head).unwrap();
//! assert_eq!(trace.t_s, [0.0, 1e-3]);
//! assert!((head.x_m[0] - 1e-3).abs() < 1e-15); // 10 px right of the origin
//! assert!((head.y_m[0] - 1e-3).abs() < 1e-15); // 10 px above it (image y is down)
//! assert!(head.x_m[1].is_nan()); // a dropped point stays NaN, never 0
//! # std::fs::remove_file(&path).ok();
//! # Ok(())
//! # }
//! ```

pub mod canonical;
pub mod common;
pub mod deeplabcut;
pub mod dltdv;
pub mod dltdv_sparse;
mod error;
pub mod generic;
pub mod kinovea;
pub mod sleap;
pub mod tracker;
pub mod trackmate;

use std::collections::BTreeMap;
use std::fmt;
use std::io::Read;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::names::significant;
use crate::trace::{PointTrack, Role, Trace};
pub use error::ImportError;

/// The tracking-tool export layouts wiperlab reads. Serialised in kebab case (`"dltdv"`,
/// `"tracker"`, `"kinovea-csv"`, ...), the same names `--format` takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Format {
    /// DLTdv `*xypts.csv` (FORMATS.md §3).
    Dltdv,
    /// DLTdv sparse `*xypts.tsv` (FORMATS.md §3).
    DltdvSparse,
    /// Tracker data export (FORMATS.md §1).
    Tracker,
    /// Kinovea trajectory CSV, quoted cells (FORMATS.md §2a).
    KinoveaCsv,
    /// Kinovea trajectory TXT ("Gnuplot"), one section per object (FORMATS.md §2b).
    KinoveaTxt,
    /// Kinovea kinematics-dialog CSV, time in ms (FORMATS.md §2c).
    KinoveaKinematics,
    /// DeepLabCut single- or multi-animal prediction CSV (FORMATS.md §4).
    Deeplabcut,
    /// SLEAP analysis CSV, one row per instance (FORMATS.md §5).
    Sleap,
    /// TrackMate spot table, ≤ 6 (one header line) or ≥ 7 (up to four header lines) (FORMATS.md §6).
    Trackmate,
    /// Any delimited table with the columns mapped in [`ImportSpec::generic`].
    Generic,
    /// wiperlab's own canonical trace CSV (`t_s,<name>_x_m,<name>_y_m,...`, seconds and metres,
    /// y up), as `wiperlab import` writes it. Reader: [`canonical::read_trace_csv`].
    Canonical,
}

impl Format {
    /// Every format, in the order `--format` lists them.
    pub const ALL: [Format; 11] = [
        Format::Dltdv,
        Format::DltdvSparse,
        Format::Tracker,
        Format::KinoveaCsv,
        Format::KinoveaTxt,
        Format::KinoveaKinematics,
        Format::Deeplabcut,
        Format::Sleap,
        Format::Trackmate,
        Format::Generic,
        Format::Canonical,
    ];

    /// The kebab-case name (`"kinovea-csv"`).
    pub fn name(self) -> &'static str {
        match self {
            Format::Dltdv => "dltdv",
            Format::DltdvSparse => "dltdv-sparse",
            Format::Tracker => "tracker",
            Format::KinoveaCsv => "kinovea-csv",
            Format::KinoveaTxt => "kinovea-txt",
            Format::KinoveaKinematics => "kinovea-kinematics",
            Format::Deeplabcut => "deeplabcut",
            Format::Sleap => "sleap",
            Format::Trackmate => "trackmate",
            Format::Generic => "generic",
            Format::Canonical => "canonical",
        }
    }

    /// The format called `name` ([`Format::name`]), if any.
    pub fn from_name(name: &str) -> Option<Format> {
        Format::ALL.into_iter().find(|f| f.name() == name)
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How many bytes [`Format::detect`] reads from the start of a file.
const SNIFF_BYTES: u64 = 64 * 1024;

impl Format {
    /// Guess the format of `path` from its first lines (content, not the file name).
    ///
    /// * DLTdv: the first line's first comma-separated field is `pt{i}_cam{j}_X` or `_Y`; DLTdv
    ///   sparse: the first line starts with `Sparse format`.
    /// * Tracker: the first line is `#multi:`, or one of the first four non-blank lines is a column
    ///   row whose first field is `t` (subscripts like `t_{1}` allowed; TAB, `;`, `,` or space
    ///   delimited) — see [`tracker`] for the full layout.
    /// * Kinovea: TXT starts `#Kinovea Trajectory`; trajectory CSV starts with the quoted cell
    ///   `"Time"`; kinematics CSV starts with `Time (ms)`.
    /// * DeepLabCut: first line starts with `scorer`; SLEAP: the header has `frame_idx` and a
    ///   `.x` column; TrackMate: first field `Label`/`LABEL` and a `POSITION_X` column.
    /// * Canonical trace CSV: the first field is `t_s` and the next one ends in `_x_m`.
    /// * [`Format::Generic`] is never detected: it needs [`ImportSpec::generic`].
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
                    "unknown tracking-file format; first line is {first:?}: expected a DLTdv \
                     xypts header (pt1_cam1_X,...), a DLTdv sparse file, a Tracker export (column \
                     row `t x y ...`), a Kinovea export, a DeepLabCut CSV (`scorer,...`), a SLEAP \
                     analysis CSV (`track,frame_idx,...`) or a TrackMate spot table \
                     (`LABEL,...,POSITION_X,...`) or a canonical trace CSV (`t_s,head_x_m,...`); \
                     for any other table set format = \"generic\" \
                     and map its columns ([generic] in the import spec)"
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
        if first.starts_with("Sparse format") {
            return Some(Format::DltdvSparse);
        }
        if first.starts_with("#Kinovea Trajectory") {
            return Some(Format::KinoveaTxt);
        }
        if first.starts_with("\"Time\"") {
            return Some(Format::KinoveaCsv);
        }
        if first.starts_with("Time (ms)") {
            return Some(Format::KinoveaKinematics);
        }
        if f0 == "t_s"
            && first
                .split(',')
                .nth(1)
                .is_some_and(|c| c.trim().ends_with("_x_m"))
        {
            return Some(Format::Canonical);
        }
        if f0 == "scorer" {
            return Some(Format::Deeplabcut);
        }
        let header: Vec<&str> = first.split(',').map(str::trim).collect();
        if header.contains(&"frame_idx") && header.iter().any(|h| h.ends_with(".x")) {
            return Some(Format::Sleap);
        }
        if (f0 == "Label" || f0 == "LABEL") && header.contains(&"POSITION_X") {
            return Some(Format::Trackmate);
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
/// | field | DLTdv (csv, sparse) | Tracker | other formats |
/// |---|---|---|---|
/// | `fps_hz` | required: t = `t0_s` + (frame − 1)/`fps_hz` | optional check of the `t` column's median step (±1 %) | required where the file has frame numbers only (DeepLabCut, SLEAP, TrackMate without a time unit, generic `frame`) |
/// | `m_per_px` or `scale_points_px` + `scale_distance_m` | required | must be absent (Tracker is calibrated) | required for pixels; alternative to `units_to_m` when the file does not state its unit |
/// | `origin_px` | subtracted from pixel coordinates | must be [0, 0] | subtracted in file units |
/// | `y_down` | default true: y_m = −(y_px − origin_y)·`m_per_px` | default false; true flips y | default: true for DeepLabCut, SLEAP, TrackMate (image rows), false otherwise |
/// | `units_to_m` | must be absent | calibrated unit → m (default 1; cm: 0.01) | required for Kinovea, TrackMate ≤ 6, generic unless `m_per_px`; overrides TrackMate's unit row |
/// | `camera`, `n_cameras` | which `cam{j}` columns; sparse: cameras in the file | must be 1 | must be 1 |
/// | `decimal_comma` | must be false | `1,5` means 1.5 (not with a `,` delimiter) | generic only (Kinovea detects it) |
/// | `t0_s` | time of frame 1 | added to the `t` column | added to every time |
/// | `time_to_s` | — | — | Kinovea CSV (required: unit not in the file), generic time column |
/// | `min_likelihood` | — | — | DeepLabCut, SLEAP: below it → NaN (default 0.6) |
/// | `sweep_angle_deg` / `sweep_from_head` | rotation so x runs along the sweep, every format | | |
/// | `generic` | — | — | the column mapping of [`Format::Generic`] |
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
    /// Metres per calibrated unit of the file (m: 1, cm: 0.01), finite and > 0. Tracker: default
    /// 1 (the unit the user calibrated in). Kinovea, TrackMate ≤ 6 and generic tables do not state
    /// whether they are in pixels or a calibrated unit: set this or `m_per_px`. Overrides a unit
    /// the file states (TrackMate ≥ 7 unit row).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub units_to_m: Option<f64>,
    /// Two image points `[[x1, y1], [x2, y2]]` (pixels) a known distance `scale_distance_m` apart:
    /// m_per_px = distance / |p2 − p1|. Alternative to `m_per_px`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scale_points_px: Option<[[f64; 2]; 2]>,
    /// Distance in metres between `scale_points_px`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scale_distance_m: Option<f64>,
    /// Rotate the trace so that x runs along the sweep: the sweep direction's angle in degrees,
    /// counter-clockwise from the physical +x axis (after the y flip). Every point is rotated by
    /// −angle about the origin.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sweep_angle_deg: Option<f64>,
    /// Estimate the sweep angle from the head's own motion (principal axis of its positions; the
    /// point with role `head`, else the first point) and rotate by it; the angle is reported.
    /// Not together with `sweep_angle_deg`. Default false.
    pub sweep_from_head: bool,
    /// Seconds per unit of the file's time column where the file does not say (Kinovea trajectory
    /// CSV, generic tables; 0.001 for ms). Default: the unit in the header (`Time (ms)`), else an
    /// error for Kinovea CSV and seconds for generic tables.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_to_s: Option<f64>,
    /// DeepLabCut / SLEAP: points with a likelihood (score) below this become NaN gaps. Default
    /// 0.6, DeepLabCut's default `pcutoff` (config.yaml); 0 keeps every point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_likelihood: Option<f64>,
    /// DLTdv sparse only: number of cameras the file's columns cover (the sparse file has no
    /// header to tell); default 1.
    pub n_cameras: usize,
    /// Column mapping of a generic delimited table ([`Format::Generic`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub generic: Option<generic::GenericColumns>,
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
    /// No format (detect), no fps, no scale, origin `[0, 0]`, format's y convention, no unit
    /// factor, no rotation, camera 1 of 1, t0 0 s, decimal point, likelihood cut-off 0.6, no roles.
    fn default() -> Self {
        ImportSpec {
            format: None,
            fps_hz: None,
            m_per_px: None,
            origin_px: [0.0, 0.0],
            y_down: None,
            units_to_m: None,
            scale_points_px: None,
            scale_distance_m: None,
            sweep_angle_deg: None,
            sweep_from_head: false,
            time_to_s: None,
            min_likelihood: None,
            n_cameras: 1,
            generic: None,
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
    /// [`ImportError`] naming the field and the allowed range.
    pub fn validate(&self, format: Format) -> Result<()> {
        self.check_ranges(format)?;
        self.check_points()?;
        self.check_format(format)?;
        if self.generic.is_some() && format != Format::Generic {
            return Err(not_for(
                "generic",
                format,
                "set format = \"generic\" to use a column mapping",
            ));
        }
        Ok(())
    }

    /// Ranges of the numeric settings, and the settings that exclude each other.
    fn check_ranges(&self, format: Format) -> Result<()> {
        for (field, v) in [
            ("fps_hz", self.fps_hz),
            ("m_per_px", self.m_per_px),
            ("units_to_m", self.units_to_m),
            ("time_to_s", self.time_to_s),
            ("scale_distance_m", self.scale_distance_m),
        ] {
            if let Some(value) = v
                && !(value.is_finite() && value > 0.0)
            {
                return Err(ImportError::NotPositive { field, value }.into());
            }
        }
        if let Some(value) = self.sweep_angle_deg {
            if !value.is_finite() {
                let field = "sweep_angle_deg";
                return Err(ImportError::NotFinite { field, value }.into());
            }
            if self.sweep_from_head {
                let (first, second) = ("sweep_angle_deg", "sweep_from_head");
                return Err(ImportError::Exclusive { first, second }.into());
            }
        }
        if let Some(value) = self.min_likelihood
            && !(0.0..=1.0).contains(&value)
        {
            return Err(ImportError::MinLikelihood { value }.into());
        }
        if self.n_cameras == 0 || (self.camera > self.n_cameras && format == Format::DltdvSparse) {
            return Err(ImportError::Cameras {
                n_cameras: self.n_cameras,
                camera: self.camera,
            }
            .into());
        }
        self.resolved_m_per_px()?;
        if !self.origin_px.iter().all(|v| v.is_finite()) {
            let origin_px = self.origin_px;
            return Err(ImportError::OriginNotFinite { origin_px }.into());
        }
        if !self.t0_s.is_finite() {
            let (field, value) = ("t0_s", self.t0_s);
            return Err(ImportError::NotFinite { field, value }.into());
        }
        Ok(())
    }

    /// Roles and point names: none empty, no point under two roles.
    fn check_points(&self) -> Result<()> {
        let mut seen: BTreeMap<&str, &str> = BTreeMap::new();
        for (role, name) in &self.points {
            if role.trim().is_empty() || name.trim().is_empty() {
                return Err(ImportError::EmptyRole {
                    role: role.clone(),
                    point: name.clone(),
                }
                .into());
            }
            if let Some(other) = seen.insert(name, role) {
                return Err(ImportError::SharedPoint {
                    first: other.to_string(),
                    second: role.clone(),
                    point: name.clone(),
                }
                .into());
            }
        }
        Ok(())
    }

    /// Settings that make no sense for `format`.
    fn check_format(&self, format: Format) -> Result<()> {
        let reject = |field, hint| Err(not_for(field, format, hint));
        match format {
            Format::Dltdv | Format::DltdvSparse => {
                if self.camera == 0 {
                    return Err(ImportError::CameraZero.into());
                }
                if self.units_to_m.is_some() {
                    return reject("units_to_m", "DLTdv is in pixels: set m_per_px");
                }
                if self.decimal_comma {
                    return reject("decimal_comma", "DLTdv always writes a decimal point");
                }
            }
            Format::Canonical => {
                for (field, set) in [
                    ("fps_hz", self.fps_hz.is_some()),
                    ("m_per_px", self.m_per_px.is_some()),
                    ("units_to_m", self.units_to_m.is_some()),
                    ("scale_points_px", self.scale_points_px.is_some()),
                    ("time_to_s", self.time_to_s.is_some()),
                ] {
                    if set {
                        return reject(field, "a canonical trace is in seconds and metres already");
                    }
                }
            }
            Format::Tracker => {
                if self.m_per_px.is_some() {
                    return reject(
                        "m_per_px",
                        "Tracker writes calibrated units: set units_to_m (1 for m, 0.01 for cm)",
                    );
                }
                if self.origin_px != [0.0, 0.0] {
                    return reject("origin_px", "Tracker coordinates are already calibrated");
                }
                if self.camera != 1 {
                    return reject("camera", "a Tracker export holds one video");
                }
            }
            _ => {
                if self.camera != 1 {
                    return reject("camera", "the file holds one video");
                }
                if self.decimal_comma && format != Format::Generic {
                    return reject(
                        "decimal_comma",
                        "the reader detects this format's decimal separator itself",
                    );
                }
            }
        }
        Ok(())
    }

    /// The format a file at `path` is read as: `format` when set, generic with a `[generic]`
    /// mapping, else [`Format::detect`] on the file's content.
    ///
    /// # Errors
    /// As [`Format::detect`].
    pub fn resolve_format(&self, path: &Path) -> Result<Format> {
        match self.format {
            Some(f) => Ok(f),
            None if self.generic.is_some() => Ok(Format::Generic),
            None => Format::detect(path),
        }
    }

    /// The image scale in m/px: `m_per_px`, or `scale_distance_m` / |p2 − p1| from
    /// `scale_points_px`, or `None` if neither is set.
    ///
    /// # Errors
    /// [`ImportError`] if both ways are given, only one of `scale_points_px` and
    /// `scale_distance_m` is, or the two points coincide or are not finite.
    pub fn resolved_m_per_px(&self) -> Result<Option<f64>> {
        match (self.m_per_px, self.scale_points_px, self.scale_distance_m) {
            (m, None, None) => Ok(m),
            (Some(_), _, _) => Err(ImportError::Exclusive {
                first: "m_per_px",
                second: "scale_points_px + scale_distance_m",
            }
            .into()),
            (None, Some([[x1, y1], [x2, y2]]), Some(d)) => {
                let len = (x2 - x1).hypot(y2 - y1);
                if !(len.is_finite() && len > 0.0) {
                    let points_px = [[x1, y1], [x2, y2]];
                    return Err(ImportError::ScalePoints { points_px }.into());
                }
                Ok(Some(d / len))
            }
            (None, _, _) => Err(ImportError::ScaleIncomplete.into()),
        }
    }
}

/// [`ImportError::NotForFormat`] for `field`, which `format` does not use; `hint` says what to do.
fn not_for(field: &'static str, format: Format, hint: &'static str) -> Error {
    ImportError::NotForFormat {
        field,
        format,
        hint,
    }
    .into()
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
/// * [`ImportError`] — a setting out of range or not applicable to the format.
pub fn read_trace(path: &Path, spec: &ImportSpec) -> Result<Trace> {
    read_trace_with_summary(path, spec).map(|(trace, _)| trace)
}

/// [`read_trace`], plus the [`ImportSummary`] of the result (with the format filled in).
///
/// # Errors
/// As [`read_trace`].
pub fn read_trace_with_summary(path: &Path, spec: &ImportSpec) -> Result<(Trace, ImportSummary)> {
    read_with(path, spec, false)
}

/// Describe a file even when the settings lack its calibration: where a frame rate is missing for
/// a file with frame numbers only, times are frame numbers (a stand-in of 1 frame/s); where a scale
/// is missing for a file in pixels or an unstated unit, positions stay in file units (a stand-in
/// of 1 m per unit). [`ImportSummary::uncalibrated`] says which stand-ins were used, so a caller
/// can print frames and pixels as such and say what a fit still needs.
///
/// # Errors
/// As [`read_trace`], except the missing frame rate and scale.
pub fn describe_file(path: &Path, spec: &ImportSpec) -> Result<(Trace, ImportSummary)> {
    read_with(path, spec, true)
}

/// [`read_trace_with_summary`] (`stand_in` false) or [`describe_file`] (true).
fn read_with(path: &Path, spec: &ImportSpec, stand_in: bool) -> Result<(Trace, ImportSummary)> {
    let format = spec.resolve_format(path)?;
    spec.validate(format)?;
    // The two-point scale becomes m_per_px for every reader.
    let mut resolved = spec.clone();
    if spec.scale_points_px.is_some() {
        resolved.m_per_px = spec.resolved_m_per_px()?;
        resolved.scale_points_px = None;
        resolved.scale_distance_m = None;
    }
    let mut notes = Vec::new();
    if let (Some(p), Some(m)) = (&spec.scale_points_px, resolved.m_per_px) {
        notes.push(format!(
            "scale from two points {p:?} {} m apart: {m:e} m/px",
            spec.scale_distance_m.unwrap_or(f64::NAN)
        ));
    }
    let (raw, uncalibrated) = read_format(path, format, &resolved, stand_in, &mut notes)?;
    let mut trace = assign_roles(path, raw, &resolved.points)?;
    if let Some(note) = rotate_to_sweep(path, &mut trace, &resolved)? {
        notes.push(note);
    }
    // The readers guarantee this; checked once more because t0_s is added to every time.
    trace
        .check()
        .map_err(|m| Error::input(path, format!("imported trace is inconsistent: {m}")))?;
    check_plausible(path, &trace, uncalibrated)?;
    let mut summary = describe(&trace);
    summary.format = Some(format);
    summary.notes = notes;
    summary.uncalibrated = uncalibrated;
    Ok((trace, summary))
}

/// Largest plausible |position| of a trace, m (or file units in an uncalibrated description): a
/// wiper sweep spans well under 1 m and image coordinates stay below 1e5 pixels even when a scale
/// of 1 keeps them as they are, so 1e6 only catches overflowed cells such as `1e308` and unit
/// mix-ups of that size.
pub const MAX_POSITION_M: f64 = 1e6;

/// At least two frames, and every tracked position within [`MAX_POSITION_M`].
///
/// # Errors
/// [`Error::Input`] naming the point, the coordinate, the frame and its time.
fn check_plausible(path: &Path, trace: &Trace, unc: Uncalibrated) -> Result<()> {
    let n = trace.t_s.len();
    if n < 2 {
        return Err(Error::input(
            path,
            format!("{n} frame(s): a trace needs at least 2 frames (a time step and a spectrum)"),
        ));
    }
    let limit = MAX_POSITION_M;
    let unit = if unc.file_units { "file units" } else { "m" };
    for p in &trace.points {
        for (axis, v) in [("x", &p.x_m), ("y", &p.y_m)] {
            if let Some(k) = v.iter().position(|c| c.abs() > limit) {
                return Err(Error::input(
                    path,
                    format!(
                        "point {}: {axis} = {:e} {unit} at frame {} (t = {} s) is beyond ±{limit:e} \
                         {unit}: not a tracked position (an overflowed cell or a wrong unit?)",
                        p.name,
                        v[k],
                        k + 1,
                        significant(trace.t_s[k], 6)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The format's reader and the calibration, with stand-ins for a missing frame rate and scale
/// when `stand_in` (see [`describe_file`]); notes go to `notes`.
fn read_format(
    path: &Path,
    format: Format,
    spec: &ImportSpec,
    stand_in: bool,
    notes: &mut Vec<String>,
) -> Result<(Trace, Uncalibrated)> {
    let mut spec = spec.clone();
    let mut unc = Uncalibrated::default();
    let trace = match format {
        Format::Dltdv => {
            if stand_in {
                // A DLTdv xypts file is always frame-indexed and in pixels.
                unc.frames = spec.fps_hz.is_none();
                unc.file_units = spec.m_per_px.is_none();
                stand_ins(&mut spec, unc, notes);
            }
            if unc == Uncalibrated::default() {
                notes.push(format!(
                    "time base: (frame − 1) / {} fps; units: pixels × {:e} m/px, image y down \
                     flipped unless y_down = false",
                    spec.fps_hz.unwrap_or(f64::NAN),
                    spec.m_per_px.unwrap_or(f64::NAN)
                ));
            }
            dltdv::read(path, &spec)?
        }
        Format::Tracker => {
            notes.push(format!(
                "time base: the file's t column (real frame times kept); units: calibrated × {} m",
                spec.units_to_m.unwrap_or(1.0)
            ));
            tracker::read(path, &spec)?
        }
        Format::Canonical => {
            notes.push("canonical trace: times in s, positions in m, y up, as written".into());
            let (trace, extras) = canonical::read_trace_csv_with_extras(path)?;
            if !extras.is_empty() {
                notes.push(format!(
                    "columns after the points skipped (not tracked points): {}",
                    extras.join(", ")
                ));
            }
            trace
        }
        other => {
            let raw = if stand_in {
                read_raw_described(path, other, &spec)?
            } else {
                read_raw(path, other, &spec)?
            };
            if stand_in {
                unc.frames =
                    matches!(raw.time, common::RawTime::Frames(_)) && spec.fps_hz.is_none();
                unc.file_units = !matches!(raw.units, common::RawUnits::Known(..))
                    && spec.m_per_px.is_none()
                    && spec.units_to_m.is_none();
                stand_ins(&mut spec, unc, notes);
            }
            let (trace, n) = common::calibrate(path, raw, &spec)?;
            notes.extend(n);
            trace
        }
    };
    Ok((trace, unc))
}

/// Sets the stand-in frame rate (1 frame/s) and scale (1 m per file unit) that `unc` calls for,
/// and says so in `notes`.
fn stand_ins(spec: &mut ImportSpec, unc: Uncalibrated, notes: &mut Vec<String>) {
    if unc.frames {
        spec.fps_hz = Some(1.0);
        notes.push(
            "no frame rate given: times are frame numbers (1 frame/s stands in below); a fit \
             needs fps_hz (--fps)"
                .into(),
        );
    }
    if unc.file_units {
        spec.m_per_px = Some(1.0);
        notes.push(
            "no scale given: positions are in file units (1 m per unit stands in below); a fit \
             needs m_per_px (--m-per-px), scale_points_px + scale_distance_m, or units_to_m"
                .into(),
        );
    }
}

/// [`read_raw`] for a description: a TrackMate spot table without a time unit (and no `fps_hz`)
/// is read by its frame numbers instead of refused, so that it is described in frames like every
/// other frame-indexed format. Any other error is the reader's own (it does not depend on the frame
/// rate, so the second read returns it again).
fn read_raw_described(path: &Path, format: Format, spec: &ImportSpec) -> Result<common::RawTrace> {
    match read_raw(path, format, spec) {
        Err(_) if format == Format::Trackmate && spec.fps_hz.is_none() => {
            let framed = ImportSpec {
                fps_hz: Some(1.0),
                ..spec.clone()
            };
            read_raw(path, format, &framed)
        }
        other => other,
    }
}

/// The reader of a format that returns file units ([`common::RawTrace`]); DLTdv and Tracker
/// calibrate in their own readers.
fn read_raw(path: &Path, format: Format, spec: &ImportSpec) -> Result<common::RawTrace> {
    match format {
        Format::DltdvSparse => dltdv_sparse::read(path, spec),
        Format::KinoveaCsv => kinovea::read_csv(path, spec),
        Format::KinoveaTxt => kinovea::read_txt(path, spec),
        Format::KinoveaKinematics => kinovea::read_kinematics(path, spec),
        Format::Deeplabcut => deeplabcut::read(path, spec),
        Format::Sleap => sleap::read(path, spec),
        Format::Trackmate => trackmate::read(path, spec),
        Format::Generic => generic::read(path, spec),
        Format::Dltdv | Format::Tracker | Format::Canonical => {
            unreachable!("DLTdv, Tracker and canonical traces are calibrated by their readers")
        }
    }
}

/// Principal-axis angle (radians, in (−π/2, π/2]) of the finite `(x, y)` samples: the direction of
/// largest variance, 0.5·atan2(2·c_xy, c_xx − c_yy). `None` with fewer than 2 finite samples or no
/// spread.
pub fn principal_axis_rad(x: &[f64], y: &[f64]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = x
        .iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let (mut cxx, mut cyy, mut cxy) = (0.0, 0.0, 0.0);
    for (a, b) in &pts {
        cxx += (a - mx) * (a - mx);
        cyy += (b - my) * (b - my);
        cxy += (a - mx) * (b - my);
    }
    if cxx + cyy <= 0.0 {
        return None;
    }
    let mut a = 0.5 * (2.0 * cxy).atan2(cxx - cyy);
    if a <= -std::f64::consts::FRAC_PI_2 {
        a += std::f64::consts::PI;
    }
    Some(a)
}

/// Rotate every point of `trace` by −θ about the origin, θ = `sweep_angle_deg` or the head's
/// principal axis (`sweep_from_head`), so that x runs along the sweep. Returns the report note.
fn rotate_to_sweep(path: &Path, trace: &mut Trace, spec: &ImportSpec) -> Result<Option<String>> {
    let (theta, note) = if let Some(deg) = spec.sweep_angle_deg {
        (
            deg.to_radians(),
            format!("rotation: by −{deg}° (sweep_angle_deg) so x runs along the sweep"),
        )
    } else if spec.sweep_from_head {
        let Some(head) = trace.role(Role::Head).or_else(|| trace.points.first()) else {
            return Err(Error::input(
                path,
                "sweep_from_head: the file has no points",
            ));
        };
        let Some(theta) = principal_axis_rad(&head.x_m, &head.y_m) else {
            return Err(Error::input(
                path,
                format!(
                    "sweep_from_head: point {:?} has fewer than two distinct tracked positions; \
                     give sweep_angle_deg instead",
                    head.name
                ),
            ));
        };
        (
            theta,
            format!(
                "rotation: sweep axis of point {:?} by principal axis = {:.4}° from +x; rotated by \
                 −{:.4}° so x runs along the sweep",
                head.name,
                theta.to_degrees(),
                theta.to_degrees()
            ),
        )
    } else {
        return Ok(None);
    };
    let (s, c) = theta.sin_cos();
    for p in &mut trace.points {
        for (x, y) in p.x_m.iter_mut().zip(p.y_m.iter_mut()) {
            let (x0, y0) = (*x, *y);
            *x = c * x0 + s * y0;
            *y = -s * x0 + c * y0;
        }
    }
    Ok(Some(note))
}

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
    // The model's roles first, in their order, then other roles alphabetically.
    let mut ordered: Vec<(&String, &String)> = roles.iter().collect();
    ordered.sort_by_key(|(role, _)| {
        let rank = Role::ALL
            .iter()
            .position(|r| r.name() == role.as_str())
            .unwrap_or(Role::ALL.len());
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
    /// `(point name, NaN samples)` in trace order; a sample counts as NaN when x or y is NaN (for a
    /// scalar point, when x is NaN).
    pub points: Vec<(String, usize)>,
    /// Per point: a scalar signal (a generic or Kinovea-kinematics column stored in x; y is NaN
    /// throughout).
    pub scalar: Vec<bool>,
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
    /// Per point (trace order): `(gap runs, longest gap)` in samples; a gap is a maximal run of
    /// samples where x or y is NaN.
    pub gaps: Vec<(usize, usize)>,
    /// Per point: NaN samples in interior gaps of at most [`FILL_MAX_SAMPLES`] samples — the ones
    /// `wiperlab spectrum` fills by linear interpolation with its default `--max-fill`.
    pub fillable: Vec<usize>,
    /// What the import did: time base, units and scale, y flip, rotation, encoding, thresholds,
    /// skipped rows (empty from [`describe`]).
    pub notes: Vec<String>,
    /// The calibration a description stood in for because the settings lack it (all false from
    /// [`read_trace_with_summary`]; see [`describe_file`]).
    pub uncalibrated: Uncalibrated,
}

/// What [`describe_file`] stood in for when the settings lack a calibration: the trace's numbers
/// are then not in seconds and metres, and a fit still needs the missing settings.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Uncalibrated {
    /// The file has frame numbers but no frame rate was given: times are frame numbers from 0
    /// (plus `t0_s`), steps in frames.
    pub frames: bool,
    /// The file is in pixels (or a unit it does not state) and no scale was given: positions are
    /// in the file's own units (origin and y flip applied).
    pub file_units: bool,
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
            .map(|p| {
                let nan = if is_scalar(p) {
                    p.x_m.iter().filter(|v| v.is_nan()).count()
                } else {
                    p.nan_samples()
                };
                (p.name.clone(), nan)
            })
            .collect(),
        scalar: trace.points.iter().map(is_scalar).collect(),
        t_first_s: t.first().copied().unwrap_or(f64::NAN),
        t_last_s: t.last().copied().unwrap_or(f64::NAN),
        dt_median_s,
        dt_min_s: dt.first().copied().unwrap_or(f64::NAN),
        dt_max_s: dt.last().copied().unwrap_or(f64::NAN),
        gaps: trace.points.iter().map(gap_runs).collect(),
        fillable: trace
            .points
            .iter()
            .map(|p| fillable_samples(p, FILL_MAX_SAMPLES))
            .collect(),
        notes: Vec::new(),
        uncalibrated: Uncalibrated::default(),
    }
}

/// The longest interior gap (samples) that `wiperlab spectrum` fills by default (`--max-fill`).
pub const FILL_MAX_SAMPLES: usize = 5;

/// NaN samples of `p` in interior runs (finite samples on both sides) of at most `max_fill`.
pub fn fillable_samples(p: &PointTrack, max_fill: usize) -> usize {
    let scalar = is_scalar(p);
    let missing: Vec<bool> = p
        .x_m
        .iter()
        .zip(&p.y_m)
        .map(|(x, y)| x.is_nan() || (!scalar && y.is_nan()))
        .collect();
    let (mut total, mut run, mut seen_finite) = (0, 0, false);
    for m in missing {
        if m {
            run += 1;
        } else {
            if seen_finite && run <= max_fill {
                total += run;
            }
            run = 0;
            seen_finite = true;
        }
    }
    total
}

/// A scalar point: y NaN throughout while x has a value somewhere.
fn is_scalar(p: &PointTrack) -> bool {
    p.y_m.iter().all(|v| v.is_nan()) && p.x_m.iter().any(|v| !v.is_nan())
}

/// `(number of NaN runs, longest run)` of a point (NaN where x or y is NaN; for a scalar point,
/// where x is NaN).
pub fn gap_runs(p: &PointTrack) -> (usize, usize) {
    let scalar = is_scalar(p);
    let (mut runs, mut longest, mut cur) = (0, 0, 0);
    for (x, y) in p.x_m.iter().zip(&p.y_m) {
        if x.is_nan() || (!scalar && y.is_nan()) {
            if cur == 0 {
                runs += 1;
            }
            cur += 1;
            longest = longest.max(cur);
        } else {
            cur = 0;
        }
    }
    (runs, longest)
}

impl fmt::Display for ImportSummary {
    /// A header line (format, frames, time range, steps), then one line per point.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(format) = self.format {
            write!(f, "{format}: ")?;
        }
        // Times to 6 significant digits (a 140 s record to the millisecond), steps to 4.
        let (t, dt) = (|v| significant(v, 6), |v| significant(v, 4));
        if self.uncalibrated.frames {
            writeln!(
                f,
                "{} frames, frame {} … {} (no frame rate: times in frames), step median {}, min \
                 {}, max {} frames",
                self.n_frames,
                t(self.t_first_s),
                t(self.t_last_s),
                dt(self.dt_median_s),
                dt(self.dt_min_s),
                dt(self.dt_max_s)
            )?;
        } else {
            writeln!(
                f,
                "{} frames, t = {} … {} s, dt median {} s ({} fps), min {} s, max {} s",
                self.n_frames,
                t(self.t_first_s),
                t(self.t_last_s),
                dt(self.dt_median_s),
                significant(self.fps_median_hz(), 6),
                dt(self.dt_min_s),
                dt(self.dt_max_s)
            )?;
        }
        for (i, (name, nan)) in self.points.iter().enumerate() {
            let pct = if self.n_frames > 0 {
                100.0 * *nan as f64 / self.n_frames as f64
            } else {
                0.0
            };
            let kind = if self.scalar.get(i) == Some(&true) {
                " (scalar, value in x)"
            } else {
                ""
            };
            write!(
                f,
                "  {name}{kind}: {} tracked, {nan} NaN ({pct:.2} %)",
                self.n_frames - nan
            )?;
            match self.gaps.get(i) {
                Some(&(runs, longest)) if runs > 0 => {
                    write!(f, " in {runs} gaps, longest {longest} samples")?;
                    let fill = self.fillable.get(i).copied().unwrap_or(0);
                    writeln!(
                        f,
                        "; {fill} in interior gaps ≤ {FILL_MAX_SAMPLES} samples (filled by \
                         spectrum), the rest split the record"
                    )?
                }
                _ => writeln!(f)?,
            }
        }
        for note in &self.notes {
            writeln!(f, "  note: {note}")?;
        }
        Ok(())
    }
}

/// Read a whole file as text, BOM removed: UTF-8, else Windows-1252 ([`common::decode`]).
pub(crate) fn read_text(path: &Path) -> Result<String> {
    common::read_decoded(path).map(|(s, _)| s)
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
            format!(
                "invalid UTF-8 in field {}: expected UTF-8 text (re-save the file as UTF-8)",
                err.field() + 1
            ),
        ),
        other => Error::parse(
            path,
            line.max(1),
            0,
            format!("expected a well-formed CSV record: {other:?}"),
        ),
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
        assert_eq!(spec.units_to_m, None);
        assert_eq!(spec.camera, 1);
        let spec: ImportSpec = toml::from_str(
            "format = \"tracker\"\nunits_to_m = 0.01\n[points]\nhead = \"mass A\"\n",
        )
        .unwrap();
        assert_eq!(spec.format, Some(Format::Tracker));
        assert_eq!(spec.points["head"], "mass A");
        let err = toml::from_str::<ImportSpec>("fps = 10.0\n").unwrap_err();
        assert!(err.to_string().contains("unknown field"), "{err}");
        let err = toml::from_str::<ImportSpec>("format = \"proanalyst\"\n").unwrap_err();
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
                units_to_m: Some(-1.0),
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
        assert!(text.contains("head: 2 tracked, 2 NaN (50.00 %) in 1 gaps, longest 2 samples; 2 in interior gaps ≤ 5"), "{text}");
        let long = PointTrack {
            name: "p".into(),
            x_m: vec![
                f64::NAN,
                1.0,
                f64::NAN,
                1.0,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                f64::NAN,
                1.0,
                f64::NAN,
            ],
            y_m: vec![0.0; 12],
        };
        // Leading and trailing NaN are never filled; the 6-sample gap is longer than 5.
        assert_eq!(fillable_samples(&long, 5), 1);
        assert_eq!(fillable_samples(&long, 6), 7);
        let empty = describe(&Trace::default());
        assert!(empty.t_first_s.is_nan() && empty.dt_median_s.is_nan());
    }
}
