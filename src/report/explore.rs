//! The files of `wiperlab explore`: the samples (`explore.csv`), the one-at-a-time sensitivity
//! (`sensitivity.csv`, `sensitivity.md`), the closest achievable pair and its constraint
//! (`constraint.txt`, also in `sensitivity.md` and the terminal summary) and the reachability map
//! (`reachability.svg`, the pair marked), from an [`Exploration`] computed upstream.

use crate::explore::reach::{
    BOUND_MARGIN, Constraint, EDGE_SHARE, MAX_LEVER_FACTOR, Push, Side, band_tolerance, constraint,
};
use crate::explore::{Exploration, Outcome, Sample, Sensitivity};
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
/// The closest achievable pair and its constraint, one sentence a line (the report page shows it
/// under the map).
pub const CONSTRAINT_TXT: &str = "constraint.txt";

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
    let txt = dir.join(CONSTRAINT_TXT);
    let mut lines = constraint_lines(e, &constraint(e)).join("\n");
    lines.push('\n');
    crate::io::write_atomic(&txt, lines.as_bytes())?;
    written.push(txt);
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

/// A line's prominence over its local floor as `{times}p`, or `floor not measurable` where the
/// floor has no bins to measure (NaN).
fn prominence_text(prominence: f64, times: &str) -> String {
    if prominence.is_finite() {
        format!("{times}{prominence:.1}")
    } else {
        "floor not measurable".into()
    }
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
            format!(
                "{:.1} Hz ({}{h})",
                l.freq_hz,
                prominence_text(l.prominence, "×")
            )
        }
        Outcome::Failed { cause, .. } => cause.to_string(),
    }
}

/// `sensitivity.md`: one row per freed parameter: its start and step, each band's line at the
/// lower end, the start and the upper end, and the elasticity; then the closest achievable pair,
/// its constraint and the same table around that pair.
pub fn sensitivity_markdown(e: &Exploration) -> String {
    let mut s = format!(
        "# One-at-a-time sensitivity of `{}` ({}, signal {})\n\nEach freed parameter moved alone by ±{:.0} % around the job's start (the blade file's values); per band the line (prominence over the local floor) at the lower end → start → upper end, and its elasticity d ln f / d ln θ.\n\n",
        e.job,
        e.model,
        e.signal.label(),
        100.0 * crate::explore::OAT_STEP
    );
    s += &oat_table(e, &e.sensitivity);
    s += "\n## Closest achievable pair and the constraint\n\n";
    for l in constraint_lines(e, &constraint(e)) {
        s += &format!("- {l}\n");
    }
    if let Some(k) = e.closest_pair {
        s += &format!(
            "\nAround sample {k}, each freed parameter moved alone by ±{:.0} % (a bound may be crossed):\n\n",
            100.0 * crate::explore::OAT_STEP
        );
        s += &oat_table(e, &e.around_closest);
    }
    s
}

