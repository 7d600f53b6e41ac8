//! The figures and text summaries each command writes (composition only; drawing is in
//! [`super::plot`]).

use super::plot::{ChartOpts, Marker, Series, Span, heatmap, line_chart};
use crate::fit::features::{BandFeatures, Features, noise_floor};
use crate::fit::result::{HistoryPoint, SearchStage};
use crate::fit::{FitOutcome, FitResult};
use crate::job::{Objective, SwarmCost};
use crate::likelihood::instfreq::FreqSpeedComparison;
use crate::model::FrictionLaw;
use crate::simulate::blade::{BladeSimulation, ContactForces};
use crate::spectrum::Spectrogram;
use crate::spectrum::instfreq::FreqSpeedPoint;
use crate::trace::Role;
use crate::{Error, Result};
use std::fmt::Write as _;
use std::path::Path;

fn peak_markers(f: &Features) -> Vec<Marker> {
    f.bands
        .iter()
        .filter_map(|b| b.peak)
        .map(|p| Marker {
            x: p.freq_hz,
            y: p.level,
            label: format!("{:.2} Hz", p.freq_hz),
        })
        .collect()
}

/// Percentiles of the log PSD that span a spectrogram's colour range: the 5th, so the few cells
/// many decades down (the detrended 0 Hz bin, the window's nulls) take the bottom colour instead
/// of stretching the scale, and the 99th, so the drive's few lowest bins, four to eight decades
/// above the rest in an absolute coordinate, take the top colour and leave the scale to the lines
/// above the floor (the ~900 Hz chatter of the shipped recording).
pub const SPECTROGRAM_PERCENTILES: (f64, f64) = (5.0, 99.0);

/// The bands of `f` as shaded spans, named with their range.
fn band_spans(f: &Features) -> Vec<Span> {
    f.bands
        .iter()
        .map(|b| {
            let [lo, hi] = b.spec.range_hz;
            Span {
                lo,
                hi,
                label: format!(
                    "band {}–{} Hz",
                    crate::names::significant(lo, 4),
                    crate::names::significant(hi, 4)
                ),
            }
        })
        .collect()
}

/// PSD with the peaks of every band marked (and, with `mark_bands`, the bands shaded), and the
/// spectrogram with its numbers (`spectrogram_<name>.csv`, [`spectrogram_csv`]) when one is given,
/// for one signal.
pub fn spectrum_figures(
    dir: &Path,
    name: &str,
    f: &Features,
    spectrogram: Option<&Spectrogram>,
    mark_bands: bool,
) -> Result<()> {
    let b0 = &f.bands[0];
    let (fr, ps): (Vec<f64>, Vec<f64>) = b0
        .full_freq_hz
        .iter()
        .zip(&b0.full_psd)
        .skip(1)
        .map(|(a, b)| (*a, *b))
        .unzip();
    line_chart(
        &dir.join(format!("psd_{name}.svg")),
        &format!(
            "Welch {} of {name} ({}, nperseg {})",
            match b0.spec.scaling {
                crate::spectrum::Scaling::Density => "PSD",
                crate::spectrum::Scaling::Spectrum => "power spectrum",
            },
            b0.spec.window.scipy_name(),
            b0.spec.nperseg
        ),
        "frequency [Hz]",
        match b0.spec.scaling {
            crate::spectrum::Scaling::Density => "PSD [m²/Hz]",
            crate::spectrum::Scaling::Spectrum => "power [m²]",
        },
        &[Series::line(name, fr, ps)],
        &ChartOpts {
            log_y: true,
            markers: peak_markers(f),
            spans: if mark_bands {
                band_spans(f)
            } else {
                Vec::new()
            },
            ..ChartOpts::default()
        },
    )?;
    if let Some(sg) = spectrogram {
        heatmap(
            &dir.join(format!("spectrogram_{name}.svg")),
            &format!(
                "spectrogram of {name} (Hann, nperseg {}, 75 % overlap)",
                sg.nperseg
            ),
            "time from first sample [s]",
            "frequency [Hz]",
            "PSD [m²/Hz]",
            &sg.t_s,
            &sg.freq_hz,
            &sg.density,
            true,
            Some(SPECTROGRAM_PERCENTILES),
        )?;
        spectrogram_csv(dir, name, sg)?;
    }
    Ok(())
}

/// Writes `spectrogram_<name>.csv` into `dir`, the numbers of `spectrogram_<name>.svg`: one row
/// per cell, `t_s` (the segment's centre, from the first sample), `freq_hz` and
/// `psd_m2_per_hz` (one-sided density), time-major. Returns the file name.
///
/// # Errors
/// [`Error::Io`] naming the file.
pub fn spectrogram_csv(dir: &Path, name: &str, sg: &Spectrogram) -> Result<String> {
    let n = sg.t_s.len() * sg.freq_hz.len();
    let mut t = Vec::with_capacity(n);
    let mut f = Vec::with_capacity(n);
    let mut p = Vec::with_capacity(n);
    for (ti, row) in sg.t_s.iter().zip(&sg.density) {
        for (fi, pi) in sg.freq_hz.iter().zip(row) {
            t.push(*ti);
            f.push(*fi);
            p.push(*pi);
        }
    }
    let cols: [(&str, &[f64]); 3] = [("t_s", &t), ("freq_hz", &f), ("psd_m2_per_hz", &p)];
    write_columns(dir, &format!("spectrogram_{name}.csv"), &cols)
}

/// Writes a simulation: the trace CSV with the model state ([`write_simulation_trace`]), the
/// transitions CSV, and SVGs of the tip and head motion.
pub fn write_simulation(dir: &Path, sim: &BladeSimulation, forces: &ContactForces) -> Result<()> {
    write_simulation_trace(&dir.join("trace.csv"), sim, forces)?;
    let tpath = dir.join("transitions.csv");
    let mut s = String::from("t_s,from,to\n");
    for t in &sim.transitions {
        let _ = writeln!(s, "{:.17e},{},{}", t.t_s, t.from, t.to);
    }
    crate::io::write_atomic(&tpath, s.as_bytes())?;
    let rel: Vec<f64> = sim
        .v3_m
        .iter()
        .zip(&sim.v_m)
        .map(|(a, b)| (a - b) * 1e3)
        .collect();
    let phase: Vec<f64> = sim.phase.iter().map(|p| p.code() as f64).collect();
    line_chart(
        &dir.join("tip_relative.svg"),
        "lip tip relative to head (model)",
        "t [s]",
        "v3 − v [mm]",
        &[Series::line("v3 − v", sim.t_s.clone(), rel)],
        &ChartOpts::default(),
    )?;
    line_chart(
        &dir.join("phase.svg"),
        "contact phase (1 slip+, 0 stick, −1 slip−)",
        "t [s]",
        "contact phase [1 slip+, 0 stick, −1 slip−]",
        &[Series::line("phase", sim.t_s.clone(), phase)],
        &ChartOpts::default(),
    )?;
    line_chart(
        &dir.join("head_drop.svg"),
        "head drop u (model)",
        "t [s]",
        "u [mm]",
        &[Series::line(
            "u",
            sim.t_s.clone(),
            sim.u_m.iter().map(|u| u * 1e3).collect(),
        )],
        &ChartOpts::default(),
    )
}

