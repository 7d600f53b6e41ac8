//! SLEAP analysis CSV reader (FORMATS.md §5).
//!
//! Header `track,frame_idx[,instance.score],<node>.x,<node>.y[,<node>.score],...`, then one row
//! **per instance** (long format): several rows share a `frame_idx` when several animals are in the
//! frame. `frame_idx` is 0-based (no time: `fps_hz` is required); x, y in pixels (image y down).
//! Empty fields are missing values; a row with no coordinates is a padding row for an empty frame.
//!
//! Result: the time axis runs over every frame from the first to the last `frame_idx`; points are
//! `<track>/<node>` (or `<node>` for untracked instances, at most one per frame). A node whose
//! `.score` is below [`ImportSpec::min_likelihood`] (default 0.6) becomes NaN (reported). The
//! score-less layout of third-party converters (SimBA's example) is read too.

use std::collections::BTreeMap;
use std::path::Path;

use crate::error::{Error, Result};
use crate::import::ImportSpec;
use crate::import::common::{
    RawTime, RawTrace, RawUnits, Table, numbered_lines, parse_cell, read_decoded,
};
use crate::import::deeplabcut::DEFAULT_MIN_LIKELIHOOD;

/// One node's x and y over the frame axis.
type Xy = (Vec<f64>, Vec<f64>);

/// Largest ratio of frame range to rows accepted (beyond 10⁶ frames).
pub(crate) const MAX_SPAN_PER_ROW: usize = 1000;

/// Largest frame index accepted (a frame axis longer than this is a corrupt file, not a video).
const MAX_FRAME: f64 = 1e8;

/// A node's columns: name, x, y and the optional score.
type Node = (String, usize, usize, Option<usize>);

/// Tracks assembled from the instance rows.
struct Instances {
    /// Track names in order of first appearance (empty = untracked).
    order: Vec<String>,
    /// Track → x, y per node over the frame axis.
    tracks: BTreeMap<String, Vec<Xy>>,
    /// Node samples set to NaN for a score below the cut-off.
    below: usize,
    /// Rows without any coordinate (empty frames).
    padding: usize,
}

/// Read a SLEAP analysis CSV (module docs) into a [`RawTrace`] in pixels.
///
/// # Errors
/// [`Error::Io`]; [`Error::Input`] for no data rows; [`Error::Parse`] (line, column, field) for a
/// header without `track`, `frame_idx` or any `<node>.x`/`.y` pair, a frame index that is not a
/// non-negative integer, a non-numeric coordinate or score, the same track twice in one frame.
pub fn read(path: &Path, spec: &ImportSpec) -> Result<RawTrace> {
    let (text, _) = read_decoded(path)?;
    let lines = numbered_lines(&text);
    let table = Table::parse(path, &lines, 1, ',')?;
    let (ct, cf, nodes) = columns(path, &table)?;
    let cutoff = spec.min_likelihood.unwrap_or(DEFAULT_MIN_LIKELIHOOD);
    let frames = frame_indices(&table, cf)?;
    let (first, last, n) = frame_span(path, &frames, table.rows.len())?;
    let cols = node_values(&table, &nodes)?;
    let n_tracks = table
        .rows
        .iter()
        .map(|(_, c)| c[ct].trim())
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    crate::import::common::check_cells(path, n, n_tracks * nodes.len())?;
    let frame_of: Vec<usize> = frames.iter().map(|f| (f - first) as usize).collect();
    let mut inst = instances(&table, ct, &frames, &frame_of, &cols, n, cutoff)?;
    let mut points = Vec::new();
    for t in &inst.order {
        if let Some(slots) = inst.tracks.remove(t) {
            for ((node, ..), (x, y)) in nodes.iter().zip(slots) {
                let name = if t.is_empty() {
                    node.clone()
                } else {
                    format!("{t}/{node}")
                };
                points.push((name, x, y));
            }
        }
    }
    let has_scores = nodes.iter().any(|n| n.3.is_some());
    let notes = vec![format!(
        "SLEAP: {} instance rows, {} empty-frame rows, {} tracks, frames {first}–{last}; {}",
        table.rows.len() - inst.padding,
        inst.padding,
        inst.order.len(),
        if has_scores {
            format!(
                "{} node samples with score < {cutoff} set to NaN",
                inst.below
            )
        } else {
            "no score columns (no likelihood cut-off applied)".to_owned()
        }
    )];
    Ok(RawTrace {
        time: RawTime::Frames((0..n).map(|k| first + k as f64).collect()),
        points,
        units: RawUnits::Pixels,
        y_down_default: true,
        notes,
    })
}

/// The `track` and `frame_idx` columns and the nodes: `<node>.x` with a matching `<node>.y` (and
/// `<node>.score` if present).
fn columns(path: &Path, table: &Table) -> Result<(usize, usize, Vec<Node>)> {
    let names = table.names();
    let hline = table.headers[0].0;
    let (Some(ct), Some(cf)) = (table.find("track"), table.find("frame_idx")) else {
        return Err(Error::parse(
            path,
            hline,
            0,
            format!(
                "expected columns track and frame_idx, found {}",
                names.join(", ")
            ),
        ));
    };
    let mut nodes: Vec<Node> = Vec::new();
    for (j, n) in names.iter().enumerate() {
        if let Some(node) = n.strip_suffix(".x") {
            let Some(cy) = table.find(&format!("{node}.y")) else {
                return Err(Error::parse(
                    path,
                    hline,
                    j + 1,
                    format!("column {n}: expected a {node}.y column to go with it"),
                ));
            };
            nodes.push((node.to_owned(), j, cy, table.find(&format!("{node}.score"))));
        }
    }
    if nodes.is_empty() {
        return Err(Error::parse(
            path,
            hline,
            0,
            format!(
                "expected <node>.x, <node>.y columns, found {}",
                names.join(", ")
            ),
        ));
    }
    Ok((ct, cf, nodes))
}

