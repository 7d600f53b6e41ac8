//! `wiperlab bench`: work–precision of the simulation methods.
//!
//! Every method runs over a range of tolerances or steps on two problems, and is compared with a
//! tight-tolerance event-driven reference (rtol 1e-13, checked against closed forms and an
//! independent RK4 + Hénon solution to ~1e-12 in `tests/suite/stick_slip_benchmarks.rs`):
//! - `belt`: Leine's block on a belt (physics.md §3.3) from stick at x = 0 over 30 s (2.5 cycles);
//!   observable x.
//! - `blade-burst`: the default blade (`data/reversal/blade_true.toml`) from its first stick onset
//!   before the reversal, over 20 ms of stick–slip; observable the lip-tip position v3.
//! - `blade-window`: the whole default reversal window `[π/2, 3π/2]/ω` (1.887 s), event-driven only.
//!   Its first stick onset comes out of the slow loss of stability of quasi-static slip, whose delay is
//!   set by how large the integration error is; transition times there do not converge with the
//!   tolerance (they differ by ~1e-3 s even between rtol 1e-13 and 1e-14). The row measures the cost.
//!
//! Errors: the largest difference between a reference transition and the nearest transition of the
//! same kind (from → to) in the method's run, and the largest difference of the observable at the
//! sample times. Cost: wall time (mean over repeats of at least 0.2 s, `--quick`: 0.05 s) and
//! right-hand-side evaluations (for Moreau–Jean: one linear contact solve per step).

use crate::model::benchmarks::{CoulombBelt, leine_belt};
use crate::model::{Blade, BladeParams, StickForm};
use crate::report::plot::{ChartOpts, Series, line_chart};
use crate::simulate::Method;
use crate::simulate::blade::default_window;
use crate::simulate::hybrid::{Mode, Phase, SolverOptions, StickSlipModel, integrate};
use crate::simulate::timestep::{NonsmoothModel, Trajectory, moreau_jean, smoothed};
use crate::{Error, Result};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// One measured configuration.
#[derive(Debug, Clone, Serialize)]
pub struct BenchRow {
    pub problem: String,
    pub method: String,
    /// What `setting` is: `rtol`, `step_s` or `eps_m_per_s`.
    pub setting_name: String,
    pub setting: f64,
    pub wall_s: f64,
    pub rhs_evals: usize,
    pub steps: usize,
    pub transitions: usize,
    /// Largest transition-time error, s (inf: a kind of transition never happened).
    pub transition_err_s: f64,
    /// Largest error of the observable at the sample times, m.
    pub trace_err_m: f64,
    /// Empty, or why the run stopped.
    pub note: String,
}

/// Options of [`run_bench`].
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Fewer settings and shorter timing loops.
    pub quick: bool,
    /// Blade parameters for the blade problems.
    pub blade: BladeParams,
}

/// Mean wall time of `f` over repeats lasting at least `min_s` (at least one run).
fn timed<T>(min_s: f64, mut f: impl FnMut() -> T) -> (T, f64) {
    let start = Instant::now();
    let mut out = f();
    let mut n = 1;
    while start.elapsed().as_secs_f64() < min_s {
        out = f();
        n += 1;
    }
    (out, start.elapsed().as_secs_f64() / n as f64)
}

