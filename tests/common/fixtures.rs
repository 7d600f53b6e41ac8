//! Fixtures shared by the integration tests and the `examples/` tools (which include this file by
//! path): the repository root, temp dirs, the shipped sample's blade, model-made recordings written
//! as DLTdv exports, and the job sections that read them.
#![allow(dead_code)] // each test file and tool uses a different subset

use std::path::{Path, PathBuf};

/// The repository root (the crate's manifest directory): the working directory of the binary under
/// test, and where `data/`, `fits/` and `docs/` are.
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh directory `wiperlab_<tag>_XXXXXX` in the system temp dir, removed with its content
/// when dropped.
pub fn temp_dir(tag: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("wiperlab_{tag}_"))
        .tempdir()
        .expect("create a temp dir")
}

/// Writes `content` to `dir/rel` (creating its parent folders) and returns the path.
pub fn write(dir: &Path, rel: &str, content: &str) -> PathBuf {
    let p = dir.join(rel);
    if let Some(parent) = p.parent() {
        std::fs::create_dir_all(parent).expect("create the file's folder");
    }
    std::fs::write(&p, content).unwrap_or_else(|e| panic!("write {}: {e}", p.display()));
    p
}

/// `join` and `write` on a temp dir, as on its path.
pub trait TempDirExt {
    /// `dir/rel`.
    fn join(&self, rel: impl AsRef<Path>) -> PathBuf;
    /// Writes `content` to `dir/rel` ([`write`]) and returns the path.
    fn write(&self, rel: &str, content: &str) -> PathBuf;
}

impl TempDirExt for tempfile::TempDir {
    fn join(&self, rel: impl AsRef<Path>) -> PathBuf {
        self.path().join(rel)
    }

    fn write(&self, rel: &str, content: &str) -> PathBuf {
        write(self.path(), rel, content)
    }
}

/// A path as `&str` (the temp dir and the clone have UTF-8 paths), for argument lists.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 path")
}

/// The project's shared data folder, `../shared` beside the clone (`/work/shared`).
pub fn shared_dir() -> PathBuf {
    root().join("../shared")
}

/// `../shared/<rel>`, or `None` (after printing why) when the shared folder is not beside the
/// clone, so tests that need it return early and pass. A file missing from a present shared folder
/// is a broken fixture and fails the test.
pub fn shared(rel: &str) -> Option<PathBuf> {
    let dir = shared_dir();
    if !dir.is_dir() {
        println!(
            "skipped: ../shared not found (tests that read ../shared need the project's shared \
             folder beside the clone)"
        );
        return None;
    }
    let path = dir.join(rel);
    assert!(
        path.exists(),
        "{} is missing although {} exists",
        path.display(),
        dir.display()
    );
    Some(path)
}

/// A file path `name` in a fresh temp dir of its own (the file is not created); the dir goes
/// when this is dropped. The name is kept because readers tell formats apart by it.
pub struct TempFile(pub PathBuf, tempfile::TempDir);

impl TempFile {
    /// A fresh temp path (the file is not created).
    pub fn path(name: &str) -> TempFile {
        let dir = temp_dir("file");
        TempFile(dir.path().join(name), dir)
    }

    /// A temp file with `content`.
    pub fn with(name: &str, content: &str) -> TempFile {
        let t = TempFile::path(name);
        std::fs::write(&t.0, content).expect("write temp file");
        t
    }
}

/// The shipped sample's true blade parameters (`data/reversal/blade_true.toml`).
pub fn true_blade() -> wiperlab::model::BladeParams {
    let p = root().join("data/reversal/blade_true.toml");
    toml::from_str(&std::fs::read_to_string(p).expect("read blade_true.toml")).expect("parse")
}

/// A model-made recording's motion: `p`'s reversal window (`default_window`) simulated at 10,000
/// frames/s with DOPRI5 at rtol 1e-10, atol 1e-12 (`SolverOptions::default()`, tighter than any
/// fit's, so a fit's error comes from the fit and the noise added when it is written), the lip
/// equations in reduced form. Returns the simulation and the first frame's time.
pub fn recording_of(
    p: &wiperlab::model::BladeParams,
) -> wiperlab::Result<(wiperlab::simulate::blade::BladeSimulation, f64)> {
    let (t0, t1) = wiperlab::simulate::blade::default_window(p);
    let times = frame_times(t0, t1, 1e4);
    let sim = wiperlab::simulate::blade::simulate_blade(
        p,
        (t0, *times.last().expect("a window of at least one frame")),
        &times,
        &wiperlab::simulate::SolverOptions::default(),
        wiperlab::model::StickForm::Reduced,
    )?;
    Ok((sim, t0))
}

