//! Tracker (Open Source Physics) data-export reader (FORMATS.md §1).
//!
//! Layout accepted (blank lines anywhere are skipped; CRLF or LF; an optional UTF-8 BOM):
//! ```text
//! #multi:                       <- optional; any line starting with '#' before the column row
//! D head D D lip_tip D D        <- optional track-name row (name over the track's first column),
//!                                  or a bare name such as `mass_B` for a single track
//! t D x D y D x D y D           <- column row: first name `t`; `_{1}` subscripts are removed;
//!                                  trailing delimiters allowed
//! 0.000000E0 D 3.06E-6 D ...    <- one row per frame; an empty cell is a missing value (NaN)
//! ```
//! * Delimiter `D`: sniffed from the column row, the first of TAB, `;`, `,`, space that occurs.
//!   With a space delimiter, track names must not contain spaces.
//! * Numbers: Java style (`0.03333333333333212`, `-3.401361196808672E-6`); with
//!   [`ImportSpec::decimal_comma`] `0,125` means 0.125 (not allowed with a `,` delimiter). `NaN`
//!   text is also read as missing.
//! * Points: each track contributes its `x` and `y` columns (other columns such as `vx`, `func`
//!   are ignored and not parsed). A track is named from the track-name row; without one the single
//!   point is called by the bare name line if present, else `point` (further x, y pairs get `_2`,
//!   `_3`, …).
//! * Conversion: t = `t0_s` + t (Tracker writes seconds, real frame times kept as they are);
//!   x_m = x·`units_to_m`; y_m = ±y·`units_to_m` (sign flipped only when `y_down = true`).

use std::borrow::Cow;
use std::path::Path;

use crate::error::{Error, Result};
use crate::import::common::unique_name;
use crate::import::{Format, ImportSpec, parse_finite, quote_cell, read_text};
use crate::trace::{PointTrack, Trace};

/// Delimiters tried, in order of preference.
const DELIMITERS: [char; 4] = ['\t', ';', ',', ' '];

/// How many non-blank lines may precede and include the column row.
const MAX_HEADER_LINES: usize = 4;

/// Tolerance of the optional `fps_hz` check against the `t` column's median step.
const FPS_CHECK_REL_TOL: f64 = 0.01;

/// A column name as Tracker means it: trimmed, unquoted, `_{...}` subscripts removed (`t_{1}` → `t`).
pub(crate) fn clean_name(s: &str) -> String {
    let s = s.trim().trim_matches('"');
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find("_{") {
        out.push_str(&rest[..i]);
        match rest[i..].find('}') {
            Some(j) => rest = &rest[i + j + 1..],
            None => {
                rest = &rest[i..];
                break;
            }
        }
    }
    out.push_str(rest);
    out.trim().to_owned()
}

/// Tracker's own sniffing, not `common::sniff_delimiter`: Tracker never quotes cells, so a quote
/// in a track name must not hide a delimiter (and no crate sniffs a delimiter from one line).
fn sniff_delimiter(line: &str) -> Option<char> {
    DELIMITERS.into_iter().find(|d| line.contains(*d))
}

/// Index (into `lines`, blank lines already removed) and delimiter of the column row: the first of
/// the first [`MAX_HEADER_LINES`] lines not starting with `#` whose first field is `t` and whose
/// next line, if any, starts with a number.
pub(crate) fn find_column_row(lines: &[&str]) -> Option<(usize, char)> {
    for (i, line) in lines.iter().enumerate().take(MAX_HEADER_LINES) {
        if line.trim_start().starts_with('#') {
            continue;
        }
        let Some(delim) = sniff_delimiter(line) else {
            continue;
        };
        if clean_name(line.split(delim).next().unwrap_or("")) != "t" {
            continue;
        }
        let next_ok = lines.get(i + 1).is_none_or(|next| {
            let first = next.split(delim).next().unwrap_or("");
            let first = if delim == ',' {
                Cow::Borrowed(first)
            } else {
                Cow::Owned(first.replace(',', "."))
            };
            parse_finite(&first).is_some()
        });
        if next_ok {
            return Some((i, delim));
        }
    }
    None
}

