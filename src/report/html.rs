//! The report page `reports/<job>/index.html` (`wiperlab report JOB`): one self-contained HTML file
//! that shows a fit result to an engineer.
//!
//! Contents, in order: the fit summary; the parameter table (value, 1σ from the cost's curvature,
//! confidence interval when the fit computed one, search bounds, determined or not, truth and
//! relative error when known); measured against model spectral peaks; the model comparison
//! (`model_trials`, or with one trial or none a line saying that only one model was fitted, and
//! why); the correlation matrix; warnings; every SVG figure of `reports/<job>/`; provenance
//! (recording path and SHA-256 at fit time and now, wiperlab version, solver tolerances, bands, fit
//! settings, dates).
//!
//! Figures are `<img src="NAME.svg">` links relative to the page (the SVGs sit beside it), so the
//! page stays small and each figure is also a file of its own. Nothing is fetched from the network:
//! the style sheet and the figure check are inline. All text from results and jobs is HTML-escaped.
//!
//! The figure check: an inline script, run on the window's `load` event (after every image has
//! loaded or failed), counts the `<img class="figure">` elements whose `naturalWidth` is 0 and
//! writes the outcome into `#figure-check` (`data-status="ok"` or `"broken"`, `data-loaded`,
//! `data-total`, `data-broken` = the failing `src`s separated by spaces). A reader sees it as a
//! line at the end of the page; `tests/report_browser.rs` reads it from headless Chromium's DOM.

use crate::fit::job::{FitJob, PARAM_NAMES};
use crate::fit::result::{FitResult, sha256_file};
use crate::{Error, Result};
use std::fmt::Write as _;
use std::path::PathBuf;

/// File name of the page inside the report directory.
pub const INDEX: &str = "index.html";

/// Where the report's inputs are and where it goes.
#[derive(Debug, Clone)]
pub struct ReportPaths {
    /// The fit job file.
    pub job: PathBuf,
    /// `fits/<job>.result.toml`.
    pub result: PathBuf,
    /// The recording as the job names it now (hashed again to detect a changed file).
    pub recording: PathBuf,
    /// `reports/<job>/`: the figures, and where `index.html` is written.
    pub dir: PathBuf,
}

/// What [`write_report`] wrote.
#[derive(Debug, Clone)]
pub struct ReportSummary {
    /// Path of `index.html`.
    pub path: PathBuf,
    /// SVG file names linked from the page, in page order.
    pub figures: Vec<String>,
    /// Figures `wiperlab fit` writes for this result that are not in the directory.
    pub missing_figures: Vec<String>,
    /// Every warning shown on the page.
    pub warnings: Vec<String>,
}

/// True when the result comes from a target job (`[targets]`: frequencies to reach, no recording),
/// read from the settings the result records.
fn is_target_job(result: &FitResult) -> bool {
    toml::from_str::<FitJob>(&result.settings).is_ok_and(|j| j.targets.is_some())
}

/// The figures `wiperlab fit` always writes for a result (file name, caption), in page order; the
/// PSD figures follow the result's bands.
pub fn fit_figure_list(result: &FitResult) -> Vec<(String, String)> {
    let (compared, psd) = if is_target_job(result) {
        (
            "the fitted model (a target job has no recording)",
            "the fitted model's PSD against the target frequency or range",
        )
    } else {
        (
            "measured and fitted model",
            "measured, model, and model plus the measurement's noise floor (as the cost compares \
             them), with both peaks marked",
        )
    };
    let mut v = vec![
        (
            "traces_tip.svg".to_string(),
            format!("Tip x − head x against time: {compared} (means removed)."),
        ),
        (
            "traces_head.svg".into(),
            format!("Head y against time: {compared} (means removed)."),
        ),
    ];
    for p in &result.peaks {
        v.push((
            format!("psd_{}.svg", p.band),
            format!("Welch PSD in the {} band: {psd}.", p.band),
        ));
    }
    v.push((
        "friction_law.svg".into(),
        "Dynamic friction coefficient μ_d(|v|) = A e^(−B|v|) + C (seed eq. 4): fitted, and the \
         truth when known."
            .into(),
    ));
    v.push((
        "cost.svg".into(),
        "Best cost against model evaluations (particle swarm, then Nelder–Mead; with [fit] restarts, each restart starts anew, so the curve jumps up where one begins; with [fit] swarm_rtol, the swarm's costs are those of its looser tolerance).".into(),
    ));
    v
}

