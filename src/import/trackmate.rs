//! Fiji TrackMate spot-table reader (FORMATS.md §6).
//!
//! * TrackMate ≤ 6 ("Spots in tracks statistics"): one header line `Label,ID,TRACK_ID,QUALITY,
//!   POSITION_X,POSITION_Y,POSITION_Z,POSITION_T,FRAME,...`, no unit row.
//! * TrackMate ≥ 7: up to four header lines — feature keys, names, short names (each omitted when
//!   equal to the previous), units in parentheses (`(micron)`, `(sec)`, empty if none).
//!
//! `,` delimiter, no quoting, `.` decimal; missing values are empty fields (GUI) or `ø` (headless
//! exporter). Files are written in Java's platform charset: a non-UTF-8 file is decoded as
//! Windows-1252 (so `ø` is byte 0xF8) and this is reported.
//!
//! One point per track, named `track<TRACK_ID>`, over every frame from the first to the last
//! `FRAME`; NaN where a track has no spot. Spots without a track id are skipped (counted).
//! Time: `FRAME`/`fps_hz` when `fps_hz` is set, else from `POSITION_T` when the unit row gives
//! it a time unit (frame interval = POSITION_T/FRAME), else an error. Coordinates: the unit row's
//! length unit (micron → 1e-6 m); `pixel` → `m_per_px` required; no unit row → `units_to_m` or
//! `m_per_px` required. Image y runs down (TrackMate's image coordinates).

use std::collections::BTreeMap;
use std::path::Path;

use crate::error::{Error, Result};
use crate::import::ImportSpec;
use crate::import::common::{
    RawTime, RawTrace, RawUnits, Table, TextEncoding, length_unit_m, numbered_lines, parse_cell,
    read_decoded, time_unit_s,
};
use crate::import::sleap::MAX_SPAN_PER_ROW;

/// Column indices of a spot table.
struct SpotColumns {
    track: usize,
    x: usize,
    y: usize,
    frame: usize,
    /// `POSITION_T`, if present.
    t: Option<usize>,
}

/// Frame and track of every spot row.
struct Spots {
    /// `FRAME` of each row (a non-negative integer).
    frames: Vec<f64>,
    /// `TRACK_ID` of each row, `None` for a spot without a track.
    track_of: Vec<Option<i64>>,
    /// Rows without a track.
    untracked: usize,
}

/// The frame range of the tracked spots: first and last `FRAME`, and the number of frames.
struct FrameSpan {
    first: f64,
    last: f64,
    n: usize,
}

/// Tracks in order of first appearance: id and `(x, y, line of the spot)` per frame.
struct Tracks {
    order: Vec<i64>,
    pts: Vec<(Vec<f64>, Vec<f64>, Vec<usize>)>,
}

/// Read a TrackMate spot table (module docs) into a [`RawTrace`] in file units.
///
/// # Errors
/// [`Error::Io`]; [`Error::Parse`] for a missing `TRACK_ID`/`POSITION_X`/`POSITION_Y`/`FRAME`
/// column, a non-integer frame, a non-numeric position, a track with two spots in one frame (a
/// split/merge track: export the single-branch tracks); [`Error::Input`] for no spot with a track,
/// or neither `fps_hz` nor a time unit.
pub fn read(path: &Path, spec: &ImportSpec) -> Result<RawTrace> {
    let (text, enc) = read_decoded(path)?;
    let lines = numbered_lines(&text);
    let n_header = header_count(path, &lines)?;
    let (table, keys) = spot_table(path, &lines, n_header)?;
    let cols = spot_columns(path, &table, &keys)?;
    // The units row is the last header line when it has a parenthesised cell.
    let units: Option<&Vec<String>> = table
        .headers
        .iter()
        .skip(1)
        .map(|h| &h.1)
        .find(|cells| cells.iter().any(|c| c.starts_with('(')));
    let unit_of = |j: usize| units.and_then(|u| u.get(j)).map(|s| s.trim().to_owned());

    let xs = table.numbers(cols.x, false)?;
    let ys = table.numbers(cols.y, false)?;
    let spots = parse_spots(&table, &cols)?;
    let tracked: Vec<usize> = (0..table.rows.len())
        .filter(|&r| spots.track_of[r].is_some())
        .collect();
    let span = frame_span(path, &table, &spots, &tracked)?;
    let tracks = assemble_tracks(&table, &cols, &spots, &tracked, &span, &xs, &ys)?;
    let (first, last) = (span.first, span.last);
    let mut notes = vec![format!(
        "TrackMate ({} header line{}): {} spots in {} tracks, frames {first}–{last}, {} \
         spots without a track skipped",
        n_header,
        if n_header == 1 {
            ", ≤ 6 layout"
        } else {
            "s, ≥ 7 layout"
        },
        tracked.len(),
        tracks.order.len(),
        spots.untracked
    )];
    if enc == TextEncoding::Windows1252 {
        notes.push("encoding: not UTF-8, decoded as Windows-1252 (Java platform charset)".into());
    }
    let t_unit = cols.t.and_then(&unit_of);
    let time = time_base(path, spec, &table, &cols, t_unit, &spots, &span, &mut notes)?;
    let points = tracks
        .order
        .iter()
        .zip(tracks.pts)
        .map(|(id, (x, y, _))| (format!("track{id}"), x, y))
        .collect();
    Ok(RawTrace {
        time,
        points,
        units: coordinate_units(unit_of(cols.x)),
        y_down_default: true,
        notes,
    })
}