/// Simulate's `trace.csv`: the canonical trace of the model (head at (v, −u), tip at (v3, −(l1+l2)),
/// so `tip_x_m` is v3) followed by the model's state and contact: `theta_rad`, `phi_rad`,
/// `theta_dot_rad_per_s`, `phi_dot_rad_per_s`, `v3_dot_m_per_s`, `normal_force_n`,
/// `friction_force_n` (along +x, on the tip) and `phase` (`slip+`, `slip-`, `stick`).
///
/// # Errors
/// As [`crate::import::canonical::write_trace_csv_with`].
pub fn write_simulation_trace(
    path: &Path,
    sim: &BladeSimulation,
    forces: &ContactForces,
) -> Result<()> {
    use crate::import::canonical::{ExtraColumn, write_trace_csv_with};
    let phase: Vec<&str> = sim.phase.iter().map(|p| p.label()).collect();
    write_trace_csv_with(
        path,
        &sim.to_trace(),
        &[
            ExtraColumn::Numbers("theta_rad", &sim.theta_rad),
            ExtraColumn::Numbers("phi_rad", &sim.phi_rad),
            ExtraColumn::Numbers("theta_dot_rad_per_s", &sim.theta_dot_rad_per_s),
            ExtraColumn::Numbers("phi_dot_rad_per_s", &sim.phi_dot_rad_per_s),
            ExtraColumn::Numbers("v3_dot_m_per_s", &sim.v3_dot_m_per_s),
            ExtraColumn::Numbers("normal_force_n", &forces.normal_n),
            ExtraColumn::Numbers("friction_force_n", &forces.friction_n),
            ExtraColumn::Labels("phase", &phase),
        ],
    )
}

/// The fit's figures: traces, PSDs per band with peaks, the friction law, the cost history, and
/// frequency against tip speed when `freq_speed` is given.
pub fn fit_figures(
    dir: &Path,
    o: &FitOutcome,
    freq_speed: Option<&FreqSpeedComparison>,
) -> Result<()> {
    // A target job has no recorded points: its figures show the model against the target lines.
    let targets_only = o.measured_trace.points.is_empty();
    trace_figures(dir, o, targets_only)?;
    for (d, m) in o.measured.bands.iter().zip(&o.model.bands) {
        band_psd_figure(dir, o, d, m, targets_only)?;
    }
    friction_law_figure(dir, &o.result, &o.best_params.friction, max_tip_speed(o))?;
    if let Some(c) = freq_speed {
        freq_vs_speed_figure(dir, c)?;
    }
    let settings = o.result.fit_settings.as_ref();
    let objective = settings.map_or(Objective::Features, |f| f.objective);
    let swarm_cost = settings.map_or(SwarmCost::Features, |f| f.search.swarm_cost);
    if let Some(post) = &o.result.posterior {
        posterior_figure(dir, &o.result, post)?;
    }
    cost_figure(dir, &o.result.history, objective, swarm_cost)
}

/// `posterior_corner.svg`: the corner plot of a posterior sample's draws, each parameter's
/// 68.27 % interval, fit and truth.
///
/// # Errors
/// As [`crate::report::plot::corner_plot`].
pub fn posterior_figure(
    dir: &Path,
    r: &FitResult,
    post: &crate::posterior::PosteriorSummary,
) -> Result<()> {
    let axes: Vec<crate::report::plot::CornerAxis> = post
        .parameters
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let fitted = r.parameters.iter().find(|f| f.name == p.name);
            let unit = p.name.unit();
            crate::report::plot::CornerAxis {
                label: if unit == "-" {
                    p.name.to_string()
                } else {
                    format!("{} ({unit})", p.name)
                },
                draws: post.draws.iter().map(|d| d[i]).collect(),
                fit: fitted.map_or(f64::NAN, |f| f.value),
                truth: fitted.and_then(|f| f.true_value),
                interval: [p.quantiles[1], p.quantiles[3]],
            }
        })
        .collect();
    crate::report::plot::corner_plot(
        &dir.join("posterior_corner.svg"),
        &format!(
            "posterior sample: {} walkers × {} steps ({} burn-in), likelihood^{:.2}{}",
            post.walkers,
            post.steps,
            post.burn_in,
            post.tempering,
            if post.ladder.is_empty() {
                String::new()
            } else {
                format!(", {} temperatures", post.ladder.len())
            }
        ),
        &axes,
    )
}

/// A signal in mm with its mean over the finite samples removed, so measured (camera frame) and
/// model (model frame) share an axis.
fn demean(x: &[f64]) -> Vec<f64> {
    let f: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
    let m = f.iter().sum::<f64>() / f.len().max(1) as f64;
    x.iter().map(|v| (v - m) * 1e3).collect::<Vec<f64>>()
}

/// The "model" series alone for a target job, else "measured" then "model".
fn measured_and_model(
    targets_only: bool,
    t_meas: &[f64],
    meas: Vec<f64>,
    t_model: &[f64],
    model: Vec<f64>,
) -> Vec<Series> {
    if targets_only {
        vec![Series::line("model", t_model.to_vec(), model)]
    } else {
        vec![
            Series::line("measured", t_meas.to_vec(), meas),
            Series::line("model", t_model.to_vec(), model),
        ]
    }
}

/// `traces_tip.svg` and `traces_head.svg`: the measured and fitted-model traces, means removed,
/// with their residual panels.
fn trace_figures(dir: &Path, o: &FitOutcome, targets_only: bool) -> Result<()> {
    let meas = if targets_only {
        Vec::new()
    } else {
        o.signal.extract(&o.measured_trace)?
    };
    let model = o.signal.extract(&o.best_sim.to_trace())?;
    let t = &o.measured_trace.t_s;
    let t_model = &o.best_sim.t_s;
    line_chart(
        &dir.join("traces_tip.svg"),
        "tip x − head x: measured and fitted model (means removed)",
        "t [s] (model clock)",
        "tip − head [mm]",
        &measured_and_model(targets_only, t, demean(&meas), t_model, demean(&model)),
        &residual_opts(t, &demean(&meas), t_model, &demean(&model)),
    )?;
    let head_meas = o
        .measured_trace
        .role(Role::Head)
        .map(|p| demean(&p.y_m))
        .unwrap_or_default();
    let head_model: Vec<f64> = demean(&o.best_sim.u_m.iter().map(|u| -u).collect::<Vec<_>>());
    line_chart(
        &dir.join("traces_head.svg"),
        "head y: measured and fitted model (means removed)",
        "t [s] (model clock)",
        "head y [mm]",
        &measured_and_model(
            targets_only,
            t,
            head_meas.clone(),
            t_model,
            head_model.clone(),
        ),
        &residual_opts(t, &head_meas, t_model, &head_model),
    )
}

/// The peak markers of one band's PSD figure: the measured peak (or, for a target job, the
/// target line at the model peak's level), then the model peak.
fn band_psd_markers(
    o: &FitOutcome,
    d: &BandFeatures,
    m: &BandFeatures,
    targets_only: bool,
) -> Vec<Marker> {
    let mut markers = Vec::new();
    if let Some(p) = d.peak.filter(|_| !targets_only) {
        markers.push(Marker {
            x: p.freq_hz,
            y: p.level,
            label: format!("measured {:.2} Hz", p.freq_hz),
        });
    }
    if let (true, Some(pk), Some(pm)) = (
        targets_only,
        o.result.peaks.iter().find(|p| p.band == d.spec.name),
        m.peak,
    ) {
        markers.push(Marker {
            x: pk.measured_hz,
            y: pm.level,
            label: match pk.target_range_hz {
                Some(r) => format!("target {:.0}–{:.0} Hz", r[0], r[1]),
                None => format!("target {:.2} Hz", pk.measured_hz),
            },
        });
    }
    if let Some(p) = m.peak {
        markers.push(Marker {
            x: p.freq_hz,
            y: p.level,
            label: format!("model {:.2} Hz", p.freq_hz),
        });
    }
    markers
}

