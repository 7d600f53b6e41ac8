//! The bad-input table: every command of the real `wiperlab` binary, run as a child process on
//! input a user can get wrong, must exit with code 2 (bad input), say what is wrong in words that
//! name the file, flag or field as the user typed it, never panic, and write nothing.
//!
//! Each case runs in its own fresh temp directory (the working directory of the child), so that a
//! default output location (`reports/...`, `<stem>.trace.csv`, `<name>.result.toml`) would land
//! there: after the case the directory must hold exactly the files the case put in it. A case that
//! is not refused up front would start real work; every child is killed after [`TIMEOUT`] and the
//! case fails.
//!
//! Input files are written by the cases (small DLTdv, Tracker, DeepLabCut and canonical CSVs) or
//! are the shipped sample (`data/reversal/`), referenced by absolute path.

use crate::common::{root, stderr, temp_dir, wiperlab};

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Longest a refused input may take: validation happens before any simulation or fit.
const TIMEOUT: Duration = Duration::from_secs(30);

/// One row of the table.
struct Case {
    /// What is wrong, in a few words (printed when the case fails).
    what: &'static str,
    /// Files the case writes into its directory before running: (relative path, content).
    files: Vec<(&'static str, String)>,
    /// Arguments; `$D` is replaced by the case's directory, `$DATA` by the crate's `data/`.
    args: Vec<&'static str>,
    /// Words the error must contain (case-sensitive), after the same replacements.
    keys: Vec<&'static str>,
}

fn case(
    what: &'static str,
    files: Vec<(&'static str, String)>,
    args: &[&'static str],
    keys: &[&'static str],
) -> Case {
    Case {
        what,
        files,
        args: args.to_vec(),
        keys: keys.to_vec(),
    }
}

/// A small DLTdv `xypts` file: two points, `rows` frames of a 50 Hz wiggle in pixels.
fn dltdv(rows: usize) -> String {
    let mut s = String::from("pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y\n");
    for i in 0..rows {
        let w = (i as f64 * 0.0314).sin();
        s += &format!(
            "{:.3},{:.3},{:.3},{:.3}\n",
            200.0 + w,
            300.0,
            100.0 + 2.0 * w,
            700.0
        );
    }
    s
}

/// [`dltdv`] with `cell` replaced at data row `row` (0-based), column `col` (0-based).
fn dltdv_with(rows: usize, row: usize, col: usize, cell: &str) -> String {
    let text = dltdv(rows);
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[row + 1].split(',').map(str::to_string).collect();
    cells[col] = cell.to_string();
    lines[row + 1] = cells.join(",");
    lines.join("\n") + "\n"
}

/// A small canonical trace CSV (`t_s,head_x_m,...`) at 1000 frames/s.
fn canonical(rows: usize) -> String {
    let mut s = String::from("t_s,head_x_m,head_y_m,tip_x_m,tip_y_m\n");
    for i in 0..rows {
        let t = i as f64 * 1e-3;
        s += &format!("{t},{},0,{},-0.005\n", 1e-4 * (300.0 * t).sin(), 0.001);
    }
    s
}

/// A DeepLabCut CSV (three header rows) with one bodypart and the given likelihood cells.
fn deeplabcut(likelihoods: &[&str]) -> String {
    let mut s = String::from(
        "scorer,DLC_resnet50,DLC_resnet50,DLC_resnet50\n\
         bodyparts,head,head,head\n\
         coords,x,y,likelihood\n",
    );
    for (i, l) in likelihoods.iter().enumerate() {
        s += &format!("{i},{},{},{l}\n", 100.0 + i as f64, 200.0);
    }
    s
}

/// The main job's line that puts its figures in the repository's `reports/`.
const REPORTS_DIR_LINE: &str = "reports_dir = \"../reports\"";

/// The shipped main job with its `../data/` paths made absolute, its `reports_dir` dropped (the
/// default, `reports/` beside the job) and `edits` (old → new) applied.
fn job(edits: &[(&str, &str)]) -> String {
    let text =
        std::fs::read_to_string(root().join("fits/reversal.toml")).expect("read the main job");
    // Its figures go to the repository's reports/ (`reports_dir = "../reports"`); here they would
    // go to `reports/` beside the job, in the case's directory, where the listing would see them.
    let mut text = text
        .replace(
            "\"../data/",
            &format!("\"{}/", root().join("data").display()),
        )
        .replace(REPORTS_DIR_LINE, "");
    for (old, new) in edits {
        assert!(text.contains(old), "the main job has no {old:?}");
        text = text.replacen(old, new, 1);
    }
    text
}

/// The shipped blade file with `old` replaced by `new`.
fn blade(old: &str, new: &str) -> String {
    let text = std::fs::read_to_string(root().join("data/reversal/blade_true.toml"))
        .expect("read blade_true.toml");
    assert!(text.contains(old), "blade_true.toml has no {old:?}");
    text.replacen(old, new, 1)
}

const SAMPLE: &str = "$DATA/reversal/wiper_reversal_sample_xypts.csv";
const BLADE: &str = "$DATA/reversal/blade_true.toml";

/// The import flags that calibrate the sample (its job's settings).
const CAL: [&str; 10] = [
    "--format",
    "dltdv",
    "--fps",
    "10000",
    "--m-per-px",
    "1.5e-5",
    "--head",
    "pt1",
    "--tip",
    "pt2",
];

fn with_cal(head: &[&'static str], tail: &[&'static str]) -> Vec<&'static str> {
    let mut v = head.to_vec();
    v.extend_from_slice(&CAL);
    v.extend_from_slice(tail);
    v
}

fn import_cases() -> Vec<Case> {
    let d = |name: &'static str, text: String| vec![(name, text)];
    vec![
        case(
            "import: no such file",
            vec![],
            &["import", "$D/none.csv"],
            &["$D/none.csv"],
        ),
        case(
            "import: empty file",
            d("e.csv", String::new()),
            &["import", "$D/e.csv"],
            &["$D/e.csv"],
        ),
        case(
            "import: not a tracking export",
            d("x.csv", "hello world\nfoo bar\n".into()),
            &["import", "$D/x.csv"],
            &["$D/x.csv", "format"],
        ),
        case(
            "import: unknown --format",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--format", "nope"],
            &["--format", "nope", "dltdv"],
        ),
        case(
            "import: DLTdv without a frame rate",
            d("a.csv", dltdv(50)),
            &[
                "import",
                "$D/a.csv",
                "--format",
                "dltdv",
                "--m-per-px",
                "1e-4",
            ],
            &["--fps"],
        ),
        case(
            "import: DLTdv without a scale",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--format", "dltdv", "--fps", "1000"],
            &["--m-per-px"],
        ),
        case(
            "import: zero frame rate",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--fps", "0", "--m-per-px", "1e-4"],
            &["fps", "> 0"],
        ),
        case(
            "import: negative frame rate",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--fps=-5", "--m-per-px", "1e-4"],
            &["fps", "> 0"],
        ),
        case(
            "import: negative frame rate after a space (read as a flag)",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--fps", "-5", "--m-per-px", "1e-4"],
            &["'-5'"],
        ),
        case(
            "import: NaN frame rate",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--fps", "nan", "--m-per-px", "1e-4"],
            &["fps", "finite"],
        ),
        case(
            "import: zero scale",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--fps", "1000", "--m-per-px", "0"],
            &["m_per_px", "> 0"],
        ),
        case(
            "import: infinite scale",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--fps", "1000", "--m-per-px", "inf"],
            &["m_per_px", "finite"],
        ),
        case(
            "import: three values for --scale-points-px",
            d("a.csv", dltdv(50)),
            &[
                "import",
                "$D/a.csv",
                "--fps",
                "1000",
                "--scale-points-px",
                "1,2,3",
            ],
            &["--scale-points-px", "X1,Y1,X2,Y2"],
        ),
        case(
            "import: two scale points in one place",
            d("a.csv", dltdv(50)),
            &[
                "import",
                "$D/a.csv",
                "--fps",
                "1000",
                "--scale-points-px",
                "5,5,5,5",
                "--scale-distance-m",
                "0.01",
            ],
            &["scale_points_px"],
        ),
        case(
            "import: one value for --origin-px",
            d("a.csv", dltdv(50)),
            &[
                "import",
                "$D/a.csv",
                "--fps",
                "1000",
                "--m-per-px",
                "1e-4",
                "--origin-px",
                "7",
            ],
            &["--origin-px", "X,Y"],
        ),
        case(
            "import: --origin-px not a number",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--origin-px", "a,b"],
            &["--origin-px", "a"],
        ),
        case(
            "import: head point not in the file",
            d("a.csv", dltdv(50)),
            &[
                "import",
                "$D/a.csv",
                "--fps",
                "1000",
                "--m-per-px",
                "1e-4",
                "--head",
                "pt9",
            ],
            &["pt9", "pt1", "pt2"],
        ),
        case(
            "import: camera 3 of a one-camera file",
            d("a.csv", dltdv(50)),
            &[
                "import",
                "$D/a.csv",
                "--format",
                "dltdv",
                "--fps",
                "1000",
                "--m-per-px",
                "1e-4",
                "--camera",
                "3",
            ],
            &["camera", "3"],
        ),
        case(
            "import: a word in a number cell",
            d("a.csv", dltdv_with(50, 3, 2, "abc")),
            &["import", "$D/a.csv", "--fps", "1000", "--m-per-px", "1e-4"],
            &["$D/a.csv:5:3:", "pt2_cam1_X", "abc"],
        ),
        case(
            "import: a 1e308 outlier",
            d("a.csv", dltdv_with(50, 10, 0, "1e308")),
            &["import", "$D/a.csv", "--fps", "1000", "--m-per-px", "1e-4"],
            &["$D/a.csv", "pt1", "frame 11"],
        ),
        case(
            "import: a one-frame file",
            d("a.csv", dltdv(1)),
            &["import", "$D/a.csv", "--fps", "1000", "--m-per-px", "1e-4"],
            &["$D/a.csv", "frame"],
        ),
        case(
            "import: output path is the input",
            d("a.csv", dltdv(50)),
            &[
                "import",
                "$D/a.csv",
                "--fps",
                "1000",
                "--m-per-px",
                "1e-4",
                "-o",
                "$D/a.csv",
            ],
            &["$D/a.csv", "input"],
        ),
        case(
            "import: output into a missing directory",
            d("a.csv", dltdv(50)),
            &[
                "import",
                "$D/a.csv",
                "--fps",
                "1000",
                "--m-per-px",
                "1e-4",
                "-o",
                "$D/no/such/dir/t.csv",
            ],
            &["$D/no/such/dir"],
        ),
        case(
            "import: likelihood cut-off above 1",
            d("dlc.csv", deeplabcut(&["0.9"; 20])),
            &[
                "import",
                "$D/dlc.csv",
                "--fps",
                "100",
                "--m-per-px",
                "1e-3",
                "--min-likelihood",
                "1.7",
            ],
            &["likelihood", "1.7"],
        ),
        case(
            "import: likelihood above 1 in the file",
            d(
                "dlc.csv",
                deeplabcut(&["0.9", "0.9", "1.7", "0.9", "0.9", "0.9"]),
            ),
            &["import", "$D/dlc.csv", "--fps", "100", "--m-per-px", "1e-3"],
            &["$D/dlc.csv:6:", "likelihood", "1.7"],
        ),
        case(
            "import: missing --spec file",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--spec", "$D/spec.toml"],
            &["$D/spec.toml"],
        ),
        case(
            "import: --spec with a TOML syntax error",
            vec![
                ("a.csv", dltdv(50)),
                ("spec.toml", "fps_hz = 1000\nm_per_px = [\n".into()),
            ],
            &["import", "$D/a.csv", "--spec", "$D/spec.toml"],
            &["$D/spec.toml:"],
        ),
        case(
            "import: --spec with an unknown field",
            vec![
                ("a.csv", dltdv(50)),
                ("spec.toml", "fps_hz = 1000\nfsp_hz = 3\n".into()),
            ],
            &["import", "$D/a.csv", "--spec", "$D/spec.toml"],
            &["$D/spec.toml:2:", "fsp_hz"],
        ),
        case(
            "import: --spec with a string for a number",
            vec![
                ("a.csv", dltdv(50)),
                ("spec.toml", "fps_hz = \"fast\"\n".into()),
            ],
            &["import", "$D/a.csv", "--spec", "$D/spec.toml"],
            &["$D/spec.toml:1:", "fast"],
        ),
        case(
            "import: zero time unit",
            d("c.csv", canonical(100)),
            &[
                "import",
                "$D/c.csv",
                "--format",
                "generic",
                "--time-to-s",
                "0",
            ],
            &["time_to_s"],
        ),
        case(
            "import: canonical trace with time going backwards",
            d(
                "c.trace.csv",
                canonical(10).replace("\n0.003,", "\n0.0005,"),
            ),
            &["import", "$D/c.trace.csv", "--describe"],
            &["$D/c.trace.csv", "t_s"],
        ),
        case(
            "import: canonical trace with a short row",
            d(
                "c.trace.csv",
                canonical(10).replace("\n0.004,", "\n0.004\n0.0041,"),
            ),
            &["import", "$D/c.trace.csv", "--describe"],
            &["$D/c.trace.csv:"],
        ),
        case(
            "import: unknown flag",
            d("a.csv", dltdv(50)),
            &["import", "$D/a.csv", "--fsp", "1000"],
            &["--fsp"],
        ),
    ]
}

fn spectrum_cases() -> Vec<Case> {
    let s = |what, tail: &[&'static str], keys| {
        case(what, vec![], &with_cal(&["spectrum", SAMPLE], tail), keys)
    };
    vec![
        s(
            "spectrum: --nperseg 4",
            &["--nperseg", "4"],
            &["--nperseg 4"],
        ),
        s(
            "spectrum: --nperseg 0",
            &["--nperseg", "0"],
            &["--nperseg 0"],
        ),
        s(
            "spectrum: --nperseg 1",
            &["--nperseg", "1"],
            &["--nperseg 1"],
        ),
        s(
            "spectrum: --nperseg past the record",
            &["--nperseg", "1000000000"],
            &["--nperseg 1000000000"],
        ),
        s(
            "spectrum: inverted band",
            &["--band", "300:30"],
            &["--band 300:30", "swapped", "did you mean --band 30:300?"],
        ),
        s(
            "spectrum: band above Nyquist",
            &["--band", "100:6000"],
            &["Nyquist", "<= 5000 Hz", "10000 Hz sample rate"],
        ),
        s(
            "spectrum: negative band",
            &["--band=-10:100"],
            &["--band -10:100"],
        ),
        s(
            "spectrum: band not a range",
            &["--band", "abc"],
            &["--band", "abc"],
        ),
        s(
            "spectrum: --noverlap not below nperseg",
            &["--nperseg", "1024", "--noverlap", "1024"],
            &["--noverlap"],
        ),
        s(
            "spectrum: unknown window",
            &["--window", "nope"],
            &["--window", "nope"],
        ),
        s(
            "spectrum: --nfft below nperseg",
            &["--nperseg", "1024", "--nfft", "512"],
            &["--nfft"],
        ),
        s(
            "spectrum: negative --max-fill",
            &["--max-fill=-1"],
            &["--max-fill"],
        ),
        case(
            "spectrum: no such file",
            vec![],
            &["spectrum", "$D/none.csv"],
            &["$D/none.csv"],
        ),
        case(
            "spectrum: fewer frames than one segment",
            vec![("c.trace.csv", canonical(6))],
            &["spectrum", "$D/c.trace.csv"],
            &["$D/c.trace.csv", "frames"],
        ),
    ]
}

fn simulate_cases() -> Vec<Case> {
    let b = |name: &'static str, old: &str, new: &str| vec![(name, blade(old, new))];
    vec![
        case(
            "simulate: no such blade file",
            vec![],
            &["simulate", "$D/b.toml"],
            &["$D/b.toml"],
        ),
        case(
            "simulate: negative head mass",
            b("b.toml", "head_mass_kg = 0.15\n", "head_mass_kg = -0.15\n"),
            &["simulate", "$D/b.toml"],
            &["$D/b.toml", "head_mass_kg", "-0.15"],
        ),
        case(
            "simulate: zero lever arm",
            b("b.toml", "l1_m = 0.002\n", "l1_m = 0.0\n"),
            &["simulate", "$D/b.toml"],
            &["$D/b.toml", "l1_m"],
        ),
        case(
            "simulate: NaN stiffness",
            b(
                "b.toml",
                "k1_nm_per_rad = 0.029748408887917077\n",
                "k1_nm_per_rad = nan\n",
            ),
            &["simulate", "$D/b.toml"],
            &["$D/b.toml", "k1_nm_per_rad"],
        ),
        case(
            "simulate: misspelt field",
            b("b.toml", "l1_m = 0.002\n", "l1_m = 0.002\nl3_m = 0.001\n"),
            &["simulate", "$D/b.toml"],
            &["$D/b.toml:", "l3_m"],
        ),
        case(
            "simulate: TOML syntax error",
            b("b.toml", "l2_m = 0.004\n", "l2_m = 0.004.1\n"),
            &["simulate", "$D/b.toml"],
            &["$D/b.toml:"],
        ),
        case(
            "simulate: unknown friction law",
            b("b.toml", "law = \"exponential\"", "law = \"coulombish\""),
            &["simulate", "$D/b.toml"],
            &["$D/b.toml:", "coulombish"],
        ),
        case(
            "simulate: a friction law without one of its keys",
            b(
                "b.toml",
                "law = \"exponential\"",
                "law = \"stribeck\"\nv_s_m_per_s = 0.1",
            ),
            &["simulate", "$D/b.toml"],
            &[
                "$D/b.toml:",
                "stribeck",
                "`b_s_per_m` (known: a, c, v_s_m_per_s, delta); missing delta",
            ],
        ),
        case(
            "simulate: --window with one value",
            vec![],
            &["simulate", BLADE, "--window", "1.83"],
            &["--window", "T0,T1"],
        ),
        case(
            "simulate: --window backwards",
            vec![],
            &["simulate", BLADE, "--window", "2.0,1.9"],
            &["--window"],
        ),
        case(
            "simulate: zero --fps",
            vec![],
            &["simulate", BLADE, "--fps", "0"],
            &["--fps"],
        ),
        case(
            "simulate: zero --rtol",
            vec![],
            &["simulate", BLADE, "--rtol", "0"],
            &["--rtol"],
        ),
        case(
            "simulate: negative --atol",
            vec![],
            &["simulate", BLADE, "--atol=-1e-9"],
            &["--atol"],
        ),
        case(
            "simulate: unknown --model",
            vec![],
            &["simulate", BLADE, "--model", "blade3dof"],
            &["--model", "blade3dof"],
        ),
        case(
            "simulate: unknown --stick",
            vec![],
            &["simulate", BLADE, "--stick", "glue"],
            &["--stick", "glue"],
        ),
    ]
}

fn modes_cases() -> Vec<Case> {
    vec![
        case(
            "modes: no such blade file",
            vec![],
            &["modes", "$D/b.toml"],
            &["$D/b.toml"],
        ),
        case(
            "modes: negative slip speed",
            vec![],
            &["modes", BLADE, "--speeds=-0.1"],
            &["--speeds", "-0.1"],
        ),
        case(
            "modes: NaN slip speed",
            vec![],
            &["modes", BLADE, "--speeds", "0.1,nan"],
            &["--speeds", "NaN"],
        ),
    ]
}

fn fit_cases() -> Vec<Case> {
    let j = |edits: &[(&str, &str)]| vec![("job.toml", job(edits))];
    let fit = &["fit", "$D/job.toml", "--quiet"][..];
    let mut cases = vec![
        case(
            "fit: no such job",
            vec![],
            &["fit", "$D/job.toml"],
            &["$D/job.toml"],
        ),
        case(
            "fit: TOML syntax error",
            j(&[("name = \"reversal\"", "name = \"reversal")]),
            fit,
            &["$D/job.toml:4:"],
        ),
        case(
            "fit: unknown parameter",
            j(&[("C = [0.1, 1.0]", "C = [0.1, 1.0]\nZ = [0, 1]")]),
            fit,
            &["$D/job.toml:", "'Z'"],
        ),
        case(
            "fit: bounds the wrong way round",
            j(&[("k1 = [0.005, 0.15]", "k1 = [0.1, 0.01]")]),
            fit,
            &["$D/job.toml:", "'k1'", "lower < upper"],
        ),
        case(
            "fit: a freed head mass that may be zero",
            j(&[("C = [0.1, 1.0]", "C = [0.1, 1.0]\nhead_mass = [0.0, 0.2]")]),
            fit,
            &["$D/job.toml:", "'head_mass'", "> 0"],
        ),
        case(
            "explore: a freed head mass that may be zero",
            j(&[("C = [0.1, 1.0]", "C = [0.1, 1.0]\nhead_mass = [0.0, 0.2]")]),
            &["explore", "$D/job.toml", "--out-dir", "$D/out"],
            &["$D/job.toml:", "'head_mass'", "> 0"],
        ),
        case(
            "explore: no samples",
            j(&[]),
            &[
                "explore",
                "$D/job.toml",
                "--samples",
                "0",
                "--out-dir",
                "$D/out",
            ],
            &["--samples 0"],
        ),
        case(
            "fit: a friction parameter the blade's law lacks",
            j(&[("C = [0.1, 1.0]", "C = [0.1, 1.0]\nD = [0.0, 1.0]")]),
            fit,
            &[
                "$D/job.toml:",
                "'D'",
                "friction law `exponential`",
                "law = \"exponential_viscous\"",
            ],
        ),
        case(
            "fit: an unknown friction law in [fit] laws",
            j(&[(
                "\nmodels = [",
                "\nlaws = [\"exponential\", \"stribek\"]\nmodels = [",
            )]),
            fit,
            &[
                "$D/job.toml:",
                "[fit] laws",
                "'stribek'",
                "known: exponential, exponential_viscous, stribeck",
            ],
        ),
        case(
            "fit: a friction parameter no law in [fit] laws has",
            j(&[
                (
                    "\nmodels = [",
                    "\nlaws = [\"exponential\", \"exponential_viscous\"]\nmodels = [",
                ),
                ("C = [0.1, 1.0]", "C = [0.1, 1.0]\ndelta = [0.5, 2.0]"),
            ]),
            fit,
            &[
                "$D/job.toml:",
                "'delta'",
                "[fit] laws",
                "exponential_viscous (A, B, C, D)",
                "law \"stribeck\"",
            ],
        ),
        case(
            "fit: a law named in [fit] models instead of [fit] laws",
            j(&[(
                "\"blade2dof\", \"blade2dof+shoulder\"]",
                "\"blade2dof@stribeck\"]",
            )]),
            fit,
            &["$D/job.toml:", "blade2dof@stribeck", "[fit] laws"],
        ),
        case(
            "fit: lip mass freed beside the k1 it holds",
            j(&[("C = [0.1, 1.0]", "C = [0.1, 1.0]\nlip_mass = [1e-4, 1e-3]")]),
            fit,
            &["$D/job.toml:", "'lip_mass'", "'k1'"],
        ),
        case(
            "fit: job name that climbs out of the directory",
            j(&[("name = \"reversal\"", "name = \"../../escape\"")]),
            fit,
            &["$D/job.toml:", "name", "../../escape"],
        ),
        case(
            "fit: band with nperseg 0",
            j(&[("nperseg = 4096", "nperseg = 0")]),
            fit,
            &["$D/job.toml:", "nperseg"],
        ),
        case(
            "fit: band with nperseg past the record",
            j(&[("nperseg = 4096", "nperseg = 1000000000")]),
            fit,
            &["$D/job.toml", "nperseg", "1000000000"],
        ),
        case(
            "fit: inverted band",
            j(&[("range_hz = [30.0, 300.0]", "range_hz = [300.0, 30.0]")]),
            fit,
            &["$D/job.toml:", "range_hz"],
        ),
        case(
            "fit: band above Nyquist",
            j(&[("range_hz = [500.0, 5000.0]", "range_hz = [500.0, 50000.0]")]),
            fit,
            &["$D/job.toml", "Nyquist"],
        ),
        case(
            "fit: recording that does not exist",
            j(&[("wiper_reversal_sample_xypts.csv", "no_such_xypts.csv")]),
            fit,
            &["no_such_xypts.csv"],
        ),
        case(
            "fit: blade file that does not exist",
            j(&[("reversal/blade.toml", "reversal/no_blade.toml")]),
            fit,
            &["no_blade.toml"],
        ),
        case(
            "fit: unknown model",
            j(&[("\"head1dof\", ", "\"head3dof\", ")]),
            fit,
            &["$D/job.toml:", "head3dof"],
        ),
        case(
            "fit: unknown signal",
            j(&[("signal = \"tip_rel_x\"", "signal = \"tip_rel_z\"")]),
            fit,
            &["$D/job.toml:", "tip_rel_z"],
        ),
        case(
            "fit: t0_s outside the drive's period",
            j(&[("t0_s = 0.9434198694385137", "t0_s = 100.0")]),
            fit,
            &["$D/job.toml", "t0_s"],
        ),
        case(
            "fit: no particles",
            j(&[("particles = 24", "particles = 0")]),
            fit,
            &["$D/job.toml:", "particles"],
        ),
        case(
            "fit: no restarts",
            j(&[("restarts = 3", "restarts = 0")]),
            fit,
            &["$D/job.toml:", "restarts"],
        ),
        case(
            "fit: weights without the features objective",
            j(&[(
                "[fit.uncertainty]",
                "[fit.weights]\npeak = 2.0\n[fit.uncertainty]",
            )]),
            fit,
            &["$D/job.toml:", "weights", "objective = \"features\""],
        ),
        case(
            "fit: unknown objective",
            j(&[("restarts = 3", "restarts = 3\nobjective = \"chi2\"")]),
            fit,
            &["$D/job.toml:", "chi2", "likelihood", "features"],
        ),
        case(
            "fit: negative iterations",
            j(&[("polish_iterations = 60", "polish_iterations = -3")]),
            fit,
            &["$D/job.toml:", "-3"],
        ),
        case(
            "fit: unknown uncertainty method",
            j(&[("method = \"profile\"", "method = \"jackknife\"")]),
            fit,
            &["$D/job.toml:", "jackknife"],
        ),
        case(
            "fit: a tempering ladder of no rungs",
            j(&[(
                "method = \"profile\"",
                "method = \"mcmc\"\ntemperatures = 0",
            )]),
            fit,
            &[
                "$D/job.toml:",
                "temperatures",
                "1 (the plain ensemble) to 16",
            ],
        ),
        case(
            "fit: a local CMA-ES run of one evaluation",
            j(&[(
                "local = \"cmaes\"              #",
                "local = \"cmaes\"\nlocal_evaluations = 1 #",
            )]),
            fit,
            &["$D/job.toml:", "local_evaluations", ">= 2"],
        ),
        case(
            "fit: an unknown local search",
            j(&[("local = \"cmaes\"              #", "local = \"bfgs\" #")]),
            fit,
            &["$D/job.toml:", "local", "nelder-mead", "cmaes"],
        ),
        case(
            "fit: a local search beside the CMA-ES search",
            j(&[(
                "local = \"cmaes\"              #",
                "method = \"cmaes\"\nlocal = \"cmaes\" #",
            )]),
            fit,
            &["$D/job.toml:", "local", "no swarm"],
        ),
        case(
            "fit: a joint signal that shares the fit's signal's tracked coordinate",
            j(&[(
                "[fit.uncertainty]",
                "[fit.likelihood]\njoint_signals = [\"tip_x\"]\n\n[fit.uncertainty]",
            )]),
            fit,
            &[
                "$D/job.toml:",
                "joint_signals",
                "\"tip_x\" shares a tracked coordinate with \"tip_rel_x\"",
            ],
        ),
        case(
            "fit: an unknown joint signal",
            j(&[(
                "[fit.uncertainty]",
                "[fit.likelihood]\njoint_signals = [\"head_z\"]\n\n[fit.uncertainty]",
            )]),
            fit,
            &["$D/job.toml:", "head_z", "head_y"],
        ),
        case(
            "fit: joint signals beside the bootstrap",
            j(&[(
                "method = \"profile\"",
                "method = \"bootstrap\"\nbootstrap = 8\n\n[fit.likelihood]\njoint_signals = [\"head_y\"]",
            )]),
            fit,
            &["$D/job.toml:", "joint_signals", "bootstrap", "laplace"],
        ),
        case(
            "fit: a local stage's tolerance of zero",
            j(&[("local_rtol = 1e-7", "local_rtol = 0.0")]),
            fit,
            &["$D/job.toml:", "local_rtol must be in (0, 1)", "0"],
        ),
        case(
            "fit: a local stage's tolerance without the local stage",
            j(&[(
                "local = \"cmaes\"              #",
                "local = \"nelder-mead\" #",
            )]),
            fit,
            &["$D/job.toml:", "local_rtol", "needs local = \"cmaes\""],
        ),
        case(
            "fit: an unknown swarm cost",
            j(&[("local = \"cmaes\"              #", "swarm_cost = \"nll\" #")]),
            fit,
            &["$D/job.toml:", "swarm cost", "features", "likelihood"],
        ),
        case(
            "fit: a swarm cost beside the CMA-ES search",
            j(&[
                (
                    "local = \"cmaes\"              #",
                    "method = \"cmaes\"\nswarm_cost = \"likelihood\" #",
                ),
                ("local_rtol = 1e-7", "#"),
            ]),
            fit,
            &["$D/job.toml:", "swarm_cost", "no swarm"],
        ),
        case(
            "fit: negative solver tolerance",
            j(&[("rtol = 1e-8", "rtol = -1e-8")]),
            fit,
            &["$D/job.toml", "rtol"],
        ),
        case(
            "fit: unknown solver method",
            j(&[("atol = 1e-10", "atol = 1e-10\nmethod = \"rk4\"")]),
            fit,
            &["$D/job.toml:", "rk4", "dop853"],
        ),
        case(
            "fit: lift-off margin out of range",
            j(&[("atol = 1e-10", "atol = 1e-10\nlift_off_margin = 1.5")]),
            fit,
            &["$D/job.toml:", "lift_off_margin", "between 0 and 1"],
        ),
        case(
            "simulate: unknown --method",
            vec![],
            &["simulate", BLADE, "--method", "rk4"],
            &["--method", "dop853"],
        ),
        case(
            "fit: swarm tolerance out of range",
            j(&[("swarm_rtol = 1e-6", "swarm_rtol = 0.0")]),
            fit,
            &["$D/job.toml:", "swarm_rtol"],
        ),
        case(
            "fit: block means without the time-domain term",
            j(&[(
                "method = \"profile\"",
                "method = \"profile\"\n[fit.likelihood]\nblock_s = 0.02",
            )]),
            fit,
            &["$D/job.toml:", "block_s", "time_domain = true"],
        ),
        case(
            "fit: block length zero",
            j(&[(
                "method = \"profile\"",
                "method = \"profile\"\n[fit.likelihood]\ntime_domain = true\nblock_s = 0.0",
            )]),
            fit,
            &["$D/job.toml:", "block_s", "> 0 s"],
        ),
        case(
            "fit: frame rate zero in the job",
            j(&[("fps_hz = 10000.0", "fps_hz = 0.0")]),
            fit,
            &["$D/job.toml", "fps_hz"],
        ),
        case(
            "fit: head point not in the recording",
            j(&[("head = \"pt1\"", "head = \"pt7\"")]),
            fit,
            &["pt7", "pt1"],
        ),
        case(
            "fit: the result path is a directory",
            {
                let mut f = j(&[]);
                f.push(("reversal.result.toml/keep", String::new()));
                f
            },
            fit,
            &["$D/reversal.result.toml"],
        ),
        case(
            "fit: unknown flag",
            j(&[]),
            &["fit", "$D/job.toml", "--jsn"],
            &["--jsn"],
        ),
        case(
            "report: no result and no --refit",
            j(&[]),
            &["report", "$D/job.toml", "--quiet"],
            &["--refit"],
        ),
    ];
    cases.extend(prior_cases());
    cases
}

/// `[fit.priors]` a user can get wrong: each names the job file (or the rig file) with its line
/// and the key.
fn prior_cases() -> Vec<Case> {
    let fit = &["fit", "$D/job.toml", "--quiet"][..];
    let with = |priors: &str| job(&[("[truth]", &format!("[fit.priors]\n{priors}\n\n[truth]"))]);
    let rig = "[fit.priors.friction_curve]\nfile = \"rig.csv\"\nspeed_column = \"v\"\n\
               coefficient_column = \"mu\"";
    vec![
        case(
            "fit: a prior on a parameter the job does not fit",
            vec![(
                "job.toml",
                with("c0 = { normal = { mean = 2.0, sd = 0.5 } }"),
            )],
            fit,
            &["$D/job.toml:", "c0", "does not fit"],
        ),
        case(
            "fit: a prior with a zero sd",
            vec![(
                "job.toml",
                with("k1 = { normal = { mean = 0.03, sd = 0.0 } }"),
            )],
            fit,
            &["$D/job.toml:", "k1", "sd must be > 0"],
        ),
        case(
            "fit: a log-normal prior on a parameter whose bounds include 0",
            vec![(
                "job.toml",
                job(&[
                    ("C = [0.1, 1.0]", "C = [0.1, 1.0]\nc0 = [0.0, 5.0]"),
                    (
                        "[truth]",
                        "[fit.priors]\nc0 = { lognormal = { median = 2.0, sd_log = 0.3 } }\n\n[truth]",
                    ),
                ]),
            )],
            fit,
            &["$D/job.toml:", "c0", "log-normal", "<= 0"],
        ),
        case(
            "fit: an unknown prior family",
            vec![("job.toml", with("k1 = { uniform = { lower = 0.01 } }"))],
            fit,
            &["$D/job.toml:", "k1", "`normal` or `lognormal`"],
        ),
        case(
            "fit: priors beside the features objective",
            vec![(
                "job.toml",
                job(&[
                    ("restarts = 3 ", "objective = \"features\"\nrestarts = 3 "),
                    (
                        "[truth]",
                        "[fit.priors]\nk1 = { normal = { mean = 0.03, sd = 0.01 } }\n\n[truth]",
                    ),
                ]),
            )],
            fit,
            &["$D/job.toml:", "[fit.priors]", "likelihood"],
        ),
        case(
            "fit: a rig curve without the coefficient's 1σ",
            vec![
                ("job.toml", with(rig)),
                ("rig.csv", "v,mu\n0.01,0.5\n".into()),
            ],
            fit,
            &["$D/job.toml:", "friction_curve", "sd_column"],
        ),
        case(
            "fit: a rig curve with a cell that is no number",
            vec![
                ("job.toml", with(&format!("{rig}\nsd = 0.05"))),
                ("rig.csv", "v,mu\n0.01,0.5\n0.02,x\n".into()),
            ],
            fit,
            &["$D/rig.csv:3:", "'mu'", "'x'"],
        ),
    ]
}

fn other_cases() -> Vec<Case> {
    vec![
        case(
            "campaign: no such campaign file",
            vec![],
            &["campaign", "list", "$D/c.toml"],
            &["$D/c.toml"],
        ),
        case(
            "campaign: TOML syntax error",
            vec![("c.toml", "name = \"x\nrecordings = 3\n".into())],
            &["campaign", "list", "$D/c.toml"],
            &["$D/c.toml:1:"],
        ),
        case(
            "bench: blade file that does not exist",
            vec![],
            &[
                "bench",
                "--quick",
                "--blade",
                "$D/b.toml",
                "--out-dir",
                "$D/out",
            ],
            &["$D/b.toml"],
        ),
        case(
            "completions: unknown shell",
            vec![],
            &["completions", "tcsh-nope"],
            &["tcsh-nope"],
        ),
        case("no command", vec![], &[], &["Usage"]),
        case("unknown command", vec![], &["fitt"], &["fitt"]),
    ]
}

/// Every file under `dir`, relative, sorted.
fn listing(dir: &Path) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("read temp dir") {
            let p = e.expect("dir entry").path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.strip_prefix(dir).expect("under dir").to_path_buf());
            }
        }
    }
    out
}

