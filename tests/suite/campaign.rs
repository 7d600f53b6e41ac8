//! `wiperlab campaign` as a lab runs it, on copies of the shipped example campaign's recordings
//! (`campaigns/example.toml`: six model-made recordings in `data/campaign/`, written by
//! `examples/make_campaign.rs`, truth in `data/campaign/truth.csv`):
//! * a local run fits every readable recording while an unreadable one fails alone, collects them
//!   into `campaign.csv`, skips finished recordings on a rerun and refits the one whose recording
//!   changed;
//! * the same campaign through a real one-node Slurm (`tests/slurm/start.sh`: munged, slurmctld
//!   and slurmd on localhost; needs root and Debian's `slurm-wlm` and `munge`) gives the same
//!   collected values as the local run. Without Slurm the test says it skipped, unless
//!   WIPERLAB_REQUIRE_SLURM=1 (CI), where that is a failure.
//!
//! Each fit of the example template costs seconds of CPU, so the local test fits two recordings
//! (and refits one) and the Slurm test, which compares two runs of the same job rather than their
//! accuracy, fits with a tiny search.

use crate::common;
use crate::common::{ok, root, run, s, temp_dir};

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The search of the fit template a test campaign uses.
#[derive(Clone, Copy)]
enum Search {
    /// The example template as shipped (3 restarts of an 8-particle swarm, 25 Nelder–Mead
    /// iterations): the fits recover C and k1.
    Example,
    /// The example template with a tiny search (4 particles, 1 swarm iteration, 3 Nelder–Mead
    /// iterations, 1 restart): a complete fit and result in about a second, far from the optimum.
    Tiny,
}

/// Copies `recordings` (file names in data/campaign/) and their conditions rows into `dir`, and
/// writes `dir/c.toml`: the example campaign's template, with `search`, on those copies.
fn campaign_copy(dir: &Path, recordings: &[&str], search: Search) -> PathBuf {
    let data = root().join("data/campaign");
    let table = std::fs::read_to_string(data.join("conditions.csv")).expect("conditions.csv");
    let mut lines = table.lines();
    let mut rows = vec![lines.next().expect("header").to_string()];
    for r in recordings {
        std::fs::copy(data.join(r), dir.join(r)).expect("copy recording");
        rows.push(
            lines
                .clone()
                .find(|l| l.starts_with(&format!("{r},")))
                .unwrap_or_else(|| panic!("no conditions row for {r}"))
                .to_string(),
        );
    }
    std::fs::write(dir.join("conditions.csv"), rows.join("\n") + "\n").expect("write table");
    let shipped = root().join("campaigns/example_template.toml");
    let template = match search {
        Search::Example => shipped,
        Search::Tiny => {
            let text = std::fs::read_to_string(&shipped)
                .expect("example template")
                .replace(
                    "\"../data/",
                    &format!("\"{}/", root().join("data").display()),
                );
            let mut replaced = 0;
            let tiny: Vec<&str> = text
                .lines()
                .map(|l| {
                    let tiny_value = match l.split(' ').next() {
                        Some("particles") => "particles = 4",
                        Some("swarm_iterations") => "swarm_iterations = 1",
                        Some("polish_iterations") => "polish_iterations = 3",
                        Some("restarts") => "restarts = 1",
                        _ => return l,
                    };
                    replaced += 1;
                    tiny_value
                })
                .collect();
            assert_eq!(
                replaced, 4,
                "the example template's search keys moved:\n{text}"
            );
            let path = dir.join("tiny_template.toml");
            std::fs::write(&path, tiny.join("\n") + "\n").expect("write template");
            path
        }
    };
    let campaign = format!(
        "template = {template:?}\nrecordings = [\"*_xypts.csv\"]\nconditions = \"conditions.csv\"\n"
    );
    let path = dir.join("c.toml");
    std::fs::write(&path, campaign).expect("write campaign");
    path
}

