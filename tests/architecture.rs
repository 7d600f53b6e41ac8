//! The module tree is the pipeline: a stage may use only the stages before it (the order stated in
//! `src/lib.rs`'s docs). This test reads every source file under `src/` and fails on a path into a
//! later stage (`crate::<stage>` in code, also inside `use crate::{…}` groups); comments are skipped,
//! since a doc link is not a dependency.

mod common;

use std::path::{Path, PathBuf};

/// The pipeline, upstream first. `error` is the shared error type; `lib` and `main` are the crate
/// roots and may name anything.
const STAGES: &[&str] = &[
    "error", "names", "io", "trace", "import", "spectrum", "model", "simulate", "fit", "campaign",
    "report", "bench", "cli",
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
    let code = "use crate::fit::job::FitJob;\nuse crate::{Error, report::plot::{a, b}, simulate};\nlet x = crate::cli::run(y);";
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
