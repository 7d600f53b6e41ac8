//! The campaign report: `<campaign dir>/<name>/report/index.html` with the collected table, the
//! failed recordings, the outliers, each fitted parameter against each condition (with its interval
//! where there is one) and the fitted friction laws overlaid. Everything shown is computed by
//! `crate::campaign::collect`; this module only draws and lays out.

use super::plot::{ChartOpts, Series, line_chart};
use crate::campaign::collect::{OUTLIER_Z, Outlier, Row, Table};
use crate::{Error, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};

const TEMPLATE: &str = include_str!("templates/campaign.html");

#[derive(Serialize)]
struct Figure {
    file: String,
    caption: String,
}

#[derive(Serialize)]
struct CellValue {
    value: String,
    interval: String,
}

#[derive(Serialize)]
struct RowView {
    index: usize,
    id: String,
    labels: Vec<String>,
    state: String,
    model: String,
    values: Vec<CellValue>,
    cost: String,
    wall: String,
}

#[derive(Serialize)]
struct Failure {
    id: String,
    reason: String,
}

#[derive(Serialize)]
struct OutlierView {
    id: String,
    param: String,
    value: String,
    z: String,
}

fn fmt(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.5}")
    } else {
        "–".into()
    }
}

/// The x positions of one condition column: numbers when every value is one, otherwise category
/// indices 1…k in first-seen order (returned as the axis label's legend).
fn condition_axis(values: &[String]) -> (Vec<f64>, String) {
    let nums: Option<Vec<f64>> = values.iter().map(|v| v.parse::<f64>().ok()).collect();
    if let Some(n) = nums {
        return (n, String::new());
    }
    let mut cats: Vec<&str> = Vec::new();
    let x = values
        .iter()
        .map(|v| {
            let i = cats.iter().position(|c| c == v).unwrap_or_else(|| {
                cats.push(v);
                cats.len() - 1
            });
            (i + 1) as f64
        })
        .collect();
    let legend = cats
        .iter()
        .enumerate()
        .map(|(i, c)| format!("{} = {c}", i + 1))
        .collect::<Vec<_>>()
        .join(", ");
    (x, format!(" [category: {legend}]"))
}

/// The x axis label of condition `cond`: with the categories' legend (`" [category: …]"`), with
/// an override's unit, or, for a numeric column of the conditions table, in that table's unit.
fn condition_label(cond: &str, legend: &str) -> String {
    if !legend.is_empty() {
        return format!("{cond}{legend}");
    }
    match crate::campaign::Override::from_column(cond) {
        Some(o) => format!("{cond} [{}]", o.unit()),
        None => format!("{cond} [unit of the conditions table]"),
    }
}

/// The condition columns of `t` with their value per row: the labels, then the overrides set for
/// at least one recording.
fn conditions(t: &Table) -> Vec<(String, Vec<String>)> {
    let mut out: Vec<(String, Vec<String>)> = t
        .label_columns
        .iter()
        .enumerate()
        .map(|(i, c)| {
            (
                c.clone(),
                t.rows.iter().map(|r| r.labels[i].clone()).collect(),
            )
        })
        .collect();
    for (i, o) in crate::campaign::Override::ALL.iter().enumerate() {
        let vals: Vec<f64> = t.rows.iter().map(|r| r.overrides[i]).collect();
        if vals.iter().any(|v| v.is_finite()) {
            out.push((
                o.column().to_string(),
                vals.iter().map(|v| format!("{v}")).collect(),
            ));
        }
    }
    out
}

fn param_of(r: &Row, p: &str) -> Option<(f64, f64, f64)> {
    r.params
        .iter()
        .find(|(n, _)| n == p)
        .map(|(_, v)| (v.value, v.lo, v.hi))
}

/// `<p>_vs_<condition>.svg`: the fitted value of every done recording against one condition, and
/// its interval ends where the results have intervals.
fn param_figure(dir: &Path, t: &Table, p: &str, cond: &str, values: &[String]) -> Result<Figure> {
    let (x, legend) = condition_axis(values);
    // Keep points off the frame: pad the range by half a category (or 5 % of a numeric span).
    let (lo, hi) = x
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let pad = if legend.is_empty() {
        0.05 * (hi - lo).max(1e-9 * lo.abs().max(1.0))
    } else {
        0.5
    };
    let mut pts = (Vec::new(), Vec::new());
    let mut ends = (Vec::new(), Vec::new());
    for (r, xi) in t.rows.iter().zip(&x) {
        if let Some((v, lo, hi)) = param_of(r, p) {
            pts.0.push(*xi);
            pts.1.push(v);
            for e in [lo, hi].into_iter().filter(|e| e.is_finite()) {
                ends.0.push(*xi);
                ends.1.push(e);
            }
        }
    }
    let mut series = vec![Series::points(format!("fitted {p}"), pts.0, pts.1)];
    if !ends.0.is_empty() {
        series.push(Series::points("interval ends", ends.0, ends.1));
    }
    let file = format!("{p}_vs_{cond}.svg");
    line_chart(
        &dir.join(&file),
        &format!("{p} against {cond}, one point per recording"),
        &condition_label(cond, &legend),
        &p.parse::<crate::model::ParamId>()
            .map_or_else(|_| p.to_string(), |id| id.axis_label()),
        &series,
        &ChartOpts {
            x_range: lo.is_finite().then_some((lo - pad, hi + pad)),
            ..ChartOpts::default()
        },
    )?;
    Ok(Figure {
        caption: format!("{p} against {cond}"),
        file,
    })
}

