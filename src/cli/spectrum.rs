//! `wiperlab spectrum`: Welch PSD, peaks and spectrogram of every tracked coordinate.

use super::{CliError, ImportArgs};
use crate::Result;
use crate::names::{quantity, significant};
use crate::spectrum::features::{BandSpec, features};
use crate::spectrum::signal::SignalExpr;
use std::path::{Path, PathBuf};

/// A `--band LO:HI` in Hz, as given.
#[derive(Debug, Clone, PartialEq)]
pub struct BandArg {
    /// The text given, used as the band's name.
    pub text: String,
    pub range_hz: [f64; 2],
}

/// A `--band` that is not `LO:HI` with two numbers.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("expected LO:HI in Hz, e.g. 30:300")]
pub struct BandArgError;

impl std::str::FromStr for BandArg {
    type Err = BandArgError;
    fn from_str(text: &str) -> std::result::Result<Self, BandArgError> {
        let (lo, hi) = text
            .split_once(':')
            .and_then(|(l, h)| Some((l.parse::<f64>().ok()?, h.parse::<f64>().ok()?)))
            .ok_or(BandArgError)?;
        Ok(BandArg {
            text: text.to_string(),
            range_hz: [lo, hi],
        })
    }
}

/// The `spectrum` command's settings.
pub(super) struct SpectrumArgs {
    pub file: PathBuf,
    pub import: ImportArgs,
    pub nperseg: Option<usize>,
    pub welch: super::WelchArgs,
    pub band: Vec<BandArg>,
    pub signal: Vec<String>,
    pub out_dir: Option<PathBuf>,
    pub max_fill: usize,
}

/// Reads the file, prints each signal's peaks per band and writes the figures, psd.csv and
/// peaks.json.
pub(super) fn run(a: SpectrumArgs) -> Result<()> {
    let trace = super::import::read_any(&a.file, &a.import)?;
    let uniform = crate::spectrum::uniform_signals_for(&trace, &signals(&trace, &a.signal)?)?;
    let fs = uniform.fs_hz;
    let n = uniform.signals.first().map(|s| s.1.len()).unwrap_or(0);
    let nperseg = a
        .nperseg
        .unwrap_or_else(|| crate::spectrum::default_nperseg(n));
    check_settings(&a.file, nperseg, n, fs, &a.band)?;
    let mut bands: Vec<BandSpec> = a
        .band
        .iter()
        .map(|b| BandSpec::new(b.text.clone(), b.range_hz, nperseg))
        .collect();
    if bands.is_empty() {
        bands.push(BandSpec::new(
            "all",
            [2.0 * fs / nperseg as f64, fs / 2.0],
            nperseg,
        ));
    }
    for b in &mut bands {
        b.window = a.welch.window;
        b.noverlap = a.welch.noverlap;
        b.nfft = a.welch.nfft;
        b.detrend = a.welch.detrend;
        b.scaling = a.welch.scaling;
        b.average = a.welch.average;
    }
    let cfg =
        bands[0]
            .welch_config()
            .map_err(|e| match crate::spectrum::SpectrumError::of(&e) {
                Some(s) => CliError::Welch(s.clone()).into(),
                None => e,
            })?;

    let dir = a
        .out_dir
        .unwrap_or_else(|| super::default_report_dir(&a.file, "spectrum"));
    crate::io::create_dir(&dir)?;
    println!(
        "{}: {} samples at {} Hz (median frame rate), Welch nperseg {nperseg} ({} window, noverlap {}, nfft {}, detrend {}, {} scaling, {} average), bin {}",
        a.file.display(),
        n,
        significant(fs, 6),
        cfg.window.scipy_name(),
        cfg.noverlap,
        cfg.nfft,
        cfg.detrend,
        cfg.scaling,
        cfg.average,
        quantity(fs / cfg.nfft as f64, "Hz")
    );
    print_grid(&trace, &uniform, n, a.max_fill);
    let mut computed = Vec::new();
    for (name, x) in &uniform.signals {
        let f = match features(x, fs, &bands, a.max_fill) {
            Ok(f) => f,
            Err(e) => {
                println!("  {name:>12}: skipped: {e}");
                continue;
            }
        };
        print_peaks(name, x, &f, cfg.scaling);
        let sg = crate::spectrum::stft::overview_spectrogram(x, fs)?;
        crate::report::figures::spectrum_figures(&dir, name, &f, sg.as_ref(), !a.band.is_empty())?;
        computed.push((name.to_string(), f));
    }
    crate::report::figures::spectrum_data_files(&dir, &computed)?;
    println!("figures in {}", dir.display());
    println!(
        "psd.csv, peaks.json and spectrogram_<signal>.csv in {}",
        dir.display()
    );
    Ok(())
}

