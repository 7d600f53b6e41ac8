//! SVG figures with plotters (SVG backend only; text is emitted as SVG `<text>`, no font files).
//!
//! * [`line_chart`]: x–y series (traces, PSDs) with optional log axes, peak markers, shaded x
//!   spans (e.g. the requested frequency bands) and vertical reference lines. NaN (or, on a log
//!   axis, a non-positive value) breaks a line: nothing is drawn through a gap, and such points
//!   never enter the axis-range computation. Lines are clipped to the plotted range. The legend
//!   sits in a strip below the plotting area, so it covers no data; each marker's label is placed
//!   where no line, point or other label crosses it (with a leader line when it had to move away
//!   from its marker). The chart is drawn at [`SCALE`] times its size and shown at [`FIGURE_SIZE`]
//!   through the SVG `viewBox`, so coordinates are not rounded to whole pixels.
//! * [`heatmap`]: a spectrogram-style `z[x][y]` image with a viridis colour map and colour bar,
//!   whose range can be set from the data's percentiles (so a few extreme cells do not compress
//!   the rest into one colour).
//!
//! A marker label is a `<text class="marker-label">` in a group `<g class="marker-labels">`, with
//! `x` its left end, `y` its baseline, and `textLength` its width (the glyphs are scaled to it):
//! it covers `[x, x + textLength] × [y − 0.8·font-size, y + 0.25·font-size]`, the box the
//! placement kept clear.
//!
//! Figures are rendered into memory and written with one `crate::io::write_atomic`, so a failed write is an
//! [`Error::Io`] naming the path; a plotters drawing failure is a [`ReportError::Draw`] naming the
//! path, data with nothing plottable a [`ReportError::NothingToPlot`].
//!
//! The report stage computes nothing: pass it spectra and traces computed upstream.

mod corner;
mod png;
mod scatter;
mod ticks;

pub use corner::{CornerAxis, corner_plot};
pub use scatter::{Category, Panel, Target, scatter_panels};

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{HeatmapProblem, ReportError};
use crate::{Error, Result};
use ticks::{TickAxis, Ticks};

/// Default figure size in pixels (width, height).
pub const FIGURE_SIZE: (u32, u32) = (900, 500);

/// Series colours (the Tableau 10 palette, as used by matplotlib), cycled.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The colour of series number `i` in [`line_chart`].
pub fn series_colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// How a [`Series`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SeriesStyle {
    /// A polyline, broken at NaN.
    #[default]
    Line,
    /// A small filled circle per finite point.
    Points,
    /// Both.
    LinePoints,
    /// A dashed polyline, broken at NaN (e.g. a curve where it is extrapolated).
    Dashed,
}

/// One named data series; `x` and `y` pair up index by index (extra entries of the longer one are
/// ignored). NaN marks a missing value.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Legend text (include the unit or source, e.g. "measured (Tracker)").
    pub label: String,
    /// Abscissae, in the unit named by the chart's `x_label`.
    pub x: Vec<f64>,
    /// Ordinates, in the unit named by the chart's `y_label`.
    pub y: Vec<f64>,
    /// Line, points or both.
    pub style: SeriesStyle,
}

impl Series {
    /// A line series.
    pub fn line(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            label: label.into(),
            x,
            y,
            style: SeriesStyle::Line,
        }
    }

    /// A dashed line series.
    pub fn dashed(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            label: label.into(),
            x,
            y,
            style: SeriesStyle::Dashed,
        }
    }

    /// A point (scatter) series.
    pub fn points(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series {
            label: label.into(),
            x,
            y,
            style: SeriesStyle::Points,
        }
    }
}

/// An annotated point, e.g. an interpolated spectral peak at `(f, level)`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Marker {
    /// Abscissa in data units.
    pub x: f64,
    /// Ordinate in data units.
    pub y: f64,
    /// Text drawn beside the marker (e.g. "78.4 Hz").
    pub label: String,
}

/// Options of [`line_chart`]. `Default` gives linear axes fitted to the data and no annotations.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ChartOpts {
    /// Logarithmic y axis (non-positive y values are treated as missing).
    pub log_y: bool,
    /// Logarithmic x axis (non-positive x values are treated as missing).
    pub log_x: bool,
    /// Plotted x range `(lo, hi)`; default: the finite data's extent.
    pub x_range: Option<(f64, f64)>,
    /// Plotted y range `(lo, hi)`; default: the extent of the finite data inside the x range, padded.
    pub y_range: Option<(f64, f64)>,
    /// Annotated points.
    pub markers: Vec<Marker>,
    /// Vertical dashed reference lines `(x, label)`, e.g. a target frequency.
    pub vlines: Vec<(f64, String)>,
    /// A residual drawn in its own panel under the chart (a third of the height, linear y axis
    /// fitted to it, the chart's x range), titled by its label: e.g. measured − model under a
    /// trace overlay, where a match cannot be told from overplotting.
    pub residual: Option<Series>,
    /// Shaded x intervals, each with a legend entry: e.g. the frequency bands a fit or a peak
    /// search looked at.
    pub spans: Vec<Span>,
    /// Shaded areas between two curves, each with a legend entry: e.g. a fitted curve's ±1σ.
    pub bands: Vec<Band>,
    /// Vertical ±1σ whiskers at points, over the data.
    pub error_bars: Vec<ErrorBars>,
}

/// Vertical whiskers from `y − sd` to `y + sd` at each `x`, capped, in series number `series`'s
/// colour on a [`line_chart`]: that series (of style points) draws the points and names them in
/// the legend. Points where `x`, `y` or `sd` is not finite are left out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ErrorBars {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub sd: Vec<f64>,
    pub series: usize,
}

/// The area between `lo` and `hi` over `x` shaded on a [`line_chart`] in a light tint of series
/// number `series`'s colour (under the data), and named in the legend. Points where `x`, `lo` or
/// `hi` is not finite are left out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Band {
    pub x: Vec<f64>,
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
    /// The series whose colour the band takes.
    pub series: usize,
    /// Legend text, e.g. "±1σ".
    pub label: String,
}

/// An x interval shaded on a [`line_chart`] (in its own tint, under the data) and named in the
/// legend.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Span {
    /// Ends in data units.
    pub lo: f64,
    pub hi: f64,
    /// Legend text, e.g. "band low 30–300 Hz".
    pub label: String,
}

/// Tints of the [`Span`]s, cycled (light, so the data stay readable over them).
const SPAN_TINTS: [RGBColor; 4] = [
    RGBColor(255, 190, 100),
    RGBColor(130, 180, 255),
    RGBColor(150, 215, 140),
    RGBColor(225, 160, 225),
];

/// Opacity of a [`Span`]'s shading.
const SPAN_OPACITY: f64 = 0.22;

/// The tint of span number `i`.
fn span_tint(i: usize) -> RGBColor {
    SPAN_TINTS[i % SPAN_TINTS.len()]
}