/// `friction_laws.svg`: the fitted μ_d(|v|) of every done recording (its blade file's law).
fn friction_figure(dir: &Path, t: &Table) -> Result<Option<Figure>> {
    let v: Vec<f64> = (0..=200).map(|i| i as f64 * 0.2 / 200.0).collect();
    let series: Vec<Series> = t
        .rows
        .iter()
        .filter_map(|r| {
            let law = r.friction?;
            let label = std::iter::once(r.id.clone())
                .chain(r.labels.iter().cloned())
                .collect::<Vec<_>>()
                .join(" ");
            Some(Series::line(
                label,
                v.clone(),
                v.iter().map(|s| law.mu_slip(*s)).collect(),
            ))
        })
        .collect();
    if series.is_empty() {
        return Ok(None);
    }
    line_chart(
        &dir.join("friction_laws.svg"),
        "fitted dynamic friction laws μ_d(|v|), each recording's blade law",
        "slip speed |v| [m/s]",
        "dynamic friction coefficient μ_d [-]",
        &series,
        &ChartOpts::default(),
    )?;
    Ok(Some(Figure {
        file: "friction_laws.svg".into(),
        caption: "fitted friction laws, one per recording".into(),
    }))
}

fn row_view(i: usize, r: &Row, params: &[String]) -> RowView {
    RowView {
        index: i,
        id: r.id.clone(),
        labels: r.labels.clone(),
        state: r.state.clone(),
        model: r.model.clone(),
        values: params
            .iter()
            .map(|p| match param_of(r, p) {
                Some((v, lo, hi)) => CellValue {
                    value: fmt(v),
                    interval: if lo.is_finite() && hi.is_finite() {
                        format!("[{}, {}]", fmt(lo), fmt(hi))
                    } else {
                        "–".into()
                    },
                },
                None => CellValue {
                    value: "–".into(),
                    interval: "–".into(),
                },
            })
            .collect(),
        cost: fmt(r.cost),
        wall: fmt(r.wall_time_s),
    }
}

/// Writes the campaign report into `dir` (created if needed): `index.html` and its SVG figures.
/// Returns the page's path.
///
/// # Errors
/// [`Error::Io`] when `dir` or a file cannot be written; [`super::ReportError`] from drawing or the
/// template.
pub fn write_campaign_report(
    dir: &Path,
    name: &str,
    t: &Table,
    outliers: &[Outlier],
) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "cannot create directory", e))?;
    let mut figures = Vec::new();
    if let Some(f) = friction_figure(dir, t)? {
        figures.push(f);
    }
    // A condition with one value for every recording says nothing: no figure.
    let varying: Vec<(String, Vec<String>)> = conditions(t)
        .into_iter()
        .filter(|(_, v)| v.iter().any(|x| *x != v[0]))
        .collect();
    for p in &t.param_names {
        for (cond, values) in &varying {
            figures.push(param_figure(dir, t, p, cond, values)?);
        }
    }
    let count = |s: &str| t.rows.iter().filter(|r| r.state == s).count();
    let ctx = minijinja::context! {
        name,
        total => t.rows.len(),
        done => count("done"),
        failed => count("failed"),
        missing => count("missing"),
        label_columns => &t.label_columns,
        params => &t.param_names,
        rows => t.rows.iter().enumerate().map(|(i, r)| row_view(i + 1, r, &t.param_names)).collect::<Vec<_>>(),
        failures => t.rows.iter().filter(|r| r.state == "failed").map(|r| Failure { id: r.id.clone(), reason: r.reason.clone() }).collect::<Vec<_>>(),
        outliers => outliers.iter().map(|o| OutlierView { id: o.id.clone(), param: o.param.clone(), value: fmt(o.value), z: format!("{:.1}", o.robust_z) }).collect::<Vec<_>>(),
        outlier_z => OUTLIER_Z,
        figures,
    };
    let mut env = minijinja::Environment::new();
    env.set_auto_escape_callback(|_| minijinja::AutoEscape::Html);
    let html = env
        .render_str(TEMPLATE, ctx)
        .map_err(|source| super::ReportError::Template {
            page: "campaign report",
            source,
        })?;
    let path = dir.join("index.html");
    crate::io::write_atomic(&path, html.as_bytes())?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numeric_and_categorical_conditions() {
        let (x, legend) = condition_axis(&["20".into(), "35.5".into()]);
        assert_eq!(x, vec![20.0, 35.5]);
        assert!(legend.is_empty());
        let (x, legend) = condition_axis(&["soft".into(), "hard".into(), "soft".into()]);
        assert_eq!(x, vec![1.0, 2.0, 1.0]);
        assert_eq!(legend, " [category: 1 = soft, 2 = hard]");
    }
}
