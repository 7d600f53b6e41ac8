//! The report page `reports/<job>/index.html` (`wiperlab report JOB`): one self-contained HTML file
//! that shows a fit result to an engineer.
//!
//! Contents, in order: the fit summary; the parameter table (value, 1σ from the cost's curvature,
//! confidence interval when the fit computed one, search bounds, determined or not, truth and
//! relative error when known); measured against model spectral peaks; the model comparison
//! (`model_trials`, or with one trial or none a line saying that only one model was fitted, and
//! why); the correlation matrix; warnings; every SVG figure of `reports/<job>/`; provenance
//! (recording path and SHA-256 at fit time and now, wiperlab version, solver tolerances, bands, fit
//! settings, the fit's own timestamp and the page's).
//!
//! Figures are `<img src="NAME.svg">` links relative to the page (the SVGs sit beside it), so the
//! page stays small and each figure is also a file of its own. Nothing is fetched from the network:
//! the style sheet and the figure check are inline. The page is the minijinja template
//! `templates/report.html` filled from a view model of already-formatted values; all text from
//! results and jobs is HTML-escaped by the template engine.
//!
//! The figure check: an inline script, run on the window's `load` event (after every image has
//! loaded or failed), counts the `<img class="figure">` elements whose `naturalWidth` is 0 and
//! writes the outcome into `#figure-check` (`data-status="ok"` or `"broken"`, `data-loaded`,
//! `data-total`, `data-broken` = the failing `src`s separated by spaces). A reader sees it as a
//! line at the end of the page; `tests/suite/report_browser.rs` reads it from headless Chromium's DOM.

use crate::fit::features::SignalKind;
use crate::fit::result::FitResult;
use crate::fit::{FitWarning, Severity};
use crate::io::sha256_file;
use crate::job::Candidate;
use crate::job::FitSection;
pub use crate::report::warning::PageWarning;
use crate::simulate::blade::ModelKind;
use crate::{Error, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};

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
    pub warnings: Vec<PageWarning>,
}

/// The figures `wiperlab fit` always writes for a result (file name, caption), in page order; the
/// PSD figures follow the result's bands.
pub fn fit_figure_list(result: &FitResult) -> Vec<(String, String)> {
    let (compared, psd) = if result.target_job {
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
        "Dynamic friction coefficient μ_d(|v|) of the blade's law: fitted, solid with its ±1σ band \
         over the slip speeds the fitted motion covers (shaded), dashed where extrapolated; the \
         truth when known."
            .into(),
    ));
    v.push((
        "cost.svg".into(),
        "Best cost against model evaluations (particle swarm, then Nelder–Mead, or CMA-ES runs; with restarts, each starts anew, so the curve jumps up where one begins; with [fit] swarm_rtol, the swarm's costs are those of its looser tolerance).".into(),
    ));
    v
}

/// Figures `wiperlab fit` writes only when the data allow (file name, caption); shown after
/// [`fit_figure_list`] when present, never reported missing.
pub const OPTIONAL_FIGURES: &[(&str, &str)] = &[
    (
        "freq_vs_speed.svg",
        "Instantaneous frequency against the lip tip's mean speed: spectrogram ridge and \
         1/stick-onset interval, measured and fitted model (written when the recording has a tip \
         point and an estimate in the band).",
    ),
    (
        "posterior_corner.svg",
        "Posterior sample ([fit.uncertainty] method = \"mcmc\"): each parameter's histogram on \
         the diagonal with its 68.27 % interval dashed, each pair's draws below it; the fit in \
         black, the truth in red when known. A histogram that fills its axis from bound to bound \
         is a parameter the recording does not determine; a thin curved cloud is a ridge the \
         recording determines only as a combination.",
    ),
];

/// A number with `sig` significant digits: plain for 1e-3 ≤ |x| < 1e5, else scientific; "—" for
/// NaN, "±∞" spelled out.
pub(super) fn num(x: f64, sig: usize) -> String {
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

/// `YYYY-MM-DD hh:mm:ss UTC` of an instant.
fn utc(t: jiff::Timestamp) -> String {
    t.strftime("%Y-%m-%d %H:%M:%S UTC").to_string()
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
    /// SHA-256 of the recording now, or why it could not be computed.
    pub recording_sha256_now: std::result::Result<String, std::sync::Arc<Error>>,
    /// When the page was written.
    pub written_utc: String,
}

/// The page template, its style sheet and its figure check (see the module docs).
const TEMPLATE: &str = include_str!("templates/report.html");
const STYLE: &str = include_str!("templates/report.css");
const FIGURE_CHECK: &str = include_str!("templates/figure_check.js");

/// What a model of the hierarchy is, in words (the result stores its short name); empty for a
/// name this page does not know.
pub(super) fn model_label(c: Candidate) -> &'static str {
    match (c.kind, c.shoulder) {
        (ModelKind::Head1dof, _) => "1-DOF head on its spring",
        (ModelKind::Necklip, false) => "neck and lip",
        (ModelKind::Necklip, true) => "neck and lip with shoulder contact",
        (ModelKind::Blade2dof, false) => "2-DOF blade",
        (ModelKind::Blade2dof, true) => "2-DOF blade with shoulder contact",
    }
}

/// A readable name for the analysed signal.
fn signal_label(s: SignalKind) -> &'static str {
    match s {
        SignalKind::TipRelX => "lip tip x − head x (horizontal, relative to the head)",
        SignalKind::TipRelY => "lip tip y − head y (vertical, relative to the head)",
        SignalKind::HeadY => "head y (vertical)",
        SignalKind::TipX => "lip tip x (horizontal)",
    }
}

#[derive(Serialize)]
struct IntervalView {
    lo: String,
    hi: String,
    /// The method's own ends when the interval was widened to points the fit evaluated.
    widened_from: Option<String>,
    /// The 95 % interval where the method gives one (a profile walked on to the 95 % rise, a
    /// posterior sample), and with a posterior sample "not determined by this recording" when it
    /// spans most of the search range.
    posterior_note: Option<String>,
    level_pct: String,
    footnote: usize,
}

#[derive(Serialize)]
struct ParamView {
    name: String,
    meaning: &'static str,
    value: String,
    std_error: String,
    interval: Option<IntervalView>,
    lower: String,
    upper: String,
    determined: bool,
    true_value: String,
    rel_error: String,
}

/// The posterior sample's 95 % interval of `name`, with the verdict when the recording does not
/// determine it; `None` without a posterior sample.
fn posterior_note(r: &FitResult, name: crate::model::ParamId) -> Option<String> {
    let p = r
        .posterior
        .as_ref()?
        .parameters
        .iter()
        .find(|p| p.name == name)?;
    let [lo, .., hi] = p.quantiles;
    let verdict = if p.determined {
        String::new()
    } else {
        format!(
            ": not determined by this recording (the posterior spans {:.0} % of the search range)",
            100.0 * p.span_fraction
        )
    };
    Some(format!("95 %: [{}, {}]{verdict}", num(lo, 4), num(hi, 4)))
}

