//! A friction rig's μ(v) curve read from its CSV log ([`read`]), for `[fit.priors.friction_curve]`.
//!
//! Rig logs come as their software writes them: a preamble before the header, trailing commas, a
//! footer after the last row. The reader therefore takes as the header the first record that names
//! every column the job asks for (cells trimmed), reads rows until the first blank or narrower
//! record (the footer, e.g. a tribometer's `TotalTime`), and refuses a full-width row after that.
//! Lines are numbered by line feeds (a bare carriage return ends a record but not a line).
//!
//! Without `group_by` every row is a point, its 1σ from `sd_column` or `sd`. With `group_by` the
//! rows are grouped by that column's value (a rig's step at one speed): each group is one point at
//! its rows' mean speed, with their mean coefficient and, as its 1σ, the sample standard deviation
//! of its coefficients (or `sd`). That spread, not the standard error of the mean, is the 1σ:
//! consecutive samples of a rig log are strongly correlated, and how well a rig's μ stands for the
//! blade's is a question of the coefficient's spread, not of how many samples were logged.

use super::prior::{FrictionCurvePrior, SpeedUnit, TrackRadius};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One point of a rig curve: the coefficient at a slip speed, with its 1σ.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigPoint {
    /// Slip speed, m/s.
    pub speed_m_per_s: f64,
    /// Friction coefficient, 1.
    pub coefficient: f64,
    /// 1σ of the coefficient, 1.
    pub sd: f64,
    /// Rows of the file behind the point (1 without `group_by`).
    pub rows: usize,
    /// The `group_by` value, when rows are grouped.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
    /// Line of the point's first row in the file.
    pub line: u64,
}

/// A rig curve as read: the file and its points in file order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigCurve {
    pub file: PathBuf,
    pub points: Vec<RigPoint>,
}

/// One data row's values: speed (m/s), coefficient, 1σ (from `sd_column`, else NaN), group.
struct Row {
    speed: f64,
    mu: f64,
    sd: f64,
    group: Option<String>,
    line: u64,
}

/// Reads the rig curve at `path` as `spec` describes it (module docs).
///
/// # Errors
/// [`Error::Io`] for an unreadable file; [`Error::Input`] without a header naming the columns or
/// without data rows; [`Error::Parse`] with the line for a cell that is not a finite number, a
/// negative coefficient, a non-positive 1σ, a short row inside the table, a group without a
/// radius or with a single row (or no spread) and no `sd`.
pub fn read(path: &Path, spec: &FrictionCurvePrior) -> Result<RigCurve> {
    let rows = read_rows(path, spec)?;
    let points = match &spec.group_by {
        None => rows
            .into_iter()
            .map(|r| RigPoint {
                speed_m_per_s: r.speed,
                coefficient: r.mu,
                sd: spec.sd.unwrap_or(r.sd),
                rows: 1,
                group: None,
                line: r.line,
            })
            .collect(),
        Some(_) => group(path, rows, spec.sd)?,
    };
    Ok(RigCurve {
        file: path.to_path_buf(),
        points,
    })
}

