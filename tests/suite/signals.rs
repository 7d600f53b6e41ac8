//! Any signal (issue 16, point 3): `spectrum --signal` takes a point's coordinate or the difference
//! of two points, and a fit job's `[spectrum] signal` the model's head and tip coordinates that
//! have dynamics and their difference; unknown names are errors that list what is known.

use crate::common::{root, run, temp_dir};

use std::path::Path;
use wiperlab::spectrum::features::SignalKind;
use wiperlab::trace::{PointTrack, Trace};

/// The peak frequency of `signal` in peaks.json (the first band).
fn peak_hz(dir: &Path, signal: &str) -> f64 {
    let peaks: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("peaks.json")).expect("peaks.json"))
            .expect("JSON");
    peaks
        .as_array()
        .expect("a list")
        .iter()
        .find(|p| p["signal"] == signal)
        .unwrap_or_else(|| panic!("no peak of {signal}: {peaks}"))["freq_hz"]
        .as_f64()
        .expect("freq_hz")
}

/// A canonical trace with points whose names hold `-` and `_`: `shd_L` moves at 120 Hz and
/// `left-wrist` at 50 Hz on top of it, so by construction the difference `left-wrist − shd_L` holds
/// only the 50 Hz line and `shd_L` only the 120 Hz one.
fn synthetic(path: &Path) {
    let fs = 1000.0;
    let mut s = String::from("t_s,left-wrist_x_m,left-wrist_y_m,shd_L_x_m,shd_L_y_m\n");
    for k in 0..4096 {
        let t = k as f64 / fs;
        let b = 1e-3 * (std::f64::consts::TAU * 120.0 * t).sin();
        let a = 1e-3 * (std::f64::consts::TAU * 50.0 * t).sin() + b;
        s.push_str(&format!("{t},0,{a},0,{b}\n"));
    }
    std::fs::write(path, s).expect("write");
}

