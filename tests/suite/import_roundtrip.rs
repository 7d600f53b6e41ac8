//! Round trips and calibration of the import layer, on synthetic traces whose exact values are
//! known: every writable layout reads back identically, and the calibration steps (two-point
//! scale, y flip, rotation to the sweep, frame rate) do what their formulas say.

use std::collections::BTreeMap;

use crate::common::TempFile;
use wiperlab::import::{
    Format, ImportSpec, canonical, dltdv, dltdv_sparse, principal_axis_rad, read_trace,
    read_trace_with_summary, tracker,
};
use wiperlab::trace::{PointTrack, Trace};

/// Two points over `n` frames at `fps`, with a gap in the tip; coordinates are multiples of 2⁻¹⁶ m
/// so that pixel ↔ metre conversions with m_per_px = 2⁻¹⁰ are exact in binary floating point.
fn trace(n: usize, fps: f64) -> Trace {
    let q = |v: f64| (v * 65536.0).round() / 65536.0;
    let t_s: Vec<f64> = (0..n).map(|k| k as f64 / fps).collect();
    let head = PointTrack {
        name: "head".into(),
        x_m: (0..n).map(|k| q(0.01 * (k as f64 * 0.3).sin())).collect(),
        y_m: (0..n).map(|k| q(-0.002 * k as f64)).collect(),
    };
    let mut tip = PointTrack {
        name: "tip".into(),
        x_m: (0..n).map(|k| q(0.02 + 0.001 * k as f64)).collect(),
        y_m: (0..n).map(|k| q(0.005 * (k as f64 * 0.7).cos())).collect(),
    };
    for k in 3..6 {
        tip.x_m[k] = f64::NAN;
        tip.y_m[k] = f64::NAN;
    }
    Trace {
        t_s,
        points: vec![head, tip],
    }
}

/// Bitwise equality, NaN equal to NaN.
fn same(a: &Trace, b: &Trace) {
    assert_eq!(a.t_s.len(), b.t_s.len());
    let bits = |v: &[f64]| {
        v.iter()
            .map(|x| if x.is_nan() { u64::MAX } else { x.to_bits() })
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&a.t_s), bits(&b.t_s), "times");
    assert_eq!(a.points.len(), b.points.len());
    for (p, q) in a.points.iter().zip(&b.points) {
        assert_eq!(p.name, q.name);
        assert_eq!(bits(&p.x_m), bits(&q.x_m), "{} x", p.name);
        assert_eq!(bits(&p.y_m), bits(&q.y_m), "{} y", p.name);
    }
}

fn roles() -> BTreeMap<String, String> {
    [("head", "pt1"), ("tip", "pt2")]
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect()
}

#[test]
fn canonical_csv_round_trip() {
    let t = trace(50, 1000.0);
    let f = TempFile::path("rt.trace.csv");
    canonical::write_trace_csv(&f.0, &t).unwrap();
    same(&canonical::read_trace_csv(&f.0).unwrap(), &t);
}

#[test]
fn tracker_text_round_trip() {
    // Tracker keeps real (irregular) frame times: use jittered times.
    let mut t = trace(40, 30.0);
    for (k, v) in t.t_s.iter_mut().enumerate() {
        *v += 1e-3 * ((k * 7) % 5) as f64;
    }
    let f = TempFile::path("rt_tracker.txt");
    tracker::write(&f.0, &t).unwrap();
    let (back, sum) = read_trace_with_summary(&f.0, &ImportSpec::default()).unwrap();
    assert_eq!(sum.format, Some(Format::Tracker), "detected by content");
    same(&back, &t);
}

#[test]
fn dltdv_xypts_round_trip() {
    let fps = 1000.0;
    let t = trace(60, fps);
    let spec = ImportSpec {
        fps_hz: Some(fps),
        m_per_px: Some(1.0 / 1024.0),
        origin_px: [200.0, 300.0],
        points: roles(),
        ..ImportSpec::default()
    };
    let f = TempFile::path("rt_xypts.csv");
    dltdv::write(&f.0, &t, &spec).unwrap();
    let back = read_trace(&f.0, &spec).unwrap();
    same(&back, &t);
}

#[test]
fn dltdv_sparse_round_trip() {
    let fps = 500.0;
    let t = trace(30, fps);
    let s = 1.0 / 1024.0;
    let px: Vec<(Vec<f64>, Vec<f64>)> = t
        .points
        .iter()
        .map(|p| {
            (
                p.x_m.iter().map(|v| v / s + 200.0).collect(),
                p.y_m.iter().map(|v| -v / s + 300.0).collect(),
            )
        })
        .collect();
    let f = TempFile::path("rt_xypts.tsv");
    dltdv_sparse::write(&f.0, &px).unwrap();
    let spec = ImportSpec {
        fps_hz: Some(fps),
        m_per_px: Some(s),
        origin_px: [200.0, 300.0],
        points: roles(),
        ..ImportSpec::default()
    };
    let (back, sum) = read_trace_with_summary(&f.0, &spec).unwrap();
    assert_eq!(sum.format, Some(Format::DltdvSparse));
    same(&back, &t);
}