fn draw_err(path: &Path, e: impl std::fmt::Display) -> Error {
    ReportError::Draw {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
    .into()
}

fn write_svg(path: &Path, svg: &str) -> Result<()> {
    crate::io::write_atomic(path, svg.as_bytes())
}

/// Maps data to the plotting plane: identity for a linear axis, `log10` for a log axis. Everything
/// is drawn in the plane (plotters sees only linear axes), so lines are straight there and clipping
/// is linear.
#[derive(Clone, Copy)]
struct Axis {
    log: bool,
}

impl Axis {
    fn valid(self, v: f64) -> bool {
        v.is_finite() && (!self.log || v > 0.0)
    }
    fn fwd(self, v: f64) -> f64 {
        if self.log { v.log10() } else { v }
    }
    fn ticks(self, lo: f64, hi: f64, target: usize) -> Ticks {
        if self.log {
            ticks::log(lo, hi)
        } else {
            ticks::linear(lo, hi, target)
        }
    }
}

/// Plane range of data in `[lo, hi]` (data units), widened when degenerate and padded by `pad` of
/// the span.
fn plane_range(axis: Axis, lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    let (mut a, mut b) = (axis.fwd(lo), axis.fwd(hi));
    if b - a <= 1e-12 * a.abs().max(b.abs()).max(1e-300) {
        let w = if axis.log {
            0.5
        } else {
            (a.abs() * 0.1).max(1e-12)
        };
        a -= w;
        b += w;
    } else {
        let span = b - a;
        a -= pad * span;
        b += pad * span;
    }
    (a, b)
}

/// Liang–Barsky clip of the segment p→q to the box `[x0,x1]×[y0,y1]`.
fn clip(p: (f64, f64), q: (f64, f64), bx: (f64, f64), by: (f64, f64)) -> Option<[(f64, f64); 2]> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (pk, qk) in [
        (-dx, p.0 - bx.0),
        (dx, bx.1 - p.0),
        (-dy, p.1 - by.0),
        (dy, by.1 - p.1),
    ] {
        if pk == 0.0 {
            if qk < 0.0 {
                return None;
            }
        } else {
            let r = qk / pk;
            if pk < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    Some([
        (p.0 + t0 * dx, p.1 + t0 * dy),
        (p.0 + t1 * dx, p.1 + t1 * dy),
    ])
}

/// The plotting plane: axis kinds and plane ranges.
#[derive(Clone, Copy)]
struct Plane {
    ax: Axis,
    ay: Axis,
    bx: (f64, f64),
    by: (f64, f64),
}

impl Plane {
    /// Plane coordinates of a data point, if valid for the axes and inside the box.
    fn point(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        if !(self.ax.valid(x) && self.ay.valid(y)) {
            return None;
        }
        let p = (self.ax.fwd(x), self.ay.fwd(y));
        (p.0 >= self.bx.0 && p.0 <= self.bx.1 && p.1 >= self.by.0 && p.1 <= self.by.1).then_some(p)
    }

    /// Visible polylines (plane coordinates) of one series: broken at invalid points, clipped to
    /// the box.
    fn polylines(&self, s: &Series) -> Vec<Vec<(f64, f64)>> {
        let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
        let mut cur: Vec<(f64, f64)> = Vec::new();
        let mut prev: Option<(f64, f64)> = None;
        let flush = |cur: &mut Vec<(f64, f64)>, out: &mut Vec<Vec<(f64, f64)>>| {
            if cur.len() >= 2 {
                out.push(std::mem::take(cur));
            } else {
                cur.clear();
            }
        };
        for (&x, &y) in s.x.iter().zip(&s.y) {
            if !(self.ax.valid(x) && self.ay.valid(y)) {
                prev = None;
                flush(&mut cur, &mut out);
                continue;
            }
            let p = (self.ax.fwd(x), self.ay.fwd(y));
            if let Some(q) = prev {
                match clip(q, p, self.bx, self.by) {
                    Some([a, b]) => {
                        if cur.last() != Some(&a) {
                            flush(&mut cur, &mut out);
                            cur.push(a);
                        }
                        cur.push(b);
                    }
                    None => flush(&mut cur, &mut out),
                }
            }
            prev = Some(p);
        }
        flush(&mut cur, &mut out);
        out
    }
}

/// An x–y chart of `series` written as SVG (≈ 900×500 px) to `path`.
///
/// `x_label` and `y_label` should name the quantity and unit, e.g. `"frequency [Hz]"`,
/// `"PSD [m²/Hz]"`. Every series gets its own colour ([`series_colour`]) and a legend entry. NaN
/// values (and non-positive values on a log axis) break lines and are left out of the automatic
/// axis ranges; lines are clipped to the plotted range. Log axes are labelled in data units at
/// powers of ten.
///
/// Errors: [`ReportError::Range`] for an empty or reversed `x_range`/`y_range` or a non-positive
/// bound on a log axis; [`ReportError::NothingToPlot`] if no series has a plottable point (the message names the
/// path) or plotters fails; [`Error::Io`] if the file cannot be written.
pub fn line_chart(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    opts: &ChartOpts,
) -> Result<()> {
    check_ranges(path, opts)?;
    let plane = chart_plane(path, title, series, opts)?;
    let size = (FIGURE_SIZE.0 * SCALE, FIGURE_SIZE.1 * SCALE);
    let legend = Legend::of(series, &opts.bands, &opts.spans);
    let mut svg = String::new();
    let labels = {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(path, e))?;
        let (plot_root, _) = root.split_vertically(size.1 - legend.height);
        draw_panels(&plot_root, plane, (title, x_label, y_label), series, opts)
            .and_then(|labels| root.present().map(|_| labels))
            .map_err(|e| draw_err(path, e))?
    };
    let tail = labels_svg(&labels) + &legend.svg(size.1 - legend.height);
    let svg = shown_at_figure_size(&svg, size).replace("</svg>", &tail);
    write_svg(path, &svg)
}

/// Errors ([`ReportError::Range`], naming the path) unless `opts`' explicit `x_range` and `y_range`
/// are finite, increasing and, on a log axis, positive.
fn check_ranges(path: &Path, opts: &ChartOpts) -> Result<()> {
    let ax = Axis { log: opts.log_x };
    let ay = Axis { log: opts.log_y };
    for (name, r, axis) in [("x_range", opts.x_range, ax), ("y_range", opts.y_range, ay)] {
        if let Some((lo, hi)) = r
            && !(axis.valid(lo) && axis.valid(hi) && lo < hi)
        {
            return Err(ReportError::Range {
                path: path.to_path_buf(),
                range: name,
                lo,
                hi,
                log: axis.log,
            }
            .into());
        }
    }
    Ok(())
}

/// The plotting plane of [`line_chart`]: the given ranges, else the valid points' x extent and the
/// padded y extent of the points and markers inside it. [`ReportError::NothingToPlot`] (naming the path and
/// title) when there is no valid point.
fn chart_plane(path: &Path, title: &str, series: &[Series], opts: &ChartOpts) -> Result<Plane> {
    let ax = Axis { log: opts.log_x };
    let ay = Axis { log: opts.log_y };
    let no_data = || -> Error {
        ReportError::NothingToPlot {
            path: path.to_path_buf(),
            title: title.to_string(),
            log: opts.log_x || opts.log_y,
        }
        .into()
    };
    let valid_pts = || {
        series
            .iter()
            .flat_map(|s| s.x.iter().copied().zip(s.y.iter().copied()))
            .chain(opts.bands.iter().flat_map(|b| {
                let x = b.x.iter().copied();
                x.clone()
                    .zip(b.lo.iter().copied())
                    .chain(x.zip(b.hi.iter().copied()))
            }))
            .filter(|&(x, y)| ax.valid(x) && ay.valid(y))
    };
    let extent = |it: &mut dyn Iterator<Item = f64>| {
        it.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        })
    };
    let (xlo, xhi) = match opts.x_range {
        Some(r) => r,
        None => extent(&mut valid_pts().map(|(x, _)| x)),
    };
    if xlo > xhi {
        return Err(no_data());
    }
    let bx = plane_range(ax, xlo, xhi, 0.0);
    let by = match opts.y_range {
        Some((lo, hi)) => plane_range(ay, lo, hi, 0.0),
        None => {
            let in_x = |x: f64| x >= xlo && x <= xhi;
            let (lo, hi) = extent(
                &mut valid_pts().filter(|&(x, _)| in_x(x)).map(|(_, y)| y).chain(
                    opts.markers
                        .iter()
                        .filter(|m| ax.valid(m.x) && ay.valid(m.y) && in_x(m.x))
                        .map(|m| m.y),
                ),
            );
            if lo > hi {
                return Err(no_data());
            }
            plane_range(ay, lo, hi, 0.05)
        }
    };
    Ok(Plane { ax, ay, bx, by })
}

/// The chart's panels on `root`: the series, and under them the residual panel when `opts` has one
/// (a third of the height, a linear y axis fitted to the residual inside the chart's x range).
fn draw_panels(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    plane: Plane,
    labels: (&str, &str, &str),
    series: &[Series],
    opts: &ChartOpts,
) -> DrawResultOf<Vec<PlacedLabel>> {
    let Some(r) = &opts.residual else {
        return draw_xy(root, plane, labels, series, opts);
    };
    let (top, bottom) = root.split_vertically(root.dim_in_pixel().1 * 2 / 3);
    let in_x = |x: f64| plane.ax.valid(x) && (plane.bx.0..=plane.bx.1).contains(&plane.ax.fwd(x));
    let (lo, hi) =
        r.x.iter()
            .zip(&r.y)
            .filter(|(x, y)| y.is_finite() && in_x(**x))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (_, y)| {
                (a.min(*y), b.max(*y))
            });
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (-1.0, 1.0) };
    let lin = Axis { log: false };
    let residual_plane = Plane {
        ay: lin,
        by: plane_range(lin, lo, hi, 0.05),
        ..plane
    };
    let plain = ChartOpts {
        log_y: false,
        markers: Vec::new(),
        vlines: Vec::new(),
        residual: None,
        ..opts.clone()
    };
    let placed = draw_xy(&top, plane, labels, series, opts)?;
    draw_xy(
        &bottom,
        residual_plane,
        (&r.label, labels.1, labels.2),
        std::slice::from_ref(r),
        &plain,
    )?;
    Ok(placed)
}

/// Internal drawing scale of [`line_chart`]: plotters' SVG backend writes whole-number
/// coordinates, so figures are drawn `SCALE` times larger and shown at [`FIGURE_SIZE`] through the
/// SVG `viewBox`, which puts every coordinate on a quarter pixel.
pub const SCALE: u32 = 4;

/// `n` display pixels in the scaled drawing.
const fn px(n: u32) -> u32 {
    n * SCALE
}