/// Largest |Δt| between each reference transition and the nearest one of the same kind in `got`.
pub fn transition_error(reference: &[(f64, Phase, Phase)], got: &[(f64, Phase, Phase)]) -> f64 {
    reference
        .iter()
        .map(|&(t, from, to)| {
            got.iter()
                .filter(|g| g.1 == from && g.2 == to)
                .map(|g| (g.0 - t).abs())
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

fn trace_error(reference: &[f64], got: &[f64]) -> f64 {
    if reference.len() != got.len() {
        return f64::INFINITY;
    }
    reference
        .iter()
        .zip(got)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// An event-driven run as a [`Trajectory`] (observable at the sample times).
fn event_driven<M, const N: usize>(
    model: &M,
    t0: f64,
    t1: f64,
    y0: [f64; N],
    mode0: Mode,
    opts: &SolverOptions,
    samples: &[f64],
) -> Result<Trajectory>
where
    M: StickSlipModel<N> + NonsmoothModel<N>,
{
    let run = integrate(model, t0, y0, mode0, t1, samples, opts)?;
    Ok(Trajectory {
        observable_m: run
            .t_s
            .iter()
            .zip(&run.y)
            .map(|(t, y)| model.observable(*t, y))
            .collect(),
        t_s: run.t_s,
        transitions: run
            .transitions
            .iter()
            .map(|tr| (tr.t_s, tr.from, tr.to))
            .collect(),
        stats: run.stats,
    })
}

fn row(
    problem: &str,
    method: &str,
    setting_name: &str,
    setting: f64,
    reference: &Trajectory,
    result: Result<(Trajectory, f64)>,
) -> BenchRow {
    match result {
        Ok((tr, wall)) => BenchRow {
            problem: problem.into(),
            method: method.into(),
            setting_name: setting_name.into(),
            setting,
            wall_s: wall,
            rhs_evals: tr.stats.rhs_evals + tr.stats.event_evals,
            steps: tr.stats.steps,
            transitions: tr.transitions.len(),
            transition_err_s: transition_error(&reference.transitions, &tr.transitions),
            trace_err_m: trace_error(&reference.observable_m, &tr.observable_m),
            note: String::new(),
        },
        Err(e) => BenchRow {
            problem: problem.into(),
            method: method.into(),
            setting_name: setting_name.into(),
            setting,
            wall_s: f64::NAN,
            rhs_evals: 0,
            steps: 0,
            transitions: 0,
            transition_err_s: f64::NAN,
            trace_err_m: f64::NAN,
            note: e.to_string(),
        },
    }
}

fn rtols(quick: bool) -> Vec<f64> {
    if quick {
        vec![1e-4, 1e-6, 1e-8, 1e-10, 1e-12]
    } else {
        (4..=12).map(|e| 10f64.powi(-e)).collect()
    }
}

fn ed_opts(rtol: f64) -> SolverOptions {
    SolverOptions {
        rtol,
        atol: rtol * 1e-2,
        ..Default::default()
    }
}

/// [`ed_opts`] with `method`.
fn ed_opts_with(rtol: f64, method: Method) -> SolverOptions {
    SolverOptions {
        method,
        ..ed_opts(rtol)
    }
}

/// The bench's name of the event-driven method with `method` ("event-driven DOPRI5", ...).
fn ed_label(method: Method) -> String {
    format!("event-driven {}", method.name().to_uppercase())
}

/// Runs the three methods on one problem (the event-driven one with each [`Method`]).
#[allow(clippy::too_many_arguments)]
fn compare<M, const N: usize>(
    problem: &str,
    model: &M,
    t0: f64,
    t1: f64,
    y0: [f64; N],
    mode0: Mode,
    samples: &[f64],
    steps_s: &[f64],
    eps: &[f64],
    quick: bool,
    rows: &mut Vec<BenchRow>,
) -> Result<()>
where
    M: StickSlipModel<N> + NonsmoothModel<N>,
{
    let min_s = if quick { 0.05 } else { 0.2 };
    let reference = event_driven(model, t0, t1, y0, mode0, &ed_opts(1e-13), samples)?;
    for &method in Method::ALL {
        for rtol in rtols(quick) {
            let o = ed_opts_with(rtol, method);
            let r = event_driven(model, t0, t1, y0, mode0, &o, samples).map(|_| {
                timed(min_s, || {
                    event_driven(model, t0, t1, y0, mode0, &o, samples).unwrap()
                })
            });
            rows.push(row(problem, &ed_label(method), "rtol", rtol, &reference, r));
        }
    }
    for &h in steps_s {
        let r = moreau_jean(model, t0, t1, y0, h, samples).map(|_| {
            timed(min_s, || {
                moreau_jean(model, t0, t1, y0, h, samples).unwrap()
            })
        });
        rows.push(row(problem, "Moreau-Jean", "step_s", h, &reference, r));
    }
    for &e in eps {
        let r = smoothed(model, e, t0, t1, y0, 1e-8, samples).map(|_| {
            timed(min_s, || {
                smoothed(model, e, t0, t1, y0, 1e-8, samples).unwrap()
            })
        });
        rows.push(row(
            problem,
            "smoothed tanh (DOPRI5 rtol 1e-8)",
            "eps_m_per_s",
            e,
            &reference,
            r,
        ));
    }
    Ok(())
}

/// The blade's state at its first stick onset in the reference run of the default window (rtol
/// 1e-13), with the time and anchor: the start of the `blade-burst` problem.
pub fn blade_burst_start(params: &BladeParams) -> Result<(f64, [f64; 4], f64)> {
    let blade = Blade::new(*params, StickForm::Reduced);
    let (t0, t1) = default_window(params);
    let y0 = blade
        .slip_equilibrium(t0)
        .map_err(|e| crate::simulate::SimulationError::at_start(t0, e))?;
    let mode = Mode {
        phase: Phase::SlipPos,
        anchor: 0.0,
        region: 0,
    };
    let run = integrate(&blade, t0, y0, mode, t1, &[], &ed_opts(1e-13))?;
    let i = run
        .transitions
        .iter()
        .position(|tr| tr.to == Phase::Stick)
        .ok_or(BenchError::NeverSticks { t0_s: t0, t1_s: t1 })?;
    let t = run.transitions[i].t_s;
    let y = run.transition_states[i];
    Ok((t, y, blade.tip_position(t, &y)))
}

/// Runs the whole study; returns the rows (also the event-order rows, problem `coulomb-fixed-step`).
pub fn run_bench(opts: &BenchOptions) -> Result<Vec<BenchRow>> {
    let quick = opts.quick;
    let mut rows = Vec::new();

    // Event location order: fixed steps on the undamped Coulomb belt (physics.md §3.1).
    rows.extend(event_order_rows()?);
    bench_belt(quick, &mut rows)?;
    bench_blade_burst(opts, &mut rows)?;
    bench_blade_window(opts, &mut rows)?;
    Ok(rows)
}

/// The `belt` problem: Leine's belt from stick at x = 0 over 30 s, all three methods.
fn bench_belt(quick: bool, rows: &mut Vec<BenchRow>) -> Result<()> {
    let belt = leine_belt();
    let samples: Vec<f64> = (0..=3000).map(|i| i as f64 * 0.01).collect();
    let steps: Vec<f64> = if quick {
        vec![1e-2, 1e-3, 1e-4]
    } else {
        vec![1e-2, 1e-3, 1e-4, 1e-5]
    };
    let eps: Vec<f64> = if quick {
        vec![1e-2, 1e-3, 1e-4]
    } else {
        vec![1e-2, 1e-3, 1e-4, 1e-5]
    };
    let stick = Mode {
        phase: Phase::Stick,
        anchor: 0.0,
        region: 0,
    };
    compare(
        "belt",
        &belt,
        0.0,
        30.0,
        [0.0, 0.2],
        stick,
        &samples,
        &steps,
        &eps,
        quick,
        rows,
    )
}

/// The `blade-burst` problem: 20 ms of stick–slip from the blade's first stick onset, all three
/// methods, then event-driven with a Baumgarte-stabilised stick.
fn bench_blade_burst(opts: &BenchOptions, rows: &mut Vec<BenchRow>) -> Result<()> {
    let quick = opts.quick;
    let blade = Blade::new(opts.blade, StickForm::Reduced);
    let (ta, ya, anchor) = blade_burst_start(&opts.blade)?;
    let tb = ta + 0.02;
    let samples: Vec<f64> = (0..=2000).map(|i| ta + i as f64 * 1e-5).collect();
    let steps: Vec<f64> = if quick {
        vec![1e-5, 1e-6]
    } else {
        vec![1e-5, 3e-6, 1e-6, 3e-7]
    };
    let eps: Vec<f64> = if quick {
        vec![1e-2, 1e-3]
    } else {
        vec![1e-2, 1e-3, 1e-4]
    };
    let mode = Mode {
        phase: Phase::Stick,
        anchor,
        region: 0,
    };
    compare(
        "blade-burst",
        &blade,
        ta,
        tb,
        ya,
        mode,
        &samples,
        &steps,
        &eps,
        quick,
        rows,
    )?;
    let baum = Blade::new(opts.blade, StickForm::Baumgarte { omega_b_per_s: 1e4 });
    let reference = event_driven(&blade, ta, tb, ya, mode, &ed_opts(1e-13), &samples)?;
    for rtol in [1e-6, 1e-8, 1e-10] {
        let r = event_driven(&baum, ta, tb, ya, mode, &ed_opts(rtol), &samples).map(|_| {
            timed(if quick { 0.05 } else { 0.2 }, || {
                event_driven(&baum, ta, tb, ya, mode, &ed_opts(rtol), &samples).unwrap()
            })
        });
        rows.push(row(
            "blade-burst",
            "event-driven DOPRI5, Baumgarte stick (omega_B 1e4/s)",
            "rtol",
            rtol,
            &reference,
            r,
        ));
    }
    Ok(())
}

/// The `blade-window` problem: the whole default reversal window, event-driven only (its cost),
/// with each [`Method`].
fn bench_blade_window(opts: &BenchOptions, rows: &mut Vec<BenchRow>) -> Result<()> {
    let quick = opts.quick;
    let blade = Blade::new(opts.blade, StickForm::Reduced);
    let (w0, w1) = default_window(&opts.blade);
    let y0 = blade
        .slip_equilibrium(w0)
        .map_err(|e| crate::simulate::SimulationError::at_start(w0, e))?;
    let slip = Mode {
        phase: Phase::SlipPos,
        anchor: 0.0,
        region: 0,
    };
    let reference = event_driven(&blade, w0, w1, y0, slip, &ed_opts(1e-13), &[])?;
    for &method in Method::ALL {
        for rtol in rtols(quick) {
            let o = ed_opts_with(rtol, method);
            let r = event_driven(&blade, w0, w1, y0, slip, &o, &[]).map(|_| {
                timed(if quick { 0.1 } else { 0.5 }, || {
                    event_driven(&blade, w0, w1, y0, slip, &o, &[]).unwrap()
                })
            });
            rows.push(row(
                "blade-window",
                &ed_label(method),
                "rtol",
                rtol,
                &reference,
                r,
            ));
        }
    }
    Ok(())
}

/// Transition-time error of the undamped Coulomb belt's first stick onset against the closed form
/// (physics.md §3.1) with fixed DOPRI5 steps `h` (tolerances loose enough to accept every step).
pub fn event_order_rows() -> Result<Vec<BenchRow>> {
    let case = CoulombBelt::ONE_HZ;
    let (belt, vb) = (case.belt(), case.v_belt_m_per_s);
    let t_onset = case.first_stick_onset_s();
    let mut rows = Vec::new();
    for h in [0.08, 0.04, 0.02, 0.01, 0.005, 0.0025] {
        let opts = SolverOptions {
            rtol: 1e6,
            atol: 1e6,
            h_max: h,
            ..Default::default()
        };
        let mode = Mode {
            phase: Phase::Stick,
            anchor: 0.0,
            region: 0,
        };
        let (run, wall) = timed(0.01, || {
            integrate(&belt, 0.0, [0.0, vb], mode, t_onset + 0.05, &[], &opts)
        });
        let run = run?;
        let te = run
            .transitions
            .iter()
            .find(|tr| tr.to == Phase::Stick)
            .map_or(f64::NAN, |tr| tr.t_s);
        rows.push(BenchRow {
            problem: "coulomb-fixed-step".into(),
            method: "event-driven DOPRI5, fixed step".into(),
            setting_name: "step_s".into(),
            setting: h,
            wall_s: wall,
            rhs_evals: run.stats.rhs_evals + run.stats.event_evals,
            steps: run.stats.steps,
            transitions: run.transitions.len(),
            transition_err_s: (te - t_onset).abs(),
            trace_err_m: f64::NAN,
            note: String::new(),
        });
    }
    Ok(rows)
}

/// Writes `rows` as a CSV file at `path` (atomically, through [`crate::io::write_atomic`]).
fn write_csv_rows<T: serde::Serialize>(path: &Path, rows: &[T]) -> Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r)
            .map_err(|e| Error::write(path.display(), "CSV", e))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::io(path, "write CSV", e.into_error()))?;
    crate::io::write_atomic(path, &bytes)
}

/// Writes `work_precision.csv` and the figures into `dir`.
pub fn write_reports(dir: &Path, rows: &[BenchRow]) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "create directory", e))?;
    let path = dir.join("work_precision.csv");
    write_csv_rows(&path, rows)?;
    work_precision_figures(dir, rows)?;
    event_order_figure(dir, rows)
}

