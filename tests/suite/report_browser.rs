//! The report page (`wiperlab report JOB` → `reports/<job>/index.html`) opened in a real browser.
//!
//! Each test runs a quick fit (4 particles, 1 swarm iteration, 3 Nelder–Mead iterations, C and k1
//! free: about 30 model runs, a few seconds) of the shipped recording `data/reversal/` in its own
//! temp dir, writes the page, and loads it in headless Chromium (`/usr/bin/chromium`, Debian's
//! `chromium` package, installed by `.ci/run`). The page's inline figure check writes, on the
//! window's `load` event, how many `<img class="figure">` loaded (`naturalWidth > 0`) into
//! `#figure-check`; the tests read it from `chromium --headless --dump-dom`.
//!
//! Without Chromium the browser part of each test prints why it is skipped and the rest still runs;
//! with `WIPERLAB_REQUIRE_BROWSER=1` (set by `.ci/run`) a missing Chromium fails instead.

use crate::common;
use crate::common::{ok, root, run_in, stderr, temp_dir, wiperlab};

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The quick job, named `quick`, with absolute paths into `data/reversal/`. Import settings are the
/// shipped main job's (`fits/reversal.toml`; t0_s from data/reversal/truth.json camera.t0_s). The
/// blade is the true one (A and B at the sample's values) and C, k1 are searched near the truth, so
/// that a handful of model runs keep contact; the page, not the fit's accuracy, is under test.
fn write_quick_job(dir: &Path) -> PathBuf {
    let data = root().join("data/reversal");
    let text = format!(
        r#"name = "quick"
blade = "{data}/blade_true.toml"

{recording}
{spectrum}
[solver]
rtol = 1e-7
atol = 1e-9

[fit]
particles = 4
swarm_iterations = 1
polish_iterations = 3
seed = 3

[fit.parameters]
C = [0.4, 0.7]
k1 = [0.02, 0.04]

[truth]
json = "{data}/truth.json"
keys = {{ C = "/params/C", k1 = "/params/k1" }}
"#,
        data = data.display(),
        recording = common::sample_recording(),
        spectrum = common::spectrum_bands(&[
            ("low", [30.0, 300.0], 4096),
            ("high", [500.0, 5000.0], 2048)
        ]),
    );
    let p = dir.join("quick.toml");
    std::fs::write(&p, text).expect("write the quick job");
    p
}

/// The SVG file names in `dir`, sorted.
fn svgs(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".svg"))
        .collect();
    v.sort();
    v
}

/// Headless Chromium, or `None` after printing why the browser check is skipped.
fn chromium() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("WIPERLAB_CHROMIUM").map(PathBuf::from),
        Some(PathBuf::from("/usr/bin/chromium")),
        Some(PathBuf::from("/usr/bin/chromium-browser")),
    ];
    if let Some(p) = candidates.into_iter().flatten().find(|p| p.is_file()) {
        return Some(p);
    }
    let why = "no Chromium at $WIPERLAB_CHROMIUM, /usr/bin/chromium or /usr/bin/chromium-browser \
               (install Debian's `chromium`; .ci/run does)";
    if std::env::var_os("WIPERLAB_REQUIRE_BROWSER").is_some_and(|v| v == "1") {
        panic!("WIPERLAB_REQUIRE_BROWSER=1 but {why}");
    }
    println!("skipped the browser check: {why}");
    None
}

/// The DOM of `page` after its `load` event, from `chromium --headless --dump-dom` (own profile
/// dir, so parallel tests do not share one; killed after 120 s).
fn dump_dom(chromium: &Path, page: &Path, profile: &Path) -> String {
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    let mut child = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox", // root in CI containers; the page is our own local file
            "--disable-gpu",
            "--no-first-run",
            "--allow-file-access-from-files",
            &format!("--user-data-dir={}", profile.display()),
            "--virtual-time-budget=20000",
            "--hide-scrollbars",
            &format!("--window-size={WINDOW_W},800"),
            "--dump-dom",
            &url,
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot start chromium");
    let started = Instant::now();
    loop {
        if child.try_wait().expect("wait for chromium").is_some() {
            break;
        }
        if started.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium did not finish within 120 s on {url}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let o = child.wait_with_output().expect("chromium output");
    let dom = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        dom.contains("</html>"),
        "chromium returned no DOM for {url} ({:?}); stderr:\n{}",
        o.status,
        String::from_utf8_lossy(&o.stderr)
    );
    dom
}

/// Width of the browser window, CSS pixels, for the DOM dump and the screenshots alike (the
/// layout, and so the boxes the page's script records, depend on it).
const WINDOW_W: u32 = 1100;

/// A decoded screenshot: width, height and RGB pixels row by row.
struct Shot {
    w: u32,
    h: u32,
    rgb: Vec<[u8; 3]>,
}

impl Shot {
    /// Fraction of the pixels of box `(x, y, w, h)` (clipped to the image) that carry ink: any
    /// channel below 200 (text, axes, data; not the white page, the light grid or the #ddd frame).
    fn ink(&self, [x, y, w, h]: [i64; 4]) -> f64 {
        let clip = |v: i64, max: u32| v.clamp(0, max as i64) as u32;
        let (x0, y0) = (clip(x, self.w), clip(y, self.h));
        let (x1, y1) = (clip(x + w, self.w), clip(y + h, self.h));
        let (mut ink, mut all) = (0usize, 0usize);
        for yy in y0..y1 {
            for xx in x0..x1 {
                all += 1;
                if self.rgb[(yy * self.w + xx) as usize]
                    .iter()
                    .any(|c| *c < 200)
                {
                    ink += 1;
                }
            }
        }
        if all == 0 {
            0.0
        } else {
            ink as f64 / all as f64
        }
    }
}

