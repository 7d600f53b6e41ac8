//! `wiperlab spectrum` on real Tracker exports of a damped pendulum (`../shared/realdata/tracker/`,
//! skipped when `../shared` is absent): the printed peak of the horizontal coordinate must be within
//! 1 % of 1/T, with T the period the recordings' author measured.
//!
//! Source of every period: `shared/realdata/SOURCES.md`, section `tracker/`, which quotes
//! `report2/PeriodVsLength.txt` of the author's repository (1.474 m → 2.421 s, 1.147 m → 2.148 s,
//! 0.614 m → 1.587 s).
//!
//! Resolution: the CLI's default Welch segment (largest power of two ≤ len/4) is 1024 samples for
//! 8047/8054 and 512 for 8049 at the files' 30 fps median rate, i.e. bins of 0.029 and 0.059 Hz,
//! wider than the 1 % tolerance (0.0041 Hz at 0.413 Hz). The peak is located by parabolic
//! interpolation between bins, which for a clean Hann-windowed line is accurate to a small
//! fraction of a bin; measured errors are 0.09 %, 0.04 % and 0.19 % for 8047, 8049, 8054. Longer segments do
//! not help: with 3949 samples (8049) 2048 leaves two Welch segments, and for 8054 nperseg 2048 or
//! 4096 give 0.6318/0.6319 Hz, no closer to 1/1.587 s — the remaining 0.2 % is between the
//! author's period and this record (SOURCES.md's independent FFT of the file: 0.632 Hz,
//! T 1.582 s). So the defaults are used, as a user would run it.

use crate::common::{ok, run, s, shared, temp_dir};

use std::path::Path;

/// Runs `wiperlab spectrum <file> --band 0.2:1.0` and returns the peak frequency printed for
/// `signal` (a line `  <signal> band    0.2:1.0: peak <f> Hz (period ...)`).
fn peak_hz(file: &Path, signal: &str) -> f64 {
    let stem = file.file_stem().unwrap().to_string_lossy().into_owned();
    let dir = temp_dir(&format!("spectrum_realdata_{stem}"));
    let o = run(&[
        "spectrum",
        s(file),
        "--band",
        "0.2:1.0",
        "--out-dir",
        s(dir.path()),
    ]);
    let out = ok(&o, &format!("spectrum {}", file.display()));
    let f = out
        .lines()
        .find_map(|l| {
            let mut w = l.split_whitespace();
            if w.next()? != signal || w.next()? != "band" || w.next()? != "0.2:1.0:" {
                return None;
            }
            if w.next()? != "peak" {
                return None;
            }
            w.next()?.parse::<f64>().ok()
        })
        .unwrap_or_else(|| panic!("no peak for {signal} in band 0.2:1.0 in:\n{out}"));
    assert!(
        dir.path().join(format!("psd_{signal}.svg")).is_file(),
        "no PSD figure for {signal} in {}",
        dir.path().display()
    );
    println!(
        "{}: {signal} peak {f:.6} Hz (period {:.4} s)",
        file.display(),
        1.0 / f
    );
    f
}

/// Peak within 1 % of 1/`period_s`.
fn check(rel: &str, signal: &str, period_s: f64) {
    let Some(file) = shared(rel) else { return };
    let f = peak_hz(&file, signal);
    let want = 1.0 / period_s;
    let err = (f - want) / want;
    println!("  vs 1/{period_s} s = {want:.6} Hz: {:+.3} %", err * 100.0);
    assert!(
        err.abs() <= 0.01,
        "{rel}: peak {f} Hz vs 1/{period_s} s = {want} Hz ({:+.3} %)",
        err * 100.0
    );
}

/// 8047.txt: L = 1.474 m, author's period 2.421 s (SOURCES.md; independent FFT 0.414 Hz).
/// Tracker track name `point` (single-track file, column row `t x y`).
#[test]
fn pendulum_8047_period() {
    check("realdata/tracker/8047.txt", "point_x", 2.421);
}

/// 8049.txt: L = 1.147 m, author's period 2.148 s (SOURCES.md; independent FFT 0.466 Hz).
/// Track `mass_B` (first line of the file).
#[test]
fn pendulum_8049_period() {
    check("realdata/tracker/8049.txt", "mass_B_x", 2.148);
}

/// 8054.txt: L = 0.614 m, author's period 1.587 s (SOURCES.md; independent FFT 0.632 Hz).
/// Track `mass_A` (first line of the file).
#[test]
fn pendulum_8054_period() {
    check("realdata/tracker/8054.txt", "mass_A_x", 1.587);
}
