//! Shared pieces of the readers: text decoding (UTF-8, else Windows-1252), line splitting with
//! quotes, missing-value cells, and the one calibration step that turns a reader's [`RawTrace`]
//! (file units, frames or file times, image y-down or not) into a [`Trace`] in seconds and metres.

use std::borrow::Cow;
use std::path::Path;

use crate::error::{Error, Result};
use crate::import::{ImportSpec, parse_finite};
use crate::trace::{PointTrack, Trace};

/// The bytes Windows-1252 leaves undefined. `encoding_rs` (WHATWG) decodes them as the C1
/// controls U+0081 ...; a file holding one is refused instead (its encoding is ambiguous).
const CP1252_UNDEFINED: [u8; 5] = [0x81, 0x8D, 0x8F, 0x90, 0x9D];

/// Which character encoding a file was decoded from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextEncoding {
    /// Valid UTF-8 (a BOM, if any, removed).
    Utf8,
    /// Not UTF-8; decoded as Windows-1252 (= ISO-8859-1 for every byte outside 0x80–0x9F), the
    /// platform charset Java writes on Western Windows/Linux systems (TrackMate's `FileWriter`).
    Windows1252,
}

/// Decode `bytes` read from `path`: UTF-8 (BOM removed) if valid, else Windows-1252.
///
/// # Errors
/// [`Error::Parse`] naming the line, column and byte offset of the first byte that is neither: a
/// NUL byte (binary or UTF-16 file) or a byte undefined in Windows-1252 (0x81, 0x8D, 0x8F, 0x90,
/// 0x9D) in a file that is not UTF-8 — the encoding is then ambiguous and the file is refused.
pub fn decode(path: &Path, bytes: &[u8]) -> Result<(String, TextEncoding)> {
    let locate = |offset: usize| {
        let line = 1 + bytes[..offset].iter().filter(|&&b| b == b'\n').count();
        let start = bytes[..offset]
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |i| i + 1);
        (line, offset - start + 1)
    };
    if let Some(offset) = bytes.iter().position(|&b| b == 0) {
        let (line, column) = locate(offset);
        return Err(Error::parse(
            path,
            line,
            column,
            format!(
                "NUL byte at byte offset {offset}: expected a text file (UTF-8 or Windows-1252); \
                 binary or UTF-16 files are not read — re-save the export as UTF-8 text"
            ),
        ));
    }
    match std::str::from_utf8(bytes) {
        Ok(s) => Ok((
            s.strip_prefix('\u{feff}').unwrap_or(s).to_owned(),
            TextEncoding::Utf8,
        )),
        Err(utf8_err) => {
            if let Some(offset) = bytes.iter().position(|b| CP1252_UNDEFINED.contains(b)) {
                let b = bytes[offset];
                let (line, column) = locate(offset);
                let (l8, _) = locate(utf8_err.valid_up_to());
                return Err(Error::parse(
                    path,
                    line,
                    column,
                    format!(
                        "byte 0x{b:02X} at byte offset {offset}: the file is not UTF-8 \
                         (first invalid byte on line {l8}, offset {}) and this byte is \
                         undefined in Windows-1252/Latin-1; expected UTF-8 text — \
                         re-save the export as UTF-8",
                        utf8_err.valid_up_to()
                    ),
                ));
            }
            let (text, _) = encoding_rs::WINDOWS_1252.decode_without_bom_handling(bytes);
            Ok((text.into_owned(), TextEncoding::Windows1252))
        }
    }
}

/// Read and [`decode`] a whole file.
///
/// # Errors
/// [`Error::Io`] if it cannot be read; [`decode`]'s errors.
pub fn read_decoded(path: &Path) -> Result<(String, TextEncoding)> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, "read", e))?;
    decode(path, &bytes)
}

/// The file's lines as `(1-based line number, text without the line end)`; LF, CRLF and a lone CR
/// at the end of a line all end a line.
pub fn numbered_lines(text: &str) -> Vec<(usize, &str)> {
    text.split('\n')
        .enumerate()
        .map(|(i, l)| (i + 1, l.strip_suffix('\r').unwrap_or(l)))
        .collect()
}