/// Parameter rows and the interval methods their footnotes number (each method named once).
fn parameter_rows(r: &FitResult) -> (Vec<ParamView>, Vec<String>) {
    let mut methods: Vec<String> = Vec::new();
    let rows = r
        .parameters
        .iter()
        .map(|p| {
            let interval = p.interval.as_ref().map(|i| {
                let method = i.method.to_string();
                if !methods.contains(&method) {
                    methods.push(method.clone());
                }
                IntervalView {
                    lo: num(i.lo, 4),
                    hi: num(i.hi, 4),
                    widened_from: i
                        .widened_from
                        .map(|[lo, hi]| format!("[{}, {}]", num(lo, 4), num(hi, 4))),
                    posterior_note: posterior_note(r, p.name).or_else(|| {
                        i.range_95
                            .map(|[lo, hi]| format!("95 %: [{}, {}]", num(lo, 4), num(hi, 4)))
                    }),
                    level_pct: format!("{:.0}", 100.0 * i.level),
                    footnote: methods.iter().position(|m| *m == method).unwrap_or(0) + 1,
                }
            });
            ParamView {
                name: p.name.to_string(),
                meaning: p.name.meaning(),
                value: num(p.value, 5),
                std_error: num(p.std_error, 3),
                interval,
                lower: num(p.lower, 4),
                upper: num(p.upper, 4),
                determined: p.determined,
                true_value: p.true_value.map_or_else(|| "—".into(), |t| num(t, 5)),
                rel_error: p.rel_error.map_or_else(|| "—".into(), pct),
            }
        })
        .collect();
    (rows, methods)
}

#[derive(Serialize)]
struct PeakView {
    band: String,
    measured: String,
    model_hz: String,
    rel_diff: String,
    measured_level: String,
    model_level: String,
    measured_line: String,
    model_line: String,
}

/// A line's origin in words: its own, or a harmonic of a stronger line; its prominence over the
/// local floor (or that the band's bins leave none); and its distance below the spectrum's dominant
/// line when that exceeds 100×.
fn line_words(o: Option<crate::spectrum::harmonics::LineOrigin>) -> String {
    let Some(o) = o else {
        return "—".into();
    };
    let mut w = match o.harmonic_of {
        Some(h) => format!("harmonic {} of {} Hz", h.order, num(h.freq_hz, 4)),
        None => "its own line".into(),
    };
    if o.prominence.is_nan() {
        w.push_str("; no measurable floor");
    } else {
        w.push_str(&format!("; {}× its floor", num(o.prominence, 3)));
    }
    if o.below_dominant > 100.0 {
        w.push_str(&format!(
            "; {}× below the dominant line ({} Hz)",
            num(o.below_dominant, 3),
            num(o.dominant_hz, 4)
        ));
    }
    w
}

fn peak_rows(r: &FitResult) -> Vec<PeakView> {
    r.peaks
        .iter()
        .map(|p| PeakView {
            band: p.band.clone(),
            measured: match p.target_range_hz {
                Some([lo, hi]) => format!("target {}–{}", num(lo, 4), num(hi, 4)),
                None if r.target_job => format!("target {}", num(p.measured_hz, 5)),
                None => num(p.measured_hz, 5),
            },
            model_hz: num(p.model_hz, 5),
            rel_diff: pct(p.rel_diff),
            measured_level: num(p.measured_level, 3),
            model_level: num(p.model_level, 3),
            measured_line: line_words(p.measured_line),
            model_line: line_words(p.model_line),
        })
        .collect()
}

#[derive(Serialize)]
struct TrialView {
    model: String,
    /// The friction law at the trial's optimum with its coefficients ([`law_cell`]).
    law: String,
    parameters: String,
    cost: String,
    wall_time_s: String,
    model_evaluations: usize,
    failed_evaluations: usize,
    chosen: bool,
    /// Why, in a few words (the numbers are in their own columns).
    short_reason: String,
    /// Why, with every number, as the fit wrote it.
    reason: String,
    log_likelihood: String,
    delta_aic: String,
    delta_bic: String,
    /// The likelihood-ratio test's p against the candidate this one extends (`X` for
    /// `X+shoulder`).
    lrt: String,
}

#[derive(Serialize)]
struct ModeView {
    phase: String,
    freq_hz: String,
    damping_ratio: String,
    self_excited: bool,
    head: String,
    head_link: String,
    neck_lip: String,
}

/// The blade's modes at the fitted parameters, one row per mode.
fn mode_rows(r: &FitResult) -> Vec<ModeView> {
    r.modes
        .iter()
        .map(|m| ModeView {
            phase: match m.phase {
                crate::model::modes::OperatingPoint::Stick => "stick".into(),
                crate::model::modes::OperatingPoint::Slip { speed_m_per_s } => {
                    format!("slip at {} m/s", num(speed_m_per_s, 3))
                }
            },
            freq_hz: num(m.freq_hz, 5),
            damping_ratio: num(m.damping_ratio, 3),
            self_excited: m.damping_ratio < 0.0,
            head: num(m.participation.head, 2),
            head_link: num(m.participation.head_link, 2),
            neck_lip: num(m.participation.neck_lip, 2),
        })
        .collect()
}

/// The goodness-of-fit test in a sentence.
fn goodness_of_fit_words(g: &crate::likelihood::GoodnessOfFit) -> String {
    let verdict = if g.fits() {
        "the model explains the recording's spectra to their noise"
    } else {
        "the spectra hold more than the model and noise: structure no candidate reproduces, or a basin the search missed, possibly absorbed by the fitted parameters"
    };
    format!(
        "Goodness of fit: the recording's excess NLL at the fit is {} nats, against {} ± {} for {} replicates of the fitted model plus the recording's tracking noise (p = {:.3}): {verdict}.",
        num(g.excess_nll_nats, 5),
        num(g.replicate_mean_nats, 4),
        num(g.replicate_sd_nats, 2),
        g.replicates,
        g.p_value,
    )
}

/// The tolerance check in a sentence.
fn tolerance_check_words(t: &crate::fit::tolerance::ToleranceCheck) -> String {
    let at: Vec<String> = t
        .points
        .iter()
        .map(|p| format!("{} nats at rtol {:e}", num(p.cost_nats, 5), p.rtol))
        .collect();
    use crate::fit::tolerance::Verdict;
    let verdict = match t.verdict() {
        Verdict::Resolved => "the integrator resolves the likelihood at the optimum",
        Verdict::NotProbed => {
            "every tighter probe failed, so whether the integrator resolves the likelihood is not known"
        }
        Verdict::Unresolved => {
            "the integrator does not resolve the likelihood at the optimum: the cost surface is rough at that depth and the intervals understate the uncertainty"
        }
    };
    let jitter = t.jitter.as_ref().map_or(String::new(), |j| {
        format!(
            " Under steps of {:e} in the normalised coordinates it jitters by {} nats (standard \
             deviation): cost differences within that do not tell parameter sets apart.",
            j.step_u,
            num(j.sd_nats, 2)
        )
    });
    format!(
        "Tolerance check: the optimum's cost is {} ({} nats apart): {verdict}.{jitter}",
        crate::names::join(&at, ", "),
        num(t.spread_nats, 2),
    )
}