/// A one-at-a-time table in Markdown: per parameter its value and step, each band's line at the
/// three points and the elasticity.
fn oat_table(e: &Exploration, rows: &[Sensitivity]) -> String {
    let mut s = "| parameter | value | ± step |".to_string();
    for (b, _) in &e.bands {
        s += &format!(" {b}: lower → at → upper | {b}: d ln f / d ln θ |");
    }
    s += "\n|---|---|---|";
    s += &"---|---|".repeat(e.bands.len());
    s.push('\n');
    for r in rows {
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

/// A value with its parameter's unit, e.g. `1.000e-2 kg`.
fn with_unit(e: &Exploration, param: usize, v: f64) -> String {
    match e.free[param].name.unit() {
        "-" => format!("{v:.3e}"),
        u => format!("{v:.3e} {u}"),
    }
}

/// The closest pair's lines against the targets, e.g. `low 61.0 Hz (×900) against 78.4 Hz (−22.2 %)`.
fn pair_text(e: &Exploration, s: &Sample) -> String {
    let Some(lines) = s.outcome.lines() else {
        return String::new();
    };
    let parts: Vec<String> = lines
        .iter()
        .zip(&e.bands)
        .zip(&e.targets)
        .map(|((l, (name, _)), t)| {
            let against = t.map_or(String::new(), |t| {
                format!(
                    " against {} Hz ({:+.2} %)",
                    span_text(t),
                    100.0 * crate::explore::reach::relative_miss(l.freq_hz, t)
                )
            });
            format!(
                "{name} {:.1} Hz ({}){against}",
                l.freq_hz,
                prominence_text(l.prominence, "x")
            )
        })
        .collect();
    parts.join(", ")
}

/// The closest achievable pair and its constraint in sentences (computed from `c`).
pub fn constraint_lines(e: &Exploration, c: &Constraint) -> Vec<String> {
    let tol: Vec<String> = (0..e.bands.len())
        .map(|b| format!("{} {:.0} %", e.bands[b].0, 100.0 * band_tolerance(b)))
        .collect();
    let metric = format!(
        "distance = the largest |relative miss| / tolerance over the bands ({})",
        tol.join(", ")
    );
    let mut out = Vec::new();
    let Some(closest) = c.closest else {
        out.push(format!(
            "No sample gave every band an own line at least {}x its local floor, so there is no closest achievable pair.",
            crate::spectrum::harmonics::MIN_PROMINENCE
        ));
        out.extend(nearer_line(e, c, "with lines"));
        return out;
    };
    let s = &e.samples[closest.sample];
    let values: Vec<String> = (0..e.free.len())
        .map(|i| format!("{}={}", e.free[i].name, with_unit(e, i, s.values[i])))
        .collect();
    out.push(format!(
        "Closest achievable pair (own lines, at least {}x their floor; {metric}): sample {}, distance {:.2}: {}.",
        crate::spectrum::harmonics::MIN_PROMINENCE,
        closest.sample,
        closest.distance,
        pair_text(e, s)
    ));
    out.push(format!("Its parameters: {}.", values.join(", ")));
    out.push(bounds_line(e, c, s));
    match c.binding {
        None => out.push("It reaches every target within its tolerance.".into()),
        Some((b, miss)) => out.extend(binding_lines(e, c, s, b, miss)),
    }
    out.extend(nearer_line(e, c, "nearer than it"));
    out
}

/// Which freed parameters of the closest sample sit on a bound.
fn bounds_line(e: &Exploration, c: &Constraint, s: &Sample) -> String {
    if c.hits.is_empty() {
        return format!(
            "No freed parameter is within {:.0} % of the box of a bound there.",
            100.0 * BOUND_MARGIN
        );
    }
    let hits: Vec<String> = c
        .hits
        .iter()
        .map(|h| {
            let f = &e.free[h.param];
            let bound = if h.side == Side::Lower {
                f.lower
            } else {
                f.upper
            };
            format!(
                "{} {} ({} at the bound {})",
                f.name,
                with_unit(e, h.param, s.values[h.param]),
                h.side,
                with_unit(e, h.param, bound)
            )
        })
        .collect();
    format!(
        "On a bound (within {:.0} % of the box): {}.",
        100.0 * BOUND_MARGIN,
        hits.join("; ")
    )
}

/// The binding band, what each lever would need to move it to its target (checked by a
/// simulation), which bound stops that, and what lies beside that bound.
fn binding_lines(e: &Exploration, c: &Constraint, s: &Sample, b: usize, miss: f64) -> Vec<String> {
    let f_hz = s.outcome.lines().map_or(f64::NAN, |l| l[b].freq_hz);
    let goal = e.targets[b].map_or(f64::NAN, |t| f_hz.clamp(t[0], t[1]));
    let name = &e.bands[b].0;
    let mut out = vec![format!(
        "Farthest from its target: band {name}, {f_hz:.1} Hz ({:+.2} %, {:.1} tolerances). Levers (elasticity d ln f / d ln θ from the sample's ±{:.0} % steps, both keeping an own, prominent line; first-order value for {goal} Hz within {}x of the sample's), strongest first:",
        100.0 * miss,
        miss.abs() / band_tolerance(b),
        100.0 * crate::explore::OAT_STEP,
        MAX_LEVER_FACTOR
    )];
    let mut levers: Vec<&Push> = c
        .pushes
        .iter()
        .filter(|p| p.is_lever(s.values[p.param]))
        .collect();
    levers.sort_by(|x, y| y.elasticity.abs().total_cmp(&x.elasticity.abs()));
    let mut blocked = Vec::new();
    for p in &levers {
        let (line, stop) = lever_line(e, p, b, miss);
        out.push(line);
        blocked.extend(stop);
    }
    if levers.is_empty() {
        out.push("  none.".into());
    }
    out.extend(others_line(e, c, s));
    out.push(if blocked.is_empty() {
        format!(
            "Constraint: no bound stops a lever of band {name}; {}.",
            if levers.is_empty() {
                "no freed parameter moves its own line far enough"
            } else {
                "its levers reach inside the box only to first order (see what their simulations gave)"
            }
        )
    } else {
        format!("Constraint: band {name} needs {}.", blocked.join("; or "))
    });
    out.extend(c.edges.iter().map(|x| edge_line(e, c, x)));
    out
}

/// One lever of band `b` (the sample's relative miss `miss`): its elasticity, first-order value,
/// the bound beyond it, and what its simulation gave ([`Exploration::lever_checks`]), nearer to the
/// target than the sample or not; and the constraint's phrase when a bound stops it.
fn lever_line(e: &Exploration, p: &Push, b: usize, miss: f64) -> (String, Option<String>) {
    let f = &e.free[p.param];
    let goal = e.targets[b].map_or(f64::NAN, |t| if miss < 0.0 { t[0] } else { t[1] });
    let check = e.lever_checks.iter().find(|k| k.param == p.param);
    let verdict = check.map_or(String::new(), |k| check_verdict(e, &k.outcome, b, miss));
    let needed = with_unit(e, p.param, p.needed);
    let stop = p.beyond.map(|side| {
        let bound = if side == Side::Lower {
            f.lower
        } else {
            f.upper
        };
        let on = if p.on_bound {
            " (the sample sits on it)"
        } else {
            ""
        };
        format!(
            "{} {} {}{on}: {needed} to first order{verdict}",
            f.name,
            side.text(),
            with_unit(e, p.param, bound)
        )
    });
    let place = match &stop {
        Some(_) => "beyond the box",
        None => "inside the box",
    };
    let simulated = check
        .map(|k| format!("; simulated there: {}", outcome_text(e, &k.outcome)))
        .unwrap_or_default();
    (
        format!(
            "  {}: elasticity {:+.3}; {goal} Hz needs {needed} ({place}){simulated}{verdict}.",
            f.name, p.elasticity
        ),
        stop,
    )
}

/// Whether a lever's simulated set brought band `b` nearer to its target than the sample's
/// relative miss `miss`, e.g. `, which gave band low −47.30 %, not nearer than the sample`.
fn check_verdict(e: &Exploration, o: &Outcome, b: usize, miss: f64) -> String {
    let (Some(lines), Some(t)) = (o.lines(), e.targets[b]) else {
        return ", where the simulation failed".into();
    };
    let m = crate::explore::reach::relative_miss(lines[b].freq_hz, t);
    let how = if m.abs() <= band_tolerance(b) {
        "within the tolerance"
    } else if m.abs() < miss.abs() {
        "nearer than the sample"
    } else {
        "not nearer than the sample"
    };
    format!(
        ", where the simulation gave band {} {:+.2} %, {how}",
        e.bands[b].0,
        100.0 * m
    )
}

/// The freed parameters that are not levers: too weak, or their step lost the line.
fn others_line(e: &Exploration, c: &Constraint, s: &Sample) -> Option<String> {
    let weak: Vec<String> = c
        .pushes
        .iter()
        .filter(|p| !p.is_lever(s.values[p.param]))
        .map(|p| format!("{} ({:+.3})", e.free[p.param].name, p.elasticity))
        .collect();
    let jumps: Vec<String> = c
        .jumps
        .iter()
        .map(|i| e.free[*i].name.to_string())
        .collect();
    let mut parts = Vec::new();
    if !weak.is_empty() {
        parts.push(format!(
            "move it too little (more than {}x their value needed): {}",
            MAX_LEVER_FACTOR,
            weak.join(", ")
        ));
    }
    if !jumps.is_empty() {
        parts.push(format!(
            "a ±{:.0} % step lost the band's own, prominent line (another line took its place, or the run failed): {}",
            100.0 * crate::explore::OAT_STEP,
            jumps.join(", ")
        ));
    }
    (!parts.is_empty()).then(|| format!("Not levers: {}.", parts.join("; ")))
}

/// Every band's line of an outcome, or the failure cause.
fn outcome_text(e: &Exploration, o: &Outcome) -> String {
    match o {
        Outcome::Lines { .. } => (0..e.bands.len())
            .map(|b| format!("{} {}", e.bands[b].0, line_text(o, b)))
            .collect::<Vec<_>>()
            .join(", "),
        Outcome::Failed { cause, .. } => format!("failed: {cause}"),
    }
}

/// What the outer [`EDGE_SHARE`] of the box beside a bound gave, and the one-at-a-time step past it.
fn edge_line(e: &Exploration, c: &Constraint, x: &crate::explore::reach::Edge) -> String {
    let f = &e.free[x.param];
    let causes: Vec<String> = x.failures.iter().map(|(k, n)| format!("{k} {n}")).collect();
    let failed = x.samples - x.with_lines;
    let all_failed = e.samples.len() - e.with_lines();
    let mut s = format!(
        "Beside {}'s {} bound (the outer {:.0} % of its box): {} samples, {} gave lines, {failed} failed{} (over the whole box {all_failed} of {} failed)",
        f.name,
        x.side,
        100.0 * EDGE_SHARE,
        x.samples,
        x.with_lines,
        if causes.is_empty() {
            String::new()
        } else {
            format!(" ({})", causes.join(", "))
        },
        e.samples.len()
    );
    let step = c
        .pushes
        .iter()
        .find(|p| p.param == x.param && p.on_bound)
        .and_then(|_| e.around_closest.get(x.param))
        .map(|r| &r.outcomes[if x.side == Side::Lower { 0 } else { 2 }]);
    if let Some(o) = step {
        let what = outcome_text(e, o);
        s += &format!(
            "; the sample's ±{:.0} % step past it gave {what}",
            100.0 * crate::explore::OAT_STEP
        );
    }
    s.push('.');
    s
}

/// The samples that came nearer than the closest pair (or at all) with lines that do not count.
fn nearer_line(e: &Exploration, c: &Constraint, what: &str) -> Option<String> {
    let (k, d, band, flaw) = c.nearer.best?;
    let n: usize = c.nearer.by_flaw.iter().map(|x| x.1).sum();
    let list = |v: &[(crate::explore::reach::LineFlaw, usize)]| {
        v.iter()
            .map(|(f, n)| format!("{f} {n}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let within: usize = c.nearer.within.iter().map(|x| x.1).sum();
    let within = if within > 0 {
        format!(
            "; {within} of them within every tolerance ({})",
            list(&c.nearer.within)
        )
    } else {
        String::new()
    };
    Some(format!(
        "{n} samples {what} had a line that does not count ({}){within}; the nearest, sample {k} at distance {d:.2} ({}), has band {}'s line {}.",
        list(&c.nearer.by_flaw),
        pair_text(e, &e.samples[k]),
        e.bands[band].0,
        flaw.text()
    ))
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
    if let Some(k) = e.closest_pair
        && let Some(l) = e.samples[k].outcome.lines()
    {
        targets.push(Target {
            label: format!(
                "closest achievable pair, sample {k} ({:.1} Hz x{:.0}, {:.1} Hz x{:.0})",
                l[0].freq_hz, l[0].prominence, l[1].freq_hz, l[1].prominence
            ),
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
    let ok = e.with_lines();
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
    let tol: Vec<f64> = (0..e.bands.len()).map(band_tolerance).collect();
    let reached = e.samples.iter().filter(|x| e.reaches(x, &tol)).count();
    s += &format!(
        "  reaching every target (first band within 1 %, the others within 2 %, each line its own and at least {}x its local floor): {reached}\n",
        crate::spectrum::harmonics::MIN_PROMINENCE
    );
    for l in constraint_lines(e, &constraint(e)) {
        s += &format!("  {l}\n");
    }
    if let Some(c) = e.closest() {
        s += "  lowest job cost:";
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
