//! Import stage against real and sample files in `../shared` (skipped when that folder is absent).
//!
//! Every expected number states where it comes from: `shared/realdata/SOURCES.md`, the file itself
//! (counted with a shell/Python one-liner given in the comment), or `shared/sample/truth.json`.

use crate::common;

use std::collections::BTreeMap;
use std::io::BufRead;
use std::path::Path;

use crate::common::{TempFile, shared};
use wiperlab::Error;
use wiperlab::import::canonical::{read_trace_csv, write_trace_csv};
use wiperlab::import::{Format, ImportSpec, describe, read_trace, read_trace_with_summary};
use wiperlab::trace::{PointTrack, Trace};

fn roles(pairs: &[(&str, &str)]) -> BTreeMap<String, String> {
    pairs
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect()
}

/// truth.json, parsed.
fn truth() -> Option<serde_json::Value> {
    let path = shared("sample/truth.json")?;
    let text = std::fs::read_to_string(path).expect("read truth.json");
    Some(serde_json::from_str(&text).expect("parse truth.json"))
}

fn num(v: &serde_json::Value, ptr: &str) -> f64 {
    v.pointer(ptr)
        .and_then(serde_json::Value::as_f64)
        .unwrap_or_else(|| panic!("truth.json has no number at {ptr}"))
}

/// Import spec of the sample's DLTdv file, all values from truth.json `camera`
/// (fps 10000, scale 1.5e-5 m/px, origin (200, 300) px, y down, pt1 = head, pt2 = lip tip).
fn sample_dltdv_spec(truth: &serde_json::Value) -> ImportSpec {
    ImportSpec {
        format: Some(Format::Dltdv),
        fps_hz: Some(num(truth, "/camera/fps")),
        m_per_px: Some(num(truth, "/camera/scale_m_per_px")),
        origin_px: [
            num(truth, "/camera/origin_px/0"),
            num(truth, "/camera/origin_px/1"),
        ],
        y_down: Some(true),
        points: roles(&[("head", "pt1"), ("tip", "pt2")]),
        ..ImportSpec::default()
    }
}

/// Import spec of the sample's Tracker file: track names from its track-name row.
fn sample_tracker_spec() -> ImportSpec {
    ImportSpec {
        points: roles(&[("head", "head"), ("tip", "lip_tip")]),
        ..ImportSpec::default()
    }
}

fn point<'a>(t: &'a Trace, name: &str) -> &'a PointTrack {
    t.point(name)
        .unwrap_or_else(|| panic!("trace has no point {name:?}"))
}

/// Frames (0-based) where the point has a NaN sample.
fn nan_frames(p: &PointTrack) -> Vec<usize> {
    (0..p.x_m.len())
        .filter(|&k| p.x_m[k].is_nan() || p.y_m[k].is_nan())
        .collect()
}

#[test]
fn detects_every_shared_file_by_content() {
    let cases = [
        (
            "realdata/dltdv/LapsanskyArmstrong2022_data_xypts.csv",
            Format::Dltdv,
        ),
        ("realdata/tracker/8047.txt", Format::Tracker),
        ("realdata/tracker/8049.txt", Format::Tracker),
        ("realdata/tracker/8054.txt", Format::Tracker),
        ("sample/wiper_reversal_sample_xypts.csv", Format::Dltdv),
        ("sample/wiper_reversal_sample_tracker.txt", Format::Tracker),
    ];
    for (rel, format) in cases {
        let Some(path) = shared(rel) else { return };
        assert_eq!(Format::detect(&path).unwrap(), format, "{rel}");
    }
    // A servo log (Mitsubishi MR Configurator, SOURCES.md friction/) is no tracking export: a clear
    // Input error naming the file and pointing to the generic reader.
    let Some(path) = shared("realdata/friction/a3MR.csv") else {
        return;
    };
    let err = Format::detect(&path).unwrap_err();
    assert!(matches!(err, Error::Input { .. }), "{err}");
    assert!(err.to_string().contains("a3MR.csv"), "{err}");
    assert!(err.to_string().contains("generic"), "{err}");
}