/// How many header lines: the first, plus up to three more whose `FRAME` cell is not a number.
fn header_count(path: &Path, lines: &[(usize, &str)]) -> Result<usize> {
    let nonblank: Vec<&str> = lines
        .iter()
        .map(|(_, l)| *l)
        .filter(|l| !l.trim().is_empty())
        .take(5)
        .collect();
    let Some(first) = nonblank.first() else {
        return Err(Error::input(
            path,
            "empty file: expected a TrackMate header LABEL,...",
        ));
    };
    let keys: Vec<String> = first
        .split(',')
        .map(|s| s.trim().to_ascii_uppercase())
        .collect();
    let Some(cx_key) = keys.iter().position(|k| k == "POSITION_X") else {
        return Err(Error::parse(
            path,
            lines
                .iter()
                .find(|(_, l)| !l.trim().is_empty())
                .map_or(1, |l| l.0),
            0,
            "expected a POSITION_X column in the TrackMate header",
        ));
    };
    // A spot row always has a FRAME number; header rows (names, short names, units) never do.
    let probe = keys.iter().position(|k| k == "FRAME").unwrap_or(cx_key);
    let mut n_header = 1;
    while n_header < nonblank.len().min(4) {
        let cell = nonblank[n_header]
            .split(',')
            .nth(probe)
            .unwrap_or("")
            .trim();
        if parse_cell(cell, false).is_ok_and(|v| v.is_some()) {
            break;
        }
        n_header += 1;
    }
    Ok(n_header)
}

/// The spot table with the feature keys (upper case) as its column names, and the keys.
fn spot_table<'a>(
    path: &'a Path,
    lines: &[(usize, &str)],
    n_header: usize,
) -> Result<(Table<'a>, Vec<String>)> {
    let mut table = Table::parse(path, lines, n_header, ',')?;
    // The keys as the table split them (quotes honoured), so indices match the rows.
    let keys: Vec<String> = table.headers[0]
        .1
        .iter()
        .map(|s| s.trim().to_ascii_uppercase())
        .collect();
    table.names = keys.clone();
    table.names.resize(table.rows[0].1.len(), String::new());
    Ok((table, keys))
}

/// The `TRACK_ID`, `POSITION_X`, `POSITION_Y`, `FRAME` (required) and `POSITION_T` columns.
fn spot_columns(path: &Path, table: &Table, keys: &[String]) -> Result<SpotColumns> {
    let hline = table.headers[0].0;
    let col = |key: &str| -> Result<usize> {
        keys.iter().position(|k| k == key).ok_or_else(|| {
            Error::parse(
                path,
                hline,
                0,
                format!("expected a {key} column in the TrackMate header"),
            )
        })
    };
    Ok(SpotColumns {
        track: col("TRACK_ID")?,
        x: col("POSITION_X")?,
        y: col("POSITION_Y")?,
        frame: col("FRAME")?,
        t: keys.iter().position(|k| k == "POSITION_T"),
    })
}

