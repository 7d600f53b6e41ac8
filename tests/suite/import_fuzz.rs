//! Fuzzing every import parser with proptest: arbitrary bytes and mutated real files must never
//! panic; a parse error must name the file and a line ≥ 1 and say what was expected; an accepted
//! file must give a consistent trace (`Trace::check`).
//!
//! Inputs tried per `cargo test` run (`CASES` = 1000 proptest cases per property):
//! * arbitrary byte strings (≤ 2 KiB), each given to all 11 readers (10 formats + canonical CSV):
//!   11 000 parses;
//! * mutated seeds (1–7 edits — byte replace/insert/delete from a set of delimiter, quote, digit,
//!   `NaN`, `ø`, Latin-1 and NUL bytes, or a duplicated span — and/or a truncation): each case
//!   mutates the 11 built-in samples and the first 8 KiB of 7 real files in ../shared/realdata
//!   (when present): 18 000 parses;
//! * 1000 byte strings for format detection.
//!
//! 30 000 inputs in all, about a second in release mode. proptest's RNG seed is random, so each
//! run tries new inputs.

use crate::common;
use crate::common::TempFile;

use proptest::prelude::*;
use std::path::Path;
use wiperlab::Error;
use wiperlab::import::{Format, ImportSpec, canonical, read_trace};

const CASES: u32 = 1000;

/// Built-in seeds per format (small, hand-written in each tool's layout, FORMATS.md).
fn builtin_seed(format: Option<Format>) -> &'static str {
    match format {
        Some(Format::Dltdv) => {
            "pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y\n1.5,2.5,NaN,NaN\n3.0,4.0,5.0,6.0\n"
        }
        Some(Format::DltdvSparse) => {
            "Sparse format camera coordinates file\n3\t4\t3\n1\t1\t10.5\n1\t2\t20.25\n3\t3\t7.0\n"
        }
        Some(Format::Tracker) => {
            "#multi:\r\n\thead\t\ttip\t\t\r\nt\tx\ty\tx\ty\t\r\n0.0\t1.5E-3\t2\t\t\r\n0.033\t1\t2\t3\t4\t\r\n"
        }
        Some(Format::KinoveaCsv) => {
            "\"Time\";\"B/h/X\";\"B/h/Y\"\r\n\"0,0\";\"1,5\";\"-2,0\"\r\n\"0,5\";;\"3,0\"\r\n"
        }
        Some(Format::KinoveaTxt) => {
            "#Kinovea Trajectory data export\n#T X Y\n\n# a\n0.000 1,5 2,5 \n0.008 1,0 2,0 \n\n# b\n0.000 7,0 8,0 \n"
        }
        Some(Format::KinoveaKinematics) => {
            "Time (ms),HEAD,Knee X,Knee Y\r\n40,1.5,2,3\r\n80,2.5,3,4\r\n"
        }
        Some(Format::Deeplabcut) => {
            "scorer,s,s,s,s,s,s\r\nindividuals,a,a,a,b,b,b\r\nbodyparts,h,h,h,t,t,t\r\ncoords,x,y,likelihood,x,y,likelihood\r\n0,1.5,2.5,0.9,,,\r\n1,1.0,2.0,0.1,3,4,0.99\r\n"
        }
        Some(Format::Sleap) => {
            "track,frame_idx,instance.score,head.x,head.y,head.score\nm1,0,0.9,1.0,2.0,0.95\nm2,0,0.9,5.0,6.0,0.2\n,1,,,,\nm1,2,0.9,3.0,4.0,0.99\n"
        }
        Some(Format::Trackmate) => {
            "LABEL,ID,TRACK_ID,POSITION_X,POSITION_Y,POSITION_T,FRAME\nLabel,Spot ID,Track ID,X,Y,T,Frame\nLabel,Spot ID,Track ID,X,Y,T,Frame\n,,,(micron),(micron),(sec),\nID1,1,0,1.0,2.0,0.0,0\nID2,2,0,ø,3.0,0.5,1\nID3,3,,9,9,0.5,1\n"
        }
        Some(Format::Generic) => "Export v1\nunits mm\nt;x;y\n0;1,5;2\n0,1;;3\n",
        Some(Format::Canonical) | None => "t_s,head_x_m,head_y_m\n0,1e-3,NaN\n0.001,2e-3,-1.5e-5\n",
    }
}

/// A real file per format in ../shared/realdata (first 8 KiB), when the folder is present.
fn real_seed(format: Option<Format>) -> Option<Vec<u8>> {
    let rel = match format? {
        Format::Dltdv => "realdata/dltdv/LapsanskyArmstrong2022_data_xypts.csv",
        Format::Tracker => "realdata/tracker/8049.txt",
        Format::KinoveaTxt => "realdata/kinovea/trop_camera_03.txt",
        Format::KinoveaKinematics => "realdata/kinovea/v1.csv",
        Format::Deeplabcut => {
            "realdata/deeplabcut/AFAMcarollia_1Apr2021_0790C_Bane_Y20210401H145003.312743000_F1_croppedDLC_resnet50_Brown2021_accuracy_testJan28shuffle1_450000.csv"
        }
        Format::Sleap => "realdata/sleap/sleap_csv_example.EXCERPT_first11lines.csv",
        Format::Trackmate => "realdata/trackmate/Spots in tracks statistics.csv",
        _ => return None,
    };
    let path = common::shared_dir().join(rel);
    let mut bytes = std::fs::read(path).ok()?;
    bytes.truncate(8192);
    Some(bytes)
}