/// Runs `args` in `dir` with an empty standard input and a time limit: (exit code, stderr).
fn run(dir: &Path, args: &[String]) -> (Option<i32>, String) {
    let start = Instant::now();
    let o = wiperlab(args)
        .current_dir(dir)
        .write_stdin("")
        .timeout(TIMEOUT)
        .output()
        .expect("start the wiperlab binary");
    let err = stderr(&o);
    if start.elapsed() >= TIMEOUT {
        return (
            None,
            format!("TIMED OUT after {TIMEOUT:?}; stderr so far:\n{err}"),
        );
    }
    (o.status.code(), err)
}

/// Runs one case; `Err` says how it failed.
fn check(n: usize, c: &Case) -> Result<(), String> {
    let tmp = temp_dir(&format!("bad_{n}"));
    let dir = tmp.path();
    for (rel, text) in &c.files {
        let p = dir.join(rel);
        std::fs::create_dir_all(p.parent().expect("parent")).expect("create parent");
        std::fs::write(&p, text).expect("write case file");
    }
    let before = listing(dir);
    let d = dir.display().to_string();
    let data = root().join("data").display().to_string();
    let sub = |s: &str| s.replace("$DATA", &data).replace("$D", &d);
    let args: Vec<String> = c.args.iter().map(|a| sub(a)).collect();
    let (code, err) = run(dir, &args);
    let after = listing(dir);
    let mut why = Vec::new();
    if code != Some(2) {
        why.push(format!("exit code {code:?}, expected 2"));
    }
    if !err.starts_with("error") && !err.contains("Usage:") {
        why.push("stderr does not start with an error".into());
    }
    if err.contains("panicked") {
        why.push("it panicked".into());
    }
    for k in &c.keys {
        if !err.contains(&sub(k)) {
            why.push(format!("the message lacks {:?}", sub(k)));
        }
    }
    if after != before {
        let new: Vec<_> = after.difference(&before).collect();
        why.push(format!("it wrote {new:?}"));
    }
    if why.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "[{n}] {}: {}\n    wiperlab {}\n    stderr: {}",
            c.what,
            why.join("; "),
            args.join(" "),
            err.trim_end().replace('\n', "\n            ")
        ))
    }
}

#[test]
fn every_bad_input_is_refused_with_exit_2_naming_what_is_wrong_and_writes_nothing() {
    let cases: Vec<Case> = [
        import_cases(),
        spectrum_cases(),
        simulate_cases(),
        modes_cases(),
        fit_cases(),
        other_cases(),
    ]
    .into_iter()
    .flatten()
    .collect();
    assert!(cases.len() >= 60, "the table has {} cases", cases.len());
    let failures: Vec<String> = cases
        .iter()
        .enumerate()
        .filter_map(|(n, c)| check(n, c).err())
        .collect();
    println!("{} bad-input cases, {} failed", cases.len(), failures.len());
    assert!(
        failures.is_empty(),
        "{} of {} bad-input cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