#[test]
fn dltdv_real_lapsansky_armstrong() {
    let Some(path) = shared("realdata/dltdv/LapsanskyArmstrong2022_data_xypts.csv") else {
        return;
    };
    // fps 48 from the authors' script (SOURCES.md); pixels kept as "metres" with scale 1.
    let spec = ImportSpec {
        fps_hz: Some(48.0),
        m_per_px: Some(1.0),
        ..ImportSpec::default()
    };
    let (trace, summary) = read_trace_with_summary(&path, &spec).unwrap();
    assert_eq!(summary.format, Some(Format::Dltdv));
    // 1481 rows (SOURCES.md); header pt1_cam1_X ... pt8_cam1_Y = 8 points (SOURCES.md).
    assert_eq!(trace.len(), 1481);
    let names: Vec<&str> = trace.points.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        ["pt1", "pt2", "pt3", "pt4", "pt5", "pt6", "pt7", "pt8"]
    );
    // NaN cells counted independently: `grep -o NaN <file> | wc -l` → 23232 (the header has none;
    // a Python csv.reader count of cells == "NaN" gives the same). 1481 × 16 − 23232 = 464 numbers.
    assert_eq!(trace.nan_count(), 23232);
    // "only 83 rows contain any point" (SOURCES.md; also `grep -vc '^NaN\(,NaN\)*$'` minus header).
    let rows_with_point = (0..trace.len())
        .filter(|&k| {
            trace
                .points
                .iter()
                .any(|p| !p.x_m[k].is_nan() || !p.y_m[k].is_nan())
        })
        .count();
    assert_eq!(rows_with_point, 83);
    // Per point, x and y are NaN together, and e.g. pt1 is NaN in 1461 rows
    // (Python: sum(row[0] == "NaN" for row in rows)).
    assert_eq!(summary.points[0], ("pt1".to_string(), 1461));
    // First row with a point is file line 265 = frame 264:
    // `NaN,NaN,NaN,NaN,1678.966076,315.05209,...` → pt3 at (1678.966076, −315.05209) (y down).
    let first = (0..trace.len())
        .find(|&k| trace.points.iter().any(|p| !p.x_m[k].is_nan()))
        .unwrap();
    assert_eq!(first, 263);
    assert_eq!(trace.t_s[263], 263.0 / 48.0);
    let pt3 = point(&trace, "pt3");
    assert_eq!((pt3.x_m[263], pt3.y_m[263]), (1678.966076, -315.05209));
    // Last frame at (1481 − 1)/48 s.
    assert_eq!(trace.t_s[1480], 1480.0 / 48.0);
}

/// (file, expected point name, rows, first data row t, x, y) — rows and header from SOURCES.md,
/// first rows copied from the files (`sed -n 2p 8047.txt`, `sed -n 3p 8049.txt`, `sed -n 3p 8054.txt`).
const TRACKER_REAL: [(&str, &str, usize, [f64; 3]); 3] = [
    (
        "realdata/tracker/8047.txt",
        "point",
        4206,
        [0.0, 0.4143889733848767, -1.4155257921331112],
    ),
    (
        "realdata/tracker/8049.txt",
        "mass_B",
        3948,
        [0.0, 0.32620016167727206, -1.0882805245630045],
    ),
    (
        "realdata/tracker/8054.txt",
        "mass_A",
        4100,
        [0.0, 0.17697842313450085, -0.5763125719536614],
    ),
];