/// Settings under which every reader can succeed on its seed.
fn spec_for(format: Format) -> ImportSpec {
    let mut s = ImportSpec {
        format: Some(format),
        ..ImportSpec::default()
    };
    match format {
        Format::Tracker | Format::Canonical => {}
        Format::Dltdv | Format::DltdvSparse | Format::Deeplabcut | Format::Sleap => {
            s.fps_hz = Some(100.0);
            s.m_per_px = Some(1e-3);
            if format == Format::DltdvSparse {
                s.n_cameras = 2;
            }
        }
        Format::Trackmate => {
            s.fps_hz = Some(100.0);
            s.units_to_m = Some(1e-6);
        }
        Format::KinoveaCsv | Format::KinoveaTxt | Format::KinoveaKinematics => {
            s.units_to_m = Some(0.01);
            s.time_to_s = Some(1.0);
        }
        Format::Generic => {
            s.units_to_m = Some(1e-3);
            s.decimal_comma = true;
            s.generic =
                Some(toml::from_str("time = \"t\"\n[points]\np = [\"x\", \"y\"]\n").unwrap());
        }
    }
    s
}

/// Run the reader on `bytes`; panics (= test failure) on a broken contract.
fn check(format: Option<Format>, bytes: &[u8], rotate: bool) {
    let f = TempFile::path("in.txt");
    std::fs::write(&f.0, bytes).unwrap();
    let result = match format {
        Some(fm) => {
            let mut spec = spec_for(fm);
            spec.sweep_from_head = rotate;
            read_trace(&f.0, &spec)
        }
        None => canonical::read_trace_csv(&f.0),
    };
    match result {
        Ok(trace) => {
            if let Err(m) = trace.check() {
                panic!("accepted input gave an inconsistent trace: {m}");
            }
        }
        Err(e) => check_error(&f.0, &e),
    }
}

fn check_error(path: &Path, e: &Error) {
    let text = e.to_string();
    match e {
        Error::Parse { line, message, .. } => {
            assert!(*line >= 1, "parse error without a line: {text}");
            assert!(
                message.contains("expected") || message.contains("twice"),
                "parse error does not say what was expected: {text}"
            );
            assert!(text.contains(&*path.to_string_lossy()), "{text}");
        }
        Error::Input { .. } | Error::Io { .. } => {
            assert!(
                text.contains(&*path.to_string_lossy()),
                "error does not name the file: {text}"
            );
        }
        e if wiperlab::import::ImportError::of(e).is_some() => {}
        other => panic!("unexpected error kind for bad input: {other:?}"),
    }
}

/// Bytes that matter to the parsers, for insertions.
const INTERESTING: &[u8] = b",;\t \n\r\"-+.eE0123456789NaN#\xf8\xc3\x81\x00/xy_{}()";

fn mutate(seed: &[u8], edits: &[(usize, u8, u8)], cut: Option<usize>) -> Vec<u8> {
    let mut v = seed.to_vec();
    for &(pos, kind, b) in edits {
        if v.is_empty() {
            v.push(b);
            continue;
        }
        let i = pos % v.len();
        let b = INTERESTING[usize::from(b) % INTERESTING.len()];
        match kind % 4 {
            0 => v[i] = b,
            1 => v.insert(i, b),
            2 => {
                v.remove(i);
            }
            _ => {
                // Duplicate a short span (repeated lines, fields).
                let end = (i + 1 + usize::from(b) % 40).min(v.len());
                let span = v[i..end].to_vec();
                v.splice(i..i, span);
            }
        }
    }
    if let Some(c) = cut {
        let n = v.len();
        v.truncate(c % (n + 1));
    }
    v
}

fn formats() -> Vec<Option<Format>> {
    let mut v: Vec<Option<Format>> = Format::ALL.iter().copied().map(Some).collect();
    v.push(None);
    v
}

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2048), rotate in any::<bool>()) {
        for f in formats() {
            check(f, &bytes, rotate);
        }
    }

    #[test]
    fn mutated_seeds_never_panic(
        edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..8),
        cut in proptest::option::of(any::<usize>()),
        rotate in any::<bool>(),
    ) {
        for f in formats() {
            let builtin = builtin_seed(f).as_bytes();
            check(f, &mutate(builtin, &edits, cut), rotate);
            if let Some(real) = real_seed(f) {
                check(f, &mutate(&real, &edits, cut), rotate);
            }
        }
    }

    #[test]
    fn detection_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        let f = TempFile::path("detect.txt");
        std::fs::write(&f.0, &bytes).unwrap();
        if let Err(e) = Format::detect(&f.0) {
            check_error(&f.0, &e);
        }
    }
}

/// The seeds themselves are accepted (so mutations start from valid files).
#[test]
fn seeds_are_valid() {
    for f in formats() {
        let t = TempFile::path("seed.txt");
        std::fs::write(&t.0, builtin_seed(f)).unwrap();
        let r = match f {
            Some(fm) => read_trace(&t.0, &spec_for(fm)),
            None => canonical::read_trace_csv(&t.0),
        };
        assert!(r.is_ok(), "{f:?}: {}", r.unwrap_err());
    }
}
