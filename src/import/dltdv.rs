//! DLTdv `*xypts.csv` reader (FORMATS.md §3; DLTdv5–8, Hedrick lab).
//!
//! Layout: one header line `pt{i}_cam{j}_X,pt{i}_cam{j}_Y,...` (point-major: all cameras of pt1,
//! then pt2, …), then one row per video frame — row 1 is frame 1, there is no frame or time column.
//! Comma delimited, `.` decimal, `%.6f` pixel coordinates, the text `NaN` where a point was not
//! digitised.
//!
//! Conversion (one camera, [`ImportSpec::camera`]):
//! * t = `t0_s` + (frame − 1)/`fps_hz` (frame 1-based);
//! * x_m = (x_px − origin_x)·`m_per_px`;
//! * y_m = −(y_px − origin_y)·`m_per_px` when `y_down` (default: image rows, origin top-left),
//!   else (y_px − origin_y)·`m_per_px` (DLTdv5–7 measure y from the bottom edge; FORMATS.md §3).
//!
//! Points are named `pt{i}`; roles are assigned by [`super::read_trace`].

use std::path::Path;

use crate::error::{Error, Result};
use crate::import::common::{csv_header, open_csv};
use crate::import::{Format, ImportSpec, csv_error, parse_finite, quote_cell, record_line};
use crate::trace::{PointTrack, Trace};

/// Which coordinate a DLTdv column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Axis {
    X,
    Y,
}

/// Parse a DLTdv column name `pt{i}_cam{j}_X` / `_Y` into `(i, j, axis)` (i, j ≥ 1).
pub(crate) fn parse_header_name(name: &str) -> Option<(usize, usize, Axis)> {
    let rest = name.trim().strip_prefix("pt")?;
    let (point, rest) = rest.split_once("_cam")?;
    let (camera, axis) = rest.split_once('_')?;
    let number = |s: &str| {
        if !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()) {
            s.parse::<usize>().ok().filter(|&n| n >= 1)
        } else {
            None
        }
    };
    let axis = match axis {
        "X" => Axis::X,
        "Y" => Axis::Y,
        _ => return None,
    };
    Some((number(point)?, number(camera)?, axis))
}

/// One point's column indices (0-based) for the selected camera.
struct PointColumns {
    point: usize,
    x: Option<usize>,
    y: Option<usize>,
}

/// Read a DLTdv `xypts.csv` into a [`Trace`] with points `pt1`, `pt2`, … in metres (y up unless
/// `y_down = false`) and times from `fps_hz`. Uses `fps_hz`, `m_per_px` (both required),
/// `origin_px`, `y_down`, `camera` and `t0_s` of `spec`; ignores `points`.
///
/// Returns N = number of data rows ≥ 1 samples; every point of the camera, NaN where DLTdv wrote
/// `NaN`.
///
/// # Errors
/// * [`Error::Io`] — cannot open/read `path`;
/// * [`Error::Input`] — `fps_hz` or `m_per_px` missing (the message names the field), empty file,
///   header without data rows, no columns for the requested camera (lists the cameras present);
/// * [`Error::Parse`] — a header cell that is not `pt{i}_cam{j}_X|Y` (line 1), a row whose field
///   count differs from the header (`line`, column 0), or a cell that is neither a finite number nor
///   `NaN` (`file:line:column: field pt2_cam1_X: expected a number or NaN, found "abc"`);
/// * [`super::ImportError`] — settings out of range ([`ImportSpec::validate`]).
pub fn read(path: &Path, spec: &ImportSpec) -> Result<Trace> {
    spec.validate(Format::Dltdv)?;
    let (fps, scale) = required_settings(path, spec)?;
    let mut reader = open_csv(path)?;
    let mut records = reader.records();
    let (header_line, names) = csv_header(
        path,
        &mut records,
        "empty file: expected a DLTdv header line pt1_cam1_X,pt1_cam1_Y,...",
    )?;
    let names: Vec<String> = names.iter().map(|h| h.trim().to_owned()).collect();
    let columns = camera_columns(path, header_line, &names, spec.camera)?;
    let [ox, oy] = spec.origin_px;
    let y_sign = if spec.y_down.unwrap_or(true) {
        -1.0
    } else {
        1.0
    };
    let mut t_s = Vec::new();
    let mut xs: Vec<Vec<f64>> = vec![Vec::new(); columns.len()];
    let mut ys: Vec<Vec<f64>> = vec![Vec::new(); columns.len()];
    let mut values = vec![f64::NAN; names.len()];
    for (row, record) in records.enumerate() {
        let record = record.map_err(|e| csv_error(path, "read", e))?;
        let line = record_line(path, &record, header_line + 1 + row, names.len())?;
        parse_row(path, line, &record, &names, &mut values)?;
        for (k, &(_, cx, cy)) in columns.iter().enumerate() {
            xs[k].push((values[cx] - ox) * scale);
            ys[k].push(y_sign * (values[cy] - oy) * scale);
        }
        t_s.push(spec.t0_s + row as f64 / fps);
    }
    if t_s.is_empty() {
        return Err(Error::input(
            path,
            "no data rows after the header (DLTdv writes one row per video frame)",
        ));
    }
    let points = columns
        .iter()
        .zip(xs.into_iter().zip(ys))
        .map(|(&(point, _, _), (x_m, y_m))| PointTrack {
            name: format!("pt{point}"),
            x_m,
            y_m,
        })
        .collect();
    Ok(Trace { t_s, points })
}