#[test]
fn tracker_real_phy180_pendulum_files() {
    for (rel, name, rows, [t0, x0, y0]) in TRACKER_REAL {
        let Some(path) = shared(rel) else { return };
        // fps_hz = 30 is only a check: the nominal 1/30 s step (SOURCES.md: real steps 0.0317–0.035 s).
        let spec = ImportSpec {
            fps_hz: Some(30.0),
            ..ImportSpec::default()
        };
        let (trace, summary) = read_trace_with_summary(&path, &spec).unwrap();
        assert_eq!(summary.format, Some(Format::Tracker), "{rel}");
        assert_eq!(trace.len(), rows, "{rel}");
        assert_eq!(trace.points.len(), 1, "{rel}: func is not a point");
        let p = &trace.points[0];
        assert_eq!(p.name, name, "{rel}");
        // "no missing values" (SOURCES.md).
        assert_eq!(trace.nan_count(), 0, "{rel}");
        // Java full-precision text parses to the same f64 the file printed.
        assert_eq!((trace.t_s[0], p.x_m[0], p.y_m[0]), (t0, x0, y0), "{rel}");
        assert!(trace.check().is_ok(), "{rel}");
        // Real frame times kept: steps 0.0317–0.0350 s (SOURCES.md), median 1/30 s.
        assert!(
            summary.dt_min_s > 0.0316 && summary.dt_max_s < 0.0351,
            "{rel}: {summary}"
        );
        assert!(
            (summary.dt_median_s - 1.0 / 30.0).abs() < 1e-9,
            "{rel}: {summary}"
        );
    }
    // Last row of 8047.txt (`tail -1`): 140.22500000000002, 0.1686570972713174, -1.4570585471600122.
    let Some(path) = shared("realdata/tracker/8047.txt") else {
        return;
    };
    let trace = read_trace(&path, &ImportSpec::default()).unwrap();
    let p = &trace.points[0];
    assert_eq!(
        (trace.t_s[4205], p.x_m[4205], p.y_m[4205]),
        (140.22500000000002, 0.1686570972713174, -1.4570585471600122)
    );
}

#[test]
fn sample_dltdv_and_tracker_give_the_same_trace() {
    let Some(truth) = truth() else { return };
    let (Some(xy), Some(trk)) = (
        shared("sample/wiper_reversal_sample_xypts.csv"),
        shared("sample/wiper_reversal_sample_tracker.txt"),
    ) else {
        return;
    };
    let a = read_trace(&xy, &sample_dltdv_spec(&truth)).unwrap();
    let b = read_trace(&trk, &sample_tracker_spec()).unwrap();
    // 18869 frames (sample/README.md, truth.json camera.n_frames).
    let n_frames = num(&truth, "/camera/n_frames") as usize;
    assert_eq!(n_frames, 18869);
    assert_eq!((a.len(), b.len()), (n_frames, n_frames));
    for t in [&a, &b] {
        let names: Vec<&str> = t.points.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["head", "tip"]);
    }

    // Times: DLTdv k/fps (t0 = 0) vs Tracker's column, printed with 7 significant digits
    // (`1.886800E0`), so |Δt| ≤ 0.5e-6·|t| (half a unit in the 7th digit). Measured: 0 (exact).
    let mut max_dt = 0.0f64;
    for (ta, tb) in a.t_s.iter().zip(&b.t_s) {
        assert!((ta - tb).abs() <= 5e-7 * tb.abs(), "{ta} vs {tb}");
        max_dt = max_dt.max((ta - tb).abs());
    }

    // Positions. DLTdv: %.6f px → rounding ≤ 0.5e-6 px × 1.5e-5 m/px = 7.5e-12 m. Tracker: 7
    // significant digits (`3.061379E-6`) → rounding ≤ 0.5e-6·|x|. Both round the same noisy
    // pixel position, so |Δ| ≤ 7.5e-12 m + 5e-7·|x_tracker| (+ a hair for f64 arithmetic).
    // Measured (printed below): max |Δ| ≈ 5e-8 m, max |Δ|/bound ≈ 0.99.
    let scale = num(&truth, "/camera/scale_m_per_px");
    let px_round = 0.5e-6 * scale;
    let mut max_abs = 0.0f64;
    let mut max_ratio = 0.0f64;
    for role in ["head", "tip"] {
        let (pa, pb) = (point(&a, role), point(&b, role));
        // Same NaN positions in both files.
        assert_eq!(nan_frames(pa), nan_frames(pb), "{role}");
        for (va, vb) in pa.x_m.iter().zip(&pb.x_m).chain(pa.y_m.iter().zip(&pb.y_m)) {
            assert_eq!(va.is_nan(), vb.is_nan());
            if va.is_nan() {
                continue;
            }
            let bound = px_round + 5.000_001e-7 * vb.abs() + 1e-18;
            let d = (va - vb).abs();
            assert!(d <= bound, "{role}: {va} vs {vb}, |Δ| {d:e} > {bound:e}");
            max_abs = max_abs.max(d);
            max_ratio = max_ratio.max(d / bound);
        }
    }
    println!(
        "DLTdv vs Tracker sample: max |Δt| = {max_dt:e} s, max |Δpos| = {max_abs:e} m, \
         max |Δ|/bound = {max_ratio:.4}"
    );
}

