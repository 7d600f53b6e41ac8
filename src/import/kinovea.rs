//! Kinovea exports (FORMATS.md §2).
//!
//! * [`read_csv`] — trajectory CSV (Kinovea 2023+): `"Time","<object>/<point>/X","<object>/<point>/Y",...`,
//!   every cell double-quoted, missing = empty unquoted field, list separator `,` or `;` (sniffed),
//!   decimal comma inside quoted cells (`"1,0";"2,0"`) detected per cell. The time unit is not
//!   written: taken from a `Time (ms)`/`Time (s)` header, else [`ImportSpec::time_to_s`], else an
//!   error.
//! * [`read_txt`] — trajectory TXT ("Gnuplot"): `#Kinovea Trajectory data export`, `#T X Y`, then
//!   one section per object (`# <name>`, rows `t x y [x2 y2 ...]`, space separated). Time in s,
//!   restarting in every section; sections may differ in length: the trace's time axis is the
//!   union of all sections' times, NaN where a section has no row. A token with a `,` is a decimal
//!   comma (older Kinovea writes `0.008 77,20 -21,97 `).
//! * [`read_kinematics`] — kinematics-dialog CSV: `Time (ms),<source>,...` (ms → s). Columns named
//!   `<name> X`/`<name> Y` (or `/X`, `_X`, `.X`) are paired into points; any other column is one
//!   scalar quantity per source (Kinovea does not say which: speed, angle ...) and becomes a point
//!   whose x holds the value and whose y is NaN (reported).
//!
//! Coordinates are in the unit the user calibrated (or pixels): the file does not say, so
//! `units_to_m` or `m_per_px` must be set. y is taken as up (Kinovea's calibrated axes); set
//! `y_down` for raw pixel coordinates.

use std::path::Path;

use crate::error::{Error, Result};
use crate::import::ImportSpec;
use crate::import::common::{
    RawTime, RawTrace, RawUnits, Table, TextEncoding, header_time_unit, numbered_lines, pair_xy,
    parse_cell, read_decoded, sniff_delimiter, unique_name,
};

/// Read a Kinovea trajectory CSV (module docs) into a [`RawTrace`] in file units.
///
/// # Errors
/// [`Error::Io`]; [`Error::Parse`] (line, column, field) for a bad header or cell; [`Error::Input`]
/// when the time unit is unknown and `time_to_s` is not set, or no X/Y column pair exists.
pub fn read_csv(path: &Path, spec: &ImportSpec) -> Result<RawTrace> {
    let (text, enc) = read_decoded(path)?;
    let lines = numbered_lines(&text);
    let Some(&(hline, htext)) = lines.iter().find(|(_, l)| !l.trim().is_empty()) else {
        return Err(Error::input(
            path,
            "empty file: expected a Kinovea header \"Time\",...",
        ));
    };
    let delim = sniff_delimiter(htext).unwrap_or(',');
    let table = Table::parse(path, &lines, 1, delim)?;
    let names = table.names();
    let factor = csv_time_factor(path, hline, &names[0], spec)?;
    let time = csv_time(&table, factor)?;
    let (pairs, single) = pair_xy(names, &[0]);
    if pairs.is_empty() {
        return Err(Error::parse(
            path,
            hline,
            0,
            format!(
                "expected an <object>/<point>/X and .../Y column pair; columns: {}",
                names.join(", ")
            ),
        ));
    }
    let mut points: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
    for (base, cx, cy) in pairs {
        let x = csv_numbers(&table, cx)?;
        let y = csv_numbers(&table, cy)?;
        let taken: Vec<String> = points.iter().map(|p| p.0.clone()).collect();
        points.push((unique_name(&taken, &base), x, y));
    }
    let mut notes = vec![format!(
        "Kinovea trajectory CSV: delimiter {delim:?}, time × {factor} s"
    )];
    if !single.is_empty() {
        let cols: Vec<&str> = single.iter().map(|&j| names[j].as_str()).collect();
        notes.push(format!(
            "ignored columns without an X/Y partner: {}",
            cols.join(", ")
        ));
    }
    push_encoding_note(enc, &mut notes);
    Ok(RawTrace {
        time: RawTime::Seconds(time),
        points,
        units: RawUnits::Unknown,
        y_down_default: false,
        notes,
    })
}