/// Log–log axes of the work–precision figures.
fn log_log() -> ChartOpts {
    ChartOpts {
        log_x: true,
        log_y: true,
        ..Default::default()
    }
}

/// One line-and-points series per (problem, method) in first-seen order, event-order rows left
/// out: `y_of` against `x_of` over the rows whose `y_of` is finite (floored at 1e-16 for the log
/// axis); methods with no such row are dropped.
fn work_precision_series(
    rows: &[BenchRow],
    x_of: &dyn Fn(&BenchRow) -> f64,
    y_of: &dyn Fn(&BenchRow) -> f64,
) -> Vec<Series> {
    let mut keys: Vec<(String, String)> = Vec::new();
    for r in rows {
        let key = (r.problem.clone(), r.method.clone());
        if r.problem != "coulomb-fixed-step" && !keys.contains(&key) {
            keys.push(key);
        }
    }
    keys.iter()
        .map(|(p, m)| {
            let sel: Vec<&BenchRow> = rows
                .iter()
                .filter(|r| &r.problem == p && &r.method == m && y_of(r).is_finite())
                .collect();
            let mut s = Series::line(
                format!("{p}: {m}"),
                sel.iter().map(|r| x_of(r)).collect(),
                sel.iter().map(|r| y_of(r).max(1e-16)).collect(),
            );
            s.style = crate::report::plot::SeriesStyle::LinePoints;
            s
        })
        .filter(|s| !s.x.is_empty())
        .collect()
}