/// `fps_hz` and `m_per_px`, which a DLTdv file cannot do without.
fn required_settings(path: &Path, spec: &ImportSpec) -> Result<(f64, f64)> {
    let fps = spec.fps_hz.ok_or_else(|| {
        Error::input(
            path,
            "a DLTdv xypts file has no time column: set the camera's frame rate (--fps on the \
             command line, fps_hz in an import spec or job)",
        )
    })?;
    let scale = spec.m_per_px.ok_or_else(|| {
        Error::input(
            path,
            "a DLTdv xypts file is in pixels: set the scale (--m-per-px or --scale-points-px with \
             --scale-distance-m on the command line, m_per_px in an import spec or job)",
        )
    })?;
    Ok((fps, scale))
}

/// `(point, x column, y column)` of every point of `camera`, in order of first appearance; every
/// header cell must be a DLTdv column name, each point needs one X and one Y column.
fn camera_columns(
    path: &Path,
    header_line: usize,
    names: &[String],
    camera: usize,
) -> Result<Vec<(usize, usize, usize)>> {
    let mut points: Vec<PointColumns> = Vec::new();
    let mut cameras: Vec<usize> = Vec::new();
    for (col, name) in names.iter().enumerate() {
        let Some((point, cam, axis)) = parse_header_name(name) else {
            return Err(Error::parse(
                path,
                header_line,
                col + 1,
                format!(
                    "expected a DLTdv column name pt{{i}}_cam{{j}}_X or pt{{i}}_cam{{j}}_Y, found {}",
                    quote_cell(name)
                ),
            ));
        };
        if !cameras.contains(&cam) {
            cameras.push(cam);
        }
        if cam != camera {
            continue;
        }
        let idx = match points.iter().position(|p| p.point == point) {
            Some(i) => i,
            None => {
                points.push(PointColumns {
                    point,
                    x: None,
                    y: None,
                });
                points.len() - 1
            }
        };
        let slot = match axis {
            Axis::X => &mut points[idx].x,
            Axis::Y => &mut points[idx].y,
        };
        if slot.is_some() {
            return Err(Error::parse(
                path,
                header_line,
                col + 1,
                format!("column {name} appears twice"),
            ));
        }
        *slot = Some(col);
    }
    complete_columns(path, header_line, points, cameras, camera)
}

/// The points' column pairs, or the error for a camera without columns or a point without X or Y.
fn complete_columns(
    path: &Path,
    header_line: usize,
    points: Vec<PointColumns>,
    mut cameras: Vec<usize>,
    camera: usize,
) -> Result<Vec<(usize, usize, usize)>> {
    if points.is_empty() {
        cameras.sort_unstable();
        let list: Vec<String> = cameras.iter().map(|c| format!("cam{c}")).collect();
        return Err(Error::input(
            path,
            format!(
                "no columns for camera {camera} (camera = {camera}); cameras in the file: {}",
                list.join(", ")
            ),
        ));
    }
    let mut columns = Vec::with_capacity(points.len());
    for p in &points {
        let missing = match (p.x, p.y) {
            (Some(x), Some(y)) => {
                columns.push((p.point, x, y));
                continue;
            }
            (None, _) => "X",
            (_, None) => "Y",
        };
        return Err(Error::parse(
            path,
            header_line,
            0,
            format!(
                "pt{}_cam{camera}_{missing} is missing (expected an X and a Y column per point)",
                p.point
            ),
        ));
    }
    Ok(columns)
}