/// A cell: `Ok(None)` when empty or `NaN` (missing), `Ok(Some(v))` for a finite number.
/// Tracker's own, not `common::parse_cell`: that one also reads TrackMate's `ø` as missing, which in
/// a Tracker export is a bad cell.
fn parse_cell(cell: &str, decimal_comma: bool) -> std::result::Result<Option<f64>, ()> {
    let cell = cell.trim();
    if cell.is_empty() || cell.eq_ignore_ascii_case("nan") {
        return Ok(None);
    }
    let mut text = Cow::Borrowed(cell);
    if decimal_comma {
        text = Cow::Owned(text.replace(',', "."));
    }
    if text.contains('\u{2212}') {
        // Some Java locales write U+2212 MINUS SIGN.
        text = Cow::Owned(text.replace('\u{2212}', "-"));
    }
    parse_finite(&text).map(Some).ok_or(())
}

/// One point being assembled from a track's columns.
struct Columns {
    base: Option<String>,
    x: Option<usize>,
    y: Option<usize>,
}

/// The table's layout: where the column row is, its delimiter and names, and each point's columns.
struct Layout {
    /// Index of the column row in the non-blank lines.
    index: usize,
    /// 1-based file line of the column row.
    line: usize,
    delim: char,
    /// Column names ([`clean_name`]), trailing empty names removed.
    header: Vec<String>,
    /// `(point name, x column, y column)`.
    columns: Vec<(String, usize, usize)>,
}

/// Read a Tracker export into a [`Trace`]: one point per track with x and y columns, named as
/// described in the module docs, times from the `t` column. Uses `units_to_m`, `y_down`,
/// `decimal_comma`, `t0_s` and, as a check only, `fps_hz` of `spec`; ignores `points`.
///
/// Returns N = number of data rows ≥ 1 samples, `t_s` strictly increasing.
///
/// # Errors
/// * [`Error::Io`] — cannot read `path`;
/// * [`Error::Input`] — no column row starting with `t` in the first lines, no x/y column pair, no
///   data rows, `decimal_comma` with a `,` delimiter, or a median time step more than 1 % away from
///   1/`fps_hz` when `fps_hz` is given;
/// * [`Error::Parse`] — more than one track-name line, a row with fewer fields than the column row
///   (or extra non-empty fields), a missing, non-increasing or non-numeric time, or a non-numeric
///   x/y cell (`file:line:column: field x (track head): expected a number or an empty cell, found "abc"`);
/// * [`super::ImportError`] — settings out of range or meant for DLTdv ([`ImportSpec::validate`]).
pub fn read(path: &Path, spec: &ImportSpec) -> Result<Trace> {
    spec.validate(Format::Tracker)?;
    let text = read_text(path)?;
    // (1-based line number, text without CR), blank lines removed.
    let lines: Vec<(usize, &str)> = text
        .split('\n')
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)))
        .filter(|(_, l)| !l.trim().is_empty())
        .collect();
    let layout = layout(path, &lines, spec)?;
    let (t_s, xs, ys) = read_rows(path, &lines[layout.index + 1..], &layout, spec)?;
    check_fps(path, &t_s, spec)?;
    let points = layout
        .columns
        .into_iter()
        .zip(xs.into_iter().zip(ys))
        .map(|((name, _, _), (x_m, y_m))| PointTrack { name, x_m, y_m })
        .collect();
    Ok(Trace { t_s, points })
}

