//! What can go wrong in the report stage: [`ReportError`], naming the figure's path and its numbers.

use std::path::PathBuf;

/// A figure or page that cannot be drawn.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// plotters failed; `reason` is its message (plotters' error type is generic over the drawing
    /// backend, so its text is what is kept).
    #[error("{}: drawing the figure failed: {reason}", path.display())]
    Draw { path: PathBuf, reason: String },
    /// An explicit chart range (`x_range` or `y_range`) that is not finite and increasing, or not
    /// positive on a log axis.
    #[error(
        "{}: {range} = ({lo}, {hi}) must be finite, increasing{}",
        path.display(),
        if *log { " and positive (log axis)" } else { "" }
    )]
    Range {
        path: PathBuf,
        range: &'static str,
        lo: f64,
        hi: f64,
        log: bool,
    },
    /// A scatter panel's `axis` (x or y) range that is not finite and increasing (and positive on
    /// a log axis).
    #[error(
        "{}: panel \"{panel}\": {axis} range ({lo}, {hi}) must be finite and increasing{}",
        path.display(),
        if *log { " and positive (log axis)" } else { "" }
    )]
    PanelRange {
        path: PathBuf,
        panel: String,
        axis: &'static str,
        lo: f64,
        hi: f64,
        log: bool,
    },
    /// A chart without a single plottable point (`log`: a log axis, which also needs positive
    /// values).
    #[error(
        "{}: nothing to plot in \"{title}\": no finite (x, y) point{}",
        path.display(),
        if *log { " with positive values on the log axes" } else { "" }
    )]
    NothingToPlot {
        path: PathBuf,
        title: String,
        log: bool,
    },
    /// A heatmap whose input is not drawable.
    #[error("{}: heatmap \"{title}\": {problem}", path.display())]
    Heatmap {
        path: PathBuf,
        title: String,
        problem: HeatmapProblem,
    },
    /// An HTML page's template (`page`) does not render.
    #[error("{page} template: {source}")]
    Template {
        page: &'static str,
        #[source]
        source: minijinja::Error,
    },
}

/// Why a heatmap's `x`, `y`, `z` cannot be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum HeatmapProblem {
    /// An axis without values.
    #[error("expected non-empty axes, got {x} x and {y} y values")]
    EmptyAxes { x: usize, y: usize },
    /// `z` not one row per x value.
    #[error("z has {rows} rows, expected one per x value ({x})")]
    Rows { rows: usize, x: usize },
    /// A row of `z` not one value per y value.
    #[error("z row {row} has {len} values, expected one per y value ({y})")]
    RowLength { row: usize, len: usize, y: usize },
    /// An axis not finite and strictly increasing.
    #[error("{axis} must be finite and strictly increasing")]
    Axis { axis: &'static str },
    /// No finite (with `log`: positive) z value.
    #[error("no finite{} z value", if *log { " positive" } else { "" })]
    NoFiniteZ { log: bool },
    /// The cells' PNG image could not be encoded.
    #[error("could not encode the cell image")]
    CellImage,
    /// plotters' SVG has no background rectangle to put the cell image after.
    #[error("unexpected SVG from plotters (no background)")]
    NoBackground,
}

impl ReportError {
    /// True for a chart range the caller set (exit code 2); false for data that cannot be drawn.
    pub fn is_setting(&self) -> bool {
        matches!(
            self,
            ReportError::Range { .. } | ReportError::PanelRange { .. }
        )
    }

    /// The report stage's error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&ReportError> {
        e.stage_error()
    }
}

impl From<ReportError> for crate::Error {
    fn from(e: ReportError) -> Self {
        let input = e.is_setting();
        crate::Error::stage(e, input)
    }
}
