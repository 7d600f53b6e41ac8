//! Helpers shared by the integration tests (`mod common;` in each test file).
#![allow(dead_code)] // each test file uses a different subset

use std::path::{Path, PathBuf};

/// The project's shared data folder, `../shared` beside the clone (`/work/shared`).
pub fn shared_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared")
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

/// A path in the system temp dir, unique per process and `name`, removed on drop.
pub struct TempFile(pub PathBuf);

impl TempFile {
    /// A fresh temp path (the file is not created).
    pub fn path(name: &str) -> TempFile {
        TempFile(std::env::temp_dir().join(format!("wiperlab_test_{}_{name}", std::process::id())))
    }

    /// A temp file with `content`.
    pub fn with(name: &str, content: &str) -> TempFile {
        let t = TempFile::path(name);
        std::fs::write(&t.0, content).expect("write temp file");
        t
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}
