//! Command-line interface: argument parsing and dispatch only; the library does the work. Each
//! command's glue (reading its inputs, calling the library, printing) is a module of its own.
//!
//! The doc comments on the argument types are clap's `--help` text, which names placeholders the
//! way command-line help does (`<file stem>`, `reports/<job>/`); rustdoc would read them as HTML.
#![allow(rustdoc::invalid_html_tags)]

use crate::Result;
use crate::simulate::Method;
use clap::{Parser, Subcommand};
pub use error::CliError;
use std::path::{Path, PathBuf};

/// Set once by [`run`] from `--quiet`.
static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// True when `--quiet` was given.
fn quiet() -> bool {
    QUIET.load(std::sync::atomic::Ordering::Relaxed)
}

/// `eprintln!` for status messages on stderr, silent under `--quiet`.
macro_rules! esay {
    ($($arg:tt)*) => {
        if !$crate::cli::quiet() {
            eprintln!($($arg)*);
        }
    };
}
use esay;

mod bench;
mod campaign;
mod error;
mod explore;
mod fit;
mod import;
mod init;
mod modes;
mod simulate;
mod spectrum;

pub use fit::{default_fit_dir, fit_files};
pub use simulate::{BAUMGARTE_OMEGA_PER_S, SimulatedModel, StickChoice};
pub use spectrum::BandArg;

/// wiperlab: a wiper blade's tracked motion beside a stick–slip model of it.
#[derive(Parser, Debug)]
#[command(name = "wiperlab", version, about, after_help = EXIT_CODES)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// No progress (on any command): no progress bar or progress lines of a fit, no per-recording
    /// lines of a campaign run, no import notes on stderr. Results, errors and warnings still
    /// appear.
    #[arg(long, short, global = true)]
    pub quiet: bool,
}

/// The exit codes, listed under the top-level `--help`.
const EXIT_CODES: &str = "Exit codes: 0 done, 1 computation failed (a simulation or fit that \
    cannot go on), 2 bad input (a file, a flag or a setting; nothing is written), 130 interrupted \
    (Ctrl-C or SIGTERM; a fit writes its best result so far to <job>.interrupted.result.toml).";

/// Welch settings of `spectrum`, named and defaulted as `scipy.signal.welch`.
#[derive(clap::Args, Debug, Clone)]
pub struct WelchArgs {
    /// Window of each segment.
    #[arg(long, value_enum, default_value_t = crate::spectrum::Window::Hann)]
    pub window: crate::spectrum::Window,
    /// Samples shared by consecutive segments (default: nperseg/2).
    #[arg(long)]
    pub noverlap: Option<usize>,
    /// FFT length in samples, ≥ nperseg (default: nperseg; longer zero-pads).
    #[arg(long)]
    pub nfft: Option<usize>,
    /// What is subtracted from each segment.
    #[arg(long, value_enum, default_value_t = crate::spectrum::Detrend::Constant)]
    pub detrend: crate::spectrum::Detrend,
    /// density (PSD, m²/Hz) or spectrum (power, m²).
    #[arg(long, value_enum, default_value_t = crate::spectrum::Scaling::Density)]
    pub scaling: crate::spectrum::Scaling,
    /// How the segments' periodograms are combined (median with SciPy's bias correction).
    #[arg(long, value_enum, default_value_t = crate::spectrum::Average::Mean)]
    pub average: crate::spectrum::Average,
}