/// Why trial `t` of `r` was (not) chosen, in a few words: the criterion for the chosen one; for
/// another, a band it cannot produce, what its likelihood-ratio test says, or that its AIC is
/// higher.
fn short_reason(r: &FitResult, t: &crate::fit::ModelTrial) -> String {
    use crate::job::NECK_BAND_MIN_HZ;
    if t.chosen {
        let compared = r
            .model_trials
            .iter()
            .filter(|o| !o.chosen)
            .any(|o| o.evidence.as_ref().is_some_and(|e| e.delta_aic.is_finite()));
        let lower = r.model_trials.iter().any(|o| {
            o.evidence
                .as_ref()
                .and_then(|e| e.delta_tic)
                .is_some_and(|d| d < 0.0)
        });
        return match (r.model_trials.len(), compared) {
            (1, _) => "the only model fitted".into(),
            (_, true) if lower => format!(
                "the fewest parameters within {} of the lowest TIC",
                crate::fit::select::INDISTINGUISHABLE_TIC
            ),
            (_, true) => "lowest AIC".into(),
            (_, false) => "the only candidate that produced every band".into(),
        };
    }
    let bands = r.spectrum.as_ref().map_or(&[][..], |s| &s.bands[..]);
    let mut why = Vec::new();
    if !t.model.kind.has_neck_mode()
        && let Some(b) = bands.iter().find(|b| b.range_hz[0] >= NECK_BAND_MIN_HZ)
    {
        why.push(format!("no neck–lip mode for band '{}'", b.name));
    }
    if !t.model.kind.has_head_mode()
        && let Some(b) = bands.iter().find(|b| b.range_hz[0] < NECK_BAND_MIN_HZ)
    {
        why.push(format!("imposes band '{}' from the head track", b.name));
    }
    let near = crate::fit::select::INDISTINGUISHABLE_TIC;
    if let Some(d) = t.evidence.as_ref().and_then(|e| e.delta_tic)
        && d.abs() <= near
    {
        why.push(format!(
            "not distinguishable by this recording (TIC within {near}); more parameters"
        ));
    }
    match t.evidence.as_ref().and_then(|e| e.lrt.as_ref()) {
        Some(l) if l.p_value < 0.05 => {
            why.push("a gain beyond chance, but not worth its parameters".into())
        }
        Some(_) => why.push("its extra parameters gain nothing beyond chance".into()),
        None if why.is_empty() => why.push("higher AIC".into()),
        None => {}
    }
    why.join("; ")
}

/// A trial's friction law and its coefficients under their blade-file keys (docs/blade.md), e.g.
/// `exponential_viscous (a 0.880, b_s_per_m 69.7, c 0.560, d_s_per_m 0.357)`; `—` in results
/// without it.
fn law_cell(t: &crate::fit::ModelTrial) -> String {
    let Some(law) = &t.friction else {
        return "—".into();
    };
    let Ok(toml::Value::Table(table)) = toml::Value::try_from(law) else {
        return law.name().into();
    };
    let coefficients: Vec<String> = table
        .iter()
        .filter_map(|(k, v)| Some(format!("{k} {}", num(v.as_float()?, 3))))
        .collect();
    format!("{} ({})", law.name(), coefficients.join(", "))
}

fn trial_rows(r: &FitResult) -> Vec<TrialView> {
    r.model_trials
        .iter()
        .map(|t| TrialView {
            model: t.model.to_string(),
            law: law_cell(t),
            parameters: crate::names::join(&t.parameters, ", "),
            cost: num(t.cost, 5),
            wall_time_s: num(t.wall_time_s, 3),
            model_evaluations: t.model_evaluations,
            failed_evaluations: t.failed_evaluations,
            chosen: t.chosen,
            short_reason: short_reason(r, t),
            reason: t.reason.clone(),
            lrt: t
                .evidence
                .as_ref()
                .and_then(|e| e.lrt.as_ref())
                .map_or("—".into(), |l| format!("{:.3}", l.p_value)),
            log_likelihood: t
                .evidence
                .as_ref()
                .map_or("—".into(), |e| format!("{:.2}", e.log_likelihood_nats)),
            delta_aic: t
                .evidence
                .as_ref()
                .map_or("—".into(), |e| match e.delta_tic {
                    Some(d) => format!("{d:+.2}"),
                    None => format!("{:+.2} (AIC)", e.delta_aic),
                }),
            delta_bic: t
                .evidence
                .as_ref()
                .map_or("—".into(), |e| format!("{:+.2}", e.delta_bic)),
        })
        .collect()
}

#[derive(Serialize)]
struct CorrelationRow {
    name: String,
    cells: Vec<String>,
}

/// True when the cost's curvature at the optimum was positive definite: the fit then fills the
/// correlation matrix with finite numbers (NaN otherwise, see [`FitResult::correlation`]).
fn curvature_positive_definite(r: &FitResult) -> bool {
    let n = r.parameters.len();
    r.correlation.len() == n
        && r.correlation
            .iter()
            .all(|row| row.len() == n && row.iter().all(|c| c.is_finite()))
}

fn correlation_rows(r: &FitResult) -> Vec<CorrelationRow> {
    r.parameters
        .iter()
        .zip(&r.correlation)
        .map(|(p, row)| CorrelationRow {
            name: p.name.to_string(),
            cells: row.iter().map(|c| format!("{c:+.3}")).collect(),
        })
        .collect()
}

#[derive(Serialize)]
struct BandView {
    name: String,
    lo_hz: String,
    hi_hz: String,
    nperseg: usize,
}

#[derive(Serialize)]
struct SignalView {
    label: &'static str,
    max_fill: usize,
}

/// One line on the fit's settings (restarts, swarm, polish, seed, cost weights).
fn fit_settings_line(f: &FitSection) -> String {
    if f.search.method == crate::job::SearchMethod::Cmaes {
        let s = &f.search;
        return format!(
            "CMA-ES with up to {} restarts of doubling population (first λ = {}), at most {} \
             evaluations per candidate (seed {}); weights peak {}, level {}, shape {}",
            s.restarts,
            s.population
                .map_or_else(|| "4 + ⌊3 ln n⌋".to_string(), |p| p.to_string()),
            s.max_evaluations,
            f.seed,
            f.weights.peak,
            f.weights.level,
            f.weights.shape
        );
    }
    let at_rtol = |rtol: Option<f64>| rtol.map_or_else(String::new, |r| format!(" at rtol {r:e}"));
    let local = match f.search.local {
        crate::job::LocalSearch::Cmaes => format!(
            ", CMA-ES ≤ {} evaluations{}",
            f.search.local_evaluations,
            at_rtol(f.search.local_rtol)
        ),
        crate::job::LocalSearch::NelderMead => String::new(),
    };
    format!(
        "{} × (particle swarm {} particles × {} iterations{}{local}, Nelder–Mead ≤ {} iterations), \
         best kept (seed {}); weights peak {}, level {}, shape {}",
        f.restarts.max(1),
        f.particles,
        f.swarm_iterations,
        at_rtol(f.swarm_rtol),
        f.polish_iterations,
        f.seed,
        f.weights.peak,
        f.weights.level,
        f.weights.shape
    )
}

#[derive(Serialize)]
struct ProvenanceView<'a> {
    job_path: &'a str,
    result_path: &'a str,
    recording_path: &'a str,
    sha256_now: Option<&'a str>,
    sha256_error: Option<String>,
    written_utc: &'a str,
}

/// One warning as the page lists it: its headline, and the full sentence folded under it.
#[derive(Serialize)]
struct WarningView {
    headline: String,
    details: Option<String>,
}

/// The warnings of one severity, in the order given.
fn warning_views(warnings: &[PageWarning], severity: Severity) -> Vec<WarningView> {
    warnings
        .iter()
        .filter(|w| w.severity() == severity)
        .map(|w| WarningView {
            headline: w.headline(),
            details: w.details(),
        })
        .collect()
}

#[derive(Serialize)]
struct FigureView<'a> {
    file: &'a str,
    caption: &'a str,
}

