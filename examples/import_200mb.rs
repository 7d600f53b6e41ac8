//! Benchmark: a ~200 MB DLTdv export imported and analysed by the real binary, with wall time and
//! peak memory (the child's maximum resident set size from `wait4`) written to
//! `reports/bench/import_200mb.md` with the machine it ran on.
//!
//! ```sh
//! cargo build --release && cargo run --release --example import_200mb
//! ```
//!
//! It runs the `wiperlab` binary beside its own folder (`target/release/wiperlab`, hence the
//! build first). About a minute on 2 cores; needs ~0.6 GB of free disk in the system temp dir and
//! about 1 GB of memory.
//!
//! The export is synthetic: 12 points of one camera, `%.6f` pixels as DLTdv writes them, rows until
//! the file holds 200,000,000 bytes, a few `NaN` gaps. The tip (`pt2`) carries a 1,200 Hz line of
//! known amplitude relative to the head (`pt1`), so the analysis has a known answer: the high band's
//! tip − head peak must be at 1,200 Hz within one Welch bin.

#[path = "../tests/common/fixtures.rs"]
mod fixtures;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// Bytes of the generated export (at least).
const TARGET_BYTES: u64 = 200_000_000;
/// Points in the export (one camera).
const POINTS: usize = 12;
/// Frame rate of the synthetic camera, Hz.
const FPS_HZ: f64 = 10_000.0;
/// The tip's line relative to the head, Hz (the known answer of the analysis).
const TIP_LINE_HZ: f64 = 1_200.0;
/// Welch segment length of the analysis (0.41 s, 2.44 Hz bins at 10 kHz).
const NPERSEG: usize = 4096;

/// A small deterministic generator (64-bit LCG, Knuth's MMIX constants) for the tracking noise.
struct Lcg(u64);

impl Lcg {
    /// Uniform in [−0.5, 0.5).
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// Writes the export; returns (frames, bytes).
fn write_export(path: &Path) -> (usize, u64) {
    let file = std::fs::File::create(path).expect("create the export");
    let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
    let header: Vec<String> = (1..=POINTS)
        .flat_map(|p| [format!("pt{p}_cam1_X"), format!("pt{p}_cam1_Y")])
        .collect();
    let mut bytes = 0u64;
    let line = header.join(",") + "\n";
    w.write_all(line.as_bytes()).expect("write");
    bytes += line.len() as u64;
    let mut rng = Lcg(1);
    let mut frames = 0usize;
    let mut row = String::with_capacity(POINTS * 24);
    while bytes < TARGET_BYTES {
        let t = frames as f64 / FPS_HZ;
        row.clear();
        // The head sweeps at 1 Hz with a 40 Hz chatter; each point follows it at its own offset.
        let head_x = 640.0 + 300.0 * (2.0 * std::f64::consts::PI * t).sin();
        let chatter = 2.0 * (2.0 * std::f64::consts::PI * 40.0 * t).sin();
        for p in 0..POINTS {
            // One frame in 5,000 loses a point (a short gap).
            if (frames + 997 * p).is_multiple_of(5000) {
                row.push_str(if p == 0 { "NaN,NaN" } else { ",NaN,NaN" });
                continue;
            }
            let mut x = head_x + chatter + 10.0 * p as f64 + 0.05 * rng.next();
            let y = 300.0 + 20.0 * p as f64 + 0.05 * rng.next();
            if p == 1 {
                x += 1.5 * (2.0 * std::f64::consts::PI * TIP_LINE_HZ * t).sin();
            }
            if p > 0 {
                row.push(',');
            }
            row.push_str(&format!("{x:.6},{y:.6}"));
        }
        row.push('\n');
        w.write_all(row.as_bytes()).expect("write");
        bytes += row.len() as u64;
        frames += 1;
    }
    w.flush().expect("flush");
    (frames, bytes)
}

/// One measured child run.
struct Run {
    what: &'static str,
    args: Vec<String>,
    wall_s: f64,
    max_rss_bytes: u64,
}

/// Runs `wiperlab args` (stdout to `stdout_file`), waits with `wait4` for its resource usage and
/// asserts exit code 0.
fn measure(what: &'static str, args: Vec<String>, stdout_file: &Path) -> Run {
    let out = std::fs::File::create(stdout_file).expect("stdout file");
    let start = Instant::now();
    let child = Command::new(wiperlab_exe())
        .args(&args)
        .stdout(out)
        .stderr(Stdio::inherit())
        .spawn()
        .expect("cannot start the wiperlab binary");
    let pid = child.id() as libc::pid_t;
    let mut status: libc::c_int = 0;
    // SAFETY: `rusage` is plain old data, valid zeroed; `wait4` fills it for our own child `pid`,
    // which nothing else waits for (the `Child` handle is dropped without waiting).
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    let wall_s = start.elapsed().as_secs_f64();
    drop(child);
    assert_eq!(r, pid, "wait4 failed");
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "wiperlab {args:?} failed (status {status})"
    );
    Run {
        what,
        args,
        wall_s,
        // Linux reports ru_maxrss in kilobytes (getrusage(2)).
        max_rss_bytes: usage.ru_maxrss as u64 * 1024,
    }
}

/// The `wiperlab` binary of the same build: `target/<profile>/wiperlab` beside this example's
/// `target/<profile>/examples/`.
fn wiperlab_exe() -> PathBuf {
    let exe = std::env::current_exe().expect("this example's path");
    let bin = exe
        .parent()
        .and_then(Path::parent)
        .expect("the example inside target/<profile>/examples")
        .join(format!("wiperlab{}", std::env::consts::EXE_SUFFIX));
    assert!(
        bin.is_file(),
        "{} not found: run `cargo build --release` first",
        bin.display()
    );
    bin
}