/// Split one line on `delim`, honouring RFC 4180 double quotes (`"a,b"`, `""` for a quote). Quoted
/// cells are returned unquoted; the bool says whether the cell was quoted. An unterminated quote
/// runs to the end of the line.
///
/// Hand-written rather than the `csv` crate (which reads the plain CSV formats: canonical, DLTdv):
/// these readers split single lines already chosen by a header search (preambles, unit rows and
/// footers of free-form exports), some with a space delimiter that `csv` cannot take.
pub fn split_record(line: &str, delim: char) -> Vec<(String, bool)> {
    let mut out = Vec::new();
    let mut cell = String::new();
    let mut quoted = false;
    let mut in_quotes = false;
    let mut chars = line.chars().peekable();
    let mut at_start = true;
    while let Some(c) = chars.next() {
        if in_quotes {
            if c == '"' {
                if chars.peek() == Some(&'"') {
                    chars.next();
                    cell.push('"');
                } else {
                    in_quotes = false;
                }
            } else {
                cell.push(c);
            }
        } else if c == '"' && at_start {
            in_quotes = true;
            quoted = true;
            at_start = false;
        } else if c == delim {
            out.push((std::mem::take(&mut cell), quoted));
            quoted = false;
            at_start = true;
        } else {
            cell.push(c);
            at_start = false;
        }
    }
    out.push((cell, quoted));
    out
}

/// Plain cells of [`split_record`].
pub fn split_cells(line: &str, delim: char) -> Vec<String> {
    split_record(line, delim)
        .into_iter()
        .map(|(c, _)| c)
        .collect()
}

/// A numeric cell: `Ok(None)` when missing (empty, `NaN`, `nan`, TrackMate's `ø`), `Ok(Some(v))`
/// for a finite number, `Err(())` otherwise. With `decimal_comma`, `,` is the decimal separator.
/// U+2212 MINUS SIGN is read as `-`.
#[allow(clippy::result_unit_err)]
pub fn parse_cell(cell: &str, decimal_comma: bool) -> std::result::Result<Option<f64>, ()> {
    let cell = cell.trim();
    if cell.is_empty() || cell.eq_ignore_ascii_case("nan") || cell == "ø" || cell == "Ø" {
        return Ok(None);
    }
    let mut text = Cow::Borrowed(cell);
    if decimal_comma {
        text = Cow::Owned(text.replace(',', "."));
    }
    if text.contains('\u{2212}') {
        text = Cow::Owned(text.replace('\u{2212}', "-"));
    }
    parse_finite(&text).map(Some).ok_or(())
}

/// Most samples (frames × points) a reader allocates: 2·10⁷ per coordinate (160 MB), e.g. a
/// million frames of 20 points. A frame index or size beyond it is a corrupt file, refused with a
/// message rather than an out-of-memory abort.
pub const MAX_CELLS: usize = 20_000_000;

/// [`Error::Input`] unless `frames × points ≤` [`MAX_CELLS`].
pub fn check_cells(path: &Path, frames: usize, points: usize) -> Result<()> {
    if frames.saturating_mul(points) > MAX_CELLS {
        return Err(Error::input(
            path,
            format!(
                "{frames} frames × {points} points exceed {MAX_CELLS} samples: expected a frame \
                 range that fits the data (a corrupt frame number?)"
            ),
        ));
    }
    Ok(())
}

/// A `csv` reader over the file at `path`: `,` delimited, RFC 4180 quotes, no header handling
/// (the first record is the header, see [`csv_header`]), rows of any width (checked by the caller).
///
/// # Errors
/// [`Error::Io`] if the file cannot be opened.
pub(crate) fn open_csv(path: &Path) -> Result<csv::Reader<std::io::BufReader<std::fs::File>>> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, "open", e))?;
    Ok(csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(std::io::BufReader::new(file)))
}