/// The `--signal`s resolved against the trace's points, or the default signals when none is given.
fn signals(trace: &crate::trace::Trace, given: &[String]) -> Result<Vec<SignalExpr>> {
    if given.is_empty() {
        return Ok(SignalExpr::defaults(trace));
    }
    given
        .iter()
        .map(|s| {
            SignalExpr::resolve(s, trace).map_err(|reason| {
                CliError::Signal {
                    given: s.clone(),
                    reason,
                }
                .into()
            })
        })
        .collect()
}

/// Checks the segment length and the bands against the record before any spectrum is computed:
/// 8 ≤ nperseg ≤ samples, and every band ordered inside (0, Nyquist].
fn check_settings(
    file: &Path,
    nperseg: usize,
    n: usize,
    fs_hz: f64,
    bands: &[BandArg],
) -> Result<()> {
    if n < 8 {
        return Err(crate::Error::input(
            file,
            format!("{n} frames: one Welch segment needs at least 8"),
        ));
    }
    if !(8..=n).contains(&nperseg) {
        return Err(CliError::Nperseg {
            nperseg,
            samples: n,
        }
        .into());
    }
    let nyquist = fs_hz / 2.0;
    for b in bands {
        let [lo, hi] = b.range_hz;
        if lo > hi {
            let swapped = match b.text.split_once(':') {
                Some((l, h)) => format!("{h}:{l}"),
                None => format!("{hi}:{lo}"),
            };
            let text = b.text.clone();
            return Err(CliError::BandSwapped { text, swapped }.into());
        }
        if !(lo >= 0.0 && lo < hi && hi <= nyquist) {
            return Err(CliError::Band {
                text: b.text.clone(),
                fs_hz,
            }
            .into());
        }
    }
    Ok(())
}

/// Says whether the samples were resampled onto the grid and how gaps are treated.
fn print_grid(
    trace: &crate::trace::Trace,
    uniform: &crate::spectrum::UniformSignals,
    n: usize,
    max_fill: usize,
) {
    let summary = crate::import::describe(trace);
    if uniform.resampled {
        println!(
            "  resampled: {} frame times (step {} … {}) → {n} uniform samples at \
             {} Hz by linear interpolation; gaps ≤ {max_fill} samples filled, longer \
             ones split the record",
            summary.n_frames,
            significant(summary.dt_min_s, 4),
            quantity(summary.dt_max_s, "s"),
            significant(uniform.fs_hz, 6)
        );
    } else {
        println!(
            "  not resampled: the {} frame times are uniform (within 1e-6 of a step); \
             gaps ≤ {max_fill} samples filled, longer ones split the record",
            summary.n_frames
        );
    }
}

/// One signal's missing samples and its peak per band: frequency to 5 significant digits (a
/// fraction of a bin at the default segment lengths), period, and the PSD (or power) with its unit.
fn print_peaks(
    name: &str,
    x: &[f64],
    f: &crate::spectrum::features::Features,
    scaling: crate::spectrum::Scaling,
) {
    let (what, unit) = match scaling {
        crate::spectrum::Scaling::Density => ("PSD", "m²/Hz"),
        crate::spectrum::Scaling::Spectrum => ("power", "m²"),
    };
    let nan = x.iter().filter(|v| v.is_nan()).count();
    println!("  {name:>12}: {nan} missing samples, {} filled", f.filled);
    for b in &f.bands {
        match b.peak {
            Some(p) => println!(
                "  {name:>12} band {:>10}: peak {} Hz (period {}), {what} {}",
                b.spec.name,
                significant(p.freq_hz, 5),
                quantity(1.0 / p.freq_hz, "s"),
                quantity(p.level, unit)
            ),
            None => println!("  {name:>12} band {:>10}: no peak", b.spec.name),
        }
    }
}
