//! README is a user manual and `docs/` holds the rest: README stays under 12 KB, gives the exact test
//! command `.ci/run` runs, names every `docs/` file (and only existing ones); links between the
//! documents resolve, headings included; and no source, test or job file cites README for a number
//! (numbers and methods live in `docs/`, each with the command that reproduces it).

use crate::common::root;

use std::path::{Path, PathBuf};

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
    let this_file = root().join("tests/suite/docs.rs");
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

// The job and blade references (`docs/job.md`, `docs/blade.md`) against the readers themselves.
// The keys come from the readers' own "unknown field" and "unknown variant/name" errors (the lists
// a user sees after a typo), so a key the code accepts and the reference lacks fails here, as
// does a row for a key the code no longer accepts.

/// The names a reader's error lists: `expected one of `a`, `b`` (serde) or `(known: a, b)`
/// (wiperlab's named enums).
fn listed(message: &str) -> Vec<String> {
    if let Some((_, known)) = message.split_once("(known: ") {
        let known = known.split(')').next().unwrap_or_default();
        return known.split(", ").map(str::to_string).collect();
    }
    let Some((_, expected)) = message.split_once("expected") else {
        panic!("the reader's error lists no names: {message}");
    };
    expected
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// What the job reader lists after reading `toml` (which must fail on an unknown name).
fn job_lists(toml: &str) -> Vec<String> {
    match toml::from_str::<wiperlab::job::FitJob>(toml) {
        Ok(_) => panic!("the job reader accepted {toml:?}"),
        Err(e) => listed(e.message()),
    }
}

/// What the blade reader lists after reading `toml` (which must fail on an unknown name).
fn blade_lists(toml: &str) -> Vec<String> {
    match toml::from_str::<wiperlab::model::BladeParams>(toml) {
        Ok(_) => panic!("the blade reader accepted {toml:?}"),
        Err(e) => listed(e.message()),
    }
}

/// The reference rows under the heading `heading` (the text after the `#`s) of `doc`, up to the
/// next heading: `(key, row)` for every table row whose first cell is a backticked key.
fn reference_rows(doc: &str, heading: &str) -> Vec<(String, String)> {
    let mut lines = doc
        .lines()
        .skip_while(|l| !(l.starts_with('#') && l.trim_start_matches('#').trim() == heading));
    assert!(lines.next().is_some(), "no heading {heading:?}");
    lines
        .take_while(|l| !l.starts_with('#'))
        .filter_map(|l| {
            let rest = l.strip_prefix("| `")?;
            let key = rest.split('`').next()?;
            Some((key.to_string(), l.to_string()))
        })
        .collect()
}

/// The keys under `heading` are exactly `keys`.
fn assert_documented(file: &str, doc: &str, heading: &str, keys: &[String]) {
    let rows: Vec<String> = reference_rows(doc, heading)
        .into_iter()
        .map(|(k, _)| k)
        .collect();
    for key in keys {
        assert!(
            rows.contains(key),
            "{file}, \"{heading}\": the reader accepts `{key}`, which the table does not list"
        );
    }
    for row in &rows {
        assert!(
            keys.contains(row),
            "{file}, \"{heading}\": the table lists `{row}`, which the reader does not accept \
             (it accepts {keys:?})"
        );
    }
}

/// The row of `key` under `heading` names every value in `values` (in backticks or quotes).
fn assert_values_documented(file: &str, doc: &str, heading: &str, key: &str, values: &[String]) {
    let rows = reference_rows(doc, heading);
    let (_, row) = rows
        .iter()
        .find(|(k, _)| k == key)
        .unwrap_or_else(|| panic!("{file}, \"{heading}\": no row for `{key}`"));
    for v in values {
        assert!(
            row.contains(&format!("`{v}`")) || row.contains(&format!("\"{v}\"")),
            "{file}, \"{heading}\", `{key}`: the reader accepts {v:?}, which the row does not name"
        );
    }
}

#[test]
fn the_job_reference_lists_every_key_the_job_reader_accepts() {
    let doc = read(&root().join("docs/job.md"));
    let unknown = "zz_not_a_key = 1";
    for (heading, table) in [
        ("Top level", ""),
        ("`[recording]`", "[recording]"),
        ("`[recording.import]`", "[recording.import]"),
        ("`[recording.import.generic]`", "[recording.import.generic]"),
        ("`[targets]`", "[targets]"),
        ("`[[targets.peaks]]`", "[[targets.peaks]]"),
        ("`[[more_recordings]]`", "[[more_recordings]]"),
        ("`[spectrum]`", "[spectrum]"),
        ("`[[spectrum.bands]]`", "[[spectrum.bands]]"),
        ("`[solver]`", "[solver]"),
        ("`[fit]`", "[fit]"),
        ("`[fit.weights]`", "[fit.weights]"),
        ("`[fit.shoulder]`", "[fit.shoulder]"),
        ("`[fit.search]`", "[fit.search]"),
        ("`[fit.uncertainty]`", "[fit.uncertainty]"),
        ("`[fit.likelihood]`", "[fit.likelihood]"),
        ("`[truth]`", "[truth]"),
    ] {
        let keys = job_lists(&format!("{table}\n{unknown}\n"));
        assert!(!keys.is_empty(), "{table}: no keys listed");
        assert_documented("docs/job.md", &doc, heading, &keys);
    }
    // The parameters a fit may free are the keys of [fit.parameters].
    let params = job_lists("[fit.parameters]\nzz_not_a_parameter = [0.0, 1.0]\n");
    assert!(params.contains(&"k1".to_string()), "{params:?}");
    assert_documented("docs/job.md", &doc, "`[fit.parameters]`", &params);
    // Every value a named setting accepts.
    for (heading, key, toml) in [
        (
            "`[recording.import]`",
            "format",
            "[recording.import]\nformat = \"zz\"",
        ),
        ("`[spectrum]`", "signal", "[spectrum]\nsignal = \"zz\""),
        (
            "`[[spectrum.bands]]`",
            "window",
            "[[spectrum.bands]]\nwindow = \"zz\"",
        ),
        (
            "`[[spectrum.bands]]`",
            "detrend",
            "[[spectrum.bands]]\ndetrend = \"zz\"",
        ),
        (
            "`[[spectrum.bands]]`",
            "scaling",
            "[[spectrum.bands]]\nscaling = \"zz\"",
        ),
        (
            "`[[spectrum.bands]]`",
            "average",
            "[[spectrum.bands]]\naverage = \"zz\"",
        ),
        ("`[solver]`", "method", "[solver]\nmethod = \"zz\""),
        ("`[fit]`", "objective", "[fit]\nobjective = \"zz\""),
        ("`[fit]`", "models", "[fit]\nmodels = [\"zz\"]"),
        ("`[fit]`", "nested_search", "[fit]\nnested_search = \"zz\""),
        (
            "`[fit]`",
            "contact_angle_scan",
            "[fit]\ncontact_angle_scan = \"zz\"",
        ),
        ("`[fit.search]`", "method", "[fit.search]\nmethod = \"zz\""),
        (
            "`[fit.uncertainty]`",
            "method",
            "[fit.uncertainty]\nmethod = \"zz\"",
        ),
    ] {
        let values = job_lists(toml);
        assert!(values.len() >= 2, "{toml}: {values:?}");
        assert_values_documented("docs/job.md", &doc, heading, key, &values);
    }
}

#[test]
fn the_blade_reference_lists_every_key_the_blade_reader_accepts() {
    let doc = read(&root().join("docs/blade.md"));
    let unknown = "zz_not_a_key = 1";
    for (heading, table) in [("Top level", ""), ("`[shoulder]`", "[shoulder]")] {
        let keys = blade_lists(&format!("{table}\n{unknown}\n"));
        assert!(!keys.is_empty(), "{table}: no keys listed");
        assert_documented("docs/blade.md", &doc, heading, &keys);
    }
    let laws = blade_lists("[friction]\nlaw = \"zz\"\n");
    assert!(laws.contains(&"exponential".to_string()), "{laws:?}");
    assert_values_documented("docs/blade.md", &doc, "`[friction]`", "law", &laws);
    for law in &laws {
        let keys = blade_lists(&format!("[friction]\nlaw = \"{law}\"\n{unknown}\n"));
        let heading = format!("`[friction]` with `law = \"{law}\"`");
        assert_documented("docs/blade.md", &doc, &heading, &keys);
    }
}

/// `wiperlab init`'s template points to the two references.
#[test]
fn the_job_template_points_to_the_references() {
    let template = read(&root().join("src/job/templates/job.toml"));
    for doc in ["docs/job.md", "docs/blade.md"] {
        assert!(
            template.contains(doc),
            "the init template does not name {doc}"
        );
    }
}

/// The headings and bold labels (`**Label.**`) of a Markdown document, lower case, without
/// backticks and a trailing full stop.
fn sections(markdown: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_code = false;
    for line in markdown.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        if line.starts_with('#') {
            out.push(line.trim_start_matches('#').trim().to_string());
        }
        for bold in line.split("**").skip(1).step_by(2) {
            out.push(bold.to_string());
        }
    }
    out.iter()
        .map(|s| s.replace('`', "").trim_end_matches('.').to_lowercase())
        .collect()
}