/// Sets the root `<svg>`'s displayed width and height to [`FIGURE_SIZE`]; its `viewBox` keeps the
/// drawing's own size `size`.
fn shown_at_figure_size(svg: &str, size: (u32, u32)) -> String {
    svg.replacen(
        &format!("<svg width=\"{}\" height=\"{}\"", size.0, size.1),
        &format!(
            "<svg width=\"{}\" height=\"{}\"",
            FIGURE_SIZE.0, FIGURE_SIZE.1
        ),
        1,
    )
}

/// How a legend entry shows its series: a line sample, a filled circle of the given radius (drawing
/// units), or a cross (a marked target).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Mark {
    Line,
    /// A dashed line sample (a [`SeriesStyle::Dashed`] series).
    Dashed,
    Point(u32),
    Cross,
    /// A shaded rectangle (a [`Span`]).
    Swatch,
}

/// A legend drawn in a strip below the plotting area (entries flow left to right, then onto a new
/// row) so that it covers no data: [`line_chart`]'s series, the categories and targets of a
/// [`scatter_panels`] panel. In the SVG it is a group `<g class="legend">` whose first `<rect>` is
/// its box.
pub(crate) struct Legend {
    /// `(label, colour, mark, x offset from the box, row)` per entry.
    entries: Vec<(String, RGBColor, Mark, u32, u32)>,
    /// Width of the box and height of the strip, in drawing units (height 0 without entries).
    width: u32,
    pub(crate) height: u32,
}

impl Legend {
    const ROW: u32 = px(18);

    /// The legend of [`line_chart`]'s series, then its bands and its shaded spans, in the
    /// figure's width.
    fn of(series: &[Series], bands: &[Band], spans: &[Span]) -> Legend {
        let lines = series.iter().enumerate().map(|(i, s)| {
            let mark = match s.style {
                SeriesStyle::Points => Mark::Point(px(3)),
                SeriesStyle::Dashed => Mark::Dashed,
                SeriesStyle::Line | SeriesStyle::LinePoints => Mark::Line,
            };
            (s.label.clone(), series_colour(i), mark)
        });
        let areas = bands
            .iter()
            .map(|b| (b.label.clone(), series_colour(b.series), Mark::Swatch));
        let shaded = spans
            .iter()
            .enumerate()
            .map(|(i, s)| (s.label.clone(), span_tint(i), Mark::Swatch));
        Legend::new(lines.chain(areas).chain(shaded), FIGURE_SIZE.0)
    }

    /// A legend of `items` laid out in a strip `room_px` display pixels wide.
    pub(crate) fn new(
        items: impl IntoIterator<Item = (String, RGBColor, Mark)>,
        room_px: u32,
    ) -> Legend {
        let room = px(room_px.saturating_sub(24).max(60));
        let (mut x, mut row, mut width) = (px(6), 0, 0);
        let mut entries = Vec::new();
        for (label, colour, mark) in items {
            // About 7 px per character of 13 px sans-serif, plus the sample and a gap.
            let w = px(7 * label.chars().count() as u32 + 48).min(room);
            if x + w > room && x > px(6) {
                (x, row) = (px(6), row + 1);
            }
            entries.push((label, colour, mark, x, row));
            x += w;
            width = width.max(x);
        }
        let height = if entries.is_empty() {
            0
        } else {
            Self::ROW * (row + 1) + px(16)
        };
        Legend {
            entries,
            width,
            height,
        }
    }

    /// The legend group, then `</svg>`, in the strip that starts at `top`.
    fn svg(&self, top: u32) -> String {
        self.group(0, top) + "</svg>"
    }

    /// The legend group in the strip whose top-left corner is `(left, top)` (drawing units);
    /// empty without entries.
    pub(crate) fn group(&self, left: u32, top: u32) -> String {
        if self.entries.is_empty() {
            return String::new();
        }
        let (x, y) = (left + px(12), top + px(4));
        let h = self.height - px(8);
        let mut g = format!(
            "<g class=\"legend\">\n<rect x=\"{x}\" y=\"{y}\" width=\"{}\" height=\"{h}\" \
             fill=\"#FFFFFF\" stroke=\"#808080\" stroke-width=\"{}\"/>\n",
            self.width,
            px(1)
        );
        for (label, c, mark, dx, row) in &self.entries {
            let (ex, ey) = (x + dx, y + px(4) + Self::ROW * row + Self::ROW / 2);
            g += &legend_mark(*mark, *c, ex, ey);
            g += &format!(
                "<text x=\"{}\" y=\"{ey}\" dy=\"0.35em\" font-family=\"sans-serif\" \
                 font-size=\"{}\">{}</text>\n",
                ex + px(26),
                px(13),
                html_escape::encode_text(label)
            );
        }
        g + "</g>\n"
    }
}

/// The sample of one legend entry whose row starts at `(ex, ey)`.
fn legend_mark(mark: Mark, c: RGBColor, ex: u32, ey: u32) -> String {
    let colour = format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
    match mark {
        Mark::Point(r) => format!(
            "<circle cx=\"{}\" cy=\"{ey}\" r=\"{r}\" fill=\"{colour}\"/>\n",
            ex + px(10)
        ),
        Mark::Line => format!(
            "<line x1=\"{ex}\" y1=\"{ey}\" x2=\"{}\" y2=\"{ey}\" stroke=\"{colour}\" \
             stroke-width=\"{}\"/>\n",
            ex + px(20),
            px(2)
        ),
        Mark::Dashed => format!(
            "<line x1=\"{ex}\" y1=\"{ey}\" x2=\"{}\" y2=\"{ey}\" stroke=\"{colour}\" \
             stroke-width=\"{}\" stroke-dasharray=\"{} {}\"/>\n",
            ex + px(20),
            px(2),
            px(5),
            px(3)
        ),
        Mark::Swatch => format!(
            "<rect x=\"{ex}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{colour}\" \
             fill-opacity=\"{}\" stroke=\"{colour}\" stroke-width=\"{}\"/>\n",
            ey - px(6),
            px(20),
            px(12),
            2.0 * SPAN_OPACITY,
            px(1)
        ),
        Mark::Cross => {
            let (cx, d, w) = (ex + px(10), px(5), px(2));
            format!(
                "<path d=\"M{} {} L{} {} M{} {} L{} {}\" stroke=\"{colour}\" stroke-width=\"{w}\"/>\n",
                cx - d,
                ey - d,
                cx + d,
                ey + d,
                cx - d,
                ey + d,
                cx + d,
                ey - d
            )
        }
    }
}

/// What plotters' drawing calls return.
type DrawResult = DrawResultOf<()>;

/// A plotters drawing result carrying `T`.
type DrawResultOf<T> = std::result::Result<T, DrawingAreaErrorKind<std::io::Error>>;

/// The chart [`draw_xy`] draws into: plane coordinates on tick axes.
type XyChart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<TickAxis, TickAxis>>;

/// Draws the axes, series, reference lines and markers of [`line_chart`] on `root`.
fn draw_xy(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    plane: Plane,
    (title, x_label, y_label): (&str, &str, &str),
    series: &[Series],
    opts: &ChartOpts,
) -> DrawResultOf<Vec<PlacedLabel>> {
    let Plane { ax, ay, bx, by } = plane;
    let xt = ax.ticks(bx.0, bx.1, 10);
    let yt = ay.ticks(by.0, by.1, 6);
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", px(22)))
        .margin(px(12))
        .x_label_area_size(px(45))
        .y_label_area_size(px(75))
        .build_cartesian_2d(
            TickAxis::new(bx.0..bx.1, &xt),
            TickAxis::new(by.0..by.1, &yt),
        )?;
    let xf = |v: &f64| xt.label(*v);
    let yf = |v: &f64| yt.label(*v);
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .label_style(("sans-serif", px(13)))
        .axis_desc_style(("sans-serif", px(15)))
        .light_line_style(BLACK.mix(0.06).stroke_width(px(1)))
        .bold_line_style(BLACK.mix(0.18).stroke_width(px(1)))
        .axis_style(BLACK.stroke_width(px(1)))
        .set_all_tick_mark_size(px(5))
        .draw()?;

    draw_spans(&mut chart, plane, &opts.spans)?;
    draw_bands(&mut chart, plane, &opts.bands)?;
    for (i, s) in series.iter().enumerate() {
        draw_one_series(&mut chart, plane, i, s)?;
    }
    draw_error_bars(&mut chart, plane, &opts.error_bars)?;
    draw_vlines(&mut chart, plane, &opts.vlines)?;
    draw_markers(&mut chart, plane, &opts.markers)?;
    Ok(place_labels(&chart, plane, series, &opts.markers))
}

