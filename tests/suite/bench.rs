//! `wiperlab bench --quick` through the library: every method runs on every problem, the
//! event-driven errors (DOPRI5 and DOP853) fall with the tolerance, Moreau–Jean converges at first
//! order, and the CSV and figures are written. (Timings are not asserted: speed is measured by the bench, not by tests.)

use crate::common;

use wiperlab::bench::{BenchOptions, run_bench, spectra_vs_rtol, write_reports, write_spectra};
use wiperlab::model::BladeParams;

#[test]
fn quick_bench_runs_every_method_and_writes_reports() {
    let text =
        std::fs::read_to_string(common::root().join("data/reversal/blade_true.toml")).unwrap();
    let blade: BladeParams = toml::from_str(&text).unwrap();
    let rows = run_bench(&BenchOptions { quick: true, blade }).unwrap();
    let sel = |problem: &str, method: &str| -> Vec<_> {
        rows.iter()
            .filter(|r| r.problem == problem && r.method.starts_with(method))
            .collect()
    };
    for problem in ["belt", "blade-burst"] {
        for method in [
            "event-driven DOPRI5",
            "event-driven DOP853",
            "Moreau-Jean",
            "smoothed tanh",
        ] {
            let s = sel(problem, method);
            assert!(!s.is_empty(), "{problem}/{method} missing");
            for r in &s {
                assert!(r.note.is_empty(), "{problem}/{method}: {}", r.note);
                assert!(r.rhs_evals > 0 && r.transition_err_s.is_finite());
            }
        }
        // Event-driven, with either integrator: the tightest setting is far more accurate than the
        // loosest, and for these two problems reaches 1e-9 s.
        for method in ["event-driven DOPRI5", "event-driven DOP853"] {
            let ed: Vec<_> = sel(problem, method)
                .into_iter()
                .filter(|r| r.method == method)
                .collect();
            let (first, last) = (ed.first().unwrap(), ed.last().unwrap());
            assert!(
                last.transition_err_s < 1e-9,
                "{problem} {method}: {}",
                last.transition_err_s
            );
            assert!(last.transition_err_s < 1e-3 * first.transition_err_s);
        }
    }
    // Moreau–Jean on the belt: first order (error ÷ 10 per step ÷ 10, within 2×).
    let mj = sel("belt", "Moreau-Jean");
    for w in mj.windows(2) {
        let ratio = w[0].transition_err_s / w[1].transition_err_s;
        assert!(ratio > 5.0 && ratio < 20.0, "Moreau-Jean ratio {ratio}");
    }
    // Event-order rows fall by ≥ 2^3.5 per halving of the step from h = 0.04 s on (h = 0.08 s, about
    // a twelfth of the period, is not yet asymptotic: measured 2^3.0).
    let order = sel("coulomb-fixed-step", "event-driven");
    for w in order.windows(2).skip(1) {
        assert!(w[0].transition_err_s / w[1].transition_err_s > 2f64.powf(3.5));
    }
    let tmp = common::temp_dir("bench");
    let dir = tmp.path();
    write_reports(dir, &rows).unwrap();
    let spectra = spectra_vs_rtol("blade_true", &blade, &[1e-6, 1e-8]).unwrap();
    let loosest = write_spectra(dir, &spectra, 0.002, 0.05).unwrap();
    assert_eq!(loosest, Some(1e-6));
    for f in [
        "work_precision.csv",
        "work_precision.svg",
        "work_precision_rhs.svg",
        "work_precision_trace.svg",
        "event_order.svg",
        "spectra_vs_rtol.csv",
        "spectra_vs_rtol.svg",
    ] {
        let len = std::fs::metadata(dir.join(f)).map(|m| m.len()).unwrap_or(0);
        assert!(len > 100, "{f}: {len} bytes");
    }
    let csv = std::fs::read_to_string(dir.join("work_precision.csv")).unwrap();
    assert_eq!(csv.lines().count(), rows.len() + 1);
}

/// `wiperlab bench` runs from any working directory: its default blades are the source tree's
/// (here run from one temp dir, outputs to another).
#[test]
fn bench_runs_from_anywhere() {
    let (cwd, out) = (common::temp_dir("bench_cwd"), common::temp_dir("bench_out"));
    common::wiperlab(["bench", "--quick", "--out-dir", common::s(out.path())])
        .current_dir(cwd.path())
        .assert()
        .success();
    for f in ["work_precision.csv", "spectra_vs_rtol.csv"] {
        assert!(out.path().join(f).exists(), "{f} not written");
    }
}