/// Columns of `clean_10kfps.csv.gz`: frame, t_sim, t_video, v, u, v3, theta, phi, state.
struct Clean {
    t_video: Vec<f64>,
    v: Vec<f64>,
    u: Vec<f64>,
    v3: Vec<f64>,
}

fn read_clean(path: &Path) -> Clean {
    let file = std::fs::File::open(path).expect("open clean gz");
    let reader = std::io::BufReader::new(flate2::read::GzDecoder::new(file));
    let mut lines = reader.lines();
    let header = lines.next().expect("header").expect("read header");
    assert_eq!(header, "frame,t_sim,t_video,v,u,v3,theta,phi,state");
    let mut c = Clean {
        t_video: Vec::new(),
        v: Vec::new(),
        u: Vec::new(),
        v3: Vec::new(),
    };
    for (k, line) in lines.enumerate() {
        let line = line.expect("read line");
        let f: Vec<f64> = line
            .split(',')
            .map(|s| s.parse().expect("number in clean file"))
            .collect();
        assert_eq!(
            f[0] as usize,
            k + 1,
            "frame column is 1-based and consecutive"
        );
        c.t_video.push(f[2]);
        c.v.push(f[3]);
        c.u.push(f[4]);
        c.v3.push(f[5]);
    }
    c
}

