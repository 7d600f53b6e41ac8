//! Helpers shared by the integration tests (`mod common;` in each test file): the binary runner
//! here, the fixtures (repository root, temp dirs, the sample's blade, model-made recordings and
//! job sections) in `fixtures.rs`, which the `examples/` tools include too.
#![allow(dead_code)] // each test file uses a different subset

mod fixtures;
pub mod scenes;

pub use fixtures::*;

use std::ffi::OsStr;
use std::path::Path;
use std::process::Output;

use assert_cmd::assert::OutputAssertExt as _;

/// The `wiperlab` binary under test with `args`, to run in the repository root (so the shipped
/// jobs' relative paths work). `.current_dir(dir)` runs it elsewhere, `.write_stdin(..)` feeds its
/// standard input, `.timeout(..)` kills it after a time; `.assert()` checks the exit code and the
/// output with `predicates`, `.output()` returns them.
pub fn wiperlab<I, S>(args: I) -> assert_cmd::Command
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    let mut cmd = assert_cmd::cargo::cargo_bin_cmd!("wiperlab");
    cmd.args(args).current_dir(root());
    cmd
}

/// The binary's path, for a test that drives the process itself (signals, a closed pipe).
pub fn wiperlab_exe() -> &'static Path {
    assert_cmd::cargo::cargo_bin!("wiperlab")
}

/// Runs `wiperlab args...` in the repository root, with an empty standard input; whatever the
/// exit code.
pub fn run<S: AsRef<OsStr>>(args: &[S]) -> Output {
    wiperlab(args).output().expect("start the wiperlab binary")
}

/// [`run`] with `dir` as working directory.
pub fn run_in<S: AsRef<OsStr>>(dir: &Path, args: &[S]) -> Output {
    wiperlab(args)
        .current_dir(dir)
        .output()
        .expect("start the wiperlab binary")
}

/// Asserts that the run `what` exited with 0 (printing its code, stdout and stderr otherwise) and
/// returns its standard output.
pub fn ok(o: &Output, what: &str) -> String {
    if let Err(e) = o.clone().assert().try_success() {
        panic!("{what} failed: {e}");
    }
    stdout(o)
}

/// A run's standard output as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A run's standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}