/// Comments, job files and the report template cite a part of the manual as
/// `docs/NAME.md, "Heading"`; each such heading (or the start of one, or a bold label) exists, so a
/// reader who follows it lands.
#[test]
fn cited_sections_of_the_docs_exist() {
    let mut checked = Vec::new();
    for dir in ["src", "tests", "benches", "examples"] {
        files(&root().join(dir), ".rs", &mut checked);
    }
    for dir in ["src", "fits", "campaigns", "data"] {
        files(&root().join(dir), ".toml", &mut checked);
    }
    files(&root().join("src"), ".html", &mut checked);
    let mut cited = 0;
    for f in &checked {
        // Comment markers at line starts removed, so a citation may run over two lines.
        let text: String = read(f)
            .lines()
            .map(|l| {
                l.trim_start()
                    .trim_start_matches("//!")
                    .trim_start_matches("///")
                    .trim_start_matches("//")
                    .trim_start_matches('#')
                    .trim()
            })
            .collect::<Vec<_>>()
            .join(" ");
        for (i, _) in text.match_indices("docs/") {
            let rest = &text[i + 5..];
            let Some((name, after)) = rest.split_once(".md, \"") else {
                continue;
            };
            if !name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c == '_' || c == '-')
            {
                continue;
            }
            let Some((quoted, _)) = after.split_once('"') else {
                continue;
            };
            let quoted = quoted.trim_end_matches('\\').trim().to_lowercase();
            let doc = root().join("docs").join(format!("{name}.md"));
            assert!(doc.is_file(), "{}: cites docs/{name}.md", f.display());
            let found = sections(&read(&doc));
            assert!(
                found.iter().any(|s| s.starts_with(&quoted)),
                "{}: cites docs/{name}.md, \"{quoted}\", which has no such heading or label",
                f.display()
            );
            cited += 1;
        }
    }
    assert!(cited > 20, "found only {cited} citations");
}