#[test]
fn sample_matches_clean_ground_truth_within_noise() {
    let Some(truth) = truth() else { return };
    let (Some(xy), Some(trk), Some(gz)) = (
        shared("sample/wiper_reversal_sample_xypts.csv"),
        shared("sample/wiper_reversal_sample_tracker.txt"),
        shared("sample/clean_10kfps.csv.gz"),
    ) else {
        return;
    };
    let clean = read_clean(&gz);
    assert_eq!(clean.v.len(), 18869);
    // Camera model (truth.json camera.pixel_model / data/reversal/README.md): x_m = X − a, y_m = Z with
    // head X = v, Z = −u; tip X = v3, Z = −(l1 + l2) = −0.006 m.
    let a_m = num(&truth, "/camera/a_m");
    let lip = num(&truth, "/params/l1") + num(&truth, "/params/l2");
    assert!((lip - 0.006).abs() < 1e-15);
    // Noise σ = 0.1 px × 1.5e-5 m/px = 1.5e-6 m per coordinate (truth.json camera.noise_sigma_px).
    let sigma = num(&truth, "/camera/noise_sigma_px") * num(&truth, "/camera/scale_m_per_px");
    assert!((sigma - 1.5e-6).abs() < 1e-18);

    let traces = [
        (
            "dltdv",
            read_trace(&xy, &sample_dltdv_spec(&truth)).unwrap(),
        ),
        ("tracker", read_trace(&trk, &sample_tracker_spec()).unwrap()),
    ];
    for (label, trace) in &traces {
        // Times: t_video = (frame − 1)/fps, printed with 4 decimals in the clean file.
        for (t, tv) in trace.t_s.iter().zip(&clean.t_video) {
            assert!((t - tv).abs() <= 0.5e-4 + 1e-12, "{label}: t {t} vs {tv}");
        }
        let head = point(trace, "head");
        let tip = point(trace, "tip");
        let n = clean.v.len();
        let expected: [(&str, &[f64], Vec<f64>); 4] = [
            (
                "head x",
                &head.x_m,
                clean.v.iter().map(|v| v - a_m).collect(),
            ),
            ("head y", &head.y_m, clean.u.iter().map(|u| -u).collect()),
            (
                "tip x",
                &tip.x_m,
                clean.v3.iter().map(|v3| v3 - a_m).collect(),
            ),
            ("tip y", &tip.y_m, vec![-lip; n]),
        ];
        for (what, got, want) in expected {
            let errs: Vec<f64> = got
                .iter()
                .zip(&want)
                .filter(|(g, _)| !g.is_nan())
                .map(|(g, w)| g - w)
                .collect();
            // 9 dropped entries remove 6 samples per point (truth.json camera.dropped).
            assert_eq!(errs.len(), n - 6, "{label} {what}");
            let max = errs.iter().fold(0.0f64, |m, e| m.max(e.abs()));
            let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
            let mean = errs.iter().sum::<f64>() / errs.len() as f64;
            println!(
                "{label} {what}: max |err| = {:.3} σ, rms = {:.4} σ, mean = {:+.4} σ",
                max / sigma,
                rms / sigma,
                mean / sigma
            );
            // P(|z| > 6) ≈ 2e-9 per sample: over 18863 samples a 6σ excursion is not expected.
            assert!(max < 6.0 * sigma, "{label} {what}: max {max:e}");
            // RMS estimate of σ has relative s.d. ≈ 1/√(2N) ≈ 0.5 %: 10 % is a wide margin.
            assert!(
                (rms / sigma - 1.0).abs() < 0.1,
                "{label} {what}: rms {rms:e}"
            );
            // The mean is noise only (s.d. σ/√N ≈ 0.007 σ); a bias would mean a wrong origin.
            assert!(mean.abs() < 0.05 * sigma, "{label} {what}: mean {mean:e}");
        }
    }
}

#[test]
fn sample_nan_samples_are_exactly_the_dropped_points_of_truth_json() {
    let Some(truth) = truth() else { return };
    let (Some(xy), Some(trk)) = (
        shared("sample/wiper_reversal_sample_xypts.csv"),
        shared("sample/wiper_reversal_sample_tracker.txt"),
    ) else {
        return;
    };
    // truth.json camera.dropped: 9 entries {frame_0based, points: "both" | "head" | "tip"}.
    let dropped = truth
        .pointer("/camera/dropped")
        .and_then(|d| d.as_array())
        .expect("camera.dropped");
    assert_eq!(dropped.len(), 9);
    let mut want_head = Vec::new();
    let mut want_tip = Vec::new();
    for d in dropped {
        let frame = d["frame_0based"].as_u64().expect("frame_0based") as usize;
        assert_eq!(d["frame_1based"].as_u64(), Some(frame as u64 + 1));
        match d["points"].as_str() {
            Some("both") => {
                want_head.push(frame);
                want_tip.push(frame);
            }
            Some("head") => want_head.push(frame),
            Some("tip") => want_tip.push(frame),
            other => panic!("unexpected dropped.points {other:?}"),
        }
    }
    want_head.sort_unstable();
    want_tip.sort_unstable();
    // The same list hard-coded (truth.json, frame_0based): both 1119, 7093, 13913; head only 2360,
    // 7264, 15116; tip only 3153, 8819, 16248.
    assert_eq!(want_head, [1119, 2360, 7093, 7264, 13913, 15116]);
    assert_eq!(want_tip, [1119, 3153, 7093, 8819, 13913, 16248]);
    for trace in [
        read_trace(&xy, &sample_dltdv_spec(&truth)).unwrap(),
        read_trace(&trk, &sample_tracker_spec()).unwrap(),
    ] {
        assert_eq!(nan_frames(point(&trace, "head")), want_head);
        assert_eq!(nan_frames(point(&trace, "tip")), want_tip);
        // x and y are dropped together: 2 coordinates × 12 samples.
        assert_eq!(trace.nan_count(), 24);
        let summary = describe(&trace);
        assert_eq!(
            summary.points,
            vec![("head".to_string(), 6), ("tip".to_string(), 6)]
        );
        let text = summary.to_string();
        assert_eq!(text.lines().count(), 3, "{text}");
        assert!(text.contains("head: 18863 tracked, 6 NaN"), "{text}");
    }
}