/// Two image points 400 px apart horizontally and 300 px vertically (500 px) that are 0.25 m apart
/// give m_per_px = 0.25/500 = 5e-4 — the same trace as m_per_px given directly.
#[test]
fn two_point_scale_equals_direct_scale() {
    let f = TempFile::path("scale_xypts.csv");
    std::fs::write(&f.0, "pt1_cam1_X,pt1_cam1_Y\n100,50\n110,40\n").unwrap();
    let direct = ImportSpec {
        fps_hz: Some(100.0),
        m_per_px: Some(5e-4),
        ..ImportSpec::default()
    };
    let two = ImportSpec {
        fps_hz: Some(100.0),
        scale_points_px: Some([[10.0, 20.0], [410.0, 320.0]]),
        scale_distance_m: Some(0.25),
        ..ImportSpec::default()
    };
    assert_eq!(two.resolved_m_per_px().unwrap(), Some(5e-4));
    let (a, b) = (
        read_trace(&f.0, &direct).unwrap(),
        read_trace(&f.0, &two).unwrap(),
    );
    same(&a, &b);
    // y down → up: pixel row 40 is above row 50, so y grows by 10 px = 5 mm.
    let p = &a.points[0];
    assert!((p.y_m[1] - p.y_m[0] - 10.0 * 5e-4).abs() < 1e-15);
    let both = ImportSpec {
        m_per_px: Some(1.0),
        ..two.clone()
    };
    let err = read_trace(&f.0, &both).unwrap_err().to_string();
    assert!(err.contains("not both"), "{err}");
    let half = ImportSpec {
        scale_distance_m: None,
        ..two
    };
    assert!(
        read_trace(&f.0, &half)
            .unwrap_err()
            .to_string()
            .contains("go together")
    );
}

/// A head moving along a line at 30° (x = s·cos 30°, y = s·sin 30°): the principal axis is 30°,
/// and after `sweep_from_head` the head moves along x only (y constant to rounding); a given
/// `sweep_angle_deg = 30` gives the same trace.
#[test]
fn rotation_to_the_sweep() {
    let a = 30f64.to_radians();
    let n = 40;
    let s: Vec<f64> = (0..n).map(|k| 0.01 * (k as f64 * 0.4).sin()).collect();
    let mut text = String::from("t\tx\ty\n");
    for (k, v) in s.iter().enumerate() {
        text.push_str(&format!(
            "{}\t{}\t{}\n",
            k as f64 / 100.0,
            v * a.cos(),
            v * a.sin()
        ));
    }
    let f = TempFile::path("rot_tracker.txt");
    std::fs::write(&f.0, text).unwrap();
    let est = ImportSpec {
        sweep_from_head: true,
        ..ImportSpec::default()
    };
    let (t, sum) = read_trace_with_summary(&f.0, &est).unwrap();
    let p = &t.points[0];
    let theta = principal_axis_rad(
        &s.iter().map(|v| v * a.cos()).collect::<Vec<_>>(),
        &s.iter().map(|v| v * a.sin()).collect::<Vec<_>>(),
    )
    .unwrap();
    assert!((theta - a).abs() < 1e-12, "{}", theta.to_degrees());
    assert!(
        sum.notes.iter().any(|n| n.contains("30.0000°")),
        "{:?}",
        sum.notes
    );
    for (k, sk) in s.iter().enumerate() {
        assert!((p.x_m[k] - sk).abs() < 1e-15, "x along the sweep");
        assert!(p.y_m[k].abs() < 1e-15, "no motion across it");
    }
    let given = ImportSpec {
        sweep_angle_deg: Some(30.0),
        ..ImportSpec::default()
    };
    let t2 = read_trace(&f.0, &given).unwrap();
    for (a, b) in t2.points[0].x_m.iter().zip(&p.x_m) {
        assert!((a - b).abs() < 1e-15);
    }
    let err = read_trace(
        &f.0,
        &ImportSpec {
            sweep_angle_deg: Some(30.0),
            sweep_from_head: true,
            ..ImportSpec::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("not both"), "{err}");
}

/// Frame-indexed formats without a frame rate fail with a message naming the setting.
#[test]
fn frame_rate_is_required_where_the_file_has_none() {
    let f = TempFile::path("nofps.csv");
    std::fs::write(
        &f.0,
        "scorer,s,s,s\nbodyparts,h,h,h\ncoords,x,y,likelihood\n0,1,2,0.9\n1,1,2,0.9\n",
    )
    .unwrap();
    let spec = ImportSpec {
        m_per_px: Some(1e-3),
        ..ImportSpec::default()
    };
    let err = read_trace(&f.0, &spec).unwrap_err().to_string();
    assert!(
        err.contains("nofps.csv") && err.contains("fps_hz") && err.contains("--fps"),
        "{err}"
    );
    let err = read_trace(
        &f.0,
        &ImportSpec {
            fps_hz: Some(100.0),
            ..ImportSpec::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("m_per_px"), "pixels need a scale: {err}");
}
