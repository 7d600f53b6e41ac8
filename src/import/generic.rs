//! Generic delimited table with user-mapped columns ([`super::Format::Generic`]).
//!
//! For exports without a dedicated reader (ProAnalyst, TEMA, Photron PFV, Phantom PCC, lab
//! scripts; FORMATS.md §7). The user names the columns in [`GenericColumns`]; the reader finds the
//! header as the first line (of the first 100) that contains every mapped name as a cell, so any
//! preamble above it is skipped. Delimiter: given, or sniffed from that line (TAB, `;`, `,`, then
//! space). Cells may be double-quoted; empty / `NaN` cells are missing. Decimal comma with
//! [`ImportSpec::decimal_comma`].
//!
//! ```toml
//! format = "generic"
//! units_to_m = 0.001            # the table is in mm (or m_per_px for pixels)
//! [generic]
//! time = "Time (ms)"            # or frame = "Frame" (+ fps_hz), or neither (row index / fps_hz)
//! [generic.points]
//! head = ["Head X", "Head Y"]
//! tip = ["Tip X", "Tip Y"]
//! ```
//! Time: the `time` column × `time_to_s` (default: a `(ms)`/`(s)` unit in the column name, else
//! seconds); or `frame` column / `fps_hz`; or row index / `fps_hz`. y is up unless `y_down`.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::import::common::{
    RawTime, RawTrace, RawUnits, Table, header_time_unit, numbered_lines, read_decoded,
    sniff_delimiter, split_cells,
};
use crate::import::{ImportError, ImportSpec};

/// How many lines the header search looks at.
const MAX_PREAMBLE_LINES: usize = 100;

/// Column mapping of a generic table (`[generic]` in the import spec).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GenericColumns {
    /// Field delimiter (one character, e.g. `"\t"`, `";"`); default: sniffed from the header.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delimiter: Option<char>,
    /// Column holding the time (unit: `time_to_s`, or `(ms)`/`(s)` in its name, else seconds).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<String>,
    /// Column holding a frame number (t = `t0_s` + frame/`fps_hz`); alternative to `time`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frame: Option<String>,
    /// Point name → `[x column, y column]`, or `[column]` for a scalar signal (force, angle ...):
    /// its value is stored as x, y is NaN.
    pub points: BTreeMap<String, Vec<String>>,
    /// Lines right after the header to skip (a unit row such as `ms,rpm,...`); default 0.
    pub skip_after_header: usize,
    /// Non-blank lines at the end of the file that are not data (a footer such as `TotalTime`);
    /// default 0.
    pub footer_lines: usize,
    /// JSON input (a file starting with `{`): the key holding the array of rows (each an array of
    /// numbers or null); default `"data"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub json_key: Option<String>,
    /// Column names for input without a header (JSON rows); default `"0"`, `"1"`, ...
    #[serde(skip_serializing_if = "Option::is_none")]
    pub columns: Option<Vec<String>>,
}

/// Read a generic table (module docs) into a [`RawTrace`] in file units.
///
/// # Errors
/// [`ImportError`] if no `[generic]` mapping or no point is given, or both `time` and `frame`;
/// [`Error::Input`] if no line of the first 100 holds every mapped column name (the message lists
/// the names wanted); [`Error::Parse`] (line, column, field) for a bad or non-increasing time or
/// frame, a non-numeric coordinate, a row with fewer fields than the header.
pub fn read(path: &Path, spec: &ImportSpec) -> Result<RawTrace> {
    let Some(map) = &spec.generic else {
        return Err(ImportError::GenericUnmapped.into());
    };
    if map.points.is_empty() {
        return Err(ImportError::GenericNoPoints.into());
    }
    if map.time.is_some() && map.frame.is_some() {
        let (first, second) = ("[generic] time", "frame");
        return Err(ImportError::Exclusive { first, second }.into());
    }
    for (name, cols) in &map.points {
        if cols.is_empty() || cols.len() > 2 {
            return Err(ImportError::GenericColumns {
                point: name.clone(),
                columns: cols.clone(),
            }
            .into());
        }
    }
    let mut wanted: Vec<&str> = map
        .points
        .values()
        .flat_map(|c| c.iter().map(String::as_str))
        .collect();
    wanted.extend(map.time.as_deref());
    wanted.extend(map.frame.as_deref());
    let (text, _) = read_decoded(path)?;
    if text.trim_start().starts_with('{') {
        let json = json_rows(path, &text, map)?;
        let lines: Vec<(usize, &str)> = json.iter().map(|(l, s)| (*l, s.as_str())).collect();
        return from_lines(path, &lines, 0, ',', map, spec, &wanted, "JSON");
    }
    let lines = numbered_lines(&text);
    let mut found = None;
    for (k, &(_, l)) in lines.iter().enumerate().take(MAX_PREAMBLE_LINES) {
        let Some(d) = map.delimiter.or_else(|| sniff_delimiter(l)) else {
            continue;
        };
        let cells: Vec<String> = split_cells(l, d)
            .into_iter()
            .map(|c| c.trim().to_owned())
            .collect();
        if wanted.iter().all(|w| cells.iter().any(|c| c == w)) {
            found = Some((k, d));
            break;
        }
    }
    let Some((k, delim)) = found else {
        return Err(Error::input(
            path,
            format!(
                "no header line in the first {MAX_PREAMBLE_LINES} lines holds all mapped columns \
                 {wanted:?}"
            ),
        ));
    };
    from_lines(path, &lines[k..], 0, delim, map, spec, &wanted, "table")
}

