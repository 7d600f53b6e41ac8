//! The canonical trace CSV: what wiperlab writes after an import and reads back bit for bit.
//!
//! ```text
//! t_s,head_x_m,head_y_m,tip_x_m,tip_y_m[,<other>_x_m,<other>_y_m ...][,<extra> ...]
//! 0,3.061379e-6,-1.904484e-4,-1.401455e-3,-5.999148e-3
//! ```
//! * Comma delimited, `.` decimal, LF line ends, one header line, one row per sample.
//! * `t_s` in seconds, positions in metres, physical y up (the [`Trace`] conventions).
//! * Columns: `head` and `tip` first when present, then the other points in trace order, then
//!   optional extra columns ([`ExtraColumn`], e.g. the model state `wiperlab simulate` writes) whose
//!   names do not end in `_x_m` or `_y_m`; a reader of the trace skips them.
//! * Numbers: Rust's shortest representation that parses back to the same `f64` (plain decimal for
//!   1e-4 ≤ |v| < 1e15, otherwise `1.5e-5` style); missing = `NaN`.
//! * Names containing `,` or `"` are quoted per RFC 4180 (the `csv` crate).

use std::path::Path;

use crate::error::{Error, Result};
use crate::import::common::{csv_header, open_csv};
use crate::import::{csv_error, quote_cell, record_line};
use crate::trace::{PointTrack, Role, Trace};

/// Shortest round-trip text of `v`: plain decimal in [1e-4, 1e15), exponent form otherwise,
/// `NaN` for any NaN.
fn format_f64(v: f64) -> String {
    let mut s = String::new();
    push_f64(&mut s, v);
    s
}

/// [`format_f64`] appended to `out`.
fn push_f64(out: &mut String, v: f64) {
    use std::fmt::Write as _;
    // Writing into a String cannot fail.
    let _ = if v.is_nan() {
        out.write_str("NaN")
    } else if v == 0.0 || (1e-4..1e15).contains(&v.abs()) || v.is_infinite() {
        write!(out, "{v}")
    } else {
        write!(out, "{v:e}")
    };
}

/// A column after the points: numbers (written as the positions are) or labels. Its name must not
/// end in `_x_m` or `_y_m` (those name points).
#[derive(Debug, Clone, Copy)]
pub enum ExtraColumn<'a> {
    /// A numeric column: name (with its unit, e.g. `theta_rad`) and one value per sample.
    Numbers(&'a str, &'a [f64]),
    /// A text column: name and one label per sample (no `,` or `"` needed, but quoted if present).
    Labels(&'a str, &'a [&'a str]),
}

impl ExtraColumn<'_> {
    fn name(&self) -> &str {
        match self {
            ExtraColumn::Numbers(n, _) | ExtraColumn::Labels(n, _) => n,
        }
    }

    fn len(&self) -> usize {
        match self {
            ExtraColumn::Numbers(_, v) => v.len(),
            ExtraColumn::Labels(_, v) => v.len(),
        }
    }

    fn cell(&self, k: usize) -> String {
        match self {
            ExtraColumn::Numbers(_, v) => format_f64(v[k]),
            ExtraColumn::Labels(_, v) => v[k].to_owned(),
        }
    }
}

/// Whether `name` would be read as a point column.
fn is_point_column(name: &str) -> bool {
    name.ends_with("_x_m") || name.ends_with("_y_m")
}

/// The column order of the canonical CSV: indices into `trace.points`, `head` and `tip` first.
fn column_order(trace: &Trace) -> Vec<usize> {
    let mut order: Vec<usize> = Role::ALL
        .iter()
        .filter_map(|r| trace.points.iter().position(|p| p.name == r.name()))
        .collect();
    for i in 0..trace.points.len() {
        if !order.contains(&i) {
            order.push(i);
        }
    }
    order
}

/// Write `trace` as the canonical CSV (module docs) to `path`, replacing an existing file.
///
/// # Errors
/// * [`Error::Input`] naming `path` if the trace breaks its invariants ([`Trace::check`]: a point
///   with a different number of samples than `t_s`, non-increasing or non-finite time), a point
///   name is empty, or two points share a name;
/// * [`Error::Io`] if the file cannot be created or written.
pub fn write_trace_csv(path: &Path, trace: &Trace) -> Result<()> {
    write_trace_csv_with(path, trace, &[])
}

