//! Where every command's outputs land: beside its input (single files in the input's directory,
//! figures and tables in `reports/` there; a fit job's `reports_dir` moves its figures), never in
//! the working directory, and in `--out-dir` when it is given (the rule docs/results.md states).
//!
//! Each test runs the real binary with a working directory (`cwd/`) different from the directory
//! of its inputs (`proj/`), both in a fresh temp dir, and checks the exact files on both sides.

use crate::common;
use crate::common::{ok, root, s, temp_dir, wiperlab};

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Output;
use tempfile::TempDir;

/// A temp dir with `cwd/` (the working directory of every command) and `proj/` (the inputs),
/// removed on drop.
struct Tmp(TempDir);

impl Tmp {
    fn new(name: &str) -> Tmp {
        let t = temp_dir(&format!("outdir_{name}"));
        std::fs::create_dir_all(t.path().join("cwd")).expect("create cwd");
        std::fs::create_dir_all(t.path().join("proj")).expect("create proj");
        Tmp(t)
    }

    fn cwd(&self) -> PathBuf {
        self.0.path().join("cwd")
    }

    fn proj(&self) -> PathBuf {
        self.0.path().join("proj")
    }

    /// Runs `wiperlab args... --quiet` in `cwd/` and asserts exit code 0; returns stdout.
    fn ok(&self, args: &[&str]) -> String {
        ok(&self.run(args), &format!("wiperlab {args:?}"))
    }

    fn run(&self, args: &[&str]) -> Output {
        wiperlab(args)
            .arg("--quiet")
            .current_dir(self.cwd())
            .output()
            .expect("start the wiperlab binary")
    }

    /// Every file under the temp dir, relative to it, as `/`-joined strings.
    fn files(&self) -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        let mut stack = vec![self.0.path().to_path_buf()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).expect("read dir") {
                let p = e.expect("dir entry").path();
                if p.is_dir() {
                    stack.push(p);
                } else {
                    let rel = p.strip_prefix(self.0.path()).expect("under the temp dir");
                    out.insert(rel.to_string_lossy().replace('\\', "/"));
                }
            }
        }
        out
    }

    /// Files under `rel/` (relative to the temp dir), by name relative to `rel/`.
    fn files_under(&self, rel: &str) -> BTreeSet<String> {
        let prefix = format!("{rel}/");
        self.files()
            .into_iter()
            .filter_map(|f| f.strip_prefix(&prefix).map(str::to_string))
            .collect()
    }
}

/// The set of `names`.
fn set(names: &[&str]) -> BTreeSet<String> {
    names.iter().map(|n| n.to_string()).collect()
}

/// The shipped sample's import flags (fits/reversal.toml `[recording.import]`).
const SAMPLE_FLAGS: [&str; 10] = [
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
];

/// Copies the shipped sample recording to `proj/rec.csv`.
fn copy_sample(t: &Tmp) -> PathBuf {
    let rec = t.proj().join("rec.csv");
    std::fs::copy(
        root().join("data/reversal/wiper_reversal_sample_xypts.csv"),
        &rec,
    )
    .expect("copy the sample");
    rec
}

/// `import`, `init`, `spectrum` and `simulate` run from another directory write beside their
/// input: `import` and `init` their one file in the input's directory, `spectrum` and `simulate`
/// into `reports/<command>/<input stem>/` there; nothing lands in the working directory.
#[test]
fn import_init_spectrum_simulate_write_beside_their_input() {
    let t = Tmp::new("beside");
    let rec = copy_sample(&t);
    let blade = t.proj().join("blade.toml");
    std::fs::copy(root().join("data/reversal/blade_true.toml"), &blade).expect("copy the blade");
    let mut import = vec!["import", "../proj/rec.csv"];
    import.extend(SAMPLE_FLAGS);
    t.ok(&import);
    let mut init = vec!["init", "../proj/rec.csv"];
    init.extend(SAMPLE_FLAGS);
    t.ok(&init);
    // The canonical trace is read back by content detection (no --format).
    t.ok(&["spectrum", "../proj/rec.trace.csv", "--band", "500:5000"]);
    t.ok(&["simulate", s(&blade), "--window", "0.9,0.92"]);
    assert!(rec.exists());
    let files = t.files();
    assert!(
        files.iter().all(|f| f.starts_with("proj/")),
        "a file outside the input's directory: {files:?}"
    );
    for f in ["proj/rec.trace.csv", "proj/rec.job.toml"] {
        assert!(files.contains(f), "{f} missing: {files:?}");
    }
    let spectrum = t.files_under("proj/reports/spectrum/rec.trace");
    for f in [
        "psd.csv",
        "peaks.json",
        "psd_tip_rel_x.svg",
        "spectrogram_tip_rel_x.svg",
    ] {
        assert!(spectrum.contains(f), "spectrum's {f} missing: {spectrum:?}");
    }
    assert_eq!(
        t.files_under("proj/reports/simulate/blade"),
        set(&[
            "trace.csv",
            "transitions.csv",
            "tip_relative.svg",
            "phase.svg",
            "head_drop.svg"
        ])
    );
}