/// `work_precision.svg`, `work_precision_rhs.svg` and `work_precision_trace.svg`.
fn work_precision_figures(dir: &Path, rows: &[BenchRow]) -> Result<()> {
    let series = |x_of: &dyn Fn(&BenchRow) -> f64, y_of: &dyn Fn(&BenchRow) -> f64| {
        work_precision_series(rows, x_of, y_of)
    };
    line_chart(
        &dir.join("work_precision.svg"),
        "Work-precision: transition-time error vs wall time",
        "wall time per run [s]",
        "max transition-time error [s]",
        &series(&|r| r.wall_s, &|r| r.transition_err_s),
        &log_log(),
    )?;
    line_chart(
        &dir.join("work_precision_rhs.svg"),
        "Work-precision: transition-time error vs right-hand-side evaluations",
        "RHS evaluations (incl. event functions; Moreau-Jean: contact solves) [count]",
        "max transition-time error [s]",
        &series(&|r| r.rhs_evals as f64, &|r| r.transition_err_s),
        &log_log(),
    )?;
    line_chart(
        &dir.join("work_precision_trace.svg"),
        "Work-precision: trace error vs wall time",
        "wall time per run [s]",
        "max error of x (belt) / lip-tip v3 (blade) [m]",
        &series(&|r| r.wall_s, &|r| r.trace_err_m),
        &log_log(),
    )
}