/// The first record of `records` as a header: its 1-based line and its cells (untrimmed), a UTF-8
/// BOM removed from the first cell (the `csv` reader keeps it).
///
/// # Errors
/// [`Error::Input`] with the message `empty` when there is no record; the `csv` reader's errors
/// ([`super::csv_error`]).
pub(crate) fn csv_header(
    path: &Path,
    records: &mut impl Iterator<Item = csv::Result<csv::StringRecord>>,
    empty: &str,
) -> Result<(usize, Vec<String>)> {
    let header = match records.next() {
        Some(r) => r.map_err(|e| super::csv_error(path, "read", e))?,
        None => return Err(Error::input(path, empty)),
    };
    let line = header.position().map_or(1, |p| p.line() as usize);
    let names = header
        .iter()
        .enumerate()
        .map(|(i, h)| {
            if i == 0 {
                h.trim_start_matches('\u{feff}').to_owned()
            } else {
                h.to_owned()
            }
        })
        .collect();
    Ok((line, names))
}

/// Time axis as a reader found it.
#[derive(Debug, Clone, PartialEq)]
pub enum RawTime {
    /// Times in seconds (already converted from the file's unit), strictly increasing.
    Seconds(Vec<f64>),
    /// 0-based frame numbers (a 1-based file subtracts 1): t = `t0_s` + frame/`fps_hz`.
    Frames(Vec<f64>),
}

/// What the file says about its coordinate unit.
#[derive(Debug, Clone, PartialEq)]
pub enum RawUnits {
    /// Pixels: [`ImportSpec::m_per_px`] (or two scale points) is required.
    Pixels,
    /// A known physical unit: metres per file unit, and the unit's name for the report.
    Known(f64, String),
    /// Calibrated units or pixels, the file does not say: `m_per_px` or `units_to_m` is required.
    Unknown,
}

/// A reader's result before calibration: coordinates in file units.
#[derive(Debug, Clone, PartialEq)]
pub struct RawTrace {
    pub time: RawTime,
    /// `(name, x, y)` in file units, NaN = missing; every vector as long as the time axis.
    pub points: Vec<(String, Vec<f64>, Vec<f64>)>,
    pub units: RawUnits,
    /// The format's y convention when the spec does not set `y_down`.
    pub y_down_default: bool,
    /// Remarks for the import report (encoding, thresholds, skipped rows ...).
    pub notes: Vec<String>,
}

/// Turn `raw` into a [`Trace`]: time base, scale, origin and y flip (see [`ImportSpec`]), returning
/// notes that say what was done (for [`super::ImportSummary::notes`]).
///
/// # Errors
/// [`Error::Input`] naming the missing setting: no `fps_hz` for a frame-indexed file, no scale for
/// pixels, neither `m_per_px` nor `units_to_m` for files that do not state their unit, `m_per_px`
/// for a file in a known physical unit; time not strictly increasing.
pub fn calibrate(path: &Path, raw: RawTrace, spec: &ImportSpec) -> Result<(Trace, Vec<String>)> {
    let mut notes = raw.notes;
    let t_s = time_base(path, raw.time, spec, &mut notes)?;
    check_increasing(path, &t_s)?;
    let scale = metres_per_unit(path, &raw.units, spec, &mut notes)?;
    let [ox, oy] = spec.origin_px;
    let y_down = spec.y_down.unwrap_or(raw.y_down_default);
    let y_sign = if y_down { -1.0 } else { 1.0 };
    if y_down {
        notes.push("y: file y runs down, flipped to physical y up".into());
    }
    if ox != 0.0 || oy != 0.0 {
        notes.push(format!("origin: ({ox}, {oy}) in file units subtracted"));
    }
    let n = t_s.len();
    let mut points = Vec::with_capacity(raw.points.len());
    for (name, x, y) in raw.points {
        debug_assert!(x.len() == n && y.len() == n);
        points.push(PointTrack {
            name,
            x_m: x.iter().map(|v| (v - ox) * scale).collect(),
            y_m: y.iter().map(|v| y_sign * (v - oy) * scale).collect(),
        });
    }
    Ok((Trace { t_s, points }, notes))
}