/// Import options shared by `import` and `spectrum`.
#[derive(clap::Args, Debug, Clone)]
pub struct ImportArgs {
    /// Sidecar TOML with the import settings (format, fps_hz, m_per_px, origin_px, points ...);
    /// flags override it (default: none).
    #[arg(long)]
    pub spec: Option<PathBuf>,
    /// File layout (default: detect from the content).
    #[arg(long, value_parser = ["dltdv", "dltdv-sparse", "tracker", "kinovea-csv", "kinovea-txt",
        "kinovea-kinematics", "deeplabcut", "sleap", "trackmate", "generic", "canonical"])]
    pub format: Option<String>,
    /// Frame rate, Hz: required where the file has frame numbers only (DLTdv, DeepLabCut, SLEAP,
    /// TrackMate without a time unit, a generic `frame` column); elsewhere a check of the time
    /// column (default: none).
    #[arg(long)]
    pub fps: Option<f64>,
    /// Image scale, metres per pixel: required where the file is in pixels (DLTdv, DeepLabCut,
    /// SLEAP, TrackMate or generic tables in pixels) unless --scale-points-px gives it; not for
    /// Tracker, which is calibrated (default: none).
    #[arg(long)]
    pub m_per_px: Option<f64>,
    /// Coordinates X,Y of the physical origin, subtracted before scaling: pixels for pixel files,
    /// the file's unit otherwise; must be 0,0 for Tracker (default: 0,0).
    // No `num_args = 2`: clap checks num_args before splitting on the delimiter, so it would reject
    // the documented `--origin-px 200,300`; the count is checked in `import_spec`.
    #[arg(long, value_delimiter = ',')]
    pub origin_px: Option<Vec<f64>>,
    /// Scale from two image points a known distance apart: X1,Y1,X2,Y2 in pixels (with
    /// --scale-distance-m).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub scale_points_px: Option<Vec<f64>>,
    /// Distance in metres between the --scale-points-px (default: none).
    #[arg(long)]
    pub scale_distance_m: Option<f64>,
    /// Metres per calibrated unit of the file (cm: 0.01; Tracker, Kinovea, TrackMate, generic;
    /// default: the unit the file states, Tracker 1).
    #[arg(long)]
    pub units_to_m: Option<f64>,
    /// Whether the file's y axis points down (default: the format's convention: true for DLTdv,
    /// DeepLabCut, SLEAP and TrackMate image rows, false otherwise).
    #[arg(long)]
    pub y_down: Option<bool>,
    /// Rotate so x runs along the sweep: sweep direction in degrees from +x (counter-clockwise;
    /// default: no rotation).
    #[arg(long, allow_negative_numbers = true)]
    pub sweep_angle_deg: Option<f64>,
    /// Rotate so x runs along the head's own principal axis of motion (angle reported; default:
    /// off).
    #[arg(long)]
    pub sweep_from_head: bool,
    /// Seconds per unit of the file's time column where the file does not say (ms: 0.001;
    /// default: the unit in the header, else s for generic tables).
    #[arg(long)]
    pub time_to_s: Option<f64>,
    /// DeepLabCut/SLEAP: likelihood (0 to 1) below which a point becomes a gap (default: 0.6,
    /// DeepLabCut's pcutoff; 0 keeps every point).
    #[arg(long)]
    pub min_likelihood: Option<f64>,
    /// DLTdv: 1-based camera to read; DLTdv sparse: --n-cameras gives how many there are
    /// (default: 1).
    #[arg(long)]
    pub camera: Option<usize>,
    /// DLTdv sparse: number of cameras in the file (default: 1).
    #[arg(long)]
    pub n_cameras: Option<usize>,
    /// Name of the tracked point that is the head (default: none, the file's names are kept).
    #[arg(long)]
    pub head: Option<String>,
    /// Name of the tracked point that is the lip tip (default: none, the file's names are kept).
    #[arg(long)]
    pub tip: Option<String>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Import a tracking-tool export into the canonical trace CSV (t_s, head_x_m, head_y_m, tip_x_m, tip_y_m, ...).
    Import {
        /// The tracking export (DLTdv, Tracker, Kinovea, DeepLabCut, SLEAP, TrackMate, a generic
        /// table or a canonical trace CSV).
        file: PathBuf,
        #[command(flatten)]
        import: ImportArgs,
        /// Print what the file holds (format, points, frames, time base, gaps) without converting.
        #[arg(long)]
        describe: bool,
        /// Output CSV (default: <file stem>.trace.csv in --out-dir; `-`: stdout).
        #[arg(short, long, conflicts_with = "out_dir")]
        output: Option<PathBuf>,
        /// Directory of <file stem>.trace.csv (default: the input's directory, wherever the
        /// command runs).
        #[arg(long)]
        out_dir: Option<PathBuf>,
    },
    /// Write a commented fit-job template for a recording: format detected, points listed, what a
    /// fit still needs marked MISSING and guesses marked CHECK.
    Init {
        /// The tracking export the job fits.
        recording: PathBuf,
        #[command(flatten)]
        import: ImportArgs,
        /// Job file to write (default: <recording stem>.job.toml in --out-dir; never overwrites
        /// a file; `-`: stdout).
        #[arg(short, long, conflicts_with = "out_dir")]
        output: Option<PathBuf>,
        /// Directory of <recording stem>.job.toml (default: the recording's directory, wherever
        /// the command runs).
        #[arg(long)]
        out_dir: Option<PathBuf>,
    },
    /// Welch PSD, peaks and spectrogram of every tracked coordinate (and tip − head).
    Spectrum {
        /// The tracking export or trace CSV to analyse.
        file: PathBuf,
        #[command(flatten)]
        import: ImportArgs,
        /// Welch segment length in samples; default: the largest power of two ≤ len/4. SciPy's
        /// default is 256 whatever the record; a long high-speed recording needs longer segments
        /// to resolve its low component (2.4 Hz bins at 10,000 frames/s need 4096).
        #[arg(long)]
        nperseg: Option<usize>,
        /// Welch settings with scipy.signal.welch's names and defaults.
        #[command(flatten)]
        welch: WelchArgs,
        /// Band LO:HI in Hz to pick a peak in (repeatable); default: the whole spectrum above 2 bins.
        #[arg(long)]
        band: Vec<BandArg>,
        /// Signal to analyse (repeatable): <point>_x, <point>_y, the difference of two points
        /// <a>-<b>_x, <a>-<b>_y (e.g. wstL-shdL_y), or tip_rel_x, tip_rel_y (tip − head); default:
        /// every point's x and y, and tip_rel_x when there are a head and a tip.
        #[arg(long)]
        signal: Vec<String>,
        /// Directory of the figures, psd.csv and peaks.json (default: reports/spectrum/<file
        /// stem>/ beside the input file, wherever the command runs).
        #[arg(long)]
        out_dir: Option<PathBuf>,
        /// Longest gap in samples filled by linear interpolation; longer gaps split the record
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
        #[arg(long, default_value = "10000")]
        fps: f64,
        /// Relative error tolerance of each integrator step (dimensionless).
        #[arg(long, default_value = "1e-10")]
        rtol: f64,
        /// Absolute error tolerance of each integrator step, in the state's units (the link
        /// angles θ, φ in rad and their rates in rad/s).
        #[arg(long, default_value = "1e-12")]
        atol: f64,
        /// Integrator of the smooth phases: dop853 (the default: at rtol 1e-10 it needs 0.69× the
        /// right-hand-side evaluations of dopri5 and half its model solves, docs/validation.md) or
        /// dopri5.
        #[arg(long, value_enum, default_value_t = Method::Dop853)]
        method: Method,
        /// Stick-phase form: reduced (drift-free) or baumgarte.
        #[arg(long, value_enum, default_value_t = StickChoice::Reduced)]
        stick: StickChoice,
        /// Model of the hierarchy: blade2dof (full head/neck/lip) or head1dof (neck and lip
        /// locked). The necklip model needs a recorded head and runs only inside a fit.
        #[arg(long, value_enum, default_value_t = SimulatedModel::Blade2dof)]
        model: SimulatedModel,
        /// Output directory (default: reports/simulate/<params stem>/ beside the parameter file,
        /// wherever the command runs).
        #[arg(long)]
        out_dir: Option<PathBuf>,
    },
    /// The linearised blade's modes in stick and in steady slip: frequency, damping ratio
    /// (negative: self-excited) and which coordinates move (head, head–link, neck–lip).
    Modes {
        /// Blade parameter TOML (see data/reversal/blade_true.toml).
        blade: PathBuf,
        /// Slip speeds in m/s, comma-separated (default: 25, 50 and 100 % of the drive's peak
        /// head speed aω).
        #[arg(long, value_delimiter = ',')]
        speeds: Option<Vec<f64>>,
        /// Print the modes as a JSON array on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Fit friction (A, B, C) and neck stiffness to a recording's spectra. Writes
    /// <name>.result.toml beside the job and the figures in <reports_dir>/<name>/ (the job's
    /// reports_dir, default reports/ beside the job; wherever the command runs).
    Fit {
        /// The fit-job TOML (`wiperlab init` writes one).
        job: PathBuf,
        /// Print the result as one JSON object on stdout.
        #[arg(long)]
        json: bool,
        /// Directory of the figures and data files (default: <reports_dir>/<name>/ beside the
        /// job). The result stays beside the job.
        #[arg(long)]
        out_dir: Option<PathBuf>,
    },
    /// Sample a job's freed parameters (seeded Sobol points over [fit.parameters]) and map where
    /// they take the model's lines: explore.csv (parameters, each band's line, prominence and
    /// failure cause), the one-at-a-time sensitivity around the job's start (sensitivity.csv, .md),
    /// the closest achievable pair and the constraint that keeps it from the targets
    /// (constraint.txt) and the reachability map (reachability.svg).
    Explore {
        /// The fit-job TOML whose [fit.parameters] are sampled.
        job: PathBuf,
        /// Number of samples (1 to 65536).
        #[arg(long, default_value_t = crate::explore::DEFAULT_SAMPLES)]
        samples: usize,
        /// Scramble seed of the Sobol sequence (same seed, same samples).
        #[arg(long, default_value_t = 1)]
        seed: u32,
        /// Output directory (default: <reports_dir>/explore/<job name>/, the job's reports_dir,
        /// default reports/ beside the job; wherever the command runs); an exploration already
        /// there is replaced, with a note on stderr.
        #[arg(long)]
        out_dir: Option<PathBuf>,
    },
    /// Write the report page <reports_dir>/<name>/index.html from <name>.result.toml beside the
    /// job (with --refit: fit first; without a result and without --refit: exit 2).
    Report {
        /// The fit-job TOML whose result the page shows.
        job: PathBuf,
        /// Run the fit again even if the result file exists.
        #[arg(long)]
        refit: bool,
        /// Directory of the page, holding the fit's figures (default: <reports_dir>/<name>/, the
        /// job's reports_dir, default reports/ beside the job; wherever the command runs).
        #[arg(long)]
        out_dir: Option<PathBuf>,
    },
    /// Campaigns: one fit job over many recordings, locally or as a Slurm job array.
    Campaign {
        #[command(subcommand)]
        action: campaign::CampaignCommand,
        /// Directory of everything the campaign writes (jobs/, results/, slurm/, campaign.csv,
        /// report/); default: <campaign name>/ beside the campaign file, wherever the command
        /// runs. Give the same --out-dir to every subcommand of one campaign.
        #[arg(long, global = true)]
        out_dir: Option<PathBuf>,
    },
    /// Print a shell completion script on stdout, e.g.
    /// `wiperlab completions bash > ~/.local/share/bash-completion/completions/wiperlab`.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Work–precision of the simulation methods (event-driven, Moreau–Jean, smoothed friction) on
    /// the belt benchmark and the blade; writes work_precision.csv and SVG figures.
    Bench {
        /// Fewer settings and shorter timing loops (about a quarter of the full bench's time).
        #[arg(long)]
        quick: bool,
        /// Blade parameter TOMLs, comma-separated: the first is used for the work–precision problems,
        /// all of them for the spectra-against-tolerance study. Default: the source tree's
        /// data/reversal/blade_true.toml and blade.toml, wherever the command runs.
        #[arg(long, value_delimiter = ',')]
        blade: Option<Vec<PathBuf>>,
        /// Output directory. Default: the source tree's reports/bench (the committed benchmark),
        /// wherever the command runs.
        #[arg(long)]
        out_dir: Option<PathBuf>,
    },
}

