//! Command-line interface: argument parsing and glue only; the library does the work.
//!
//! The doc comments on the argument types are clap's `--help` text, which names placeholders the
//! way command-line help does (`<file stem>`, `reports/<job>/`); rustdoc would read them as HTML.
#![allow(rustdoc::invalid_html_tags)]

use crate::fit::features::{BandSpec, SignalKind, features};
use crate::fit::job::{LoadedJob, parse_toml, read_text};
use crate::import::{Format, ImportSpec};
use crate::model::{BladeParams, StickForm};
use crate::simulate::SolverOptions;
use crate::simulate::blade::{ModelKind, default_window, simulate_model};
use crate::{Error, Result};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};

mod campaign;

/// wiperlab: a wiper blade's tracked motion beside a stick–slip model of it.
#[derive(Parser, Debug)]
#[command(name = "wiperlab", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// Import options shared by `import` and `spectrum`.
#[derive(clap::Args, Debug, Clone)]
pub struct ImportArgs {
    /// Sidecar TOML with the import settings (format, fps_hz, m_per_px, origin_px, points ...).
    #[arg(long)]
    pub spec: Option<PathBuf>,
    /// File layout (default: detect from the content).
    #[arg(long, value_parser = ["dltdv", "dltdv-sparse", "tracker", "kinovea-csv", "kinovea-txt",
        "kinovea-kinematics", "deeplabcut", "sleap", "trackmate", "generic", "canonical"])]
    pub format: Option<String>,
    /// Frame rate, Hz (required for DLTdv).
    #[arg(long)]
    pub fps: Option<f64>,
    /// Image scale, metres per pixel (DLTdv).
    #[arg(long)]
    pub m_per_px: Option<f64>,
    /// Pixel coordinates X,Y of the physical origin (DLTdv).
    // No `num_args = 2`: clap checks num_args before splitting on the delimiter, so it would reject
    // the documented `--origin-px 200,300`; the count is checked in `import_spec`.
    #[arg(long, value_delimiter = ',')]
    pub origin_px: Option<Vec<f64>>,
    /// Scale from two image points a known distance apart: X1,Y1,X2,Y2 in pixels (with
    /// --scale-distance-m).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub scale_points_px: Option<Vec<f64>>,
    /// Distance in metres between the --scale-points-px.
    #[arg(long)]
    pub scale_distance_m: Option<f64>,
    /// Metres per calibrated unit of the file (cm: 0.01; Tracker, Kinovea, TrackMate, generic).
    #[arg(long)]
    pub units_to_m: Option<f64>,
    /// Whether the file's y axis points down (default: the format's convention).
    #[arg(long)]
    pub y_down: Option<bool>,
    /// Rotate so x runs along the sweep: sweep direction in degrees from +x (counter-clockwise).
    #[arg(long, allow_negative_numbers = true)]
    pub sweep_angle_deg: Option<f64>,
    /// Rotate so x runs along the head's own principal axis of motion (angle reported).
    #[arg(long)]
    pub sweep_from_head: bool,
    /// Seconds per unit of the file's time column where the file does not say (ms: 0.001).
    #[arg(long)]
    pub time_to_s: Option<f64>,
    /// DeepLabCut/SLEAP: likelihood below which a point becomes a gap (default 0.6).
    #[arg(long)]
    pub min_likelihood: Option<f64>,
    /// DLTdv: 1-based camera to read; DLTdv sparse: --n-cameras gives how many there are.
    #[arg(long)]
    pub camera: Option<usize>,
    /// DLTdv sparse: number of cameras in the file (default 1).
    #[arg(long)]
    pub n_cameras: Option<usize>,
    /// Name of the tracked point that is the head.
    #[arg(long)]
    pub head: Option<String>,
    /// Name of the tracked point that is the lip tip.
    #[arg(long)]
    pub tip: Option<String>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Import a tracking-tool export into the canonical trace CSV (t_s, head_x_m, head_y_m, tip_x_m, tip_y_m, ...).
    Import {
        file: PathBuf,
        #[command(flatten)]
        import: ImportArgs,
        /// Print what the file holds (format, points, frames, time base, gaps) without converting.
        #[arg(long)]
        describe: bool,
        /// Output CSV (default: <file stem>.trace.csv beside the input).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Welch PSD, peaks and spectrogram of every tracked coordinate (and tip − head).
    Spectrum {
        file: PathBuf,
        #[command(flatten)]
        import: ImportArgs,
        /// Welch segment length (samples); default: the largest power of two ≤ len/4.
        #[arg(long)]
        nperseg: Option<usize>,
        /// Band LO:HI in Hz to pick a peak in (repeatable); default: the whole spectrum above 2 bins.
        #[arg(long)]
        band: Vec<String>,
        /// Directory for the SVG figures (default: reports/spectrum/<file stem>).
        #[arg(long)]
        out_dir: Option<PathBuf>,
        /// Longest gap (samples) filled by linear interpolation; longer gaps split the record
        /// into separate Welch runs.
        #[arg(long, default_value_t = crate::import::FILL_MAX_SAMPLES)]
        max_fill: usize,
    },
    /// Simulate the blade model over its reversal window.
    Simulate {
        /// Blade parameter TOML (see data/reversal/blade_true.toml).
        params: PathBuf,
        /// Window T0,T1 in s on the model clock (default: fastest forward to fastest backward).
        // No `num_args = 2` (see `origin_px`); the count is checked in `run`.
        #[arg(long, value_delimiter = ',')]
        window: Option<Vec<f64>>,
        /// Output sampling rate, Hz.
        #[arg(long, default_value_t = 10000.0)]
        fps: f64,
        #[arg(long, default_value_t = 1e-10)]
        rtol: f64,
        #[arg(long, default_value_t = 1e-12)]
        atol: f64,
        /// Stick-phase form: reduced (drift-free) or baumgarte.
        #[arg(long, default_value = "reduced", value_parser = ["reduced", "baumgarte"])]
        stick: String,
        /// Model of the hierarchy: blade2dof (full head/neck/lip) or head1dof (neck and lip locked).
        #[arg(long, default_value = "blade2dof", value_parser = ["blade2dof", "head1dof"])]
        model: String,
        /// Output directory (default: reports/simulate/<params stem>).
        #[arg(long)]
        out_dir: Option<PathBuf>,
    },
    /// Fit friction (A, B, C) and neck stiffness to a recording's spectra.
    Fit {
        job: PathBuf,
        /// Print the result as one JSON object on stdout.
        #[arg(long)]
        json: bool,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Write the report page reports/<job>/index.html from fits/<job>.result.toml (fitting first
    /// if the result is missing).
    Report {
        job: PathBuf,
        /// Run the fit again even if the result file exists.
        #[arg(long)]
        refit: bool,
        /// No progress bar when fitting.
        #[arg(long)]
        quiet: bool,
    },
    /// Campaigns: one fit job over many recordings, locally or as a Slurm job array.
    Campaign {
        #[command(subcommand)]
        action: campaign::CampaignCommand,
    },
    /// Work–precision of the simulation methods (event-driven, Moreau–Jean, smoothed friction) on
    /// the belt benchmark and the blade; writes work_precision.csv and SVG figures.
    Bench {
        /// Fewer settings and shorter timing loops (about 10 s instead of 20 s).
        #[arg(long)]
        quick: bool,
        /// Blade parameter TOMLs, comma-separated: the first is used for the work–precision problems,
        /// all of them for the spectra-against-tolerance study.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "data/reversal/blade_true.toml,data/reversal/blade.toml"
        )]
        blade: Vec<PathBuf>,
        /// Output directory.
        #[arg(long, default_value = "reports/bench")]
        out_dir: PathBuf,
    },
}