/// The canonical CSV of `trace` as bytes (what [`write_trace_csv`] writes); `path` only names the
/// destination in errors.
///
/// # Errors
/// As [`write_trace_csv`], without the file's.
pub fn trace_csv_bytes(path: &Path, trace: &Trace) -> Result<Vec<u8>> {
    trace_csv_bytes_with(path, trace, &[])
}

/// Write `trace` followed by the columns `extra` (module docs) to `path`, replacing an existing
/// file. Reading the file back gives `trace`; the extra columns are skipped.
///
/// # Errors
/// As [`write_trace_csv`]; [`Error::Input`] naming `path` too when an extra column's length is not
/// the trace's, its name is empty, `t_s`, a point column's (`_x_m`, `_y_m`) or repeated.
pub fn write_trace_csv_with(path: &Path, trace: &Trace, extra: &[ExtraColumn]) -> Result<()> {
    check_trace(path, trace, extra)?;
    crate::io::write_atomic_with(path, |w| write_rows(w, path, trace, extra))
}

/// Checks the extra columns against `trace` ([`write_trace_csv_with`]).
fn check_extra(path: &Path, trace: &Trace, extra: &[ExtraColumn]) -> Result<()> {
    for (i, c) in extra.iter().enumerate() {
        let name = c.name();
        let bad = if name.is_empty() || name == "t_s" || is_point_column(name) {
            Some("a name that is not empty, t_s or a point's (_x_m, _y_m)".to_owned())
        } else if extra[..i].iter().any(|d| d.name() == name) {
            Some("a name of its own (it repeats)".to_owned())
        } else if c.len() != trace.t_s.len() {
            Some(format!("{} values (it has {})", trace.t_s.len(), c.len()))
        } else {
            None
        };
        if let Some(expected) = bad {
            return Err(Error::input(
                path,
                format!("cannot write trace: extra column {name:?}: expected {expected}"),
            ));
        }
    }
    Ok(())
}

/// [`trace_csv_bytes`] followed by the columns `extra`.
///
/// # Errors
/// As [`write_trace_csv_with`], without the file's.
pub fn trace_csv_bytes_with(path: &Path, trace: &Trace, extra: &[ExtraColumn]) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    write_trace_csv_to(&mut bytes, path, trace, extra)?;
    Ok(bytes)
}

/// [`trace_csv_bytes_with`] streamed into `w` (e.g. stdout), row by row.
///
/// # Errors
/// As [`write_trace_csv_with`]; a failed write of `w` is [`Error::Io`] naming `path`.
pub fn write_trace_csv_to(
    w: &mut dyn std::io::Write,
    path: &Path,
    trace: &Trace,
    extra: &[ExtraColumn],
) -> Result<()> {
    check_trace(path, trace, extra)?;
    write_rows(w, path, trace, extra)
}

/// The checks before writing: the extra columns, the trace's invariants, the points' names.
fn check_trace(path: &Path, trace: &Trace, extra: &[ExtraColumn]) -> Result<()> {
    check_extra(path, trace, extra)?;
    trace
        .check()
        .map_err(|m| Error::input(path, format!("cannot write trace: {m}")))?;
    for (i, p) in trace.points.iter().enumerate() {
        if p.name.is_empty() {
            return Err(Error::input(
                path,
                "cannot write trace: a point has no name",
            ));
        }
        if trace.points[..i].iter().any(|q| q.name == p.name) {
            return Err(Error::input(
                path,
                format!("cannot write trace: two points are named {:?}", p.name),
            ));
        }
    }
    Ok(())
}

/// The header and one row per sample of a checked trace, into `w`; each cell is formatted into one
/// reused buffer, so memory stays that of one row whatever the trace's length.
fn write_rows(
    w: &mut dyn std::io::Write,
    path: &Path,
    trace: &Trace,
    extra: &[ExtraColumn],
) -> Result<()> {
    let order = column_order(trace);
    let mut w = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(w);
    let mut header = vec!["t_s".to_owned()];
    for &i in &order {
        let name = &trace.points[i].name;
        header.push(format!("{name}_x_m"));
        header.push(format!("{name}_y_m"));
    }
    header.extend(extra.iter().map(|c| c.name().to_owned()));
    w.write_record(&header)
        .map_err(|e| csv_error(path, "write", e))?;
    let mut cell = String::new();
    let mut field = |w: &mut csv::Writer<_>, v: f64| {
        cell.clear();
        push_f64(&mut cell, v);
        w.write_field(&cell)
    };
    for (k, &t) in trace.t_s.iter().enumerate() {
        let mut row = || -> csv::Result<()> {
            field(&mut w, t)?;
            for &i in &order {
                let p = &trace.points[i];
                field(&mut w, p.x_m[k])?;
                field(&mut w, p.y_m[k])?;
            }
            for c in extra {
                w.write_field(c.cell(k))?;
            }
            w.write_record(None::<&[u8]>)
        };
        row().map_err(|e| csv_error(path, "write", e))?;
    }
    w.flush().map_err(|e| Error::io(path, "cannot write", e))
}