/// `psd_<band>.svg`: one band's measured and model PSDs (and the model plus the measured noise
/// floor) on a log axis, peaks marked; the model alone against the target for a target job.
fn band_psd_figure(
    dir: &Path,
    o: &FitOutcome,
    d: &BandFeatures,
    m: &BandFeatures,
    targets_only: bool,
) -> Result<()> {
    // The cost adds the measurement's noise floor to the model PSD (src/search/problem.rs, `cost_of`);
    // without it the model's deep stick–slip troughs look like misfits they are not.
    let floor = noise_floor(d);
    let markers = band_psd_markers(o, d, m, targets_only);
    line_chart(
        &dir.join(format!("psd_{}.svg", d.spec.name)),
        &format!(
            "Welch PSD, {} band {}–{} Hz (nperseg {}): {}",
            d.spec.name,
            crate::names::significant(d.spec.range_hz[0], 4),
            crate::names::significant(d.spec.range_hz[1], 4),
            d.spec.nperseg,
            if targets_only {
                "model against the target"
            } else {
                "measured, model, model + noise floor"
            }
        ),
        "frequency [Hz]",
        "PSD [m²/Hz]",
        &if targets_only {
            vec![Series::line("model", m.freq_hz.clone(), m.psd.clone())]
        } else {
            vec![
                Series::line("measured", d.freq_hz.clone(), d.psd.clone()),
                Series::line("model", m.freq_hz.clone(), m.psd.clone()),
                Series::line(
                    format!(
                        "model + measured noise floor {floor:.2e} m²/Hz (as the cost compares)"
                    ),
                    m.freq_hz.clone(),
                    m.psd.iter().map(|p| p + floor).collect(),
                ),
            ]
        },
        &ChartOpts {
            log_y: true,
            markers,
            ..ChartOpts::default()
        },
    )
}

/// Chart options with a "measured − model" residual panel when both sides are sampled at the same
/// times (the fit simulates at the recording's frames); none for a target job's empty measurement.
fn residual_opts(t_meas: &[f64], meas: &[f64], t_model: &[f64], model: &[f64]) -> ChartOpts {
    let same = !meas.is_empty() && t_meas.len() == t_model.len() && meas.len() == model.len();
    ChartOpts {
        residual: same.then(|| {
            Series::line(
                "residual: measured − model",
                t_meas.to_vec(),
                meas.iter().zip(model).map(|(d, m)| d - m).collect(),
            )
        }),
        ..ChartOpts::default()
    }
}

/// The fastest slip speed the fitted model's lip tip reaches in the window, m/s (`|Δv3/Δt|` over
/// the samples), or `None` without two finite samples.
fn max_tip_speed(o: &FitOutcome) -> Option<f64> {
    let sim = &o.best_sim;
    let v = sim
        .t_s
        .windows(2)
        .zip(sim.v3_m.windows(2))
        .map(|(t, x)| ((x[1] - x[0]) / (t[1] - t[0])).abs())
        .filter(|v| v.is_finite())
        .fold(f64::NAN, f64::max);
    (v.is_finite() && v > 0.0).then_some(v)
}

/// Writes `friction_law.svg`: the fitted law `law` from 0 to past the fastest slip speed
/// `v_max_m_per_s` the model's tip reaches (0.2 m/s when unknown). Over the measured range (the
/// result's [`crate::model::friction_curve::FrictionCurve`], shaded) it is solid with its ±1σ
/// band; outside it dashed and labelled extrapolation; the true law on the same axes when known.
///
/// # Errors
/// [`Error::Io`]/[`super::ReportError`] from drawing.
pub fn friction_law_figure(
    dir: &Path,
    r: &FitResult,
    law: &FrictionLaw,
    v_max_m_per_s: Option<f64>,
) -> Result<()> {
    let curve = r.friction_curve.as_ref();
    let rig = r.priors.as_ref().and_then(|p| p.friction_curve.as_ref());
    let v_top = speed_axis_top(r, v_max_m_per_s);
    let grid: Vec<f64> = (0..=200).map(|i| i as f64 * v_top / 200.0).collect();
    let mu = |l: &FrictionLaw, v: &[f64]| -> Vec<f64> { v.iter().map(|x| l.mu_slip(*x)).collect() };
    let mut series = Vec::new();
    let mut opts = ChartOpts::default();
    let Some(c) = curve else {
        series.push(Series::dashed(
            "fitted law (the fitted model never slips: no measured range)",
            grid.clone(),
            mu(law, &grid),
        ));
        rig_points(rig, &mut series, &mut opts);
        return line_chart(
            &dir.join("friction_law.svg"),
            &format!("dynamic friction coefficient μ_d(|v|), law {}", law.name()),
            FRICTION_X_LABEL,
            FRICTION_Y_LABEL,
            &series,
            &opts,
        );
    };
    let [lo, hi] = c.measured_range_m_per_s;
    let [p_lo, p_hi] = c.range_percentiles;
    series.push(Series::line(
        format!(
            "fitted μ_d over the measured range ({p_lo:.0}th–{p_hi:.0}th percentile of slip speeds)"
        ),
        c.speed_m_per_s.clone(),
        c.mu_d.clone(),
    ));
    // The law outside the range: [0, lo] and [hi, top], broken between.
    let outside: Vec<f64> = grid
        .iter()
        .copied()
        .filter(|v| *v < lo)
        .chain([lo, f64::NAN, hi])
        .chain(grid.iter().copied().filter(|v| *v > hi))
        .collect();
    series.push(Series::dashed(
        "fitted law outside the range: extrapolation",
        outside.clone(),
        outside
            .iter()
            .map(|v| {
                if v.is_nan() {
                    f64::NAN
                } else {
                    law.mu_slip(*v)
                }
            })
            .collect(),
    ));
    if let (Some(truth), Some(rms)) = (&c.true_law, c.rms_rel_diff_to_truth) {
        series.push(Series::line(
            format!(
                "true μ_d ({}; fitted lies {:.1} % rms from it over the range)",
                truth.name(),
                100.0 * rms
            ),
            grid.clone(),
            mu(truth, &grid),
        ));
    }
    curve_bands(c, &mut opts);
    opts.spans.push(Span {
        lo,
        hi,
        label: format!("measured slip speeds {:.1}–{:.1} mm/s", 1e3 * lo, 1e3 * hi),
    });
    let (y_lo, y_hi) = measured_y_range(c);
    opts.y_range = Some(match rig_points(rig, &mut series, &mut opts) {
        Some((lo, hi)) => (
            y_lo.min(lo - 0.05 * (hi - lo)),
            y_hi.max(hi + 0.05 * (hi - lo)),
        ),
        None => (y_lo, y_hi),
    });
    line_chart(
        &dir.join("friction_law.svg"),
        &friction_title(r, law, !c.mu_d_sigma.is_empty()),
        FRICTION_X_LABEL,
        FRICTION_Y_LABEL,
        &series,
        &opts,
    )
}