/// Times in seconds from the reader's axis (`t0_s` added; frames need `fps_hz`), noting the base.
fn time_base(
    path: &Path,
    time: RawTime,
    spec: &ImportSpec,
    notes: &mut Vec<String>,
) -> Result<Vec<f64>> {
    Ok(match time {
        RawTime::Seconds(t) => {
            notes.push("time base: the file's time column (real frame times kept)".into());
            t.into_iter().map(|t| spec.t0_s + t).collect()
        }
        RawTime::Frames(f) => {
            let fps = spec.fps_hz.ok_or_else(|| {
                Error::input(
                    path,
                    "this file has frame numbers but no times: set the frame rate (fps_hz in \
                     the import spec, --fps on the command line)",
                )
            })?;
            notes.push(format!(
                "time base: frame number / {fps} fps (frame rate from the import settings)"
            ));
            f.into_iter().map(|f| spec.t0_s + f / fps).collect()
        }
    })
}

/// [`Error::Input`] at the first sample of `t_s` that is not after the previous one.
fn check_increasing(path: &Path, t_s: &[f64]) -> Result<()> {
    if let Some(i) = t_s
        .windows(2)
        .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
    {
        return Err(Error::input(
            path,
            format!(
                "time is not strictly increasing at sample {}: {} s after {} s",
                i + 1,
                t_s[i + 1],
                t_s[i]
            ),
        ));
    }
    Ok(())
}

/// Metres per file unit from the file's unit and the spec's `m_per_px`/`units_to_m`, noting the
/// choice; errors name the missing or conflicting setting.
fn metres_per_unit(
    path: &Path,
    units: &RawUnits,
    spec: &ImportSpec,
    notes: &mut Vec<String>,
) -> Result<f64> {
    let m_per_px = spec.resolved_m_per_px()?;
    Ok(match (units, m_per_px, spec.units_to_m) {
        (_, Some(_), Some(_)) => {
            return Err(super::ImportError::Exclusive {
                first: "either m_per_px (pixels)",
                second: "units_to_m (calibrated units)",
            }
            .into());
        }
        (RawUnits::Pixels | RawUnits::Unknown, Some(s), None) => {
            notes.push(format!("units: pixels × {s:e} m/px"));
            s
        }
        (RawUnits::Pixels, None, _) => {
            return Err(Error::input(
                path,
                "coordinates are in pixels: set m_per_px (metres per pixel) or two image points a \
                 known distance apart (scale_points_px + scale_distance_m)",
            ));
        }
        (RawUnits::Known(f, unit), None, None) => {
            notes.push(format!("units: {unit} (from the file) = {f:e} m"));
            *f
        }
        (RawUnits::Known(_, unit), Some(_), None) => {
            return Err(Error::input(
                path,
                format!(
                    "the file states its coordinates are in {unit}: m_per_px does not apply (set \
                     units_to_m to override the unit)"
                ),
            ));
        }
        (RawUnits::Known(_, unit), None, Some(u)) => {
            notes.push(format!(
                "units: file says {unit}; overridden by units_to_m = {u:e} m per unit"
            ));
            u
        }
        (RawUnits::Unknown, None, Some(u)) => {
            notes.push(format!("units: file units × units_to_m = {u:e} m per unit"));
            u
        }
        (RawUnits::Unknown, None, None) => {
            return Err(Error::input(
                path,
                "the file does not state its coordinate unit (calibrated or pixels): set \
                 units_to_m (metres per calibrated unit, e.g. 0.01 for cm) or m_per_px",
            ));
        }
    })
}

/// Sniff the delimiter of a header line: the first of TAB, `;`, `,` that occurs outside quotes,
/// else space when present.
pub fn sniff_delimiter(line: &str) -> Option<char> {
    let mut in_q = false;
    let mut seen = [false; 4];
    for c in line.chars() {
        if c == '"' {
            in_q = !in_q;
        } else if !in_q {
            match c {
                '\t' => seen[0] = true,
                ';' => seen[1] = true,
                ',' => seen[2] = true,
                ' ' => seen[3] = true,
                _ => {}
            }
        }
    }
    ['\t', ';', ',', ' ']
        .into_iter()
        .zip(seen)
        .find(|(_, s)| *s)
        .map(|(c, _)| c)
}