/// JSON `{ "<json_key>": [[...], ...] }` as CSV lines: a header (`columns` or `0`, `1`, ...), then
/// one line per row numbered from 1 (the row index, which error messages call the line).
fn json_rows(path: &Path, text: &str, map: &GenericColumns) -> Result<Vec<(usize, String)>> {
    let v: serde_json::Value = serde_json::from_str(text).map_err(|e| {
        Error::parse(
            path,
            e.line().max(1),
            e.column(),
            format!("expected valid JSON: {e}"),
        )
    })?;
    let key = map.json_key.as_deref().unwrap_or("data");
    let Some(rows) = v.get(key).and_then(|d| d.as_array()) else {
        return Err(Error::input(
            path,
            format!("expected a JSON object with an array of rows under {key:?} (json_key)"),
        ));
    };
    let width = rows.first().and_then(|r| r.as_array()).map_or(0, Vec::len);
    let names: Vec<String> = match &map.columns {
        Some(c) => c.clone(),
        None => (0..width).map(|j| j.to_string()).collect(),
    };
    let mut out = vec![(0, names.join(","))];
    for (i, r) in rows.iter().enumerate() {
        let Some(cells) = r.as_array() else {
            return Err(Error::parse(
                path,
                i + 1,
                0,
                format!("{key}[{i}]: expected an array of numbers, found {r}"),
            ));
        };
        let mut line = Vec::with_capacity(cells.len());
        for (j, c) in cells.iter().enumerate() {
            match c {
                serde_json::Value::Number(n) => line.push(n.to_string()),
                serde_json::Value::Null => line.push(String::new()),
                other => {
                    return Err(Error::parse(
                        path,
                        i + 1,
                        j + 1,
                        format!("{key}[{i}][{j}]: expected a number or null, found {other}"),
                    ));
                }
            }
        }
        out.push((i + 1, line.join(",")));
    }
    Ok(out)
}

/// The table from its header line `lines[0]` on (after `skip_after_header` and without
/// `footer_lines`), mapped to a [`RawTrace`].
#[allow(clippy::too_many_arguments)]
fn from_lines(
    path: &Path,
    lines: &[(usize, &str)],
    header: usize,
    delim: char,
    map: &GenericColumns,
    spec: &ImportSpec,
    wanted: &[&str],
    what: &str,
) -> Result<RawTrace> {
    let mut body: Vec<(usize, &str)> = lines[header..]
        .iter()
        .copied()
        .filter(|(_, l)| !l.trim().is_empty())
        .collect();
    if body.len() < 1 + map.skip_after_header + map.footer_lines {
        return Err(Error::input(
            path,
            "no data rows between the header (+ skip_after_header) and the footer_lines",
        ));
    }
    body.truncate(body.len() - map.footer_lines);
    body.drain(1..1 + map.skip_after_header);
    let table = Table::parse(path, &body, 1, delim)?;
    for w in wanted {
        if table.find(w).is_none() {
            return Err(Error::parse(
                path,
                table.headers[0].0,
                0,
                format!(
                    "expected a column {w:?}; columns: {}",
                    table.names().join(", ")
                ),
            ));
        }
    }
    let dc = spec.decimal_comma;
    let idx = |name: &str| table.find(name).unwrap_or(0);
    let time = time_axis(&table, map, spec)?;
    let mut points = Vec::new();
    for (name, cols) in &map.points {
        let x = table.numbers(idx(&cols[0]), dc)?;
        let y = match cols.get(1) {
            Some(c) => table.numbers(idx(c), dc)?,
            None => vec![f64::NAN; x.len()],
        };
        points.push((name.clone(), x, y));
    }
    Ok(RawTrace {
        time,
        points,
        units: RawUnits::Unknown,
        y_down_default: false,
        notes: vec![format!(
            "generic {what}: header on line {}, delimiter {delim:?}, {} rows",
            table.headers[0].0,
            table.rows.len()
        )],
    })
}

/// The time axis: the `time` column × its factor (`time_to_s`, else a unit in the column name,
/// else seconds), the `frame` column, or the row index.
fn time_axis(table: &Table, map: &GenericColumns, spec: &ImportSpec) -> Result<RawTime> {
    let dc = spec.decimal_comma;
    let idx = |name: &str| table.find(name).unwrap_or(0);
    Ok(if let Some(tc) = &map.time {
        let factor = spec
            .time_to_s
            .or_else(|| header_time_unit(tc))
            .unwrap_or(1.0);
        RawTime::Seconds(
            table
                .axis(idx(tc), dc, "a time")?
                .into_iter()
                .map(|t| t * factor)
                .collect(),
        )
    } else if let Some(fc) = &map.frame {
        RawTime::Frames(table.axis(idx(fc), dc, "a frame number")?)
    } else {
        RawTime::Frames((0..table.rows.len()).map(|r| r as f64).collect())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::TempFile;

    #[test]
    fn preamble_and_mapping() {
        let f = TempFile::new(
            "generic.txt",
            "ProAnalyst export\nUnits: mm\n\nTime (ms);HX;HY;other\n0;1,5;2;x\n2;;3;y\n",
        );
        let spec: ImportSpec = toml::from_str(
            "format = \"generic\"\ndecimal_comma = true\nunits_to_m = 0.001\n[generic]\ntime = \
             \"Time (ms)\"\n[generic.points]\nhead = [\"HX\", \"HY\"]\n",
        )
        .unwrap();
        let raw = read(&f.0, &spec).unwrap();
        assert_eq!(raw.time, RawTime::Seconds(vec![0.0, 0.002]));
        assert_eq!(raw.points[0].1[0], 1.5);
        assert!(raw.points[0].1[1].is_nan());
        assert!(raw.notes[0].contains("line 4"), "{:?}", raw.notes);
    }
}