/// The spans inside the x range, shaded from the bottom of the plot to its top, under the data.
fn draw_spans(chart: &mut XyChart<'_, '_>, plane: Plane, spans: &[Span]) -> DrawResult {
    let Plane { ax, bx, by, .. } = plane;
    for (i, s) in spans.iter().enumerate() {
        if !(ax.valid(s.lo) && ax.valid(s.hi)) {
            continue;
        }
        let (a, b) = (ax.fwd(s.lo).max(bx.0), ax.fwd(s.hi).min(bx.1));
        if a >= b {
            continue;
        }
        chart.draw_series(std::iter::once(Rectangle::new(
            [(a, by.0), (b, by.1)],
            span_tint(i).mix(SPAN_OPACITY).filled(),
        )))?;
    }
    Ok(())
}

/// The bands as filled polygons (upper edge forward, lower edge back) in a light tint of their
/// series' colour, each point held inside the plotting box, under the data.
fn draw_bands(chart: &mut XyChart<'_, '_>, plane: Plane, bands: &[Band]) -> DrawResult {
    let Plane { ax, ay, bx, by } = plane;
    for b in bands {
        let pts: Vec<(f64, f64, f64)> = (0..b.x.len().min(b.lo.len()).min(b.hi.len()))
            .filter(|&i| ax.valid(b.x[i]) && ay.valid(b.lo[i]) && ay.valid(b.hi[i]))
            .map(|i| (ax.fwd(b.x[i]), ay.fwd(b.lo[i]), ay.fwd(b.hi[i])))
            .filter(|p| p.0 >= bx.0 && p.0 <= bx.1)
            .collect();
        if pts.len() < 2 {
            continue;
        }
        let inside = |y: f64| y.clamp(by.0, by.1);
        let outline: Vec<(f64, f64)> = pts
            .iter()
            .map(|p| (p.0, inside(p.2)))
            .chain(pts.iter().rev().map(|p| (p.0, inside(p.1))))
            .collect();
        chart.draw_series(std::iter::once(Polygon::new(
            outline,
            series_colour(b.series).mix(SPAN_OPACITY).filled(),
        )))?;
    }
    Ok(())
}

/// Series number `i` in its colour: its clipped polylines and/or a circle per visible point, as
/// one plotters series (so the legend has one entry even when the data breaks into pieces or has
/// none to show).
fn draw_one_series(chart: &mut XyChart<'_, '_>, plane: Plane, i: usize, s: &Series) -> DrawResult {
    let colour = series_colour(i);
    let line_style = colour.stroke_width(px(2));
    let lines = if s.style == SeriesStyle::Points {
        Vec::new()
    } else {
        plane.polylines(s)
    };
    let pts: Vec<(f64, f64)> = if s.style == SeriesStyle::Line {
        Vec::new()
    } else {
        s.x.iter()
            .zip(&s.y)
            .filter_map(|(&x, &y)| plane.point(x, y))
            .collect()
    };
    if s.style == SeriesStyle::Dashed {
        for l in lines {
            chart.draw_series(DashedLineSeries::new(l, px(8), px(5), line_style))?;
        }
        return Ok(());
    }
    let elems: Vec<DynElement<'static, SVGBackend<'_>, (f64, f64)>> = lines
        .into_iter()
        .map(|l| PathElement::new(l, line_style).into_dyn())
        .chain(
            pts.into_iter()
                .map(|p| Circle::new(p, px(3), colour.filled()).into_dyn()),
        )
        .collect();
    chart.draw_series(elems)?;
    Ok(())
}

/// The error bars' whiskers and caps inside the x range, each end held inside the plotting box.
fn draw_error_bars(chart: &mut XyChart<'_, '_>, plane: Plane, bars: &[ErrorBars]) -> DrawResult {
    let Plane { ax, ay, bx, by } = plane;
    let cap = 0.006 * (bx.1 - bx.0);
    for b in bars {
        let style = series_colour(b.series).stroke_width(px(2));
        for ((&x, &y), &sd) in b.x.iter().zip(&b.y).zip(&b.sd) {
            let (lo, hi) = (y - sd, y + sd);
            if !(ax.valid(x) && ay.valid(lo) && ay.valid(hi)) {
                continue;
            }
            let xp = ax.fwd(x);
            if xp < bx.0 || xp > bx.1 {
                continue;
            }
            let [l, h] = [lo, hi].map(|v| ay.fwd(v).clamp(by.0, by.1));
            let segments = [
                vec![(xp, l), (xp, h)],
                vec![(xp - cap, l), (xp + cap, l)],
                vec![(xp - cap, h), (xp + cap, h)],
            ];
            chart.draw_series(segments.into_iter().map(|s| PathElement::new(s, style)))?;
        }
    }
    Ok(())
}

/// The vertical dashed reference lines inside the x range, each labelled at its top.
fn draw_vlines(chart: &mut XyChart<'_, '_>, plane: Plane, vlines: &[(f64, String)]) -> DrawResult {
    let Plane { ax, bx, by, .. } = plane;
    let grey = RGBColor(90, 90, 90);
    for (x, label) in vlines {
        if !ax.valid(*x) {
            continue;
        }
        let xp = ax.fwd(*x);
        if xp < bx.0 || xp > bx.1 {
            continue;
        }
        chart.draw_series(DashedLineSeries::new(
            vec![(xp, by.0), (xp, by.1)],
            px(6),
            px(4),
            grey.stroke_width(px(1)),
        ))?;
        chart.draw_series(std::iter::once(
            EmptyElement::at((xp, by.1))
                + Text::new(
                    label.clone(),
                    (px(4) as i32, px(4) as i32),
                    ("sans-serif", px(13)).into_font().color(&grey),
                ),
        ))?;
    }
    Ok(())
}

/// Radius of a marker's circle, drawing units.
const MARKER_RADIUS: u32 = px(5);

/// The visible markers as open circles (their labels are placed by [`place_labels`]).
fn draw_markers(chart: &mut XyChart<'_, '_>, plane: Plane, markers: &[Marker]) -> DrawResult {
    for m in markers {
        let Some(p) = plane.point(m.x, m.y) else {
            continue;
        };
        chart.draw_series(std::iter::once(
            EmptyElement::at(p) + Circle::new((0, 0), MARKER_RADIUS, BLACK.stroke_width(px(2))),
        ))?;
    }
    Ok(())
}

/// Font size of a marker label, drawing units.
const LABEL_FONT: f64 = px(13) as f64;

/// A marker label's width per character, in font sizes: wider than a sans-serif font's average
/// glyph, and exact on the page because the text is scaled to it (`textLength`).
const LABEL_CHAR_EM: f64 = 0.6;

/// A label's extent above and below its baseline, in font sizes.
const LABEL_ASCENT_EM: f64 = 0.8;
const LABEL_DESCENT_EM: f64 = 0.25;

/// Clearance kept between a label and any line, point or other label, drawing units.
const LABEL_CLEARANCE: f64 = px(3) as f64;

/// Distances (display pixels beyond the marker's circle) at which a label is tried, nearest first;
/// beyond the first two the label gets a leader line to its marker.
const LABEL_DISTANCES_PX: [f64; 10] = [
    3.0, 10.0, 20.0, 32.0, 48.0, 70.0, 100.0, 140.0, 190.0, 250.0,
];

/// A marker label where [`place_labels`] put it (drawing units).
#[derive(Debug, Clone, PartialEq)]
struct PlacedLabel {
    text: String,
    /// Left end and baseline.
    x: f64,
    y: f64,
    width: f64,
    /// From the marker's circle to the label, when the label had to move away.
    leader: Option<[(f64, f64); 2]>,
}

/// An axis-aligned box `[x0, x1] × [y0, y1]`, drawing units.
#[derive(Debug, Clone, Copy, PartialEq)]
struct LabelBox {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl LabelBox {
    fn grown(self, d: f64) -> LabelBox {
        LabelBox {
            x0: self.x0 - d,
            y0: self.y0 - d,
            x1: self.x1 + d,
            y1: self.y1 + d,
        }
    }
    fn overlaps(&self, o: &LabelBox) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }
    fn inside(&self, o: &LabelBox) -> bool {
        self.x0 >= o.x0 && self.x1 <= o.x1 && self.y0 >= o.y0 && self.y1 <= o.y1
    }
    fn crossed_by(&self, p: (f64, f64), q: (f64, f64)) -> bool {
        clip(p, q, (self.x0, self.x1), (self.y0, self.y1)).is_some()
    }
    /// Whether a circle of radius `r` at `c` reaches into the box.
    fn touches_circle(&self, c: (f64, f64), r: f64) -> bool {
        let nx = c.0.clamp(self.x0, self.x1);
        let ny = c.1.clamp(self.y0, self.y1);
        (nx - c.0).powi(2) + (ny - c.1).powi(2) < r * r
    }
}

/// What a label must keep clear of: the data's segments and points, the markers' circles, the
/// labels placed so far, all in drawing units, and the plotting area it must stay inside.
struct Obstacles {
    segments: Vec<((f64, f64), (f64, f64))>,
    circles: Vec<((f64, f64), f64)>,
    labels: Vec<LabelBox>,
    area: LabelBox,
}