/// Every data row of the file, speeds in m/s.
fn read_rows(path: &Path, spec: &FrictionCurvePrior) -> Result<Vec<Row>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, "cannot read", e))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(bytes.as_slice());
    let wanted = spec.columns();
    let mut columns: Option<Vec<usize>> = None;
    let mut header_line = 0;
    let mut footer: Option<(u64, usize)> = None;
    let mut rows = Vec::new();
    let mut lines = Lines::new(&bytes);
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(0, |p| lines.at(p.byte()));
            Error::parse(path, line as usize, 0, format!("not readable as CSV: {e}"))
        })?;
        let line = record.position().map_or(0, |p| lines.at(p.byte()));
        let Some(idx) = &columns else {
            columns = wanted
                .iter()
                .map(|w| record.iter().position(|f| f == *w))
                .collect();
            header_line = line;
            continue;
        };
        let width = idx.iter().max().map_or(0, |m| m + 1);
        if record.iter().all(str::is_empty) || record.len() < width {
            footer.get_or_insert((line, record.len()));
            continue;
        }
        if let Some((at, fields)) = footer {
            return Err(Error::parse(
                path,
                at as usize,
                0,
                format!(
                    "a row of {fields} field(s) inside the table, whose rows need {width}: a \
                     footer may only follow the last row"
                ),
            ));
        }
        rows.push(row(path, spec, &record, idx, line)?);
    }
    if columns.is_none() {
        return Err(Error::input(
            path,
            format!(
                "no header row names the columns {}",
                wanted
                    .iter()
                    .map(|w| format!("'{w}'"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    if rows.is_empty() {
        return Err(Error::input(
            path,
            format!("no data rows after the header (line {header_line})"),
        ));
    }
    Ok(rows)
}

/// Line numbers of byte offsets, counted forward from the last offset asked for. The `csv` crate's
/// own line count is off by one after a CRLF (it places a record at the line feed that ends the
/// previous line): a record's line is that of its first byte after any CR or LF.
struct Lines<'b> {
    bytes: &'b [u8],
    at: usize,
    line: u64,
}

impl<'b> Lines<'b> {
    fn new(bytes: &'b [u8]) -> Self {
        Lines {
            bytes,
            at: 0,
            line: 1,
        }
    }

    /// The 1-based line of the record the reader places at byte `byte` (not before the last).
    fn at(&mut self, byte: u64) -> u64 {
        let mut start = (byte as usize).max(self.at);
        while matches!(self.bytes.get(start), Some(b'\r' | b'\n')) {
            start += 1;
        }
        let start = start.min(self.bytes.len());
        self.line += self.bytes[self.at..start]
            .iter()
            .filter(|&&b| b == b'\n')
            .count() as u64;
        self.at = start;
        self.line
    }
}

/// One data row: its cells at `idx` (speed, coefficient, then 1σ and group when asked for).
fn row(
    path: &Path,
    spec: &FrictionCurvePrior,
    record: &csv::StringRecord,
    idx: &[usize],
    line: u64,
) -> Result<Row> {
    let at = |msg: String| Error::parse(path, line as usize, 0, msg);
    let number = |k: usize, name: &str| -> Result<f64> {
        let cell = &record[idx[k]];
        match cell.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(at(format!(
                "column '{name}': expected a finite number, got '{cell}'"
            ))),
        }
    };
    let raw_speed = number(0, &spec.speed_column)?;
    let mu = number(1, &spec.coefficient_column)?;
    if mu < 0.0 {
        return Err(at(format!(
            "column '{}': a friction coefficient must be >= 0 (got {mu})",
            spec.coefficient_column
        )));
    }
    let mut next = 2;
    let sd = match &spec.sd_column {
        Some(name) => {
            let s = number(next, name)?;
            next += 1;
            if s <= 0.0 {
                return Err(at(format!("column '{name}': a 1σ must be > 0 (got {s})")));
            }
            s
        }
        None => f64::NAN,
    };
    let group = spec
        .group_by
        .as_ref()
        .map(|_| record[idx[next]].to_string());
    let speed = match (spec.speed_unit, &spec.track_radius_m) {
        (SpeedUnit::MetresPerSecond, _) => raw_speed.abs(),
        (SpeedUnit::MillimetresPerSecond, _) => raw_speed.abs() * 1e-3,
        (SpeedUnit::Rpm, radius) => {
            let r = match (radius, &group) {
                (Some(TrackRadius::All(r)), _) => *r,
                (Some(TrackRadius::PerGroup(m)), Some(g)) => *m.get(g).ok_or_else(|| {
                    at(format!(
                        "group '{g}' has no radius in [fit.priors.friction_curve] track_radius_m"
                    ))
                })?,
                _ => f64::NAN,
            };
            raw_speed.abs() * std::f64::consts::TAU * r / 60.0
        }
    };
    Ok(Row {
        speed,
        mu,
        sd,
        group,
        line,
    })
}

/// The rows grouped by their group value, in the order groups first appear: one point each.
fn group(path: &Path, rows: Vec<Row>, sd: Option<f64>) -> Result<Vec<RigPoint>> {
    let mut groups: Vec<(String, Vec<Row>)> = Vec::new();
    for r in rows {
        let key = r.group.clone().unwrap_or_default();
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, g)) => g.push(r),
            None => groups.push((key, vec![r])),
        }
    }
    groups
        .into_iter()
        .map(|(key, g)| {
            let n = g.len() as f64;
            let speed = g.iter().map(|r| r.speed).sum::<f64>() / n;
            let mu = g.iter().map(|r| r.mu).sum::<f64>() / n;
            let spread = (g.iter().map(|r| (r.mu - mu).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let line = g[0].line;
            let sd = match sd {
                Some(s) => s,
                None if g.len() >= 2 && spread > 0.0 => spread,
                None => {
                    return Err(Error::parse(
                        path,
                        line as usize,
                        0,
                        format!(
                            "group '{key}' ({} row(s) from this line) has no spread of its \
                             coefficient to take as its 1σ: give sd in [fit.priors.friction_curve]",
                            g.len()
                        ),
                    ));
                }
            };
            Ok(RigPoint {
                speed_m_per_s: speed,
                coefficient: mu,
                sd,
                rows: g.len(),
                group: Some(key),
                line,
            })
        })
        .collect()
}
