//! DLTdv sparse `*xypts.tsv` reader (FORMATS.md §3, `sparseSave.m`).
//!
//! ```text
//! Sparse format camera coordinates file
//! <rows>\t<cols>\t<nnz>
//! <row>\t<col>\t<value>         <- nnz triplets, 1-based, %.6f
//! ```
//! The matrix is the dense `xypts` table (row = frame, 1-based; columns point-major
//! `pt1_cam1_X, pt1_cam1_Y, pt1_cam2_X, …`) with missing points stored as absent entries (zeros),
//! so an entry that is absent — or exactly 0, which DLTdv cannot tell from missing — is NaN. The
//! file does not say how many cameras the columns cover: [`ImportSpec::n_cameras`] (default 1).
//! Points are named `pt{i}`; time and scale as for [`super::dltdv`] (frame 1 at `t0_s`, pixels,
//! image y down by default).

use std::path::Path;

use crate::error::{Error, Result};
use crate::import::ImportSpec;
use crate::import::common::{RawTime, RawTrace, RawUnits, numbered_lines, read_decoded};

/// Largest dense matrix accepted (rows × cols): 2·[`MAX_CELLS`](super::common::MAX_CELLS).
const MAX_CELLS: usize = 2 * super::common::MAX_CELLS;

/// The size line: its file line and the dense matrix's rows, columns and stored-entry count.
struct Size {
    line: usize,
    rows: usize,
    cols: usize,
    nnz: usize,
}

/// Read a DLTdv sparse xypts file (module docs) into a [`RawTrace`] in pixels.
///
/// # Errors
/// [`Error::Io`]; [`Error::Parse`] (line, column) for a size line that is not three positive
/// integers, a column count not a multiple of 2·`n_cameras`, a triplet with a row/column outside
/// the size, a repeated entry, or a non-numeric value; [`Error::Input`] if the triplet count
/// differs from `nnz`.
pub fn read(path: &Path, spec: &ImportSpec) -> Result<RawTrace> {
    let (text, _) = read_decoded(path)?;
    let lines: Vec<(usize, &str)> = numbered_lines(&text)
        .into_iter()
        .filter(|(_, l)| !l.trim().is_empty())
        .collect();
    if lines.len() < 2 {
        return Err(Error::input(
            path,
            "expected a title line and a `rows<TAB>cols<TAB>nnz` line",
        ));
    }
    let size = size_line(path, lines[1], spec)?;
    let dense = dense_matrix(path, &lines[2..], &size)?;
    let Size {
        rows, cols, nnz, ..
    } = size;
    let n_points = cols / (2 * spec.n_cameras);
    let cam = spec.camera - 1;
    let mut points = Vec::with_capacity(n_points);
    for i in 0..n_points {
        let cx = (i * spec.n_cameras + cam) * 2;
        let x: Vec<f64> = (0..rows).map(|r| dense[r * cols + cx]).collect();
        let y: Vec<f64> = (0..rows).map(|r| dense[r * cols + cx + 1]).collect();
        points.push((format!("pt{}", i + 1), x, y));
    }
    Ok(RawTrace {
        time: RawTime::Frames((0..rows).map(|r| r as f64).collect()),
        points,
        units: RawUnits::Pixels,
        y_down_default: true,
        notes: vec![format!(
            "DLTdv sparse: {rows} frames × {cols} columns ({n_points} points × {} cameras, camera \
             {} read), {nnz} stored values",
            spec.n_cameras, spec.camera
        )],
    })
}

/// The three values of a size or triplet line (`what` names it in the error).
fn fields(path: &Path, line: usize, l: &str, what: &str) -> Result<Vec<String>> {
    let f: Vec<String> = l
        .split(['\t', ' ', ','])
        .filter(|s| !s.is_empty())
        .map(str::to_owned)
        .collect();
    if f.len() != 3 {
        return Err(Error::parse(
            path,
            line,
            0,
            format!(
                "expected {what} (three TAB-separated values), found {} values",
                f.len()
            ),
        ));
    }
    Ok(f)
}

/// A non-negative integer in column `col` of `line`.
fn int(path: &Path, line: usize, col: usize, s: &str, what: &str) -> Result<usize> {
    s.trim().parse::<usize>().map_err(|_| {
        Error::parse(
            path,
            line,
            col,
            format!(
                "expected {what} (an integer), found {}",
                super::quote_cell(s)
            ),
        )
    })
}