/// Seconds per unit of the trajectory CSV's first column `name` (which must start with `Time`):
/// `time_to_s`, else the unit in the header (`Time (ms)`).
fn csv_time_factor(path: &Path, hline: usize, name: &str, spec: &ImportSpec) -> Result<f64> {
    if !name.starts_with("Time") {
        return Err(Error::parse(
            path,
            hline,
            1,
            format!(
                "expected the first column to be \"Time\", found {}",
                super::quote_cell(name)
            ),
        ));
    }
    match (header_time_unit(name), spec.time_to_s) {
        (_, Some(f)) => Ok(f),
        (Some(f), None) => Ok(f),
        (None, None) => Err(Error::input(
            path,
            "the Kinovea trajectory CSV does not state the unit of its Time column: set \
             time_to_s (1 for seconds, 0.001 for milliseconds)",
        )),
    }
}

/// The trajectory CSV's first column × `factor`: seconds, strictly increasing. Commas are always
/// decimal here: a cell that still holds a `,` after splitting was quoted (or `;` separated).
fn csv_time(table: &Table, factor: f64) -> Result<Vec<f64>> {
    let mut time: Vec<f64> = Vec::with_capacity(table.rows.len());
    for r in 0..table.rows.len() {
        let cell = &table.rows[r].1[0];
        let v = match parse_cell(cell, true) {
            Ok(Some(v)) => v * factor,
            _ => return Err(table.bad_cell(r, 0, "a time")),
        };
        if let Some(&p) = time.last().filter(|&&p| v <= p) {
            return Err(table.bad_cell(
                r,
                0,
                &format!("a time after the previous row's {p} s (strictly increasing)"),
            ));
        }
        time.push(v);
    }
    Ok(time)
}

/// Column `c` of a trajectory CSV (decimal comma), NaN where empty.
fn csv_numbers(table: &Table, c: usize) -> Result<Vec<f64>> {
    (0..table.rows.len())
        .map(|r| match parse_cell(&table.rows[r].1[c], true) {
            Ok(v) => Ok(v.unwrap_or(f64::NAN)),
            Err(()) => Err(table.bad_cell(r, c, "a number or an empty cell")),
        })
        .collect()
}

/// Say so in `notes` when the file was not UTF-8.
fn push_encoding_note(enc: TextEncoding, notes: &mut Vec<String>) {
    if enc != TextEncoding::Utf8 {
        notes.push("encoding: not UTF-8, decoded as Windows-1252".into());
    }
}

/// A point of a [`RawTrace`]: name, x and y in file units.
type Point = (String, Vec<f64>, Vec<f64>);

/// One `# <name>` section of a trajectory TXT: its rows' times and coordinate columns.
struct Section {
    name: String,
    /// Values per row (time + coordinates), fixed by the section's first row; 0 before it.
    width: usize,
    t: Vec<f64>,
    /// x1, y1, x2, y2 ... columns.
    xy: Vec<Vec<f64>>,
}

/// Read a Kinovea trajectory TXT (module docs) into a [`RawTrace`] in file units.
///
/// # Errors
/// [`Error::Io`]; [`Error::Parse`] (line, column) for a data row before the first section, a row
/// with an odd number of coordinates or a different width than the section's first row, a
/// non-numeric token or a time not after the previous row's; [`Error::Input`] if no section has
/// rows.
pub fn read_txt(path: &Path, spec: &ImportSpec) -> Result<RawTrace> {
    let (text, enc) = read_decoded(path)?;
    let factor = spec.time_to_s.unwrap_or(1.0);
    let mut sections: Vec<Section> = Vec::new();
    for (line, l) in numbered_lines(&text) {
        let trimmed = l.trim();
        if trimmed.is_empty() {
            continue;
        }
        if let Some(rest) = trimmed.strip_prefix('#') {
            if line <= 2 && (rest.starts_with("Kinovea") || rest.trim() == "T X Y") {
                continue;
            }
            sections.push(Section {
                name: rest.trim().to_owned(),
                width: 0,
                t: Vec::new(),
                xy: Vec::new(),
            });
            continue;
        }
        let Some(sec) = sections.last_mut() else {
            return Err(Error::parse(
                path,
                line,
                1,
                "data row before the first section: expected a `# <object name>` line",
            ));
        };
        push_txt_row(path, line, &tokens(l), factor, sec)?;
    }
    sections.retain(|s| !s.t.is_empty());
    if sections.is_empty() {
        return Err(Error::input(
            path,
            "no data rows: expected `# <object>` sections of `t x y` rows",
        ));
    }
    let (time, points) = merge_sections(&sections);
    let lengths: Vec<String> = sections
        .iter()
        .map(|s| format!("{} {}", s.name, s.t.len()))
        .collect();
    let mut notes = vec![format!(
        "Kinovea trajectory TXT: {} sections (rows: {}); time axis = union of the sections' times \
         ({} samples), NaN where a section has no row",
        sections.len(),
        lengths.join(", "),
        time.len()
    )];
    push_encoding_note(enc, &mut notes);
    Ok(RawTrace {
        time: RawTime::Seconds(time),
        points,
        units: RawUnits::Unknown,
        y_down_default: false,
        notes,
    })
}

