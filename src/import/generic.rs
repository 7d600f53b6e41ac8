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
use crate::import::ImportSpec;
use crate::import::common::{
    RawTime, RawTrace, RawUnits, Table, numbered_lines, read_decoded, sniff_delimiter, split_cells,
    time_unit_s,
};

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
    /// Point name → `[x column, y column]`.
    pub points: BTreeMap<String, [String; 2]>,
}

/// Read a generic table (module docs) into a [`RawTrace`] in file units.
///
/// # Errors
/// [`Error::Config`] if no `[generic]` mapping or no point is given, or both `time` and `frame`;
/// [`Error::Input`] if no line of the first 100 holds every mapped column name (the message lists
/// the names wanted); [`Error::Parse`] (line, column, field) for a bad or non-increasing time or
/// frame, a non-numeric coordinate, a row with fewer fields than the header.
pub fn read(path: &Path, spec: &ImportSpec) -> Result<RawTrace> {
    let Some(map) = &spec.generic else {
        return Err(Error::Config(
            "import: format \"generic\" needs a [generic] column mapping (time or frame column, \
             and [generic.points] name = [x column, y column])"
                .into(),
        ));
    };
    if map.points.is_empty() {
        return Err(Error::Config(
            "import: [generic.points] is empty: map at least one point to [x column, y column]"
                .into(),
        ));
    }
    if map.time.is_some() && map.frame.is_some() {
        return Err(Error::Config(
            "import: [generic] set time or frame, not both".into(),
        ));
    }
    let mut wanted: Vec<&str> = map
        .points
        .values()
        .flat_map(|[x, y]| [x.as_str(), y.as_str()])
        .collect();
    wanted.extend(map.time.as_deref());
    wanted.extend(map.frame.as_deref());
    let (text, _) = read_decoded(path)?;
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
    let table = Table::parse(path, &lines[k..], 1, delim)?;
    let dc = spec.decimal_comma;
    let idx = |name: &str| table.find(name).unwrap_or(0);
    let time = if let Some(tc) = &map.time {
        let factor = spec
            .time_to_s
            .or_else(|| {
                let open = tc.find('(')?;
                let close = tc[open..].find(')')? + open;
                time_unit_s(&tc[open + 1..close])
            })
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
    };
    let mut points = Vec::new();
    for (name, [x, y]) in &map.points {
        points.push((
            name.clone(),
            table.numbers(idx(x), dc)?,
            table.numbers(idx(y), dc)?,
        ));
    }
    Ok(RawTrace {
        time,
        points,
        units: RawUnits::Unknown,
        y_down_default: false,
        notes: vec![format!(
            "generic table: header on line {}, delimiter {delim:?}, {} rows",
            table.headers[0].0,
            table.rows.len()
        )],
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