/// Parse the size line `rows cols nnz`: rows ≥ 1, cols a positive multiple of 2·`n_cameras`, the
/// matrix at most [`MAX_CELLS`].
fn size_line(path: &Path, (sl, st): (usize, &str), spec: &ImportSpec) -> Result<Size> {
    let size = fields(path, sl, st, "rows, cols, nnz")?;
    let rows = int(path, sl, 1, &size[0], "the row count")?;
    let cols = int(path, sl, 2, &size[1], "the column count")?;
    let nnz = int(path, sl, 3, &size[2], "the non-zero count")?;
    let per_point = 2 * spec.n_cameras;
    if rows == 0 || cols == 0 || cols % per_point != 0 || rows.saturating_mul(cols) > MAX_CELLS {
        return Err(Error::parse(
            path,
            sl,
            2,
            format!(
                "expected rows ≥ 1 and a column count that is a multiple of 2 × n_cameras = \
                 {per_point} (≤ {MAX_CELLS} cells), found rows {rows}, cols {cols}"
            ),
        ));
    }
    Ok(Size {
        line: sl,
        rows,
        cols,
        nnz,
    })
}

/// The dense `rows × cols` matrix (row-major) from the triplet lines, NaN where absent or 0; the
/// triplet count must match the size line's `nnz`.
fn dense_matrix(path: &Path, triplets: &[(usize, &str)], size: &Size) -> Result<Vec<f64>> {
    let (rows, cols) = (size.rows, size.cols);
    let mut dense = vec![f64::NAN; rows * cols];
    let mut count = 0usize;
    for &(line, l) in triplets {
        let f = fields(path, line, l, "a row, column, value triplet")?;
        let r = int(path, line, 1, &f[0], "a row")?;
        let c = int(path, line, 2, &f[1], "a column")?;
        if r == 0 || r > rows || c == 0 || c > cols {
            return Err(Error::parse(
                path,
                line,
                1,
                format!("expected row 1..={rows} and column 1..={cols}, found ({r}, {c})"),
            ));
        }
        let Some(v) = super::parse_finite(&f[2]) else {
            return Err(Error::parse(
                path,
                line,
                3,
                format!("expected a number, found {}", super::quote_cell(&f[2])),
            ));
        };
        let cell = &mut dense[(r - 1) * cols + (c - 1)];
        if !cell.is_nan() {
            return Err(Error::parse(
                path,
                line,
                1,
                format!("entry ({r}, {c}) appears twice"),
            ));
        }
        *cell = if v == 0.0 { f64::NAN } else { v };
        count += 1;
    }
    if count != size.nnz {
        return Err(Error::input(
            path,
            format!(
                "the size line (line {}) says {} entries, the file has {count}",
                size.line, size.nnz
            ),
        ));
    }
    Ok(dense)
}

/// Write `x`, `y` pixel tracks (frame 1 first, NaN = missing, one camera) as a DLTdv sparse
/// xypts file — the layout [`read`] reads (used for round-trip tests).
///
/// # Errors
/// [`Error::Io`] if the file cannot be written; [`super::ImportError`] if the tracks differ in length.
pub fn write(path: &Path, points: &[(Vec<f64>, Vec<f64>)]) -> Result<()> {
    let rows = points.first().map_or(0, |p| p.0.len());
    if points
        .iter()
        .any(|p| p.0.len() != rows || p.1.len() != rows)
    {
        let lengths = points.iter().map(|p| (p.0.len(), p.1.len())).collect();
        return Err(super::ImportError::TrackLengths { lengths }.into());
    }
    let mut body = String::new();
    let mut nnz = 0;
    for r in 0..rows {
        for (i, (x, y)) in points.iter().enumerate() {
            for (k, v) in [x[r], y[r]].into_iter().enumerate() {
                if v.is_finite() && v != 0.0 {
                    body.push_str(&format!("{}\t{}\t{v:.6}\n", r + 1, 2 * i + k + 1));
                    nnz += 1;
                }
            }
        }
    }
    let text = format!(
        "Sparse format camera coordinates file\n{rows}\t{}\t{nnz}\n{body}",
        2 * points.len()
    );
    crate::io::write_atomic(path, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::TempFile;

    #[test]
    fn two_cameras_sparse() {
        let f = TempFile::new(
            "sparse_xypts.tsv",
            "Sparse format camera coordinates file\n3\t4\t3\n1\t1\t10.5\n1\t2\t20.25\n3\t3\t7.0\n",
        );
        let spec = ImportSpec {
            n_cameras: 2,
            ..ImportSpec::default()
        };
        let raw = read(&f.0, &spec).unwrap();
        assert_eq!(raw.points.len(), 1);
        assert_eq!(raw.points[0].1[0], 10.5);
        assert!(raw.points[0].1[1].is_nan() && raw.points[0].1[2].is_nan());
        let spec2 = ImportSpec { camera: 2, ..spec };
        let raw = read(&f.0, &spec2).unwrap();
        assert_eq!(raw.points[0].1[2], 7.0);
        let bad = TempFile::new("sparse_bad.tsv", "Sparse\n2\t2\t1\n3\t1\t1.0\n");
        let err = read(&bad.0, &ImportSpec::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains(":3:1:") && err.contains("row 1..=2"), "{err}");
    }
}