/// Everything the template shows, already formatted (the template only lays it out).
#[derive(Serialize)]
struct PageView<'a> {
    style: &'static str,
    figure_check: &'static str,
    job: &'a str,
    recording: &'a str,
    model: String,
    model_label: &'static str,
    cost: String,
    model_evaluations: usize,
    failed_evaluations: usize,
    swarm_iterations: u64,
    polish_iterations: u64,
    wall_time_s: String,
    threads: usize,
    transitions: usize,
    fitted_utc: Option<String>,
    sigma_shown: bool,
    /// The 1σ come from the likelihood's Fisher information.
    spread_fisher: bool,
    spread_sandwich: bool,
    parameters: Vec<ParamView>,
    interval_methods: Vec<String>,
    peaks: Vec<PeakView>,
    trials: Vec<TrialView>,
    /// The chosen model's goodness of fit in words, when the result has one.
    goodness_of_fit: Option<String>,
    tolerance_check: Option<String>,
    modes: Vec<ModeView>,
    correlation: Vec<CorrelationRow>,
    /// The opening summary: what was found, whether the fit is good, what to do if not.
    summary: super::summary::Summary,
    /// Warnings that need the reader's attention, and those for information.
    attention: Vec<WarningView>,
    information: Vec<WarningView>,
    figures: Vec<FigureView<'a>>,
    /// A target job (no recording): the page has a reachability-map section.
    target_job: bool,
    /// `wiperlab explore`'s map of this job, when there is one.
    map: Option<FigureView<'a>>,
    prov: ProvenanceView<'a>,
    sha256_fit: &'a str,
    version_fit: &'a str,
    version_page: &'static str,
    solver_rtol: String,
    solver_atol: String,
    bands: Vec<BandView>,
    signal: Option<SignalView>,
    fit_settings: Option<String>,
    /// The drive the fit used and the one read from the tracked head
    /// ([`super::figures::drive_line`]).
    drive: Option<String>,
    settings: &'a str,
    /// `[fit.priors]` beside the fit, when the job gave any.
    priors: Option<PriorsView>,
}

/// The priors' section: each parameter prior beside the fit, and the rig curve's points.
#[derive(Serialize)]
struct PriorsView {
    nats: String,
    parameters: Vec<PriorRow>,
    rig_file: String,
    rig: Vec<RigRow>,
}

#[derive(Serialize)]
struct PriorRow {
    name: String,
    meaning: &'static str,
    prior: String,
    prior_interval: String,
    value: String,
    interval: String,
    z: String,
}

#[derive(Serialize)]
struct RigRow {
    speed: String,
    coefficient: String,
    sd: String,
    mu_d: String,
    z: String,
}

/// The result's priors as the page shows them.
fn priors_view(r: &FitResult) -> Option<PriorsView> {
    use crate::job::ParamPrior;
    let p = r.priors.as_ref()?;
    let pair = |[lo, hi]: [f64; 2]| format!("[{}, {}]", num(lo, 4), num(hi, 4));
    let parameters = (p.parameters.iter())
        .map(|q| PriorRow {
            name: q.name.to_string(),
            meaning: q.name.meaning(),
            prior: match q.prior {
                ParamPrior::Normal { mean, sd } => {
                    format!("normal, mean {}, sd {}", num(mean, 4), num(sd, 3))
                }
                ParamPrior::Lognormal { median, sd_log } => {
                    format!(
                        "log-normal, median {}, sd_log {}",
                        num(median, 4),
                        num(sd_log, 3)
                    )
                }
            },
            prior_interval: pair(q.prior_interval),
            value: num(q.value, 4),
            interval: q.interval.map_or_else(|| "—".into(), pair),
            z: num(q.z, 3),
        })
        .collect();
    let curve = p.friction_curve.as_ref();
    Some(PriorsView {
        nats: num(p.nats_at_fit, 4),
        parameters,
        rig_file: curve.map_or_else(String::new, |c| c.file.display().to_string()),
        rig: curve.map_or_else(Vec::new, |c| {
            c.points
                .iter()
                .map(|q| RigRow {
                    speed: num(q.speed_m_per_s, 4),
                    coefficient: num(q.coefficient, 4),
                    sd: num(q.sd, 3),
                    mu_d: num(q.mu_d_fit, 4),
                    z: num(q.z, 3),
                })
                .collect()
        }),
    })
}

/// The settings part of the view: bands, signal and fit settings as the result records them.
fn settings_views(r: &FitResult) -> (Vec<BandView>, Option<SignalView>, Option<String>) {
    let bands = r.spectrum.as_ref().map_or_else(Vec::new, |s| {
        s.bands
            .iter()
            .map(|b| BandView {
                name: b.name.clone(),
                lo_hz: num(b.range_hz[0], 4),
                hi_hz: num(b.range_hz[1], 4),
                nperseg: b.nperseg,
            })
            .collect()
    });
    let signal = r.spectrum.as_ref().map(|s| SignalView {
        label: signal_label(s.signal),
        max_fill: s.max_fill,
    });
    (
        bands,
        signal,
        r.fit_settings.as_ref().map(fit_settings_line),
    )
}

fn provenance_view(prov: &Provenance) -> ProvenanceView<'_> {
    ProvenanceView {
        job_path: &prov.job_path,
        result_path: &prov.result_path,
        recording_path: &prov.recording_path,
        sha256_now: prov.recording_sha256_now.as_deref().ok(),
        sha256_error: prov
            .recording_sha256_now
            .as_ref()
            .err()
            .map(ToString::to_string),
        written_utc: &prov.written_utc,
    }
}

fn page_view<'a>(
    r: &'a FitResult,
    figures: &'a [Figure],
    map: Option<&'a Figure>,
    warnings: &[PageWarning],
    prov: &'a Provenance,
) -> PageView<'a> {
    let (parameters, interval_methods) = parameter_rows(r);
    let (bands, signal, fit_settings) = settings_views(r);
    let fisher = r.spread_source == crate::fit::SpreadSource::FisherInformation;
    let sandwich = r.spread_source == crate::fit::SpreadSource::Sandwich;
    let pd = fisher || curvature_positive_definite(r);
    PageView {
        style: STYLE,
        figure_check: FIGURE_CHECK,
        job: &r.job,
        recording: &r.recording,
        model: r.model.to_string(),
        model_label: model_label(r.model),
        cost: num(r.cost, 5),
        model_evaluations: r.model_evaluations,
        failed_evaluations: r.failed_evaluations,
        swarm_iterations: r.swarm_iterations,
        polish_iterations: r.polish_iterations,
        wall_time_s: num(r.wall_time_s, 3),
        threads: r.threads,
        transitions: r.transitions_in_best_model,
        fitted_utc: r.fitted_at.map(utc),
        sigma_shown: pd,
        spread_fisher: fisher,
        spread_sandwich: sandwich,
        parameters,
        interval_methods,
        peaks: peak_rows(r),
        trials: trial_rows(r),
        goodness_of_fit: r.goodness_of_fit.as_ref().map(goodness_of_fit_words),
        tolerance_check: r.tolerance_check.as_ref().map(|t| {
            let widening = super::figures::rounding_widening_words(&r.parameters)
                .map_or(String::new(), |w| format!(" In the intervals, {w}."));
            tolerance_check_words(t) + &widening
        }),
        modes: mode_rows(r),
        correlation: if pd { correlation_rows(r) } else { Vec::new() },
        summary: super::summary::summary(r, warnings),
        attention: warning_views(warnings, Severity::Attention),
        information: warning_views(warnings, Severity::Information),
        figures: figures
            .iter()
            .map(|f| FigureView {
                file: &f.file,
                caption: &f.caption,
            })
            .collect(),
        target_job: r.target_job,
        map: map.map(|f| FigureView {
            file: &f.file,
            caption: &f.caption,
        }),
        prov: provenance_view(prov),
        sha256_fit: &r.input_sha256,
        version_fit: &r.wiperlab_version,
        version_page: env!("CARGO_PKG_VERSION"),
        solver_rtol: format!("{:e}", r.solver_rtol),
        solver_atol: format!("{:e}", r.solver_atol),
        bands,
        signal,
        fit_settings,
        drive: r.drive.as_ref().map(super::figures::drive_line),
        settings: &r.settings,
        priors: priors_view(r),
    }
}

