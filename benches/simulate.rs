//! Criterion benches (issue 5): the blade's right-hand side, one reversal window, one fit cost
//! evaluation. Run: `cargo bench --bench simulate`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::sync::atomic::AtomicUsize;
use std::sync::{Arc, Mutex};
use wiperlab::fit::features::{SignalKind, default_bands, features};
use wiperlab::job::{Objective, Weights};
use wiperlab::model::{Blade, BladeParams, StickForm};
use wiperlab::search::SpectralProblem;
use wiperlab::search::evidence::RecordingLikelihood;
use wiperlab::simulate::blade::{default_window, simulate_blade};
use wiperlab::simulate::hybrid::{Mode, Phase, SolverOptions, StickSlipModel};

fn params() -> BladeParams {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/reversal/blade_true.toml"
    ))
    .expect("data/reversal/blade_true.toml");
    toml::from_str(&text).expect("blade parameters")
}

fn opts(rtol: f64) -> SolverOptions {
    SolverOptions {
        rtol,
        atol: rtol * 1e-2,
        ..Default::default()
    }
}

fn rhs(c: &mut Criterion) {
    let p = params();
    let blade = Blade::new(p, StickForm::Reduced);
    let (t0, _) = default_window(&p);
    let y = blade.slip_equilibrium(t0).expect("equilibrium");
    let slip = Mode {
        phase: Phase::SlipPos,
        anchor: 0.0,
        region: 0,
    };
    let stick = Mode {
        phase: Phase::Stick,
        anchor: blade.tip_position(t0, &y),
        region: 0,
    };
    c.bench_function("blade rhs, slip", |b| {
        b.iter(|| {
            let mut dy = [0.0; 4];
            blade
                .rhs(&slip, black_box(t0), black_box(&y), &mut dy)
                .expect("rhs");
            dy
        })
    });
    c.bench_function("blade rhs, stick (drift-free)", |b| {
        b.iter(|| {
            let mut dy = [0.0; 4];
            blade
                .rhs(&stick, black_box(t0), black_box(&y), &mut dy)
                .expect("rhs");
            dy
        })
    });
}

fn window(c: &mut Criterion) {
    let p = params();
    let w = default_window(&p);
    let mut g = c.benchmark_group("reversal window");
    g.sample_size(10);
    for rtol in [1e-6, 1e-8] {
        g.bench_function(format!("rtol {rtol:e}"), |b| {
            b.iter(|| simulate_blade(&p, w, &[], &opts(rtol), StickForm::Reduced).expect("run"))
        });
    }
    g.finish();
}

fn cost(c: &mut Criterion) {
    // A synthetic "measurement": the true blade at 10 kHz over its window; cost at the true
    // parameters with nothing freed (one model run + features + cost, as in the fit).
    let p = params();
    let (t0, t1) = default_window(&p);
    let fs = 10_000.0;
    let n = ((t1 - t0) * fs) as usize + 1;
    let times: Vec<f64> = (0..n).map(|i| t0 + i as f64 / fs).collect();
    let window = (t0, times[n - 1]);
    let solver = opts(1e-8);
    let sim = simulate_blade(&p, window, &times, &solver, StickForm::Reduced).expect("run");
    let x = SignalKind::TipRelX
        .extract(&sim.to_trace())
        .expect("signal");
    let bands = default_bands();
    let measured = features(&x, fs, &bands, 5).expect("features");
    let mut problem = SpectralProblem {
        model: wiperlab::simulate::blade::ModelKind::Blade2dof,
        head: None,
        targets: None,
        time_targets: None,
        others: Vec::new(),
        label: String::new(),
        base: p,
        free: Vec::new(),
        floors: vec![0.0; bands.len()],
        lines: measured
            .bands
            .iter()
            .map(wiperlab::likelihood::band_has_line)
            .collect(),
        measured,
        bands,
        signal: SignalKind::TipRelX,
        nan_mask: vec![false; n],
        sample_times: times,
        fs_hz: fs,
        max_fill: 5,
        window,
        solver,
        swarm_solver: solver,
        local_solver: solver,
        swarm_cost: Default::default(),
        objective: Objective::Likelihood,
        weights: Weights::default(),
        likelihood: Err(wiperlab::search::NoLikelihood::NotBuilt),
        signal_likelihood: None,
        evaluations: Arc::new(AtomicUsize::new(0)),
        failures: std::sync::Arc::new(AtomicUsize::new(0)),
        failure_causes: Default::default(),
        first_failure: Mutex::new(None),
        near_best: Mutex::new(Default::default()),
        last_jitter: Mutex::new(None),
        prior: Default::default(),
    };
    problem.likelihood = Ok(Arc::new(
        RecordingLikelihood::new(&problem, &x, false).expect("likelihood"),
    ));
    let mut g = c.benchmark_group("fit");
    g.sample_size(10);
    g.bench_function("SpectralProblem::cost_at (rtol 1e-8)", |b| {
        b.iter(|| problem.cost_at(black_box(&[])))
    });
    g.finish();
}

criterion_group!(benches, rhs, window, cost);
criterion_main!(benches);
