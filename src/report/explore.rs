//! The files of `wiperlab explore`: the samples (`explore.csv`), the one-at-a-time sensitivity
//! (`sensitivity.csv`, `sensitivity.md`) and the reachability map (`reachability.svg`), from an
//! [`Exploration`] computed upstream.

use crate::fit::explore::{Exploration, Outcome, Sample};
use crate::report::plot::{Category, Panel, Target, scatter_panels};
use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// The samples' table.
pub const SAMPLES_CSV: &str = "explore.csv";
/// The sensitivity table, CSV and Markdown.
pub const SENSITIVITY_CSV: &str = "sensitivity.csv";
pub const SENSITIVITY_MD: &str = "sensitivity.md";
/// The reachability map.
pub const MAP_SVG: &str = "reachability.svg";

/// Writes the four files into `dir` (created if missing); returns their paths.
///
/// # Errors
/// [`Error::Io`] naming the file; [`super::ReportError`] when the figure cannot be drawn.
pub fn write_exploration(dir: &Path, e: &Exploration) -> Result<Vec<PathBuf>> {
    crate::io::create_dir(dir)?;
    let mut written = Vec::new();
    let samples = dir.join(SAMPLES_CSV);
    crate::io::write_atomic(&samples, samples_csv(e)?.as_bytes())?;
    written.push(samples);
    let sens = dir.join(SENSITIVITY_CSV);
    crate::io::write_atomic(&sens, sensitivity_csv(e)?.as_bytes())?;
    written.push(sens);
    let md = dir.join(SENSITIVITY_MD);
    crate::io::write_atomic(&md, sensitivity_markdown(e).as_bytes())?;
    written.push(md);
    if e.bands.len() >= 2 {
        let map = dir.join(MAP_SVG);
        scatter_panels(&map, &map_title(e), &map_panels(e))?;
        written.push(map);
    }
    Ok(written)
}

fn csv_err(e: impl std::error::Error + Send + Sync + 'static) -> Error {
    Error::write("an exploration table", "CSV", e)
}

/// Header cells of one band's columns.
fn band_header(band: &str) -> [String; 4] {
    [
        format!("{band}_hz"),
        format!("{band}_prominence"),
        format!("{band}_harmonic_of_hz"),
        format!("{band}_below_dominant"),
    ]
}

/// `f64` as a CSV cell: shortest round-trip form, empty for NaN.
fn cell(v: f64) -> String {
    if v.is_nan() {
        String::new()
    } else {
        v.to_string()
    }
}

/// One sample's cells after its parameters: per band the line, then cost, failure and message.
fn outcome_cells(o: &Outcome, bands: usize) -> Vec<String> {
    let mut row = Vec::new();
    match o {
        Outcome::Lines { lines, cost } => {
            for l in lines {
                row.extend([
                    cell(l.freq_hz),
                    cell(l.prominence),
                    l.harmonic_of_hz.map(cell).unwrap_or_default(),
                    cell(l.below_dominant),
                ]);
            }
            row.extend([cell(*cost), String::new(), String::new()]);
        }
        Outcome::Failed { cause, message } => {
            row.extend(std::iter::repeat_n(String::new(), 4 * bands + 1));
            row.extend([cause.to_string(), message.clone()]);
        }
    }
    row
}

/// `explore.csv`: `sample` (0-based Sobol index), the freed parameters (SI, the names of
/// `[fit.parameters]`), per band `<band>_hz`, `_prominence`, `_harmonic_of_hz`,
/// `_below_dominant`, then `cost` (the job's), `failure` and `failure_message`.
pub fn samples_csv(e: &Exploration) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["sample".to_string()];
    header.extend(e.free.iter().map(|f| f.name.to_string()));
    for (b, _) in &e.bands {
        header.extend(band_header(b));
    }
    header.extend(["cost", "failure", "failure_message"].map(String::from));
    w.write_record(&header).map_err(csv_err)?;
    for (i, s) in e.samples.iter().enumerate() {
        let mut row = vec![i.to_string()];
        row.extend(s.values.iter().map(|v| cell(*v)));
        row.extend(outcome_cells(&s.outcome, e.bands.len()));
        w.write_record(&row).map_err(csv_err)?;
    }
    String::from_utf8(w.into_inner().map_err(|e| csv_err(e.into_error()))?).map_err(csv_err)
}