/// The whitespace-separated tokens of `l`, each with its 1-based character column.
fn tokens(l: &str) -> Vec<(usize, &str)> {
    let mut tokens: Vec<(usize, &str)> = Vec::new();
    let mut start = None;
    for (ci, (bi, ch)) in l.char_indices().enumerate() {
        if ch.is_whitespace() {
            if let Some((c0, b0)) = start.take() {
                tokens.push((c0, &l[b0..bi]));
            }
        } else if start.is_none() {
            start = Some((ci + 1, bi));
        }
    }
    if let Some((c0, b0)) = start {
        tokens.push((c0, &l[b0..]));
    }
    tokens
}

/// Append the data row on `line` (its `tokens`: a time and x, y pairs) to `sec`.
fn push_txt_row(
    path: &Path,
    line: usize,
    tokens: &[(usize, &str)],
    factor: f64,
    sec: &mut Section,
) -> Result<()> {
    check_txt_width(path, line, tokens.len(), sec)?;
    let mut vals = Vec::with_capacity(tokens.len());
    for (k, &(col, tok)) in tokens.iter().enumerate() {
        match parse_cell(tok, true) {
            Ok(Some(v)) => vals.push(v),
            Ok(None) if k > 0 => vals.push(f64::NAN),
            _ => {
                return Err(Error::parse(
                    path,
                    line,
                    col,
                    format!(
                        "section {:?}: expected {}, found {}",
                        sec.name,
                        if k == 0 { "a time" } else { "a number" },
                        super::quote_cell(tok)
                    ),
                ));
            }
        }
    }
    let t = vals[0] * factor;
    if let Some(&p) = sec.t.last().filter(|&&p| t <= p) {
        return Err(Error::parse(
            path,
            line,
            1,
            format!(
                "section {:?}: time {t} s is not after the previous row's {p} s (expected \
                 strictly increasing times)",
                sec.name
            ),
        ));
    }
    sec.t.push(t);
    for (k, v) in vals[1..].iter().enumerate() {
        sec.xy[k].push(*v);
    }
    Ok(())
}

/// A row of `n` values must be a time and x, y pairs, as wide as the section's first row (whose
/// width it sets).
fn check_txt_width(path: &Path, line: usize, n: usize, sec: &mut Section) -> Result<()> {
    if n < 3 || n.is_multiple_of(2) {
        return Err(Error::parse(
            path,
            line,
            0,
            format!(
                "section {:?}: expected a time and x, y pairs (an odd number ≥ 3 of values), \
                 found {n} values",
                sec.name
            ),
        ));
    }
    if sec.width == 0 {
        sec.width = n;
        sec.xy = vec![Vec::new(); n - 1];
    } else if n != sec.width {
        return Err(Error::parse(
            path,
            line,
            0,
            format!(
                "section {:?}: expected {} values like its first row, found {n}",
                sec.name, sec.width
            ),
        ));
    }
    Ok(())
}

/// The union of all sections' times (exact values as written) and every section's points on it,
/// NaN where a section has no row.
fn merge_sections(sections: &[Section]) -> (Vec<f64>, Vec<Point>) {
    let mut time: Vec<f64> = sections.iter().flat_map(|s| s.t.iter().copied()).collect();
    time.sort_by(f64::total_cmp);
    time.dedup();
    let mut points: Vec<Point> = Vec::new();
    for s in sections {
        let idx: Vec<usize> =
            s.t.iter()
                .map(|t| time.binary_search_by(|u| u.total_cmp(t)).unwrap_or(0))
                .collect();
        for k in 0..s.xy.len() / 2 {
            let mut x = vec![f64::NAN; time.len()];
            let mut y = vec![f64::NAN; time.len()];
            for (r, &i) in idx.iter().enumerate() {
                x[i] = s.xy[2 * k][r];
                y[i] = s.xy[2 * k + 1][r];
            }
            let base = if k == 0 {
                s.name.clone()
            } else {
                format!("{}_{}", s.name, k + 1)
            };
            let taken: Vec<String> = points.iter().map(|p| p.0.clone()).collect();
            points.push((unique_name(&taken, &base), x, y));
        }
    }
    (time, points)
}