/// Every row's `frame_idx`: a non-negative integer up to [`MAX_FRAME`].
fn frame_indices(table: &Table, cf: usize) -> Result<Vec<f64>> {
    let mut frames = Vec::with_capacity(table.rows.len());
    for r in 0..table.rows.len() {
        match parse_cell(&table.rows[r].1[cf], false) {
            Ok(Some(f)) if f >= 0.0 && f.fract() == 0.0 && f <= MAX_FRAME => frames.push(f),
            _ => return Err(table.bad_cell(r, cf, "a non-negative integer frame index")),
        }
    }
    Ok(frames)
}

/// First and last frame and the frame count, refused when implausibly many for `rows` rows.
fn frame_span(path: &Path, frames: &[f64], rows: usize) -> Result<(f64, f64, usize)> {
    let first = frames.iter().copied().fold(f64::INFINITY, f64::min);
    let last = frames.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let n = (last - first) as usize + 1;
    if n > MAX_SPAN_PER_ROW * rows + 1_000_000 {
        return Err(Error::input(
            path,
            format!(
                "frame_idx runs from {first} to {last} but the file has only {rows} rows: expected \
                 a frame range of at most {MAX_SPAN_PER_ROW} × rows + 10⁶ (a corrupt frame index?)"
            ),
        ));
    }
    Ok((first, last, n))
}

/// x, y and score columns of every node (three per node; scores NaN without a score column).
fn node_values(table: &Table, nodes: &[Node]) -> Result<Vec<Vec<f64>>> {
    let mut v = Vec::new();
    for (_, cx, cy, cs) in nodes {
        v.push(table.numbers(*cx, false)?);
        v.push(table.numbers(*cy, false)?);
        v.push(match cs {
            Some(c) => table.numbers(*c, false)?,
            None => vec![f64::NAN; table.rows.len()],
        });
    }
    Ok(v)
}

/// Place every instance row at its frame (`frame_of`, 0-based on the `n`-frame axis) in its
/// track; node samples scored below `cutoff` stay NaN; one instance per track and frame.
fn instances(
    table: &Table,
    ct: usize,
    frames: &[f64],
    frame_of: &[usize],
    cols: &[Vec<f64>],
    n: usize,
    cutoff: f64,
) -> Result<Instances> {
    let n_nodes = cols.len() / 3;
    let mut inst = Instances {
        order: Vec::new(),
        tracks: BTreeMap::new(),
        below: 0,
        padding: 0,
    };
    let mut seen: BTreeMap<(String, usize), usize> = BTreeMap::new();
    for r in 0..table.rows.len() {
        let k = frame_of[r];
        let any = (0..n_nodes).any(|i| !cols[3 * i][r].is_nan() || !cols[3 * i + 1][r].is_nan());
        let track = table.rows[r].1[ct].trim().to_owned();
        if !any {
            inst.padding += 1;
            continue;
        }
        if let Some(prev) = seen.insert((track.clone(), k), table.rows[r].0) {
            return Err(table.bad_cell(
                r,
                ct,
                &format!(
                    "one instance per track and frame (frame {} already has track {track:?} on \
                     line {prev}; name the tracks in SLEAP before exporting)",
                    frames[r]
                ),
            ));
        }
        let slots = inst.tracks.entry(track.clone()).or_insert_with(|| {
            inst.order.push(track.clone());
            vec![(vec![f64::NAN; n], vec![f64::NAN; n]); n_nodes]
        });
        for (i, slot) in slots.iter_mut().enumerate() {
            let (x, y, s) = (cols[3 * i][r], cols[3 * i + 1][r], cols[3 * i + 2][r]);
            if s < cutoff && !(x.is_nan() && y.is_nan()) {
                inst.below += 1;
                continue;
            }
            slot.0[k] = x;
            slot.1[k] = y;
        }
    }
    Ok(inst)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::TempFile;

    #[test]
    fn long_format_with_scores_and_padding() {
        let f = TempFile::new(
            "sleap.csv",
            "track,frame_idx,instance.score,head.x,head.y,head.score\n\
             m1,0,0.9,1.0,2.0,0.95\nm2,0,0.9,5.0,6.0,0.2\n,1,,,,\nm1,2,0.9,3.0,4.0,0.99\n",
        );
        let raw = read(&f.0, &ImportSpec::default()).unwrap();
        assert_eq!(raw.time, RawTime::Frames(vec![0.0, 1.0, 2.0]));
        assert_eq!(raw.points.len(), 2);
        assert_eq!(raw.points[0].0, "m1/head");
        assert_eq!(raw.points[0].1[0], 1.0);
        assert!(raw.points[0].1[1].is_nan());
        assert!(
            raw.points[1].1.iter().all(|v| v.is_nan()),
            "score 0.2 < 0.6"
        );
    }

    #[test]
    fn duplicate_track_in_a_frame_is_an_error() {
        let f = TempFile::new("sleap_dup.csv", "track,frame_idx,a.x,a.y\n,0,1,2\n,0,3,4\n");
        let err = read(&f.0, &ImportSpec::default()).unwrap_err().to_string();
        assert!(err.contains(":3:1:") && err.contains("line 2"), "{err}");
    }
}
