//! A corner plot of a posterior sample (Foreman-Mackey 2016, *JOSS* 1:24, as in `corner.py`): for
//! k parameters a k × k grid whose diagonal holds each parameter's histogram and whose lower
//! triangle holds each pair's draws, with the fit and (when known) the truth marked. Drawn at
//! [`SCALE`] times its size and shown through the `viewBox`, like the other figures.

use std::path::Path;

use plotters::prelude::*;

use super::ticks::{self, TickAxis};
use super::{DrawResult, SCALE, draw_err, px};
use crate::Result;

/// One parameter of [`corner_plot`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CornerAxis {
    /// Axis label, with its unit.
    pub label: String,
    /// The draws of this parameter (the same draws, in the same order, for every axis).
    pub draws: Vec<f64>,
    /// The fit's value (a black line or cross).
    pub fit: f64,
    /// The true value when known (a red line or cross).
    pub truth: Option<f64>,
    /// The 68.27 % interval, dashed on the histogram.
    pub interval: [f64; 2],
}

/// Side of one cell, display pixels.
const CELL: u32 = 230;
/// Histogram bins on the diagonal.
const BINS: usize = 30;
const DRAW_COLOUR: RGBColor = RGBColor(31, 119, 180);
const TRUTH_COLOUR: RGBColor = RGBColor(214, 39, 40);

/// The plotted range of `a`: its draws, fit and truth, padded by 5 % (widened when flat).
fn range_of(a: &CornerAxis) -> (f64, f64) {
    let values = a.draws.iter().chain([&a.fit]).chain(a.truth.iter());
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(*v), h.max(*v))
        });
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1e-12)
    };
    (lo - pad, hi + pad)
}

/// Counts of `x` in [`BINS`] equal bins over `(lo, hi)`.
fn histogram(x: &[f64], (lo, hi): (f64, f64)) -> Vec<usize> {
    let mut counts = vec![0; BINS];
    for v in x.iter().filter(|v| v.is_finite()) {
        let b = ((v - lo) / (hi - lo) * BINS as f64).floor();
        if (0.0..BINS as f64).contains(&b) {
            counts[b as usize] += 1;
        }
    }
    counts
}

/// The corner plot of `axes` at `path`, under `title`.
///
/// # Errors
/// [`crate::report::ReportError::NothingToPlot`] without axes or draws;
/// [`crate::report::ReportError::Draw`] for a plotters failure; [`crate::Error::Io`] for the write.
pub fn corner_plot(path: &Path, title: &str, axes: &[CornerAxis]) -> Result<()> {
    if axes.is_empty() || axes[0].draws.is_empty() {
        return Err(crate::report::ReportError::NothingToPlot {
            path: path.to_path_buf(),
            title: title.into(),
            log: false,
        }
        .into());
    }
    let k = axes.len() as u32;
    let shown = (CELL * k + 40, CELL * k + 50);
    let size = (shown.0 * SCALE, shown.1 * SCALE);
    let ranges: Vec<(f64, f64)> = axes.iter().map(range_of).collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let drawn = root
            .fill(&WHITE)
            .and_then(|_| root.titled(title, ("sans-serif", px(18))))
            .and_then(|area| {
                let cells = area.split_evenly((axes.len(), axes.len()));
                for (n, cell) in cells.iter().enumerate() {
                    let (i, j) = (n / axes.len(), n % axes.len());
                    if j < i {
                        draw_pair(cell, axes, &ranges, (i, j))?;
                    } else if j == i {
                        draw_histogram(cell, &axes[i], ranges[i], i + 1 == axes.len())?;
                    }
                }
                root.present()
            });
        drawn.map_err(|e| draw_err(path, e))?;
    }
    let svg = svg.replacen(
        &format!("<svg width=\"{}\" height=\"{}\"", size.0, size.1),
        &format!("<svg width=\"{}\" height=\"{}\"", shown.0, shown.1),
        1,
    );
    crate::io::write_atomic(path, svg.as_bytes())
}

type CellChart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, plotters::coord::cartesian::Cartesian2d<TickAxis, TickAxis>>;

type Cell<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;

/// Builds a cell's chart over `x` × `y` with tick labels on the bottom row and left column only.
fn cell_chart<'a, 'b>(
    cell: &'a Cell<'b>,
    (x, y): ((f64, f64), (f64, f64)),
    labels: (Option<&str>, Option<&str>),
    ticks: &'a (ticks::Ticks, ticks::Ticks),
) -> std::result::Result<CellChart<'a, 'b>, DrawingAreaErrorKind<std::io::Error>> {
    let mut chart = ChartBuilder::on(cell)
        .margin(px(4))
        .x_label_area_size(px(if labels.0.is_some() { 42 } else { 4 }))
        .y_label_area_size(px(if labels.1.is_some() { 58 } else { 4 }))
        .build_cartesian_2d(
            TickAxis::new(x.0..x.1, &ticks.0),
            TickAxis::new(y.0..y.1, &ticks.1),
        )?;
    let (xf, yf) = (|v: &f64| ticks.0.label(*v), |v: &f64| ticks.1.label(*v));
    let blank = |_: &f64| String::new();
    let mut mesh = chart.configure_mesh();
    mesh.label_style(("sans-serif", px(10)))
        .axis_desc_style(("sans-serif", px(11)))
        .light_line_style(TRANSPARENT)
        .bold_line_style(BLACK.mix(0.08).stroke_width(px(1)));
    match labels.0 {
        Some(l) => mesh.x_desc(l).x_label_formatter(&xf),
        None => mesh.x_label_formatter(&blank),
    };
    match labels.1 {
        Some(l) => mesh.y_desc(l).y_label_formatter(&yf),
        None => mesh.y_label_formatter(&blank),
    };
    mesh.draw()?;
    Ok(chart)
}