/// A fresh temp directory (`wiperlab_<tag>_...`, removed when dropped) holding a model-made fit case: the recording
/// `rec_xypts.csv` ([`write_dltdv`] of `sim` with `noise_px`), `blade.toml` (`start`, the blade the
/// fit starts from) and `truth.json` (`truth_json`, the values the recording was made with).
pub fn write_case(
    tag: &str,
    sim: &wiperlab::simulate::blade::BladeSimulation,
    start: &wiperlab::model::BladeParams,
    truth_json: &str,
    noise_px: &mut dyn FnMut() -> f64,
) -> tempfile::TempDir {
    let case = temp_dir(tag);
    let dir = case.path();
    write_dltdv(&dir.join("rec_xypts.csv"), sim, noise_px);
    std::fs::write(
        dir.join("blade.toml"),
        toml::to_string(start).expect("blade to TOML"),
    )
    .expect("write blade.toml");
    std::fs::write(dir.join("truth.json"), truth_json).expect("write truth.json");
    case
}

/// Frame times `t0 + k/fps` covering `[t0, t1)`.
pub fn frame_times(t0: f64, t1: f64, fps: f64) -> Vec<f64> {
    let n = ((t1 - t0) * fps) as usize;
    (0..n).map(|k| t0 + k as f64 / fps).collect()
}

/// Writes a simulation as a DLTdv8 `xypts.csv` (point 1 the head, point 2 the lip tip) through the
/// shipped sample's camera model (data/reversal/README.md, "Camera and coordinates": 15 µm per
/// pixel, `x_px = 200 + (X − a)/S`, `y_px = 300 − Z/S` with a = 0.1 m, y down, `%.6f`), written
/// here by hand so the data do not depend on the reader under test. `noise_px` draws the tracking
/// noise added to each coordinate (pixels).
pub fn write_dltdv(
    path: &Path,
    sim: &wiperlab::simulate::blade::BladeSimulation,
    noise_px: &mut dyn FnMut() -> f64,
) {
    use std::fmt::Write as _;
    let (s, a) = (1.5e-5, 0.1);
    let mut csv = String::from("pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y\n");
    for i in 0..sim.t_s.len() {
        let _ = writeln!(
            csv,
            "{:.6},{:.6},{:.6},{:.6}",
            200.0 + (sim.v_m[i] - a) / s + noise_px(),
            300.0 + sim.u_m[i] / s + noise_px(),
            200.0 + (sim.v3_m[i] - a) / s + noise_px(),
            300.0 + sim.reach_m / s + noise_px()
        );
    }
    std::fs::write(path, csv).expect("write the recording");
}

/// The `[recording.import]` lines of a job reading a file written by [`write_dltdv`] whose frame 1
/// is at `t0` on the model clock.
pub fn dltdv_import(t0: f64) -> String {
    format!(
        "format = \"dltdv\"\nfps_hz = 10000.0\nm_per_px = 1.5e-5\norigin_px = [200.0, 300.0]\nt0_s = {t0:?}\n"
    )
}

/// Frame 1 of the shipped sample (`data/reversal/`) on the model clock, s: data/reversal/truth.json
/// `camera.t0_s` (drive phase ωt = π/2), as in the main job `fits/reversal.toml`.
pub const SAMPLE_T0_S: f64 = 0.9434198694385137;

/// The `[recording]` section of a job, with its `[recording.import]` ([`dltdv_import`]) and points
/// (`pt1` the head, `pt2` the lip tip), for a DLTdv export laid out like the shipped sample or
/// written by [`write_dltdv`]. `file` is written as given (relative paths resolve from the job).
pub fn dltdv_recording(file: &str, t0: f64) -> String {
    format!(
        "[recording]\nfile = {file:?}\n[recording.import]\n{}[recording.import.points]\nhead = \"pt1\"\ntip = \"pt2\"\n",
        dltdv_import(t0)
    )
}

/// [`dltdv_recording`] of the shipped sample recording, by absolute path.
pub fn sample_recording() -> String {
    let file = root().join("data/reversal/wiper_reversal_sample_xypts.csv");
    dltdv_recording(&file.display().to_string(), SAMPLE_T0_S)
}

/// The `[spectrum]` section of a job: signal tip x − head x and the given bands
/// `(name, [lo, hi] Hz, nperseg)`.
pub fn spectrum_bands(bands: &[(&str, [f64; 2], usize)]) -> String {
    let mut s = String::from("[spectrum]\nsignal = \"tip_rel_x\"\nmax_fill = 5\n");
    for (name, [lo, hi], nperseg) in bands {
        s.push_str(&format!(
            "[[spectrum.bands]]\nname = {name:?}\nrange_hz = [{lo:?}, {hi:?}]\nnperseg = {nperseg}\n"
        ));
    }
    s
}