/// Read a canonical trace CSV (module docs) written by [`write_trace_csv`] or by hand.
///
/// Cells `NaN` (any case) or empty are missing values. Returns the points in column order; time
/// must be finite and strictly increasing. Extra columns after the points are skipped
/// ([`read_trace_csv_with_extras`] names them).
///
/// # Errors
/// * [`Error::Io`] — cannot open/read `path`;
/// * [`Error::Input`] — empty file or no data rows;
/// * [`Error::Parse`] — header not `t_s` followed by `<name>_x_m,<name>_y_m` pairs and then
///   columns not named like points (line 1 and the column), a row with a different field count
///   (line, column 0), a non-number cell
///   (`file:line:column: field head_x_m: expected a number or NaN, found "abc"`), a missing or
///   non-increasing time.
pub fn read_trace_csv(path: &Path) -> Result<Trace> {
    read_trace_csv_with_extras(path).map(|(trace, _)| trace)
}

/// [`read_trace_csv`] and the names of the extra columns it skipped, in file order.
///
/// # Errors
/// As [`read_trace_csv`].
pub fn read_trace_csv_with_extras(path: &Path) -> Result<(Trace, Vec<String>)> {
    let mut reader = open_csv(path)?;
    let mut records = reader.records();
    let (header_line, names) = csv_header(
        path,
        &mut records,
        "empty file: expected a header t_s,<name>_x_m,<name>_y_m,...",
    )?;
    let mut points = header_points(path, header_line, &names)?;
    let extras = names[1 + 2 * points.len()..].to_vec();
    let mut t_s: Vec<f64> = Vec::new();
    for (row, record) in records.enumerate() {
        let record = record.map_err(|e| csv_error(path, "read", e))?;
        let line = record_line(path, &record, header_line + 1 + row, names.len())?;
        let cell = |j: usize| row_cell(path, line, &record, &names, j);
        let t = cell(0)?;
        check_time(path, line, t, t_s.last().copied())?;
        t_s.push(t);
        for (k, p) in points.iter_mut().enumerate() {
            p.x_m.push(cell(1 + 2 * k)?);
            p.y_m.push(cell(2 + 2 * k)?);
        }
    }
    if t_s.is_empty() {
        return Err(Error::input(path, "no data rows after the header"));
    }
    Ok((Trace { t_s, points }, extras))
}

/// The empty points named by a header `t_s,<name>_x_m,<name>_y_m,...[,<extra>...]` (names unique);
/// the points end at the first column not named `<name>_x_m` or `<name>_y_m`, and no such column
/// may follow.
fn header_points(path: &Path, header_line: usize, names: &[String]) -> Result<Vec<PointTrack>> {
    if names.first().map(String::as_str) != Some("t_s") {
        return Err(Error::parse(
            path,
            header_line,
            1,
            format!(
                "expected the first column t_s, found {}",
                quote_cell(names.first().map_or("", String::as_str))
            ),
        ));
    }
    let n_point_cols = names[1..].iter().take_while(|n| is_point_column(n)).count();
    if let Some(k) = names[1 + n_point_cols..]
        .iter()
        .position(|n| is_point_column(n))
    {
        let col = 2 + n_point_cols + k;
        return Err(Error::parse(
            path,
            header_line,
            col,
            format!(
                "point column {} after the other columns: expected every <name>_x_m,<name>_y_m \
                 pair right after t_s",
                quote_cell(&names[col - 1])
            ),
        ));
    }
    let mut points: Vec<PointTrack> = Vec::new();
    for (k, pair) in names[1..=n_point_cols].chunks(2).enumerate() {
        let col = 2 + 2 * k;
        let Some(name) = pair[0].strip_suffix("_x_m").filter(|n| !n.is_empty()) else {
            return Err(Error::parse(
                path,
                header_line,
                col,
                format!("expected <name>_x_m, found {}", quote_cell(&pair[0])),
            ));
        };
        let Some(y_col) = pair.get(1) else {
            return Err(Error::parse(
                path,
                header_line,
                col,
                format!(
                    "expected t_s followed by pairs <name>_x_m,<name>_y_m: no {name}_y_m after \
                     {name}_x_m"
                ),
            ));
        };
        if y_col.strip_suffix("_y_m") != Some(name) {
            return Err(Error::parse(
                path,
                header_line,
                col + 1,
                format!("expected {name}_y_m, found {}", quote_cell(y_col)),
            ));
        }
        if points.iter().any(|p| p.name == name) {
            return Err(Error::parse(
                path,
                header_line,
                col,
                format!("point {name:?} appears twice"),
            ));
        }
        points.push(PointTrack {
            name: name.to_owned(),
            x_m: Vec::new(),
            y_m: Vec::new(),
        });
    }
    Ok(points)
}