/// Find the column row among the non-blank `lines`, read the track names above it and map the
/// x/y columns to points.
fn layout(path: &Path, lines: &[(usize, &str)], spec: &ImportSpec) -> Result<Layout> {
    let texts: Vec<&str> = lines
        .iter()
        .take(MAX_HEADER_LINES + 1)
        .map(|(_, l)| *l)
        .collect();
    let Some((index, delim)) = find_column_row(&texts) else {
        return Err(Error::input(
            path,
            "not a Tracker export: no column row starting with `t` (then x, y, ...; TAB, `;`, `,` \
             or space delimited) followed by a numeric row in the first lines",
        ));
    };
    if spec.decimal_comma && delim == ',' {
        return Err(Error::input(
            path,
            "decimal_comma is set but the file is `,` delimited: the two cannot be told apart; \
             re-export with a `;` or TAB delimiter",
        ));
    }
    let (line, column_text) = lines[index];
    let name_row = track_name_row(path, &lines[..index])?;
    let mut header: Vec<String> = column_text.split(delim).map(clean_name).collect();
    while header.last().is_some_and(|h| h.is_empty()) {
        header.pop();
    }
    let col_track = column_tracks(name_row, delim, header.len());
    let columns = point_columns(&header, &col_track);
    if columns.is_empty() {
        return Err(Error::parse(
            path,
            line,
            0,
            format!(
                "expected a track with both an x and a y column; columns: {}",
                header.join(", ")
            ),
        ));
    }
    Ok(Layout {
        index,
        line,
        delim,
        header,
        columns,
    })
}

/// The track-name row of the preamble: `#` lines are markers (`#multi:`), at most one other line.
fn track_name_row<'a>(
    path: &Path,
    preamble: &[(usize, &'a str)],
) -> Result<Option<(usize, &'a str)>> {
    let mut name_row: Option<(usize, &str)> = None;
    for &(line, text) in preamble {
        if text.trim_start().starts_with('#') {
            continue;
        }
        if name_row.is_some() {
            return Err(Error::parse(
                path,
                line,
                0,
                "unexpected line before the column row: expected at most `#multi:` \
                 and one track-name row there",
            ));
        }
        name_row = Some((line, text));
    }
    Ok(name_row)
}

/// Track name over each of `ncols` columns: the last non-empty name at or left of it.
fn column_tracks(
    name_row: Option<(usize, &str)>,
    delim: char,
    ncols: usize,
) -> Vec<Option<String>> {
    match name_row {
        None => vec![None; ncols],
        Some((_, text)) if !text.contains(delim) => vec![Some(text.trim().to_owned()); ncols],
        Some((_, text)) => {
            let fields: Vec<&str> = text.split(delim).map(str::trim).collect();
            let mut current: Option<String> = None;
            (0..ncols)
                .map(|j| {
                    if let Some(f) = fields.get(j).filter(|f| !f.is_empty()) {
                        current = Some(f.trim_matches('"').to_owned());
                    }
                    current.clone()
                })
                .collect()
        }
    }
}

/// `(point name, x column, y column)` for every track with both an `x` and a `y` column, named
/// after the track (`point` without one; `_2`, `_3` ... when taken).
fn point_columns(header: &[String], col_track: &[Option<String>]) -> Vec<(String, usize, usize)> {
    let mut groups: Vec<Columns> = Vec::new();
    for j in 1..header.len() {
        let slot_is_x = match header[j].as_str() {
            "x" => true,
            "y" => false,
            _ => continue,
        };
        let base = &col_track[j];
        let reuse = groups.last().is_some_and(|g| {
            &g.base == base
                && if slot_is_x {
                    g.x.is_none()
                } else {
                    g.y.is_none()
                }
        });
        if !reuse {
            groups.push(Columns {
                base: base.clone(),
                x: None,
                y: None,
            });
        }
        if let Some(g) = groups.last_mut() {
            if slot_is_x {
                g.x = Some(j);
            } else {
                g.y = Some(j);
            }
        }
    }
    let mut columns: Vec<(String, usize, usize)> = Vec::new();
    for g in &groups {
        let (Some(x), Some(y)) = (g.x, g.y) else {
            continue;
        };
        let base = g.base.clone().unwrap_or_else(|| "point".to_owned());
        let taken: Vec<String> = columns.iter().map(|c| c.0.clone()).collect();
        columns.push((unique_name(&taken, &base), x, y));
    }
    columns
}

/// Times (`t0_s` added) and each point's x, y in metres from the data rows after the column row.
type Rows = (Vec<f64>, Vec<Vec<f64>>, Vec<Vec<f64>>);

/// Parse the data `rows` (non-blank lines after the column row) of a table with `layout`.
fn read_rows(
    path: &Path,
    rows: &[(usize, &str)],
    layout: &Layout,
    spec: &ImportSpec,
) -> Result<Rows> {
    let n = layout.columns.len();
    let (mut t_s, mut xs, mut ys) = (Vec::new(), vec![Vec::new(); n], vec![Vec::new(); n]);
    let y_sign = if spec.y_down.unwrap_or(false) {
        -1.0
    } else {
        1.0
    };
    let scale = spec.units_to_m.unwrap_or(1.0);
    let mut prev_t: Option<f64> = None;
    for &(line, text) in rows {
        let fields = row_fields(path, line, text, layout)?;
        let bad = |j: usize, what: &str| bad_field(path, line, layout, &fields, j, what);
        let t = match parse_cell(fields[0], spec.decimal_comma) {
            Ok(Some(t)) => t,
            _ => return Err(bad(0, "a time in seconds")),
        };
        if let Some(p) = prev_t.filter(|&p| t <= p) {
            return Err(Error::parse(
                path,
                line,
                1,
                format!(
                    "field t: time {t} s is not after the previous row's {p} s (expected \
                     strictly increasing times)"
                ),
            ));
        }
        prev_t = Some(t);
        t_s.push(spec.t0_s + t);
        for (k, &(_, cx, cy)) in layout.columns.iter().enumerate() {
            let x = parse_cell(fields[cx], spec.decimal_comma)
                .map_err(|()| bad(cx, "a number or an empty cell"))?;
            let y = parse_cell(fields[cy], spec.decimal_comma)
                .map_err(|()| bad(cy, "a number or an empty cell"))?;
            xs[k].push(x.map_or(f64::NAN, |x| x * scale));
            ys[k].push(y.map_or(f64::NAN, |y| y_sign * y * scale));
        }
    }
    if t_s.is_empty() {
        return Err(Error::input(
            path,
            format!("no data rows after the column row (line {})", layout.line),
        ));
    }
    Ok((t_s, xs, ys))
}

/// A data row's fields: at least as many as the column row, any extra ones empty.
fn row_fields<'a>(
    path: &Path,
    line: usize,
    text: &'a str,
    layout: &Layout,
) -> Result<Vec<&'a str>> {
    let ncols = layout.header.len();
    let fields: Vec<&str> = text.split(layout.delim).collect();
    if fields.len() < ncols || fields[ncols..].iter().any(|f| !f.trim().is_empty()) {
        return Err(Error::parse(
            path,
            line,
            0,
            format!(
                "expected {ncols} fields like the column row (line {}), found {}",
                layout.line,
                fields.len()
            ),
        ));
    }
    Ok(fields)
}