/// `event_order.svg`: the `coulomb-fixed-step` rows' stick-onset error against the step, with an
/// h⁵ line through the smallest step; nothing when there are no such rows.
fn event_order_figure(dir: &Path, rows: &[BenchRow]) -> Result<()> {
    let order: Vec<&BenchRow> = rows
        .iter()
        .filter(|r| r.problem == "coulomb-fixed-step")
        .collect();
    if order.is_empty() {
        return Ok(());
    }
    let x: Vec<f64> = order.iter().map(|r| r.setting).collect();
    let y: Vec<f64> = order.iter().map(|r| r.transition_err_s).collect();
    let (x0, y0) = (x[x.len() - 1], y[y.len() - 1]);
    let slope: Vec<f64> = x.iter().map(|h| y0 * (h / x0).powi(5)).collect();
    let mut s = Series::line("DOPRI5 + event location on CONTD5", x.clone(), y);
    s.style = crate::report::plot::SeriesStyle::LinePoints;
    line_chart(
        &dir.join("event_order.svg"),
        "Stick-onset time error vs fixed step (undamped Coulomb belt, closed form)",
        "step h [s]",
        "|t_onset - closed form| [s]",
        &[s, Series::line("slope 5 (h^5)", x, slope)],
        &log_log(),
    )
}