/// A screenshot of `page` in a `WINDOW_W` × `height` window, kept as the PNG `out` and decoded.
/// Killed after 120 s.
fn screenshot(chromium: &Path, page: &Path, profile: &Path, height: u32, out: &Path) -> Shot {
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    let mut child = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--allow-file-access-from-files",
            "--hide-scrollbars",
            &format!("--user-data-dir={}", profile.display()),
            "--virtual-time-budget=20000",
            &format!("--window-size={WINDOW_W},{height}"),
            &format!("--screenshot={}", out.display()),
            &url,
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("cannot start chromium");
    let started = Instant::now();
    while child.try_wait().expect("wait for chromium").is_none() {
        if started.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium took no screenshot within 120 s of {url}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let file = std::fs::File::open(out).unwrap_or_else(|e| panic!("{}: {e}", out.display()));
    let mut dec = png::Decoder::new(std::io::BufReader::new(file));
    dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = dec.read_info().expect("a PNG screenshot");
    let mut buf = vec![0; reader.output_buffer_size().expect("PNG size")];
    let info = reader.next_frame(&mut buf).expect("PNG frame");
    let n = info.color_type.samples();
    assert!(n >= 3, "screenshot in {:?}", info.color_type);
    let rgb = buf[..info.buffer_size()]
        .chunks(n)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    Shot {
        w: info.width,
        h: info.height,
        rgb,
    }
}

/// Boxes `x,y,w,h` separated by spaces, as the page's script writes them.
fn boxes(list: &str) -> Vec<[i64; 4]> {
    list.split_whitespace()
        .map(|b| {
            let v: Vec<i64> = b.split(',').map(|n| n.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

/// Takes a full-page screenshot of `page` (its height as the page's script measured it in
/// `dom`), keeps it as `out`, and returns what did not render: a screenshot not of the page's
/// size, or blank (under 1 % ink); a figure whose box is not its SVG's shape (the file's width ×
/// height, within 3 px inside the 1 px frame) or has under 0.5 % ink; a table with under 0.5 %
/// ink. Figures are named by their `src`.
fn screenshot_problems(
    chromium: &Path,
    page: &Path,
    dom: &str,
    profile: &Path,
    out: &Path,
) -> Vec<String> {
    let i = dom.find("id=\"figure-check\"").expect("figure check");
    let tag = &dom[dom[..i].rfind('<').unwrap()..i + dom[i..].find('>').unwrap()];
    let size: Vec<u32> = attr(tag, "data-page")
        .expect("the page's size in the DOM")
        .split(',')
        .map(|n| n.parse().unwrap())
        .collect();
    assert!(
        size[0] <= WINDOW_W,
        "page {size:?} in a {WINDOW_W} px window"
    );
    let ph = size[1];
    let shot = screenshot(chromium, page, profile, ph, out);
    if (shot.w, shot.h) != (WINDOW_W, ph) {
        return vec![format!(
            "screenshot {}x{}, expected {WINDOW_W}x{ph}",
            shot.w, shot.h
        )];
    }
    let mut problems = Vec::new();
    let all = shot.ink([0, 0, shot.w as i64, shot.h as i64]);
    if all < 0.01 {
        problems.push(format!("page blank ({:.3} % ink)", 100.0 * all));
    }
    let html = std::fs::read_to_string(page).unwrap();
    let srcs: Vec<&str> = html
        .split("<img class=\"figure\" src=\"")
        .skip(1)
        .filter_map(|s| s.split('"').next())
        .collect();
    let figs = boxes(&attr(tag, "data-figure-boxes").unwrap_or_default());
    assert_eq!(figs.len(), srcs.len(), "a box per figure");
    for (src, b) in srcs.iter().zip(figs) {
        let inner = [b[0] + 1, b[1] + 1, b[2] - 2, b[3] - 2];
        let svg = std::fs::read_to_string(page.parent().unwrap().join(src)).unwrap_or_default();
        let head = &svg[..svg.find('>').unwrap_or(0)];
        let want_h = match (num_attr(head, "width"), num_attr(head, "height")) {
            (Some(w), Some(h)) => inner[2] as f64 * h / w,
            _ => f64::NAN,
        };
        let ink = shot.ink(inner);
        if !((inner[3] as f64 - want_h).abs() <= 3.0 && ink >= 0.005) {
            problems.push(format!(
                "{src}: box {b:?} (height {want_h:.0} expected), {:.2} % ink",
                100.0 * ink
            ));
        }
    }
    for (k, b) in boxes(&attr(tag, "data-table-boxes").unwrap_or_default())
        .iter()
        .enumerate()
    {
        let ink = shot.ink(*b);
        if ink < 0.005 || b[3] < 10 {
            problems.push(format!("table {k}: box {b:?}, {:.2} % ink", 100.0 * ink));
        }
    }
    problems
}

/// Keeps the screenshot `shot` as `reports/screenshots/<name>` in the source tree (git-ignored:
/// a CI artefact).
fn keep_screenshot(shot: &Path, name: &str) {
    let dir = root().join("reports/screenshots");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(shot, dir.join(name)).unwrap();
}

/// The figure check's outcome as the page's script left it in the DOM.
#[derive(Debug, PartialEq)]
struct Check {
    status: String,
    loaded: usize,
    total: usize,
    broken: Vec<String>,
}

fn attr(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let i = tag.find(&key)? + key.len();
    let j = tag[i..].find('"')? + i;
    Some(tag[i..j].to_string())
}

fn figure_check(dom: &str) -> Check {
    let i = dom
        .find("id=\"figure-check\"")
        .unwrap_or_else(|| panic!("no #figure-check in the DOM:\n{dom}"));
    let start = dom[..i].rfind('<').unwrap();
    let end = dom[i..].find('>').unwrap() + i;
    let tag = &dom[start..end];
    let n = |k: &str| -> usize {
        attr(tag, k)
            .unwrap_or_else(|| panic!("figure check did not run (no {k}): {tag}"))
            .parse()
            .unwrap()
    };
    Check {
        status: attr(tag, "data-status").unwrap_or_default(),
        loaded: n("data-loaded"),
        total: n("data-total"),
        broken: attr(tag, "data-broken")
            .unwrap_or_default()
            .split_whitespace()
            .map(String::from)
            .collect(),
    }
}

/// The figures `wiperlab fit` always writes for a two-band job (src/report/html.rs
/// `fit_figure_list`).
const FIT_FIGURES: [&str; 6] = [
    "cost.svg",
    "friction_law.svg",
    "psd_high.svg",
    "psd_low.svg",
    "traces_head.svg",
    "traces_tip.svg",
];

/// The figures `wiperlab fit` writes only when the data allow (src/report/html.rs
/// `OPTIONAL_FIGURES`).
const OPTIONAL_FIGURES: [&str; 2] = ["freq_vs_speed.svg", "posterior_corner.svg"];

/// The SVGs of a fit's report directory, checked to be every always-written figure plus only
/// known optional ones.
fn fit_svgs(dir: &Path) -> Vec<String> {
    let figs = svgs(dir);
    for f in FIT_FIGURES {
        assert!(figs.iter().any(|g| g == f), "{f} missing from {figs:?}");
    }
    for g in &figs {
        assert!(
            FIT_FIGURES.contains(&g.as_str()) || OPTIONAL_FIGURES.contains(&g.as_str()),
            "unexpected figure {g}"
        );
    }
    figs
}

/// Quick fit with `wiperlab fit` (checks the report hint), then `wiperlab report` on the existing
/// result; the page holds the tables, the SHA-256 of the recording, and every figure loads.
#[test]
fn report_page_after_a_quick_fit_loads_every_figure_in_chromium() {
    let tmp = temp_dir("ok");
    let job = write_quick_job(tmp.path());
    let job_s = job.to_str().unwrap();
    let out = ok(&run_in(tmp.path(), &["fit", job_s, "--quiet"]), "quick fit");
    assert!(
        out.contains("wiperlab report") && out.contains("reports/quick/index.html"),
        "fit prints no report hint:\n{out}"
    );
    let result = tmp.path().join("quick.result.toml");
    let before = std::fs::read(&result).expect("fit wrote the result");

    let o = run_in(tmp.path(), &["report", job_s]);
    let (out, err) = (ok(&o, "report"), stderr(&o));
    assert!(
        !err.contains("running the fit"),
        "report refitted although the result exists:\n{err}"
    );
    assert_eq!(
        std::fs::read(&result).unwrap(),
        before,
        "report rewrote the result"
    );
    let dir = tmp.path().join("reports/quick");
    let page = dir.join("index.html");
    let figs = fit_svgs(&dir);
    assert!(
        out.contains(&format!("index.html ({} figures)", figs.len())),
        "{out}"
    );
    let html = std::fs::read_to_string(&page).unwrap();

    // Tables: a row per freed parameter, per band; one model only.
    for needle in [
        "<td class=\"l\">C</td>",
        "<td class=\"l\">k1</td>",
        "<td class=\"l\">low</td>",
        "<td class=\"l\">high</td>",
        "Only one model (blade2dof) was fitted",
        "rtol 1e-7, atol 1e-9", // the quick job's [solver]
        "low 30.00–300.0 Hz (Welch, Hann, nperseg 4096)",
        "1 × (particle swarm 4 particles × 1 iterations, Nelder–Mead ≤ 3 iterations), best kept (seed 3)",
    ] {
        assert!(html.contains(needle), "page lacks {needle:?}");
    }
    // A job fitted to a recording has no targets to map.
    assert!(!html.contains("id=\"reachability\""), "a map section");
    // Every figure is linked once; nothing is fetched from elsewhere.
    for f in &figs {
        assert_eq!(
            html.matches(&format!("src=\"{f}\"")).count(),
            1,
            "link to {f}"
        );
    }
    for external in ["http://", "https://", "//cdn", "<link "] {
        assert!(!html.contains(external), "external resource {external:?}");
    }
    // Provenance: the recording's SHA-256 at fit time, checked against coreutils' sha256sum.
    let rec = root().join("data/reversal/wiper_reversal_sample_xypts.csv");
    match Command::new("sha256sum").arg(&rec).output() {
        Ok(o) if o.status.success() => {
            let want = String::from_utf8_lossy(&o.stdout)
                .split_whitespace()
                .next()
                .unwrap()
                .to_string();
            assert!(
                html.contains(&format!("<code id=\"sha256-fit\">{want}</code>")),
                "no fit-time SHA-256 {want}"
            );
            assert!(html.contains(&format!("<code id=\"sha256-now\">{want}</code>")));
        }
        _ => println!("sha256sum not available: SHA-256 not cross-checked"),
    }

    let Some(chromium) = chromium() else { return };
    let dom = dump_dom(&chromium, &page, &tmp.path().join("profile"));
    let check = figure_check(&dom);
    println!("figure check: {check:?}");
    assert_eq!(
        check,
        Check {
            status: "ok".into(),
            loaded: figs.len(),
            total: figs.len(),
            broken: vec![],
        }
    );
    // A full-page screenshot: every figure and table rendered where the page laid it out.
    let shot = tmp.path().join("report_quick.png");
    let problems = screenshot_problems(&chromium, &page, &dom, &tmp.path().join("shot"), &shot);
    assert!(problems.is_empty(), "{problems:?}");
    keep_screenshot(&shot, "report_quick.png");
}

/// The check must be able to fail: a page whose link points at a missing file, and a figure whose
/// SVG is cut in half, are both reported broken by name. (Also: `report` without a result is an
/// input error that says how to get one, exit 2, nothing written; `--refit` fits first.)
#[test]
fn browser_check_catches_a_broken_link_and_a_corrupt_svg() {
    let tmp = temp_dir("broken");
    let job = write_quick_job(tmp.path());
    let o = run_in(tmp.path(), &["report", job.to_str().unwrap(), "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("no fit result") && err.contains("--refit"),
        "{err}"
    );
    assert!(!tmp.path().join("quick.result.toml").exists());
    assert!(!tmp.path().join("reports/quick/index.html").exists());
    ok(
        &run_in(
            tmp.path(),
            &["report", job.to_str().unwrap(), "--refit", "--quiet"],
        ),
        "report --refit",
    );
    assert!(tmp.path().join("quick.result.toml").is_file());
    let dir = tmp.path().join("reports/quick");
    let page = dir.join("index.html");
    let html = std::fs::read_to_string(&page).unwrap();
    let n = fit_svgs(&dir).len();

    let Some(chromium) = chromium() else { return };
    // 1. A broken link, in a copy of the page beside the original.
    let bad_link = dir.join("broken_link.html");
    assert_eq!(html.matches("src=\"psd_high.svg\"").count(), 1);
    std::fs::write(
        &bad_link,
        html.replace("src=\"psd_high.svg\"", "src=\"psd_missing.svg\""),
    )
    .unwrap();
    let dom = dump_dom(&chromium, &bad_link, &tmp.path().join("p1"));
    let check = figure_check(&dom);
    println!("broken link: {check:?}");
    assert_eq!(check.status, "broken");
    assert_eq!((check.loaded, check.total), (n - 1, n));
    assert_eq!(check.broken, ["psd_missing.svg"]);
    // The screenshot check names the missing figure, and only it.
    let problems = screenshot_problems(
        &chromium,
        &bad_link,
        &dom,
        &tmp.path().join("s1"),
        &tmp.path().join("broken.png"),
    );
    println!("broken link, screenshot: {problems:?}");
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(problems[0].starts_with("psd_missing.svg: "), "{problems:?}");

    // A figure that loads but shows nothing (a valid, all-white SVG of the usual size): the
    // figure check counts it loaded, the screenshot finds it blank.
    let head = dir.join("traces_head.svg");
    let kept = std::fs::read(&head).unwrap();
    std::fs::write(
        &head,
        "<svg width=\"900\" height=\"500\" viewBox=\"0 0 3600 2000\" \
         xmlns=\"http://www.w3.org/2000/svg\"><rect width=\"3600\" height=\"2000\" fill=\"#FFFFFF\"/></svg>",
    )
    .unwrap();
    let dom = dump_dom(&chromium, &page, &tmp.path().join("p3"));
    assert_eq!(figure_check(&dom).status, "ok");
    let problems = screenshot_problems(
        &chromium,
        &page,
        &dom,
        &tmp.path().join("s3"),
        &tmp.path().join("blank.png"),
    );
    println!("blank figure, screenshot: {problems:?}");
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(problems[0].starts_with("traces_head.svg: "), "{problems:?}");
    std::fs::write(&head, kept).unwrap();

    // 2. A corrupt figure: the original page, with traces_tip.svg truncated (unclosed XML).
    let svg = dir.join("traces_tip.svg");
    let text = std::fs::read_to_string(&svg).unwrap();
    std::fs::write(&svg, &text[..text.len() / 2]).unwrap();
    let check = figure_check(&dump_dom(&chromium, &page, &tmp.path().join("p2")));
    println!("corrupt SVG: {check:?}");
    assert_eq!(check.status, "broken");
    assert_eq!((check.loaded, check.total), (n - 1, n));
    assert_eq!(check.broken, ["traces_tip.svg"]);
}

/// Text from results is escaped: a warning and a model-comparison row carrying markup appear as
/// text, and the browser still sees only the real figures (an unescaped `<img class="figure">`
/// would be one more, broken). Also renders the model-comparison table.
#[test]
fn report_escapes_text_from_the_result() {
    let tmp = temp_dir("escape");
    let job = write_quick_job(tmp.path());
    let job_s = job.to_str().unwrap();
    ok(&run_in(tmp.path(), &["fit", job_s, "--quiet"]), "quick fit");
    let result = tmp.path().join("quick.result.toml");
    let mut t: toml::Table = toml::from_str(&std::fs::read_to_string(&result).unwrap()).unwrap();
    let evil = r#"<img class="figure" src="injected.svg"> & "quotes""#;
    t.insert("warnings".into(), toml::Value::Array(vec![evil.into()]));
    // Without details, the sentence is shown as written.
    t.remove("warning_details");
    let trial = |model: &str, cost: f64, chosen: bool| {
        let mut m = toml::Table::new();
        m.insert("model".into(), model.into());
        m.insert("parameters".into(), toml::Value::Array(vec!["k1".into()]));
        m.insert("cost".into(), cost.into());
        m.insert("wall_time_s".into(), 1.25.into());
        m.insert("model_evaluations".into(), 30.into());
        m.insert("chosen".into(), chosen.into());
        m.insert("reason".into(), format!("<b>cost {cost}</b>").into());
        toml::Value::Table(m)
    };
    t.insert(
        "model_trials".into(),
        toml::Value::Array(vec![
            trial("head1dof", 7.5, false),
            trial("blade2dof", 1.5, true),
        ]),
    );
    std::fs::write(&result, toml::to_string(&t).unwrap()).unwrap();

    ok(&run_in(tmp.path(), &["report", job_s]), "report");
    let page = tmp.path().join("reports/quick/index.html");
    let n = fit_svgs(&tmp.path().join("reports/quick")).len();
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(!html.contains("injected.svg\">"), "unescaped markup");
    assert!(html.contains(
        "<li>&lt;img class=&quot;figure&quot; src=&quot;injected.svg&quot;&gt; &amp; &quot;quotes&quot;</li>"
    ));
    assert!(html.contains("&lt;b&gt;cost 7.5&lt;/b&gt;"));
    assert!(html.contains("<tr class=\"chosen\"><td class=\"l\">blade2dof</td>"));
    assert!(!html.contains("Only one model"));

    let Some(chromium) = chromium() else { return };
    let check = figure_check(&dump_dom(&chromium, &page, &tmp.path().join("profile")));
    assert_eq!((check.status.as_str(), check.total), ("ok", n), "{check:?}");
}

/// A result file that is not a fit result is a one-line input error naming the file, line and
/// column (exit code 2), not a panic and not a silent refit.
#[test]
fn unreadable_result_is_a_clear_input_error() {
    let tmp = temp_dir("bad_result");
    let job = write_quick_job(tmp.path());
    let result = tmp.path().join("quick.result.toml");
    std::fs::write(&result, "job = \"quick\"\ncost = \"low\"\n").unwrap();
    let o = run_in(tmp.path(), &["report", job.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "stderr:\n{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(
        lines[0].starts_with(&format!("error: {}:2:", result.display())),
        "{err}"
    );
    assert!(!tmp.path().join("reports/quick/index.html").exists());
    assert_eq!(
        std::fs::read_to_string(&result).unwrap(),
        "job = \"quick\"\ncost = \"low\"\n",
        "the result was overwritten"
    );
}

/// Attribute `name="..."` of the SVG element text `el`, as a number.
fn num_attr(el: &str, name: &str) -> Option<f64> {
    let i = el.find(&format!(" {name}=\""))? + name.len() + 3;
    el[i..].split('"').next()?.parse().ok()
}

/// Every polyline vertex, point along each polyline segment (32 per segment) and circle of `svg`
/// that lies inside a legend box (each `<g class="legend">`'s first `<rect>`, grown by a circle's
/// radius), described; and the legend boxes. `Err` when the figure has no legend group.
fn data_under_legend(svg: &str) -> Result<(Vec<String>, Vec<[f64; 4]>), String> {
    let mut boxes = Vec::new();
    let mut data = String::new();
    let mut rest = svg;
    while let Some(start) = rest.find("<g class=\"legend\">") {
        let end = start
            + rest[start..]
                .find("</g>")
                .ok_or("legend group not closed")?;
        let legend = &rest[start..end];
        let rect = &legend[legend.find("<rect").ok_or("legend without a box")?..];
        let [x, y, w, h] =
            ["x", "y", "width", "height"].map(|a| num_attr(rect, a).unwrap_or(f64::NAN));
        if ![x, y, w, h].iter().all(|v| v.is_finite()) || w <= 0.0 || h <= 0.0 {
            return Err(format!("legend box unreadable: {rect:.80}"));
        }
        boxes.push([x, y, w, h]);
        data += &rest[..start];
        rest = &rest[end..];
    }
    if boxes.is_empty() {
        return Err("no legend group".into());
    }
    data += rest;
    Ok((data_in_boxes(&data, &boxes), boxes))
}

/// Every polyline vertex, point along each polyline segment (32 per segment) and circle of `data`
/// that lies inside one of `boxes` (`[x, y, width, height]`, grown by a circle's radius),
/// described.
fn data_in_boxes(data: &str, boxes: &[[f64; 4]]) -> Vec<String> {
    let inside = |px: f64, py: f64, grow: f64| {
        boxes.iter().any(|[x, y, w, h]| {
            px > x - grow && px < x + w + grow && py > y - grow && py < y + h + grow
        })
    };
    let mut hits = Vec::new();
    for el in data.split('<').skip(1) {
        if el.starts_with("polyline") {
            let pts: Vec<(f64, f64)> = el
                .split("points=\"")
                .nth(1)
                .and_then(|p| p.split('"').next())
                .unwrap_or("")
                .split_whitespace()
                .filter_map(|p| {
                    let (a, b) = p.split_once(',')?;
                    Some((a.parse().ok()?, b.parse().ok()?))
                })
                .collect();
            for s in pts.windows(2) {
                for k in 0..=32 {
                    let f = k as f64 / 32.0;
                    let (px, py) = (
                        s[0].0 + f * (s[1].0 - s[0].0),
                        s[0].1 + f * (s[1].1 - s[0].1),
                    );
                    if inside(px, py, 0.0) {
                        hits.push(format!("polyline through ({px:.0}, {py:.0})"));
                    }
                }
            }
        } else if el.starts_with("circle") {
            let (cx, cy, r) = (num_attr(el, "cx"), num_attr(el, "cy"), num_attr(el, "r"));
            if let (Some(cx), Some(cy), Some(r)) = (cx, cy, r)
                && inside(cx, cy, r)
            {
                hits.push(format!("circle at ({cx}, {cy})"));
            }
        }
    }
    hits
}

/// The boxes of the marker labels of `svg` (`<text class="marker-label">`, `[x, y, width,
/// height]`): from `x` to `x + textLength`, and from `0.8·font-size` above the baseline `y` to
/// `0.25·font-size` below it (plot.rs's module docs).
fn label_boxes(svg: &str) -> Vec<[f64; 4]> {
    svg.split("<text class=\"marker-label\"")
        .skip(1)
        .map(|t| {
            let open = &t[..t.find('>').unwrap_or(t.len())];
            let [x, y, fs, w] = ["x", "y", "font-size", "textLength"]
                .map(|a| num_attr(open, a).unwrap_or(f64::NAN));
            [x, y - 0.8 * fs, w, 1.05 * fs]
        })
        .collect()
}

/// Data (outside the legends and the labels' own group) passing under a marker label, described,
/// with the label boxes; every box must be readable.
fn data_under_labels(svg: &str) -> (Vec<String>, Vec<[f64; 4]>) {
    let boxes = label_boxes(svg);
    for b in &boxes {
        assert!(
            b.iter().all(|v| v.is_finite()) && b[2] > 0.0,
            "unreadable label box {b:?}"
        );
    }
    let mut data = svg.to_string();
    for group in ["<g class=\"legend\">", "<g class=\"marker-labels\">"] {
        while let Some(start) = data.find(group) {
            let end = start + data[start..].find("</g>").expect("group not closed") + 4;
            data.replace_range(start..end, "");
        }
    }
    (data_in_boxes(&data, &boxes), boxes)
}

/// The axis titles of a plotters figure: the `<text>` elements turned upright (y axes, colour
/// bars: `rotate(270, …)`) or hung above their anchor (x axes: `dy="-0.5ex"`); tick labels and
/// titles are neither.
fn axis_labels(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let (open, rest) = t.split_once('>')?;
            let text = rest.split("</text>").next()?.trim();
            (open.contains("transform=\"rotate(") || open.contains("dy=\"-0.5ex\""))
                .then(|| text.to_string())
        })
        .collect()
}

/// Checks one figure of `what`: drawn at 4× and shown through the viewBox (quarter-pixel
/// coordinates), every axis title (at least two) names a unit in brackets, and no data passes
/// under a legend. Figures in `no_legend` (heatmaps: a colour bar, no series) must have none; every
/// other figure must have one.
fn check_figure(what: &str, dir: &Path, name: &str, no_legend: bool) {
    let svg = std::fs::read_to_string(dir.join(name)).unwrap();
    let f = format!("{what} {name}");
    let head = &svg[..svg.find('>').unwrap()];
    let (w, h) = (
        num_attr(head, "width").unwrap(),
        num_attr(head, "height").unwrap(),
    );
    assert!(
        head.contains(&format!("viewBox=\"0 0 {} {}\"", 4.0 * w, 4.0 * h)),
        "{f}: not drawn at 4x: {head}"
    );
    let labels = axis_labels(&svg);
    assert!(labels.len() >= 2, "{f}: axis titles {labels:?}");
    for l in &labels {
        let unit = l
            .find('[')
            .and_then(|i| l[i..].find(']').filter(|j| *j > 1));
        assert!(unit.is_some(), "{f}: axis title {l:?} names no unit");
    }
    match data_under_legend(&svg) {
        Ok((hits, b)) => {
            assert!(!no_legend, "{f}: a legend where none was expected");
            assert!(hits.is_empty(), "{f}: legend boxes {b:?} cover {hits:?}");
        }
        Err(e) => assert!(no_legend, "{f}: {e}"),
    }
    let (hits, b) = data_under_labels(&svg);
    assert!(hits.is_empty(), "{f}: marker labels {b:?} cover {hits:?}");
}

/// The checker finds data under a legend box drawn over it (a hand-made SVG whose polyline
/// crosses the box without a vertex inside it, and a circle beside it within its radius).
#[test]
fn legend_check_can_fail() {
    let svg = "<svg><polyline points=\"0,50 200,50\"/><circle cx=\"95\" cy=\"10\" r=\"6\"/>\
               <g class=\"legend\"><rect x=\"100\" y=\"0\" width=\"50\" height=\"60\"/></g></svg>";
    let (hits, _) = data_under_legend(svg).unwrap();
    assert!(hits.iter().any(|h| h.starts_with("polyline")), "{hits:?}");
    assert!(hits.iter().any(|h| h.starts_with("circle")), "{hits:?}");
    assert!(data_under_legend("<svg><polyline points=\"0,0 1,1\"/></svg>").is_err());
    // With two legends (a panel each), data under the second one is found too.
    let two = "<svg><g class=\"legend\"><rect x=\"0\" y=\"0\" width=\"10\" height=\"10\"/></g>\
               <circle cx=\"50\" cy=\"50\" r=\"1\"/>\
               <g class=\"legend\"><rect x=\"45\" y=\"45\" width=\"10\" height=\"10\"/></g></svg>";
    let (hits, boxes) = data_under_legend(two).unwrap();
    assert_eq!((hits.len(), boxes.len()), (1, 2), "{hits:?}");
}

/// The label checker finds a curve through a label and a marker's circle under it, and passes a
/// label beside them.
#[test]
fn label_check_can_fail() {
    let label = |x: f64, y: f64| {
        format!(
            "<g class=\"marker-labels\"><text class=\"marker-label\" x=\"{x}\" y=\"{y}\" \
             font-size=\"52\" textLength=\"300\">model 876.39 Hz</text></g>"
        )
    };
    // The label covers [100, 400] × [58.4, 114.6]; the curve runs along y = 100.
    let svg = format!(
        "<svg><polyline points=\"0,100 500,100\"/><circle cx=\"90\" cy=\"80\" r=\"20\"/>{}</svg>",
        label(100.0, 100.0)
    );
    let (hits, boxes) = data_under_labels(&svg);
    assert_eq!(boxes, [[100.0, 58.4, 300.0, 1.05 * 52.0]]);
    assert!(hits.iter().any(|h| h.starts_with("polyline")), "{hits:?}");
    assert!(hits.iter().any(|h| h.starts_with("circle")), "{hits:?}");
    // The same label 100 units higher is clear of both.
    let svg = format!(
        "<svg><polyline points=\"0,100 500,100\"/><circle cx=\"90\" cy=\"80\" r=\"20\"/>{}</svg>",
        label(100.0, 0.0)
    );
    assert!(data_under_labels(&svg).0.is_empty());
}

/// The axis-title reader finds plotters' x title (hung above its anchor) and rotated y title, and
/// not tick labels or the title.
#[test]
fn axis_titles_are_found_with_and_without_units() {
    let svg = "<svg><text x=\"1\" y=\"1\" dy=\"0.76em\" text-anchor=\"middle\">\ntitle\n</text>\
               <text x=\"5\" y=\"9\" dy=\"0.5ex\">\n0.5\n</text>\
               <text x=\"5\" y=\"9\" dy=\"-0.5ex\" text-anchor=\"middle\">\nt [s]\n</text>\
               <text x=\"2\" y=\"3\" transform=\"rotate(270, 2, 3)\">\nphase\n</text></svg>";
    assert_eq!(axis_labels(svg), ["t [s]", "phase"]);
}

/// Every figure the quick fit writes has a legend, and no data line, point or marker passes under
/// it. The figures are drawn at 4× scale and shown at 900 × 500 through the viewBox (so
/// coordinates fall on quarter pixels).
#[test]
fn legends_cover_no_data_in_any_fit_figure() {
    let tmp = temp_dir("legends");
    let job = write_quick_job(tmp.path());
    ok(
        &run_in(tmp.path(), &["fit", job.to_str().unwrap(), "--quiet"]),
        "quick fit",
    );
    let dir = tmp.path().join("reports/quick");
    let figs = svgs(&dir);
    assert!(figs.len() >= 5, "{figs:?}");
    for f in &figs {
        let svg = std::fs::read_to_string(dir.join(f)).unwrap();
        assert!(
            svg.starts_with("<svg width=\"900\" height=\"500\" viewBox=\"0 0 3600 2000\""),
            "{f}: {:.100}",
            svg
        );
        check_figure("fit", &dir, f, false);
    }
}

/// The SVG files of `dir`, checked to be at least `min` many.
fn svgs_at_least(dir: &Path, min: usize) -> Vec<String> {
    let figs = svgs(dir);
    assert!(figs.len() >= min, "{}: {figs:?}", dir.display());
    figs
}

/// The figures of every other command that draws, made with the real binary on small inputs in a
/// temp dir: `spectrum` of the shipped recording (import settings of fits/reversal.toml),
/// `simulate` of the true blade, `bench --quick`, `explore` of the seed-experiment job with
/// three freed parameters (16 samples), and `campaign collect` after a tiny two-recording
/// campaign. Each passes [`check_figure`]: quarter-pixel coordinates, units on every axis and
/// colour bar, no data under a legend (the spectrograms are the only figures without one).
/// `modes` prints a table and draws nothing.
#[test]
fn every_figure_of_every_command_has_units_and_a_legend_over_no_data() {
    let tmp = temp_dir("all_figures");
    let rec = root().join("data/reversal/wiper_reversal_sample_xypts.csv");
    let dir = |n: &str| tmp.path().join(n);
    let s = |p: PathBuf| p.to_str().unwrap().to_string();
    let run = |args: &[String], what: &str| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        ok(&run_in(tmp.path(), &args), what)
    };
    let spectrum = [
        "spectrum",
        &s(rec),
        "--fps",
        "10000",
        "--m-per-px",
        "1.5e-5",
        "--origin-px",
        "200,300",
        "--out-dir",
        &s(dir("spectrum")),
        "-q",
    ];
    run(&spectrum.map(String::from), "spectrum");
    let blade = root().join("data/reversal/blade_true.toml");
    run(
        &["simulate", &s(blade), "--out-dir", &s(dir("simulate"))].map(String::from),
        "simulate",
    );
    run(
        &["bench", "--quick", "--out-dir", &s(dir("bench")), "-q"].map(String::from),
        "bench --quick",
    );
    let job = explore_job(tmp.path());
    run(
        &[
            "explore",
            &s(job),
            "--samples",
            "16",
            "--seed",
            "1",
            "--out-dir",
            &s(dir("explore")),
            "-q",
        ]
        .map(String::from),
        "explore",
    );
    let campaign = tiny_campaign(&dir("campaign"));
    run(
        &["campaign", "run", &s(campaign.clone()), "-q"].map(String::from),
        "campaign run",
    );
    run(
        &["campaign", "collect", &s(campaign)].map(String::from),
        "campaign collect",
    );

    let spec = svgs_at_least(&dir("spectrum"), 8);
    for f in &spec {
        check_figure(
            "spectrum",
            &dir("spectrum"),
            f,
            f.starts_with("spectrogram_"),
        );
    }
    for (what, n) in [("simulate", 3), ("bench", 5), ("explore", 1)] {
        for f in svgs_at_least(&dir(what), n) {
            check_figure(what, &dir(what), &f, false);
        }
    }
    let report = dir("campaign/c/report");
    for f in svgs_at_least(&report, 3) {
        check_figure("campaign collect", &report, &f, false);
    }
    // Both of the map's panels have their legend (targets and start; failure causes).
    let map = std::fs::read_to_string(dir("explore/reachability.svg")).unwrap();
    assert_eq!(
        map.matches("<g class=\"legend\">").count(),
        2,
        "reachability.svg"
    );
}

/// fits/seed_experiment_geometry.toml (target job: 78.4 Hz and 900 Hz) with absolute paths, C,
/// the head mass and the lip length freed, and a tiny search.
fn explore_job(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(root().join("fits/seed_experiment_geometry.toml")).unwrap();
    // Without its `reports_dir = "../reports"`, the page and the exploration go to `reports/`
    // beside the copy, in `dir`.
    let text = text
        .replace(
            "\"../data/",
            &format!("\"{}/", root().join("data").display()),
        )
        .replace("reports_dir = \"../reports\"", "");
    let head = text.split("[fit]").next().unwrap();
    let path = dir.join("explore_job.toml");
    std::fs::write(
        &path,
        format!(
            "{head}[fit]\nparticles = 4\nswarm_iterations = 1\npolish_iterations = 2\nseed = 1\n\n\
             [fit.parameters]\nC = [0.3, 0.8]\nhead_mass = [0.01, 0.15]\nl2 = [0.003, 0.006]\n"
        ),
    )
    .unwrap();
    path
}

/// A campaign in `dir` over copies of two of data/campaign/'s recordings (two compounds at the
/// normal sweep), on the example template with a tiny search (4 particles, 1 swarm iteration, 3
/// Nelder–Mead iterations, 1 restart): `dir/c.toml`.
fn tiny_campaign(dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let data = root().join("data/campaign");
    let table = std::fs::read_to_string(data.join("conditions.csv")).unwrap();
    let mut rows = vec![table.lines().next().unwrap().to_string()];
    for r in ["hard_normal_xypts.csv", "soft_normal_xypts.csv"] {
        std::fs::copy(data.join(r), dir.join(r)).unwrap();
        rows.extend(
            table
                .lines()
                .filter(|l| l.starts_with(&format!("{r},")))
                .map(String::from),
        );
    }
    std::fs::write(dir.join("conditions.csv"), rows.join("\n") + "\n").unwrap();
    let template = std::fs::read_to_string(root().join("campaigns/example_template.toml")).unwrap();
    let template: String = template
        .replace(
            "\"../data/",
            &format!("\"{}/", root().join("data").display()),
        )
        .lines()
        .map(|l| match l.split(' ').next() {
            Some("particles") => "particles = 4".to_string(),
            Some("swarm_iterations") => "swarm_iterations = 1".to_string(),
            Some("polish_iterations") => "polish_iterations = 3".to_string(),
            Some("restarts") => "restarts = 1".to_string(),
            _ => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(dir.join("t.toml"), template).unwrap();
    let c = dir.join("c.toml");
    std::fs::write(
        &c,
        "template = \"t.toml\"\nrecordings = [\"*_xypts.csv\"]\nconditions = \"conditions.csv\"\n",
    )
    .unwrap();
    c
}

/// `fit` writes the numbers behind its figures as CSV beside the SVGs, with the column names the
/// docs give (units in the names), and the result lists them: PSD per band on the band's bins
/// (frequencies inside the job's band, increasing), measured and model traces.
#[test]
fn fit_writes_psd_and_trace_csv_with_named_columns() {
    let tmp = temp_dir("csv");
    let job = write_quick_job(tmp.path());
    ok(
        &run_in(tmp.path(), &["fit", job.to_str().unwrap(), "--quiet"]),
        "quick fit",
    );
    let dir = tmp.path().join("reports/quick");
    let read = |name: &str| -> (Vec<String>, Vec<Vec<f64>>) {
        let mut r =
            csv::Reader::from_path(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let header = r.headers().unwrap().iter().map(str::to_string).collect();
        let rows = r
            .records()
            .map(|rec| {
                rec.unwrap()
                    .iter()
                    .map(|v| v.parse::<f64>().unwrap())
                    .collect()
            })
            .collect();
        (header, rows)
    };
    // The quick job's bands: low 30–300 Hz, high 500–5000 Hz.
    for (band, lo, hi) in [("low", 30.0, 300.0), ("high", 500.0, 5000.0)] {
        let (h, rows) = read(&format!("psd_{band}.csv"));
        assert_eq!(
            h,
            ["freq_hz", "psd_measured_m2_per_hz", "psd_model_m2_per_hz"]
        );
        assert!(rows.len() > 5, "{band}: {} rows", rows.len());
        assert!(
            rows.windows(2).all(|w| w[0][0] < w[1][0]),
            "{band}: bins increase"
        );
        assert!(
            rows.iter().all(|r| r[0] >= lo && r[0] <= hi),
            "{band}: bins in band"
        );
        assert!(
            rows.iter().all(|r| r[1] > 0.0 && r[2] > 0.0),
            "{band}: positive PSD"
        );
    }
    for name in ["traces_measured.csv", "traces_model.csv"] {
        let (h, rows) = read(name);
        assert_eq!(h, ["t_s", "tip_rel_x_m", "head_y_m"], "{name}");
        assert!(rows.len() > 100, "{name}: {} rows", rows.len());
    }
    let result: toml::Table =
        toml::from_str(&std::fs::read_to_string(tmp.path().join("quick.result.toml")).unwrap())
            .unwrap();
    let listed: Vec<&str> = result["data_files"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|v| v.as_str())
        .collect();
    assert_eq!(
        listed,
        [
            "psd_low.csv",
            "psd_high.csv",
            "traces_measured.csv",
            "traces_model.csv",
            "friction_curve.csv"
        ]
    );
}

/// `spectrum` writes psd.csv (f_hz, then one PSD column per signal, units in the names) and
/// peaks.json (signal, band, freq_hz, psd_m2_per_hz, prominence per peak) beside its figures, for
/// the shipped sample recording (import settings of fits/reversal.toml).
#[test]
fn spectrum_writes_psd_csv_and_peaks_json() {
    let tmp = temp_dir("spectrum_csv");
    let rec = root().join("data/reversal/wiper_reversal_sample_xypts.csv");
    let out = tmp.path().join("spec");
    let args = [
        "spectrum",
        rec.to_str().unwrap(),
        "--fps",
        "10000",
        "--m-per-px",
        "1.5e-5",
        "--origin-px",
        "200,300",
        "--band",
        "30:300",
        "--band",
        "500:5000",
        "--out-dir",
        out.to_str().unwrap(),
    ];
    ok(&run_in(tmp.path(), &args), "spectrum");
    // Each PSD figure shades the two bands, names them in its legend, and keeps its labels and
    // legend off the data.
    let psd_svgs: Vec<String> = svgs(&out)
        .into_iter()
        .filter(|f| f.starts_with("psd_"))
        .collect();
    assert!(!psd_svgs.is_empty());
    for f in &psd_svgs {
        let svg = std::fs::read_to_string(out.join(f)).unwrap();
        let legend = &svg[svg.find("<g class=\"legend\">").unwrap()..];
        assert!(
            legend.contains("band 30–300 Hz") && legend.contains("band 500–5000 Hz"),
            "{f}"
        );
        check_figure("spectrum --band", &out, f, false);
    }
    // Beside each spectrogram, its numbers: one row per cell, time-major, frequencies ascending
    // within each time.
    let sgs: Vec<String> = svgs(&out)
        .into_iter()
        .filter(|f| f.starts_with("spectrogram_"))
        .collect();
    assert!(!sgs.is_empty());
    for f in &sgs {
        let csv_path = out.join(f.replace(".svg", ".csv"));
        let mut r = csv::Reader::from_path(&csv_path).unwrap();
        let header: Vec<String> = r.headers().unwrap().iter().map(str::to_string).collect();
        assert_eq!(header, ["t_s", "freq_hz", "psd_m2_per_hz"], "{f}");
        let rows: Vec<[f64; 3]> = r
            .records()
            .map(|rec| {
                let v: Vec<f64> = rec.unwrap().iter().map(|v| v.parse().unwrap()).collect();
                [v[0], v[1], v[2]]
            })
            .collect();
        let times = rows.windows(2).filter(|w| w[1][0] != w[0][0]).count() + 1;
        let freqs = rows.iter().filter(|r| r[0] == rows[0][0]).count();
        assert!(times > 10 && freqs > 10, "{f}: {times} × {freqs}");
        assert_eq!(rows.len(), times * freqs, "{f}");
        for block in rows.chunks(freqs) {
            assert!(block.iter().all(|r| r[0] == block[0][0]), "{f}");
            assert!(block.windows(2).all(|w| w[0][1] < w[1][1]), "{f}");
        }
        assert!(rows.iter().all(|r| r[2] >= 0.0), "{f}");
    }
    let mut r = csv::Reader::from_path(out.join("psd.csv")).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(str::to_string).collect();
    assert_eq!(header[0], "f_hz");
    assert!(header.len() >= 3, "{header:?}");
    assert!(
        header[1..].iter().all(|h| h.ends_with("_psd_m2_per_hz")),
        "{header:?}"
    );
    let rows: Vec<Vec<f64>> = r
        .records()
        .map(|rec| rec.unwrap().iter().map(|v| v.parse().unwrap()).collect())
        .collect();
    assert!(rows.len() > 100 && rows.windows(2).all(|w| w[0][0] < w[1][0]));
    let peaks: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("peaks.json")).unwrap()).unwrap();
    let peaks = peaks.as_array().unwrap();
    assert!(!peaks.is_empty());
    for p in peaks {
        for k in ["signal", "band", "freq_hz", "psd_m2_per_hz", "prominence"] {
            assert!(p.get(k).is_some(), "{p} lacks {k}");
        }
        assert!(p["freq_hz"].as_f64().unwrap() > 0.0);
    }
}

/// A fit whose stderr is not a terminal (here a pipe) prints one-line progress messages instead of
/// the bar: at most one per interval (5 s by default; 0 here through WIPERLAB_PROGRESS_INTERVAL_S),
/// each with the stage, the model runs so far and the elapsed time; `--quiet` prints none.
#[test]
fn piped_fit_prints_progress_lines() {
    let tmp = temp_dir("piped");
    let job = write_quick_job(tmp.path());
    let run = |quiet: bool| {
        let mut args = vec!["fit", job.to_str().unwrap()];
        if quiet {
            args.push("--quiet");
        }
        wiperlab(&args)
            .current_dir(tmp.path())
            .env("WIPERLAB_PROGRESS_INTERVAL_S", "0")
            .output()
            .unwrap()
    };
    let o = run(false);
    assert!(o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("progress: "))
        .collect();
    assert!(lines.len() >= 2, "{err}");
    assert!(
        lines
            .iter()
            .all(|l| l.contains("model runs") && l.ends_with(" s")),
        "{err}"
    );
    assert!(lines.iter().any(|l| l.contains("blade2dof")), "{err}");
    let quiet = run(true);
    assert!(quiet.status.success());
    assert!(!String::from_utf8_lossy(&quiet.stderr).contains("progress: "));
}

/// A target job's page (issue 17 point 6): the blade's modes table, and the reachability map of
/// `wiperlab explore` once an exploration of the job exists beside the page
/// (`reports/explore/<job>/reachability.svg`, linked as `../explore/<job>/reachability.svg`);
/// before it, the section says how to make one. In Chromium the map loads with the fit's figures.
#[test]
fn target_job_page_shows_the_modes_and_the_exploration_map() {
    let tmp = temp_dir("target_map");
    let job = explore_job(tmp.path());
    let job_s = job.to_str().unwrap();
    ok(
        &run_in(tmp.path(), &["fit", job_s, "--quiet"]),
        "target fit",
    );
    ok(&run_in(tmp.path(), &["report", job_s, "--quiet"]), "report");
    let dir = tmp.path().join("reports/seed_experiment_geometry");
    let page = dir.join("index.html");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("<h2 id=\"reachability\">"), "no map section");
    assert!(
        html.contains("<p id=\"reachability-map\">No exploration of this job"),
        "no hint without an exploration"
    );
    // The modes table: stick and steady slip at the window's speeds.
    let modes = &html[html
        .find("<table id=\"modes-table\">")
        .expect("modes table")..];
    let modes = &modes[..modes.find("</table>").unwrap()];
    assert!(modes.contains("<td class=\"l\">stick</td>"), "{modes}");
    assert!(
        modes.matches("<td class=\"l\">slip at ").count() >= 3,
        "{modes}"
    );

    ok(
        &run_in(
            tmp.path(),
            &["explore", job_s, "--samples", "8", "--seed", "1", "--quiet"],
        ),
        "explore",
    );
    assert!(
        tmp.path()
            .join("reports/explore/seed_experiment_geometry/reachability.svg")
            .is_file()
    );
    ok(&run_in(tmp.path(), &["report", job_s, "--quiet"]), "report");
    let html = std::fs::read_to_string(&page).unwrap();
    let link = "<img class=\"figure\" src=\"../explore/seed_experiment_geometry/reachability.svg\"";
    assert_eq!(html.matches(link).count(), 1, "map not linked once");
    assert!(!html.contains("No exploration of this job"));
    let n = svgs(&dir).len() + 1;

    let Some(chromium) = chromium() else { return };
    let dom = dump_dom(&chromium, &page, &tmp.path().join("profile"));
    let check = figure_check(&dom);
    println!("target job page: {check:?}");
    assert_eq!(
        (check.status.as_str(), check.loaded, check.total),
        ("ok", n, n)
    );
    let shot = tmp.path().join("report_target_job.png");
    let problems = screenshot_problems(&chromium, &page, &dom, &tmp.path().join("shot"), &shot);
    assert!(problems.is_empty(), "{problems:?}");
    keep_screenshot(&shot, "report_target_job.png");
}
