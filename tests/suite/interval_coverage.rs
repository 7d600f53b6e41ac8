//! Do the fit's intervals cover the truth at their stated rate?
//!
//! Synthetic recordings of the 1-DOF head model (cheap enough to fit many times) around the reversal,
//! each with its own tracking noise (Gaussian, σ = 0.1 px per coordinate, as in the shipped sample:
//! data/reversal/README.md), are fitted for k1 and C with parametric-bootstrap intervals at 68.27 %
//! (`wiperlab::uncertainty::bootstrap_intervals`). The recordings are simulated at rtol 1e-10, a hundred
//! times tighter than the fit's 1e-8, so that the fit's integrator error is part of what the
//! intervals must cover (no inverse crime) while staying far below the tracking noise. With R recordings the number
//! covering the truth is Binomial(R, 0.6827); the test accepts the central ~98 % of that law.

use crate::common;

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use wiperlab::fit::run_fit;
use wiperlab::job::LoadedJob;
use wiperlab::model::StickForm;
use wiperlab::model::{BladeParams, FrictionLaw};
use wiperlab::simulate::SolverOptions;
use wiperlab::simulate::blade::{ModelKind, simulate_model};

const RECORDINGS: usize = 12;

fn binomial_cdf(k: usize, n: usize, p: f64) -> f64 {
    let mut c = 1.0f64;
    let mut total = 0.0;
    for i in 0..=k {
        if i > 0 {
            c *= (n - i + 1) as f64 / i as f64;
        }
        total += c * p.powi(i as i32) * (1.0 - p).powi((n - i) as i32);
    }
    total
}

/// What a coverage test accepts.
#[derive(Clone, Copy, PartialEq)]
enum Accept {
    /// The central ~98 % of Binomial(recordings, 0.6827): the stated rate.
    Rate,
    /// The stated rate, and every interval contains its own estimate (an interval built around
    /// it).
    RateAroundEstimate,
}

/// Fits `recordings` noisy recordings of the head model with the given `[fit.uncertainty]` section
/// and counts, per parameter, the 68.27 % intervals that cover the truth; asserts that every
/// Laplace interval contains its estimate and that the counts are accepted by `accept` under
/// Binomial(recordings, 0.6827).
fn coverage(label: &str, recordings: usize, uncertainty: &str, accept: Accept) {
    let base: BladeParams = common::true_blade();
    let (k1_true, c_true) = (0.015, 0.56);
    let mut truth = base;
    truth.k1_nm_per_rad = k1_true;
    if let FrictionLaw::Exponential { c, .. } = &mut truth.friction {
        *c = c_true;
    }
    // 0.6 s around the reversal at 1.8868 s (truth.json /params/t_reversal_s), 10 kfps.
    let (t0, fps, n) = (1.60, 1e4, 6000usize);
    let times: Vec<f64> = (0..n).map(|k| t0 + k as f64 / fps).collect();
    let opts = SolverOptions {
        rtol: 1e-10,
        atol: 1e-12,
        ..SolverOptions::default()
    };
    let sim = simulate_model(
        ModelKind::Head1dof,
        &truth,
        (t0, *times.last().unwrap()),
        &times,
        &opts,
        StickForm::Reduced,
    )
    .unwrap();
    let tmp = common::temp_dir(&format!("coverage_{label}"));
    let dir = tmp.path();
    std::fs::write(dir.join("blade.toml"), toml::to_string(&base).unwrap()).unwrap();
    std::fs::write(
        dir.join("truth.json"),
        format!("{{\"k1\": {k1_true}, \"C\": {c_true}}}"),
    )
    .unwrap();
    let noise = Normal::new(0.0, 0.1).unwrap();
    let mut covered = std::collections::BTreeMap::<String, usize>::new();
    for r in 0..recordings {
        let mut rng = rand::rngs::StdRng::seed_from_u64(1000 + r as u64);
        common::write_dltdv(&dir.join(format!("rec{r}_xypts.csv")), &sim, &mut || {
            noise.sample(&mut rng)
        });
        let job = format!(
            r#"name = "coverage{r}"
blade = "blade.toml"
{recording}{spectrum}[solver]
rtol = 1e-8
atol = 1e-10
[fit]
particles = 8
swarm_iterations = 5
polish_iterations = 40
seed = 3
restarts = 2
{uncertainty}[fit.parameters]
k1 = [0.008, 0.03]
C = [0.4, 0.7]
[truth]
json = "truth.json"
keys = {{ k1 = "/k1", C = "/C" }}
"#,
            uncertainty = uncertainty.replace("{seed}", &(50 * r).to_string()),
            recording = common::dltdv_recording(&format!("rec{r}_xypts.csv"), t0),
            spectrum = common::spectrum_bands(&[("low", [30.0, 300.0], 2048)]),
        );
        std::fs::write(dir.join(format!("job{r}.toml")), job).unwrap();
        let loaded = LoadedJob::load(&dir.join(format!("job{r}.toml"))).unwrap();
        let out = run_fit(&loaded, false).unwrap();
        assert_eq!(
            (out.result.model.kind, out.result.model.shoulder),
            (ModelKind::Head1dof, false),
            "the smallest capable model for a low band"
        );
        for p in &out.result.parameters {
            let iv = p
                .interval
                .as_ref()
                .expect("an interval for every parameter");
            let t = p.true_value.unwrap();
            let inside = iv.lo <= t && t <= iv.hi;
            // Laplace intervals are built around the estimate; a basic bootstrap interval can
            // exclude it (its replicates' bias moves both ends), which issue 14 lists as open.
            assert!(
                accept != Accept::RateAroundEstimate || (iv.lo <= p.value && p.value <= iv.hi),
                "{label} recording {r}: {} = {} outside its interval [{}, {}]",
                p.name,
                p.value,
                iv.lo,
                iv.hi
            );
            eprintln!(
                "{label} recording {r}: {} = {:.6} (truth {t:.6}), interval [{:.6}, {:.6}] {}",
                p.name,
                p.value,
                iv.lo,
                iv.hi,
                if inside { "covers" } else { "misses" }
            );
            *covered.entry(p.name.to_string()).or_default() += usize::from(inside);
        }
    }
    // Acceptance region [lo, hi] with P(X < lo) ≈ P(X > hi) ≈ 1 % under Binomial(R, 0.6827).
    let p = 0.6827;
    let lo = (0..=recordings)
        .find(|&k| binomial_cdf(k, recordings, p) > 0.01)
        .unwrap();
    let hi = (0..=recordings)
        .find(|&k| binomial_cdf(k, recordings, p) >= 0.99)
        .unwrap();
    for (name, c) in &covered {
        eprintln!(
            "{label} {name}: {c} of {recordings} intervals cover the truth (accepted {lo}..={hi})"
        );
    }
    for (name, c) in &covered {
        assert!(
            (lo..=hi).contains(c),
            "{label} {name}: {c} of {recordings} 68 % intervals cover the truth (accepted {lo}..={hi})"
        );
    }
}