/// Spectral peaks of the blade at one tolerance.
#[derive(Debug, Clone, Serialize)]
pub struct SpectrumRow {
    /// Which parameter file.
    pub blade: String,
    pub rtol: f64,
    pub wall_s: f64,
    pub transitions: usize,
    /// Peak frequency per band (default fit bands: low, high), Hz; NaN if none.
    pub low_peak_hz: f64,
    pub high_peak_hz: f64,
}

/// The fit's spectral peaks (src/spectrum/features.rs: default bands, signal tip − head x, Welch) of the
/// blade simulated over its default window at 10 kHz (the shipped recording's sampling), for each
/// `rtol` (atol = rtol·1e-2).
pub fn spectra_vs_rtol(
    name: &str,
    params: &BladeParams,
    rtols: &[f64],
) -> Result<Vec<SpectrumRow>> {
    use crate::fit::features::{SignalKind, default_bands, features};
    let (t0, t1) = default_window(params);
    let fs = 10_000.0;
    let n = ((t1 - t0) * fs).floor() as usize + 1;
    let times: Vec<f64> = (0..n).map(|i| t0 + i as f64 / fs).collect();
    let window = (t0, times[n - 1]);
    let bands = default_bands();
    let mut rows = Vec::new();
    for &rtol in rtols {
        let start = Instant::now();
        let sim = crate::simulate::blade::simulate_blade(
            params,
            window,
            &times,
            &ed_opts(rtol),
            StickForm::Reduced,
        )?;
        let wall = start.elapsed().as_secs_f64();
        let x = SignalKind::TipRelX.extract(&sim.to_trace())?;
        let f = features(&x, fs, &bands, 5)?;
        let peak = |i: usize| f.bands[i].peak.as_ref().map_or(f64::NAN, |p| p.freq_hz);
        rows.push(SpectrumRow {
            blade: name.into(),
            rtol,
            wall_s: wall,
            transitions: sim.transitions.len(),
            low_peak_hz: peak(0),
            high_peak_hz: peak(1),
        });
    }
    Ok(rows)
}

/// Writes `spectra_vs_rtol.csv` and `spectra_vs_rtol.svg` (relative peak deviation from the
/// tightest tolerance) into `dir`; returns the loosest rtol at which, for every blade, both peaks
/// are within `rel` of the tightest run's and the number of transitions within
/// `max_count_change` (relative) of it, with every tighter rtol also passing. (The count guard
/// exists because at loose tolerances the peaks can still sit within 0.2 % while the stick–slip
/// motion itself has changed: 216 transitions at rtol 1e-4 against 146.) A band with no peak at
/// some tolerance (NaN) passes only if the tightest run has none either.
pub fn write_spectra(
    dir: &Path,
    rows: &[SpectrumRow],
    rel: f64,
    max_count_change: f64,
) -> Result<Option<f64>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, "create directory", e))?;
    let path = dir.join("spectra_vs_rtol.csv");
    write_csv_rows(&path, rows)?;
    let mut series = Vec::new();
    let mut rtols: Vec<f64> = rows.iter().map(|r| r.rtol).collect();
    rtols.sort_by(f64::total_cmp);
    rtols.dedup();
    // For each rtol: is it, and every tighter one, within `rel` for every blade and band?
    let mut ok_all = vec![true; rtols.len()];
    for name in blade_names(rows) {
        let sel: Vec<&SpectrumRow> = rows.iter().filter(|r| r.blade == name).collect();
        let Some(conv) = sel.iter().min_by(|a, b| a.rtol.total_cmp(&b.rtol)) else {
            continue;
        };
        let n_conv = conv.transitions as f64;
        for (k, rt) in rtols.iter().enumerate() {
            let within = sel.iter().filter(|r| r.rtol == *rt).all(|r| {
                peak_devs(r, conv).iter().all(|d| *d <= rel)
                    && (r.transitions as f64 - n_conv).abs() <= max_count_change * n_conv
            });
            ok_all[k] &= within;
        }
        series.extend(deviation_series(name, &sel, conv));
    }
    spectra_figure(dir, &rtols, rel, series)?;
    Ok(loosest_passing(&rtols, &ok_all))
}