/// `<file stem>` of `p` (default `out`), for default output directories.
fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into())
}

/// Writes the shell's completion script for wiperlab on stdout.
fn completions(shell: clap_complete::Shell) -> Result<()> {
    use clap::CommandFactory;
    clap_complete::generate(
        shell,
        &mut Cli::command(),
        "wiperlab",
        &mut std::io::stdout(),
    );
    Ok(())
}

/// The directory holding `input` (`.` for a bare file name).
fn input_dir(input: &Path) -> &Path {
    match input.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The output rule for figures and tables: `<input dir>/reports/<command>/<input stem>/`, beside
/// the input whatever the working directory.
fn default_report_dir(input: &Path, command: &str) -> PathBuf {
    input_dir(input)
        .join(crate::job::DEFAULT_REPORTS_DIR)
        .join(command)
        .join(stem(input))
}

/// The output rule for single-file outputs: `<out_dir>/<file_name>`, by default beside `input`.
fn single_output(input: &Path, out_dir: Option<&Path>, file_name: &str) -> PathBuf {
    out_dir.unwrap_or_else(|| input_dir(input)).join(file_name)
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> Result<()> {
    QUIET.store(cli.quiet, std::sync::atomic::Ordering::Relaxed);
    match cli.command {
        Command::Import {
            file,
            import,
            describe,
            output,
            out_dir,
        } => import::run(&file, &import, describe, output, out_dir),
        Command::Init {
            recording,
            import,
            output,
            out_dir,
        } => init::run(&recording, &import, output, out_dir),
        Command::Spectrum {
            file,
            import,
            nperseg,
            welch,
            band,
            signal,
            out_dir,
            max_fill,
        } => spectrum::run(spectrum::SpectrumArgs {
            file,
            import,
            nperseg,
            welch,
            band,
            signal,
            out_dir,
            max_fill,
        }),
        Command::Simulate {
            params,
            window,
            fps,
            rtol,
            atol,
            method,
            stick,
            model,
            out_dir,
        } => simulate::run(simulate::SimulateArgs {
            params,
            window,
            fps,
            rtol,
            atol,
            method,
            stick,
            model,
            out_dir,
        }),
        Command::Bench {
            quick,
            blade,
            out_dir,
        } => bench::run(quick, blade, out_dir),
        Command::Campaign { action, out_dir } => campaign::run(action, out_dir),
        Command::Completions { shell } => completions(shell),
        Command::Modes {
            blade,
            speeds,
            json,
        } => modes::run(&blade, speeds.as_deref(), json),
        Command::Fit { job, json, out_dir } => fit::fit(&job, json, cli.quiet, out_dir),
        Command::Explore {
            job,
            samples,
            seed,
            out_dir,
        } => explore::run(&job, samples, seed, out_dir),
        Command::Report {
            job,
            refit,
            out_dir,
        } => fit::report(&job, refit, cli.quiet, out_dir),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    /// Every command, subcommands included, with its path (`wiperlab campaign run`).
    fn all_commands() -> Vec<(String, clap::Command)> {
        fn walk(path: String, c: clap::Command, out: &mut Vec<(String, clap::Command)>) {
            for sub in c.get_subcommands() {
                walk(format!("{path} {}", sub.get_name()), sub.clone(), out);
            }
            out.push((path, c));
        }
        let mut out = Vec::new();
        walk("wiperlab".into(), Cli::command(), &mut out);
        out
    }

    /// clap's own consistency checks (conflicting names, defaults outside possible values ...).
    #[test]
    fn the_command_line_is_consistent() {
        Cli::command().debug_assert();
    }

    /// Every argument says what it is; a default shows as people write it (`1e-10`, not
    /// `0.0000000001`); `-o` is only ever `--output`, a file.
    #[test]
    fn every_argument_has_help_and_readable_defaults() {
        for (path, c) in all_commands() {
            for a in c.get_arguments() {
                let id = a.get_id().as_str();
                if matches!(id, "help" | "version") {
                    continue;
                }
                assert!(a.get_help().is_some(), "{path} {id}: no help text");
                for d in a.get_default_values() {
                    let d = d.to_string_lossy();
                    assert!(!d.contains("0.0000"), "{path} {id}: default written {d}");
                }
                if a.get_short() == Some('o') {
                    assert_eq!(id, "output", "{path}: -o names {id}, not a file");
                }
            }
        }
    }

    /// The exit codes are in the top-level help.
    #[test]
    fn the_help_lists_the_exit_codes() {
        let help = Cli::command().render_long_help().to_string();
        for code in [
            "0 done",
            "1 computation failed",
            "2 bad input",
            "130 interrupted",
        ] {
            assert!(help.contains(code), "{code} missing from\n{help}");
        }
    }

    /// `simulate --model` offers only models that run on their own.
    #[test]
    fn simulate_offers_no_necklip() {
        let e = Cli::try_parse_from(["wiperlab", "simulate", "b.toml", "--model", "necklip"])
            .expect_err("necklip is not simulated alone");
        assert_eq!(e.kind(), clap::error::ErrorKind::InvalidValue, "{e}");
    }
}