/// The friction figure's shaded bands, both in the fitted curve's colour: the envelope of the
/// models the recording does not distinguish (lighter alone, under the band) and the ±1σ band.
fn curve_bands(c: &crate::model::friction_curve::FrictionCurve, opts: &mut ChartOpts) {
    let band = |[lo, hi]: [Vec<f64>; 2], label: String| super::plot::Band {
        x: c.speed_m_per_s.clone(),
        lo,
        hi,
        series: 0,
        label,
    };
    if let Some(edges) = c.envelope_edges() {
        let label = format!(
            "with the {} model(s) the recording does not distinguish",
            c.alternative_laws.len()
        );
        opts.bands.push(band(edges, label));
    }
    if let Some(edges) = c.band_edges() {
        let label = if c.band_widened() {
            "±1σ by the delta method, widened to the evaluated points as likely as the fit".into()
        } else {
            "±1σ by the delta method from the fitted covariance".into()
        };
        opts.bands.push(band(edges, label));
    }
}

/// The friction figure's last slip speed: past the fastest slip speed `v_max_m_per_s` the model's
/// tip reaches (0.2 m/s when unknown), the measured range and the rig curve's points.
fn speed_axis_top(r: &FitResult, v_max_m_per_s: Option<f64>) -> f64 {
    let range_hi = (r.friction_curve.as_ref()).map_or(0.0, |c| c.measured_range_m_per_s[1]);
    let rig_hi = (r.priors.as_ref())
        .and_then(|p| p.friction_curve.as_ref())
        .map_or(0.0, |c| {
            c.points.iter().map(|p| p.speed_m_per_s).fold(0.0, f64::max)
        });
    (v_max_m_per_s.map_or(0.2, |v| 1.05 * v))
        .max(1.1 * range_hi)
        .max(1.05 * rig_hi)
}

/// The summary's line on the truth's own cost and the fit's distance from it, in the true model
/// when the result priced the truth there (empty without a truth's cost).
fn truth_line(r: &FitResult) -> String {
    let (Some(t), Some(short)) = (r.truth_cost, r.shortfall_nats()) else {
        return String::new();
    };
    let (whose, fit) = match r.truth_model {
        Some(m) => (format!(" (in the true model, {m})"), " of that model"),
        None => (String::new(), ""),
    };
    format!(
        "  truth's own cost{whose} {t:.2} nats: the fit{fit} is {:.2} nats {} likely than the truth{}{}\n",
        short.abs(),
        if short > 0.0 { "less" } else { "more" },
        truth_tolerance_words(r, short),
        averaged_shortfall_words(r)
    )
}

/// Where either side's cost jitters by more than [`crate::fit::SHORTFALL_TOLERANCE_NATS`], the
/// fit's distance from the truth with each cost averaged over its rounding draws
/// ([`FitResult::averaged_shortfall_nats`]); empty otherwise.
fn averaged_shortfall_words(r: &FitResult) -> String {
    let rough = |t: &Option<crate::fit::tolerance::ToleranceCheck>| {
        (t.as_ref().and_then(|t| t.jitter.as_ref()))
            .is_some_and(|j| j.sd_nats > crate::fit::SHORTFALL_TOLERANCE_NATS)
    };
    let Some(short) = r.averaged_shortfall_nats() else {
        return String::new();
    };
    if !(rough(&r.tolerance_check) || rough(&r.truth_tolerance)) {
        return String::new();
    }
    let verdict = if short > crate::fit::SHORTFALL_TOLERANCE_NATS {
        ": by the averaged cost the search stopped short, on a draw that suits the recording"
    } else {
        ""
    };
    format!(
        "; averaged over their rounding draws the fit is {:.2} nats {} likely than the truth{verdict}",
        short.abs(),
        if short > 0.0 { "less" } else { "more" },
    )
}

/// What the truth's own tolerance check says of the comparison: the truth's costs at the probed
/// tolerances and, when they spread by more than the fit's distance from the truth, that the
/// integrator does not tell the two apart (empty without the check).
fn truth_tolerance_words(r: &FitResult, short: f64) -> String {
    let Some(tc) = r.truth_tolerance.as_ref().filter(|t| t.probed()) else {
        return String::new();
    };
    let (costs, rtols) = tolerance_lists(tc);
    let verdict = if tc.spread_nats > short.abs() {
        ": wider than the gap, so the integrator does not tell the fit from the truth"
    } else {
        ""
    };
    let jitter = tc.jitter.as_ref().map_or(String::new(), |j| {
        let wider = if j.sd_nats > short.abs() {
            ", more than the gap"
        } else {
            ""
        };
        format!(
            "; it jitters by {:.2} nats under steps of {:e}{wider}",
            j.sd_nats, j.step_u
        )
    });
    format!(
        " (the truth costs {costs} nats at rtol {rtols}, {:.2} apart{verdict}{jitter})",
        tc.spread_nats
    )
}

/// A tolerance check's costs (nats, two decimals) and tolerances, each as a comma-separated list.
fn tolerance_lists(t: &crate::fit::tolerance::ToleranceCheck) -> (String, String) {
    let costs: Vec<String> = (t.points.iter())
        .map(|p| format!("{:.2}", p.cost_nats))
        .collect();
    let rtols: Vec<String> = t.points.iter().map(|p| format!("{:e}", p.rtol)).collect();
    (costs.join(", "), rtols.join(", "))
}

/// Widening factors below this are not worth a summary line: the rounding's share of the 1σ is
/// then within the spread's own sampling error over the noise replicates.
const WIDENING_WORTH_SAYING: f64 = 1.05;

/// The drive in one line: the blade file's, the second harmonic the fit used, and what the tracked
/// head shows (docs/fit.md, "The drive").
pub(super) fn drive_line(d: &crate::model::drive::DriveCheck) -> String {
    let r = &d.reading;
    let sig = |v: f64| crate::names::significant(v, 3);
    format!(
        "v = a(1 − cos ωt) + (h·a/2)·sin 2ωt, blade file a = {} mm, h = {}; the fit used h = {}; \
         the tracked head shows a = {} ± {} mm, h = {} ± {}, clock offset {} ± {} µs",
        sig(1e3 * d.blade_amplitude_m),
        sig(d.blade_speed_harmonic),
        sig(d.fitted_speed_harmonic),
        sig(1e3 * r.amplitude_m),
        crate::names::significant(1e3 * r.amplitude_se_m, 2),
        sig(r.speed_harmonic),
        crate::names::significant(r.speed_harmonic_se, 2),
        sig(1e6 * r.clock_offset_s),
        crate::names::significant(1e6 * r.clock_offset_se_s, 2),
    )
}

/// The summary's line on how much the rounding's draws widen each parameter's 1σ
/// (`rounding_widening`), when any does by [`WIDENING_WORTH_SAYING`] or more.
pub(super) fn rounding_widening_words(params: &[crate::estimate::FittedParam]) -> Option<String> {
    let wide: Vec<String> = params
        .iter()
        .filter_map(|p| Some((p.name, p.rounding_widening?)))
        .filter(|(_, w)| *w >= WIDENING_WORTH_SAYING)
        .map(|(name, w)| format!("{name} ×{w:.2}"))
        .collect();
    (!wide.is_empty()).then(|| {
        format!(
            "the rounding's draws of the slip's onset widen the 1σ: {} (docs/uncertainty.md, \"Jitter\")",
            wide.join(", ")
        )
    })
}