/// Parse every cell of a data row into `values`: a finite number, or NaN for the text `NaN`.
fn parse_row(
    path: &Path,
    line: usize,
    record: &csv::StringRecord,
    names: &[String],
    values: &mut [f64],
) -> Result<()> {
    for (col, cell) in record.iter().enumerate() {
        let cell = cell.trim();
        values[col] = if cell.eq_ignore_ascii_case("nan") {
            f64::NAN
        } else {
            parse_finite(cell).ok_or_else(|| {
                Error::parse(
                    path,
                    line,
                    col + 1,
                    format!(
                        "field {}: expected a number or NaN, found {}",
                        names[col],
                        quote_cell(cell)
                    ),
                )
            })?
        };
    }
    Ok(())
}

/// Write `trace` as a DLTdv `xypts.csv` for one camera: the inverse of [`read`] with the same
/// `spec` (`m_per_px`, `origin_px`, `y_down`). Points become `pt1`, `pt2`, … in trace order; NaN is
/// written as `NaN`; pixel values with Rust's shortest round-trip formatting (DLTdv itself writes
/// `%.6f`, which [`read`] accepts too). The time axis is not written (DLTdv has none): it must be
/// `t0_s + k/fps_hz` for [`read`] to give it back.
///
/// # Errors
/// [`Error::Input`] if `m_per_px` is not set or the trace breaks its invariants; [`Error::Io`].
pub fn write(path: &Path, trace: &Trace, spec: &ImportSpec) -> Result<()> {
    let scale = spec.resolved_m_per_px()?.ok_or_else(|| {
        Error::input(
            path,
            "writing DLTdv pixels needs m_per_px in the import spec",
        )
    })?;
    trace
        .check()
        .map_err(|m| Error::input(path, format!("cannot write trace: {m}")))?;
    let [ox, oy] = spec.origin_px;
    let y_sign = if spec.y_down.unwrap_or(true) {
        -1.0
    } else {
        1.0
    };
    let mut out = String::new();
    let header: Vec<String> = (1..=trace.points.len())
        .flat_map(|i| [format!("pt{i}_cam1_X"), format!("pt{i}_cam1_Y")])
        .collect();
    out.push_str(&header.join(","));
    out.push('\n');
    let cell = |v: f64| {
        if v.is_nan() {
            "NaN".to_owned()
        } else {
            format!("{v}")
        }
    };
    for k in 0..trace.len() {
        let row: Vec<String> = trace
            .points
            .iter()
            .flat_map(|p| {
                [
                    cell(p.x_m[k] / scale + ox),
                    cell(y_sign * p.y_m[k] / scale + oy),
                ]
            })
            .collect();
        out.push_str(&row.join(","));
        out.push('\n');
    }
    crate::io::write_atomic(path, out.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str, content: &str) -> crate::import::TempFile {
        crate::import::TempFile::new(&format!("dltdv_{name}_xypts.csv"), content)
    }

    fn spec() -> ImportSpec {
        ImportSpec {
            fps_hz: Some(100.0),
            m_per_px: Some(0.5),
            origin_px: [10.0, 20.0],
            ..ImportSpec::default()
        }
    }

    #[test]
    fn header_names() {
        assert_eq!(parse_header_name("pt12_cam3_Y"), Some((12, 3, Axis::Y)));
        for bad in [
            "pt1_cam1_Z",
            "pt_cam1_X",
            "pt0_cam1_X",
            "pt1_X",
            "p1_cam1_X",
            "pt1_cam+1_X",
        ] {
            assert_eq!(parse_header_name(bad), None, "{bad}");
        }
    }

    #[test]
    fn converts_pixels_frames_and_nan() {
        let f = temp(
            "convert",
            "pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y\n\
             12.000000,16.000000,NaN,NaN\n\
             10.000000,20.000000,11.000000,22.000000\n",
        );
        let t = read(&f.0, &spec()).unwrap();
        assert_eq!(t.t_s, [0.0, 0.01]);
        let p1 = t.point("pt1").unwrap();
        // (12 − 10)·0.5 = 1; y down: −(16 − 20)·0.5 = 2.
        assert_eq!((p1.x_m[0], p1.y_m[0]), (1.0, 2.0));
        let p2 = t.point("pt2").unwrap();
        assert!(p2.x_m[0].is_nan() && p2.y_m[0].is_nan());
        assert_eq!((p2.x_m[1], p2.y_m[1]), (0.5, -1.0));
    }

    #[test]
    fn y_up_and_t0_and_second_camera() {
        let f = temp(
            "cam2",
            "pt1_cam1_X,pt1_cam1_Y,pt1_cam2_X,pt1_cam2_Y\n1,2,30,40\n1,2,NaN,NaN\n1,2,31,41\n",
        );
        let s = ImportSpec {
            camera: 2,
            y_down: Some(false),
            t0_s: 5.0,
            ..spec()
        };
        let t = read(&f.0, &s).unwrap();
        assert_eq!(t.t_s, [5.0, 5.01, 5.02]);
        let p = t.point("pt1").unwrap();
        assert_eq!((p.x_m[0], p.y_m[0]), (10.0, 10.0));
        assert!(p.x_m[1].is_nan());
        let err = read(
            &f.0,
            &ImportSpec {
                camera: 3,
                ..spec()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("cameras in the file: cam1, cam2"), "{err}");
    }

    #[test]
    fn bad_number_names_line_column_and_field() {
        let f = temp(
            "badnum",
            "pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y\n1,2,3,4\n1,2,abc,4\n",
        );
        let err = read(&f.0, &spec()).unwrap_err();
        assert!(matches!(
            err,
            Error::Parse {
                line: 3,
                column: 3,
                ..
            }
        ));
        let msg = err.to_string();
        assert!(
            msg.ends_with(":3:3: field pt2_cam1_X: expected a number or NaN, found \"abc\""),
            "{msg}"
        );
    }

    #[test]
    fn empty_cell_and_inf_are_errors() {
        let f = temp("emptycell", "pt1_cam1_X,pt1_cam1_Y\n1,\n");
        let msg = read(&f.0, &spec()).unwrap_err().to_string();
        assert!(msg.contains(":2:2: field pt1_cam1_Y"), "{msg}");
        let f = temp("inf", "pt1_cam1_X,pt1_cam1_Y\nInf,1\n");
        let msg = read(&f.0, &spec()).unwrap_err().to_string();
        assert!(msg.contains(":2:1:"), "{msg}");
    }

    #[test]
    fn wrong_field_count_names_line() {
        let f = temp("count", "pt1_cam1_X,pt1_cam1_Y\n1,2\n1,2\n1,2,3\n");
        let err = read(&f.0, &spec()).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, Error::Parse { line: 4, .. }), "{msg}");
        assert!(
            msg.contains("expected 2 fields like the header, found 3"),
            "{msg}"
        );
    }

    #[test]
    fn bad_header_and_empty_files() {
        let f = temp("hdr", "pt1_cam1_X,frame\n1,2\n");
        let msg = read(&f.0, &spec()).unwrap_err().to_string();
        assert!(msg.contains(":1:2: expected a DLTdv column name"), "{msg}");
        let f = temp("noy", "pt1_cam1_X\n1\n");
        let msg = read(&f.0, &spec()).unwrap_err().to_string();
        assert!(msg.contains("pt1_cam1_Y is missing"), "{msg}");
        let f = temp("empty", "");
        let msg = read(&f.0, &spec()).unwrap_err().to_string();
        assert!(msg.contains("empty file"), "{msg}");
        let f = temp("norows", "pt1_cam1_X,pt1_cam1_Y\n");
        let msg = read(&f.0, &spec()).unwrap_err().to_string();
        assert!(msg.contains("no data rows"), "{msg}");
    }

    #[test]
    fn crlf_and_bom_are_accepted() {
        let f = temp(
            "crlf",
            "\u{feff}pt1_cam1_X,pt1_cam1_Y\r\n1,2\r\nNaN,NaN\r\n",
        );
        let t = read(&f.0, &spec()).unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t.nan_count(), 2);
    }

    #[test]
    fn missing_fps_or_scale_is_named() {
        let f = temp("nofps", "pt1_cam1_X,pt1_cam1_Y\n1,2\n");
        let err = read(
            &f.0,
            &ImportSpec {
                fps_hz: None,
                ..spec()
            },
        )
        .unwrap_err();
        assert!(matches!(err, Error::Input { .. }));
        let msg = err.to_string();
        assert!(msg.contains("fps_hz") && msg.contains("nofps"), "{msg}");
        let msg = read(
            &f.0,
            &ImportSpec {
                m_per_px: None,
                ..spec()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(msg.contains("m_per_px"), "{msg}");
    }
}
