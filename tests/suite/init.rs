//! `wiperlab init RECORDING`: the job template it writes for the shipped sample recording, run as
//! a user runs it, and what the job loader makes of it once the MISSING lines are filled in.
//!
//! The reference settings come from the shipped main job `fits/reversal.toml` (the sample's
//! frame rate 10,000 frames/s, 1.5e-5 m/px, points pt1 = head and pt2 = tip, and the default
//! bands, which the template's band rule reproduces at 10,000 frames/s).

use crate::common::{root, run_in, temp_dir};

use std::process::Output;
use tempfile::TempDir;

use wiperlab::job::{LoadedJob, ParamPrior};
use wiperlab::model::ParamId;

/// A fresh temp dir holding a copy of the sample recording as `rec_xypts.csv`; removed on drop.
fn scratch(name: &str) -> TempDir {
    let d = temp_dir(&format!("init_{name}"));
    std::fs::copy(
        root().join("data/reversal/wiper_reversal_sample_xypts.csv"),
        d.path().join("rec_xypts.csv"),
    )
    .expect("copy the sample");
    d
}

fn text(o: &Output) -> String {
    format!(
        "stdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn without_settings_the_template_marks_what_a_fit_needs() {
    let s = scratch("bare");
    let o = run_in(s.path(), &["init", "rec_xypts.csv"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let job = s.path().join("rec_xypts.job.toml");
    // The count names the settings marked, not the header that explains the marks: MISSING the
    // blade, the frame rate and the scale; CHECK the roles guessed from the names, t0_s and the
    // default bands (no frame rate).
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("(3 MISSING, 3 CHECK)"),
        "{}",
        text(&o)
    );
    let t = std::fs::read_to_string(&job).expect("the template");
    // Detected format and the file's points.
    assert!(t.contains("format = \"dltdv\""), "{t}");
    assert!(t.contains("points: pt1, pt2"), "{t}");
    // Blade, frame rate and scale are missing; the roles are guessed.
    for missing in ["# blade = ", "# fps_hz = ", "# m_per_px = "] {
        let at = t
            .find(missing)
            .unwrap_or_else(|| panic!("no {missing:?} in\n{t}"));
        let before = &t[..at];
        assert!(before.contains("MISSING"), "{missing} not marked MISSING");
    }
    assert!(
        t.contains("head = \"pt1\"") && t.contains("tip = \"pt2\""),
        "{t}"
    );
    assert!(t.contains("CHECK: guessed"), "{t}");
    // As written, the job does not run: the loader names the missing blade.
    let e = LoadedJob::load(&job).expect_err("a job without a blade");
    assert!(e.to_string().contains("blade"), "{e}");
    // `init` never overwrites a job: exit 2, the file unchanged.
    std::fs::write(&job, "# mine\n").expect("write");
    let o = run_in(s.path(), &["init", "rec_xypts.csv"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("never overwrites"), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(&job).expect("read"), "# mine\n");
}

#[test]
fn with_the_sample_settings_the_filled_in_template_loads_like_the_main_job() {
    let s = scratch("calibrated");
    std::fs::create_dir_all(s.path().join("jobs")).expect("mkdir");
    let o = run_in(
        s.path(),
        &[
            "init",
            "rec_xypts.csv",
            "--fps",
            "10000",
            "--m-per-px",
            "1.5e-5",
            "--origin-px",
            "200,300",
            "--head",
            "pt1",
            "--tip",
            "pt2",
            "-o",
            "jobs/sample.toml",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let job = s.path().join("jobs/sample.toml");
    // Only the blade is MISSING; t0_s and the scaled bands are CHECK.
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("(1 MISSING, 2 CHECK)"),
        "{}",
        text(&o)
    );
    let t = std::fs::read_to_string(&job).expect("the template");
    assert!(!t.contains("CHECK: guessed"), "roles were given: {t}");
    // The job lives elsewhere than the recording: the recording's path is absolute.
    let rec = s
        .path()
        .canonicalize()
        .expect("canon")
        .join("rec_xypts.csv");
    assert!(t.contains(&format!("file = \"{}\"", rec.display())), "{t}");
    // Fill in the one MISSING line (the blade) as a user would.
    let blade = root().join("data/reversal/blade.toml");
    let filled = t.replace(
        "# blade = \"blade.toml\"",
        &format!("blade = \"{}\"", blade.display()),
    );
    std::fs::write(&job, &filled).expect("write the filled job");
    let loaded = LoadedJob::load(&job).unwrap_or_else(|e| panic!("{e}\n{filled}"));
    let main = LoadedJob::load(&root().join("fits/reversal.toml")).expect("the main job");
    let imp = &loaded.job.recording.as_ref().expect("recording").import;
    let main_imp = &main.job.recording.as_ref().expect("recording").import;
    assert_eq!(imp.fps_hz, main_imp.fps_hz);
    assert_eq!(imp.m_per_px, main_imp.m_per_px);
    assert_eq!(imp.origin_px, main_imp.origin_px);
    assert_eq!(imp.points, main_imp.points);
    assert_eq!(loaded.job.spectrum.signal, main.job.spectrum.signal);
    let bands = |j: &LoadedJob| -> Vec<(String, [f64; 2], usize)> {
        j.job
            .spectrum
            .bands
            .iter()
            .map(|b| (b.name.clone(), b.range_hz, b.nperseg))
            .collect()
    };
    assert_eq!(bands(&loaded), bands(&main));
    assert_eq!(
        loaded.free.iter().map(|f| f.0).collect::<Vec<_>>(),
        main.free.iter().map(|f| f.0).collect::<Vec<_>>()
    );
    assert!(
        loaded.job.fit.priors.is_empty(),
        "the priors are commented out"
    );
    // Uncommenting the [fit.priors] example, the template's last lines, gives a job that loads
    // with the priors it shows.
    let (before, example) = filled
        .split_once("# [fit.priors]\n")
        .unwrap_or_else(|| panic!("no [fit.priors] example in\n{filled}"));
    let mut with_priors = format!("{before}[fit.priors]\n");
    for line in example.lines() {
        let setting = line.strip_prefix("# ");
        with_priors += setting.unwrap_or_else(|| panic!("{line:?} is not commented out"));
        with_priors += "\n";
    }
    std::fs::write(&job, &with_priors).expect("write the job with priors");
    let loaded = LoadedJob::load(&job).unwrap_or_else(|e| panic!("{e}\n{with_priors}"));
    let priors = &loaded.job.fit.priors.parameters;
    assert_eq!(
        priors.get(&ParamId::K1),
        Some(&ParamPrior::Lognormal {
            median: 0.01,
            sd_log: 0.5
        })
    );
    assert_eq!(
        priors.get(&ParamId::C),
        Some(&ParamPrior::Normal { mean: 0.3, sd: 0.1 })
    );
    assert_eq!(priors.len(), 2);
}

#[test]
fn describe_needs_no_calibration_and_says_what_a_fit_needs() {
    let s = scratch("describe");
    let o = run_in(s.path(), &["import", "rec_xypts.csv", "--describe"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    // 18,869 frames: the sample's row count (data/reversal/README.md), frames 0 … 18868.
    assert!(out.contains("18869 frames, frame 0 … 18868"), "{out}");
    assert!(out.contains("times in frames"), "{out}");
    assert!(out.contains("a fit needs fps_hz (--fps)"), "{out}");
    assert!(out.contains("a fit needs m_per_px (--m-per-px)"), "{out}");
    // With the settings, the same file is described in seconds (frame 18869 at 1.8868 s).
    let o = run_in(
        s.path(),
        &[
            "import",
            "rec_xypts.csv",
            "--describe",
            "--fps",
            "10000",
            "--m-per-px",
            "1.5e-5",
        ],
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("t = 0 … 1.8868 s"), "{out}");
    assert!(!out.contains("a fit needs"), "{out}");
}

/// `-o -` prints the job on stdout (the recording by absolute path, since the job's place is
/// unknown) and writes no file; the same job as `-o FILE` apart from that path.
#[test]
fn dash_o_dash_prints_the_job_on_stdout() {
    let s = scratch("stdout");
    let o = run_in(s.path(), &["init", "rec_xypts.csv", "-o", "-"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let printed = String::from_utf8_lossy(&o.stdout).into_owned();
    let abs = s.path().canonicalize().unwrap().join("rec_xypts.csv");
    assert!(
        printed.contains(&format!("file = {:?}", abs.display().to_string())),
        "{printed}"
    );
    let files: Vec<_> = std::fs::read_dir(s.path()).unwrap().collect();
    assert_eq!(files.len(), 1, "only the recording: {files:?}");
    let o = run_in(s.path(), &["init", "rec_xypts.csv", "-o", "job.toml"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let written = std::fs::read_to_string(s.path().join("job.toml")).unwrap();
    let strip = |t: &str| -> Vec<String> {
        t.lines()
            .filter(|l| !l.starts_with("file = ") && !l.starts_with("# Fit job for "))
            .map(str::to_string)
            .collect()
    };
    assert_eq!(strip(&printed), strip(&written));
}

/// A recording with its own times: the template states their frame rate as people write it
/// (times k/1000 s, so 1000 frames/s, not `1000.000000` or the median step's last bits).
#[test]
fn a_recording_with_times_states_its_frame_rate_rounded() {
    let s = scratch("timed");
    let mut csv = String::from("t_s,head_x_m,head_y_m\n");
    for k in 0..50 {
        csv.push_str(&format!("{},{},0\n", k as f64 / 1000.0, 1e-4 * k as f64));
    }
    std::fs::write(s.path().join("timed.csv"), csv).expect("write");
    let o = run_in(s.path(), &["init", "timed.csv", "--format", "canonical"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let t = std::fs::read_to_string(s.path().join("timed.job.toml")).expect("the template");
    assert!(
        t.contains("# The file's own times give 1000 frames/s;"),
        "{t}"
    );
}