/// A unique name: `base`, or `base_2`, `base_3` ... if taken.
pub fn unique_name(taken: &[String], base: &str) -> String {
    let mut name = base.to_owned();
    let mut k = 1;
    while taken.contains(&name) {
        k += 1;
        name = format!("{base}_{k}");
    }
    name
}

/// Metres per unit of a length unit name (`m`, `cm`, `mm`, `µm`/`micron`/`um`, `nm`, `in`),
/// or `None` for pixels and unknown names.
pub fn length_unit_m(unit: &str) -> Option<f64> {
    let u = unit
        .trim()
        .trim_matches(|c| c == '(' || c == ')')
        .to_ascii_lowercase();
    Some(match u.as_str() {
        "m" | "meter" | "meters" | "metre" | "metres" => 1.0,
        "cm" => 1e-2,
        "mm" => 1e-3,
        "µm" | "μm" | "um" | "micron" | "microns" | "micrometer" | "micrometre" => 1e-6,
        "nm" => 1e-9,
        "in" | "inch" => 0.0254,
        _ => return None,
    })
}

/// Seconds per unit of a time unit name (`s`, `sec`, `ms`, `min`, `h`), `None` otherwise.
pub fn time_unit_s(unit: &str) -> Option<f64> {
    let u = unit
        .trim()
        .trim_matches(|c| c == '(' || c == ')')
        .to_ascii_lowercase();
    Some(match u.as_str() {
        "s" | "sec" | "second" | "seconds" => 1.0,
        "ms" | "msec" => 1e-3,
        "µs" | "us" => 1e-6,
        "min" => 60.0,
        "h" | "hr" => 3600.0,
        _ => return None,
    })
}

/// Seconds per unit of the time unit in a column name's parentheses (`Time (ms)` → 0.001), `None`
/// without parentheses or for an unknown unit ([`time_unit_s`]).
pub fn header_time_unit(name: &str) -> Option<f64> {
    let open = name.find('(')?;
    let close = name[open..].find(')')? + open;
    time_unit_s(&name[open + 1..close])
}

/// A delimited table: header line(s) and data rows, each with its 1-based file line.
#[derive(Debug, Clone)]
pub struct Table<'a> {
    pub path: &'a Path,
    pub delim: char,
    /// The header lines (`(line, cells)`), the last one being the column names.
    pub headers: Vec<(usize, Vec<String>)>,
    /// Column names used in messages and [`Table::find`]: the last header line, padded with empty
    /// names to the table's width (a reader may replace them, e.g. TrackMate's feature keys).
    pub names: Vec<String>,
    /// Data rows `(line, cells)`, blank lines skipped, every row as wide as the widest header line.
    pub rows: Vec<(usize, Vec<String>)>,
}

