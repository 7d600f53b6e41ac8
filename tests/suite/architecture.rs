//! The module tree is the pipeline: a stage may use only the stages before it (the order stated in
//! `src/lib.rs`'s docs). This test reads every source file under `src/` and fails on a path into a
//! later stage (`crate::<stage>` in code, also inside `use crate::{…}` groups); comments are skipped,
//! since a doc link is not a dependency.

use crate::common;

use std::path::{Path, PathBuf};

/// The pipeline, upstream first. `error` is the shared error type; `lib` and `main` are the crate
/// roots and may name anything.
const STAGES: &[&str] = &[
    "error",
    "names",
    "io",
    "trace",
    "import",
    "spectrum",
    "model",
    "simulate",
    "job",
    "likelihood",
    "posterior",
    "estimate",
    "search",
    "uncertainty",
    "fit",
    "explore",
    "campaign",
    "report",
    "bench",
    "cli",
];

fn rank(stage: &str) -> Option<usize> {
    STAGES.iter().position(|s| *s == stage)
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src/ is readable") {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The stage a file belongs to: the first component below `src/` without its `.rs`.
fn stage_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).expect("file under src/");
    let first = rel.components().next().expect("non-empty path");
    first
        .as_os_str()
        .to_string_lossy()
        .trim_end_matches(".rs")
        .to_string()
}

/// The code part of a line: everything before a `//` comment (string literals holding `//` are
/// rare in this crate and would only hide a reference, never invent one).
fn code_part(line: &str) -> &str {
    match line.find("//") {
        Some(i) => &line[..i],
        None => line,
    }
}

/// The top-level module names that `code` reaches through `crate::`, including every name of a
/// `crate::{a::b, c}` group (which may span lines, hence the whole file's code as one string).
fn crate_references(code: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find("crate::") {
        rest = &rest[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0usize;
            let mut item = String::new();
            for ch in group.chars() {
                match ch {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        names.push(first_ident(&item));
                        item.clear();
                        continue;
                    }
                    _ => {}
                }
                item.push(ch);
            }
            names.push(first_ident(&item));
        } else {
            names.push(first_ident(rest));
        }
    }
    names.retain(|n| !n.is_empty());
    names
}

fn first_ident(s: &str) -> String {
    s.trim_start()
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect()
}

#[test]
fn no_stage_uses_a_later_stage() {
    let src = common::root().join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    assert!(files.len() > 20, "found only {} source files", files.len());
    let mut violations = Vec::new();
    let mut unknown = Vec::new();
    for file in &files {
        let stage = stage_of(&src, file);
        if stage == "lib" || stage == "main" {
            continue;
        }
        let Some(own) = rank(&stage) else {
            unknown.push(file.display().to_string());
            continue;
        };
        let text = std::fs::read_to_string(file).expect("source file is UTF-8");
        let code: String = text.lines().map(code_part).collect::<Vec<_>>().join("\n");
        for name in crate_references(&code) {
            match rank(&name) {
                Some(r) if r > own => violations.push(format!(
                    "{}: stage `{stage}` uses later stage `{name}`",
                    file.display()
                )),
                _ => {}
            }
        }
    }
    assert!(
        unknown.is_empty(),
        "source files outside the stated pipeline (add the module to STAGES and to lib.rs's docs): {unknown:?}"
    );
    assert!(
        violations.is_empty(),
        "dependencies against the pipeline:\n{}",
        violations.join("\n")
    );
}

/// The checker itself finds references in the forms the crate uses, so the test above can fail.
#[test]
fn reference_scanner_sees_paths_and_groups() {
    let code = "use crate::fit::result::FitResult;\nuse crate::{Error, report::plot::{a, b}, simulate};\nlet x = crate::cli::run(y);";
    assert_eq!(
        crate_references(code),
        vec!["fit", "Error", "report", "simulate", "cli"]
    );
    assert_eq!(code_part("let a = 1; // crate::cli"), "let a = 1; ");
}

/// `lib.rs` states the same order as [`STAGES`], so the documented and the checked pipeline agree.
#[test]
fn lib_docs_state_the_checked_order() {
    let lib =
        std::fs::read_to_string(common::root().join("src/lib.rs")).expect("src/lib.rs is readable");
    let line = lib
        .lines()
        .find(|l| l.contains("Pipeline order:"))
        .expect("lib.rs docs have a line 'Pipeline order: a → b → …'");
    let stated: Vec<String> = line
        .split("Pipeline order:")
        .nth(1)
        .unwrap()
        .split('→')
        .map(|s| s.trim().trim_end_matches('.').trim_matches('`').to_string())
        .collect();
    assert_eq!(stated, STAGES);
}

/// Most of `src/`'s lines one top-level room may hold: a fifth.
const MAX_ROOM_SHARE: f64 = 0.2;

/// Every file under `dir` (recursively), templates included.
fn all_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("directory is readable") {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            all_files(&path, out);
        } else {
            out.push(path);
        }
    }
}

/// Lines per top-level room (the first component below `src/` without its `.rs`, as in
/// [`stage_of`]), counted as `wc -l` counts them: newline characters of every file under `src/`,
/// Rust sources and the templates they include alike, comments, blank lines and tests included.
fn room_lines(src: &Path) -> Vec<(String, usize)> {
    let mut files = Vec::new();
    all_files(src, &mut files);
    let mut rooms = std::collections::BTreeMap::<String, usize>::new();
    for file in &files {
        let bytes = std::fs::read(file).expect("source file is readable");
        let lines = bytes.iter().filter(|b| **b == b'\n').count();
        *rooms.entry(stage_of(src, file)).or_default() += lines;
    }
    rooms.into_iter().collect()
}

/// The rooms whose share of `total` lines is above [`MAX_ROOM_SHARE`], with their shares.
fn oversized(rooms: &[(String, usize)]) -> Vec<String> {
    let total: usize = rooms.iter().map(|(_, n)| n).sum();
    rooms
        .iter()
        .filter(|(_, n)| *n as f64 > MAX_ROOM_SHARE * total as f64)
        .map(|(room, n)| {
            format!(
                "{room}: {n} of {total} lines ({:.1} %)",
                100.0 * *n as f64 / total as f64
            )
        })
        .collect()
}

/// Each room does one job and none holds more than a fifth of the code: a room that grows past
/// that is split into stages of one job each (and [`STAGES`] says where they run).
#[test]
fn no_room_holds_more_than_a_fifth_of_the_code() {
    let rooms = room_lines(&common::root().join("src"));
    assert!(
        rooms.len() > 10,
        "found only {} rooms under src/",
        rooms.len()
    );
    let over = oversized(&rooms);
    assert!(
        over.is_empty(),
        "rooms above {} % of src/'s lines:\n{}",
        100.0 * MAX_ROOM_SHARE,
        over.join("\n")
    );
}

/// The share check flags a room just above a fifth and passes one at exactly a fifth.
#[test]
fn share_check_flags_a_room_above_a_fifth() {
    let rooms = |big: usize| {
        let mut r = vec![("a".to_string(), big)];
        r.extend(["b", "c", "d", "e"].map(|n| (n.to_string(), 100)));
        r
    };
    assert_eq!(oversized(&rooms(100)), Vec::<String>::new());
    assert_eq!(oversized(&rooms(101)), vec!["a: 101 of 501 lines (20.2 %)"]);
}
