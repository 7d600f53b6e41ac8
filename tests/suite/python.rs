//! The Python package (`python/`): builds it with maturin into a virtual environment under
//! `target/python/` and runs its pytest suite (`python/tests/`).
//!
//! Needs CPython 3.10 or later with pip and venv (`python3`, or the interpreter named by
//! `WIPERLAB_PYTHON`) and the package registry: the environment gets maturin, NumPy, SciPy and
//! pytest by name, once (kept in `target/python/venv` and reused while the requirements are the
//! same). Without such a Python the test prints why it is skipped; with
//! `WIPERLAB_REQUIRE_PYTHON=1` (set by `.ci/run`) that is a failure.
//!
//! The extension is built with the release profile into this test's own target directory, so it
//! reuses the dependencies `cargo test --release` has just compiled (the feature sets of the two
//! builds are kept equal in `Cargo.toml` and `python/Cargo.toml`); only pyo3, numpy and the
//! bindings themselves are compiled, once.

use crate::common::{root, wiperlab_exe};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

/// What the virtual environment holds: the build backend and what the suite imports.
const REQUIREMENTS: &[&str] = &["maturin>=1.9,<2", "numpy>=1.22", "scipy>=1.11", "pytest>=7"];

/// The target directory this test binary was built in (`<target>/release/deps/python-…`).
fn target_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    exe.ancestors()
        .nth(3)
        .expect("test executable inside <target>/<profile>/deps")
        .to_path_buf()
}

/// Runs `cmd`, returning its output, or why it could not be started.
fn run(cmd: &mut Command) -> Result<Output, String> {
    cmd.output()
        .map_err(|e| format!("cannot run {:?}: {e}", cmd.get_program()))
}

/// `out`'s stdout and stderr, for a failure message.
fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// A CPython ≥ 3.10 with pip and venv, or why there is none.
fn find_python() -> Result<PathBuf, String> {
    let python = std::env::var_os("WIPERLAB_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("python3"));
    let check = "import sys, ensurepip, venv; print(sys.version.split()[0]); \
                 sys.exit(0 if sys.version_info >= (3, 10) else 3)";
    let out = run(Command::new(&python).args(["-c", check]))?;
    if !out.status.success() {
        return Err(format!(
            "{} is not CPython 3.10+ with venv and ensurepip: {}",
            python.display(),
            text(&out).trim()
        ));
    }
    let pip = run(Command::new(&python).args(["-m", "pip", "--version"]))?;
    if !pip.status.success() {
        return Err(format!(
            "{} has no pip: {}",
            python.display(),
            text(&pip).trim()
        ));
    }
    Ok(python)
}

/// The virtual environment with [`REQUIREMENTS`], made (or remade) when its stamp differs.
fn venv(python: &Path, dir: &Path) -> Result<PathBuf, String> {
    let stamp = dir.join("wiperlab-requirements.txt");
    let want = REQUIREMENTS.join("\n");
    let bin = dir.join("bin").join("python");
    if bin.exists() && std::fs::read_to_string(&stamp).is_ok_and(|s| s == want) {
        return Ok(bin);
    }
    let out = run(Command::new(python)
        .args(["-m", "venv", "--clear"])
        .arg(dir))?;
    if !out.status.success() {
        return Err(format!(
            "python -m venv {} failed: {}",
            dir.display(),
            text(&out)
        ));
    }
    // Wheels only, and no byte-compiling of SciPy's thousands of modules at install time.
    let out = run(Command::new(&bin)
        .args([
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
        ])
        .args(["--no-compile", "--only-binary", ":all:"])
        .args(REQUIREMENTS))?;
    if !out.status.success() {
        return Err(format!(
            "pip install {} failed: {}",
            REQUIREMENTS.join(" "),
            text(&out)
        ));
    }
    std::fs::write(&stamp, want).map_err(|e| format!("{}: {e}", stamp.display()))?;
    Ok(bin)
}

#[test]
fn python_package_builds_and_its_suite_passes() {
    let required = std::env::var("WIPERLAB_REQUIRE_PYTHON").as_deref() == Ok("1");
    let skip = |why: String| {
        if required {
            panic!("WIPERLAB_REQUIRE_PYTHON=1 but the Python package cannot be tested: {why}");
        }
        println!("skipped: the Python package is not tested: {why}");
    };
    let python = match find_python() {
        Ok(p) => p,
        Err(why) => return skip(why),
    };
    let target = target_dir();
    let work = target.join("python");
    let started = Instant::now();
    let py = match venv(&python, &work.join("venv")) {
        Ok(p) => p,
        Err(why) => return skip(why),
    };
    let venv_s = started.elapsed().as_secs_f64();

    // Build the wheel with maturin into this target directory, then install it.
    let wheels = work.join("wheels");
    let _ = std::fs::remove_dir_all(&wheels);
    let maturin = py.with_file_name("maturin");
    let started = Instant::now();
    let out = Command::new(&maturin)
        .args(["build", "--release", "--manifest-path"])
        .arg(root().join("python").join("Cargo.toml"))
        .arg("--out")
        .arg(&wheels)
        .arg("--interpreter")
        .arg(&py)
        .env("CARGO_TARGET_DIR", &target)
        .output()
        .expect("run maturin");
    assert!(
        out.status.success(),
        "maturin build failed:\n{}",
        text(&out)
    );
    let build_s = started.elapsed().as_secs_f64();
    let wheel: Vec<PathBuf> = std::fs::read_dir(&wheels)
        .expect("wheel directory")
        .map(|e| e.expect("wheel entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "whl"))
        .collect();
    assert_eq!(wheel.len(), 1, "expected one wheel in {}", wheels.display());
    let out = Command::new(&py)
        .args([
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
        ])
        .args(["--force-reinstall", "--no-deps"])
        .arg(&wheel[0])
        .output()
        .expect("run pip");
    assert!(
        out.status.success(),
        "pip install of the wheel failed:\n{}",
        text(&out)
    );

    // The suite, from the source tree (its tests read the shipped data and run the CLI).
    let started = Instant::now();
    let out = Command::new(&py)
        .args([
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "python/tests",
        ])
        .current_dir(root())
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .env("WIPERLAB_BIN", wiperlab_exe())
        .output()
        .expect("run pytest");
    let suite_s = started.elapsed().as_secs_f64();
    println!("{}", text(&out));
    println!(
        "virtual environment {venv_s:.1} s, maturin build {build_s:.1} s, pytest {suite_s:.1} s"
    );
    assert!(out.status.success(), "the pytest suite failed");
}