fn import_spec(a: &ImportArgs) -> Result<ImportSpec> {
    let mut spec = match &a.spec {
        Some(p) => parse_toml::<ImportSpec>(p, &read_text(p)?)?,
        None => ImportSpec::default(),
    };
    if let Some(f) = &a.format {
        spec.format = Format::from_name(f);
    }
    if let Some(p) = &a.scale_points_px {
        let &[x1, y1, x2, y2] = p.as_slice() else {
            return Err(Error::Config(format!(
                "--scale-points-px: expected X1,Y1,X2,Y2 in pixels (got {} values)",
                p.len()
            )));
        };
        spec.scale_points_px = Some([[x1, y1], [x2, y2]]);
    }
    if a.scale_distance_m.is_some() {
        spec.scale_distance_m = a.scale_distance_m;
    }
    if a.units_to_m.is_some() {
        spec.units_to_m = a.units_to_m;
    }
    if a.y_down.is_some() {
        spec.y_down = a.y_down;
    }
    if a.sweep_angle_deg.is_some() {
        spec.sweep_angle_deg = a.sweep_angle_deg;
    }
    if a.sweep_from_head {
        spec.sweep_from_head = true;
    }
    if a.time_to_s.is_some() {
        spec.time_to_s = a.time_to_s;
    }
    if a.min_likelihood.is_some() {
        spec.min_likelihood = a.min_likelihood;
    }
    if let Some(c) = a.camera {
        spec.camera = c;
    }
    if let Some(n) = a.n_cameras {
        spec.n_cameras = n;
    }
    if a.fps.is_some() {
        spec.fps_hz = a.fps;
    }
    if a.m_per_px.is_some() {
        spec.m_per_px = a.m_per_px;
    }
    if let Some(o) = &a.origin_px {
        let &[x, y] = o.as_slice() else {
            return Err(Error::Config(format!(
                "--origin-px: expected X,Y in pixels, e.g. 200,300 (got {} values)",
                o.len()
            )));
        };
        spec.origin_px = [x, y];
    }
    if let Some(h) = &a.head {
        spec.points.insert("head".into(), h.clone());
    }
    if let Some(t) = &a.tip {
        spec.points.insert("tip".into(), t.clone());
    }
    Ok(spec)
}