/// Bootstrap intervals (12 replicates, each a refit) on 12 recordings cover the truth at their rate.
/// Measured with these seeds: C 9/12, k1 9/12 against 8.2 expected. About 70 CPU-seconds, a tenth
/// of the suite's budget, for a method that is not the default: run it with
/// `cargo test --release --test suite interval_coverage:: -- --include-ignored`.
#[test]
#[ignore = "70 CPU-seconds for the non-default bootstrap; run with --include-ignored"]
fn bootstrap_intervals_cover_the_truth_at_their_rate() {
    coverage(
        "bootstrap",
        RECORDINGS,
        "[fit.uncertainty]\nbootstrap = 12\npolish_iterations = 40\nseed = {seed}\n",
        Accept::Rate,
    );
}

/// Laplace intervals (the likelihood's sandwich covariance, no refits) on 24 recordings cover the
/// truth at their rate, and each contains its estimate. Measured with these seeds: C 19/24, k1 16/24
/// against 16.4 expected. With the Fisher information alone (before the sandwich) they would be
/// about 2.3 times too wide: the Whittle likelihood lets the deterministic stick–slip signal's
/// ordinates scatter like a random process's, several times more than they do under tracking noise
/// (docs/uncertainty.md, "Uncertainty").
#[test]
fn laplace_intervals_cover_the_truth_at_their_rate() {
    coverage(
        "laplace",
        24,
        "[fit.uncertainty]\nmethod = \"laplace\"\n",
        Accept::RateAroundEstimate,
    );
}

/// Profile-likelihood intervals (each parameter walked out from the fit with the other re-polished,
/// to the sandwich-calibrated rise, `wiperlab::uncertainty::profile_intervals_at`) on the same 24
/// recordings cover the truth at their rate (measured with these seeds: C 17/24, k1 14/24), and each
/// contains its estimate. Where the likelihood
/// is quadratic they are the Laplace intervals; the rise limit μ/2 with μ = σ²_sandwich/σ²_Fisher is
/// what makes them so (with the uncalibrated 0.5 nats they would be the Fisher intervals, 2.3 times
/// too wide on these recordings).
#[test]
fn profile_intervals_cover_the_truth_at_their_rate() {
    coverage(
        "profile",
        24,
        "[fit.uncertainty]\nmethod = \"profile\"\n",
        Accept::RateAroundEstimate,
    );
}