/// Figures `wiperlab fit` writes only when the data allow (file name, caption); shown after
/// [`fit_figure_list`] when present, never reported missing.
pub const OPTIONAL_FIGURES: &[(&str, &str)] = &[(
    "freq_vs_speed.svg",
    "Instantaneous frequency against the lip tip's mean speed: spectrogram ridge and \
     1/stick-onset interval, measured and fitted model (written when the recording has a tip \
     point and an estimate in the band).",
)];

/// Escapes text for HTML element content and double- or single-quoted attribute values.
pub fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            c => o.push(c),
        }
    }
    o
}

/// Percent-encodes a file name for a relative URL (RFC 3986 unreserved characters kept).
fn url_path(name: &str) -> String {
    let mut o = String::new();
    for b in name.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
            o.push(b as char);
        } else {
            let _ = write!(o, "%{b:02X}");
        }
    }
    o
}

/// A number with `sig` significant digits: plain for 1e-3 ≤ |x| < 1e5, else scientific; "—" for
/// NaN, "±∞" spelled out.
fn num(x: f64, sig: usize) -> String {
    if x.is_nan() {
        return "—".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "∞" } else { "−∞" }.into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let e = x.abs().log10().floor() as i32;
    if (-3..5).contains(&e) {
        let dec = (sig as i32 - 1 - e).max(0) as usize;
        format!("{x:.dec$}")
    } else {
        format!("{x:.*e}", sig.saturating_sub(1))
    }
}

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:+.2} %", 100.0 * x)
    } else {
        "—".into()
    }
}

/// Days since 1970-01-01 → (year, month, day), proleptic Gregorian (H. Hinnant, "chrono-Compatible
/// Low-Level Date Algorithms", `civil_from_days`).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let y = yoe + era * 400;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (if m <= 2 { y + 1 } else { y }, m, d)
}

/// `YYYY-MM-DD hh:mm:ss UTC` of a system time.
fn utc(t: std::time::SystemTime) -> String {
    let s = match t.duration_since(std::time::UNIX_EPOCH) {
        Ok(d) => d.as_secs() as i64,
        Err(e) => -(e.duration().as_secs() as i64),
    };
    let (y, mo, d) = civil_from_days(s.div_euclid(86_400));
    let r = s.rem_euclid(86_400);
    format!(
        "{y:04}-{mo:02}-{d:02} {:02}:{:02}:{:02} UTC",
        r / 3600,
        r / 60 % 60,
        r % 60
    )
}

/// One figure on the page.
#[derive(Debug, Clone)]
pub struct Figure {
    /// File name relative to the page.
    pub file: String,
    pub caption: String,
}

