//! One test per real tracking-tool export in `../shared/realdata` (skipped with a printed reason
//! when `../shared` is absent): each is read through `wiperlab::import::read_trace_with_summary`
//! and its row, point and gap counts are checked against counts made independently of wiperlab
//! (SOURCES.md tables, or the awk one-off quoted at each test). Where SOURCES.md gives a dominant
//! frequency, the spectrum of the imported trace must find it within the stated accuracy.
//!
//! DLTdv `xypts.csv` and the Tracker pendulums are covered in `tests/suite/import.rs` and
//! `tests/suite/spectrum_realdata.rs`.

use crate::common::shared;
use wiperlab::import::{Format, ImportSpec, read_trace_with_summary};
use wiperlab::spectrum::{WelchConfig, find_peak, resample_uniform, welch_gappy};
use wiperlab::trace::Trace;

fn spec(format: Format) -> ImportSpec {
    ImportSpec {
        format: Some(format),
        ..ImportSpec::default()
    }
}

fn names(t: &Trace) -> Vec<&str> {
    t.points.iter().map(|p| p.name.as_str()).collect()
}

fn nan_samples(t: &Trace) -> usize {
    t.points.iter().map(|p| p.nan_samples()).sum()
}

/// Peak frequency (Hz) of `x` (uniformly sampled at `fs_hz`, NaN gaps ≤ 5 samples filled) in
/// `band`: Welch with Hann segments of `nperseg`, zero-padded to `nfft`, parabolic interpolation.
fn peak_hz(x: &[f64], fs_hz: f64, nperseg: usize, nfft: usize, band: (f64, f64)) -> f64 {
    let cfg = WelchConfig::new(nperseg).with_nfft(nfft).unwrap();
    let (psd, gaps) = welch_gappy(x, fs_hz, &cfg, 5).unwrap();
    let p = find_peak(&psd.freq_hz, &psd.density, band).expect("a peak in the band");
    println!(
        "  peak {:.4} Hz (nperseg {nperseg}, nfft {nfft}; {} filled, {} dropped, {} runs)",
        p.freq_hz, gaps.filled, gaps.dropped, gaps.runs
    );
    p.freq_hz
}

/// `pas_camera_01.txt`: SOURCES.md kinovea/ table — 5 markers, 500 data lines; each section has
/// 100 rows (`awk '/^#/{s++} s>=1 && NF>0 && !/^#/{n[s]++} END{for(i in n) print i, n[i]}'`),
/// all sections on the same 100 times, no missing value. Coordinates use decimal commas: the first
/// row of `# métatarses` is `0.000 77,20 -21,97`.
#[test]
fn kinovea_txt_pas_camera_01() {
    let Some(path) = shared("realdata/kinovea/pas_camera_01.txt") else {
        return;
    };
    let s = ImportSpec {
        units_to_m: Some(0.01),
        ..ImportSpec::default()
    };
    let (t, sum) = read_trace_with_summary(&path, &s).unwrap();
    assert_eq!(sum.format, Some(Format::KinoveaTxt), "detected by content");
    assert_eq!(
        names(&t),
        ["métatarses", "tarse", "jarret", "hanche", "pointe dos"]
    );
    assert_eq!(t.len(), 100);
    assert_eq!(nan_samples(&t), 0);
    let m = t.point("métatarses").unwrap();
    assert!((m.x_m[0] - 0.7720).abs() < 1e-12 && (m.y_m[0] + 0.2197).abs() < 1e-12);
    assert_eq!(t.t_s[1], 0.008);
}

/// `trop_camera_03.txt`: SOURCES.md — 6 markers, 394 data lines; per section 59, 67, 67, 67, 67,
/// 67 rows and 67 distinct times over all sections
/// (`awk '/^#/{s++; next} NF>0{n[s]++; t[$1]=1} END{...}'`), so métatarses has 67 − 59 = 8 NaN
/// samples and the others none.
#[test]
fn kinovea_txt_trop_camera_03() {
    let Some(path) = shared("realdata/kinovea/trop_camera_03.txt") else {
        return;
    };
    let s = ImportSpec {
        units_to_m: Some(0.01),
        ..ImportSpec::default()
    };
    let (t, sum) = read_trace_with_summary(&path, &s).unwrap();
    assert_eq!(t.len(), 67);
    assert_eq!(t.points.len(), 6);
    assert_eq!(t.point("métatarses").unwrap().nan_samples(), 8);
    assert_eq!(nan_samples(&t), 8);
    assert_eq!(sum.points.iter().map(|p| p.1).sum::<usize>(), 8);
    // Without a unit the import refuses rather than guessing cm or pixels.
    let err = read_trace_with_summary(&path, &ImportSpec::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("units_to_m"), "{err}");
}