/// The histogram of one parameter, its 68.27 % interval dashed, the fit black, the truth red.
fn draw_histogram(cell: &Cell<'_>, a: &CornerAxis, x: (f64, f64), bottom: bool) -> DrawResult {
    let counts = histogram(&a.draws, x);
    let top = 1.1 * counts.iter().copied().max().unwrap_or(1).max(1) as f64;
    let t = (ticks::linear(x.0, x.1, 4), ticks::linear(0.0, top, 3));
    let mut chart = cell_chart(
        cell,
        (x, (0.0, top)),
        (bottom.then_some(&*a.label), None),
        &t,
    )?;
    let w = (x.1 - x.0) / BINS as f64;
    chart.draw_series(counts.iter().enumerate().map(|(b, c)| {
        let x0 = x.0 + b as f64 * w;
        Rectangle::new(
            [(x0, 0.0), (x0 + w, *c as f64)],
            DRAW_COLOUR.mix(0.5).filled(),
        )
    }))?;
    for v in a.interval {
        chart.draw_series(DashedLineSeries::new(
            [(v, 0.0), (v, top)],
            px(5),
            px(4),
            BLACK.stroke_width(px(1)),
        ))?;
    }
    let marks = [(Some(a.fit), BLACK), (a.truth, TRUTH_COLOUR)];
    for (v, colour) in marks.iter().filter_map(|(v, c)| v.map(|v| (v, c))) {
        chart.draw_series(LineSeries::new(
            [(v, 0.0), (v, top)],
            colour.stroke_width(px(2)),
        ))?;
    }
    Ok(())
}

/// The draws of parameters `j` (x) and `i` (y), the fit a black cross, the truth a red one.
fn draw_pair(
    cell: &Cell<'_>,
    axes: &[CornerAxis],
    r: &[(f64, f64)],
    (i, j): (usize, usize),
) -> DrawResult {
    let t = (
        ticks::linear(r[j].0, r[j].1, 4),
        ticks::linear(r[i].0, r[i].1, 4),
    );
    let labels = (
        (i + 1 == axes.len()).then_some(axes[j].label.as_str()),
        (j == 0).then_some(axes[i].label.as_str()),
    );
    let mut chart = cell_chart(cell, (r[j], r[i]), labels, &t)?;
    chart.draw_series(
        axes[j]
            .draws
            .iter()
            .zip(&axes[i].draws)
            .map(|(x, y)| Circle::new((*x, *y), px(1), DRAW_COLOUR.mix(0.35).filled())),
    )?;
    let truth = axes[j].truth.zip(axes[i].truth);
    for (p, colour) in [
        (Some((axes[j].fit, axes[i].fit)), BLACK),
        (truth, TRUTH_COLOUR),
    ] {
        if let Some(p) = p {
            chart.draw_series(std::iter::once(Cross::new(
                p,
                px(6),
                colour.stroke_width(px(2)),
            )))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_plot_has_a_histogram_per_parameter_and_points_per_pair() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("corner.svg");
        let axis = |label: &str, f: fn(usize) -> f64| CornerAxis {
            label: label.into(),
            draws: (0..200).map(f).collect(),
            fit: f(100),
            truth: Some(f(50)),
            interval: [f(40), f(160)],
        };
        let axes = [
            axis("A", |n| n as f64 / 200.0),
            axis("B (s/m)", |n| 100.0 + ((n * 37) % 200) as f64),
            axis("C", |n| 0.3 + 1e-3 * ((n * 11) % 200) as f64),
        ];
        corner_plot(&path, "posterior", &axes).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        // 3 pairs × 200 draws, drawn as circles; 3 histograms of 30 bins (rectangles).
        assert_eq!(svg.matches("<circle").count(), 3 * 200, "circles");
        assert!(svg.matches("<rect").count() >= 3 * BINS);
        // B labels the bottom row's middle x axis and the left column's middle y axis.
        assert_eq!(svg.matches("B (s/m)").count(), 2);
        let empty = [CornerAxis::default()];
        assert!(corner_plot(&path, "posterior", &empty).is_err());
    }

    #[test]
    fn histogram_bins_count_every_draw_inside_the_range() {
        let c = histogram(&[0.0, 0.05, 0.5, 0.99, 1.0, f64::NAN], (0.0, 1.0));
        // 1.0 is the range's upper edge (outside the half-open last bin), NaN is skipped.
        assert_eq!(c.iter().sum::<usize>(), 4);
        assert_eq!((c[0], c[1], c[15], c[29]), (1, 1, 1, 1));
    }
}