/// Every row's frame and track id (`None`: empty, `ø` or `None` cell).
fn parse_spots(table: &Table, cols: &SpotColumns) -> Result<Spots> {
    let mut frames = Vec::with_capacity(table.rows.len());
    let mut track_of = Vec::with_capacity(table.rows.len());
    let mut untracked = 0usize;
    for r in 0..table.rows.len() {
        match parse_cell(&table.rows[r].1[cols.frame], false) {
            Ok(Some(f)) if f >= 0.0 && f.fract() == 0.0 && f <= 1e8 => frames.push(f),
            _ => return Err(table.bad_cell(r, cols.frame, "a non-negative integer frame")),
        }
        let cell = table.rows[r].1[cols.track].trim();
        match parse_cell(cell, false) {
            Ok(Some(t)) if t.fract() == 0.0 => track_of.push(Some(t as i64)),
            Ok(None) => {
                untracked += 1;
                track_of.push(None)
            }
            _ if cell.eq_ignore_ascii_case("none") => {
                untracked += 1;
                track_of.push(None)
            }
            _ => {
                return Err(table.bad_cell(r, cols.track, "an integer track id or an empty cell"));
            }
        }
    }
    Ok(Spots {
        frames,
        track_of,
        untracked,
    })
}

/// The frame range of the `tracked` rows, refused when empty, implausibly long for the row count,
/// or too large to allocate for the number of tracks.
fn frame_span(path: &Path, table: &Table, spots: &Spots, tracked: &[usize]) -> Result<FrameSpan> {
    if tracked.is_empty() {
        return Err(Error::input(
            path,
            format!(
                "no spot belongs to a track ({} spots without TRACK_ID)",
                spots.untracked
            ),
        ));
    }
    let frames = &spots.frames;
    let first = tracked
        .iter()
        .map(|&r| frames[r])
        .fold(f64::INFINITY, f64::min);
    let last = tracked
        .iter()
        .map(|&r| frames[r])
        .fold(f64::NEG_INFINITY, f64::max);
    let n = (last - first) as usize + 1;
    if n > MAX_SPAN_PER_ROW * table.rows.len() + 1_000_000 {
        return Err(Error::input(
            path,
            format!(
                "FRAME runs from {first} to {last} with only {} rows: a corrupt frame?",
                table.rows.len()
            ),
        ));
    }
    let n_tracks = tracked
        .iter()
        .filter_map(|&r| spots.track_of[r])
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    crate::import::common::check_cells(path, n, n_tracks)?;
    Ok(FrameSpan { first, last, n })
}

/// Place every tracked spot at its frame in its track; two spots of a track in one frame are an
/// error.
fn assemble_tracks(
    table: &Table,
    cols: &SpotColumns,
    spots: &Spots,
    tracked: &[usize],
    span: &FrameSpan,
    xs: &[f64],
    ys: &[f64],
) -> Result<Tracks> {
    let n = span.n;
    let mut index: BTreeMap<i64, usize> = BTreeMap::new();
    let mut order: Vec<i64> = Vec::new();
    let mut pts: Vec<(Vec<f64>, Vec<f64>, Vec<usize>)> = Vec::new();
    for &r in tracked {
        let Some(id) = spots.track_of[r] else {
            continue;
        };
        let i = *index.entry(id).or_insert_with(|| {
            order.push(id);
            pts.push((vec![f64::NAN; n], vec![f64::NAN; n], vec![0; n]));
            pts.len() - 1
        });
        let k = (spots.frames[r] - span.first) as usize;
        if pts[i].2[k] != 0 {
            return Err(table.bad_cell(
                r,
                cols.frame,
                &format!(
                    "one spot per track and frame (track {id} already has a spot in frame {} on \
                     line {}; split/merge tracks are not a single trajectory)",
                    spots.frames[r], pts[i].2[k]
                ),
            ));
        }
        pts[i].2[k] = table.rows[r].0;
        pts[i].0[k] = xs[r];
        pts[i].1[k] = ys[r];
    }
    Ok(Tracks { order, pts })
}

/// The time axis: frames when `fps_hz` is set, else seconds from the median `POSITION_T`/`FRAME`
/// (which needs a time unit `t_unit` for `POSITION_T`); notes the derived frame interval.
#[allow(clippy::too_many_arguments)]
fn time_base(
    path: &Path,
    spec: &ImportSpec,
    table: &Table,
    cols: &SpotColumns,
    t_unit: Option<String>,
    spots: &Spots,
    span: &FrameSpan,
    notes: &mut Vec<String>,
) -> Result<RawTime> {
    let (first, n) = (span.first, span.n);
    if spec.fps_hz.is_some() {
        return Ok(RawTime::Frames((0..n).map(|k| first + k as f64).collect()));
    }
    let t_unit = t_unit.and_then(|u| time_unit_s(&u));
    let (Some(ct), Some(tu)) = (cols.t, t_unit) else {
        return Err(Error::input(
            path,
            "the spot table has frame numbers but no calibrated time (no POSITION_T unit): \
             set the frame rate (fps_hz in the import spec, --fps on the command line)",
        ));
    };
    let frames = &spots.frames;
    let ts = table.numbers(ct, false)?;
    let mut dts: Vec<f64> = (0..table.rows.len())
        .filter(|&r| frames[r] > 0.0 && ts[r].is_finite())
        .map(|r| ts[r] * tu / frames[r])
        .collect();
    dts.sort_by(f64::total_cmp);
    let Some(&dt) = dts
        .get(dts.len() / 2)
        .filter(|d| d.is_finite() && **d > 0.0)
    else {
        return Err(Error::input(
            path,
            "cannot derive the frame interval from POSITION_T/FRAME: set fps_hz",
        ));
    };
    notes.push(format!(
        "frame interval {} s from POSITION_T/FRAME (median over spots)",
        crate::names::significant(dt, 6)
    ));
    Ok(RawTime::Seconds(
        (0..n).map(|k| (first + k as f64) * dt).collect(),
    ))
}