/// The error for field `j` of a row: `field x (track head): expected <what>, found "..."`.
fn bad_field(
    path: &Path,
    line: usize,
    layout: &Layout,
    fields: &[&str],
    j: usize,
    what: &str,
) -> Error {
    let label = match layout.columns.iter().find(|(_, x, y)| *x == j || *y == j) {
        Some((name, _, _)) => format!("{} (track {name})", layout.header[j]),
        None => layout.header[j].clone(),
    };
    Error::parse(
        path,
        line,
        j + 1,
        format!(
            "field {label}: expected {what}, found {}",
            quote_cell(fields[j].trim())
        ),
    )
}

/// With `fps_hz` set: [`Error::Input`] unless the median step of `t_s` is within
/// [`FPS_CHECK_REL_TOL`] of 1/`fps_hz`.
fn check_fps(path: &Path, t_s: &[f64], spec: &ImportSpec) -> Result<()> {
    let Some(fps) = spec.fps_hz else {
        return Ok(());
    };
    let summary = super::describe(&Trace {
        t_s: t_s.to_vec(),
        points: Vec::new(),
    });
    let dt = summary.dt_median_s;
    if dt.is_finite() && (dt * fps - 1.0).abs() > FPS_CHECK_REL_TOL {
        return Err(Error::input(
            path,
            format!(
                "the t column's median step {} s ({} fps) disagrees with fps_hz = {fps} \
                 by more than {} % (fps_hz is only a check for Tracker files; remove it to \
                 use the file's times)",
                crate::names::significant(dt, 4),
                crate::names::significant(1.0 / dt, 6),
                FPS_CHECK_REL_TOL * 100.0
            ),
        ));
    }
    Ok(())
}