/// `--out-dir` puts each command's outputs in the directory given (created if need be), and
/// nothing beside the input.
#[test]
fn out_dir_moves_import_init_spectrum_and_simulate_outputs() {
    let t = Tmp::new("moved");
    copy_sample(&t);
    let mut import = vec!["import", "../proj/rec.csv", "--out-dir", "../o/import"];
    import.extend(SAMPLE_FLAGS);
    t.ok(&import);
    let mut init = vec!["init", "../proj/rec.csv", "--out-dir", "../o/init"];
    init.extend(SAMPLE_FLAGS);
    t.ok(&init);
    let trace = t.0.path().join("o/import/rec.trace.csv");
    t.ok(&["spectrum", s(&trace), "--out-dir", "../o/spectrum"]);
    let blade = root().join("data/reversal/blade_true.toml");
    t.ok(&[
        "simulate",
        s(&blade),
        "--window",
        "0.9,0.92",
        "--out-dir",
        "../o/simulate",
    ]);
    assert_eq!(t.files_under("proj"), set(&["rec.csv"]));
    assert_eq!(t.files_under("o/import"), set(&["rec.trace.csv"]));
    assert_eq!(t.files_under("o/init"), set(&["rec.job.toml"]));
    // The job written elsewhere names the recording so that it resolves from there.
    let job = std::fs::read_to_string(t.0.path().join("o/init/rec.job.toml")).expect("the job");
    let rec = t.proj().canonicalize().expect("proj").join("rec.csv");
    assert!(
        job.contains(&format!("file = {:?}", rec.display().to_string())),
        "{job}"
    );
    assert!(t.files_under("o/spectrum").contains("psd.csv"));
    assert!(t.files_under("o/simulate").contains("trace.csv"));
    assert!(t.files_under("cwd").is_empty());
    // -o and --out-dir together are refused before anything is read.
    let o = t.run(&["import", "../proj/rec.csv", "-o", "x.csv", "--out-dir", "d"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--out-dir"));
}

/// A quick job (a handful of model runs near the truth; the output places, not the fit, are
/// under test) at `proj/<file>` with `extra` lines after its name.
fn write_quick_job(t: &Tmp, file: &str, extra: &str) -> PathBuf {
    let data = root().join("data/reversal");
    let text = format!(
        "name = \"quick\"\n{extra}\nblade = \"{data}/blade_true.toml\"\n\n{recording}\n{spectrum}\n\
         [solver]\nrtol = 1e-7\natol = 1e-9\n\n[fit]\nparticles = 2\nswarm_iterations = 1\n\
         polish_iterations = 1\nseed = 3\nmodels = [\"blade2dof\"]\n\n[fit.parameters]\n\
         C = [0.4, 0.7]\nk1 = [0.02, 0.04]\n",
        data = data.display(),
        recording = common::sample_recording(),
        spectrum = common::spectrum_bands(&[
            ("low", [30.0, 300.0], 4096),
            ("high", [500.0, 5000.0], 2048)
        ]),
    );
    let p = t.proj().join(file);
    std::fs::write(&p, text).expect("write the quick job");
    p
}

/// `fit`, `report` and `explore` run from another directory: the result goes beside the job, the
/// figures, page and exploration into `reports/` beside the job; with `reports_dir` in the job
/// they go there (relative to the job), and with `--out-dir` into the directory given.
#[test]
fn fit_report_and_explore_write_beside_the_job() {
    let t = Tmp::new("fit");
    let job = write_quick_job(&t, "quick.toml", "");
    t.ok(&["fit", "../proj/quick.toml"]);
    t.ok(&["report", "../proj/quick.toml"]);
    t.ok(&["explore", "../proj/quick.toml", "--samples", "2"]);
    let files = t.files();
    assert!(
        files.iter().all(|f| f.starts_with("proj/")),
        "a file outside the job's directory: {files:?}"
    );
    assert!(files.contains("proj/quick.result.toml"), "{files:?}");
    let figures = t.files_under("proj/reports/quick");
    for f in [
        "index.html",
        "psd_low.svg",
        "psd_high.svg",
        "friction_law.svg",
        "psd_low.csv",
    ] {
        assert!(figures.contains(f), "{f} missing: {figures:?}");
    }
    let explore = t.files_under("proj/reports/explore/quick");
    for f in ["explore.csv", "sensitivity.csv", "reachability.svg"] {
        assert!(explore.contains(f), "{f} missing: {explore:?}");
    }

    // reports_dir = "../figs": relative to the job, wherever the command runs.
    let moved = write_quick_job(&t, "moved.toml", "reports_dir = \"../figs\"");
    std::fs::remove_file(t.proj().join("quick.result.toml")).expect("remove the result");
    t.ok(&["report", s(&moved), "--refit"]);
    assert!(t.files_under("figs/quick").contains("index.html"));
    assert!(t.files_under("figs/quick").contains("psd_high.svg"));
    assert!(t.proj().join("quick.result.toml").exists());

    // --out-dir wins over both.
    t.ok(&["fit", s(&job), "--out-dir", "../o/fit"]);
    t.ok(&["report", s(&job), "--out-dir", "../o/fit"]);
    t.ok(&[
        "explore",
        s(&job),
        "--samples",
        "2",
        "--out-dir",
        "../o/explore",
    ]);
    assert!(t.files_under("o/fit").contains("index.html"));
    assert!(t.files_under("o/fit").contains("psd_low.svg"));
    assert!(t.files_under("o/explore").contains("explore.csv"));
    assert!(t.files_under("cwd").is_empty());
}

/// A campaign writes `<name>/` beside the campaign file, or into `--out-dir` (given before or
/// after the subcommand), and its Slurm script passes that directory on to every task.
#[test]
fn campaign_writes_beside_the_campaign_file_or_in_out_dir() {
    let t = Tmp::new("campaign");
    let data = root().join("data");
    let template = std::fs::read_to_string(root().join("campaigns/example_template.toml"))
        .expect("the example template")
        .replace("\"../data/", &format!("\"{}/", data.display()));
    std::fs::write(t.proj().join("tpl.toml"), template).expect("write the template");
    std::fs::write(
        t.proj().join("camp.toml"),
        format!(
            "template = \"tpl.toml\"\nrecordings = [\"{d}/campaign/*_xypts.csv\"]\nconditions = \"{d}/campaign/conditions.csv\"\n",
            d = data.display()
        ),
    )
    .expect("write the campaign");
    t.ok(&["campaign", "collect", "../proj/camp.toml"]);
    assert_eq!(
        t.files_under("proj/camp"),
        set(&["campaign.csv", "report/index.html"])
    );
    t.ok(&[
        "campaign",
        "--out-dir",
        "../o",
        "collect",
        "../proj/camp.toml",
    ]);
    t.ok(&[
        "campaign",
        "slurm",
        "../proj/camp.toml",
        "--out-dir",
        "../o",
    ]);
    assert_eq!(
        t.files_under("o"),
        set(&["campaign.csv", "report/index.html", "slurm/array.sh"])
    );
    let script = std::fs::read_to_string(t.0.path().join("o/slurm/array.sh")).expect("the script");
    let given = script
        .split("--out-dir '")
        .nth(1)
        .and_then(|rest| rest.split('\'').next())
        .unwrap_or_else(|| panic!("no --out-dir in the task line:\n{script}"));
    assert!(Path::new(given).is_absolute(), "{script}");
    assert_eq!(
        Path::new(given)
            .canonicalize()
            .expect("the --out-dir exists"),
        t.0.path().join("o").canonicalize().expect("o/")
    );
    assert!(t.files_under("cwd").is_empty());
}

/// The shipped jobs keep their committed outputs where the docs show them: `reports_dir =
/// "../reports"` resolves to the repository's `reports/`, from the job file alone.
#[test]
fn shipped_jobs_write_to_the_repositorys_reports() {
    let reports = root().join("reports").canonicalize().expect("reports/");
    for job in [
        "reversal",
        "reversal_tracker",
        "seed_experiment",
        "seed_experiment_geometry",
        "seed_simulation",
    ] {
        let path = root().join(format!("fits/{job}.toml"));
        let loaded = wiperlab::job::LoadedJob::load(&path).expect("a shipped job");
        let dir = loaded.reports_dir().canonicalize().expect("reports_dir");
        assert_eq!(dir, reports, "{job}");
    }
    assert!(root().join("reports/reversal/psd_high.svg").exists());
    assert!(
        root()
            .join("reports/explore/seed_experiment_geometry/explore.csv")
            .exists()
    );
}