/// The summary's line on `[fit.priors]`: the prior's share of the cost and how far the fit lies
/// from each prior, in the prior's standard deviations (empty without priors).
fn prior_lines(r: &FitResult) -> String {
    let Some(p) = &r.priors else {
        return String::new();
    };
    let mut terms: Vec<String> = (p.parameters.iter())
        .map(|q| format!("{} z {:+.2}", q.name, q.z))
        .collect();
    if let Some(c) = &p.friction_curve {
        let worst = c.points.iter().map(|q| q.z.abs()).fold(0.0, f64::max);
        terms.push(format!(
            "rig curve {} points, largest |z| {worst:.2}",
            c.points.len()
        ));
    }
    format!(
        "  priors: {:.2} nats of the cost; {} (z: the fit's distance from each prior in its \
         standard deviations; |z| > 2: the recording disagrees with it)\n",
        p.nats_at_fit,
        terms.join(", ")
    )
}

/// The rig curve of `[fit.priors.friction_curve]` as points with ±1σ error bars, added to `series`
/// and `opts`; the lowest and highest ends of its bars, when there is one.
fn rig_points(
    rig: Option<&crate::likelihood::prior::RigCurveReport>,
    series: &mut Vec<Series>,
    opts: &mut ChartOpts,
) -> Option<(f64, f64)> {
    let c = rig?;
    let name = c.file.file_name().map(|n| n.to_string_lossy().into_owned());
    series.push(Series::points(
        format!(
            "rig curve μ ± 1σ, the prior on μ_d ({})",
            name.unwrap_or_default()
        ),
        c.points.iter().map(|p| p.speed_m_per_s).collect(),
        c.points.iter().map(|p| p.coefficient).collect(),
    ));
    opts.error_bars.push(super::plot::ErrorBars {
        x: c.points.iter().map(|p| p.speed_m_per_s).collect(),
        y: c.points.iter().map(|p| p.coefficient).collect(),
        sd: c.points.iter().map(|p| p.sd).collect(),
        series: series.len() - 1,
    });
    let lo = c
        .points
        .iter()
        .map(|p| p.coefficient - p.sd)
        .fold(f64::INFINITY, f64::min);
    let hi = (c.points.iter())
        .map(|p| p.coefficient + p.sd)
        .fold(f64::NEG_INFINITY, f64::max);
    (lo <= hi).then_some((lo, hi))
}

/// The friction figure's μ axis: the curve, its band and the truth over the measured range, with
/// half their span (at least 0.01) above and below, so that the band is seen; the extrapolation
/// leaves the box where it climbs to μ_s.
fn measured_y_range(c: &crate::model::friction_curve::FrictionCurve) -> (f64, f64) {
    let values = (c.mu_d.iter().copied())
        .chain(c.band_edges().into_iter().flatten().flatten())
        .chain(c.mu_d_true.iter().copied())
        .chain(c.mu_d_envelope.iter().flatten().copied())
        .filter(|v| v.is_finite());
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let pad = (0.5 * (hi - lo)).max(0.01);
    (lo - pad, hi + pad)
}

const FRICTION_X_LABEL: &str = "slip speed |v̇3| [m/s]";
const FRICTION_Y_LABEL: &str = "dynamic friction coefficient μ_d [-]";

/// The friction figure's title: the law, and whether the ±1σ band is drawn and, when not, why (no
/// coefficient of the law was fitted, or their 1σ or correlations are not finite: the curvature
/// was not positive definite).
fn friction_title(r: &FitResult, law: &FrictionLaw, band: bool) -> String {
    let head = format!("dynamic friction coefficient μ_d(|v|), law {}", law.name());
    let fitted = law
        .mu_slip_gradient(0.0)
        .iter()
        .any(|(id, _)| r.parameters.iter().any(|p| p.name == *id));
    match (band, fitted) {
        (true, _) => format!("{head}, 68 % band from the fit"),
        (false, true) => format!("{head}; no ±1σ: the coefficients' covariance is not finite"),
        (false, false) => format!("{head}; no ±1σ: no coefficient of the law was fitted"),
    }
}

/// Writes `cost.svg`: best cost against the restart's own model evaluations, one series per restart
/// and stage (the restarts run in parallel, each from its own swarm). With the likelihood
/// objective the swarm ranks by the feature cost (unless `[fit.search] swarm_cost =
/// "likelihood"`) and the polish by the NLL above the saturated model (nats), so the stages are
/// separate series and the axis names what each reads.
fn cost_figure(
    dir: &Path,
    history: &[HistoryPoint],
    objective: Objective,
    swarm_cost: SwarmCost,
) -> Result<()> {
    let by_features = swarm_cost == SwarmCost::Features;
    let restarts = history.iter().map(|h| h.restart + 1).max().unwrap_or(0);
    let split = objective == Objective::Likelihood;
    let stages: &[Option<SearchStage>] = if split {
        &[
            Some(SearchStage::Swarm),
            Some(SearchStage::Local),
            Some(SearchStage::Polish),
            Some(SearchStage::SignalLocal),
            Some(SearchStage::SignalPolish),
            Some(SearchStage::Cmaes),
        ]
    } else {
        &[None]
    };
    let series: Vec<Series> = (0..restarts.max(1))
        .flat_map(|r| stages.iter().map(move |st| (r, *st)))
        .map(|(r, st)| {
            let (it, c): (Vec<f64>, Vec<f64>) = history
                .iter()
                .filter(|h| h.restart == r && st.is_none_or(|s| h.stage == s))
                .map(|h| (h.evaluations as f64, h.best_cost))
                .unzip();
            let what = match st {
                Some(SearchStage::Swarm) if by_features => "swarm, feature cost",
                Some(SearchStage::Swarm) => "swarm, nats",
                Some(SearchStage::Local) => "local CMA-ES, nats",
                Some(SearchStage::Polish) => "Nelder–Mead, nats",
                Some(SearchStage::SignalLocal) => "local CMA-ES on the signal alone, nats",
                Some(SearchStage::SignalPolish) => "Nelder–Mead after it, nats",
                Some(SearchStage::Cmaes) => "CMA-ES",
                None => "search",
            };
            let label = if st == Some(SearchStage::Cmaes) {
                format!("CMA-ES run {}", r + 1)
            } else if restarts > 1 {
                format!("restart {} ({what})", r + 1)
            } else {
                format!("best cost ({what})")
            };
            Series::line(label, it, c)
        })
        .filter(|s| !s.x.is_empty())
        .collect();
    let y_label = if split && by_features {
        "best cost (swarm: feature cost [-]; polish: NLL above saturated [nats])"
    } else if split {
        "best cost (NLL above saturated [nats])"
    } else {
        "best cost [-]"
    };
    line_chart(
        &dir.join("cost.svg"),
        "best cost against model evaluations",
        "model evaluations of the restart [count]",
        y_label,
        &series,
        &ChartOpts {
            log_y: true,
            ..ChartOpts::default()
        },
    )
}