impl Obstacles {
    fn clear(&self, b: &LabelBox) -> bool {
        let g = b.grown(LABEL_CLEARANCE);
        b.inside(&self.area)
            && !self.segments.iter().any(|(p, q)| g.crossed_by(*p, *q))
            && !self.circles.iter().any(|(c, r)| g.touches_circle(*c, *r))
            && !self.labels.iter().any(|l| g.overlaps(l))
    }
}

/// Places each visible marker's label where nothing crosses it: the first clear box among
/// positions around the marker (up-right, up-left, up, right, left, down-right, down-left, down)
/// at growing distances; the nearest position when none is clear.
fn place_labels(
    chart: &XyChart<'_, '_>,
    plane: Plane,
    series: &[Series],
    markers: &[Marker],
) -> Vec<PlacedLabel> {
    let to_px = |p: (f64, f64)| {
        let (x, y) = chart.backend_coord(&p);
        (f64::from(x), f64::from(y))
    };
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let mut obstacles = Obstacles {
        segments: Vec::new(),
        circles: Vec::new(),
        labels: Vec::new(),
        area: LabelBox {
            x0: f64::from(xr.start),
            y0: f64::from(yr.start),
            x1: f64::from(xr.end),
            y1: f64::from(yr.end),
        },
    };
    for s in series {
        if s.style != SeriesStyle::Points {
            for line in plane.polylines(s) {
                let pts: Vec<(f64, f64)> = line.into_iter().map(to_px).collect();
                obstacles
                    .segments
                    .extend(pts.windows(2).map(|w| (w[0], w[1])));
            }
        }
        if s.style != SeriesStyle::Line {
            let r = f64::from(px(3));
            obstacles.circles.extend(
                s.x.iter()
                    .zip(&s.y)
                    .filter_map(|(&x, &y)| plane.point(x, y))
                    .map(|p| (to_px(p), r)),
            );
        }
    }
    let centres: Vec<(&Marker, (f64, f64))> = markers
        .iter()
        .filter_map(|m| plane.point(m.x, m.y).map(|p| (m, to_px(p))))
        .collect();
    let r = f64::from(MARKER_RADIUS);
    obstacles
        .circles
        .extend(centres.iter().map(|(_, c)| (*c, r + f64::from(px(1)))));
    let mut placed = Vec::new();
    for (m, c) in centres {
        let width = LABEL_CHAR_EM * LABEL_FONT * m.label.chars().count() as f64;
        let height = (LABEL_ASCENT_EM + LABEL_DESCENT_EM) * LABEL_FONT;
        let candidates: Vec<(LabelBox, f64)> = LABEL_DISTANCES_PX
            .iter()
            .flat_map(|d| {
                let g = r + f64::from(SCALE) * d;
                let k = std::f64::consts::FRAC_1_SQRT_2 * g;
                // (left, top) of each position.
                [
                    (c.0 + k, c.1 - k - height),
                    (c.0 - k - width, c.1 - k - height),
                    (c.0 - width / 2.0, c.1 - g - height),
                    (c.0 + g, c.1 - height / 2.0),
                    (c.0 - g - width, c.1 - height / 2.0),
                    (c.0 + k, c.1 + k),
                    (c.0 - k - width, c.1 + k),
                    (c.0 - width / 2.0, c.1 + g),
                ]
                .map(|(x0, y0)| {
                    let b = LabelBox {
                        x0,
                        y0,
                        x1: x0 + width,
                        y1: y0 + height,
                    };
                    (b, *d)
                })
            })
            .collect();
        let (b, d) = candidates
            .iter()
            .find(|(b, _)| obstacles.clear(b))
            .or_else(|| candidates.iter().find(|(b, _)| b.inside(&obstacles.area)))
            .copied()
            .unwrap_or(candidates[0]);
        obstacles.labels.push(b);
        let leader = (d > LABEL_DISTANCES_PX[1]).then(|| {
            let to = (c.0.clamp(b.x0, b.x1), c.1.clamp(b.y0, b.y1));
            let (dx, dy) = (to.0 - c.0, to.1 - c.1);
            let n = dx.hypot(dy).max(1e-9);
            [(c.0 + r * dx / n, c.1 + r * dy / n), to]
        });
        placed.push(PlacedLabel {
            text: m.label.clone(),
            x: b.x0,
            y: b.y0 + LABEL_ASCENT_EM * LABEL_FONT,
            width,
            leader,
        });
    }
    placed
}

/// The marker labels as an SVG group (empty without labels): each label's leader line, then its
/// text on a white halo, scaled to its box's width.
fn labels_svg(labels: &[PlacedLabel]) -> String {
    if labels.is_empty() {
        return String::new();
    }
    let mut g = String::from("<g class=\"marker-labels\">\n");
    for l in labels {
        if let Some([a, b]) = l.leader {
            g += &format!(
                "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#505050\" \
                 stroke-width=\"{}\"/>\n",
                a.0,
                a.1,
                b.0,
                b.1,
                px(1)
            );
        }
        g += &format!(
            "<text class=\"marker-label\" x=\"{:.1}\" y=\"{:.1}\" font-family=\"sans-serif\" \
             font-size=\"{LABEL_FONT}\" textLength=\"{:.1}\" lengthAdjust=\"spacingAndGlyphs\" \
             fill=\"#000000\" stroke=\"#FFFFFF\" stroke-width=\"{}\" stroke-linejoin=\"round\" \
             paint-order=\"stroke\">{}</text>\n",
            l.x,
            l.y,
            l.width,
            px(3),
            html_escape::encode_text(&l.text)
        );
    }
    g + "</g>\n"
}

/// Matplotlib's viridis colour map (`colorous::VIRIDIS`). `t` is clamped to [0, 1]; NaN maps to
/// the low end.
pub fn viridis(t: f64) -> RGBColor {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let c = colorous::VIRIDIS.eval_continuous(t);
    RGBColor(c.r, c.g, c.b)
}

/// Largest number of cells kept along x and y by [`heatmap`]; denser data is decimated by taking
/// the maximum over blocks (which keeps narrow spectral ridges visible).
pub const HEATMAP_MAX_CELLS: (usize, usize) = (400, 300);

/// Colour of missing cells (NaN, or non-positive with `log_z`).
const NAN_COLOUR: RGBColor = RGBColor(220, 220, 220);

/// Block maxima of `z` (`[x][y]`) over `bx × by` blocks, ignoring NaN (a block of NaN stays NaN).
fn decimate(z: &[Vec<f64>], bx: usize, by: usize) -> Vec<Vec<f64>> {
    let ny = z.first().map_or(0, Vec::len);
    z.chunks(bx)
        .map(|cols| {
            (0..ny)
                .step_by(by)
                .map(|j0| {
                    cols.iter()
                        .flat_map(|c| &c[j0..(j0 + by).min(ny)])
                        .copied()
                        .filter(|v| !v.is_nan())
                        .fold(f64::NAN, f64::max)
                })
                .collect()
        })
        .collect()
}

/// Cell edges around increasing centres `c` (midpoints; half a spacing beyond each end).
fn edges(c: &[f64]) -> Vec<f64> {
    let n = c.len();
    if n == 1 {
        let w = (c[0].abs() * 0.5).max(0.5);
        return vec![c[0] - w, c[0] + w];
    }
    let mut e = Vec::with_capacity(n + 1);
    e.push(c[0] - 0.5 * (c[1] - c[0]));
    for w in c.windows(2) {
        e.push(0.5 * (w[0] + w[1]));
    }
    e.push(c[n - 1] + 0.5 * (c[n - 1] - c[n - 2]));
    e
}

/// Edges of blocks of `b` cells, from the full edge list.
fn block_edges(e: &[f64], b: usize) -> Vec<f64> {
    let n = e.len() - 1;
    let mut out: Vec<f64> = (0..n).step_by(b).map(|i| e[i]).collect();
    out.push(e[n]);
    out
}