impl<'a> Table<'a> {
    /// Split `lines` (from [`numbered_lines`], blank lines included or not): the first `n_header`
    /// non-blank lines are headers, the rest data rows. Trailing empty cells beyond the header's
    /// width are dropped (trailing delimiters).
    ///
    /// # Errors
    /// [`Error::Input`] if there are fewer than `n_header` lines or no data row;
    /// [`Error::Parse`] for a row with fewer cells than the header, or extra non-empty cells.
    pub fn parse(
        path: &'a Path,
        lines: &[(usize, &str)],
        n_header: usize,
        delim: char,
    ) -> Result<Table<'a>> {
        let mut it = lines.iter().filter(|(_, l)| !l.trim().is_empty());
        let mut headers = Vec::with_capacity(n_header);
        for _ in 0..n_header {
            let Some(&(line, text)) = it.next() else {
                return Err(Error::input(
                    path,
                    format!("expected {n_header} header line(s), the file has fewer lines"),
                ));
            };
            let mut cells: Vec<String> = split_cells(text, delim)
                .into_iter()
                .map(|c| c.trim().to_owned())
                .collect();
            while cells.len() > 1 && cells.last().is_some_and(|c| c.is_empty()) {
                cells.pop();
            }
            headers.push((line, cells));
        }
        let width = headers.iter().map(|h| h.1.len()).max().unwrap_or(0);
        let header_line = headers.last().map_or(0, |h| h.0);
        let mut names = headers.last().map_or_else(Vec::new, |h| h.1.clone());
        names.resize(width, String::new());
        let mut rows = Vec::new();
        for &(line, text) in it {
            let mut cells = split_cells(text, delim);
            if cells.len() < width {
                return Err(Error::parse(
                    path,
                    line,
                    0,
                    format!(
                        "expected {width} fields like the header (line {header_line}), found {}",
                        cells.len()
                    ),
                ));
            }
            if let Some(k) = cells[width..].iter().position(|c| !c.trim().is_empty()) {
                return Err(Error::parse(
                    path,
                    line,
                    width + k + 1,
                    format!(
                        "expected {width} fields like the header (line {header_line}), found a \
                         non-empty field {} beyond them",
                        width + k + 1
                    ),
                ));
            }
            cells.truncate(width);
            rows.push((line, cells));
        }
        if rows.is_empty() {
            return Err(Error::input(
                path,
                format!("no data rows after the header (line {header_line})"),
            ));
        }
        Ok(Table {
            path,
            delim,
            headers,
            names,
            rows,
        })
    }

    /// The column names (last header line).
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Index of the column named `name` (exact, after trimming).
    pub fn find(&self, name: &str) -> Option<usize> {
        self.names().iter().position(|n| n == name)
    }

    /// The error for cell `(row, col)`: `file:line:column: field <name>: expected <what>, found "..."`.
    pub fn bad_cell(&self, row: usize, col: usize, what: &str) -> Error {
        let (line, cells) = &self.rows[row];
        Error::parse(
            self.path,
            *line,
            col + 1,
            format!(
                "field {}: expected {what}, found {}",
                self.names().get(col).map_or("?", |s| s.as_str()),
                super::quote_cell(cells[col].trim())
            ),
        )
    }

    /// Column `col` as numbers, NaN where missing (empty, `NaN`, `ø`).
    ///
    /// # Errors
    /// [`Error::Parse`] naming line, column and field for a cell that is not a number or missing.
    pub fn numbers(&self, col: usize, decimal_comma: bool) -> Result<Vec<f64>> {
        (0..self.rows.len())
            .map(|r| match parse_cell(&self.rows[r].1[col], decimal_comma) {
                Ok(v) => Ok(v.unwrap_or(f64::NAN)),
                Err(()) => Err(self.bad_cell(r, col, "a number or an empty cell")),
            })
            .collect()
    }

    /// Column `col` as a strictly increasing time or frame axis: every cell a finite number.
    ///
    /// # Errors
    /// [`Error::Parse`] naming the line, column and field of a missing, non-numeric or
    /// non-increasing value.
    pub fn axis(&self, col: usize, decimal_comma: bool, what: &str) -> Result<Vec<f64>> {
        let mut out: Vec<f64> = Vec::with_capacity(self.rows.len());
        for r in 0..self.rows.len() {
            let v = match parse_cell(&self.rows[r].1[col], decimal_comma) {
                Ok(Some(v)) => v,
                _ => return Err(self.bad_cell(r, col, what)),
            };
            if let Some(&p) = out.last().filter(|&&p| v <= p) {
                return Err(self.bad_cell(
                    r,
                    col,
                    &format!("{what} after the previous row's {p} (strictly increasing)"),
                ));
            }
            out.push(v);
        }
        Ok(out)
    }
}

/// Split a column name `<base><sep>X` / `<base><sep>Y` (sep one of `/`, `.`, `_`, space; X/Y in
/// either case) into `(base, is_x)`.
pub fn xy_suffix(name: &str) -> Option<(&str, bool)> {
    let n = name.trim();
    // The last character may be multi-byte (`ø`): split on a char boundary.
    let last = n.chars().next_back()?;
    let base = &n[..n.len() - last.len_utf8()];
    let is_x = match last {
        'X' | 'x' => true,
        'Y' | 'y' => false,
        _ => return None,
    };
    let base = base.strip_suffix(['/', '.', '_', ' '])?;
    if base.is_empty() {
        return None;
    }
    Some((base, is_x))
}