/// Writes a template value: as given when marked safe, nothing for none, else escaped for HTML
/// text and quoted attributes (`&`, `<`, `>`, `"`, `'`; `html_escape`'s quoted-attribute rules,
/// which unlike minijinja's own escaper leave `/` readable in paths).
fn escape_html(
    out: &mut minijinja::Output,
    _state: &minijinja::State,
    value: &minijinja::Value,
) -> std::result::Result<(), minijinja::Error> {
    let written = if value.is_safe() {
        write!(out, "{value}")
    } else if value.is_none() || value.is_undefined() {
        Ok(())
    } else {
        out.write_str(&html_escape::encode_quoted_attribute(&value.to_string()))
    };
    written.map_err(|e| minijinja::Error::new(minijinja::ErrorKind::WriteFailure, e.to_string()))
}

/// Renders the page from [`TEMPLATE`]. `warnings` are shown as given (the caller collects them,
/// see [`write_report`]); the template engine escapes all text for HTML.
///
/// # Errors
/// The template engine's error (a template that does not compile or render is a bug).
pub fn render_html(
    r: &FitResult,
    figures: &[Figure],
    map: Option<&Figure>,
    warnings: &[PageWarning],
    prov: &Provenance,
) -> std::result::Result<String, minijinja::Error> {
    let mut env = minijinja::Environment::new();
    env.set_formatter(escape_html);
    env.add_template("report.html", TEMPLATE)?;
    env.get_template("report.html")?
        .render(page_view(r, figures, map, warnings, prov))
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
    let (figures, missing) = report_figures(r, dir)?;
    let mut warnings = result_warnings(r);
    if !missing.is_empty() {
        warnings.push(PageWarning::FiguresMissing {
            dir: dir.clone(),
            files: missing.clone(),
        });
    }
    let now_hash = sha256_file(&paths.recording).map_err(std::sync::Arc::new);
    match &now_hash {
        Ok(h) if !r.input_sha256.is_empty() && *h != r.input_sha256 => {
            warnings.push(PageWarning::RecordingChanged {
                path: paths.recording.clone(),
                sha256_now: h.clone(),
                sha256_at_fit: r.input_sha256.clone(),
            })
        }
        Err(e) => warnings.push(PageWarning::CannotHashRecording {
            reason: e.to_string(),
        }),
        _ => {}
    }

    let prov = Provenance {
        job_path: paths.job.display().to_string(),
        result_path: paths.result.display().to_string(),
        recording_path: paths.recording.display().to_string(),
        recording_sha256_now: now_hash,
        written_utc: utc(jiff::Timestamp::now()),
    };
    let path = dir.join(INDEX);
    let map = exploration_map(r, dir);
    let html = render_html(r, &figures, map.as_ref(), &warnings, &prov)
        .map_err(|e| Error::io(&path, "cannot render", std::io::Error::other(e)))?;
    crate::io::write_atomic(&path, html.as_bytes())?;
    Ok(ReportSummary {
        path,
        figures: figures.into_iter().map(|f| f.file).collect(),
        missing_figures: missing,
        warnings,
    })
}

/// The SVGs in `dir` as the page lists them (the fit's own in [`fit_figure_list`] order, then
/// [`OPTIONAL_FIGURES`], then the rest by name), and the fit figures missing from it.
fn report_figures(r: &FitResult, dir: &Path) -> Result<(Vec<Figure>, Vec<String>)> {
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
    Ok((figures, missing))
}

/// `wiperlab explore`'s reachability map of a target job, linked from the page in `dir`
/// (`reports/<job>/`): `reports/explore/<job>/reachability.svg` beside it, when it exists, its
/// caption followed by the exploration's closest achievable pair and constraint
/// (`constraint.txt` beside the map, when there is one).
/// `None` for a job fitted to a recording (it has no targets to map) or without an exploration.
fn exploration_map(r: &FitResult, dir: &Path) -> Option<Figure> {
    use crate::report::explore::{CONSTRAINT_TXT, MAP_SVG};
    let rel = format!("explore/{}/{MAP_SVG}", r.job);
    let path = dir.parent()?.join(&rel);
    let mut caption = "achieved line pairs of the job's freed parameters coloured by the weaker \
                       line's prominence, the targets, the start and the closest achievable pair \
                       marked, and the failed runs by cause (`wiperlab explore`)"
        .to_string();
    let notes = path.with_file_name(CONSTRAINT_TXT);
    if let Ok(text) = std::fs::read_to_string(&notes) {
        let text: Vec<&str> = text
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        caption += &format!(". {}", text.join(" "));
        caption = caption.trim_end_matches('.').to_string();
    }
    (r.target_job && path.is_file()).then(|| Figure {
        file: format!("../{rel}"),
        caption,
    })
}