/// A colour-mapped image of `z[i][j]` at cell centres `(x[i], y[j])`, written as SVG (≈ 900×500 px)
/// to `path`, with a colour bar. For a [`Spectrogram`](crate::spectrum::Spectrogram) pass
/// `x = t_s`, `y = freq_hz`, `z = density` and `log_z = true` (the colour bar is then logarithmic
/// and labelled in z units). `z_label` names the colour bar's quantity and unit, e.g.
/// `"PSD [m²/Hz]"`.
///
/// `x` and `y` must be finite and strictly increasing; `z` must have `x.len()` rows of `y.len()`
/// values. More than [`HEATMAP_MAX_CELLS`] cells per axis are decimated by block maxima. NaN (and, if
/// `log_z`, non-positive) cells are drawn light grey. The cells are embedded as one PNG `<image>`
/// (rendered at the plot's pixel size), the axes and colour bar as SVG, which keeps the file small.
///
/// `percentiles`: the colour range spans these percentiles (0–100) of the colour values (log10 z
/// with `log_z`) over all finite cells, cells beyond taking the end colours, and the colour bar
/// says so; `None`: the cells' full extent. A spectrogram's extent holds a few cells many decades
/// below the rest (the detrended 0 Hz bin, the window's nulls), which would compress every line
/// into a few colours.
///
/// Errors: [`ReportError::Heatmap`] (naming the path) for empty or mismatched shapes, non-increasing
/// axes, no finite `z`, or a plotters failure; [`Error::Io`] if the file cannot be written.
#[allow(clippy::too_many_arguments)]
pub fn heatmap(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    z_label: &str,
    x: &[f64],
    y: &[f64],
    z: &[Vec<f64>],
    log_z: bool,
    percentiles: Option<(f64, f64)>,
) -> Result<()> {
    let bad = |problem| -> Error {
        ReportError::Heatmap {
            path: path.to_path_buf(),
            title: title.to_string(),
            problem,
        }
        .into()
    };
    check_heatmap_shape(x, y, z).map_err(bad)?;
    let values = colour_values(z, log_z);
    let clipped = percentiles.and_then(|p| percentile_range(&values, p));
    let (xe, ye, zd) = heatmap_cells(x, y, values);
    let extent = colour_range(&zd, log_z).map_err(bad)?;
    let zr = clipped.unwrap_or(extent);

    let size = (FIGURE_SIZE.0 * SCALE, FIGURE_SIZE.1 * SCALE);
    let mut svg = String::new();
    let image = {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let desc = match (log_z, clipped.and(percentiles)) {
            (true, Some((lo, hi))) => format!("{z_label}, log scale, {lo}–{hi} percentile"),
            (false, Some((lo, hi))) => format!("{z_label}, {lo}–{hi} percentile"),
            (true, None) => format!("{z_label}, log colour scale"),
            (false, None) => z_label.to_string(),
        };
        let labels = (title, x_label, y_label, desc.as_str());
        let r = draw_heatmap_axes(&root, labels, &xe, &ye, zr, log_z);
        let area = r
            .and_then(|a| root.present().map(|_| a))
            .map_err(|e| draw_err(path, e))?;
        heatmap_image(area, &xe, &ye, &zd, zr).ok_or_else(|| bad(HeatmapProblem::CellImage))?
    };
    // Put the image right after the background rectangle, so axes and ticks are drawn over it.
    let at = svg
        .find("<rect")
        .and_then(|i| svg[i..].find("/>").map(|j| i + j + 2))
        .ok_or_else(|| bad(HeatmapProblem::NoBackground))?;
    svg.insert_str(at, &format!("\n{image}"));
    write_svg(path, &shown_at_figure_size(&svg, size))
}

/// Why `x`, `y`, `z` are not a [`heatmap`]'s input: empty axes, `z` not `x.len()` rows of
/// `y.len()` values, or an axis not finite and strictly increasing.
fn check_heatmap_shape(
    x: &[f64],
    y: &[f64],
    z: &[Vec<f64>],
) -> std::result::Result<(), HeatmapProblem> {
    if x.is_empty() || y.is_empty() {
        let (x, y) = (x.len(), y.len());
        return Err(HeatmapProblem::EmptyAxes { x, y });
    }
    if z.len() != x.len() {
        let (rows, x) = (z.len(), x.len());
        return Err(HeatmapProblem::Rows { rows, x });
    }
    if let Some(row) = z.iter().position(|r| r.len() != y.len()) {
        let (len, y) = (z[row].len(), y.len());
        return Err(HeatmapProblem::RowLength { row, len, y });
    }
    for (axis, a) in [("x", x), ("y", y)] {
        if a.iter().any(|v| !v.is_finite()) || a.windows(2).any(|w| w[1] <= w[0]) {
            return Err(HeatmapProblem::Axis { axis });
        }
    }
    Ok(())
}

/// Colour values: log10 z for a log scale; missing cells (not finite, or non-positive with
/// `log_z`) are NaN.
fn colour_values(z: &[Vec<f64>], log_z: bool) -> Vec<Vec<f64>> {
    z.iter()
        .map(|r| {
            r.iter()
                .map(|&v| match (v.is_finite(), log_z) {
                    (false, _) => f64::NAN,
                    (true, true) if v <= 0.0 => f64::NAN,
                    (true, true) => v.log10(),
                    (true, false) => v,
                })
                .collect()
        })
        .collect()
}

/// Cell edges along x and y and the cell values, decimated by block maxima to at most
/// [`HEATMAP_MAX_CELLS`].
fn heatmap_cells(x: &[f64], y: &[f64], zt: Vec<Vec<f64>>) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    let bx = x.len().div_ceil(HEATMAP_MAX_CELLS.0);
    let by = y.len().div_ceil(HEATMAP_MAX_CELLS.1);
    let (xe, ye) = (edges(x), edges(y));
    if bx > 1 || by > 1 {
        (
            block_edges(&xe, bx),
            block_edges(&ye, by),
            decimate(&zt, bx, by),
        )
    } else {
        (xe, ye, zt)
    }
}

/// The colour bar's range: the finite cells' extent, widened by ±0.5 when flat; an error message
/// when no cell is finite.
fn colour_range(zd: &[Vec<f64>], log_z: bool) -> std::result::Result<(f64, f64), HeatmapProblem> {
    let (zmin, zmax) = zd
        .iter()
        .flatten()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if zmin > zmax {
        return Err(HeatmapProblem::NoFiniteZ { log: log_z });
    }
    Ok(if zmax > zmin {
        (zmin, zmax)
    } else {
        (zmin - 0.5, zmax + 0.5)
    })
}

/// The `(lo, hi)` percentiles (0–100) of the finite colour values, `None` when they coincide or
/// no value is finite.
fn percentile_range(values: &[Vec<f64>], (lo, hi): (f64, f64)) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = values
        .iter()
        .flatten()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    v.sort_by(f64::total_cmp);
    let q = |p: f64| crate::spectrum::stats::quantile_sorted(&v, p / 100.0);
    let (a, b) = (q(lo), q(hi));
    (a.is_finite() && b.is_finite() && b > a).then_some((a, b))
}

/// Pixel rectangle `(x0, y0, width, height)` of the plotting area.
type PixelArea = (i32, i32, u32, u32);

/// Draws title, axes and colour bar (no cells); returns the plotting area's pixel rectangle.
fn draw_heatmap_axes(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    (title, x_label, y_label, z_label): (&str, &str, &str, &str),
    xe: &[f64],
    ye: &[f64],
    (zlo, zhi): (f64, f64),
    log_z: bool,
) -> std::result::Result<PixelArea, DrawingAreaErrorKind<std::io::Error>> {
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", px(22)))?;
    let (main, bar) = root.split_horizontally(px(FIGURE_SIZE.0 - 140));
    let (x0, x1) = (xe[0], xe[xe.len() - 1]);
    let (y0, y1) = (ye[0], ye[ye.len() - 1]);
    let xt = ticks::linear(x0, x1, 10);
    let yt = ticks::linear(y0, y1, 6);
    let mut chart = ChartBuilder::on(&main)
        .margin(px(10))
        .x_label_area_size(px(45))
        .y_label_area_size(px(75))
        .build_cartesian_2d(TickAxis::new(x0..x1, &xt), TickAxis::new(y0..y1, &yt))?;
    let xf = |v: &f64| xt.label(*v);
    let yf = |v: &f64| yt.label(*v);
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .label_style(("sans-serif", px(13)))
        .axis_desc_style(("sans-serif", px(15)))
        .draw()?;
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let area = (
        xr.start,
        yr.start,
        (xr.end - xr.start).max(1) as u32,
        (yr.end - yr.start).max(1) as u32,
    );

    let zt = if log_z {
        ticks::log(zlo, zhi)
    } else {
        ticks::linear(zlo, zhi, 6)
    };
    let mut cb = ChartBuilder::on(&bar)
        .margin_top(px(10))
        .margin_bottom(px(55))
        .margin_right(px(5))
        .y_label_area_size(px(90))
        .build_cartesian_2d(0.0..1.0, TickAxis::new(zlo..zhi, &zt))?;
    let zf = |v: &f64| zt.label(*v);
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(z_label)
        .set_tick_mark_size(LabelAreaPosition::Left, px(6) as i32)
        .y_label_formatter(&zf)
        .label_style(("sans-serif", px(12)))
        .axis_desc_style(("sans-serif", px(13)))
        .draw()?;
    // Each band reaches half a band into the next (not the last): no seams between rectangles
    // that end on fractions of a pixel.
    let n = 100;
    let span = zhi - zlo;
    cb.draw_series((0..n).map(|k| {
        let a = zlo + span * k as f64 / n as f64;
        let b = zlo + span * ((k + 1) as f64 + if k + 1 < n { 0.5 } else { 0.0 }) / n as f64;
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            viridis((k as f64 + 0.5) / n as f64).filled(),
        )
    }))?;
    Ok(area)
}

