//! Scatter panels side by side: points coloured by a value (with a labelled log colour bar), points
//! grouped by category (each in its own colour, with a legend), and marked targets. Drawn like
//! [`super::line_chart`]: at [`SCALE`] times the size, shown through the `viewBox`.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::ticks::{self, TickAxis};
use super::{Axis, DrawResult, Legend, Mark, SCALE, draw_err, plane_range, px, viridis};
use crate::Result;

/// Points of one category (e.g. one failure cause), drawn in one colour with a legend entry.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Category {
    pub label: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    /// Drawn light grey and small (context, e.g. the runs that did not fail).
    pub muted: bool,
}

/// A marked point with a label (a target, the start), drawn as a black cross; `x_span` and `y_span`
/// draw its range as a dashed box when they are wider than a point.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Target {
    pub label: String,
    pub x_span: [f64; 2],
    pub y_span: [f64; 2],
}

/// One panel of [`scatter_panels`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
    /// Plotted ranges (data units).
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    /// `(x, y, z)`: coloured by z on a log scale (viridis); z ≤ 0 or NaN is drawn grey.
    pub coloured: Vec<(f64, f64, f64)>,
    /// What z is, with its unit, for the colour bar.
    pub z_label: String,
    pub categories: Vec<Category>,
    pub targets: Vec<Target>,
}

/// Colours of the categories that are not muted, in order: red, orange, purple, brown, pink, olive
/// (Tableau 10, leaving out the blue and green of the viridis map and the grey of muted points).
const CATEGORY_COLOURS: [RGBColor; 6] = [
    RGBColor(214, 39, 40),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
];

/// Panel size in display pixels.
const PANEL: (u32, u32) = (620, 520);
/// Width of a colour bar beside a panel, display pixels.
const BAR: u32 = 170;

/// Panels left to right in one SVG at `path`, under `title`.
///
/// # Errors
/// [`crate::report::ReportError::PanelRange`] (naming the path) for a range that is not finite and
/// increasing (and positive on a log axis); [`crate::report::ReportError::Draw`] for a plotters
/// failure; [`Error::Io`] for the write.
pub fn scatter_panels(path: &Path, title: &str, panels: &[Panel]) -> Result<()> {
    for p in panels {
        for (name, (lo, hi), log) in [("x", p.x_range, p.log_x), ("y", p.y_range, p.log_y)] {
            if !(lo.is_finite() && hi.is_finite() && lo < hi && (!log || lo > 0.0)) {
                return Err(crate::report::ReportError::PanelRange {
                    path: path.to_path_buf(),
                    panel: p.title.clone(),
                    axis: name,
                    lo,
                    hi,
                    log,
                }
                .into());
            }
        }
    }
    let widths: Vec<u32> = panels
        .iter()
        .map(|p| PANEL.0 + if p.coloured.is_empty() { 0 } else { BAR })
        .collect();
    let legends: Vec<Legend> = panels
        .iter()
        .zip(&widths)
        .map(|(p, w)| panel_legend(p, *w))
        .collect();
    let strip = legends.iter().map(|l| l.height).max().unwrap_or(0);
    let shown = (
        widths.iter().sum::<u32>().max(1),
        PANEL.1 + 40 + strip / SCALE,
    );
    let size = (shown.0 * SCALE, shown.1 * SCALE);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let drawn = root
            .fill(&WHITE)
            .and_then(|_| {
                root.split_vertically(size.1 - strip)
                    .0
                    .titled(title, ("sans-serif", px(20)))
            })
            .and_then(|area| {
                let mut rest = area;
                for (p, w) in panels.iter().zip(&widths) {
                    let (this, next) = rest.split_horizontally(px(*w));
                    draw_panel(&this, p)?;
                    rest = next;
                }
                root.present()
            });
        drawn.map_err(|e| draw_err(path, e))?;
    }
    // Each panel's legend in the strip under it, where it covers no data.
    let mut groups = String::new();
    let mut left = 0;
    for (l, w) in legends.iter().zip(&widths) {
        groups += &l.group(left, size.1 - strip);
        left += px(*w);
    }
    let svg = svg
        .replacen(
            &format!("<svg width=\"{}\" height=\"{}\"", size.0, size.1),
            &format!("<svg width=\"{}\" height=\"{}\"", shown.0, shown.1),
            1,
        )
        .replace("</svg>", &(groups + "</svg>"));
    crate::io::write_atomic(path, svg.as_bytes())
}

/// The legend of a panel `width_px` wide: its categories (by their colour and point size), then its
/// targets (black crosses).
fn panel_legend(p: &Panel, width_px: u32) -> Legend {
    let cats = p.categories.iter().enumerate().map(|(i, c)| {
        let (col, r) = category_style(i, c);
        (c.label.clone(), col, Mark::Point(r))
    });
    let targets = p
        .targets
        .iter()
        .map(|t| (t.label.clone(), BLACK, Mark::Cross));
    Legend::new(cats.chain(targets), width_px)
}

/// Colour and radius (drawing units) of category number `i`.
fn category_style(i: usize, c: &Category) -> (RGBColor, u32) {
    if c.muted {
        (RGBColor(200, 200, 200), px(2))
    } else {
        (CATEGORY_COLOURS[i % CATEGORY_COLOURS.len()], px(3))
    }
}

/// The log10 colour range of the positive finite z values, widened when flat.
fn z_range(points: &[(f64, f64, f64)]) -> Option<(f64, f64)> {
    let (lo, hi) = points
        .iter()
        .filter(|p| p.2.is_finite() && p.2 > 0.0)
        .map(|p| p.2.log10())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    let widened = if hi > lo {
        (lo, hi)
    } else {
        (lo - 0.5, hi + 0.5)
    };
    (lo <= hi).then_some(widened)
}