/// `campaign.csv` as rows of column → value.
fn read_table(path: &Path) -> Vec<BTreeMap<String, String>> {
    let mut r = csv::Reader::from_path(path).expect("campaign.csv");
    let headers = r.headers().expect("header").clone();
    r.records()
        .map(|rec| {
            let rec = rec.expect("row");
            headers
                .iter()
                .zip(rec.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// data/campaign/truth.csv: recording file name → (C, k1).
fn truth() -> BTreeMap<String, (f64, f64)> {
    let mut r = csv::Reader::from_path(root().join("data/campaign/truth.csv")).expect("truth.csv");
    r.records()
        .map(|rec| {
            let rec = rec.expect("row");
            (
                rec[0].to_string(),
                (rec[1].parse().expect("C"), rec[2].parse().expect("k1")),
            )
        })
        .collect()
}

fn num(row: &BTreeMap<String, String>, col: &str) -> f64 {
    row.get(col)
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no number in column {col}: {row:?}"))
}

/// Runs `campaign run` with `args` on a campaign with a recording that cannot be read, and returns
/// its standard output, whose summary line reads e.g. "campaign 'c': 2 fitted, 0 skipped (…), 1
/// failed". A failed recording is a failed computation: the run exits with 1.
fn run_with_a_failure(args: &[&str]) -> String {
    let o = run(&[&["campaign", "run"], args].concat());
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{out}\n{err}");
    out
}

#[test]
fn local_campaign_fits_collects_skips_and_survives_a_failure() {
    let dir = temp_dir("local");
    // Two compounds at two sweep speeds, so that every condition varies (compound, sweep, t0_s,
    // drive speed), and a third recording that cannot be read.
    let c = campaign_copy(
        dir.path(),
        &[
            "hard_normal_xypts.csv",
            "hard_slow_xypts.csv",
            "soft_fast_xypts.csv",
        ],
        Search::Example,
    );
    std::fs::write(
        dir.path().join("hard_slow_xypts.csv"),
        "pt1_cam1_X,pt1_cam1_Y\n1,x\n",
    )
    .expect("break a recording");
    let cs = c.to_str().expect("UTF-8 path");
    // The unreadable recording fails alone: the others are fitted in the same run, which then
    // exits with 1.
    let out = run_with_a_failure(&[cs, "--jobs", "2"]);
    assert!(
        out.contains("2 fitted, 0 skipped") && out.contains("1 failed"),
        "{out}"
    );
    ok(&run(&["campaign", "collect", cs]), "campaign collect");
    let rows = read_table(&dir.path().join("c/campaign.csv"));
    assert_eq!(rows.len(), 3);
    let bad = rows
        .iter()
        .find(|r| r["id"] == "hard_slow_xypts")
        .expect("row of the broken recording");
    assert_eq!(bad["state"], "failed");
    assert!(bad["reason"].contains("hard_slow_xypts.csv"), "{bad:?}");
    // The report page lists every recording (the broken one among the failures) and draws each
    // parameter against each varying condition and the friction laws.
    let page =
        std::fs::read_to_string(dir.path().join("c/report/index.html")).expect("report page");
    for id in ["hard_normal_xypts", "soft_fast_xypts", "hard_slow_xypts"] {
        assert!(page.contains(id), "{id} missing from the report page");
    }
    for fig in [
        "friction_laws",
        "C_vs_compound",
        "k1_vs_sweep",
        "C_vs_drive_omega_rad_per_s",
    ] {
        let svg = dir.path().join(format!("c/report/{fig}.svg"));
        assert!(
            page.contains(&format!("{fig}.svg")),
            "{fig} not on the page"
        );
        assert!(
            std::fs::read_to_string(&svg).is_ok_and(|t| t.contains("<svg")),
            "{fig}"
        );
    }
    assert!(
        !dir.path().join("c/report/C_vs_repeat.svg").exists(),
        "repeat is 1 everywhere"
    );
    let truth = truth();
    let fitted: Vec<_> = rows
        .iter()
        .filter(|r| r["id"] != "hard_slow_xypts")
        .collect();
    assert_eq!(fitted.len(), 2);
    for row in fitted {
        assert_eq!(row["state"], "done", "{row:?}");
        let (c_true, k1_true) = truth[&format!("{}.csv", row["id"])];
        let (c, k1) = (num(row, "C"), num(row, "k1"));
        println!(
            "{}: C {:+.2} %, k1 {:+.2} % ({} / {} sweep)",
            row["id"],
            100.0 * (c / c_true - 1.0),
            100.0 * (k1 / k1_true - 1.0),
            row["compound"],
            row["sweep"]
        );
        // C and k1 within the single-recording tests' 5 % (tests/suite/fit_recovery.rs).
        assert!((c / c_true - 1.0).abs() < 0.05, "C: {row:?}");
        assert!((k1 / k1_true - 1.0).abs() < 0.05, "k1: {row:?}");
        // The conditions table's labels and overrides reach the row.
        assert!(["soft", "hard"].contains(&row["compound"].as_str()));
        assert!(num(row, "drive_omega_rad_per_s") > 0.0 && num(row, "t0_s") > 0.0);
    }
    // A rerun skips both fitted recordings (same content hashes) and tries the failed one again.
    let out = run_with_a_failure(&[cs]);
    assert!(
        out.contains("0 fitted, 2 skipped") && out.contains("1 failed"),
        "{out}"
    );
    // A changed recording is refitted alone.
    let changed = dir.path().join("soft_fast_xypts.csv");
    let mut text = std::fs::read_to_string(&changed).expect("read copy");
    let last = text.lines().last().expect("a row").to_string();
    text.push_str(&last);
    text.push('\n');
    std::fs::write(&changed, text).expect("append a frame");
    let out = run_with_a_failure(&[cs]);
    assert!(
        out.contains("1 fitted, 1 skipped") && out.contains("1 failed"),
        "{out}"
    );
    ok(
        &run(&["campaign", "collect", cs]),
        "collect after the refit",
    );
    let rows = read_table(&dir.path().join("c/campaign.csv"));
    assert_eq!(rows.iter().filter(|r| r["state"] == "done").count(), 2);
    assert_eq!(rows.iter().filter(|r| r["state"] == "failed").count(), 1);
}

#[test]
fn campaign_errors_name_the_file_and_line() {
    let dir = temp_dir("errors");
    let c = campaign_copy(dir.path(), &["soft_fast_xypts.csv"], Search::Example);
    let cs = c.to_str().expect("UTF-8 path");
    // A conditions row naming a recording the campaign does not have: file, line, the name.
    let table = dir.path().join("conditions.csv");
    let mut text = std::fs::read_to_string(&table).expect("table");
    text.push_str("nope_xypts.csv,1.0,1.6,soft,normal,1\n");
    std::fs::write(&table, &text).expect("write table");
    let o = run(&["campaign", "list", cs]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("conditions.csv:3:") && err.contains("nope_xypts.csv"),
        "{err}"
    );
    // A non-number in an override column: its line and column.
    let header = text.lines().next().expect("header");
    std::fs::write(
        &table,
        format!("{header}\nsoft_fast_xypts.csv,fast,1.6,soft,fast,1\n"),
    )
    .expect("write table");
    let o = run(&["campaign", "list", cs]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("conditions.csv:2:2") && err.contains("t0_s"),
        "{err}"
    );
}

/// A campaign of two example recordings whose conditions table gives the first its own blade
/// file and truth JSON (`blade_file`, `truth_json`, relative to the table in `sub/`) and leaves the
/// second's cells empty; the template is the example's with a `[truth]` section. Returns the
/// campaign file and the conditions table.
fn campaign_with_files(dir: &Path) -> (PathBuf, PathBuf) {
    let data = root().join("data/campaign");
    for r in ["soft_fast_xypts.csv", "hard_fast_xypts.csv"] {
        std::fs::copy(data.join(r), dir.join(r)).expect("copy recording");
    }
    std::fs::create_dir_all(dir.join("sub/truths")).expect("mkdir");
    let blade = std::fs::read_to_string(root().join("data/reversal/blade_true.toml"))
        .expect("blade_true.toml")
        .replace("c = 0.56", "c = 0.43");
    std::fs::write(dir.join("sub/truths/own.blade.toml"), blade).expect("write blade");
    std::fs::write(
        dir.join("sub/truths/own.json"),
        r#"{"params": {"C": 0.43, "k1": 0.021}}"#,
    )
    .expect("write truth");
    std::fs::write(
        dir.join("default_truth.json"),
        r#"{"params": {"C": 0.5, "k1": 0.03}}"#,
    )
    .expect("write truth");
    let template = std::fs::read_to_string(root().join("campaigns/example_template.toml"))
        .expect("template")
        .replace(
            "\"../data/reversal/blade_true.toml\"",
            &format!("{:?}", root().join("data/reversal/blade_true.toml")),
        )
        + "\n[truth]\njson = \"default_truth.json\"\nkeys = { C = \"/params/C\", k1 = \"/params/k1\" }\n";
    std::fs::write(dir.join("template.toml"), template).expect("write template");
    let table = dir.join("sub/conditions.csv");
    std::fs::write(
        &table,
        "recording,drive_omega_rad_per_s,blade_file,truth_json,compound\n\
         soft_fast_xypts.csv,2.0,truths/own.blade.toml,truths/own.json,soft\n\
         hard_fast_xypts.csv,,,,hard\n",
    )
    .expect("write table");
    let campaign = dir.join("c.toml");
    std::fs::write(
        &campaign,
        "template = \"template.toml\"\nrecordings = [\"*_xypts.csv\"]\nconditions = \"sub/conditions.csv\"\n",
    )
    .expect("write campaign");
    (campaign, table)
}

/// `blade_file` and `truth_json` replace the template's blade file and truth JSON for their row
/// only (the drive override still applied on top of the row's blade), are not condition labels,
/// and a changed truth file changes the recording's input hash. No fit runs.
#[test]
fn conditions_give_a_recording_its_own_blade_and_truth() {
    use wiperlab::campaign::run::{EntryPaths, generate};
    use wiperlab::campaign::{Campaign, FileOverride};
    let dir = temp_dir("files");
    let (c, _) = campaign_with_files(dir.path());
    let campaign = Campaign::load(&c).expect("campaign loads");
    assert_eq!(campaign.label_columns, vec!["compound".to_string()]);
    let own = campaign.entry("soft_fast_xypts").expect("entry");
    let plain = campaign.entry("hard_fast_xypts").expect("entry");
    assert_eq!(
        own.files.get(&FileOverride::BladeFile),
        Some(&dir.path().join("sub/truths/own.blade.toml"))
    );
    assert!(plain.files.is_empty(), "{:?}", plain.files);
    let out = campaign.out_dir();
    let g = generate(&campaign, own, &EntryPaths::new(&out, own)).expect("generate");
    let blade: wiperlab::model::BladeParams = toml::from_str(&g.blade_text).expect("blade");
    match blade.friction {
        wiperlab::model::FrictionLaw::Exponential { c, .. } => assert_eq!(c, 0.43),
        other => panic!("{other:?}"),
    }
    assert_eq!(blade.drive_omega_rad_per_s, 2.0);
    let job: toml::Table = toml::from_str(&g.job_text).expect("job");
    let json = |j: &toml::Table| j["truth"]["json"].as_str().expect("json").to_string();
    assert_eq!(json(&job), s(&dir.path().join("sub/truths/own.json")));
    let p = generate(&campaign, plain, &EntryPaths::new(&out, plain)).expect("generate");
    let plain_blade: wiperlab::model::BladeParams = toml::from_str(&p.blade_text).expect("blade");
    assert_eq!(plain_blade, common::true_blade());
    let plain_job: toml::Table = toml::from_str(&p.job_text).expect("job");
    assert_eq!(json(&plain_job), s(&dir.path().join("default_truth.json")));
    assert_eq!(
        campaign.truth_of(own).expect("truth").json,
        dir.path().join("sub/truths/own.json")
    );
    // The truth's bytes are part of the input hash: a changed truth refits the recording.
    std::fs::write(
        dir.path().join("sub/truths/own.json"),
        r#"{"params": {"C": 0.44, "k1": 0.021}}"#,
    )
    .expect("rewrite truth");
    let again = generate(&campaign, own, &EntryPaths::new(&out, own)).expect("generate");
    assert_ne!(again.input_sha256, g.input_sha256);
    assert_eq!(again.job_text, g.job_text);
}

/// A missing, unparsable or incomplete per-recording file is an input error at the table's line
/// and column that names the column and the file; so is a `truth_json` column for a template
/// without `[truth]`.
#[test]
fn bad_per_recording_files_name_the_table_cell() {
    let dir = temp_dir("bad_files");
    let (c, table) = campaign_with_files(dir.path());
    let cs = c.to_str().expect("UTF-8 path");
    let original = std::fs::read_to_string(&table).expect("table");
    let check = |table_text: String, expect: &[&str]| {
        std::fs::write(&table, table_text).expect("write table");
        let o = run(&["campaign", "list", cs]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        for e in expect {
            assert!(err.contains(e), "expected {e:?} in: {err}");
        }
    };
    check(
        original.replace("truths/own.blade.toml", "truths/none.blade.toml"),
        &[
            "conditions.csv:2:3",
            "blade_file",
            "none.blade.toml",
            "cannot read",
        ],
    );
    std::fs::write(
        dir.path().join("sub/truths/bad.blade.toml"),
        "l1_m = 0.002\n",
    )
    .expect("write");
    check(
        original.replace("truths/own.blade.toml", "truths/bad.blade.toml"),
        &["conditions.csv:2:3", "bad.blade.toml", "not a blade file"],
    );
    std::fs::write(
        dir.path().join("sub/truths/short.json"),
        r#"{"params": {"C": 0.4}}"#,
    )
    .expect("write");
    check(
        original.replace("truths/own.json", "truths/short.json"),
        &["conditions.csv:2:4", "short.json", "/params/k1", "'k1'"],
    );
    std::fs::write(dir.path().join("sub/truths/broken.json"), "{\"params\": ").expect("write");
    check(
        original.replace("truths/own.json", "truths/broken.json"),
        &["conditions.csv:2:4", "broken.json", "not valid JSON"],
    );
    std::fs::write(&table, &original).expect("write table");
    let template = dir.path().join("template.toml");
    let text = std::fs::read_to_string(&template).expect("template");
    let without = &text[..text.find("[truth]").expect("[truth]")];
    std::fs::write(&template, without).expect("write template");
    let o = run(&["campaign", "list", cs]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("conditions.csv:1:4") && err.contains("has no [truth] section"),
        "{err}"
    );
}

/// Slurm is usable here: root, the daemons' binaries and the start script.
fn slurm_available() -> Result<(), String> {
    let root_user = Command::new("id")
        .arg("-u")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
        .unwrap_or(false);
    if !root_user {
        return Err("not root (the test starts slurmctld and slurmd)".into());
    }
    for bin in [
        "/usr/sbin/slurmctld",
        "/usr/sbin/slurmd",
        "/usr/sbin/munged",
    ] {
        if !Path::new(bin).exists() {
            return Err(format!("{bin} is not installed (Debian: slurm-wlm, munge)"));
        }
    }
    Ok(())
}

#[test]
fn slurm_array_gives_the_local_results() {
    if let Err(why) = slurm_available() {
        if std::env::var("WIPERLAB_REQUIRE_SLURM").as_deref() == Ok("1") {
            panic!("WIPERLAB_REQUIRE_SLURM=1 but Slurm cannot run here: {why}");
        }
        println!("skipped: {why}");
        return;
    }
    let state = std::env::temp_dir().join("wiperlab-slurm");
    let start = Command::new("bash")
        .arg(root().join("tests/slurm/start.sh"))
        .arg(&state)
        .output()
        .expect("run tests/slurm/start.sh");
    ok(&start, "starting Slurm");
    // An array of two tasks, both running at once (--max-parallel 2). The test compares two runs
    // of the same job, so a tiny search suffices; the local test checks the fits' accuracy.
    let two = ["hard_fast_xypts.csv", "soft_fast_xypts.csv"];
    let via_slurm = temp_dir("slurm");
    let local = temp_dir("slurm_local");
    let cs = campaign_copy(via_slurm.path(), &two, Search::Tiny);
    let cl = campaign_copy(local.path(), &two, Search::Tiny);
    let (cs, cl) = (cs.to_str().expect("path"), cl.to_str().expect("path"));
    let out = ok(
        &run(&[
            "campaign",
            "slurm",
            cs,
            "--cpus-per-task",
            "1",
            "--max-parallel",
            "2",
            "--submit",
        ]),
        "campaign slurm --submit",
    );
    assert!(out.contains("submitted Slurm job"), "{out}");
    ok(&run(&["campaign", "run", cl, "--jobs", "2"]), "local run");
    // Poll the array through `campaign status` (squeue and the tasks' status files).
    let t0 = Instant::now();
    loop {
        let st = ok(&run(&["campaign", "status", cs]), "campaign status");
        if st.lines().last().is_some_and(|l| l.trim() == "2 done") {
            break;
        }
        assert!(
            !st.contains("failed") && t0.elapsed() < Duration::from_secs(600),
            "array not done after {:?}:\n{st}",
            t0.elapsed()
        );
        std::thread::sleep(Duration::from_secs(2));
    }
    ok(&run(&["campaign", "collect", cs]), "collect (Slurm)");
    ok(&run(&["campaign", "collect", cl]), "collect (local)");
    let a = read_table(&via_slurm.path().join("c/campaign.csv"));
    let b = read_table(&local.path().join("c/campaign.csv"));
    assert_eq!(a.len(), 2);
    for (ra, rb) in a.iter().zip(&b) {
        assert_eq!(ra["id"], rb["id"]);
        assert_eq!(ra["state"], "done");
        // Same binary, same generated job, same seed: the same fit, bit for bit.
        for col in [
            "C",
            "k1",
            "cost",
            "model",
            "peak_low_model_hz",
            "peak_high_model_hz",
        ] {
            assert_eq!(ra[col], rb[col], "{col} of {}", ra["id"]);
        }
    }
    let logs = via_slurm.path().join("c/slurm/logs");
    let n_logs = std::fs::read_dir(&logs).map_or(0, |d| d.count());
    assert_eq!(n_logs, 2, "one log per array task in {}", logs.display());
    let _ = Command::new("bash")
        .arg(root().join("tests/slurm/stop.sh"))
        .arg(&state)
        .output();
}