/// `v1.csv`: SOURCES.md — header `Time (ms),HEAD,Knee,ankle,food`, 126 rows at 40 ms steps
/// (first row 40, last 5040: `head -2`, `tail -1`). Four scalar columns → four points whose x holds
/// the value and whose y is NaN.
#[test]
fn kinovea_kinematics_v1() {
    let Some(path) = shared("realdata/kinovea/v1.csv") else {
        return;
    };
    let s = ImportSpec {
        units_to_m: Some(1.0),
        ..ImportSpec::default()
    };
    let (t, sum) = read_trace_with_summary(&path, &s).unwrap();
    assert_eq!(sum.format, Some(Format::KinoveaKinematics));
    assert_eq!(t.len(), 126);
    assert_eq!(names(&t), ["HEAD", "Knee", "ankle", "food"]);
    assert!((t.t_s[0] - 0.040).abs() < 1e-12 && (t.t_s[125] - 5.040).abs() < 1e-12);
    assert!((sum.dt_median_s - 0.040).abs() < 1e-9);
    assert_eq!(t.points[0].x_m[0], 65.1052398681641);
    assert!(t.points.iter().all(|p| p.x_m.iter().all(|v| v.is_finite())));
    assert!(t.points.iter().all(|p| p.y_m.iter().all(|v| v.is_nan())));
}

const DLC_IL5: &str = "realdata/deeplabcut/IL5-519-Cam2_2020-06-25_000124Track9DLC_resnet50_Austin2020_accuracy_testApr7shuffle3_1150000.csv";
const DLC_AFAM: &str = "realdata/deeplabcut/AFAMcarollia_1Apr2021_0790C_Bane_Y20210401H145003.312743000_F1_croppedDLC_resnet50_Brown2021_accuracy_testJan28shuffle1_450000.csv";

/// Count check of a DeepLabCut file: `rows` frames, 16 body parts, and the number of point
/// samples with likelihood < 0.6, counted by
/// `awk -F, 'NR>3{for(i=4;i<=NF;i+=3) if($i<0.6) c++} END{print c}'` — each becomes a NaN sample.
fn dlc_counts(rel: &str, fps: f64, rows: usize, below: usize) -> Option<Trace> {
    let path = shared(rel)?;
    let s = ImportSpec {
        fps_hz: Some(fps),
        m_per_px: Some(1.0),
        ..ImportSpec::default()
    };
    let (t, sum) = read_trace_with_summary(&path, &s).unwrap();
    assert_eq!(sum.format, Some(Format::Deeplabcut));
    assert_eq!(t.len(), rows);
    assert_eq!(t.points.len(), 16);
    assert_eq!(&names(&t)[..3], ["t3L", "wstL", "t5L"]);
    assert_eq!(nan_samples(&t), below, "samples below the 0.6 cut-off");
    assert!((t.t_s[1] - 1.0 / fps).abs() < 1e-15);
    // Cut-off 0 keeps every point: the file has no NaN (SOURCES.md).
    let all = ImportSpec {
        min_likelihood: Some(0.0),
        ..s
    };
    let t0 = wiperlab::import::read_trace(&path, &all).unwrap();
    assert_eq!(nan_samples(&t0), 0);
    Some(t0)
}

/// IL5 (800 fps, SOURCES.md): 431 rows, 1588 samples below 0.6. Wingbeat ≈ 12.5–13 Hz
/// (SOURCES.md, independent FFT of wrist/digit y relative to the shoulder). Signal: the left
/// wrist's y minus the left shoulder's y (subtracting the body point removes the ≈ 2 Hz
/// translation peak), all 431 samples as one Hann segment zero-padded to 8192.
///
/// Independent reference: NumPy 2.x, same signal, `np.hanning(n+1)[:-1]` window, mean removed,
/// `np.fft.rfft(x*w, 8192)`, arg-max over 5–40 Hz = 13.0859 Hz (grid 0.0977 Hz, no
/// interpolation; other wing points give 12.50–13.09 Hz, which is SOURCES.md's ≈ range). The
/// interpolated peak must be within one grid bin (0.0977 Hz) of it.
#[test]
fn deeplabcut_il5_counts_and_wingbeat() {
    let Some(t) = dlc_counts(DLC_IL5, 800.0, 431, 1588) else {
        return;
    };
    let w = t.point("wstL").unwrap();
    let s = t.point("shdL").unwrap();
    let rel: Vec<f64> = w.y_m.iter().zip(&s.y_m).map(|(a, b)| a - b).collect();
    let f = peak_hz(&rel, 800.0, 431, 8192, (5.0, 40.0));
    let numpy_hz = 13.0859375;
    assert!(
        (f - numpy_hz).abs() <= 800.0 / 8192.0,
        "wingbeat {f} Hz vs NumPy {numpy_hz} Hz"
    );
}