/// Read a Kinovea kinematics-dialog CSV (module docs) into a [`RawTrace`] in file units.
///
/// # Errors
/// [`Error::Io`]; [`Error::Parse`] for a header whose first column is not a time with a unit
/// (`Time (ms)`) when `time_to_s` is not set, a row with a different number of fields, a
/// non-numeric or non-increasing time, a non-numeric value.
pub fn read_kinematics(path: &Path, spec: &ImportSpec) -> Result<RawTrace> {
    let (text, _) = read_decoded(path)?;
    let lines = numbered_lines(&text);
    let Some(&(hline, htext)) = lines.iter().find(|(_, l)| !l.trim().is_empty()) else {
        return Err(Error::input(
            path,
            "empty file: expected a header Time (ms),...",
        ));
    };
    let delim = sniff_delimiter(htext).unwrap_or(',');
    let table = Table::parse(path, &lines, 1, delim)?;
    let names = table.names().to_vec();
    let factor = match (spec.time_to_s, header_time_unit(&names[0])) {
        (Some(f), _) | (None, Some(f)) => f,
        (None, None) => {
            return Err(Error::parse(
                path,
                hline,
                1,
                format!(
                    "expected a time column with its unit, e.g. \"Time (ms)\", found {} (or set \
                     time_to_s)",
                    super::quote_cell(&names[0])
                ),
            ));
        }
    };
    let decimal_comma = delim == ';';
    let time: Vec<f64> = table
        .axis(0, decimal_comma, "a time")?
        .into_iter()
        .map(|t| t * factor)
        .collect();
    let (pairs, single) = pair_xy(&names, &[0]);
    let mut points: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
    for (base, cx, cy) in pairs {
        let taken: Vec<String> = points.iter().map(|p| p.0.clone()).collect();
        points.push((
            unique_name(&taken, &base),
            table.numbers(cx, decimal_comma)?,
            table.numbers(cy, decimal_comma)?,
        ));
    }
    for &j in &single {
        let taken: Vec<String> = points.iter().map(|p| p.0.clone()).collect();
        points.push((
            unique_name(&taken, &names[j]),
            table.numbers(j, decimal_comma)?,
            vec![f64::NAN; time.len()],
        ));
    }
    if points.is_empty() {
        return Err(Error::parse(
            path,
            hline,
            0,
            "expected at least one data column after the time",
        ));
    }
    let mut notes = vec![format!("Kinovea kinematics CSV: time × {factor} s")];
    if !single.is_empty() {
        let cols: Vec<&str> = single.iter().map(|&j| names[j].as_str()).collect();
        notes.push(format!(
            "scalar columns (no X/Y pair; Kinovea does not say which quantity): {} — value stored \
             as x, y is NaN",
            cols.join(", ")
        ));
    }
    Ok(RawTrace {
        time: RawTime::Seconds(time),
        points,
        units: RawUnits::Unknown,
        y_down_default: false,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::TempFile;

    #[test]
    fn csv_with_semicolons_and_decimal_commas() {
        let f = TempFile::new(
            "kin.csv",
            "\"Time\";\"Blade/head/X\";\"Blade/head/Y\"\r\n\"0,0\";\"1,5\";\"-2,0\"\r\n\"0,5\";;\"3,0\"\r\n",
        );
        let spec = ImportSpec {
            time_to_s: Some(1.0),
            ..ImportSpec::default()
        };
        let raw = read_csv(&f.0, &spec).unwrap();
        assert_eq!(raw.time, RawTime::Seconds(vec![0.0, 0.5]));
        assert_eq!(raw.points[0].0, "Blade/head");
        assert_eq!(raw.points[0].1[0], 1.5);
        assert!(raw.points[0].1[1].is_nan());
        assert_eq!(raw.points[0].2, [-2.0, 3.0]);
        let err = read_csv(&f.0, &ImportSpec::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("time_to_s"), "{err}");
    }

    #[test]
    fn txt_sections_of_different_length() {
        let f = TempFile::new(
            "kin.txt",
            "#Kinovea Trajectory data export\n#T X Y\n\n# a\n0.000 1,5 2,5 \n0.008 1,0 2,0 \n\n# b\n0.000 7,0 8,0 \n",
        );
        let raw = read_txt(&f.0, &ImportSpec::default()).unwrap();
        assert_eq!(raw.time, RawTime::Seconds(vec![0.0, 0.008]));
        assert_eq!(raw.points[0].1, [1.5, 1.0]);
        assert_eq!(raw.points[1].0, "b");
        assert!(raw.points[1].1[1].is_nan());
        let bad = TempFile::new(
            "kinbad.txt",
            "#Kinovea Trajectory data export\n# a\n0.0 1,0 x\n",
        );
        let err = read_txt(&bad.0, &ImportSpec::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains(":3:9:"), "{err}");
    }
}