#[test]
fn canonical_round_trip_of_the_sample_is_bit_identical() {
    let Some(truth) = truth() else { return };
    let (Some(xy), Some(trk)) = (
        shared("sample/wiper_reversal_sample_xypts.csv"),
        shared("sample/wiper_reversal_sample_tracker.txt"),
    ) else {
        return;
    };
    for (name, trace) in [
        (
            "rt_dltdv.csv",
            read_trace(&xy, &sample_dltdv_spec(&truth)).unwrap(),
        ),
        (
            "rt_tracker.csv",
            read_trace(&trk, &sample_tracker_spec()).unwrap(),
        ),
    ] {
        let tmp = TempFile::path(name);
        write_trace_csv(&tmp.0, &trace).unwrap();
        let header = std::fs::read_to_string(&tmp.0).unwrap();
        assert!(header.starts_with("t_s,head_x_m,head_y_m,tip_x_m,tip_y_m\n"));
        let back = read_trace_csv(&tmp.0).unwrap();
        assert_eq!(back.len(), trace.len());
        let bits = |v: &[f64]| -> Vec<Option<u64>> {
            // NaN positions must match; NaN payloads need not.
            v.iter()
                .map(|x| (!x.is_nan()).then(|| x.to_bits()))
                .collect()
        };
        assert_eq!(bits(&back.t_s), bits(&trace.t_s));
        assert_eq!(back.points.len(), trace.points.len());
        for (p, q) in trace.points.iter().zip(&back.points) {
            assert_eq!(p.name, q.name);
            assert_eq!(bits(&p.x_m), bits(&q.x_m), "{name} {}", p.name);
            assert_eq!(bits(&p.y_m), bits(&q.y_m), "{name} {}", p.name);
        }
    }
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let path = common::TempFile::path("no_such_file_xypts.csv").0;
    for spec in [
        ImportSpec::default(),
        ImportSpec {
            format: Some(Format::Dltdv),
            fps_hz: Some(1.0),
            m_per_px: Some(1.0),
            ..ImportSpec::default()
        },
        ImportSpec {
            format: Some(Format::Tracker),
            ..ImportSpec::default()
        },
    ] {
        let err = read_trace(&path, &spec).unwrap_err();
        assert!(matches!(err, Error::Io { .. }), "{err:?}");
        assert!(err.is_input_error());
        assert!(
            err.to_string().contains(&path.display().to_string()),
            "{err}"
        );
    }
    let err = read_trace_csv(&path).unwrap_err();
    assert!(matches!(err, Error::Io { .. }), "{err:?}");
}