/// Provenance lines shown at the end of the page (already measured; the renderer computes nothing).
#[derive(Debug, Clone)]
pub struct Provenance {
    pub job_path: String,
    pub result_path: String,
    pub recording_path: String,
    /// SHA-256 of the recording now, or the reason it could not be computed.
    pub recording_sha256_now: std::result::Result<String, String>,
    /// When the page was written.
    pub written_utc: String,
    /// Modification time of the result file.
    pub result_modified_utc: Option<String>,
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1000px;margin:1.5em auto;padding:0 1em;\
color:#222;line-height:1.4}h1{font-size:1.6em}h2{margin-top:1.6em;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:.6em 0}th,td{border:1px solid #ccc;padding:.25em .6em;\
text-align:right;white-space:nowrap}th{background:#f2f2f2}td.l,th.l{text-align:left;white-space:normal}tr.chosen td{font-weight:bold}\
.warn{color:#a33}.ok{color:#262}figure{margin:1.2em 0}figure img{max-width:100%;height:auto;\
border:1px solid #ddd}figcaption,.note{font-size:.9em;color:#444}pre{background:#f6f6f6;padding:.6em;\
overflow-x:auto;font-size:.85em}code{font-size:.9em}";

/// The figure check run by the browser (see the module docs).
const FIGURE_CHECK: &str = "window.addEventListener('load',function(){\
var imgs=document.querySelectorAll('img.figure');var broken=[];\
for(var i=0;i<imgs.length;i++){var m=imgs[i];\
if(!(m.complete&&m.naturalWidth>0&&m.naturalHeight>0)){broken.push(m.getAttribute('src'));}}\
var el=document.getElementById('figure-check');\
el.setAttribute('data-total',String(imgs.length));\
el.setAttribute('data-loaded',String(imgs.length-broken.length));\
el.setAttribute('data-broken',broken.join(' '));\
el.setAttribute('data-status',broken.length?'broken':'ok');\
el.className=broken.length?'warn':'ok';\
el.textContent='Figure check (in this browser): '+(imgs.length-broken.length)+' of '+imgs.length+\
' figures loaded'+(broken.length?'; broken: '+broken.join(', '):'.');});";

/// Renders the page. `warnings` are shown as given (the caller collects them, see
/// [`write_report`]); all text is escaped here.
pub fn render_html(
    r: &FitResult,
    figures: &[Figure],
    warnings: &[String],
    prov: &Provenance,
) -> String {
    let e = |s: &str| escape(s);
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>wiperlab fit report: {}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n",
        e(&r.job)
    );
    let _ = writeln!(h, "<h1>Fit report: {}</h1>", e(&r.job));
    let _ = writeln!(
        h,
        "<p>Recording <code>{}</code>, model <b>{}</b>, cost <b>{}</b> after {} model evaluations \
         ({} failed), {} swarm + {} Nelder–Mead iterations, {} s on {} threads; the best model \
         has {} stick–slip transitions.</p>",
        e(&r.recording),
        e(&r.model),
        num(r.cost, 5),
        r.model_evaluations,
        r.failed_evaluations,
        r.swarm_iterations,
        r.polish_iterations,
        num(r.wall_time_s, 3),
        r.threads,
        r.transitions_in_best_model
    );

    // Parameters.
    h.push_str("<h2 id=\"parameters\">Fitted parameters</h2>\n");
    h.push_str(
        "<p>1σ: from the cost's curvature at the optimum (cost read as χ²); indicative. \
         Interval: a confidence interval when the fit computed one, with its level and method.</p>\n",
    );
    h.push_str(
        "<table id=\"parameter-table\">\n<tr><th class=\"l\">parameter</th><th class=\"l\">meaning, unit</th>\
         <th>fitted</th><th>± 1σ</th><th>interval</th><th>search bounds</th><th>determined</th>\
         <th>true</th><th>rel. error</th></tr>\n",
    );
    let mut methods: Vec<String> = Vec::new();
    for p in &r.parameters {
        let meaning = PARAM_NAMES
            .iter()
            .find(|(n, _)| *n == p.name)
            .map(|(_, m)| *m)
            .unwrap_or("");
        // The method is named once below the table (footnote number), not in every row.
        let interval = match &p.interval {
            Some(i) => {
                if !methods.contains(&i.method) {
                    methods.push(i.method.clone());
                }
                let k = methods.iter().position(|m| *m == i.method).unwrap_or(0) + 1;
                format!(
                    "[{}, {}] ({:.0} %)<sup>{k}</sup>",
                    num(i.lo, 4),
                    num(i.hi, 4),
                    100.0 * i.level
                )
            }
            None => "—".into(),
        };
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td>\
             <td>[{}, {}]</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            e(&p.name),
            e(meaning),
            num(p.value, 5),
            num(p.std_error, 3),
            interval,
            num(p.lower, 4),
            num(p.upper, 4),
            if p.determined {
                "yes".to_string()
            } else {
                "<span class=\"warn\">NO</span>".to_string()
            },
            p.true_value
                .map(|t| num(t, 5))
                .unwrap_or_else(|| "—".into()),
            p.rel_error.map(pct).unwrap_or_else(|| "—".into())
        );
    }
    h.push_str("</table>\n");
    for (k, m) in methods.iter().enumerate() {
        let _ = writeln!(
            h,
            "<p class=\"note\"><sup>{}</sup> Interval method: {}</p>",
            k + 1,
            e(m)
        );
    }

    // Peaks.
    h.push_str("<h2 id=\"peaks\">Measured against model peaks</h2>\n");
    h.push_str(
        "<table id=\"peak-table\">\n<tr><th class=\"l\">band</th><th>measured or target [Hz]</th>\
         <th>model [Hz]</th><th>(model − measured)/measured</th><th>measured PSD [m²/Hz]</th>\
         <th>model PSD [m²/Hz]</th></tr>\n",
    );
    let target = is_target_job(r);
    for p in &r.peaks {
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            e(&p.band),
            match p.target_range_hz {
                Some([lo, hi]) => format!("target {}–{}", num(lo, 4), num(hi, 4)),
                None if target => format!("target {}", num(p.measured_hz, 5)),
                None => num(p.measured_hz, 5),
            },
            num(p.model_hz, 5),
            pct(p.rel_diff),
            num(p.measured_level, 3),
            num(p.model_level, 3)
        );
    }
    h.push_str("</table>\n");

    // Model comparison.
    h.push_str("<h2 id=\"models\">Model comparison</h2>\n");
    if r.model_trials.len() <= 1 {
        let _ = writeln!(
            h,
            "<p id=\"model-comparison\">Only one model ({}) was fitted; no comparison{}.</p>",
            e(&r.model),
            r.model_trials
                .first()
                .map(|t| format!(
                    " (chosen as {}; cost {}, {} model evaluations, {} s)",
                    e(&t.reason),
                    num(t.cost, 5),
                    t.model_evaluations,
                    num(t.wall_time_s, 3)
                ))
                .unwrap_or_default()
        );
    } else {
        h.push_str(
            "<table id=\"model-comparison\">\n<tr><th class=\"l\">model</th><th class=\"l\">freed parameters</th>\
             <th>cost</th><th>wall time [s]</th><th>model evaluations</th><th>chosen</th>\
             <th class=\"l\">reason</th></tr>\n",
        );
        for t in &r.model_trials {
            let _ = writeln!(
                h,
                "<tr{}><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td>\
                 <td>{}</td><td class=\"l\">{}</td></tr>",
                if t.chosen { " class=\"chosen\"" } else { "" },
                e(&t.model),
                e(&t.parameters.join(", ")),
                num(t.cost, 5),
                num(t.wall_time_s, 3),
                t.model_evaluations,
                if t.chosen { "yes" } else { "no" },
                e(&t.reason)
            );
        }
        h.push_str("</table>\n");
    }

    // Correlations.
    h.push_str("<h2 id=\"correlation\">Parameter correlations</h2>\n");
    let n = r.parameters.len();
    let finite = r.correlation.len() == n
        && r.correlation
            .iter()
            .all(|row| row.len() == n && row.iter().all(|c| c.is_finite()));
    if n == 0 {
        h.push_str("<p>No parameters.</p>\n");
    } else if !finite {
        h.push_str(
            "<p>Not available: the cost's curvature matrix at the optimum is not positive \
             definite (the 1σ values come from its diagonal alone).</p>\n",
        );
    } else {
        h.push_str("<table id=\"correlation-table\">\n<tr><th></th>");
        for p in &r.parameters {
            let _ = write!(h, "<th>{}</th>", e(&p.name));
        }
        h.push_str("</tr>\n");
        for (p, row) in r.parameters.iter().zip(&r.correlation) {
            let _ = write!(h, "<tr><th class=\"l\">{}</th>", e(&p.name));
            for c in row {
                let _ = write!(h, "<td>{c:+.3}</td>");
            }
            h.push_str("</tr>\n");
        }
        h.push_str("</table>\n");
    }

    // Warnings.
    h.push_str("<h2 id=\"warnings\">Warnings</h2>\n");
    if warnings.is_empty() {
        h.push_str("<p id=\"warning-list\">None.</p>\n");
    } else {
        h.push_str("<ul id=\"warning-list\" class=\"warn\">\n");
        for w in warnings {
            let _ = writeln!(h, "<li>{}</li>", e(w));
        }
        h.push_str("</ul>\n");
    }

    // Figures.
    h.push_str("<h2 id=\"figures\">Figures</h2>\n");
    if figures.is_empty() {
        h.push_str("<p class=\"warn\">No figures in the report directory.</p>\n");
    }
    for f in figures {
        let _ = writeln!(
            h,
            "<figure><img class=\"figure\" src=\"{}\" alt=\"{}\" width=\"900\">\
             <figcaption><code>{}</code>: {}</figcaption></figure>",
            e(&url_path(&f.file)),
            e(&f.caption),
            e(&f.file),
            e(&f.caption)
        );
    }

    // Provenance.
    h.push_str("<h2 id=\"provenance\">Provenance</h2>\n<table id=\"provenance-table\">\n");
    let row = |h: &mut String, k: &str, v: String| {
        let _ = writeln!(
            h,
            "<tr><th class=\"l\">{k}</th><td class=\"l\">{v}</td></tr>"
        );
    };
    row(
        &mut h,
        "job file",
        format!("<code>{}</code>", e(&prov.job_path)),
    );
    row(
        &mut h,
        "result file",
        format!(
            "<code>{}</code>{}",
            e(&prov.result_path),
            prov.result_modified_utc
                .as_ref()
                .map(|t| format!(", written {}", e(t)))
                .unwrap_or_default()
        ),
    );
    row(
        &mut h,
        "recording",
        format!("<code>{}</code>", e(&prov.recording_path)),
    );
    row(
        &mut h,
        "recording SHA-256 at fit time",
        if r.input_sha256.is_empty() {
            "not recorded by this result".into()
        } else {
            format!("<code id=\"sha256-fit\">{}</code>", e(&r.input_sha256))
        },
    );
    row(
        &mut h,
        "recording SHA-256 now",
        match &prov.recording_sha256_now {
            Ok(s) => format!("<code id=\"sha256-now\">{}</code>", e(s)),
            Err(m) => format!("<span class=\"warn\">{}</span>", e(m)),
        },
    );
    row(
        &mut h,
        "wiperlab version",
        format!(
            "{} (fit), {} (this page)",
            e(&r.wiperlab_version),
            e(env!("CARGO_PKG_VERSION"))
        ),
    );
    row(
        &mut h,
        "solver",
        format!(
            "DOPRI5 with events, rtol {:e}, atol {:e}",
            r.solver_rtol, r.solver_atol
        ),
    );
    let job: Option<FitJob> = toml::from_str(&r.settings).ok();
    if let Some(j) = &job {
        let bands: Vec<String> = j
            .spectrum
            .bands
            .iter()
            .map(|b| {
                format!(
                    "{} {}–{} Hz (Welch, Hann, nperseg {})",
                    e(&b.name),
                    num(b.range_hz[0], 4),
                    num(b.range_hz[1], 4),
                    b.nperseg
                )
            })
            .collect();
        row(&mut h, "spectral bands", bands.join("; "));
        row(
            &mut h,
            "signal",
            format!(
                "<code>{}</code>, gaps up to {} samples filled",
                e(&format!("{:?}", j.spectrum.signal)),
                j.spectrum.max_fill
            ),
        );
        let f = &j.fit;
        row(
            &mut h,
            "fit settings",
            format!(
                "{} × (particle swarm {} particles × {} iterations{}, Nelder–Mead ≤ {} iterations), \
                 best kept (seed {}); weights peak {}, level {}, shape {}",
                f.restarts.max(1),
                f.particles,
                f.swarm_iterations,
                match f.swarm_rtol {
                    Some(r) => format!(" at rtol {r:e}"),
                    None => String::new(),
                },
                f.polish_iterations,
                f.seed,
                f.weights.peak,
                f.weights.level,
                f.weights.shape
            ),
        );
    }
    row(&mut h, "page written", e(&prov.written_utc));
    h.push_str("</table>\n");
    if r.settings.is_empty() {
        h.push_str("<p>The result does not record the job's settings.</p>\n");
    } else {
        let _ = writeln!(
            h,
            "<details><summary>Settings the fit ran with (job, defaults filled in)</summary>\
             <pre>{}</pre></details>",
            e(&r.settings)
        );
    }

    h.push_str(
        "<p id=\"figure-check\" data-status=\"not-run\">Figure check: not run (JavaScript is off).</p>\n",
    );
    let _ = write!(h, "<script>{FIGURE_CHECK}</script>\n</body>\n</html>\n");
    h
}

