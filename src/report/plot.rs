//! SVG figures with plotters (SVG backend only; text is emitted as SVG `<text>`, no font files).
//!
//! * [`line_chart`]: x–y series (traces, PSDs) with optional log axes, peak markers and vertical
//!   reference lines. NaN (or, on a log axis, a non-positive value) breaks a line: nothing is drawn
//!   through a gap, and such points never enter the axis-range computation. Lines are clipped to
//!   the plotted range. The legend sits in a strip below the plotting area, so it covers no data;
//!   the chart is drawn at [`SCALE`] times its size and shown at [`FIGURE_SIZE`] through the SVG
//!   `viewBox`, so coordinates are not rounded to whole pixels.
//! * [`heatmap`]: a spectrogram-style `z[x][y]` image with a viridis colour map and colour bar.
//!
//! Figures are rendered into memory and written with one `crate::io::write_atomic`, so a failed write is an
//! [`Error::Io`] naming the path; a plotters drawing failure is a [`ReportError::Draw`] naming the
//! path, data with nothing plottable a [`ReportError::NothingToPlot`].
//!
//! The report stage computes nothing: pass it spectra and traces computed upstream.

mod png;
mod scatter;
mod ticks;

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
    let legend = Legend::of(series);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(path, e))?;
        let (plot_root, _) = root.split_vertically(size.1 - legend.height);
        draw_panels(&plot_root, plane, (title, x_label, y_label), series, opts)
            .and_then(|_| root.present())
            .map_err(|e| draw_err(path, e))?;
    }
    let svg =
        shown_at_figure_size(&svg, size).replace("</svg>", &legend.svg(size.1 - legend.height));
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
) -> std::result::Result<(), DrawingAreaErrorKind<std::io::Error>> {
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
    draw_xy(&top, plane, labels, series, opts)?;
    draw_xy(
        &bottom,
        residual_plane,
        (&r.label, labels.1, labels.2),
        std::slice::from_ref(r),
        &plain,
    )
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
    Point(u32),
    Cross,
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

    /// The legend of [`line_chart`]'s series, in the figure's width.
    fn of(series: &[Series]) -> Legend {
        Legend::new(
            series.iter().enumerate().map(|(i, s)| {
                let mark = if s.style == SeriesStyle::Points {
                    Mark::Point(px(3))
                } else {
                    Mark::Line
                };
                (s.label.clone(), series_colour(i), mark)
            }),
            FIGURE_SIZE.0,
        )
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
type DrawResult = std::result::Result<(), DrawingAreaErrorKind<std::io::Error>>;

/// The chart [`draw_xy`] draws into: plane coordinates on tick axes.
type XyChart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<TickAxis, TickAxis>>;

/// Draws the axes, series, reference lines and markers of [`line_chart`] on `root`.
fn draw_xy(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    plane: Plane,
    (title, x_label, y_label): (&str, &str, &str),
    series: &[Series],
    opts: &ChartOpts,
) -> DrawResult {
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

    for (i, s) in series.iter().enumerate() {
        draw_one_series(&mut chart, plane, i, s)?;
    }
    draw_vlines(&mut chart, plane, &opts.vlines)?;
    draw_markers(&mut chart, plane, &opts.markers)
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

/// The visible markers as open circles with their labels.
fn draw_markers(chart: &mut XyChart<'_, '_>, plane: Plane, markers: &[Marker]) -> DrawResult {
    for (i, m) in markers.iter().enumerate() {
        let Some(p) = plane.point(m.x, m.y) else {
            continue;
        };
        // Every other label goes below its marker, so two close peaks (measured and model) keep
        // readable labels.
        let dy = px(if i % 2 == 0 { 16 } else { 0 }) as i32;
        let dy = if i % 2 == 0 { -dy } else { px(4) as i32 };
        chart.draw_series(std::iter::once(
            EmptyElement::at(p)
                + Circle::new((0, 0), px(5), BLACK.stroke_width(px(2)))
                + Text::new(
                    m.label.clone(),
                    (px(7) as i32, dy),
                    ("sans-serif", px(13)).into_font(),
                ),
        ))?;
    }
    Ok(())
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
    let (xe, ye, zd) = heatmap_cells(x, y, colour_values(z, log_z));
    let zr = colour_range(&zd, log_z).map_err(bad)?;

    let size = (FIGURE_SIZE.0 * SCALE, FIGURE_SIZE.1 * SCALE);
    let mut svg = String::new();
    let image = {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let labels = (title, x_label, y_label, z_label);
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
    let desc = if log_z {
        format!("{z_label}, log colour scale")
    } else {
        z_label.to_string()
    };
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(desc)
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
        )
        .unwrap_err();
        assert!(
            matches!(ReportError::of(&e), Some(ReportError::Heatmap { path, .. }) if path.ends_with("h.svg")),
            "{e}"
        );
        assert!(heatmap(p, "t", "x", "y", "z", &[], &[], &[], false).is_err());
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
                false
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
                false
            )
            .is_err()
        );
        assert!(heatmap(p, "t", "x", "y", "z", &[0.0], &[0.0], &[vec![-1.0]], true).is_err());
    }

    #[test]
    fn colour_map() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(f64::NAN), RGBColor(68, 1, 84));
        assert_ne!(series_colour(0), series_colour(1));
    }
}