#[test]
fn non_number_cell_reports_line_column_and_field() {
    let spec = ImportSpec {
        fps_hz: Some(100.0),
        m_per_px: Some(1.0),
        ..ImportSpec::default()
    };
    let f = TempFile::with(
        "badcell_xypts.csv",
        "pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y\n1,2,3,4\nNaN,NaN,NaN,NaN\n1,2,abc,4\n",
    );
    let err = read_trace(&f.0, &spec).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, Error::Parse { .. }), "{msg}");
    assert!(msg.contains("badcell_xypts.csv:4:3:"), "{msg}");
    assert!(
        msg.contains("field pt2_cam1_X: expected a number or NaN, found \"abc\""),
        "{msg}"
    );

    let f = TempFile::with(
        "badcell_tracker.txt",
        "#multi:\n\thead\t\tlip_tip\t\t\nt\tx\ty\tx\ty\t\n0\t1\t2\t3\t4\n1E-4\t1\t2\t3\t4..\n",
    );
    let msg = read_trace(&f.0, &ImportSpec::default())
        .unwrap_err()
        .to_string();
    assert!(msg.contains("badcell_tracker.txt:5:5:"), "{msg}");
    assert!(msg.contains("field y (track lip_tip)"), "{msg}");
}

#[test]
fn dltdv_without_fps_names_fps_hz_and_the_file() {
    let f = TempFile::with("nofps_xypts.csv", "pt1_cam1_X,pt1_cam1_Y\n1,2\n");
    let spec = ImportSpec {
        m_per_px: Some(1.0),
        ..ImportSpec::default()
    };
    let err = read_trace(&f.0, &spec).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, Error::Input { .. }), "{msg}");
    assert!(
        msg.contains("fps_hz") && msg.contains("nofps_xypts.csv"),
        "{msg}"
    );
}

#[test]
fn unknown_role_lists_available_points() {
    let f = TempFile::with(
        "roles_xypts.csv",
        "pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y\n1,2,3,4\n",
    );
    let spec = ImportSpec {
        fps_hz: Some(100.0),
        m_per_px: Some(1.0),
        points: roles(&[("head", "pt1"), ("tip", "pt3")]),
        ..ImportSpec::default()
    };
    let msg = read_trace(&f.0, &spec).unwrap_err().to_string();
    assert!(msg.contains("\"pt3\""), "{msg}");
    assert!(msg.contains("points in the file: pt1, pt2"), "{msg}");

    // Tracker: a misspelt track name; the sample's tracks are listed.
    let Some(trk) = shared("sample/wiper_reversal_sample_tracker.txt") else {
        return;
    };
    let spec = ImportSpec {
        points: roles(&[("head", "head"), ("tip", "tip")]),
        ..ImportSpec::default()
    };
    let msg = read_trace(&trk, &spec).unwrap_err().to_string();
    assert!(msg.contains("points in the file: head, lip_tip"), "{msg}");
}

#[test]
fn spec_from_toml_sidecar() {
    let Some(xy) = shared("sample/wiper_reversal_sample_xypts.csv") else {
        return;
    };
    // The sample's camera (data/reversal/README.md): 10,000 fps, 15 µm/px, origin (200, 300) px, pt1/pt2.
    let spec: ImportSpec = toml::from_str(
        r#"
        format = "dltdv"
        fps_hz = 10000.0
        m_per_px = 1.5e-5
        origin_px = [200.0, 300.0]
        [points]
        head = "pt1"
        tip = "pt2"
        "#,
    )
    .unwrap();
    let trace = read_trace(&xy, &spec).unwrap();
    // First data row `200.204092,312.696557,106.569660,699.943223` →
    // head ((200.204092 − 200)·1.5e-5, −(312.696557 − 300)·1.5e-5).
    let head = point(&trace, "head");
    assert_eq!(head.x_m[0], (200.204092 - 200.0) * 1.5e-5);
    assert_eq!(head.y_m[0], -(312.696557 - 300.0) * 1.5e-5);
    let tip = point(&trace, "tip");
    assert_eq!(tip.y_m[0], -(699.943223 - 300.0) * 1.5e-5);
    // Last frame at (18869 − 1)/10000 s.
    assert_eq!(trace.t_s[18868], 18868.0 / 10000.0);
}