/// AFAM (700 fps, SOURCES.md): 116 rows, 484 samples below 0.6. Wingbeat ≈ 8.3–8.7 Hz
/// (SOURCES.md: "only ~1.4 wingbeats, coarse"). Signal as for IL5 (left wrist y − left shoulder
/// y, one Hann segment of 116 samples zero-padded to 8192). Independent reference: the same NumPy
/// 2.x one-off over 1–60 Hz gives 8.2031 Hz (grid 700/8192 = 0.0854 Hz); the interpolated peak
/// must be within one grid bin of it. (With 1.4 cycles the estimate itself is coarse: the Hann
/// main lobe is ±12 Hz wide; SOURCES.md's 8.3–8.7 Hz is within 0.5 Hz.)
#[test]
fn deeplabcut_afam_counts() {
    let Some(t) = dlc_counts(DLC_AFAM, 700.0, 116, 484) else {
        return;
    };
    let w = t.point("wstL").unwrap();
    let s = t.point("shdL").unwrap();
    let rel: Vec<f64> = w.y_m.iter().zip(&s.y_m).map(|(a, b)| a - b).collect();
    let f = peak_hz(&rel, 700.0, 116, 8192, (1.0, 60.0));
    let numpy_hz = 8.203125;
    assert!(
        (f - numpy_hz).abs() <= 700.0 / 8192.0,
        "wingbeat {f} Hz vs NumPy {numpy_hz} Hz"
    );
}

/// SLEAP excerpt (SOURCES.md sleap/): header + frames 0–1 of 5 tracks, 4 nodes (Head, Thorax,
/// Abdomen, Tail), no score columns: 2 frames × 20 points, no gaps; first value of the file
/// `track_0,0,592.7771606445312,97.11058807373047`.
#[test]
fn sleap_excerpt() {
    let Some(path) = shared("realdata/sleap/sleap_csv_example.EXCERPT_first11lines.csv") else {
        return;
    };
    let s = ImportSpec {
        fps_hz: Some(30.0),
        m_per_px: Some(1.0),
        y_down: Some(false),
        ..ImportSpec::default()
    };
    let (t, sum) = read_trace_with_summary(&path, &s).unwrap();
    assert_eq!(sum.format, Some(Format::Sleap));
    assert_eq!(t.len(), 2);
    assert_eq!(t.points.len(), 20);
    assert_eq!(names(&t)[0], "track_0/Head");
    assert_eq!(names(&t)[19], "track_4/Tail");
    assert_eq!(nan_samples(&t), 0);
    assert_eq!(t.points[0].x_m[0], 592.7771606445312);
    assert_eq!(t.points[0].y_m[0], 97.11058807373047);
    // No frame rate in the file: a clear error without one.
    let err = read_trace_with_summary(&path, &spec(Format::Sleap))
        .unwrap_err()
        .to_string();
    assert!(err.contains("fps_hz"), "{err}");
}

/// TrackMate ≤ 6 (SOURCES.md trackmate/): 19819 rows, 118 tracks, frames 0–1073
/// (`awk -F, 'NR>1{s[$3]++; if($9>m)m=$9} END{...}'`: 19819 spots, 118 track ids, last frame 1073;
/// no track has two spots in one frame). One point per track over 1074 frames, so the NaN samples
/// are 118 × 1074 − 19819 = 106913.
#[test]
fn trackmate_spots_in_tracks() {
    let Some(path) = shared("realdata/trackmate/Spots in tracks statistics.csv") else {
        return;
    };
    let s = ImportSpec {
        fps_hz: Some(10.0),
        m_per_px: Some(1e-6),
        ..ImportSpec::default()
    };
    let (t, sum) = read_trace_with_summary(&path, &s).unwrap();
    assert_eq!(sum.format, Some(Format::Trackmate));
    assert_eq!(t.len(), 1074);
    assert_eq!(t.points.len(), 118);
    assert_eq!(nan_samples(&t), 118 * 1074 - 19819);
    // First spot: `ID68,68,0,2.983,71.960,47.792,0,0,0,...` → track0 at frame 0, y flipped.
    let p = t.point("track0").unwrap();
    assert!((p.x_m[0] - 71.960e-6).abs() < 1e-15 && (p.y_m[0] + 47.792e-6).abs() < 1e-15);
    // Uncalibrated time (POSITION_T = FRAME, no unit row): fps is required.
    let err = read_trace_with_summary(&path, &spec(Format::Trackmate))
        .unwrap_err()
        .to_string();
    assert!(err.contains("fps_hz"), "{err}");
}

