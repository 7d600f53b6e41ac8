//! Command-line interface: argument parsing and glue only; the library does the work.

use crate::fit::features::{BandSpec, SignalKind, features};
use crate::fit::job::{LoadedJob, parse_toml, read_text};
use crate::import::{Format, ImportSpec};
use crate::model::{BladeParams, StickForm};
use crate::simulate::SolverOptions;
use crate::simulate::blade::{ModelKind, default_window, simulate_model};
use crate::{Error, Result};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};

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
    /// File layout (default: detect).
    #[arg(long, value_parser = ["dltdv", "tracker", "canonical"])]
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
}

fn import_spec(a: &ImportArgs) -> Result<ImportSpec> {
    let mut spec = match &a.spec {
        Some(p) => parse_toml::<ImportSpec>(p, &read_text(p)?)?,
        None => ImportSpec::default(),
    };
    if let Some(f) = &a.format {
        spec.format = match f.as_str() {
            "dltdv" => Some(Format::Dltdv),
            "tracker" => Some(Format::Tracker),
            _ => None,
        };
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
    let outcome = crate::fit::run_fit(job, progress)?;
    let result_path = result_path(job);
    let toml_text = outcome.result.to_toml()?;
    std::fs::write(&result_path, toml_text)
        .map_err(|e| Error::io(&result_path, "cannot write", e))?;
    let report_dir = report_dir(job);
    create_dir(&report_dir)?;
    crate::report::figures::fit_figures(&report_dir, &outcome)?;
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
        } => {
            let trace = read_any(&file, &import)?;
            let fs = crate::spectrum::median_rate_hz(&trace.t_s);
            let mut signals: Vec<(String, Vec<f64>)> = Vec::new();
            let uniform = |x: &[f64]| -> Result<Vec<f64>> {
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
            for (name, x) in &signals {
                let f = features(x, fs, &bands, 5)?;
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
                crate::report::figures::spectrum_figures(&dir, name, x, fs, &f)?;
            }
            println!("figures in {}", dir.display());
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