/// One panel: axes, coloured points, categories, targets, and its colour bar.
fn draw_panel(area: &DrawingArea<SVGBackend<'_>, Shift>, p: &Panel) -> DrawResult {
    let zr = z_range(&p.coloured);
    let (main, bar) = area.split_horizontally(px(PANEL.0));
    let (ax, ay) = (Axis { log: p.log_x }, Axis { log: p.log_y });
    let bx = plane_range(ax, p.x_range.0, p.x_range.1, 0.0);
    let by = plane_range(ay, p.y_range.0, p.y_range.1, 0.0);
    let (xt, yt) = (ax.ticks(bx.0, bx.1, 8), ay.ticks(by.0, by.1, 8));
    let mut chart = ChartBuilder::on(&main)
        .caption(&p.title, ("sans-serif", px(15)))
        .margin(px(10))
        .x_label_area_size(px(45))
        .y_label_area_size(px(70))
        .build_cartesian_2d(
            TickAxis::new(bx.0..bx.1, &xt),
            TickAxis::new(by.0..by.1, &yt),
        )?;
    let (xf, yf) = (|v: &f64| xt.label(*v), |v: &f64| yt.label(*v));
    chart
        .configure_mesh()
        .x_desc(p.x_label.as_str())
        .y_desc(p.y_label.as_str())
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .label_style(("sans-serif", px(12)))
        .axis_desc_style(("sans-serif", px(13)))
        .light_line_style(BLACK.mix(0.05).stroke_width(px(1)))
        .bold_line_style(BLACK.mix(0.15).stroke_width(px(1)))
        .draw()?;
    let inside = |x: f64, y: f64| {
        (ax.valid(x) && ay.valid(y))
            .then(|| (ax.fwd(x), ay.fwd(y)))
            .filter(|q| q.0 >= bx.0 && q.0 <= bx.1 && q.1 >= by.0 && q.1 <= by.1)
    };
    let colour = |z: f64| match zr {
        Some((lo, hi)) if z.is_finite() && z > 0.0 => viridis((z.log10() - lo) / (hi - lo)),
        _ => RGBColor(160, 160, 160),
    };
    chart.draw_series(p.coloured.iter().filter_map(|&(x, y, z)| {
        inside(x, y).map(|q| Circle::new(q, px(3), colour(z).filled()))
    }))?;
    for (i, c) in p.categories.iter().enumerate() {
        let (col, r) = category_style(i, c);
        chart.draw_series(
            c.x.iter()
                .zip(&c.y)
                .filter_map(|(&x, &y)| inside(x, y))
                .map(move |q| Circle::new(q, r, col.filled())),
        )?;
    }
    draw_targets(&mut chart, p, &inside)?;
    match zr {
        Some(r) => colour_bar(&bar, r, &p.z_label),
        None => Ok(()),
    }
}

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<TickAxis, TickAxis>>;

/// Each target as a black cross with its label, and its span as a dashed box when it has one.
fn draw_targets(
    chart: &mut Chart<'_, '_>,
    p: &Panel,
    inside: &dyn Fn(f64, f64) -> Option<(f64, f64)>,
) -> DrawResult {
    for t in &p.targets {
        let (cx, cy) = (
            0.5 * (t.x_span[0] + t.x_span[1]),
            0.5 * (t.y_span[0] + t.y_span[1]),
        );
        let corners = [
            inside(t.x_span[0], t.y_span[0]),
            inside(t.x_span[1], t.y_span[1]),
        ];
        if let [Some(a), Some(b)] = corners
            && (a.0 != b.0 || a.1 != b.1)
        {
            chart.draw_series(DashedLineSeries::new(
                vec![(a.0, a.1), (b.0, a.1), (b.0, b.1), (a.0, b.1), (a.0, a.1)],
                px(6),
                px(4),
                BLACK.stroke_width(px(1)),
            ))?;
        }
        let Some(q) = inside(cx, cy) else {
            continue;
        };
        chart.draw_series(std::iter::once(
            EmptyElement::at(q)
                + Cross::new((0, 0), px(7), BLACK.stroke_width(px(3)))
                + Text::new(
                    t.label.clone(),
                    (px(9) as i32, -(px(16) as i32)),
                    ("sans-serif", px(12)).into_font(),
                ),
        ))?;
    }
    Ok(())
}

/// A vertical viridis bar over the log10 range `(lo, hi)`, labelled in data units.
fn colour_bar(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    (lo, hi): (f64, f64),
    label: &str,
) -> DrawResult {
    let zt = ticks::log(lo, hi);
    let mut cb = ChartBuilder::on(area)
        .margin_top(px(40))
        .margin_bottom(px(55))
        .margin_right(px(70))
        .y_label_area_size(px(80))
        .build_cartesian_2d(0.0..1.0, TickAxis::new(lo..hi, &zt))?;
    let zf = |v: &f64| zt.label(*v);
    let desc = format!("{label}, log scale");
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(desc.as_str())
        .y_label_formatter(&zf)
        .label_style(("sans-serif", px(11)))
        .axis_desc_style(("sans-serif", px(12)))
        .draw()?;
    // Each band reaches half a band into the next (not the last): no seams between rectangles
    // that end on fractions of a pixel.
    let n = 100;
    cb.draw_series((0..n).map(|k| {
        let a = lo + (hi - lo) * k as f64 / n as f64;
        let b = lo + (hi - lo) * ((k + 1) as f64 + if k + 1 < n { 0.5 } else { 0.0 }) / n as f64;
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            viridis((k as f64 + 0.5) / n as f64).filled(),
        )
    }))?;
    Ok(())
}
