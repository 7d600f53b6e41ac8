//! Several recordings in one fit: two recordings the model made of the same blade at two sweep
//! speeds (the shipped sample's ω and 0.7 ω), at a tighter tolerance than the fit uses, written as
//! DLTdv files through the sample's camera model. A joint fit shares C and k1 between them (each
//! recording keeps its own drive) and must recover both within 5 %, as the single-recording fit does
//! (tests/suite/fit_recovery.rs), and report the peaks of both recordings.

use crate::common;

use std::path::Path;
use wiperlab::fit::run_fit;
use wiperlab::job::LoadedJob;
use wiperlab::model::{BladeParams, FrictionLaw};

/// Simulates `p` over its default window at 10 kfps and writes a DLTdv xypts file; returns t0.
fn write_recording(p: &BladeParams, path: &Path) -> f64 {
    let (sim, t0) = common::recording_of(p).unwrap();
    common::write_dltdv(path, &sim, &mut || 0.0);
    t0
}

#[test]
fn joint_fit_of_two_sweep_speeds_recovers_shared_parameters() {
    let base: BladeParams = common::true_blade();
    let (c_true, k1_true) = (0.5, 0.026);
    let mut truth = base;
    truth.k1_nm_per_rad = k1_true;
    if let FrictionLaw::Exponential { c, .. } = &mut truth.friction {
        *c = c_true;
    }
    let mut slow = truth;
    slow.drive_omega_rad_per_s = 0.7 * truth.drive_omega_rad_per_s;
    let tmp = common::temp_dir("joint_fit");
    let dir = tmp.path();
    let t0_fast = write_recording(&truth, &dir.join("fast_xypts.csv"));
    let t0_slow = write_recording(&slow, &dir.join("slow_xypts.csv"));
    std::fs::write(dir.join("blade.toml"), toml::to_string(&base).unwrap()).unwrap();
    std::fs::write(
        dir.join("truth.json"),
        format!("{{\"C\": {c_true}, \"k1\": {k1_true}}}"),
    )
    .unwrap();
    let import = common::dltdv_import;
    let job = format!(
        r#"name = "joint"
blade = "blade.toml"
[recording]
file = "fast_xypts.csv"
[recording.import]
{fast}[recording.import.points]
head = "pt1"
tip = "pt2"

[[more_recordings]]
name = "slow"
file = "slow_xypts.csv"
drive_omega_rad_per_s = {omega_slow:?}
[more_recordings.import]
{slow}[more_recordings.import.points]
head = "pt1"
tip = "pt2"

[fit]                    # the fit's default solver (rtol 1e-7): C +0.02 %, k1 −0.15 % (rtol 1e-8: +0.30 %, +0.17 %)
particles = 8
swarm_iterations = 6
polish_iterations = 25
seed = 3
[fit.uncertainty]        # two replicates: checks that a joint fit gets intervals, not their coverage
bootstrap = 2
[fit.parameters]
C = [0.3, 0.8]
k1 = [0.01, 0.05]
[truth]
json = "truth.json"
keys = {{ C = "/C", k1 = "/k1" }}
"#,
        fast = import(t0_fast),
        slow = import(t0_slow),
        omega_slow = slow.drive_omega_rad_per_s
    );
    std::fs::write(dir.join("job.toml"), job).unwrap();
    let loaded = LoadedJob::load(&dir.join("job.toml")).unwrap();
    let out = run_fit(&loaded, false).unwrap();
    for pk in &out.result.peaks {
        eprintln!(
            "peak {}: model {:.3} Hz, measured {:.3} Hz",
            pk.band, pk.model_hz, pk.measured_hz
        );
    }
    assert!(
        out.result.peaks.iter().any(|p| p.band == "slow:high"),
        "the second recording's peaks are reported"
    );
    for pk in &out.result.peaks {
        assert!(
            pk.rel_diff.abs() < 0.02,
            "{}: {:+.2} %",
            pk.band,
            100.0 * pk.rel_diff
        );
    }
    for p in &out.result.parameters {
        eprintln!(
            "{}: fitted {:.6} true {:.6} rel err {:+.3}%",
            p.name,
            p.value,
            p.true_value.unwrap(),
            100.0 * p.rel_error.unwrap()
        );
        assert!(p.rel_error.unwrap().abs() < 0.05, "{} off", p.name);
        // Every parameter of a joint fit has a bootstrap interval, whose replicates re-noise both
        // recordings, each at its own measured noise level.
        let iv = p.interval.as_ref().unwrap_or_else(|| {
            panic!(
                "{}: no interval; warnings {:?}",
                p.name, out.result.warnings
            )
        });
        eprintln!(
            "{}: interval [{:.6}, {:.6}] ({})",
            p.name, iv.lo, iv.hi, iv.method
        );
        assert!(
            iv.lo.is_finite() && iv.hi.is_finite() && iv.lo < iv.hi,
            "{iv:?}"
        );
        // One noise level per recording: both recordings were re-noised.
        assert!(
            matches!(&iv.method, wiperlab::fit::IntervalMethod::Bootstrap { noise_sigma_m, .. } if noise_sigma_m.len() == 2),
            "{}",
            iv.method
        );
    }
}