/// `describe_file` describes every real export without a calibration (issue 15 point 6): the
/// TrackMate table without a time unit, which an import refuses without `fps_hz` (above), is
/// described in frames, with the same 1074 frames and 118 tracks as the calibrated import and the
/// note that a fit needs `--fps`; the DLTdv file likewise in frames and pixels.
#[test]
fn describe_needs_no_calibration() {
    use wiperlab::import::describe_file;
    let cases = [
        (
            "realdata/trackmate/Spots in tracks statistics.csv",
            1074,
            118,
        ),
        (
            "realdata/dltdv/LapsanskyArmstrong2022_data_xypts.csv",
            1481,
            0,
        ),
    ];
    for (rel, frames, points) in cases {
        let Some(path) = shared(rel) else { return };
        let (t, sum) =
            describe_file(&path, &ImportSpec::default()).unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert_eq!(t.len(), frames, "{rel}");
        if points > 0 {
            assert_eq!(t.points.len(), points, "{rel}");
        }
        assert!(sum.uncalibrated.frames, "{rel}: described in frames");
        let text = sum.to_string();
        assert!(text.contains("a fit needs fps_hz (--fps)"), "{rel}: {text}");
        assert!(
            text.contains("a fit needs m_per_px (--m-per-px)"),
            "{rel}: {text}"
        );
    }
}

/// Every file above is detected by content (no `format` given).
#[test]
fn detects_every_new_format() {
    let cases = [
        ("realdata/kinovea/pas_camera_01.txt", Format::KinoveaTxt),
        ("realdata/kinovea/v1.csv", Format::KinoveaKinematics),
        (DLC_IL5, Format::Deeplabcut),
        (
            "realdata/sleap/sleap_csv_example.EXCERPT_first11lines.csv",
            Format::Sleap,
        ),
        (
            "realdata/trackmate/Spots in tracks statistics.csv",
            Format::Trackmate,
        ),
    ];
    for (rel, want) in cases {
        let Some(path) = shared(rel) else { return };
        assert_eq!(Format::detect(&path).unwrap(), want, "{rel}");
    }
}

/// The pendulum 8047.txt (SOURCES.md: 4206 rows, x, y in m): the importer keeps Tracker's real
/// frame times, and resampling to the median rate is a separate, explicit step whose grid is
/// uniform.
#[test]
fn tracker_times_kept_and_resampling_explicit() {
    let Some(path) = shared("realdata/tracker/8047.txt") else {
        return;
    };
    let (t, sum) = read_trace_with_summary(&path, &ImportSpec::default()).unwrap();
    assert_eq!(t.len(), 4206);
    // SOURCES.md: real frame times vary 0.0317–0.0350 s around 1/30 s.
    assert!(sum.dt_min_s < 0.0325 && sum.dt_max_s > 0.0345, "{sum}");
    let fs = wiperlab::spectrum::median_rate_hz(&t.t_s);
    let (t0, x) = resample_uniform(&t.t_s, &t.points[0].x_m, fs).unwrap();
    assert_eq!(t0, t.t_s[0]);
    let expect_n = ((t.t_s[4205] - t.t_s[0]) * fs).floor() as usize + 1;
    assert!(x.len().abs_diff(expect_n) <= 1, "{} vs {expect_n}", x.len());
}

/// A generic-table spec from TOML.
fn toml_spec(text: &str) -> ImportSpec {
    toml::from_str(text).expect("valid import spec")
}

/// Damper JSON as a generic table: column 0 = t (s), 1 = displacement (in) (SOURCES.md friction/).
const DAMPER_SPEC: &str = "format = \"generic\"\nunits_to_m = 0.0254\n[generic]\ntime = \"t\"\n\
    columns = [\"t\", \"displacement\", \"force\", \"velocity\", \"act1\", \"act2\"]\n\
    [generic.points]\ndisplacement = [\"displacement\"]\nforce = [\"force\"]\n";