#[test]
fn spectrum_takes_a_points_coordinate_and_a_difference_of_two_points() {
    let dir = temp_dir("synthetic");
    let file = dir.path().join("two.trace.csv");
    synthetic(&file);
    let out = dir.path().join("out");
    let o = run(&[
        "spectrum",
        file.to_str().unwrap(),
        "--signal",
        "left-wrist-shd_L_y",
        "--signal",
        "shd_L_y",
        "--nperseg",
        "1000",
        "--band",
        "20:200",
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("psd.csv")).expect("psd.csv");
    assert_eq!(
        csv.lines().next().unwrap(),
        "f_hz,left-wrist-shd_L_y_psd_m2_per_hz,shd_L_y_psd_m2_per_hz"
    );
    // 1 Hz bins: the lines fall on bins, and the parabolic peak lands on them.
    let diff = peak_hz(&out, "left-wrist-shd_L_y");
    let single = peak_hz(&out, "shd_L_y");
    assert!((diff - 50.0).abs() < 0.01, "difference peaks at {diff} Hz");
    assert!(
        (single - 120.0).abs() < 0.01,
        "shd_L_y peaks at {single} Hz"
    );
    assert!(out.join("psd_left-wrist-shd_L_y.svg").exists());
    // The spectrogram's colour bar (its only heatmap) says what it shows, in which unit, on
    // which scale and over which percentile range of the values its colours span.
    for name in ["left-wrist-shd_L_y", "shd_L_y"] {
        let svg = std::fs::read_to_string(out.join(format!("spectrogram_{name}.svg")))
            .expect("spectrogram");
        assert!(
            svg.lines().any(|l| {
                let l = l.trim();
                l.starts_with("PSD [m²/Hz], log scale, ") && l.ends_with(" percentile")
            }),
            "spectrogram_{name}.svg: no colour-bar label with its unit, scale and range"
        );
    }
}

#[test]
fn spectrum_refuses_an_unknown_point_listing_the_known_ones() {
    let dir = temp_dir("unknown");
    let file = dir.path().join("two.trace.csv");
    synthetic(&file);
    let out = dir.path().join("out");
    for (signal, needle) in [
        ("wrist-shoulder_y", "no point \"wrist-shoulder\""),
        (
            "shd_L_z",
            "expected <point>_x, <point>_y, <a>-<b>_x or <a>-<b>_y",
        ),
    ] {
        let o = run(&[
            "spectrum",
            file.to_str().unwrap(),
            "--signal",
            signal,
            "--out-dir",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!("--signal {signal}"))
                && err.contains(needle)
                && err.contains("points: left-wrist, shd_L"),
            "{err}"
        );
        assert!(!out.exists(), "nothing is written on bad input");
    }
}

/// The DeepLabCut bat recording (../shared/realdata, 700 fps, SOURCES.md): wrist y − shoulder y
/// beats at the wingbeat. NumPy's reference, as in tests/suite/import_realdata.rs: 8.203125 Hz with
/// nperseg 116, nfft 8192; here within one bin (700/8192 Hz).
#[test]
fn spectrum_of_wrist_minus_shoulder_on_the_real_deeplabcut_file() {
    let path = root().join("../shared/realdata/deeplabcut/AFAMcarollia_1Apr2021_0790C_Bane_Y20210401H145003.312743000_F1_croppedDLC_resnet50_Brown2021_accuracy_testJan28shuffle1_450000.csv");
    if !path.exists() {
        println!("skipped: {} is absent", path.display());
        return;
    }
    let dir = temp_dir("afam");
    let o = run(&[
        "spectrum",
        path.to_str().unwrap(),
        "--fps",
        "700",
        "--m-per-px",
        "1",
        "--min-likelihood",
        "0",
        "--signal",
        "wstL-shdL_y",
        "--nperseg",
        "116",
        "--nfft",
        "8192",
        "--band",
        "1:60",
        "--out-dir",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let f = peak_hz(dir.path(), "wstL-shdL_y");
    let numpy_hz = 8.203125;
    println!("wstL-shdL_y peaks at {f} Hz (NumPy {numpy_hz} Hz)");
    assert!((f - numpy_hz).abs() <= 700.0 / 8192.0, "{f} Hz");
}

#[test]
fn fit_signals_are_the_models_coordinates_and_their_difference() {
    let trace = Trace {
        t_s: vec![0.0, 1.0],
        points: vec![
            PointTrack {
                name: "head".into(),
                x_m: vec![1.0, 2.0],
                y_m: vec![-0.5, -0.25],
            },
            PointTrack {
                name: "tip".into(),
                x_m: vec![4.0, 8.0],
                y_m: vec![-6.0, -6.0],
            },
        ],
    };
    let get = |name: &str| name.parse::<SignalKind>().unwrap().extract(&trace).unwrap();
    assert_eq!(get("tip_rel_x"), [3.0, 6.0]);
    assert_eq!(get("tip_rel_y"), [-5.5, -5.75]);
    assert_eq!(get("head_y"), [-0.5, -0.25]);
    assert_eq!(get("tip_x"), [4.0, 8.0]);
    // The drive (head x) and the glass (tip y) are the model's givens, not signals to fit.
    for name in ["head_x", "tip_y"] {
        assert!(name.parse::<SignalKind>().is_err(), "{name}");
    }
}

/// A job naming a signal the model does not have fails at its line, listing the known signals,
/// with exit code 2 and before any work.
#[test]
fn a_fit_job_with_an_unknown_signal_names_its_line_and_the_known_ones() {
    let dir = temp_dir("job");
    let job = std::fs::read_to_string(root().join("fits/reversal.toml")).expect("job");
    let data = root().join("data");
    let job = job
        .replace("\"../data", &format!("\"{}", data.display()))
        .replace("signal = \"tip_rel_x\"", "signal = \"wstL-shdL_y\"");
    let line = job
        .lines()
        .position(|l| l.starts_with("signal = "))
        .expect("a signal line")
        + 1;
    let path = dir.path().join("bad_signal.toml");
    std::fs::write(&path, job).expect("write");
    let o = run(&["fit", path.to_str().unwrap(), "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("bad_signal.toml:{line}:"))
            && err.contains(
                "unknown signal 'wstL-shdL_y' (known: tip_rel_x, tip_rel_y, head_y, tip_x)"
            ),
        "{err}"
    );
    assert!(!dir.path().join("bad_signal.result.toml").exists());
}
