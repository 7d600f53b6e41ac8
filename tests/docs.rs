//! README is a user manual and `docs/` holds the rest: README stays under 12 KB, gives the exact test
//! command `.ci/run` runs, names every `docs/` file (and only existing ones); links between the
//! documents resolve, headings included; and no source, test or job file cites README for a number
//! (numbers and methods live in `docs/`, each with the command that reproduces it).

use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Files under `dir` (recursively) whose name ends with `suffix`.
fn files(dir: &Path, suffix: &str, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            files(&path, suffix, out);
        } else if path.to_string_lossy().ends_with(suffix) {
            out.push(path);
        }
    }
}

fn docs_files() -> Vec<PathBuf> {
    let mut out = Vec::new();
    files(&root().join("docs"), ".md", &mut out);
    out.sort();
    out
}

/// Targets of the Markdown links and images in `text`: the `path` of every `](path)`.
fn link_targets(text: &str) -> Vec<String> {
    text.split("](")
        .skip(1)
        .filter_map(|rest| rest.split_once(')').map(|(t, _)| t.to_string()))
        .collect()
}

/// GitHub's anchor for a heading: lower case, spaces to hyphens, other punctuation dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

fn anchors(markdown: &str) -> Vec<String> {
    let mut in_code = false;
    let mut out = Vec::new();
    for line in markdown.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
        } else if !in_code && line.starts_with('#') {
            out.push(anchor(line.trim_start_matches('#')));
        }
    }
    out
}

#[test]
fn readme_is_a_short_manual_with_the_ci_test_command() {
    let readme = read(&root().join("README.md"));
    assert!(
        readme.len() <= 12 * 1024,
        "README.md is {} bytes (at most 12,288)",
        readme.len()
    );
    assert!(
        readme
            .lines()
            .any(|l| l.starts_with("cargo test --release")),
        "README.md must give `cargo test --release` at the start of a line"
    );
    let ci = read(&root().join(".ci/run"));
    assert!(
        ci.lines().any(|l| l.trim() == "cargo test --release"),
        ".ci/run no longer runs exactly `cargo test --release`, the command README gives"
    );
}

#[test]
fn readme_names_every_docs_file_and_only_existing_ones() {
    let readme = read(&root().join("README.md"));
    let mut named = Vec::new();
    for word in readme.split(|c: char| c == '`' || c.is_whitespace() || c == '(' || c == ')') {
        if let Some(rest) = word.strip_prefix("docs/") {
            let name = rest.trim_end_matches([',', '.', ':', ';']);
            if name.is_empty() {
                continue; // the folder itself
            }
            assert!(
                root().join("docs").join(name).is_file(),
                "README.md names docs/{name}, which does not exist"
            );
            named.push(name.to_string());
        }
    }
    for doc in docs_files() {
        let name = doc.file_name().unwrap().to_string_lossy().to_string();
        assert!(
            named.contains(&name),
            "docs/{name} is not named in README.md's \"Read more\""
        );
    }
    for target in link_targets(&readme) {
        if !target.starts_with("http") {
            assert!(
                root().join(&target).is_file(),
                "README.md links {target}, which does not exist"
            );
        }
    }
}

/// Every relative link in `docs/*.md` reaches an existing file, and a `#heading` one of its headings.
#[test]
fn links_between_docs_resolve() {
    for doc in docs_files() {
        let text = read(&doc);
        for target in link_targets(&text) {
            if target.starts_with("http") {
                continue;
            }
            let (file, heading) = match target.split_once('#') {
                Some((f, h)) => (f, Some(h)),
                None => (target.as_str(), None),
            };
            let path = if file.is_empty() {
                doc.clone()
            } else {
                doc.parent().unwrap().join(file)
            };
            assert!(
                path.exists(),
                "{}: link {target}: {} does not exist",
                doc.display(),
                path.display()
            );
            if let Some(h) = heading {
                let found = anchors(&read(&path));
                assert!(
                    found.iter().any(|a| a == h),
                    "{}: link {target}: no heading #{h} in {} (headings: {found:?})",
                    doc.display(),
                    path.display()
                );
            }
        }
    }
}

/// README is a manual, not a reference: sources, tests, benches, examples and the shipped jobs cite
/// `docs/` (or `CHANGELOG.md` for history), never README. The shipped recording's own
/// `data/reversal/README.md` (its data sheet) may be cited.
#[test]
fn no_source_cites_the_readme() {
    let mut checked = Vec::new();
    for dir in ["src", "tests", "benches", "examples"] {
        files(&root().join(dir), ".rs", &mut checked);
    }
    for dir in ["fits", "campaigns"] {
        files(&root().join(dir), ".toml", &mut checked);
    }
    let this_file = root().join("tests/docs.rs");
    assert!(checked.len() > 20, "found only {} files", checked.len());
    for f in checked.iter().filter(|f| **f != this_file) {
        for (i, line) in read(f).lines().enumerate() {
            let cites_readme = line.contains("README")
                && !line.contains("data/reversal/README.md")
                && !line.contains("sample/README.md");
            assert!(
                !cites_readme,
                "{}:{}: cites the README; numbers and methods live in docs/",
                f.display(),
                i + 1
            );
        }
    }
}