fn read_any(file: &Path, a: &ImportArgs) -> Result<crate::trace::Trace> {
    if a.format.as_deref() == Some("canonical") {
        return crate::import::canonical::read_trace_csv(file);
    }
    crate::import::read_trace(file, &import_spec(a)?)
}

fn create_dir(p: &Path) -> Result<()> {
    std::fs::create_dir_all(p).map_err(|e| Error::io(p, "cannot create directory", e))
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into())
}

/// `<job dir>/<name>.result.toml`.
fn result_path(job: &LoadedJob) -> PathBuf {
    job.path
        .parent()
        .unwrap_or(Path::new("."))
        .join(format!("{}.result.toml", job.name))
}

/// `reports/<name>/` (relative to the working directory).
fn report_dir(job: &LoadedJob) -> PathBuf {
    Path::new("reports").join(&job.name)
}

/// Runs the fit, writes the result TOML and the fit's figures; returns the result and both paths.
fn fit_and_write(
    job: &LoadedJob,
    progress: bool,
) -> Result<(crate::fit::FitResult, PathBuf, PathBuf)> {
    let mut outcome = crate::fit::run_fit(job, progress)?;
    let report_dir = report_dir(job);
    create_dir(&report_dir)?;
    outcome.result.data_files = crate::report::figures::fit_data_files(&report_dir, &outcome)?;
    let result_path = result_path(job);
    let toml_text = outcome.result.to_toml()?;
    crate::io::write_atomic(&result_path, toml_text.as_bytes())?;
    let freq_speed = crate::fit::instfreq::compare_freq_speed(&outcome)?;
    crate::report::figures::fit_figures(&report_dir, &outcome, freq_speed.as_ref())?;
    Ok((outcome.result, result_path, report_dir))
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Import {
            file,
            import,
            describe,
            output,
        } => {
            if let Some(out) = &output {
                crate::io::refuse_overwriting_input(&file, out)?;
            }
            let spec = import_spec(&import)?;
            let (trace, summary) = crate::import::read_trace_with_summary(&file, &spec)?;
            if describe {
                println!("{summary}");
                return Ok(());
            }
            let out = output.unwrap_or_else(|| file.with_extension("trace.csv"));
            crate::import::canonical::write_trace_csv(&out, &trace)?;
            eprintln!("{summary}");
            println!("wrote {}", out.display());
            Ok(())
        }
        Command::Spectrum {
            file,
            import,
            nperseg,
            band,
            out_dir,
            max_fill,
        } => {
            let trace = read_any(&file, &import)?;
            let fs = crate::spectrum::median_rate_hz(&trace.t_s);
            let mut signals: Vec<(String, Vec<f64>)> = Vec::new();
            // Frame-indexed files (t = frame/fps) are uniform already: resampling them would only
            // smear each NaN over its neighbours through rounding of the grid.
            let t0 = trace.t_s.first().copied().unwrap_or(0.0);
            let already_uniform = trace
                .t_s
                .iter()
                .enumerate()
                .all(|(k, t)| (t - (t0 + k as f64 / fs)).abs() <= 1e-6 / fs);
            let uniform = |x: &[f64]| -> Result<Vec<f64>> {
                if already_uniform {
                    return Ok(x.to_vec());
                }
                Ok(crate::spectrum::resample_uniform(&trace.t_s, x, fs)?.1)
            };
            for p in &trace.points {
                signals.push((format!("{}_x", p.name), uniform(&p.x_m)?));
                signals.push((format!("{}_y", p.name), uniform(&p.y_m)?));
            }
            if let Ok(x) = SignalKind::TipRelX.extract(&trace) {
                signals.push(("tip_rel_x".into(), uniform(&x)?));
            }
            let n = signals.first().map(|s| s.1.len()).unwrap_or(0);
            let nperseg = nperseg.unwrap_or_else(|| {
                let mut p = 8usize;
                while p * 2 <= n / 4 {
                    p *= 2;
                }
                p
            });
            let mut bands = Vec::new();
            for b in &band {
                let (lo, hi) = b
                    .split_once(':')
                    .and_then(|(l, h)| Some((l.parse::<f64>().ok()?, h.parse::<f64>().ok()?)))
                    .ok_or_else(|| {
                        Error::Config(format!("--band {b}: expected LO:HI in Hz, e.g. 30:300"))
                    })?;
                bands.push(BandSpec {
                    name: b.clone(),
                    range_hz: [lo, hi],
                    nperseg,
                });
            }
            if bands.is_empty() {
                bands.push(BandSpec {
                    name: "all".into(),
                    range_hz: [2.0 * fs / nperseg as f64, fs / 2.0],
                    nperseg,
                });
            }
            let dir = out_dir.unwrap_or_else(|| Path::new("reports/spectrum").join(stem(&file)));
            create_dir(&dir)?;
            println!(
                "{}: {} samples at {:.6} Hz (median frame rate), Welch nperseg {nperseg} (Hann, 50 % overlap), bin {:.4} Hz",
                file.display(),
                n,
                fs,
                fs / nperseg as f64
            );
            let summary = crate::import::describe(&trace);
            if already_uniform {
                println!(
                    "  not resampled: the {} frame times are uniform (within 1e-6 of a step); \
                     gaps ≤ {max_fill} samples filled, longer ones split the record",
                    summary.n_frames
                );
            } else {
                println!(
                    "  resampled: {} frame times (step {} … {} s) → {n} uniform samples at \
                     {fs:.6} Hz by linear interpolation; gaps ≤ {max_fill} samples filled, longer \
                     ones split the record",
                    summary.n_frames, summary.dt_min_s, summary.dt_max_s
                );
            }
            let mut computed = Vec::new();
            for (name, x) in &signals {
                let f = match features(x, fs, &bands, max_fill) {
                    Ok(f) => f,
                    Err(e) => {
                        println!("  {name:>12}: skipped: {e}");
                        continue;
                    }
                };
                let nan = x.iter().filter(|v| v.is_nan()).count();
                println!("  {name:>12}: {nan} missing samples, {} filled", f.filled);
                for b in &f.bands {
                    match b.peak {
                        Some(p) => println!(
                            "  {name:>12} band {:>10}: peak {:.6} Hz (period {:.6} s), PSD {:.4e}",
                            b.spec.name,
                            p.freq_hz,
                            1.0 / p.freq_hz,
                            p.level
                        ),
                        None => println!("  {name:>12} band {:>10}: no peak", b.spec.name),
                    }
                }
                let sg = crate::spectrum::stft::overview_spectrogram(x, fs)?;
                crate::report::figures::spectrum_figures(&dir, name, &f, sg.as_ref())?;
                computed.push((name.to_string(), f));
            }
            crate::report::figures::spectrum_data_files(&dir, &computed)?;
            println!("figures in {}", dir.display());
            println!("psd.csv and peaks.json in {}", dir.display());
            Ok(())
        }
        Command::Simulate {
            params,
            window,
            fps,
            rtol,
            atol,
            stick,
            model,
            out_dir,
        } => {
            let kind = if model == "head1dof" {
                ModelKind::Head1dof
            } else {
                ModelKind::Blade2dof
            };
            let p: BladeParams = parse_toml(&params, &read_text(&params)?)?;
            p.validate().map_err(|m| Error::input(&params, m))?;
            let win = match window {
                Some(w) => match w.as_slice() {
                    &[t0, t1] => (t0, t1),
                    _ => {
                        return Err(Error::Config(format!(
                            "--window: expected T0,T1 in s, e.g. 1.83,1.85 (got {} values)",
                            w.len()
                        )));
                    }
                },
                None => default_window(&p),
            };
            if !(fps > 0.0 && fps.is_finite()) {
                return Err(Error::Config(format!("--fps must be > 0 (got {fps})")));
            }
            let n = ((win.1 - win.0) * fps).floor() as usize + 1;
            let times: Vec<f64> = (0..n).map(|k| win.0 + k as f64 / fps).collect();
            let form = if stick == "baumgarte" {
                StickForm::Baumgarte { omega_b_per_s: 1e4 }
            } else {
                StickForm::Reduced
            };
            let opts = SolverOptions {
                rtol,
                atol,
                ..SolverOptions::default()
            };
            let t = std::time::Instant::now();
            let sim = simulate_model(kind, &p, win, &times, &opts, form)?;
            let wall = t.elapsed().as_secs_f64();
            let dir = out_dir.unwrap_or_else(|| Path::new("reports/simulate").join(stem(&params)));
            create_dir(&dir)?;
            crate::report::figures::write_simulation(&dir, &sim)?;
            println!(
                "simulated {:.4}..{:.4} s in {wall:.3} s: {} transitions, {} steps ({} rejected), {} RHS evaluations; outputs in {}",
                win.0,
                win.1,
                sim.transitions.len(),
                sim.stats.steps,
                sim.stats.rejected,
                sim.stats.rhs_evals,
                dir.display()
            );
            Ok(())
        }
        Command::Bench {
            quick,
            blade,
            out_dir,
        } => {
            let mut blades = Vec::new();
            for path in &blade {
                let params: BladeParams = parse_toml(path, &read_text(path)?)?;
                params.validate().map_err(Error::Config)?;
                blades.push((path.display().to_string(), params));
            }
            let Some((_, params)) = blades.first() else {
                return Err(Error::Config(
                    "bench: --blade needs at least one file".into(),
                ));
            };
            let rows = crate::bench::run_bench(&crate::bench::BenchOptions {
                quick,
                blade: *params,
            })?;
            crate::bench::write_reports(&out_dir, &rows)?;
            println!(
                "{:<13} {:<44} {:>8} {:>10} {:>10} {:>10} {:>6} {:>10} {:>10}",
                "problem",
                "method",
                "setting",
                "value",
                "wall_s",
                "rhs",
                "trans",
                "t_err_s",
                "trace_err"
            );
            for r in &rows {
                println!(
                    "{:<13} {:<44} {:>8} {:>10.1e} {:>10.3e} {:>10} {:>6} {:>10.2e} {:>10.2e} {}",
                    r.problem,
                    r.method,
                    r.setting_name,
                    r.setting,
                    r.wall_s,
                    r.rhs_evals,
                    r.transitions,
                    r.transition_err_s,
                    r.trace_err_m,
                    r.note
                );
            }
            println!("wrote {}", out_dir.join("work_precision.csv").display());
            let rtols: Vec<f64> = if quick {
                vec![1e-6, 1e-8, 1e-10, 1e-12]
            } else {
                (4..=13).map(|e| 10f64.powi(-e)).collect()
            };
            let mut spectra = Vec::new();
            for (name, p) in &blades {
                spectra.extend(crate::bench::spectra_vs_rtol(name, p, &rtols)?);
            }
            let loosest = crate::bench::write_spectra(&out_dir, &spectra, 0.002, 0.05)?;
            println!(
                "\n{:<32} {:>8} {:>9} {:>6} {:>12} {:>12}",
                "blade", "rtol", "wall_s", "trans", "low_peak_hz", "high_peak_hz"
            );
            for r in &spectra {
                println!(
                    "{:<32} {:>8.0e} {:>9.3} {:>6} {:>12.3} {:>12.3}",
                    r.blade, r.rtol, r.wall_s, r.transitions, r.low_peak_hz, r.high_peak_hz
                );
            }
            match loosest {
                Some(r) => println!(
                    "loosest rtol with both peaks of every blade within 0.2 % of its tightest run (and the transition count within 5 %): {r:e}"
                ),
                None => println!(
                    "no rtol has both peaks within 0.2 % (and the transition count within 5 %) of the tightest"
                ),
            }
            println!("wrote {}", out_dir.join("spectra_vs_rtol.csv").display());
            Ok(())
        }
        Command::Campaign { action } => campaign::run(action),
        Command::Fit { job, json, quiet } => {
            let loaded = LoadedJob::load(&job)?;
            let (result, result_path, report_dir) = fit_and_write(&loaded, !quiet && !json)?;
            if json {
                println!(
                    "{}",
                    serde_json::to_string(&result).map_err(|e| Error::Numerics(e.to_string()))?
                );
            } else {
                print!("{}", crate::report::figures::fit_summary(&result));
                println!(
                    "wrote {} and figures in {}",
                    result_path.display(),
                    report_dir.display()
                );
                println!(
                    "report page: `wiperlab report {}` writes {}",
                    job.display(),
                    report_dir.join(crate::report::html::INDEX).display()
                );
            }
            Ok(())
        }
        Command::Report { job, refit, quiet } => {
            let loaded = LoadedJob::load(&job)?;
            let result_path = result_path(&loaded);
            let report_dir = report_dir(&loaded);
            let result = if refit || !result_path.exists() {
                if !refit {
                    eprintln!("{} not found: running the fit first", result_path.display());
                }
                fit_and_write(&loaded, !quiet)?.0
            } else {
                crate::fit::FitResult::read(&result_path)?
            };
            let summary = crate::report::html::write_report(
                &result,
                &crate::report::html::ReportPaths {
                    job: job.clone(),
                    result: result_path,
                    recording: loaded.recording_path.clone(),
                    dir: report_dir,
                },
            )?;
            for w in &summary.warnings {
                eprintln!("warning: {w}");
            }
            println!(
                "wrote {} ({} figures); open it in a browser",
                summary.path.display(),
                summary.figures.len()
            );
            Ok(())
        }
    }
}