/// Writes the `spectrum` command's numbers into `dir`: `psd.csv` (`f_hz`, then
/// `<signal>_psd_m2_per_hz` per signal, `<signal>_power_spectrum_m2` with `scaling = spectrum`:
/// the full one-sided Welch estimate of the first band's
/// settings; signals whose bins differ from the first signal's are left out) and `peaks.json` (an
/// array of `{signal, band, freq_hz, psd_m2_per_hz, prominence}`, one per band with a peak).
/// Returns the file names.
///
/// # Errors
/// [`Error::Io`] naming the file.
pub fn spectrum_data_files(dir: &Path, signals: &[(String, Features)]) -> Result<Vec<String>> {
    let Some((_, first)) = signals.first() else {
        return Ok(Vec::new());
    };
    let f_hz = &first.bands[0].full_freq_hz;
    // The column's quantity and unit follow the Welch scaling.
    let quantity = match first.bands[0].spec.scaling {
        crate::spectrum::Scaling::Density => "psd_m2_per_hz",
        crate::spectrum::Scaling::Spectrum => "power_spectrum_m2",
    };
    let names: Vec<String> = signals
        .iter()
        .map(|(n, _)| format!("{n}_{quantity}"))
        .collect();
    let mut cols: Vec<(&str, &[f64])> = vec![("f_hz", f_hz)];
    for ((_, f), n) in signals.iter().zip(&names) {
        if &f.bands[0].full_freq_hz == f_hz {
            cols.push((n, &f.bands[0].full_psd));
        }
    }
    let mut files = vec![write_columns(dir, "psd.csv", &cols)?];
    let peaks: Vec<serde_json::Value> = signals
        .iter()
        .flat_map(|(n, f)| {
            f.bands.iter().filter_map(move |b| {
                b.peak.map(|p| {
                    serde_json::json!({
                        "signal": n,
                        "band": b.spec.name,
                        "freq_hz": p.freq_hz,
                        quantity: p.level,
                        "prominence": if p.prominence.is_finite() { Some(p.prominence) } else { None },
                    })
                })
            })
        })
        .collect();
    let path = dir.join("peaks.json");
    let text = serde_json::to_string_pretty(&peaks)
        .map_err(|e| Error::io(&path, "cannot encode", std::io::Error::other(e)))?;
    crate::io::write_atomic(&path, (text + "\n").as_bytes())?;
    files.push("peaks.json".into());
    Ok(files)
}

/// Writes one CSV into `dir` from named columns of equal length (NaN written as `NaN`).
fn write_columns(dir: &Path, name: &str, columns: &[(&str, &[f64])]) -> Result<String> {
    let path = dir.join(name);
    let fail = |e: csv::Error| Error::io(&path, "cannot write", std::io::Error::other(e));
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(columns.iter().map(|c| c.0)).map_err(fail)?;
    let rows = columns.iter().map(|c| c.1.len()).min().unwrap_or(0);
    for i in 0..rows {
        w.write_record(columns.iter().map(|c| format!("{:e}", c.1[i])))
            .map_err(fail)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::io(&path, "cannot write", e.into_error()))?;
    crate::io::write_atomic(&path, &bytes)?;
    Ok(name.to_string())
}

/// Writes the fit's numbers behind its figures as CSV into `dir` and returns the file names:
/// `psd_<band>.csv` (`freq_hz`, `psd_measured_m2_per_hz` when there is a recording,
/// `psd_model_m2_per_hz`; Welch one-sided density inside the band, measured and model on the same
/// bins), `traces_measured.csv` (`t_s`, the job's signal in m, `head_y_m`; absent for a target
/// job), `traces_model.csv` (`t_s`, the signal in m, `head_y_m` = −u) and, when the fitted model
/// slips, `friction_curve.csv` ([`friction_curve_csv`]). Values as the fit computed them (no
/// means removed).
///
/// # Errors
/// [`Error::Io`] naming the file; [`crate::spectrum::SpectrumError`] if the signal cannot be extracted.
pub fn fit_data_files(dir: &Path, o: &FitOutcome) -> Result<Vec<String>> {
    let mut files = Vec::new();
    let targets_only = o.measured_trace.points.is_empty();
    for (d, m) in o.measured.bands.iter().zip(&o.model.bands) {
        let name = format!("psd_{}.csv", d.spec.name);
        let same_bins = d.freq_hz == m.freq_hz;
        files.push(if targets_only || !same_bins {
            let cols: [(&str, &[f64]); 2] =
                [("freq_hz", &m.freq_hz), ("psd_model_m2_per_hz", &m.psd)];
            write_columns(dir, &name, &cols)?
        } else {
            let cols: [(&str, &[f64]); 3] = [
                ("freq_hz", &d.freq_hz),
                ("psd_measured_m2_per_hz", &d.psd),
                ("psd_model_m2_per_hz", &m.psd),
            ];
            write_columns(dir, &name, &cols)?
        });
    }
    let signal_col = format!(
        "{}_m",
        serde_json::to_value(o.signal)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_else(|| "signal".into())
    );
    if !targets_only {
        let sig = o.signal.extract(&o.measured_trace)?;
        let head: Vec<f64> = o
            .measured_trace
            .role(Role::Head)
            .map(|p| p.y_m.clone())
            .unwrap_or_else(|| vec![f64::NAN; sig.len()]);
        let cols: [(&str, &[f64]); 3] = [
            ("t_s", &o.measured_trace.t_s),
            (&signal_col, &sig),
            ("head_y_m", &head),
        ];
        files.push(write_columns(dir, "traces_measured.csv", &cols)?);
    }
    let sig = o.signal.extract(&o.best_sim.to_trace())?;
    let head: Vec<f64> = o.best_sim.u_m.iter().map(|u| -u).collect();
    let cols: [(&str, &[f64]); 3] = [
        ("t_s", &o.best_sim.t_s),
        (&signal_col, &sig),
        ("head_y_m", &head),
    ];
    files.push(write_columns(dir, "traces_model.csv", &cols)?);
    if let Some(c) = &o.result.friction_curve {
        files.push(friction_curve_csv(dir, c)?);
    }
    Ok(files)
}

/// Writes `friction_curve.csv`: the fitted law on the measured slip-speed range, `speed_m_per_s`,
/// `mu_d`, then `mu_d_sigma` (1σ by the delta method) and the band's edges `mu_d_lo`, `mu_d_hi`
/// (±1σ, widened to the evaluated points as likely as the fit) when the fit gives a band,
/// `mu_d_envelope_lo`, `mu_d_envelope_hi` when models the recording does not distinguish give an
/// envelope, and `mu_d_true` when the truth is known.
fn friction_curve_csv(
    dir: &Path,
    c: &crate::model::friction_curve::FrictionCurve,
) -> Result<String> {
    let band = c.band_edges();
    let envelope = c.envelope_edges();
    let mut cols: Vec<(&str, &[f64])> =
        vec![("speed_m_per_s", &c.speed_m_per_s), ("mu_d", &c.mu_d)];
    if let Some([lo, hi]) = &band {
        cols.extend([
            ("mu_d_sigma", c.mu_d_sigma.as_slice()),
            ("mu_d_lo", lo),
            ("mu_d_hi", hi),
        ]);
    }
    if let Some([lo, hi]) = &envelope {
        cols.extend([
            ("mu_d_envelope_lo", lo.as_slice()),
            ("mu_d_envelope_hi", hi),
        ]);
    }
    if !c.mu_d_true.is_empty() {
        cols.push(("mu_d_true", &c.mu_d_true));
    }
    write_columns(dir, "friction_curve.csv", &cols)
}