/// The cells rendered at the plotting area's pixel size, as an SVG `<image>` with an embedded PNG.
fn heatmap_image(
    (x0, y0, w, h): PixelArea,
    xe: &[f64],
    ye: &[f64],
    z: &[Vec<f64>],
    (zlo, zhi): (f64, f64),
) -> Option<String> {
    let (xa, xb) = (xe[0], xe[xe.len() - 1]);
    let (ya, yb) = (ye[0], ye[ye.len() - 1]);
    // Cell index of a coordinate: the last edge ≤ v, clamped to the cell range.
    let cell = |e: &[f64], v: f64| e.partition_point(|&b| b <= v).clamp(1, e.len() - 1) - 1;
    // One image pixel per display pixel: the drawing is SCALE times the displayed size.
    let (iw, ih) = ((w / SCALE).max(1), (h / SCALE).max(1));
    let cols: Vec<usize> = (0..iw)
        .map(|c| cell(xe, xa + (c as f64 + 0.5) / iw as f64 * (xb - xa)))
        .collect();
    let rows: Vec<usize> = (0..ih)
        .map(|r| cell(ye, yb - (r as f64 + 0.5) / ih as f64 * (yb - ya)))
        .collect();
    let span = zhi - zlo;
    let mut rgb = Vec::with_capacity(iw as usize * ih as usize * 3);
    for &j in &rows {
        for &i in &cols {
            let v = z[i][j];
            let RGBColor(r, g, b) = if v.is_nan() {
                NAN_COLOUR
            } else {
                viridis((v - zlo) / span)
            };
            rgb.extend_from_slice(&[r, g, b]);
        }
    }
    let png = png::encode_rgb(iw, ih, &rgb)?;
    Some(format!(
        "<image x=\"{x0}\" y=\"{y0}\" width=\"{w}\" height=\"{h}\" preserveAspectRatio=\"none\" \
         href=\"{}\"/>",
        png::data_uri(&png)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn tmp_dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("wiperlab-plot-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn assert_svg(path: &Path, must_contain: &[&str]) -> String {
        let s = std::fs::read_to_string(path).unwrap();
        assert!(
            s.trim_start().starts_with("<svg"),
            "{}",
            &s[..80.min(s.len())]
        );
        assert!(s.trim_end().ends_with("</svg>"));
        for m in must_contain {
            assert!(s.contains(m), "{} lacks {m:?}", path.display());
        }
        s
    }

    #[test]
    fn a_residual_gets_its_own_panel_with_its_own_scale() {
        // Measured and model 1 mm sines a 1 % amplitude apart: overlaid they look the same; the
        // residual panel's axis is fitted to the 0.01 mm difference.
        let d = tmp_dir("residual");
        let t: Vec<f64> = (0..400).map(|k| k as f64 * 1e-3).collect();
        let meas: Vec<f64> = t.iter().map(|t| (50.0 * t).sin()).collect();
        let model: Vec<f64> = meas.iter().map(|v| 0.99 * v).collect();
        let residual: Vec<f64> = meas.iter().zip(&model).map(|(a, b)| a - b).collect();
        let path = d.join("residual.svg");
        line_chart(
            &path,
            "a trace",
            "t [s]",
            "x [mm]",
            &[
                Series::line("measured", t.clone(), meas),
                Series::line("model", t.clone(), model),
            ],
            &ChartOpts {
                residual: Some(Series::line("residual: measured − model", t, residual)),
                ..ChartOpts::default()
            },
        )
        .unwrap();
        // Both panels' titles, and tick labels of the residual's ±0.01 scale.
        let svg = assert_svg(&path, &["a trace", "residual: measured − model", "0.01"]);
        // The legend still lists the two overlaid series only.
        let legend = &svg[svg.find("class=\"legend\"").unwrap()..];
        assert!(legend.contains("measured") && legend.contains("model"));
        assert!(!legend.contains("residual"));
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn line_chart_with_gaps_log_axes_markers_and_vlines() {
        let d = tmp_dir("line");
        let f: Vec<f64> = (0..500).map(|k| k as f64 * 2.0).collect();
        let mut p: Vec<f64> = f
            .iter()
            .map(|f| 1e-9 + 1e-6 / (1.0 + ((f - 78.4) / 3.0).powi(2)))
            .collect();
        for v in &mut p[100..120] {
            *v = f64::NAN;
        }
        p[0] = 0.0; // not plottable on a log axis
        let sim: Vec<f64> = p.iter().map(|v| v * 2.0).collect();
        let series = [
            Series::line("measured", f.clone(), p),
            Series {
                label: "model".into(),
                x: f.clone(),
                y: sim,
                style: SeriesStyle::LinePoints,
            },
            Series::points("empty", vec![f64::NAN], vec![f64::NAN]),
        ];
        for (lx, ly) in [(false, false), (false, true), (true, true), (true, false)] {
            let opts = ChartOpts {
                log_x: lx,
                log_y: ly,
                x_range: Some((1.0, 600.0)),
                markers: vec![Marker {
                    x: 78.4,
                    y: 1e-6,
                    label: "78.4 Hz".into(),
                }],
                vlines: vec![(519.0, "neck 519 Hz".into())],
                ..ChartOpts::default()
            };
            let path = d.join(format!("psd_{lx}_{ly}.svg"));
            line_chart(
                &path,
                "PSD of lip tip",
                "frequency [Hz]",
                "PSD [m²/Hz]",
                &series,
                &opts,
            )
            .unwrap();
            let s = assert_svg(
                &path,
                &[
                    "PSD of lip tip",
                    "frequency [Hz]",
                    "PSD [m²/Hz]",
                    "measured",
                    "model",
                    "78.4 Hz",
                    "neck 519 Hz",
                ],
            );
            assert!(
                !s.contains("NaN") && !s.contains("inf"),
                "non-finite coordinates"
            );
        }
        std::fs::remove_dir_all(&d).ok();
    }

    /// The label boxes of `svg`'s marker labels and its polylines' points (drawing units).
    fn labels_and_lines(svg: &str) -> (Vec<LabelBox>, Vec<Vec<(f64, f64)>>) {
        let attr = |el: &str, name: &str| -> f64 {
            let i = el.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
            el[i..].split('"').next().unwrap().parse().unwrap()
        };
        let boxes = svg
            .split("<text class=\"marker-label\"")
            .skip(1)
            .map(|t| {
                let (x, y, fs, w) = (
                    attr(t, "x"),
                    attr(t, "y"),
                    attr(t, "font-size"),
                    attr(t, "textLength"),
                );
                LabelBox {
                    x0: x,
                    y0: y - 0.8 * fs,
                    x1: x + w,
                    y1: y + 0.25 * fs,
                }
            })
            .collect();
        let lines = svg
            .split("<polyline")
            .skip(1)
            .map(|p| {
                let pts = p
                    .split("points=\"")
                    .nth(1)
                    .unwrap()
                    .split('"')
                    .next()
                    .unwrap();
                pts.split_whitespace()
                    .map(|xy| {
                        let (a, b) = xy.split_once(',').unwrap();
                        (a.parse().unwrap(), b.parse().unwrap())
                    })
                    .collect()
            })
            .collect();
        (boxes, lines)
    }

    #[test]
    fn peak_labels_keep_clear_of_the_curves_and_of_each_other() {
        // Two markers on one sharp peak that reaches the top of the plot (as a fit's measured and
        // model peaks do), a second curve under it and a flat floor across the whole width.
        let d = tmp_dir("labels");
        let f: Vec<f64> = (0..400).map(|k| 500.0 + 11.25 * k as f64).collect();
        let peak = |f0: f64, w: f64| -> Vec<f64> {
            f.iter()
                .map(|f| 1e-15 + 4e-15 / (1.0 + ((f - f0) / w).powi(2)))
                .collect()
        };
        let series = [
            Series::line("measured", f.clone(), peak(875.6, 40.0)),
            Series::line("model", f.clone(), peak(876.4, 60.0)),
        ];
        let markers = vec![
            Marker {
                x: 875.6,
                y: 5e-15,
                label: "measured 875.61 Hz".into(),
            },
            Marker {
                x: 876.4,
                y: 5e-15,
                label: "model 876.39 Hz".into(),
            },
        ];
        let path = d.join("labels.svg");
        let opts = ChartOpts {
            log_y: true,
            markers,
            spans: vec![Span {
                lo: 500.0,
                hi: 1500.0,
                label: "band 500–1500 Hz".into(),
            }],
            ..ChartOpts::default()
        };
        line_chart(&path, "peaks", "f [Hz]", "PSD [m²/Hz]", &series, &opts).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        let (boxes, lines) = labels_and_lines(&svg);
        assert_eq!(boxes.len(), 2, "{svg}");
        assert!(!boxes[0].overlaps(&boxes[1]), "{boxes:?}");
        for b in &boxes {
            for l in &lines {
                for w in l.windows(2) {
                    assert!(
                        !b.crossed_by(w[0], w[1]),
                        "{b:?} crossed by {:?}",
                        (w[0], w[1])
                    );
                }
            }
        }
        // The band is shaded and named in the legend.
        assert!(svg.contains("fill-opacity"), "no shading");
        let legend = &svg[svg.find("<g class=\"legend\">").unwrap()..];
        assert!(legend.contains("band 500–1500 Hz"));
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn nan_breaks_lines_and_is_not_drawn_through() {
        let s = Series::line(
            "x",
            vec![0.0, 1.0, 2.0, 3.0, 4.0],
            vec![0.0, 1.0, f64::NAN, 1.0, 0.0],
        );
        let lin = Axis { log: false };
        let plane = Plane {
            ax: lin,
            ay: lin,
            bx: (0.0, 4.0),
            by: (0.0, 1.0),
        };
        let l = plane.polylines(&s);
        assert_eq!(
            l,
            vec![vec![(0.0, 0.0), (1.0, 1.0)], vec![(3.0, 1.0), (4.0, 0.0)]]
        );
        // Clipping at the x range: the segment 0→1 is cut at x = 0.5.
        let l = Plane {
            bx: (0.5, 4.0),
            ..plane
        }
        .polylines(&s);
        assert_eq!(l[0], vec![(0.5, 0.5), (1.0, 1.0)]);
        // Log y: the 0 values are invalid there and break the line too.
        let l = Plane {
            ay: Axis { log: true },
            by: (-1.0, 1.0),
            ..plane
        }
        .polylines(&s);
        assert!(l.is_empty(), "{l:?}");
    }

    #[test]
    fn line_chart_errors_name_the_path() {
        let d = tmp_dir("err");
        let path = d.join("empty.svg");
        let series = [Series::line(
            "all NaN",
            vec![1.0, 2.0],
            vec![f64::NAN, f64::NAN],
        )];
        let e = line_chart(&path, "t", "x", "y", &series, &ChartOpts::default()).unwrap_err();
        assert!(
            matches!(ReportError::of(&e), Some(ReportError::NothingToPlot { path, .. }) if path.ends_with("empty.svg")),
            "{e}"
        );
        let e = line_chart(&path, "t", "x", "y", &[], &ChartOpts::default()).unwrap_err();
        assert!(
            matches!(ReportError::of(&e), Some(ReportError::NothingToPlot { .. })),
            "{e}"
        );
        let opts = ChartOpts {
            log_y: true,
            y_range: Some((0.0, 1.0)),
            ..ChartOpts::default()
        };
        let series = [Series::line("ok", vec![1.0, 2.0], vec![1.0, 2.0])];
        assert!(matches!(
            line_chart(&path, "t", "x", "y", &series, &opts),
            Err(ref e) if matches!(ReportError::of(e), Some(ReportError::Range { .. }))
        ));
        let missing = d.join("no/such/dir/f.svg");
        let e = line_chart(&missing, "t", "x", "y", &series, &ChartOpts::default()).unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e}");
        // A single point (degenerate ranges) still draws.
        let one = [Series::points("one", vec![3.0], vec![5.0])];
        line_chart(&path, "single", "x", "y", &one, &ChartOpts::default()).unwrap();
        assert_svg(&path, &["single"]);
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn heatmap_of_chirp_spectrogram_with_decimation_and_nan() {
        let d = tmp_dir("heat");
        let fs = 8000.0;
        let x: Vec<f64> = (0..16000)
            .map(|n| {
                let t = n as f64 / fs;
                (2.0 * std::f64::consts::PI * (200.0 * t + 300.0 * t * t)).sin()
            })
            .collect();
        let mut sg = crate::spectrum::spectrogram(&x, fs, 128, 96, 1024).unwrap();
        // > 400 time slices and > 300 bins: decimated. Some NaN and zero cells.
        assert!(sg.n_times() > 400 && sg.n_freqs() > 300);
        sg.density[3][10] = f64::NAN;
        sg.density[4][10] = 0.0;
        let path = d.join("sg.svg");
        heatmap(
            &path,
            "Spectrogram of chirp",
            "time [s]",
            "frequency [Hz]",
            "PSD [1/Hz]",
            &sg.t_s,
            &sg.freq_hz,
            &sg.density,
            true,
            None,
        )
        .unwrap();
        let s = assert_svg(
            &path,
            &[
                "Spectrogram of chirp",
                "time [s]",
                "frequency [Hz]",
                "log colour scale",
                "<image",
                "data:image/png;base64,iVBORw0KGgo", // base64 of the PNG signature
            ],
        );
        // Cells are one embedded image, not one <rect> each: the file stays small.
        assert!(s.matches("<rect").count() < 300);
        assert!(s.len() < 400_000, "{} bytes", s.len());
        // Linear z, small and non-decimated.
        heatmap(
            &path,
            "small",
            "i",
            "j",
            "z [1]",
            &[0.0, 1.0],
            &[0.0, 1.0, 2.0],
            &[vec![1.0, 2.0, 3.0], vec![4.0, f64::NAN, 6.0]],
            false,
            None,
        )
        .unwrap();
        assert_svg(&path, &["small"]);
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn heatmap_rejects_bad_shapes() {
        let p = Path::new("/nonexistent/h.svg");
        let e = heatmap(
            p,
            "t",
            "x",
            "y",
            "z",
            &[0.0],
            &[0.0, 1.0],
            &[vec![1.0]],
            false,
            None,
        )
        .unwrap_err();
        assert!(
            matches!(ReportError::of(&e), Some(ReportError::Heatmap { path, .. }) if path.ends_with("h.svg")),
            "{e}"
        );
        assert!(heatmap(p, "t", "x", "y", "z", &[], &[], &[], false, None).is_err());
        assert!(
            heatmap(
                p,
                "t",
                "x",
                "y",
                "z",
                &[1.0, 0.0],
                &[0.0],
                &[vec![1.0], vec![1.0]],
                false,
                None
            )
            .is_err()
        );
        assert!(
            heatmap(
                p,
                "t",
                "x",
                "y",
                "z",
                &[0.0],
                &[0.0],
                &[vec![f64::NAN]],
                false,
                Some((5.0, 99.9))
            )
            .is_err()
        );
        assert!(
            heatmap(
                p,
                "t",
                "x",
                "y",
                "z",
                &[0.0],
                &[0.0],
                &[vec![-1.0]],
                true,
                None
            )
            .is_err()
        );
    }

    #[test]
    fn the_colour_range_spans_the_percentiles_asked_for() {
        // 0..=1000 in one row: NumPy's linear percentiles are 5th → 50, 99.9th → 999 (closed form
        // for evenly spaced values: q·(n − 1)).
        let row: Vec<f64> = (0..=1000).map(f64::from).collect();
        let (lo, hi) = percentile_range(std::slice::from_ref(&row), (5.0, 99.9)).unwrap();
        assert!(
            (lo - 50.0).abs() < 1e-9 && (hi - 999.0).abs() < 1e-9,
            "{lo} {hi}"
        );
        // NaN cells are left out; a flat field has no range.
        let mut with_nan = row;
        with_nan.push(f64::NAN);
        assert_eq!(
            percentile_range(&[with_nan], (0.0, 100.0)),
            Some((0.0, 1000.0))
        );
        assert_eq!(percentile_range(&[vec![3.0; 10]], (5.0, 99.9)), None);
        // A spectrum-like field: a line at 1e-8 over a 1e-14 floor, and a few cells at 1e-21.
        // Over its extent the floor sits 7 of 13 decades up; between the percentiles it is the
        // bottom colour and the line the top, so the line stands out over the whole bar.
        let mut z = vec![vec![1e-14; 200]; 50];
        for r in &mut z {
            r[100] = 1e-8;
        }
        z[0][0] = 1e-21;
        let (lo, hi) = percentile_range(&colour_values(&z, true), (5.0, 99.9)).unwrap();
        assert!(
            (lo - -14.0).abs() < 1e-12 && (hi - -8.0).abs() < 1e-12,
            "{lo} {hi}"
        );
        let d = tmp_dir("heat_pct");
        let path = d.join("sg.svg");
        let t: Vec<f64> = (0..50).map(f64::from).collect();
        let f: Vec<f64> = (0..200).map(f64::from).collect();
        heatmap(
            &path,
            "pct",
            "t [s]",
            "f [Hz]",
            "PSD [m²/Hz]",
            &t,
            &f,
            &z,
            true,
            Some((5.0, 99.9)),
        )
        .unwrap();
        assert_svg(&path, &["PSD [m²/Hz], log scale, 5–99.9 percentile"]);
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn colour_map() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(f64::NAN), RGBColor(68, 1, 84));
        assert_ne!(series_colour(0), series_colour(1));
    }
}
