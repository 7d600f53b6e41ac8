//! The CLI end to end: the README's main job, and bad input giving a one-line error with exit 2.

use std::path::Path;
use std::process::Command;

fn wiperlab() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_wiperlab"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

#[test]
fn main_job_end_to_end() {
    let out = wiperlab()
        .args(["fit", "fits/reversal.toml", "--json"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // Issue requirement: the fitted model's low and high peaks within 2 % of the measured ones.
    let peaks = r["peaks"].as_array().unwrap();
    assert_eq!(peaks.len(), 2);
    for p in peaks {
        let d = p["rel_diff"].as_f64().unwrap();
        assert!(d.abs() < 0.02, "{}: {d}", p["band"]);
    }
    // Measured peaks where data/reversal/README.md puts them (49.0 and 887.6 Hz with a one-window
    // estimator; ours uses Welch with nperseg 4096 / 2048, hence the looser ranges).
    let low = peaks[0]["measured_hz"].as_f64().unwrap();
    let high = peaks[1]["measured_hz"].as_f64().unwrap();
    assert!((45.0..55.0).contains(&low) && (850.0..920.0).contains(&high));
    for p in r["parameters"].as_array().unwrap() {
        assert!(p["true_value"].as_f64().is_some() && p["rel_error"].as_f64().unwrap().is_finite());
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let res = std::fs::read_to_string(root.join("fits/reversal.result.toml")).unwrap();
    let _: toml::Value = toml::from_str(&res).unwrap();
    for f in [
        "traces_tip",
        "traces_head",
        "psd_low",
        "psd_high",
        "friction_law",
        "cost",
    ] {
        let s = std::fs::read_to_string(root.join(format!("reports/reversal/{f}.svg"))).unwrap();
        assert!(s.contains("<svg"), "{f}");
    }
}

fn expect_input_error(args: &[&str], needles: &[&str]) {
    let out = wiperlab().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "args {args:?}: stderr {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    for n in needles {
        assert!(err.contains(n), "{n:?} not in {err}");
    }
}

fn temp_job(name: &str, edit: impl Fn(String) -> String) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("fits/reversal.toml"))
        .unwrap()
        .replace("../data/", &format!("{}/data/", root.display()));
    let dir = std::env::temp_dir().join(format!("wiperlab_cli_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, edit(text)).unwrap();
    p.display().to_string()
}

#[test]
fn bad_input_gives_one_line_and_exit_2() {
    expect_input_error(&["fit", "no/such/job.toml"], &["no/such/job.toml"]);
    let p = temp_job("syntax.toml", |t| {
        t.replace("particles = 24", "particles = = 24")
    });
    expect_input_error(&["fit", &p], &["syntax.toml:"]);
    let p = temp_job("unknown.toml", |t| {
        t.replace("A = [0.2, 1.5]", "Z = [0.0, 1.0]")
    });
    expect_input_error(&["fit", &p], &["unknown.toml:", "unknown parameter 'Z'"]);
    let p = temp_job("bounds.toml", |t| {
        t.replace("k1 = [0.005, 0.15]", "k1 = [0.15, 0.005]")
    });
    expect_input_error(&["fit", &p], &["bounds.toml:", "k1", "lower < upper"]);
    // A recording cell that is not a number: file, line, column and field.
    let dir = std::env::temp_dir().join(format!("wiperlab_cli_bad_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad_xypts.csv");
    std::fs::write(
        &bad,
        "pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y\n1,2,3,4\n1,2,abc,4\n",
    )
    .unwrap();
    let bad = bad.display().to_string();
    expect_input_error(
        &[
            "import",
            &bad,
            "--format",
            "dltdv",
            "--fps",
            "100",
            "--m-per-px",
            "1e-5",
            "--describe",
        ],
        &["bad_xypts.csv:3:3:", "pt2_cam1_X"],
    );
    expect_input_error(
        &["import", "does_not_exist.csv", "--describe"],
        &["does_not_exist.csv"],
    );
}

#[test]
fn tracker_pendulum_frequency_within_1_percent() {
    // ../shared/realdata/tracker/8047.txt: Tracker export of a 1.474 m pendulum; the author measured
    // T = 2.421 s (SOURCES.md, report2/PeriodVsLength.txt of the source repository).
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let file = root.join("../shared/realdata/tracker/8047.txt");
    if !file.exists() {
        eprintln!(
            "skipped: ../shared not found (tests that read ../shared need the project's shared folder beside the clone)"
        );
        return;
    }
    let dir = std::env::temp_dir().join(format!("wiperlab_spec_{}", std::process::id()));
    let out = wiperlab()
        .args([
            "spectrum",
            &file.display().to_string(),
            "--band",
            "0.2:1.0",
            "--out-dir",
            &dir.display().to_string(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text
        .lines()
        .find(|l| l.contains("point_x"))
        .expect("point_x line");
    let f: f64 = line
        .split("peak ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let f_ref = 1.0 / 2.421;
    assert!(((f - f_ref) / f_ref).abs() < 0.01, "{f} Hz vs {f_ref} Hz");
    assert!(dir.join("psd_point_x.svg").exists());
}