/// Writes `freq_vs_speed.svg` into `dir`: ridge and stick-onset rate against the tip's mean speed
/// (mm/s), measurement and model on one chart, frequency axis limited to the comparison's band
/// (computed upstream by [`crate::likelihood::instfreq::compare_freq_speed`]).
///
/// # Errors
/// [`Error::Io`]/[`super::ReportError`] from drawing.
pub fn freq_vs_speed_figure(dir: &Path, c: &FreqSpeedComparison) -> Result<()> {
    let band_hz = c.band_hz;
    let xy = |p: &[FreqSpeedPoint]| -> (Vec<f64>, Vec<f64>) {
        p.iter()
            .filter(|q| q.freq_hz >= band_hz.0 && q.freq_hz <= band_hz.1)
            .map(|q| (q.speed_m_per_s * 1e3, q.freq_hz))
            .unzip()
    };
    let mut series = Vec::new();
    for (label, pts) in [
        ("measured: spectrogram ridge", &c.measured.ridge),
        ("model: spectrogram ridge", &c.model.ridge),
        ("measured: 1/stick-onset interval", &c.measured.onsets),
        ("model: 1/stick-onset interval", &c.model.onsets),
    ] {
        let (x, y) = xy(pts);
        series.push(Series::points(label, x, y));
    }
    line_chart(
        &dir.join("freq_vs_speed.svg"),
        &format!(
            "instantaneous frequency against lip-tip speed ({:.0}–{:.0} Hz)",
            band_hz.0, band_hz.1
        ),
        "mean lip-tip speed |Δv3|/Δt [mm/s]",
        "frequency [Hz]",
        &series,
        &ChartOpts::default(),
    )
}