/// The result's own warnings; one per undetermined parameter they do not already name; and, when
/// model evaluations failed but the result does not warn about the chosen model's failures, one
/// for the failures over all candidates.
fn result_warnings(r: &FitResult) -> Vec<PageWarning> {
    let names = |w: &FitWarning, p: crate::model::ParamId| match w {
        FitWarning::Text { text } => text.contains(p.name()),
        w => w.parameter() == Some(p),
    };
    let mut warnings: Vec<PageWarning> = r.warnings.iter().cloned().map(PageWarning::Fit).collect();
    for p in &r.parameters {
        if !p.determined && !r.warnings.iter().any(|w| names(w, p.name)) {
            warnings.push(PageWarning::Undetermined {
                parameter: p.name,
                std_error: p.std_error,
                lower: p.lower,
                upper: p.upper,
            });
        }
    }
    let fit_warned = r
        .warnings
        .iter()
        .any(|w| matches!(w, FitWarning::FailedEvaluations { .. }));
    if r.failed_evaluations > 0 && !fit_warned {
        warnings.push(PageWarning::FailedEvaluations {
            failed: r.failed_evaluations,
            evaluations: r.model_evaluations,
            first: r.first_failure.clone(),
        });
    }
    warnings
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::io::sha256_hex;

    /// The main job's search (`fits/reversal.toml`: 3 restarts of a 24 × 25 swarm at rtol 1e-6, a
    /// local CMA-ES run of at most 1,000 evaluations at rtol 1e-7, a 60-iteration polish) in the
    /// report's one line, each stage with its own tolerance.
    #[test]
    fn the_settings_line_names_each_search_stage_and_its_tolerance() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let job = crate::job::LoadedJob::load(&root.join("fits/reversal.toml")).expect("main job");
        let line = fit_settings_line(&job.job.fit);
        assert!(
            line.starts_with(
                "3 × (particle swarm 24 particles × 25 iterations at rtol 1e-6, CMA-ES ≤ 1000 \
                 evaluations at rtol 1e-7, Nelder–Mead ≤ 60 iterations), best kept (seed 1)"
            ),
            "{line}"
        );
    }

    #[test]
    fn line_words_give_the_origin_and_the_prominence() {
        use crate::spectrum::harmonics::{Fundamental, LineOrigin};
        // The seed experiment's cluster fit: 905.5 Hz, 65.19× its floor, harmonic 2 of 447.7 Hz.
        let mut o = LineOrigin {
            freq_hz: 905.46,
            prominence: 65.19,
            harmonic_of: Some(Fundamental {
                freq_hz: 447.71,
                order: 2,
                level_ratio: 2.21,
            }),
            dominant_hz: 77.93,
            below_dominant: 3.737e7,
        };
        let w = line_words(Some(o));
        assert!(
            w.starts_with("harmonic 2 of 447.7 Hz; 65.2× its floor; "),
            "{w}"
        );
        assert!(w.contains("below the dominant line (77.93 Hz)"), "{w}");
        o.harmonic_of = None;
        o.prominence = f64::NAN;
        o.below_dominant = 1.0;
        assert_eq!(line_words(Some(o)), "its own line; no measurable floor");
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

    /// A small result (k1 and B fitted) for the report stage's unit tests.
    pub(in crate::report) fn result() -> FitResult {
        use crate::fit::result::{FittedParam, Interval, PeakComparison};
        let p = |name: &str, determined: bool, interval: Option<Interval>| FittedParam {
            name: name.parse().unwrap(),
            value: 0.03,
            lower: 0.005,
            upper: 0.15,
            std_error: if determined { 0.001 } else { 0.2 },
            fisher_std_error: None,
            rounding_widening: None,
            determined,
            true_value: Some(0.029),
            rel_error: Some(0.03 / 0.029 - 1.0),
            interval,
        };
        FitResult {
            job: "unit".into(),
            recording: "rec.csv".into(),
            wiperlab_version: "0.1.0".into(),
            model: "blade2dof".parse().unwrap(),
            cost: 1.5,
            parameters: vec![
                p(
                    "k1",
                    true,
                    Some(Interval {
                        lo: 0.028,
                        hi: 0.032,
                        level: 0.68,
                        method: crate::fit::IntervalMethod::Profile {
                            rise_limit_nats: 0.125,
                        },
                        widened_from: None,
                        range_95: None,
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
                measured_line: None,
                model_line: None,
            }],
            undetermined: vec![crate::model::ParamId::B],
            correlation: vec![vec![1.0, -0.9], vec![-0.9, 1.0]],
            spread_source: crate::fit::SpreadSource::CostCurvature,
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
            warnings: Default::default(),
            input_sha256: sha256_hex(b"the recording at fit time"),
            settings: String::new(),
            target_job: false,
            spectrum: None,
            fit_settings: None,
            fitted_at: None,
            data_files: vec![],
            modes: vec![],
            interrupted: false,
            goodness_of_fit: None,
            tolerance_check: None,
            tracking_noise: None,
            drive: None,
            truth_cost: None,
            truth_segment: None,
            truth_tolerance: None,
            truth_model: None,
            truth_model_cost: None,
            friction_curve: None,
            posterior: None,
            priors: None,
            history: vec![],
        }
    }

    /// A fresh directory `wiperlab_html_<name>_<pid>` for a page: its `reports/` folder holding
    /// an empty SVG for each of `figures`, and the recording `rec.csv` holding `recording`.
    fn page_paths(name: &str, figures: &[impl AsRef<str>], recording: &str) -> ReportPaths {
        let dir = std::env::temp_dir().join(format!("wiperlab_html_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let figs = dir.join("reports");
        std::fs::create_dir_all(&figs).unwrap();
        for f in figures {
            let svg = "<svg xmlns=\"http://www.w3.org/2000/svg\"/>";
            std::fs::write(figs.join(f.as_ref()), svg).unwrap();
        }
        let rec = dir.join("rec.csv");
        std::fs::write(&rec, recording).unwrap();
        ReportPaths {
            job: dir.join("job.toml"),
            result: dir.join("unit.result.toml"),
            recording: rec,
            dir: figs,
        }
    }

    #[test]
    fn page_tables_and_warnings_from_a_result() {
        // Only two of the fit's figures, plus one extra SVG.
        let figures = ["cost.svg", "psd_low.svg", "extra.svg", "freq_vs_speed.svg"];
        let paths = page_paths("unit", &figures, "the recording changed since");
        let r = result();
        let s = write_report(&r, &paths).unwrap();
        // Fit figures in fit_figure_list order, then the optional ones, then the others by name.
        assert_eq!(
            s.figures,
            ["psd_low.svg", "cost.svg", "freq_vs_speed.svg", "extra.svg"]
        );
        assert_eq!(
            s.missing_figures,
            ["traces_tip.svg", "traces_head.svg", "friction_law.svg"]
        );
        let has = |f: &dyn Fn(&PageWarning) -> bool| s.warnings.iter().any(f);
        assert!(
            has(&|w| matches!(w, PageWarning::Undetermined { parameter, .. }
                if *parameter == crate::model::ParamId::B)),
            "{:?}",
            s.warnings
        );
        assert!(
            has(&|w| matches!(
                w,
                PageWarning::FailedEvaluations {
                    failed: 2,
                    evaluations: 30,
                    ..
                }
            )),
            "{:?}",
            s.warnings
        );
        assert!(
            has(&|w| matches!(w, PageWarning::FiguresMissing { files, .. } if files.len() == 3)),
            "{:?}",
            s.warnings
        );
        assert!(
            has(&|w| matches!(w, PageWarning::RecordingChanged { .. })),
            "{:?}",
            s.warnings
        );
        assert_eq!(s.warnings.len(), 4, "{:?}", s.warnings);
        // Failed evaluations below the fit's own threshold are for information; the rest need
        // attention.
        let severities: Vec<Severity> = s.warnings.iter().map(PageWarning::severity).collect();
        assert_eq!(
            severities
                .iter()
                .filter(|s| **s == Severity::Information)
                .count(),
            1,
            "{severities:?}"
        );
        let html = std::fs::read_to_string(&s.path).unwrap();
        // Three need attention, each a headline with its sentence folded under it; the failed
        // evaluations are for information, folded while something needs attention.
        let attention = &html[html.find("<ul id=\"attention-list\"").unwrap()..];
        let attention = &attention[..attention.find("</ul>").unwrap()];
        assert_eq!(attention.matches("<li>").count(), 3, "{attention}");
        assert!(attention.contains(
            "<li>The data leave B undetermined (1σ 0.200 over a search range [0.005000, 0.1500]): \
             read its value with care, or fix it from another measurement.<details><summary>\
             details</summary>the data leave B undetermined"
        ), "{attention}");
        assert!(html.contains(
            "<details id=\"information\"><summary><b>For information</b> (1): normal on a good fit"
        ));
        assert!(html.contains("<section id=\"summary\" class=\"check\">"));
        assert!(html.contains("<td>[0.02800, 0.03200] (68 %)<sup>1</sup></td>"));
        assert!(html.contains(
            "<sup>1</sup> Interval method: profile likelihood: where the NLL, minimised over the \
             other parameters, has risen 0.125 nats from the fit"
        ));
        assert!(html.contains("<td>+3.45 %</td>")); // 0.03/0.029 − 1
        assert!(html.contains("<span class=\"warn\">NO</span>"));
        assert!(html.contains("<td>-0.900</td>"));
        assert!(html.contains(&format!(
            "<code id=\"sha256-now\">{}</code>",
            sha256_hex(b"the recording changed since")
        )));
        assert!(html.contains("Only one model (blade2dof) was fitted"));
        assert!(html.contains("The result does not record the job's settings."));
        // No test in the result: no goodness-of-fit paragraph.
        assert!(!html.contains("id=\"goodness-of-fit\""));
        std::fs::remove_dir_all(paths.dir.parent().unwrap()).ok();
    }

    /// Unchanged recording, all figures present, nothing failed: no warnings at all; a fit its
    /// recording contradicts gets the goodness-of-fit paragraph in words, with its numbers.
    #[test]
    fn page_without_warnings_and_with_a_misfit_paragraph() {
        let mut r = result();
        // Every fit figure, beside the first page's optional and extra ones.
        let mut figures: Vec<String> = fit_figure_list(&r).into_iter().map(|(f, _)| f).collect();
        figures.extend(["freq_vs_speed.svg", "extra.svg"].map(String::from));
        let paths = page_paths("misfit", &figures, "the recording at fit time");
        r.parameters[1].determined = true;
        r.failed_evaluations = 0;
        // A fit its recording contradicts: the paragraph says so in words, with its numbers.
        r.goodness_of_fit = Some(crate::likelihood::GoodnessOfFit {
            excess_nll_nats: 170.96,
            replicate_mean_nats: 78.37,
            replicate_sd_nats: 7.96,
            replicates: 999,
            p_value: 0.001,
        });
        let s = write_report(&r, &paths).unwrap();
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);
        let html = std::fs::read_to_string(&s.path).unwrap();
        assert!(html.contains("<p id=\"warning-list\">None.</p>"));
        assert!(html.contains("<p id=\"goodness-of-fit\">Goodness of fit: the recording&#x27;s excess NLL at the fit is 170.96 nats, against 78.37 ± 8.0 for 999 replicates"), "{html}");
        assert!(html.contains("(p = 0.001): the spectra hold more than the model and noise"));
        std::fs::remove_dir_all(paths.dir.parent().unwrap()).ok();
    }

    /// The page of `r` written into a fresh directory named after `tag`, read back; the
    /// directory is removed.
    fn page_html(r: &FitResult, tag: &str) -> String {
        let dir = std::env::temp_dir().join(format!("wiperlab_html_{tag}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let paths = ReportPaths {
            job: dir.join("job.toml"),
            result: dir.join("unit.result.toml"),
            recording: dir.join("rec.csv"),
            dir: dir.clone(),
        };
        let html = std::fs::read_to_string(write_report(r, &paths).unwrap().path).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        html
    }

    #[test]
    fn a_widened_interval_shows_the_methods_own_ends() {
        let mut r = result();
        if let Some(iv) = r.parameters[0].interval.as_mut() {
            iv.widened_from = Some([0.029, 0.031]);
        }
        let html = page_html(&r, "wide");
        assert!(
            html.contains(
                "<td>[0.02800, 0.03200] (68 %)<sup>1</sup><br><span class=\"note\">widened from \
                 [0.02900, 0.03100]</span></td>"
            ),
            "{html}"
        );
    }

    #[test]
    fn the_tolerance_sentence_names_what_the_rounding_widens() {
        use crate::estimate::TolerancePoint;
        let mut r = result();
        let point = |rtol: f64, cost_nats| TolerancePoint {
            rtol,
            atol: rtol * 1e-2,
            cost_nats,
            transitions: 100,
        };
        r.tolerance_check = Some(crate::fit::tolerance::ToleranceCheck {
            points: vec![point(1e-8, 70.0), point(1e-9, 70.1)],
            spread_nats: 0.1,
            failed: Vec::new(),
            jitter: None,
        });
        r.parameters[0].rounding_widening = Some(2.5);
        let html = page_html(&r, "round");
        let name = r.parameters[0].name;
        assert!(
            html.contains("In the intervals, the rounding")
                && html.contains(&format!("{name} ×2.50")),
            "{html}"
        );
    }

    /// A result with priors shows each prior beside the fitted value and interval, and the rig
    /// curve's points beside the fitted μ_d, in the priors section.
    #[test]
    fn priors_are_shown_beside_the_fit() {
        use crate::likelihood::prior::{
            ParamPriorReport, PriorsReport, RigCurveReport, RigPointReport,
        };
        let dir = std::env::temp_dir().join(format!("wiperlab_html_prior_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let mut r = result();
        r.priors = Some(PriorsReport {
            nats_at_fit: 1.25,
            parameters: vec![ParamPriorReport {
                name: crate::model::ParamId::ThetaC,
                prior: crate::job::ParamPrior::Normal {
                    mean: 0.08,
                    sd: 0.01,
                },
                prior_interval: [0.07, 0.09],
                value: 0.085,
                interval: Some([0.08, 0.09]),
                z: 0.5,
            }],
            friction_curve: Some(RigCurveReport {
                file: "rig.csv".into(),
                points: vec![RigPointReport {
                    speed_m_per_s: 0.075,
                    coefficient: 0.17,
                    sd: 0.008,
                    mu_d_fit: 0.18,
                    z: 1.25,
                }],
            }),
        });
        let paths = ReportPaths {
            job: dir.join("job.toml"),
            result: dir.join("unit.result.toml"),
            recording: dir.join("rec.csv"),
            dir: dir.clone(),
        };
        let html = std::fs::read_to_string(write_report(&r, &paths).unwrap().path).unwrap();
        for row in [
            "here 1.250 nats at the fit",
            "<td class=\"l\">normal, mean 0.08000, sd 0.0100</td><td>[0.07000, 0.09000]</td>\
             <td>0.08500</td><td>[0.08000, 0.09000]</td><td>0.500</td>",
            "<code>rig.csv</code>",
            "<tr><td>0.07500</td><td>0.1700</td><td>0.00800</td><td>0.1800</td><td>1.25</td></tr>",
        ] {
            assert!(html.contains(row), "no {row:?} in {html}");
        }
        r.priors = None;
        let html = std::fs::read_to_string(write_report(&r, &paths).unwrap().path).unwrap();
        assert!(!html.contains("id=\"priors\""));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_parameter_the_posterior_spreads_over_its_bounds_is_called_not_determined() {
        let dir = std::env::temp_dir().join(format!("wiperlab_html_post_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let mut r = result();
        let name = r.parameters[0].name;
        r.posterior = Some(crate::posterior::PosteriorSummary {
            walkers: 8,
            steps: 10,
            burn_in: 2,
            acceptance_fraction: 0.3,
            tempering: 1.0,
            evaluations: 88,
            ladder: Vec::new(),
            swap_fractions: Vec::new(),
            parameters: vec![crate::posterior::ParamPosterior {
                name,
                quantiles: [0.01, 0.02, 0.03, 0.04, 0.05],
                r_hat: 1.0,
                autocorr_steps: 1.0,
                ess: 64.0,
                span_fraction: 0.8,
                determined: false,
            }],
            draws: Vec::new(),
        });
        let paths = ReportPaths {
            job: dir.join("job.toml"),
            result: dir.join("unit.result.toml"),
            recording: dir.join("rec.csv"),
            dir: dir.clone(),
        };
        let html = std::fs::read_to_string(write_report(&r, &paths).unwrap().path).unwrap();
        assert!(
            html.contains(
                "<span class=\"note\">95 %: [0.01000, 0.05000]: not determined by this recording \
                 (the posterior spans 80 % of the search range)</span>"
            ),
            "{html}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn model_reasons_are_short_and_their_numbers_have_columns() {
        use crate::fit::{ModelTrial, RatioTest, TrialEvidence};
        let mut r = result();
        r.spectrum = Some(Default::default()); // bands low 30–300 Hz, high 500–5000 Hz
        let evidence = |delta_aic: f64, lrt: Option<RatioTest>| TrialEvidence {
            log_likelihood_nats: 5805.8,
            spectral_nll_nats: vec![],
            time_nll_nats: None,
            residual_rms_m: 1e-5,
            n_effective: 1e3,
            effective_parameters: None,
            tic: Some(-11603.6 + delta_aic),
            delta_tic: Some(delta_aic),
            aic: -11603.6 + delta_aic,
            bic: -11580.0 + delta_aic,
            delta_aic,
            delta_bic: delta_aic,
            lrt,
        };
        let trial = |model: &str, chosen: bool, e: TrialEvidence| ModelTrial {
            model: model.parse().unwrap(),
            parameters: vec![crate::model::ParamId::K1],
            cost: 78.3,
            wall_time_s: 4.0,
            model_evaluations: 3658,
            failed_evaluations: 408,
            chosen,
            reason: "the fit's own sentence, with every number".into(),
            not_distinguishable: false,
            evidence: Some(e),
            friction: None,
        };
        let lrt = |p_value: f64| RatioTest {
            against: "blade2dof".parse().unwrap(),
            statistic: 0.21,
            df: 2,
            p_value,
        };
        r.model_trials = vec![
            trial("head1dof", false, evidence(905.2, None)),
            trial("blade2dof", true, evidence(0.0, None)),
            trial("blade2dof+shoulder", false, evidence(3.8, Some(lrt(0.901)))),
        ];
        let rows = trial_rows(&r);
        let reasons: Vec<&str> = rows.iter().map(|t| t.short_reason.as_str()).collect();
        assert_eq!(
            reasons,
            [
                "no neck–lip mode for band 'high'",
                "lowest AIC",
                "its extra parameters gain nothing beyond chance"
            ]
        );
        assert_eq!(rows[2].lrt, "0.901");
        assert_eq!(rows[0].lrt, "—");
        r.model_trials[2].evidence = Some(evidence(2.5, Some(lrt(0.01))));
        assert_eq!(
            trial_rows(&r)[2].short_reason,
            "a gain beyond chance, but not worth its parameters"
        );
        r.model_trials[2].evidence = Some(evidence(1.5, Some(lrt(0.01))));
        assert_eq!(
            trial_rows(&r)[2].short_reason,
            "not distinguishable by this recording (TIC within 2); more parameters; a gain beyond \
             chance, but not worth its parameters"
        );
        // Laws as candidates: the viscous law 1.2 below the chosen exponential one, which has
        // fewer parameters; the law column names each law with its coefficients.
        let mut laws = r.clone();
        laws.model_trials = vec![
            trial("blade2dof@exponential", true, evidence(0.0, None)),
            trial("blade2dof@exponential_viscous", false, evidence(-1.2, None)),
        ];
        laws.model_trials[1].friction = Some(crate::model::FrictionLaw::ExponentialViscous {
            a: 0.88,
            b_s_per_m: 69.7,
            c: 0.56,
            d_s_per_m: 0.3567,
        });
        let rows = trial_rows(&laws);
        assert_eq!(
            rows[0].short_reason,
            "the fewest parameters within 2 of the lowest TIC"
        );
        assert!(rows[1].short_reason.starts_with("not distinguishable"));
        assert_eq!(rows[0].law, "—");
        assert_eq!(
            rows[1].law,
            "exponential_viscous (a 0.880, b_s_per_m 69.7, c 0.560, d_s_per_m 0.357)"
        );
        // The full sentence stays on the page, folded under the short one.
        let prov = Provenance {
            job_path: "job.toml".into(),
            result_path: "r.toml".into(),
            recording_path: "rec.csv".into(),
            recording_sha256_now: Ok(String::new()),
            written_utc: "now".into(),
        };
        let html = render_html(&r, &[], None, &[], &prov).unwrap();
        assert!(
            html.contains(
                "<td class=\"l reason\">lowest AIC<details><summary>why, in numbers</summary>the \
             fit&#x27;s own sentence, with every number</details></td>"
            ),
            "{html}"
        );
        assert!(html.contains("<td>3658 (408)</td>"));
    }

    #[test]
    fn utc_dates() {
        // 86,400 + 3,723 s after the epoch is 1970-01-02 01:02:03 (1 day, 1 h 2 min 3 s).
        assert_eq!(
            utc(jiff::Timestamp::from_second(86_400 + 3_723).unwrap()),
            "1970-01-02 01:02:03 UTC"
        );
        // Day 20,778 after the epoch is 2026-11-21 (date(1) arithmetic).
        assert_eq!(
            utc(jiff::Timestamp::from_second(20_778 * 86_400).unwrap()),
            "2026-11-21 00:00:00 UTC"
        );
    }

    /// Text from the result is escaped, file names are percent-encoded in links, the fit's own
    /// timestamp is shown, and ±1σ and correlations are left out when the curvature is not positive
    /// definite.
    #[test]
    fn page_escapes_encodes_and_hides_sigma_without_curvature() {
        let mut r = result();
        r.job = "<b>job</b>".into();
        r.fitted_at = Some("2026-11-22T09:08:07Z".parse().unwrap());
        let figures = [Figure {
            file: "psd_a b#?.svg".into(),
            caption: "a \"quoted\" <caption>".into(),
        }];
        let prov = Provenance {
            job_path: "job.toml".into(),
            result_path: "r.toml".into(),
            recording_path: "rec.csv".into(),
            recording_sha256_now: Err(std::sync::Arc::new(Error::input(
                std::path::Path::new("rec.csv"),
                "gone & away",
            ))),
            written_utc: "now".into(),
        };
        let text = PageWarning::Fit(FitWarning::Text {
            text: "<i>w</i>".into(),
        });
        let html = render_html(&r, &figures, None, &[text], &prov).unwrap();
        assert!(
            html.contains("<h1>Fit report: &lt;b&gt;job&lt;/b&gt;</h1>"),
            "{html}"
        );
        assert!(html.contains("src=\"psd_a%20b%23%3F.svg\""), "{html}");
        assert!(html.contains("alt=\"a &quot;quoted&quot; &lt;caption&gt;\""));
        assert!(html.contains("<li>&lt;i&gt;w&lt;/i&gt;</li>"));
        assert!(html.contains("<span class=\"warn\">rec.csv: gone &amp; away</span>"));
        assert!(html.contains("Fitted 2026-11-22 09:08:07 UTC."));
        assert!(html.contains("model <b>blade2dof</b> (2-DOF blade)"));
        assert!(html.contains("<th>± 1σ</th>"));
        r.correlation = vec![vec![f64::NAN; 2]; 2];
        let html = render_html(&r, &figures, None, &[], &prov).unwrap();
        assert!(!html.contains("<th>± 1σ</th>"), "{html}");
        assert!(html.contains("1σ: not shown"));
        assert!(!html.contains("correlation-table"));
    }

    /// A target job's map comes with the exploration's constraint.txt in its caption; a job fitted
    /// to a recording has no map.
    #[test]
    fn the_map_caption_carries_the_constraint() {
        let root = std::env::temp_dir().join(format!("wiperlab_map_{}", std::process::id()));
        let page = root.join("reports").join("job");
        let explore = root.join("reports").join("explore").join("job");
        std::fs::create_dir_all(&page).unwrap();
        std::fs::create_dir_all(&explore).unwrap();
        std::fs::write(explore.join(crate::report::explore::MAP_SVG), "<svg/>").unwrap();
        std::fs::write(
            explore.join(crate::report::explore::CONSTRAINT_TXT),
            "Closest achievable pair: sample 7.\nConstraint: band low needs head_mass below its lower bound.\n",
        )
        .unwrap();
        let mut r = result();
        r.job = "job".into();
        assert!(
            exploration_map(&r, &page).is_none(),
            "a recording's fit got a map"
        );
        r.target_job = true;
        let map = exploration_map(&r, &page).unwrap();
        assert_eq!(map.file, "../explore/job/reachability.svg");
        assert!(
            map.caption.ends_with(
                "(`wiperlab explore`). Closest achievable pair: sample 7. Constraint: band low needs head_mass below its lower bound"
            ),
            "{}",
            map.caption
        );
        std::fs::remove_dir_all(&root).ok();
    }
}