/// The friction damper's drive frequency from its displacement: SOURCES.md friction/ 1. — 1024 Hz,
/// `rows` rows, dominant frequency = excitation frequency `drive_hz` (independent FFT). Welch with
/// one Hann segment of `nperseg` (bin 1024/nperseg Hz), parabolic interpolation; must be within
/// 1 % of the drive.
fn damper(rel: &str, rows: usize, nperseg: usize, drive_hz: f64) {
    let Some(path) = shared(rel) else { return };
    let (t, sum) = read_trace_with_summary(&path, &toml_spec(DAMPER_SPEC)).unwrap();
    println!("{sum}");
    assert_eq!(t.len(), rows);
    assert_eq!(sum.scalar, [true, true]);
    assert_eq!(
        sum.points,
        [("displacement".into(), 0), ("force".into(), 0)]
    );
    assert!((sum.dt_median_s - 1.0 / 1024.0).abs() < 1e-12);
    let x = &t.point("displacement").unwrap().x_m;
    let f = peak_hz(x, 1024.0, nperseg, nperseg, (0.2, 5.0));
    let f_force = peak_hz(
        &t.point("force").unwrap().x_m,
        1024.0,
        nperseg,
        nperseg,
        (0.2, 5.0),
    );
    for f in [f, f_force] {
        assert!(
            ((f - drive_hz) / drive_hz).abs() <= 0.01,
            "{rel}: {f} Hz vs drive {drive_hz} Hz"
        );
    }
}

#[test]
fn friction_damper_1hz_drive() {
    damper("realdata/friction/1Hz35lbtension.json", 10241, 8192, 1.0);
}

#[test]
fn friction_damper_0_5hz_drive() {
    damper("realdata/friction/0.5Hz35lbtension.json", 18433, 16384, 0.5);
}

/// Tribometer log (SOURCES.md friction/ 2.): 7196 data rows at 10 Hz, header on line 2 (line 1
/// holds a bare CR), trailing commas, a 2-line `TotalTime` footer. `Timestamp` restarts in every
/// step, so the time base is the row index / 10 Hz.
#[test]
fn tribometer_generic_table() {
    let Some(path) = shared(
        "realdata/friction/013_FX2_316SS_0.25in_Rotary_3N_4tests_75-300mm-s_6-15mm-radius_3min-each.csv",
    ) else {
        return;
    };
    let spec = toml_spec(
        "format = \"generic\"\nfps_hz = 10.0\nunits_to_m = 1.0\n[generic]\nfooter_lines = 2\n\
         [generic.points]\ncof = [\"DAQ.COF ()\"]\n",
    );
    let (t, sum) = read_trace_with_summary(&path, &spec).unwrap();
    assert_eq!(t.len(), 7196);
    assert_eq!(sum.points, [("cof".into(), 0)]);
    assert_eq!(
        t.points[0].x_m[0], 0.155274,
        "first data row: 4,0.144,4,3.012628,0.4677829,0.155274"
    );
    // Without the footer setting the footer is a row error naming its line.
    let no_footer = toml_spec(
        "format = \"generic\"\nfps_hz = 10.0\nunits_to_m = 1.0\n[generic.points]\ncof = [\"DAQ.COF ()\"]\n",
    );
    let err = read_trace_with_summary(&path, &no_footer)
        .unwrap_err()
        .to_string();
    assert!(err.contains(":7200:0: expected 10 fields"), "{err}");
}

/// NI export a3NI.csv (SOURCES.md friction/ 3.): UTF-8 BOM, 4-line preamble (names on line 3,
/// units on line 4), 1078 rows at 2 kHz (`Interval,0.0005`). Mitsubishi a3MR.csv: header on line
/// 4 (`Time,Analog 1,...`), unit row `ms,...`, 1024 rows at 0.667 ms.
#[test]
fn ni_and_servo_logs_generic_tables() {
    let Some(ni) = shared("realdata/friction/a3NI.csv") else {
        return;
    };
    let spec = toml_spec(
        "format = \"generic\"\nunits_to_m = 1.0\n[generic]\ntime = \"Channel name\"\n\
         skip_after_header = 1\n[generic.points]\nforce = [\"Force\"]\n",
    );
    let (t, sum) = read_trace_with_summary(&ni, &spec).unwrap();
    assert_eq!(t.len(), 1078);
    assert!((sum.dt_median_s - 0.0005).abs() < 1e-12);
    let Some(mr) = shared("realdata/friction/a3MR.csv") else {
        return;
    };
    let spec = toml_spec(
        "format = \"generic\"\nunits_to_m = 1.0\ntime_to_s = 0.001\n[generic]\ntime = \"Time\"\n\
         skip_after_header = 1\n[generic.points]\nspeed = [\"Analog 1\"]\n",
    );
    let (t, sum) = read_trace_with_summary(&mr, &spec).unwrap();
    assert_eq!(t.len(), 1024);
    assert!(
        (sum.dt_median_s - 0.000666666).abs() < 1e-9,
        "Sampling time interval(ms),0.667"
    );
}
