//! DeepLabCut prediction CSV reader (FORMATS.md §4).
//!
//! Single-animal: three header rows `scorer,...` / `bodyparts,...` / `coords,x,y,likelihood,...`;
//! multi-animal (maDLC): four, with `individuals,...` second. Then one row per frame, the first
//! column the 0-based frame index (no time: `fps_hz` is required), x, y in pixels (image y down),
//! likelihood in [0, 1] (anything else is an error at its cell). Missing values (maDLC) are empty
//! fields.
//!
//! Points: `<bodypart>` (single animal) or `<individual>/<bodypart>` (multi-animal). A point whose
//! likelihood is below [`ImportSpec::min_likelihood`] (default 0.6, DeepLabCut's `pcutoff`) or
//! missing (`NaN`, empty) becomes NaN in x and y — a gap, never a low-confidence position; the count is reported.

use std::path::Path;

use crate::error::{Error, Result};
use crate::import::ImportSpec;
use crate::import::common::{RawTime, RawTrace, RawUnits, Table, numbered_lines, read_decoded};

/// DeepLabCut's default `pcutoff` (config.yaml), used when `min_likelihood` is not set.
pub const DEFAULT_MIN_LIKELIHOOD: f64 = 0.6;

/// One point's columns: `<bodypart>` or `<individual>/<bodypart>`, x, y and likelihood.
struct Cols {
    name: String,
    x: Option<usize>,
    y: Option<usize>,
    l: Option<usize>,
}

/// Read a DeepLabCut CSV (module docs) into a [`RawTrace`] in pixels.
///
/// # Errors
/// [`Error::Io`]; [`Error::Input`] for missing header rows or no data; [`Error::Parse`] (line,
/// column, field) for a header row not named `scorer`/`individuals`/`bodyparts`/`coords`, a
/// body part without x and y, a first column that is not an increasing frame index (labeled
/// training data with image paths is refused), a non-numeric cell.
pub fn read(path: &Path, spec: &ImportSpec) -> Result<RawTrace> {
    let (text, _) = read_decoded(path)?;
    let lines = numbered_lines(&text);
    let nonblank: Vec<&(usize, &str)> =
        lines.iter().filter(|(_, l)| !l.trim().is_empty()).collect();
    let multi = nonblank.get(1).is_some_and(|(_, l)| {
        l.split(',')
            .next()
            .is_some_and(|c| c.trim() == "individuals")
    });
    let n_header = if multi { 4 } else { 3 };
    let table = Table::parse(path, &lines, n_header, ',')?;
    let groups = column_groups(path, &table, multi)?;
    let coords_line = table.headers[n_header - 1].0;
    // The first column: 0-based frame index. Image paths mean labeled training data.
    if table.rows[0].1[0].trim().parse::<f64>().is_err() {
        return Err(table.bad_cell(
            0,
            0,
            "a frame index (this looks like labeled training data with image paths, not a \
             prediction time series)",
        ));
    }
    let frames = table.axis(0, false, "a frame index")?;
    let cutoff = spec.min_likelihood.unwrap_or(DEFAULT_MIN_LIKELIHOOD);
    let mut points = Vec::new();
    let mut below = 0usize;
    for g in &groups {
        let (x, y) = point_values(path, &table, coords_line, g, cutoff, &mut below)?;
        points.push((g.name.clone(), x, y));
    }
    let notes = vec![format!(
        "DeepLabCut {}: {below} point samples with likelihood < {cutoff} set to NaN",
        if multi {
            "multi-animal"
        } else {
            "single-animal"
        }
    )];
    Ok(RawTrace {
        time: RawTime::Frames(frames),
        points,
        units: RawUnits::Pixels,
        y_down_default: true,
        notes,
    })
}

/// Check the header rows' first cells and group the columns by (individual, body part).
fn column_groups(path: &Path, table: &Table, multi: bool) -> Result<Vec<Cols>> {
    let expect: &[&str] = if multi {
        &["scorer", "individuals", "bodyparts", "coords"]
    } else {
        &["scorer", "bodyparts", "coords"]
    };
    for ((line, cells), want) in table.headers.iter().zip(expect) {
        if cells.first().map(String::as_str) != Some(*want) {
            return Err(Error::parse(
                path,
                *line,
                1,
                format!(
                    "expected a DeepLabCut header row starting with {want:?}, found {}",
                    super::quote_cell(cells.first().map_or("", |s| s.as_str()))
                ),
            ));
        }
    }
    let row = |name: &str| -> &Vec<String> {
        let k = expect.iter().position(|w| *w == name).unwrap_or(0);
        &table.headers[k].1
    };
    let coords_line = table.headers[expect.len() - 1].0;
    let (coords, bodyparts) = (row("coords"), row("bodyparts"));
    let individuals = if multi {
        Some(row("individuals"))
    } else {
        None
    };
    let mut groups: Vec<Cols> = Vec::new();
    for j in 1..table.names().len() {
        let bp = bodyparts.get(j).map_or("", |s| s.as_str());
        let name = match individuals {
            Some(ind) => format!("{}/{bp}", ind.get(j).map_or("", |s| s.as_str())),
            None => bp.to_owned(),
        };
        let coord = coords.get(j).map_or("", |s| s.as_str());
        assign_column(path, coords_line, &mut groups, name, coord, j)?;
    }
    Ok(groups)
}