/// The distinct blade names of `rows`, in first-seen order.
fn blade_names(rows: &[SpectrumRow]) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    for r in rows {
        if !names.contains(&r.blade.as_str()) {
            names.push(&r.blade);
        }
    }
    names
}

/// Relative deviation of a peak frequency `f` from the converged `f_conv`. A band without a peak
/// (NaN: e.g. a mode at the band's edge) agrees with a run that has none either (0), and
/// disagrees completely with one that has (infinite).
fn rel_dev(f: f64, f_conv: f64) -> f64 {
    match (f.is_nan(), f_conv.is_nan()) {
        (true, true) => 0.0,
        (false, false) => ((f - f_conv) / f_conv).abs(),
        _ => f64::INFINITY,
    }
}

/// [`rel_dev`] of the low and high band peaks of `r` against the converged run `conv`.
fn peak_devs(r: &SpectrumRow, conv: &SpectrumRow) -> [f64; 2] {
    [
        rel_dev(r.low_peak_hz, conv.low_peak_hz),
        rel_dev(r.high_peak_hz, conv.high_peak_hz),
    ]
}

/// One blade's deviation series against rtol, one per band that has a peak at the tightest
/// tolerance, over the looser runs that kept the peak (floored at 1e-9 for the log axis).
fn deviation_series(name: &str, sel: &[&SpectrumRow], conv: &SpectrumRow) -> Vec<Series> {
    let mut series = Vec::new();
    let others: Vec<&&SpectrumRow> = sel.iter().filter(|r| r.rtol > conv.rtol).collect();
    for (i, band) in ["low band peak", "high band peak"].iter().enumerate() {
        // No peak at the tightest tolerance: nothing to draw a deviation from.
        if [conv.low_peak_hz, conv.high_peak_hz][i].is_nan() {
            continue;
        }
        // Runs that lost the peak (infinite deviation) are left out of the plot.
        let pts: Vec<(f64, f64)> = others
            .iter()
            .map(|r| (r.rtol, peak_devs(r, conv)[i]))
            .filter(|(_, d)| d.is_finite())
            .collect();
        if pts.is_empty() {
            continue;
        }
        let mut s = Series::line(
            format!("{name}: {band}"),
            pts.iter().map(|p| p.0).collect(),
            pts.iter().map(|p| p.1.max(1e-9)).collect(),
        );
        s.style = crate::report::plot::SeriesStyle::LinePoints;
        series.push(s);
    }
    series
}

/// `spectra_vs_rtol.svg`: the deviation `series` plus the `rel` limit line over the looser
/// tolerances (`rtols` ascending); nothing when there is only one tolerance.
fn spectra_figure(dir: &Path, rtols: &[f64], rel: f64, mut series: Vec<Series>) -> Result<()> {
    let loose: Vec<f64> = rtols.iter().copied().skip(1).collect();
    if loose.is_empty() {
        return Ok(());
    }
    series.push(Series::line(
        format!("{} % limit", rel * 100.0),
        loose.clone(),
        vec![rel; loose.len()],
    ));
    line_chart(
        &dir.join("spectra_vs_rtol.svg"),
        &format!(
            "Fit spectral peaks vs rtol (relative to rtol {:e}; floor 1e-9 = identical)",
            rtols[0]
        ),
        "rtol [-]",
        "|peak - converged| / converged [-]",
        &series,
        &ChartOpts {
            log_x: true,
            log_y: true,
            ..Default::default()
        },
    )
}

/// The loosest of `rtols` (ascending) that passes with every tighter one passing too.
fn loosest_passing(rtols: &[f64], ok_all: &[bool]) -> Option<f64> {
    let mut best = None;
    for (k, rt) in rtols.iter().enumerate() {
        if ok_all[k] {
            best = Some(*rt);
        } else {
            break;
        }
    }
    best
}

/// A benchmark problem that cannot be set up from the blade's parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BenchError {
    /// The reference run over the default window `[t0_s, t1_s]` never enters stick: there is no
    /// stick onset to start the `blade-burst` problem from.
    #[error("the blade never sticks in its window [{t0_s}, {t1_s}] s")]
    NeverSticks { t0_s: f64, t1_s: f64 },
}

impl From<BenchError> for Error {
    fn from(e: BenchError) -> Self {
        Error::stage(e, false)
    }
}