/// Writes `paths.dir/index.html` for result `r`: links every SVG in `paths.dir` (the fit's own
/// figures first, in [`fit_figure_list`] order, then [`OPTIONAL_FIGURES`], then any other SVG by
/// name), and collects the
/// warnings: the result's own, undetermined parameters, failed model evaluations, fit figures
/// missing from the directory, and a recording whose SHA-256 differs from the one fitted.
///
/// # Errors
/// [`Error::Io`] naming the directory or page if it cannot be listed or written.
pub fn write_report(r: &FitResult, paths: &ReportPaths) -> Result<ReportSummary> {
    let dir = &paths.dir;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "cannot create directory", e))?;
    let mut present: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, "cannot list", e))?
        .filter_map(|d| d.ok())
        .filter(|d| d.path().is_file())
        .filter_map(|d| d.file_name().into_string().ok())
        .filter(|n| n.ends_with(".svg"))
        .collect();
    present.sort();
    let mut figures = Vec::new();
    let mut missing = Vec::new();
    for (file, caption) in fit_figure_list(r) {
        if let Some(i) = present.iter().position(|p| *p == file) {
            present.remove(i);
            figures.push(Figure { file, caption });
        } else {
            missing.push(file);
        }
    }
    for (file, caption) in OPTIONAL_FIGURES {
        if let Some(i) = present.iter().position(|p| p == file) {
            present.remove(i);
            figures.push(Figure {
                file: file.to_string(),
                caption: caption.to_string(),
            });
        }
    }
    for file in present {
        figures.push(Figure {
            caption: format!("figure {file}"),
            file,
        });
    }

    let mut warnings = r.warnings.clone();
    for p in &r.parameters {
        if !p.determined && !warnings.iter().any(|w| w.contains(&p.name)) {
            warnings.push(format!(
                "the data leave {} undetermined (1σ {} over a search range [{}, {}]); read its \
                 value with care and see the correlations",
                p.name,
                num(p.std_error, 3),
                num(p.lower, 4),
                num(p.upper, 4)
            ));
        }
    }
    if r.failed_evaluations > 0 {
        warnings.push(format!(
            "{} of {} model evaluations failed and were given the failure cost; first: {}",
            r.failed_evaluations,
            r.model_evaluations,
            r.first_failure.as_deref().unwrap_or("(not recorded)")
        ));
    }
    if !missing.is_empty() {
        warnings.push(format!(
            "figures missing from {}: {} (run `wiperlab report --refit` to redraw them)",
            dir.display(),
            missing.join(", ")
        ));
    }
    let now_hash = sha256_file(&paths.recording).map_err(|e| e.to_string());
    match &now_hash {
        Ok(h) if !r.input_sha256.is_empty() && *h != r.input_sha256 => warnings.push(format!(
            "the recording {} has changed since the fit (SHA-256 {} now, {} at fit time); refit \
             with `wiperlab report --refit`",
            paths.recording.display(),
            h,
            r.input_sha256
        )),
        Err(m) => warnings.push(format!("cannot hash the recording: {m}")),
        _ => {}
    }

    let prov = Provenance {
        job_path: paths.job.display().to_string(),
        result_path: paths.result.display().to_string(),
        recording_path: paths.recording.display().to_string(),
        recording_sha256_now: now_hash,
        written_utc: utc(std::time::SystemTime::now()),
        result_modified_utc: std::fs::metadata(&paths.result)
            .and_then(|m| m.modified())
            .ok()
            .map(utc),
    };
    let html = render_html(r, &figures, &warnings, &prov);
    let path = dir.join(INDEX);
    std::fs::write(&path, html).map_err(|e| Error::io(&path, "cannot write", e))?;
    Ok(ReportSummary {
        path,
        figures: figures.into_iter().map(|f| f.file).collect(),
        missing_figures: missing,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::result::sha256_hex;

    #[test]
    fn escape_covers_markup_and_quotes() {
        assert_eq!(
            escape(r#"<b a="1" b='2'>&amp;</b>"#),
            "&lt;b a=&quot;1&quot; b=&#39;2&#39;&gt;&amp;amp;&lt;/b&gt;"
        );
        assert_eq!(escape("μ_d = A e^(−B|v|)"), "μ_d = A e^(−B|v|)");
        assert_eq!(url_path("psd_a b#?.svg"), "psd_a%20b%23%3F.svg");
    }

    #[test]
    fn numbers_keep_significant_digits() {
        assert_eq!(num(0.026464608, 4), "0.02646");
        assert_eq!(num(90.319214, 5), "90.319");
        assert_eq!(num(1.5e-10, 3), "1.50e-10");
        assert_eq!(num(123456.0, 3), "1.23e5");
        assert_eq!(num(f64::NAN, 3), "—");
        assert_eq!(num(0.0, 3), "0");
        assert_eq!(pct(-0.0245066), "-2.45 %");
    }

    fn result() -> FitResult {
        use crate::fit::result::{FittedParam, Interval, PeakComparison};
        let p = |name: &str, determined: bool, interval: Option<Interval>| FittedParam {
            name: name.into(),
            value: 0.03,
            lower: 0.005,
            upper: 0.15,
            std_error: if determined { 0.001 } else { 0.2 },
            determined,
            true_value: Some(0.029),
            rel_error: Some(0.03 / 0.029 - 1.0),
            interval,
        };
        FitResult {
            job: "unit".into(),
            recording: "rec.csv".into(),
            wiperlab_version: "0.1.0".into(),
            model: "blade2dof".into(),
            cost: 1.5,
            parameters: vec![
                p(
                    "k1",
                    true,
                    Some(Interval {
                        lo: 0.028,
                        hi: 0.032,
                        level: 0.68,
                        method: "profile".into(),
                    }),
                ),
                p("B", false, None),
            ],
            peaks: vec![PeakComparison {
                band: "low".into(),
                measured_hz: 49.0,
                model_hz: 49.5,
                rel_diff: 0.5 / 49.0,
                measured_level: 1e-9,
                model_level: 2e-9,
                target_range_hz: None,
            }],
            undetermined: vec!["B".into()],
            correlation: vec![vec![1.0, -0.9], vec![-0.9, 1.0]],
            swarm_iterations: 1,
            polish_iterations: 2,
            model_evaluations: 30,
            failed_evaluations: 2,
            first_failure: Some("contact lost".into()),
            wall_time_s: 0.5,
            threads: 2,
            solver_rtol: 1e-8,
            solver_atol: 1e-10,
            transitions_in_best_model: 10,
            model_trials: vec![],
            warnings: vec![],
            input_sha256: sha256_hex(b"the recording at fit time"),
            settings: String::new(),
            history: vec![],
        }
    }

    #[test]
    fn page_tables_and_warnings_from_a_result() {
        let dir = std::env::temp_dir().join(format!("wiperlab_html_unit_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let figs = dir.join("reports");
        std::fs::create_dir_all(&figs).unwrap();
        // Only two of the fit's figures, plus one extra SVG.
        for f in ["cost.svg", "psd_low.svg", "extra.svg", "freq_vs_speed.svg"] {
            std::fs::write(figs.join(f), "<svg xmlns=\"http://www.w3.org/2000/svg\"/>").unwrap();
        }
        let rec = dir.join("rec.csv");
        std::fs::write(&rec, "the recording changed since").unwrap();
        let r = result();
        let s = write_report(
            &r,
            &ReportPaths {
                job: dir.join("job.toml"),
                result: dir.join("unit.result.toml"),
                recording: rec.clone(),
                dir: figs.clone(),
            },
        )
        .unwrap();
        // Fit figures in fit_figure_list order, then the optional ones, then the others by name.
        assert_eq!(
            s.figures,
            ["psd_low.svg", "cost.svg", "freq_vs_speed.svg", "extra.svg"]
        );
        assert_eq!(
            s.missing_figures,
            ["traces_tip.svg", "traces_head.svg", "friction_law.svg"]
        );
        let has = |needle: &str| s.warnings.iter().any(|w| w.contains(needle));
        assert!(has("leave B undetermined"), "{:?}", s.warnings);
        assert!(has("2 of 30 model evaluations failed"), "{:?}", s.warnings);
        assert!(has("figures missing"), "{:?}", s.warnings);
        assert!(has("has changed since the fit"), "{:?}", s.warnings);
        assert_eq!(s.warnings.len(), 4, "{:?}", s.warnings);
        let html = std::fs::read_to_string(&s.path).unwrap();
        assert!(html.contains("<td>[0.02800, 0.03200] (68 %)<sup>1</sup></td>"));
        assert!(html.contains("<sup>1</sup> Interval method: profile</p>"));
        assert!(html.contains("<td>+3.45 %</td>")); // 0.03/0.029 − 1
        assert!(html.contains("<span class=\"warn\">NO</span>"));
        assert!(html.contains("<td>-0.900</td>"));
        assert!(html.contains(&format!(
            "<code id=\"sha256-now\">{}</code>",
            sha256_hex(b"the recording changed since")
        )));
        assert!(html.contains("Only one model (blade2dof) was fitted"));
        assert!(html.contains("The result does not record the job's settings."));

        // Unchanged recording, all figures present, nothing failed: no warnings at all.
        std::fs::write(&rec, "the recording at fit time").unwrap();
        for (f, _) in fit_figure_list(&r) {
            std::fs::write(figs.join(f), "<svg xmlns=\"http://www.w3.org/2000/svg\"/>").unwrap();
        }
        let mut r = r;
        r.parameters[1].determined = true;
        r.failed_evaluations = 0;
        let s = write_report(
            &r,
            &ReportPaths {
                job: dir.join("job.toml"),
                result: dir.join("unit.result.toml"),
                recording: rec,
                dir: figs,
            },
        )
        .unwrap();
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);
        assert!(
            std::fs::read_to_string(&s.path)
                .unwrap()
                .contains("<p id=\"warning-list\">None.</p>")
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn civil_dates() {
        // Day 0 is 1970-01-01; 2000-03-01 is day 11017; 2026-11-21 is day 20778 (date(1) arithmetic).
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(11_017), (2000, 3, 1));
        assert_eq!(civil_from_days(20_778), (2026, 11, 21));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
        assert_eq!(
            utc(std::time::UNIX_EPOCH + std::time::Duration::from_secs(86_400 + 3_723)),
            "1970-01-02 01:02:03 UTC"
        );
    }
}