/// Group columns into points by [`xy_suffix`]: `(base, x col, y col)` in order of the x column;
/// columns without a partner are returned separately.
pub fn pair_xy(names: &[String], skip: &[usize]) -> (Vec<(String, usize, usize)>, Vec<usize>) {
    let mut pairs: Vec<(String, Option<usize>, Option<usize>)> = Vec::new();
    let mut single = Vec::new();
    for (j, n) in names.iter().enumerate() {
        if skip.contains(&j) {
            continue;
        }
        match xy_suffix(n) {
            Some((base, is_x)) => {
                let slot = pairs
                    .iter_mut()
                    .find(|p| p.0 == base && if is_x { p.1.is_none() } else { p.2.is_none() });
                match slot {
                    Some(p) if is_x => p.1 = Some(j),
                    Some(p) => p.2 = Some(j),
                    None if is_x => pairs.push((base.to_owned(), Some(j), None)),
                    None => pairs.push((base.to_owned(), None, Some(j))),
                }
            }
            None => single.push(j),
        }
    }
    let mut out = Vec::new();
    for (b, x, y) in pairs {
        match (x, y) {
            (Some(x), Some(y)) => out.push((b, x, y)),
            (Some(j), None) | (None, Some(j)) => single.push(j),
            (None, None) => {}
        }
    }
    single.sort_unstable();
    (out, single)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decodes_utf8_and_windows_1252() {
        let p = Path::new("f.csv");
        let (s, e) = decode(p, "\u{feff}a,ø\n".as_bytes()).unwrap();
        assert_eq!((s.as_str(), e), ("a,ø\n", TextEncoding::Utf8));
        let (s, e) = decode(p, b"a,\xf8\n\x80").unwrap();
        assert_eq!((s.as_str(), e), ("a,ø\n€", TextEncoding::Windows1252));
        let err = decode(p, b"ok\nab\xf8\x81").unwrap_err().to_string();
        assert!(err.starts_with("f.csv:2:4:"), "{err}");
        assert!(err.contains("byte offset 6"), "{err}");
        let err = decode(p, b"a\0b").unwrap_err().to_string();
        assert!(err.contains("NUL byte at byte offset 1"), "{err}");
    }

    #[test]
    fn windows_1252_high_bytes() {
        let p = Path::new("f.csv");
        let (s, _) = decode(p, b"\x80\x82\x8e\x91\x9c\x9f\xa0\xf8\xff").unwrap();
        assert_eq!(s, "€‚Ž‘œŸ\u{a0}øÿ");
        for b in [0x81, 0x8d, 0x8f, 0x90, 0x9d] {
            let err = decode(p, &[b'a', 0xf8, b]).unwrap_err().to_string();
            assert!(err.starts_with("f.csv:1:3: byte 0x"), "{err}");
        }
    }

    #[test]
    fn splits_quoted_cells() {
        assert_eq!(
            split_cells("\"1,0\";\"2,0\";;\"a\"\"b\"", ';'),
            ["1,0", "2,0", "", "a\"b"]
        );
        assert_eq!(split_cells("a,b,", ','), ["a", "b", ""]);
    }

    #[test]
    fn xy_suffixes() {
        assert_eq!(xy_suffix("B/h/X"), Some(("B/h", true)));
        assert_eq!(xy_suffix("Knee Y"), Some(("Knee", false)));
        // A multi-byte last character (a case tests/suite/import_fuzz.rs found) has no suffix, no panic.
        assert_eq!(xy_suffix("B/h/ø"), None);
        assert_eq!(xy_suffix("X"), None);
    }

    #[test]
    fn cells() {
        assert_eq!(parse_cell("ø", false), Ok(None));
        assert_eq!(parse_cell(" 1,5 ", true), Ok(Some(1.5)));
        assert_eq!(parse_cell("\u{2212}2", false), Ok(Some(-2.0)));
        assert_eq!(parse_cell("x", false), Err(()));
    }
}