/// `sensitivity.csv`: per freed parameter and end (`lower`, `start`, `upper`), its value, the
/// lines and failure as in `explore.csv`, and per band the elasticity d ln f / d ln θ.
pub fn sensitivity_csv(e: &Exploration) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["parameter".to_string(), "at".into(), "value".into()];
    for (b, _) in &e.bands {
        header.extend(band_header(b));
    }
    header.extend(["cost", "failure", "failure_message"].map(String::from));
    header.extend(e.bands.iter().map(|(b, _)| format!("{b}_elasticity")));
    w.write_record(&header).map_err(csv_err)?;
    for s in &e.sensitivity {
        for (k, at) in ["lower", "start", "upper"].iter().enumerate() {
            let mut row = vec![s.parameter.to_string(), at.to_string(), cell(s.values[k])];
            row.extend(outcome_cells(&s.outcomes[k], e.bands.len()));
            row.extend(s.elasticity.iter().map(|x| x.map(cell).unwrap_or_default()));
            w.write_record(&row).map_err(csv_err)?;
        }
    }
    String::from_utf8(w.into_inner().map_err(|e| csv_err(e.into_error()))?).map_err(csv_err)
}

/// A line as `f Hz (prominence ×p)`, or the failure cause.
fn line_text(o: &Outcome, band: usize) -> String {
    match o {
        Outcome::Lines { lines, .. } => {
            let l = &lines[band];
            let h = l
                .harmonic_of_hz
                .map(|h| format!(", harmonic of {h:.1} Hz"))
                .unwrap_or_default();
            format!("{:.1} Hz (×{:.1}{h})", l.freq_hz, l.prominence)
        }
        Outcome::Failed { cause, .. } => cause.to_string(),
    }
}

/// `sensitivity.md`: one row per freed parameter: its start and step, each band's line at the
/// lower end, the start and the upper end, and the elasticity.
pub fn sensitivity_markdown(e: &Exploration) -> String {
    let mut s = format!(
        "# One-at-a-time sensitivity of `{}` ({}, signal {})\n\nEach freed parameter moved alone by ±{:.0} % around the job's start (the blade file's values); per band the line (prominence over the local floor) at the lower end → start → upper end, and its elasticity d ln f / d ln θ.\n\n| parameter | start | ± step |",
        e.job,
        e.model,
        e.signal.label(),
        100.0 * crate::fit::explore::OAT_STEP
    );
    for (b, _) in &e.bands {
        s += &format!(" {b}: lower → start → upper | {b}: d ln f / d ln θ |");
    }
    s += "\n|---|---|---|";
    s += &"---|---|".repeat(e.bands.len());
    s.push('\n');
    for r in &e.sensitivity {
        s += &format!(
            "| {} | {:.4e} | {:.2e} |",
            r.parameter,
            r.values[1],
            0.5 * (r.values[2] - r.values[0])
        );
        for b in 0..e.bands.len() {
            s += &format!(
                " {} → {} → {} | {} |",
                line_text(&r.outcomes[0], b),
                line_text(&r.outcomes[1], b),
                line_text(&r.outcomes[2], b),
                r.elasticity[b].map_or("—".into(), |x| format!("{x:+.3}"))
            );
        }
        s.push('\n');
    }
    s
}

fn map_title(e: &Exploration) -> String {
    format!(
        "{}: {} Sobol samples (seed {}) of {} freed parameters, {}",
        e.job,
        e.samples.len(),
        e.seed,
        e.free.len(),
        e.model
    )
}

