//! `wiperlab import --describe` and `wiperlab spectrum` on the new formats: what they print, and
//! the exit code and message for missing settings (through the built binary).

use crate::common::{TempFile, root, run, shared, temp_dir, wiperlab_exe};
use std::process::{Command, Output};

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// SLEAP, written here: frame 1 has no instance (padding row), so head has one NaN sample in one
/// gap; the summary names format, frames, time base, units and the gap.
#[test]
fn describe_prints_format_points_time_units_gaps() {
    let f = TempFile::with(
        "describe_sleap.csv",
        "track,frame_idx,head.x,head.y\nm,0,10,20\n,1,,\nm,2,12,22\n",
    );
    let o = run(&[
        "import",
        f.0.to_str().unwrap(),
        "--describe",
        "--fps",
        "50",
        "--m-per-px",
        "0.001",
    ]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    assert!(out.starts_with("sleap: 3 frames"), "{out}");
    assert!(out.contains("dt median 0.02 s (50 fps)"), "{out}");
    assert!(
        out.contains("m/head: 2 tracked, 1 NaN (33.33 %) in 1 gaps, longest 1 samples"),
        "{out}"
    );
    assert!(out.contains("time base: frame number / 50 fps"), "{out}");
    assert!(out.contains("units: pixels × 1e-3 m/px"), "{out}");
    assert!(out.contains("y: file y runs down"), "{out}");
}

/// Without a frame rate: converting is exit code 2 with a message naming the file and the flag;
/// `--describe` counts in frames instead and says what a fit will need.
#[test]
fn missing_fps_is_exit_2_naming_the_setting() {
    let f = TempFile::with(
        "nofps_sleap.csv",
        "track,frame_idx,a.x,a.y\nm,0,1,2\nm,1,1,3\n",
    );
    let out_csv = TempFile::path("nofps_sleap.trace.csv");
    let o = run(&[
        "import",
        f.0.to_str().unwrap(),
        "--m-per-px",
        "1",
        "-o",
        out_csv.0.to_str().unwrap(),
    ]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{out}{err}");
    assert!(
        err.contains("nofps_sleap.csv") && err.contains("--fps"),
        "{err}"
    );
    assert!(!out_csv.0.exists());
    let o = run(&[
        "import",
        f.0.to_str().unwrap(),
        "--describe",
        "--m-per-px",
        "1",
    ]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    assert!(out.contains("2 frames, frame 0 … 1"), "{out}");
    assert!(out.contains("a fit needs fps_hz (--fps)"), "{out}");
}

/// `--format` overrides detection: a Tracker-looking file read as generic fails for want of a
/// column mapping (a Config error), while detection reads it as Tracker.
#[test]
fn format_flag_overrides_detection() {
    let f = TempFile::with("override.txt", "t\tx\ty\n0\t1\t2\n0.1\t1\t2\n");
    let o = run(&["import", f.0.to_str().unwrap(), "--describe"]);
    assert!(
        text(&o).0.starts_with("tracker: 2 frames"),
        "{:?}",
        text(&o)
    );
    let o = run(&[
        "import",
        f.0.to_str().unwrap(),
        "--describe",
        "--format",
        "generic",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("[generic]"), "{:?}", text(&o));
}

/// The two-point scale and rotation flags reach the import: 3-4-5 px triangle, 0.5 m → 0.1 m/px.
#[test]
fn scale_points_and_rotation_flags() {
    let f = TempFile::with(
        "flags_xypts.csv",
        "pt1_cam1_X,pt1_cam1_Y\n0,0\n10,0\n20,0\n",
    );
    let o = run(&[
        "import",
        f.0.to_str().unwrap(),
        "--describe",
        "--fps",
        "10",
        "--scale-points-px",
        "0,0,3,4",
        "--scale-distance-m",
        "0.5",
        "--sweep-from-head",
    ]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    assert!(out.contains("1e-1 m/px"), "{out}");
    assert!(out.contains("by principal axis = 0.0000°"), "{out}");
}

/// `wiperlab spectrum` on a DeepLabCut file states whether it resampled and the filled samples per
/// signal (IL5, 800 fps; SOURCES.md). Resampling of jittered Tracker times is checked in
/// `tracker_resampling_is_reported`.
#[test]
fn spectrum_reports_resampling_and_filled_points() {
    let Some(path) = shared(
        "realdata/deeplabcut/IL5-519-Cam2_2020-06-25_000124Track9DLC_resnet50_Austin2020_accuracy_testApr7shuffle3_1150000.csv",
    ) else {
        return;
    };
    let tmp = temp_dir("import_cli");
    let dir = tmp.path();
    let o = run(&[
        "spectrum",
        path.to_str().unwrap(),
        "--fps",
        "800",
        "--m-per-px",
        "1e-4",
        "--band",
        "5:40",
        "--out-dir",
        dir.to_str().unwrap(),
    ]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    // Frame-indexed times (frame/800) are uniform: no resampling, so the gaps stay as imported.
    assert!(
        out.contains("not resampled: the 431 frame times are uniform"),
        "{out}"
    );
    assert!(out.contains("gaps ≤ 5 samples filled"), "{out}");
    // t3L has 17 samples below the 0.6 cut-off (awk count as in tests/suite/import_realdata.rs) in 7
    // gaps of at most 6 samples (`--describe`); the gaps of ≤ 5 are filled.
    let line = out
        .lines()
        .find(|l| l.trim_start().starts_with("t3L_x: 17 missing samples, "))
        .unwrap_or_else(|| panic!("{out}"));
    let filled: usize = line
        .split(", ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(filled > 0 && filled < 17, "{line}");
}

/// Tracker 8047.txt keeps its jittered frame times (SOURCES.md: 0.0317–0.0350 s): spectrum says
/// it resampled them.
#[test]
fn tracker_resampling_is_reported() {
    let Some(path) = shared("realdata/tracker/8047.txt") else {
        return;
    };
    let tmp = temp_dir("import_cli_t");
    let dir = tmp.path();
    let o = run(&[
        "spectrum",
        path.to_str().unwrap(),
        "--band",
        "0.2:1.0",
        "--out-dir",
        dir.to_str().unwrap(),
    ]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    assert!(out.contains("resampled: 4206 frame times"), "{out}");
    assert!(
        out.contains("point_x: 0 missing samples, 0 filled"),
        "{out}"
    );
}

/// `import X -o X` (also spelled through another path) is refused with exit code 2 before anything
/// is written: the export is left as it was.
#[test]
fn import_never_writes_over_its_input() {
    let content = "track,frame_idx,head.x,head.y\nm,0,10,20\nm,1,11,21\n";
    let f = TempFile::with("overwrite_sleap.csv", content);
    let path = f.0.to_str().unwrap();
    let dir = f.0.parent().unwrap();
    let other_spelling = dir.join(".").join(f.0.file_name().unwrap());
    for out in [path, other_spelling.to_str().unwrap()] {
        let o = run(&[
            "import",
            path,
            "-o",
            out,
            "--fps",
            "50",
            "--m-per-px",
            "0.001",
        ]);
        let (stdout, err) = text(&o);
        assert_eq!(o.status.code(), Some(2), "{stdout}{err}");
        assert!(err.contains("is the input file"), "{err}");
        assert_eq!(std::fs::read_to_string(&f.0).unwrap(), content);
    }
}

/// `spectrum --window boxcar --scaling spectrum` against the closed form: a sine of amplitude A
/// centred on a bin (f = 100 fs/nperseg), boxcar-windowed, has one-sided power A²/2 in that bin
/// (scipy.signal.welch's `scaling='spectrum'`), and the CSV column says which quantity it holds.
#[test]
fn spectrum_welch_options_match_the_closed_form() {
    let (fs, n, amp) = (1000.0_f64, 8192usize, 1e-3_f64);
    let f = 100.0 * fs / 1024.0;
    // Tracking-noise stand-in for the other coordinates (xorshift, 1e-6 m).
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut noise = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        1e-6 * ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
    };
    let mut text = String::from("t_s,head_x_m,head_y_m,tip_x_m,tip_y_m\n");
    for k in 0..n {
        let t = k as f64 / fs;
        let x = amp * (2.0 * std::f64::consts::PI * f * t).sin();
        text.push_str(&format!(
            "{t:.6},{:e},{:e},{x:e},{:e}\n",
            noise(),
            noise(),
            noise()
        ));
    }
    let tmp = temp_dir("welch_cli");
    let dir = tmp.path();
    let path = dir.join("sine.csv");
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    let o = run(&[
        "spectrum",
        path.to_str().unwrap(),
        "--format",
        "canonical",
        "--nperseg",
        "1024",
        "--window",
        "boxcar",
        "--scaling",
        "spectrum",
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The console names the quantity and its unit (power, m², with --scaling spectrum).
    let stdout = String::from_utf8_lossy(&o.stdout);
    let line = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("tip_x band"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(line.contains(", power ") && line.ends_with(" m²"), "{line}");
    let csv = std::fs::read_to_string(out.join("psd.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "tip_x_power_spectrum_m2")
        .unwrap_or_else(|| panic!("{header:?}"));
    let row: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap())
                .collect::<Vec<f64>>()
        })
        .find(|r| (r[0] - f).abs() < 1e-9)
        .expect("the sine's bin");
    let expected = amp * amp / 2.0;
    assert!(
        (row[col] - expected).abs() < 1e-9 * expected,
        "{} vs {expected}",
        row[col]
    );
}

/// Settings that cannot work are refused before any spectrum is computed, naming the flag (exit 2):
/// a segment longer than the record or shorter than 8, a band upside down, a band past Nyquist.
#[test]
fn spectrum_refuses_impossible_settings_naming_the_flag() {
    let Some(path) = root()
        .join("data/reversal/wiper_reversal_sample_xypts.csv")
        .canonicalize()
        .ok()
    else {
        panic!("the shipped recording is missing");
    };
    let base = [
        "spectrum",
        path.to_str().unwrap(),
        "--fps",
        "10000",
        "--m-per-px",
        "1.5e-5",
        "--origin-px",
        "200,300",
    ];
    let cases: [(&[&str], &str); 4] = [
        (&["--nperseg", "4"], "--nperseg 4"),
        (&["--nperseg", "10000000"], "--nperseg 10000000"),
        (
            &["--band", "300:30"],
            "--band 300:30: LO and HI are swapped: did you mean --band 30:300?",
        ),
        // The sample's 10,000 frames/s (data/reversal/README.md): Nyquist 5000 Hz.
        (
            &["--band", "100:6000"],
            "--band 100:6000: expected 0 <= LO < HI <= 5000 Hz (the Nyquist frequency, half the \
             10000 Hz sample rate)",
        ),
    ];
    for (extra, key) in cases {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(key), "{extra:?}: {err}");
    }
}

/// `wiperlab completions SHELL` prints a completion script (clap_complete) that knows every command
/// and the value enums (e.g. `--window` values); bash checks the script's syntax when it is there.
#[test]
fn completions_cover_the_commands() {
    for shell in ["bash", "zsh", "fish"] {
        let o = run(&["completions", shell]);
        assert!(o.status.success(), "{shell}");
        let script = String::from_utf8_lossy(&o.stdout);
        for word in [
            "import", "spectrum", "simulate", "modes", "fit", "report", "campaign", "bench",
            "blackman",
        ] {
            assert!(script.contains(word), "{shell}: no {word}");
        }
        if shell == "bash" && std::path::Path::new("/bin/bash").exists() {
            let tmp = temp_dir("compl");
            let dir = tmp.path();
            let f = dir.join("wiperlab.bash");
            std::fs::write(&f, script.as_bytes()).unwrap();
            let check = Command::new("/bin/bash")
                .arg("-n")
                .arg(&f)
                .status()
                .unwrap();
            assert!(check.success(), "bash -n rejects the script");
        }
    }
    let o = run(&["completions", "tcsh-nope"]);
    assert_eq!(o.status.code(), Some(2));
}

/// `import -o -` writes the canonical CSV on stdout, byte for byte what `-o FILE` writes, and
/// creates no file.
#[test]
fn import_to_stdout_with_dash() {
    let rec = root().join("data/reversal/wiper_reversal_sample_xypts.csv");
    let tmp = temp_dir("dash");
    let dir = tmp.path();
    let file = dir.join("out.trace.csv");
    let common = [
        "import",
        rec.to_str().unwrap(),
        "--fps",
        "10000",
        "--m-per-px",
        "1.5e-5",
        "--origin-px",
        "200,300",
        "-o",
    ];
    let mut to_file = common.to_vec();
    to_file.push(file.to_str().unwrap());
    assert!(run(&to_file).status.success());
    let mut to_stdout = common.to_vec();
    to_stdout.push("-");
    let o = run(&to_stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(o.stdout, std::fs::read(&file).unwrap());
    assert!(!std::path::Path::new("-").exists());
}

/// `--quiet` (global, any position) silences the import's notes on stderr; the file is written.
#[test]
fn quiet_import_writes_without_notes() {
    let out = TempFile::path("quiet.trace.csv");
    let o = run(&[
        "--quiet",
        "import",
        "data/reversal/wiper_reversal_sample_xypts.csv",
        "--fps",
        "10000",
        "--m-per-px",
        "1.5e-5",
        "-o",
        out.0.to_str().unwrap(),
    ]);
    let (stdout, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{stdout}{err}");
    assert!(err.is_empty(), "{err}");
    assert!(out.0.exists());
}

/// A reader that stops early (`wiperlab modes ... | head -1`, here 800 slip speeds: about 120 kB
/// of table, more than a pipe buffers) ends the command quietly: no panic about a broken pipe.
#[test]
fn a_closed_stdout_ends_quietly() {
    use std::io::{BufRead, BufReader};
    // 0.2 mm/s … 0.16 m/s, below the sample drive's peak head speed aω = 0.1665 m/s.
    let speeds: Vec<String> = (1..=800)
        .map(|i| format!("{:.4}", 0.0002 * i as f64))
        .collect();
    let mut child = std::process::Command::new(wiperlab_exe())
        .args([
            "modes",
            "data/reversal/blade_true.toml",
            "--speeds",
            &speeds.join(","),
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start wiperlab");
    let mut first = String::new();
    BufReader::new(child.stdout.take().expect("stdout"))
        .read_line(&mut first)
        .expect("read one line");
    // The pipe's read end is dropped here, long before the table is written out.
    let o = child.wait_with_output().expect("wait");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!first.is_empty());
    assert!(!err.contains("panicked"), "{err}");
}