/// Put column `j` (`coord` of point `name`) into its group, creating the group if new.
fn assign_column(
    path: &Path,
    coords_line: usize,
    groups: &mut Vec<Cols>,
    name: String,
    coord: &str,
    j: usize,
) -> Result<()> {
    let g = match groups.iter().position(|g| g.name == name) {
        Some(i) => i,
        None => {
            groups.push(Cols {
                name,
                x: None,
                y: None,
                l: None,
            });
            groups.len() - 1
        }
    };
    let slot = match coord {
        "x" => &mut groups[g].x,
        "y" => &mut groups[g].y,
        "likelihood" => &mut groups[g].l,
        other => {
            return Err(Error::parse(
                path,
                coords_line,
                j + 1,
                format!(
                    "expected coords x, y or likelihood, found {}",
                    super::quote_cell(other)
                ),
            ));
        }
    };
    if slot.is_some() {
        return Err(Error::parse(
            path,
            coords_line,
            j + 1,
            format!("column {coord} of {:?} appears twice", groups[g].name),
        ));
    }
    *slot = Some(j);
    Ok(())
}

/// A point's x and y, NaN where its likelihood is below `cutoff` or missing (counted in `below`).
///
/// # Errors
/// [`Error::Parse`] at a likelihood outside [0, 1] (DeepLabCut writes probabilities).
fn point_values(
    path: &Path,
    table: &Table,
    coords_line: usize,
    g: &Cols,
    cutoff: f64,
    below: &mut usize,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let (Some(cx), Some(cy)) = (g.x, g.y) else {
        return Err(Error::parse(
            path,
            coords_line,
            0,
            format!("body part {:?}: expected an x and a y column", g.name),
        ));
    };
    let mut x = table.numbers(cx, false)?;
    let mut y = table.numbers(cy, false)?;
    if let Some(cl) = g.l {
        let l = table.numbers(cl, false)?;
        for i in 0..l.len() {
            if l[i] < 0.0 || l[i] > 1.0 {
                return Err(table.bad_cell(i, cl, "a likelihood in [0, 1]"));
            }
            // A missing (NaN) likelihood is not a confident detection: a gap, as below the cut-off.
            let confident = l[i] >= cutoff; // false for NaN
            let tracked = !(x[i].is_nan() && y[i].is_nan());
            if !confident && tracked {
                x[i] = f64::NAN;
                y[i] = f64::NAN;
                *below += 1;
            }
        }
    }
    Ok((x, y))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::TempFile;

    #[test]
    fn multi_animal_with_gaps_and_cutoff() {
        let f = TempFile::new(
            "dlc_ma.csv",
            "scorer,s,s,s,s,s,s\r\nindividuals,a1,a1,a1,single,single,single\r\n\
             bodyparts,head,head,head,post,post,post\r\ncoords,x,y,likelihood,x,y,likelihood\r\n\
             0,1.5,2.5,0.9,,,\r\n1,1.0,2.0,0.1,3,4,0.99\r\n",
        );
        let raw = read(&f.0, &ImportSpec::default()).unwrap();
        assert_eq!(raw.time, RawTime::Frames(vec![0.0, 1.0]));
        let names: Vec<&str> = raw.points.iter().map(|p| p.0.as_str()).collect();
        assert_eq!(names, ["a1/head", "single/post"]);
        assert_eq!(raw.points[0].1[0], 1.5);
        assert!(raw.points[0].1[1].is_nan(), "likelihood 0.1 < 0.6 → gap");
        assert!(raw.points[1].2[0].is_nan());
        assert!(raw.notes[0].contains("1 point samples"), "{:?}", raw.notes);
    }

    /// A `nan` likelihood (a frame DeepLabCut did not score) is a gap, like one below the cut-off;
    /// a likelihood above 1 is no probability: an error at its cell (line 5, column 4).
    #[test]
    fn missing_likelihood_is_a_gap_and_one_above_1_an_error() {
        let head = "scorer,s,s,s\nbodyparts,h,h,h\ncoords,x,y,likelihood\n";
        let f = TempFile::new("dlc_nan.csv", &format!("{head}0,1,2,0.9\n1,1,2,nan\n"));
        let raw = read(&f.0, &ImportSpec::default()).unwrap();
        assert_eq!(raw.points[0].1[0], 1.0);
        assert!(raw.points[0].1[1].is_nan(), "NaN likelihood → gap");
        let f = TempFile::new("dlc_17.csv", &format!("{head}0,1,2,0.9\n1,1,2,1.7\n"));
        let err = read(&f.0, &ImportSpec::default()).unwrap_err().to_string();
        assert!(err.contains(":5:4:") && err.contains("[0, 1]"), "{err}");
    }

    #[test]
    fn labeled_data_is_refused() {
        let f = TempFile::new(
            "dlc_lab.csv",
            "scorer,s,s\nbodyparts,h,h\ncoords,x,y\nlabeled-data/v/img001.png,1,2\n",
        );
        let err = read(&f.0, &ImportSpec::default()).unwrap_err().to_string();
        assert!(
            err.contains(":4:1:") && err.contains("labeled training data"),
            "{err}"
        );
    }
}