/// Cell `j` of a data row: a number (infinities included), NaN when empty or `NaN`.
fn row_cell(
    path: &Path,
    line: usize,
    record: &csv::StringRecord,
    names: &[String],
    j: usize,
) -> Result<f64> {
    let text = record.get(j).unwrap_or("").trim();
    if text.is_empty() || text.eq_ignore_ascii_case("nan") {
        return Ok(f64::NAN);
    }
    text.parse::<f64>()
        .ok()
        .filter(|v| !v.is_nan())
        .ok_or_else(|| {
            Error::parse(
                path,
                line,
                j + 1,
                format!(
                    "field {}: expected a number or NaN, found {}",
                    names[j],
                    quote_cell(text)
                ),
            )
        })
}

/// [`Error::Parse`] unless the time `t` of the row on `line` is finite and after `prev`.
fn check_time(path: &Path, line: usize, t: f64, prev: Option<f64>) -> Result<()> {
    if !t.is_finite() {
        return Err(Error::parse(
            path,
            line,
            1,
            format!("field t_s: expected a finite time, found {t}"),
        ));
    }
    if let Some(prev) = prev
        && t <= prev
    {
        return Err(Error::parse(
            path,
            line,
            1,
            format!(
                "field t_s: time {t} s is not after the previous row's {prev} s (expected \
                 strictly increasing times)"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_path(name: &str) -> crate::import::TempFile {
        crate::import::TempFile::at(&format!("canonical_{name}.csv"))
    }

    #[test]
    fn formats_round_trip() {
        for v in [
            0.0,
            -0.0,
            1e-4,
            9.999999999999999e-5,
            0.1 + 0.2,
            -3.401361196808672E-6,
            1.5e-5,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            1e15,
            123456.789,
        ] {
            let s = format_f64(v);
            assert_eq!(
                s.parse::<f64>().unwrap().to_bits(),
                v.to_bits(),
                "{v} -> {s}"
            );
        }
        assert_eq!(format_f64(f64::NAN), "NaN");
        assert_eq!(format_f64(1.5e-5), "1.5e-5");
        assert_eq!(format_f64(0.25), "0.25");
    }

    #[test]
    fn round_trip_orders_roles_first_and_keeps_nan() {
        let trace = Trace {
            t_s: vec![0.0, 1e-4, 1e-4 + 1e-4 * (1.0 + f64::EPSILON)],
            points: vec![
                PointTrack {
                    name: "marker, left".into(),
                    x_m: vec![1.0, 2.0, 3.0],
                    y_m: vec![f64::NAN, 0.1, 0.2],
                },
                PointTrack {
                    name: "tip".into(),
                    x_m: vec![-1e-300, f64::NAN, 0.3],
                    y_m: vec![-0.006, f64::NAN, -0.0],
                },
                PointTrack {
                    name: "head".into(),
                    x_m: vec![0.1 + 0.2, 1e20, -7.5e-12],
                    y_m: vec![1.0 / 3.0, 2.0 / 3.0, f64::NAN],
                },
            ],
        };
        let f = temp_path("rt");
        write_trace_csv(&f.0, &trace).unwrap();
        let text = std::fs::read_to_string(&f.0).unwrap();
        assert!(
            text.starts_with(
                "t_s,head_x_m,head_y_m,tip_x_m,tip_y_m,\"marker, left_x_m\",\"marker, left_y_m\"\n"
            ),
            "{text}"
        );
        let back = read_trace_csv(&f.0).unwrap();
        let names: Vec<_> = back.points.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["head", "tip", "marker, left"]);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back.t_s), bits(&trace.t_s));
        for p in &trace.points {
            let q = back.point(&p.name).unwrap();
            assert_eq!(bits(&q.x_m), bits(&p.x_m), "{}", p.name);
            assert_eq!(bits(&q.y_m), bits(&p.y_m), "{}", p.name);
        }
    }

    /// Extra columns after the points: written as the positions are (numbers) or as given
    /// (labels), skipped and named when read back; names that would read as points are refused.
    #[test]
    fn extra_columns_are_written_after_the_points_and_skipped_on_reading() {
        let trace = Trace {
            t_s: vec![0.0, 0.5],
            points: vec![PointTrack {
                name: "head".into(),
                x_m: vec![1.0, 2.0],
                y_m: vec![3.0, f64::NAN],
            }],
        };
        let f = temp_path("extra");
        let theta = [0.1 + 0.2, -1.5e-5];
        let phase = ["stick", "slip+"];
        let extra = [
            ExtraColumn::Numbers("theta_rad", &theta),
            ExtraColumn::Labels("phase", &phase),
        ];
        write_trace_csv_with(&f.0, &trace, &extra).unwrap();
        let text = std::fs::read_to_string(&f.0).unwrap();
        assert_eq!(
            text,
            "t_s,head_x_m,head_y_m,theta_rad,phase\n0,1,3,0.30000000000000004,stick\n0.5,2,NaN,-1.5e-5,slip+\n"
        );
        let (back, extras) = read_trace_csv_with_extras(&f.0).unwrap();
        assert_eq!(extras, ["theta_rad", "phase"]);
        assert_eq!(back.points.len(), 1);
        assert_eq!(back.points[0].x_m, [1.0, 2.0]);
        for (name, len) in [
            ("tip_y_m", 2),
            ("t_s", 2),
            ("", 2),
            ("theta_rad", 2),
            ("ok", 1),
        ] {
            let v = vec![0.0; len];
            let cols = [
                ExtraColumn::Numbers("theta_rad", &theta),
                ExtraColumn::Numbers(name, &v),
            ];
            let msg = write_trace_csv_with(&f.0, &trace, &cols)
                .unwrap_err()
                .to_string();
            assert!(msg.contains("extra column"), "{name:?}: {msg}");
        }
    }

    #[test]
    fn write_rejects_broken_traces() {
        let f = temp_path("broken");
        let trace = Trace {
            t_s: vec![0.0, 1.0],
            points: vec![PointTrack {
                name: "head".into(),
                x_m: vec![0.0],
                y_m: vec![0.0, 0.0],
            }],
        };
        let msg = write_trace_csv(&f.0, &trace).unwrap_err().to_string();
        assert!(msg.contains("\"head\" has 1 x and 2 y samples"), "{msg}");
    }

    #[test]
    fn read_errors_name_line_and_column() {
        let f = temp_path("errs");
        let cases = [
            (
                "time,a_x_m,a_y_m\n0,1,2\n",
                ":1:1: expected the first column t_s",
            ),
            ("t_s,a_x_m,b_y_m\n0,1,2\n", ":1:3: expected a_y_m"),
            ("t_s,a_x_m\n0,1\n", ":1:2: expected t_s followed by pairs"),
            (
                "t_s,a_x_m,theta_rad\n0,1,2\n",
                ":1:2: expected t_s followed by pairs <name>_x_m,<name>_y_m: no a_y_m",
            ),
            (
                "t_s,a_x_m,a_y_m,phase,b_x_m,b_y_m\n0,1,2,stick,3,4\n",
                ":1:5: point column \"b_x_m\" after the other columns",
            ),
            (
                "t_s,a_x_m,a_y_m\n0,1,2\n1,x,2\n",
                ":3:2: field a_x_m: expected a number or NaN, found \"x\"",
            ),
            ("t_s,a_x_m,a_y_m\n0,1,2\n1,1\n", ":3:0: expected 3 fields"),
            (
                "t_s,a_x_m,a_y_m\n0,1,2\n0,1,2\n",
                ":3:1: field t_s: time 0 s is not after",
            ),
            (
                "t_s,a_x_m,a_y_m\nNaN,1,2\n",
                ":2:1: field t_s: expected a finite time",
            ),
            ("t_s,a_x_m,a_y_m\n", "no data rows"),
            ("", "empty file"),
        ];
        for (content, needle) in cases {
            std::fs::write(&f.0, content).unwrap();
            let msg = read_trace_csv(&f.0).unwrap_err().to_string();
            assert!(msg.contains(needle), "{content:?}: {msg}");
        }
        std::fs::write(&f.0, "t_s,a_x_m,a_y_m\r\n0,,nan\r\n").unwrap();
        let t = read_trace_csv(&f.0).unwrap();
        assert!(t.points[0].x_m[0].is_nan() && t.points[0].y_m[0].is_nan());
    }
}