/// The coordinate unit from the unit row's `POSITION_X` cell.
fn coordinate_units(unit: Option<String>) -> RawUnits {
    match unit {
        Some(u) if u.to_ascii_lowercase().contains("pixel") => RawUnits::Pixels,
        Some(u) => match length_unit_m(&u) {
            Some(f) => RawUnits::Known(f, u),
            None => RawUnits::Unknown,
        },
        None => RawUnits::Unknown,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::TempFile;

    #[test]
    fn trackmate7_four_line_header_latin1_missing() {
        let mut bytes = b"LABEL,ID,TRACK_ID,POSITION_X,POSITION_Y,POSITION_T,FRAME\n\
Label,Spot ID,Track ID,X,Y,T,Frame\n\
Label,Spot ID,Track ID,X,Y,T,Frame\n\
,,,(micron),(micron),(sec),\n"
            .to_vec();
        bytes.extend_from_slice(b"ID1,1,0,1.0,2.0,0.0,0\nID2,2,0,\xf8,3.0,0.5,1\nID3,3,\xf8,9,9,0.5,1\nID4,4,0,1.5,4.0,1.0,2\n");
        let f = TempFile::at("tm7.csv");
        std::fs::write(&f.0, &bytes).unwrap();
        let raw = read(&f.0, &ImportSpec::default()).unwrap();
        assert_eq!(raw.time, RawTime::Seconds(vec![0.0, 0.5, 1.0]));
        assert_eq!(raw.units, RawUnits::Known(1e-6, "(micron)".into()));
        assert_eq!(raw.points.len(), 1);
        assert!(raw.points[0].1[1].is_nan(), "ø is missing");
        assert_eq!(raw.points[0].2, [2.0, 3.0, 4.0]);
        assert!(
            raw.notes.iter().any(|n| n.contains("Windows-1252")),
            "{:?}",
            raw.notes
        );
        assert!(
            raw.notes[0].contains("1 spots without a track"),
            "{:?}",
            raw.notes
        );
    }

    #[test]
    fn corrupt_frame_is_refused_not_allocated() {
        let mut text = String::from("Label,ID,TRACK_ID,POSITION_X,POSITION_Y,FRAME\n");
        for id in 0..30 {
            text.push_str(&format!("ID{id},{id},{id},1,2,0\n"));
        }
        text.push_str("IDx,99,0,1,2,900000\n");
        let f = TempFile::new("tm_corrupt.csv", &text);
        let spec = ImportSpec {
            fps_hz: Some(10.0),
            ..ImportSpec::default()
        };
        let err = read(&f.0, &spec).unwrap_err().to_string();
        assert!(err.contains("exceed") && err.contains("corrupt"), "{err}");
    }

    #[test]
    fn trackmate6_needs_fps() {
        let f = TempFile::new(
            "tm6.csv",
            "Label,ID,TRACK_ID,QUALITY,POSITION_X,POSITION_Y,POSITION_Z,POSITION_T,FRAME\n\
             ID1,1,0,1,71.960,47.792,0,0,0\nID2,2,0,1,72.0,47.0,0,1,1\n",
        );
        let err = read(&f.0, &ImportSpec::default()).unwrap_err().to_string();
        assert!(err.contains("fps_hz"), "{err}");
        let spec = ImportSpec {
            fps_hz: Some(10.0),
            ..ImportSpec::default()
        };
        let raw = read(&f.0, &spec).unwrap();
        assert_eq!(raw.units, RawUnits::Unknown);
        assert_eq!(raw.points[0].1, [71.96, 72.0]);
    }
}
