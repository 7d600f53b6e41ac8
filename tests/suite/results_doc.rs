//! docs/results.md reads every output file with pandas; this test checks that every column and key
//! its Python example uses exists in the files wiperlab writes, so the example cannot rot.
//!
//! The import, spectrum and simulate outputs are made here (as the doc's commands make them, into a
//! temp dir); the fit's files are the main job's (`reports/reversal/psd_low.csv` is committed;
//! `traces_*.csv` and `fits/reversal.result.toml` exist after the main job ran, e.g. in
//! tests/suite/cli.rs, and are skipped with a message when absent).

use crate::common::{root, temp_dir, wiperlab};

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The first ```python block of docs/results.md.
fn example() -> String {
    let doc = std::fs::read_to_string(root().join("docs/results.md")).expect("docs/results.md");
    let start = doc.find("```python\n").expect("a python block") + "```python\n".len();
    let len = doc[start..].find("```").expect("the block's end");
    doc[start..start + len].to_string()
}

/// Every `"..."` string inside `[...]` subscripts of `var` (`var["a"]`, `var[["a", "b"]]`).
fn subscripts(code: &str, var: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let pat = format!("{var}[");
    let mut rest = code;
    while let Some(i) = rest.find(&pat) {
        // Only whole identifiers: `psd[` must not match inside `tip_psd[`.
        let before = rest[..i].chars().last();
        rest = &rest[i + pat.len()..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let end = rest.find(']').unwrap_or(rest.len());
        let inner = &rest[..end];
        // A boolean mask like peaks[peaks["signal"] == ...] holds its own subscript: skip to it.
        out.extend(
            inner
                .split('"')
                .skip(1)
                .step_by(2)
                .filter(|s| !s.is_empty())
                .map(str::to_string),
        );
    }
    out
}

/// `var -> path` for every `var = pd.read_csv("path")` of the example.
fn csv_reads(code: &str) -> BTreeMap<String, String> {
    code.lines()
        .filter_map(|l| {
            let (var, rhs) = l.split_once(" = pd.read_csv(\"")?;
            let path = rhs.split('"').next()?;
            Some((var.trim().to_string(), path.to_string()))
        })
        .collect()
}

fn csv_header(path: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .next()
        .unwrap_or("")
        .split(',')
        .map(str::to_string)
        .collect()
}

#[test]
fn every_column_the_pandas_example_reads_exists() {
    let code = example();
    let tmp = temp_dir("results_doc");
    let dir = tmp.path();
    std::fs::create_dir_all(dir.join("data/reversal")).expect("mkdir");
    for f in ["wiper_reversal_sample_xypts.csv", "blade_true.toml"] {
        std::fs::copy(
            root().join("data/reversal").join(f),
            dir.join("data/reversal").join(f),
        )
        .expect("copy");
    }
    // The doc's first three commands, in a scratch copy of the layout.
    wiperlab([
        "import",
        "data/reversal/wiper_reversal_sample_xypts.csv",
        "--fps",
        "10000",
        "--m-per-px",
        "1.5e-5",
        "--head",
        "pt1",
        "--tip",
        "pt2",
        "-o",
        "sample.trace.csv",
    ])
    .current_dir(dir)
    .assert()
    .success();
    wiperlab([
        "spectrum",
        "sample.trace.csv",
        "--band",
        "30:300",
        "--band",
        "500:5000",
    ])
    .current_dir(dir)
    .assert()
    .success();
    wiperlab(["simulate", "data/reversal/blade_true.toml"])
        .current_dir(dir)
        .assert()
        .success();
    // Made here, or the main job's (repository root).
    let locate = |rel: &str| -> Option<PathBuf> {
        [dir.join(rel), root().join(rel)]
            .into_iter()
            .find(|p| p.exists())
    };
    let reads = csv_reads(&code);
    assert!(reads.len() >= 7, "the example reads {} CSVs", reads.len());
    let mut checked = 0;
    for (var, rel) in &reads {
        let Some(path) = locate(rel) else {
            println!("skipped {rel}: not written yet (the main job writes it)");
            continue;
        };
        let header = csv_header(&path);
        let used = subscripts(&code, var);
        assert!(
            !used.is_empty(),
            "the example reads {rel} but uses no column"
        );
        for c in &used {
            assert!(header.contains(c), "{rel} has no column {c:?}: {header:?}");
        }
        checked += used.len();
    }
    // peaks.json: a list of objects with the keys the example uses.
    let peaks_rel = "reports/spectrum/sample.trace/peaks.json";
    assert!(code.contains(peaks_rel));
    let peaks: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join(peaks_rel)).expect("peaks.json"))
            .expect("JSON");
    let first = peaks[0].as_object().expect("a list of objects");
    for k in subscripts(&code, "peaks") {
        if k == "tip_x" {
            // the value compared against, not a key
            assert!(
                peaks
                    .as_array()
                    .unwrap()
                    .iter()
                    .any(|p| p["signal"] == "tip_x")
            );
            continue;
        }
        assert!(first.contains_key(&k), "peaks.json has no key {k:?}");
        checked += 1;
    }
    // The result's [[parameters]] keys.
    match locate("fits/reversal.result.toml") {
        Some(p) => {
            let r: toml::Value =
                toml::from_str(&std::fs::read_to_string(p).expect("read")).expect("TOML");
            let p0 = r["parameters"][0].as_table().expect("[[parameters]]");
            for k in subscripts(&code, "params") {
                assert!(p0.contains_key(&k), "result parameters have no key {k:?}");
                checked += 1;
            }
            // The result's own keys (`result["goodness_of_fit"]`) and those of its tables.
            for k in subscripts(&code, "result") {
                assert!(r.get(&k).is_some(), "the result has no key {k:?}");
                checked += 1;
            }
            let gof = r["goodness_of_fit"].as_table().expect("[goodness_of_fit]");
            for k in subscripts(&code, "gof") {
                assert!(gof.contains_key(&k), "goodness_of_fit has no key {k:?}");
                checked += 1;
            }
            let fc = r["friction_curve"].as_table().expect("[friction_curve]");
            for k in subscripts(&code, "fc") {
                assert!(fc.contains_key(&k), "friction_curve has no key {k:?}");
                checked += 1;
            }
        }
        None => println!("skipped fits/reversal.result.toml: the main job writes it"),
    }
    println!("{checked} columns and keys of docs/results.md checked");
}