/// A human-readable summary of a fit result.
pub fn fit_summary(r: &FitResult) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "fit '{}': cost {:.4}, {} model evaluations ({} failed), {} swarm + {} polish iterations, {:.1} s on {} threads (rtol {:e})",
        r.job,
        r.cost,
        r.model_evaluations,
        r.failed_evaluations,
        r.swarm_iterations,
        r.polish_iterations,
        r.wall_time_s,
        r.threads,
        r.solver_rtol
    );
    let _ = writeln!(
        s,
        "  {:<6} {:>14} {:>12} {:>14} {:>10}  determined",
        "param", "fitted", "± 1σ", "true", "rel err"
    );
    for p in &r.parameters {
        let _ = writeln!(
            s,
            "  {:<6} {:>14.6e} {:>12.3e} {:>14} {:>10}  {}",
            p.name,
            p.value,
            p.std_error,
            p.true_value
                .map(|t| format!("{t:.6e}"))
                .unwrap_or_else(|| "-".into()),
            p.rel_error
                .map(|e| format!("{:+.2}%", 100.0 * e))
                .unwrap_or_else(|| "-".into()),
            if p.determined { "yes" } else { "NO" }
        );
    }
    for pk in &r.peaks {
        let _ = writeln!(
            s,
            "  peak {:<5} measured {:>9.3} Hz  model {:>9.3} Hz  ({:+.2}%)",
            pk.band,
            pk.measured_hz,
            pk.model_hz,
            100.0 * pk.rel_diff
        );
    }
    if let Some(g) = &r.goodness_of_fit {
        let _ = writeln!(
            s,
            "  goodness of fit: excess NLL {:.2} nats, noise replicates of the fit {:.2} ± {:.2} (p = {:.3}: {})",
            g.excess_nll_nats,
            g.replicate_mean_nats,
            g.replicate_sd_nats,
            g.p_value,
            if g.fits() {
                "the model explains the spectra to their noise"
            } else {
                "the spectra hold more than the model and noise"
            }
        );
    }
    if let Some(t) = &r.tolerance_check {
        use crate::fit::tolerance::Verdict;
        let (costs, rtols) = tolerance_lists(t);
        let _ = writeln!(
            s,
            "  tolerance check: cost {costs} nats at rtol {rtols} ({:.2} nats apart: {})",
            t.spread_nats,
            match t.verdict() {
                Verdict::Resolved => "resolved by the integrator",
                Verdict::NotProbed => "no probe ran, see the warning",
                Verdict::Unresolved => "not resolved, see the warning",
            }
        );
        if let (Some(j), Some(at)) = (&t.jitter, t.points.first()) {
            let _ = writeln!(
                s,
                "  cost jitter: {:.3} nats (standard deviation) under steps of {:e} at rtol {:e}",
                j.sd_nats, j.step_u, at.rtol
            );
        }
    }
    if let Some(w) = rounding_widening_words(&r.parameters) {
        let _ = writeln!(s, "  {w}");
    }
    if let Some(d) = &r.drive {
        let _ = writeln!(s, "  drive: {}", drive_line(d));
    }
    if let Some(n) = &r.tracking_noise {
        let _ = writeln!(
            s,
            "  tracking noise ({}): σ {:.3e} m, lag-one correlation ρ {:.2}",
            n.spectrum, n.sigma_m, n.rho
        );
        for j in &n.joint {
            let _ = writeln!(
                s,
                "  joint signal {} (read through the cross-spectra): tracking noise σ {:.3e} m, ρ {:.2}",
                j.signal, j.sigma_m, j.rho
            );
        }
    }
    s.push_str(&truth_line(r));
    s.push_str(&prior_lines(r));
    if !r.undetermined.is_empty() {
        let _ = writeln!(
            s,
            "  warning: the data leave {} undetermined (flat cost in that direction; see the correlation matrix)",
            crate::names::join(&r.undetermined, ", ")
        );
    }
    if let Some(f) = &r.first_failure {
        let _ = writeln!(
            s,
            "  note: {} evaluations failed; first: {f}",
            r.failed_evaluations
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::{drive_line, friction_law_figure};
    use crate::model::friction_curve::{FrictionCurve, Spread};
    use crate::model::{FrictionLaw, ParamId};

    /// The drive line reads the result's numbers: dep_009's drive departure as its fit read it
    /// (h −0.043624 ± 6.9e-7 against the blade file's 0; docs/validation.md, "The drive read from
    /// the head").
    #[test]
    fn the_drive_line_gives_the_blade_files_drive_and_the_heads() {
        let reading = crate::model::drive::DriveReading {
            amplitude_m: 0.100_000_006,
            amplitude_se_m: 4.2e-8,
            speed_harmonic: -0.043_624,
            speed_harmonic_se: 6.9e-7,
            clock_offset_s: 2.6e-8,
            clock_offset_se_s: 2.1e-7,
            residual_rms_m: 2.4e-6,
            residual_lag_one: 0.0,
            samples: 33_953,
        };
        let check = crate::model::drive::DriveCheck {
            reading,
            blade_amplitude_m: 0.1,
            blade_speed_harmonic: 0.0,
            fitted_speed_harmonic: 0.0,
        };
        let line = drive_line(&check);
        assert!(
            line.contains("blade file a = 100 mm, h = 0; the fit used h = 0"),
            "{line}"
        );
        assert!(line.contains("h = -0.0436 ± 6.9e-7"), "{line}");
        assert!(line.contains("clock offset 0.026 ± 0.21 µs"), "{line}");
    }

    const LAW: FrictionLaw = FrictionLaw::Exponential {
        a: 0.8,
        b_s_per_m: 10.0,
        c: 0.2,
    };

    /// The figure of a hand-built curve (slip speeds 0–0.1 m/s, A and C fitted, a viscous truth):
    /// it exists and names the measured range, the band's method, the extrapolation, the truth
    /// with its rms difference, the axes, and the dashed legend sample; without a fitted
    /// coefficient the title says there is no band.
    #[test]
    fn the_rounding_line_names_the_parameters_it_widens_and_only_those() {
        use crate::estimate::FittedParam;
        use crate::model::ParamId;
        let param = |name, w| FittedParam {
            name,
            value: 1.0,
            lower: 0.0,
            upper: 2.0,
            std_error: 0.1,
            fisher_std_error: None,
            rounding_widening: w,
            determined: true,
            true_value: None,
            rel_error: None,
            interval: None,
        };
        let calm = [param(ParamId::A, Some(1.01)), param(ParamId::B, None)];
        assert_eq!(super::rounding_widening_words(&calm), None);
        let rough = [
            param(ParamId::A, Some(2.5)),
            param(ParamId::B, Some(1.0)),
            param(ParamId::C, Some(1.05)),
        ];
        let line = super::rounding_widening_words(&rough).expect("two parameters widen");
        assert!(line.contains("A ×2.50, C ×1.05"), "{line}");
        assert!(!line.contains('B'), "{line}");
    }

    #[test]
    fn a_fit_on_a_lucky_rounding_draw_is_short_by_the_averaged_cost() {
        use crate::fit::tolerance::ToleranceCheck;
        use crate::search::jitter::RoundingJitter;
        // A lucky draw: the optimum's own cost below the truth's, its draws' mean far above
        // (docs/validation.md, "Jitter", has searches that ended on such draws).
        let check = |costs: Vec<f64>| ToleranceCheck {
            points: Vec::new(),
            spread_nats: 0.0,
            failed: Vec::new(),
            jitter: RoundingJitter::of(costs),
        };
        let mut r = crate::report::html::tests::result();
        r.cost = 43.0;
        r.truth_cost = Some(43.5);
        r.tolerance_check = Some(check(vec![43.0, 60.0, 62.0]));
        r.truth_tolerance = Some(check(vec![43.5, 45.0, 46.0]));
        // Means 55 and 44.83: 10.17 nats short by the averaged cost.
        let short = r.averaged_shortfall_nats().unwrap();
        assert!((short - (55.0 - 134.5 / 3.0)).abs() < 1e-12, "{short}");
        let line = super::truth_line(&r);
        assert!(
            line.contains("the fit is 0.50 nats more likely than the truth"),
            "{line}"
        );
        assert!(
            line.contains("averaged over their rounding draws the fit is 10.17 nats less likely than the truth: by the averaged cost the search stopped short"),
            "{line}"
        );
        // Where neither side jitters, the line says nothing of the draws.
        r.tolerance_check = Some(check(vec![43.0, 43.0, 43.0]));
        r.truth_tolerance = Some(check(vec![43.5, 43.5, 43.5]));
        assert!(!super::truth_line(&r).contains("averaged"));
        // Nor where the truth is read in another model than the chosen one.
        r.truth_model = "head1dof".parse().ok();
        assert_eq!(r.averaged_shortfall_nats(), None);
    }

    #[test]
    fn the_friction_figure_draws_the_measured_range_band_extrapolation_and_truth() {
        let dir = tempfile::tempdir().unwrap();
        let mut r = crate::report::html::tests::result();
        let speeds: Vec<f64> = (0..=100).map(|i| i as f64 * 0.001).collect();
        let truth = FrictionLaw::ExponentialViscous {
            a: 0.8,
            b_s_per_m: 10.0,
            c: 0.2,
            d_s_per_m: 0.5,
        };
        let spread = Spread {
            ids: &[ParamId::A, ParamId::C],
            sigma: &[0.02, 0.01],
            corr: &[vec![1.0, 0.0], vec![0.0, 1.0]],
        };
        r.parameters.truncate(0);
        r.friction_curve = FrictionCurve::new(LAW, &speeds, Some(spread), Some(truth));
        for (name, fitted) in [("A", 0.8), ("C", 0.2)] {
            let mut p = crate::report::html::tests::result().parameters[0].clone();
            p.name = name.parse().unwrap();
            p.value = fitted;
            r.parameters.push(p);
        }
        friction_law_figure(dir.path(), &r, &LAW, Some(0.167)).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("friction_law.svg")).unwrap();
        let rms = r
            .friction_curve
            .as_ref()
            .unwrap()
            .rms_rel_diff_to_truth
            .unwrap();
        for label in [
            "fitted μ_d over the measured range (10th–90th percentile of slip speeds)",
            "measured slip speeds 10.0–90.0 mm/s",
            "±1σ by the delta method from the fitted covariance",
            "fitted law outside the range: extrapolation",
            &format!(
                "true μ_d (exponential_viscous; fitted lies {:.1} % rms from it over the range)",
                100.0 * rms
            ),
            "slip speed |v̇3| [m/s]",
            "dynamic friction coefficient μ_d [-]",
            "law exponential, 68 % band from the fit",
            "stroke-dasharray",
        ] {
            assert!(svg.contains(label), "no {label:?} in the figure");
        }
        assert!(!svg.contains("does not distinguish"));
        // A law the recording does not distinguish: the envelope is drawn and named.
        let curve = r.friction_curve.clone();
        r.friction_curve = (curve.clone()).map(|c| {
            let other = c.alternative(truth, None, &[], &[]);
            c.with_alternatives(&[other])
        });
        friction_law_figure(dir.path(), &r, &LAW, Some(0.167)).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("friction_law.svg")).unwrap();
        assert!(svg.contains("with the 1 model(s) the recording does not distinguish"));
        // The truth among the points the search evaluated within the rise limit: the band's
        // legend says that it was widened.
        let limits = [0.5; crate::model::friction_curve::CURVE_POINTS];
        r.friction_curve = curve
            .clone()
            .map(|c| c.with_near_best(&[(0.2, truth)], &limits));
        friction_law_figure(dir.path(), &r, &LAW, Some(0.167)).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("friction_law.svg")).unwrap();
        assert!(svg.contains(
            "±1σ by the delta method, widened to the evaluated points as likely as the fit"
        ));
        r.friction_curve = curve;
        // A rig curve: its points in the legend, each with a whisker and two caps.
        let lines = |svg: &str| svg.matches("<polyline").count();
        let before = lines(&svg);
        let point = |v: f64, mu: f64| crate::likelihood::prior::RigPointReport {
            speed_m_per_s: v,
            coefficient: mu,
            sd: 0.02,
            mu_d_fit: LAW.mu_slip(v),
            z: 0.0,
        };
        r.priors = Some(crate::likelihood::prior::PriorsReport {
            nats_at_fit: 0.0,
            parameters: Vec::new(),
            friction_curve: Some(crate::likelihood::prior::RigCurveReport {
                file: "data/rig.csv".into(),
                points: vec![point(0.03, 0.75), point(0.06, 0.6)],
            }),
        });
        friction_law_figure(dir.path(), &r, &LAW, Some(0.167)).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("friction_law.svg")).unwrap();
        assert!(svg.contains("rig curve μ ± 1σ, the prior on μ_d (rig.csv)"));
        assert_eq!(lines(&svg), before + 6, "two whiskers, four caps");
        assert!(
            crate::report::figures::fit_summary(&r).contains(
                "  priors: 0.00 nats of the cost; rig curve 2 points, largest |z| 0.00 (z:"
            ),
            "{}",
            crate::report::figures::fit_summary(&r)
        );
        r.priors = None;
        assert!(!crate::report::figures::fit_summary(&r).contains("priors:"));
        r.parameters.clear();
        r.friction_curve = FrictionCurve::new(LAW, &speeds, None, None);
        friction_law_figure(dir.path(), &r, &LAW, None).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("friction_law.svg")).unwrap();
        assert!(svg.contains("no ±1σ: no coefficient of the law was fitted"));
        assert!(!svg.contains("true μ_d"));
    }
}