/// Write `trace` as a Tracker "Export Data" text file (FORMATS.md §1 layout: `#multi:` when
/// there is more than one point, a track-name row, a column row `t<TAB>x<TAB>y<TAB>...` with
/// trailing delimiters, TAB delimited, LF line ends): the inverse of [`read`] with the default
/// spec. Values in metres and seconds with Rust's shortest round-trip formatting; NaN as an
/// empty cell, as Tracker writes a missing step. Read back with the default spec it gives the same
/// trace bit for bit (point names included; a single point is called by its track name).
///
/// # Errors
/// [`Error::Input`] if the trace breaks its invariants or a point name is empty, starts with `#`,
/// has surrounding spaces or contains a TAB or a line break; [`Error::Io`].
pub fn write(path: &Path, trace: &Trace) -> Result<()> {
    trace
        .check()
        .map_err(|m| Error::input(path, format!("cannot write trace: {m}")))?;
    if let Some(p) = trace.points.iter().find(|p| {
        p.name.contains(['\t', '\n', '\r'])
            || p.name.trim() != p.name
            || p.name.is_empty()
            || p.name.starts_with('#')
    }) {
        return Err(Error::input(
            path,
            format!(
                "cannot write point name {:?} into a TAB-delimited Tracker file",
                p.name
            ),
        ));
    }
    let mut out = String::new();
    if trace.points.len() > 1 {
        out.push_str("#multi:\n");
    }
    // Name over each track's x column: `\thead\t\ttip\t\t`.
    out.push('\t');
    for p in &trace.points {
        out.push_str(&p.name);
        out.push_str("\t\t");
    }
    out.push('\n');
    out.push_str("t\t");
    for _ in &trace.points {
        out.push_str("x\ty\t");
    }
    out.push('\n');
    let cell = |v: f64| {
        if v.is_nan() {
            String::new()
        } else {
            format!("{v}")
        }
    };
    for k in 0..trace.len() {
        out.push_str(&format!("{}\t", trace.t_s[k]));
        for p in &trace.points {
            out.push_str(&cell(p.x_m[k]));
            out.push('\t');
            out.push_str(&cell(p.y_m[k]));
            out.push('\t');
        }
        out.push('\n');
    }
    crate::io::write_atomic(path, out.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str, content: &str) -> crate::import::TempFile {
        crate::import::TempFile::new(&format!("tracker_{name}.txt"), content)
    }

    fn read_str(name: &str, content: &str) -> Result<Trace> {
        let f = temp(name, content);
        read(&f.0, &ImportSpec::default())
    }

    fn names(t: &Trace) -> Vec<&str> {
        t.points.iter().map(|p| p.name.as_str()).collect()
    }

    #[test]
    fn subscripts_are_removed() {
        assert_eq!(clean_name(" t_{1} "), "t");
        assert_eq!(clean_name("x_{12}"), "x");
        assert_eq!(clean_name("\"y\""), "y");
        assert_eq!(clean_name("mass_B"), "mass_B");
        assert_eq!(clean_name("x_{1"), "x_{1");
    }

    #[test]
    fn multi_track_export_with_empty_cells_and_trailing_delimiters() {
        let t = read_str(
            "multi",
            "#multi:\n\thead\t\tlip_tip\t\t\nt\tx\ty\tx\ty\t\n\
             0.000000E0\t3.061379E-6\t-1.904484E-4\t-1.401455E-3\t-5.999148E-3\n\
             1.000000E-4\t\t\t\t\n\
             2.000000E-4\t1.0E-6\t2.0E-6\t\t\n",
        )
        .unwrap();
        assert_eq!(names(&t), ["head", "lip_tip"]);
        assert_eq!(t.t_s, [0.0, 1e-4, 2e-4]);
        let head = t.point("head").unwrap();
        assert_eq!(head.x_m[0], 3.061379E-6);
        assert_eq!(head.y_m[0], -1.904484E-4);
        assert!(head.x_m[1].is_nan() && head.y_m[1].is_nan());
        assert_eq!(head.x_m[2], 1.0E-6);
        let tip = t.point("lip_tip").unwrap();
        assert_eq!(tip.y_m[0], -5.999148E-3);
        assert!(tip.x_m[2].is_nan() && tip.y_m[2].is_nan());
        assert_eq!(t.nan_count(), 6);
    }

    #[test]
    fn plain_header_crlf_single_point() {
        let t = read_str(
            "plain",
            "t\tx\ty\r\n0.0\t0.4143889733848767\t-1.4155257921331112\r\n\
             0.03333333333333212\t0.41\t-3.401361196808672E-6\r\n",
        )
        .unwrap();
        assert_eq!(names(&t), ["point"]);
        assert_eq!(t.t_s, [0.0, 0.03333333333333212]);
        assert_eq!(
            t.points[0].y_m,
            [-1.4155257921331112, -3.401361196808672E-6]
        );
    }

    #[test]
    fn space_and_comma_delimiters_with_trailing_delimiters() {
        // FORMATS.md §1: SPACE and `,` are export-dialog delimiters; every name and value row
        // ends with the delimiter.
        let t = read_str(
            "space",
            "#multi:\n head  tip  \nt x y x y \n0.0 1.5E-3 2 3 4 \n0.1  2 3 4 \n",
        )
        .unwrap();
        assert_eq!(names(&t), ["head", "tip"]);
        assert_eq!(t.points[0].x_m[0], 1.5e-3);
        assert!(
            t.points[0].x_m[1].is_nan(),
            "empty field between two spaces"
        );
        let t = read_str(
            "comma",
            "#multi:\r\n,head,,tip,,\r\nt,x,y,x,y,\r\n0.0,1,2,,,\r\n0.1,1,2,3,4,\r\n",
        )
        .unwrap();
        assert_eq!(names(&t), ["head", "tip"]);
        assert!(t.points[1].x_m[0].is_nan());
        assert_eq!(t.points[1].y_m[1], 4.0);
    }

    #[test]
    fn bare_name_subscripts_and_func_column() {
        let t = read_str(
            "bare",
            "mass_A\r\nt_{1}\tx_{1}\ty_{1}\tfunc\r\n0.0\t0.17\t-0.57\tnot-a-number-is-fine\r\n",
        )
        .unwrap();
        assert_eq!(names(&t), ["mass_A"]);
        assert_eq!(t.points[0].x_m, [0.17]);
    }

    #[test]
    fn several_pairs_without_names_get_suffixes() {
        let t = read_str("pairs", "t x y x y\n0 1 2 3 4\n").unwrap();
        assert_eq!(names(&t), ["point", "point_2"]);
        assert_eq!(t.points[1].y_m, [4.0]);
    }

    #[test]
    fn extra_track_columns_are_ignored() {
        let t = read_str(
            "vx",
            "#multi:\n;mass A;;;mass B;;\nt;x;y;vx;x;y;\n0;1;2;abc;3;4\n",
        )
        .unwrap();
        assert_eq!(names(&t), ["mass A", "mass B"]);
        assert_eq!(t.point("mass B").unwrap().x_m, [3.0]);
    }

    #[test]
    fn decimal_comma_semicolon() {
        let f = temp("comma", "t;x;y;\n0,0;1,5;\u{2212}2,25\n0,1;;\n");
        let spec = ImportSpec {
            decimal_comma: true,
            units_to_m: Some(0.01),
            ..ImportSpec::default()
        };
        let t = read(&f.0, &spec).unwrap();
        assert_eq!(t.t_s, [0.0, 0.1]);
        assert_eq!(t.points[0].x_m[0], 1.5 * 0.01);
        assert_eq!(t.points[0].y_m[0], -2.25 * 0.01);
        assert!(t.points[0].x_m[1].is_nan());
        // Without the flag the first comma decimal (the time on line 2) is a parse error.
        let msg = read(&f.0, &ImportSpec::default()).unwrap_err().to_string();
        assert!(
            msg.contains(":2:1: field t: expected a time in seconds, found \"0,0\""),
            "{msg}"
        );
    }

    #[test]
    fn decimal_comma_with_comma_delimiter_is_refused() {
        let f = temp("commacomma", "t,x,y\n0,1,2\n");
        let spec = ImportSpec {
            decimal_comma: true,
            ..ImportSpec::default()
        };
        let msg = read(&f.0, &spec).unwrap_err().to_string();
        assert!(msg.contains("cannot be told apart"), "{msg}");
    }

    #[test]
    fn bad_number_names_line_column_and_field() {
        let err = read_str(
            "bad",
            "#multi:\n\thead\t\ttip\t\nt\tx\ty\tx\ty\n0\t1\t2\t3\t4\n1\t1\t2\t3x\t4\n",
        )
        .unwrap_err();
        assert!(matches!(
            err,
            Error::Parse {
                line: 5,
                column: 4,
                ..
            }
        ));
        let msg = err.to_string();
        assert!(
            msg.ends_with(
                ":5:4: field x (track tip): expected a number or an empty cell, found \"3x\""
            ),
            "{msg}"
        );
    }

    #[test]
    fn time_errors() {
        let msg = read_str("tmiss", "t\tx\ty\n0\t1\t2\n\t1\t2\n")
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains(":3:1: field t: expected a time in seconds"),
            "{msg}"
        );
        let msg = read_str("tback", "t\tx\ty\n0\t1\t2\n0\t1\t2\n")
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains(":3:1: field t: time 0 s is not after"),
            "{msg}"
        );
    }

    #[test]
    fn short_row_and_structure_errors() {
        let msg = read_str("short", "t\tx\ty\n0\t1\n")
            .unwrap_err()
            .to_string();
        assert!(msg.contains(":2:0: expected 3 fields"), "{msg}");
        let msg = read_str("nodata", "t\tx\ty\t\n").unwrap_err().to_string();
        assert!(msg.contains("no data rows"), "{msg}");
        let msg = read_str("noxy", "t\tvx\n0\t1\n").unwrap_err().to_string();
        assert!(
            msg.contains("expected a track with both an x and a y column"),
            "{msg}"
        );
        let msg = read_str("two", "a\nb\nt\tx\ty\n0\t1\t2\n")
            .unwrap_err()
            .to_string();
        assert!(msg.contains(":2:0: unexpected line"), "{msg}");
        let msg = read_str("none", "time\tx\n0\t1\n").unwrap_err().to_string();
        assert!(msg.contains("not a Tracker export"), "{msg}");
        let msg = read_str("empty", "").unwrap_err().to_string();
        assert!(msg.contains("not a Tracker export"), "{msg}");
    }

    #[test]
    fn fps_is_a_check_only() {
        let f = temp("fps", "t\tx\ty\n0\t1\t2\n0.1\t1\t2\n0.2\t1\t2\n");
        let ok = ImportSpec {
            fps_hz: Some(10.0),
            y_down: Some(true),
            t0_s: 1.0,
            ..ImportSpec::default()
        };
        let t = read(&f.0, &ok).unwrap();
        assert_eq!(t.t_s, [1.0, 1.1, 1.2]);
        assert_eq!(t.points[0].y_m, [-2.0; 3]);
        let bad = ImportSpec {
            fps_hz: Some(30.0),
            ..ImportSpec::default()
        };
        let msg = read(&f.0, &bad).unwrap_err().to_string();
        assert!(msg.contains("fps_hz = 30"), "{msg}");
    }

    #[test]
    fn find_column_row_skips_preamble() {
        assert_eq!(
            find_column_row(&["#multi:", "\thead\t", "t\tx\ty\t", "0\t1\t2"]),
            Some((2, '\t'))
        );
        assert_eq!(find_column_row(&["t,x,y", "0,1,2"]), Some((0, ',')));
        assert_eq!(find_column_row(&["t x y", "a b c"]), None);
    }
}