/// `cmd args` on stdout, trimmed, or `unknown`.
fn sh(cmd: &str, args: &[&str]) -> String {
    Command::new(cmd)
        .args(args)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}

/// The machine: CPU model, cores, memory, kernel.
fn machine() -> String {
    let lscpu = sh("lscpu", &[]);
    let model = lscpu
        .lines()
        .find_map(|l| l.strip_prefix("Model name:"))
        .map_or("unknown".into(), |m| m.trim().to_string());
    let mem = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|m| {
            m.lines()
                .find_map(|l| l.strip_prefix("MemTotal:"))
                .map(|v| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    format!(
        "{model}, `nproc` {}, MemTotal {mem}, Linux {}",
        sh("nproc", &[]),
        sh("uname", &["-r"])
    )
}

fn mb(bytes: u64) -> f64 {
    bytes as f64 / 1e6
}

fn main() {
    let tmp = fixtures::temp_dir("import_200mb");
    let dir: PathBuf = tmp.path().to_path_buf();
    let export = dir.join("big_xypts.csv");
    let t = Instant::now();
    let (frames, bytes) = write_export(&export);
    println!(
        "generated {} ({:.1} MB, {frames} frames) in {:.1} s",
        export.display(),
        mb(bytes),
        t.elapsed().as_secs_f64()
    );
    let s = |p: &Path| p.display().to_string();
    let calib = [
        "--fps",
        "10000",
        "--m-per-px",
        "1.5e-5",
        "--head",
        "pt1",
        "--tip",
        "pt2",
        "--quiet",
    ]
    .map(String::from);
    let trace = dir.join("big.trace.csv");
    let mut import = vec!["import".into(), s(&export), "-o".into(), s(&trace)];
    import.extend(calib.iter().cloned());
    let spectrum_args = |input: &Path, out: &str| -> Vec<String> {
        let mut a = vec![
            "spectrum".into(),
            s(input),
            "--band".into(),
            "30:300".into(),
            "--band".into(),
            "500:5000".into(),
            "--nperseg".into(),
            NPERSEG.to_string(),
            "--signal".into(),
            "tip_rel_x".into(),
            "--signal".into(),
            "head_x".into(),
            "--out-dir".into(),
            s(&dir.join(out)),
        ];
        if input == export {
            a.extend(calib.iter().cloned());
        }
        a
    };
    let runs = vec![
        measure(
            "import → canonical trace CSV",
            import,
            &dir.join("import.out"),
        ),
        measure(
            "spectrum of the export (import + Welch, peaks, spectrograms)",
            spectrum_args(&export, "spectrum_export"),
            &dir.join("spectrum_export.out"),
        ),
        measure(
            "spectrum of the canonical trace (content-detected)",
            spectrum_args(&trace, "spectrum_trace"),
            &dir.join("spectrum_trace.out"),
        ),
    ];
    // The trace holds every frame; the analysis finds the known line.
    let trace_rows = std::fs::read_to_string(&trace)
        .expect("the trace")
        .lines()
        .count();
    assert_eq!(trace_rows, frames + 1, "header + one row per frame");
    let bin_hz = FPS_HZ / NPERSEG as f64;
    for out in ["spectrum_export", "spectrum_trace"] {
        let peaks: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join(out).join("peaks.json")).expect("peaks.json"),
        )
        .expect("JSON");
        let high = peaks
            .as_array()
            .expect("a list")
            .iter()
            .find(|p| p["signal"] == "tip_rel_x" && p["band"] == "500:5000")
            .expect("tip_rel_x's high-band peak");
        let f = high["freq_hz"].as_f64().expect("freq_hz");
        assert!(
            (f - TIP_LINE_HZ).abs() <= bin_hz,
            "{out}: peak at {f} Hz, the export's line is at {TIP_LINE_HZ} Hz (bin {bin_hz} Hz)"
        );
    }
    let mut md = format!(
        "# Importing and analysing a 200 MB tracking export\n\n\
         Written by `cargo build --release && cargo run --release --example import_200mb` \
         (examples/import_200mb.rs), which generates the export, runs the commands below as child \
         processes and reads each one's peak resident memory (`ru_maxrss` from `wait4`).\n\n\
         - Export: synthetic DLTdv `xypts.csv`, {POINTS} points of one camera, {frames} frames at \
         10,000 frames/s ({:.1} s), {:.1} MB; the tip carries a {TIP_LINE_HZ} Hz line, which both \
         analyses find within one {bin_hz:.2} Hz bin.\n\
         - Machine: {}.\n\
         - wiperlab {}.\n\n\
         | step | wall time (s) | peak memory (MB) | peak / file size |\n|---|---|---|---|\n",
        frames as f64 / FPS_HZ,
        mb(bytes),
        machine(),
        env!("CARGO_PKG_VERSION"),
    );
    for r in &runs {
        md.push_str(&format!(
            "| {} | {:.1} | {:.0} | {:.2} |\n",
            r.what,
            r.wall_s,
            mb(r.max_rss_bytes),
            r.max_rss_bytes as f64 / bytes as f64
        ));
    }
    md.push_str("\nCommands (the export and outputs in a temp dir):\n\n```sh\n");
    for r in &runs {
        let args: Vec<String> = r.args.iter().map(|a| a.replace(&s(&dir), "$TMP")).collect();
        md.push_str(&format!("wiperlab {}\n", args.join(" ")));
    }
    md.push_str("```\n");
    println!("{md}");
    let report = fixtures::root().join("reports/bench/import_200mb.md");
    std::fs::write(&report, md).expect("write the report");
}