/// The two panels: achieved (band 0, band 1) lines coloured by the weaker line's prominence, with
/// the targets and the start; and the failures by cause in the plane of the two parameters that
/// best separate them.
fn map_panels(e: &Exploration) -> Vec<Panel> {
    let (b0, b1) = (&e.bands[0], &e.bands[1]);
    let coloured: Vec<(f64, f64, f64)> = e
        .samples
        .iter()
        .filter_map(|s| s.outcome.lines())
        .map(|l| {
            (
                l[0].freq_hz,
                l[1].freq_hz,
                l[0].prominence.min(l[1].prominence),
            )
        })
        .collect();
    let mut targets = Vec::new();
    if let (Some(x), Some(y)) = (e.targets[0], e.targets[1]) {
        targets.push(Target {
            label: format!("target ({} Hz, {} Hz)", span_text(x), span_text(y)),
            x_span: x,
            y_span: y,
        });
    }
    if let Some(l) = e.start.outcome.lines() {
        targets.push(Target {
            label: format!("start ({:.1} Hz, {:.1} Hz)", l[0].freq_hz, l[1].freq_hz),
            x_span: [l[0].freq_hz; 2],
            y_span: [l[1].freq_hz; 2],
        });
    }
    let map = Panel {
        title: format!(
            "reachability: {} of {} runs gave both lines",
            coloured.len(),
            e.samples.len()
        ),
        x_label: format!("line in band '{}' [Hz]", b0.0),
        y_label: format!("line in band '{}' [Hz]", b1.0),
        x_range: (b0.1[0], b0.1[1]),
        y_range: (b1.1[0], b1.1[1]),
        coloured,
        z_label: "weaker line's prominence, power over local floor [-]".into(),
        targets,
        ..Panel::default()
    };
    let mut panels = vec![map];
    if e.free.len() >= 2 {
        panels.push(failure_panel(e));
    }
    panels
}

fn span_text(r: [f64; 2]) -> String {
    if r[0] == r[1] {
        format!("{}", r[0])
    } else {
        format!("{}–{}", r[0], r[1])
    }
}

/// The failures by cause over the two parameters that best separate them (the other runs grey).
fn failure_panel(e: &Exploration) -> Panel {
    let (i, j) = e.failure_axes();
    let (fi, fj) = (&e.free[i], &e.free[j]);
    let pick = |keep: &dyn Fn(&Sample) -> bool| {
        let s: Vec<&Sample> = e.samples.iter().filter(|s| keep(s)).collect();
        (
            s.iter().map(|s| s.values[i]).collect::<Vec<_>>(),
            s.iter().map(|s| s.values[j]).collect::<Vec<_>>(),
        )
    };
    let (x, y) = pick(&|s| s.outcome.lines().is_some());
    let mut categories = vec![Category {
        label: format!("gave lines ({})", x.len()),
        x,
        y,
        muted: true,
    }];
    for (cause, n) in e.failure_counts() {
        let (x, y) =
            pick(&|s| matches!(&s.outcome, Outcome::Failed { cause: c, .. } if *c == cause));
        categories.push(Category {
            label: format!("{cause} ({n})"),
            x,
            y,
            muted: false,
        });
    }
    Panel {
        title: "failed runs by cause".into(),
        x_label: fi.name.axis_label(),
        y_label: fj.name.axis_label(),
        log_x: fi.log,
        log_y: fj.log,
        x_range: (fi.lower, fi.upper),
        y_range: (fj.lower, fj.upper),
        categories,
        ..Panel::default()
    }
}

/// A few lines for the terminal: counts, failures by cause, the closest sample and where the
/// files are.
pub fn summary(e: &Exploration) -> String {
    let ok = e
        .samples
        .iter()
        .filter(|s| s.outcome.lines().is_some())
        .count();
    let mut s = format!(
        "{}: {} samples of {} ({}), {ok} gave lines in every band, {:.1} s on {} threads\n",
        e.job,
        e.samples.len(),
        crate::names::join(&e.free.iter().map(|f| f.name).collect::<Vec<_>>(), ", "),
        e.model,
        e.wall_time_s,
        e.threads
    );
    for (cause, n) in e.failure_counts() {
        s += &format!("  failed: {cause} {n}\n");
    }
    let tol: Vec<f64> = (0..e.bands.len())
        .map(|b| if b == 0 { 0.01 } else { 0.02 })
        .collect();
    let reached = e.samples.iter().filter(|x| e.reaches(x, &tol)).count();
    s += &format!(
        "  reaching every target (first band within 1 %, the others within 2 %, each line its own and at least {}x its local floor): {reached}\n",
        crate::spectrum::harmonics::MIN_PROMINENCE
    );
    if let Some(c) = e.closest() {
        s += "  closest to the targets (lowest job cost):";
        for (f, v) in e.free.iter().zip(&c.values) {
            s += &format!(" {}={v:.4e}", f.name);
        }
        s.push('\n');
        for (b, (name, _)) in e.bands.iter().enumerate() {
            s += &format!("    {name}: {}", line_text(&c.outcome, b));
            if let Some(t) = e.targets[b] {
                s += &format!(" against {} Hz", span_text(t));
            }
            s.push('\n');
        }
    }
    s
}
