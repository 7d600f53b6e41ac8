//! Are a fit's intervals consistent with its likelihood? At the point where a fit of a recording
//! with a known truth ended (its `<name>.result.toml`), this tool compares three descriptions of
//! the likelihood around the fit:
//!
//! 1. **The likelihood along the segment from the fit to the truth**: the NLL at 11 points of the
//!    straight line between them in the search's normalised coordinates (one simulation each).
//! 2. **The rise the Laplace method predicts there**: `½ dᵀ F d` with `F` the Gauss–Newton Fisher
//!    information the Laplace intervals come from (`wiperlab::search::evidence::at_fit_smoothed`), and
//!    the truth's Mahalanobis distance under the reported sandwich covariance.
//! 3. **A posterior sample** (the affine-invariant ensemble of `[fit.uncertainty] method = "mcmc"`,
//!    32 walkers, the likelihood tempered by `k/tr(F⁻¹V)`): its 68 % and 95 % intervals and the
//!    truth's quantile in each marginal. With `--temperatures K` the sample is parallel-tempered
//!    (`wiperlab::posterior::tempering`, a geometric ladder of K rungs): hot ensembles cross the
//!    ridges between basins and hand their points down to the untempered one.
//!
//! The job must be the one the fit ran (same recording, bounds and likelihood): the tool prints
//! the cost it finds at the fitted point beside the result's, and stops when they differ by more
//! than 0.5 nats. `--noise white` re-reads a result made with the white tracking-noise floor by a
//! job that does not say so. How the development set's fits look under this tool is in
//! docs/validation.md, "Intervals against the likelihood".
//!
//! ```sh
//! cargo run --release --example interval_check -- JOB.toml JOB.result.toml --noise white --steps 400
//! ```

use clap::Parser;
use nalgebra::{DMatrix, DVector};
use std::path::PathBuf;
use wiperlab::job::{Candidate, LoadedJob, NoiseSpectrum};
use wiperlab::likelihood::covariance::{cholesky_of_covariance, covariance_of};
use wiperlab::likelihood::secant::{SECANT_PROBE_SIGMA, flat_axes};
use wiperlab::posterior::tempering::{geometric_ladder, sample_tempered};
use wiperlab::posterior::{EnsembleSettings, ensemble::gaussian_ball_with};
use wiperlab::search::evidence::{LocalFit, at_fit_smoothed};
use wiperlab::search::{FAILED_COST, SpectralProblem, problem_for};
use wiperlab::uncertainty::posterior_tempering;

#[derive(Parser)]
struct Args {
    /// The fit job (with `[truth]` for every freed parameter).
    job: PathBuf,
    /// The result the job's fit wrote.
    result: PathBuf,
    /// Read the likelihood with this tracking-noise spectrum instead of the job's.
    #[arg(long)]
    noise: Option<String>,
    /// Steps of every walker of the posterior sample (0: no sample).
    #[arg(long, default_value_t = 400)]
    steps: usize,
    /// Rungs of the parallel-tempering ladder (1: the plain ensemble).
    #[arg(long, default_value_t = 1)]
    temperatures: usize,
}

const WALKERS: usize = 32;

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

/// What the posterior sample needs from the fit's local description.
struct Spread {
    /// `k/tr(F⁻¹V)`, the likelihood's tempering.
    tempering: f64,
    /// Cholesky factor of the sandwich covariance: the walkers' starting ball.
    ball: Option<DMatrix<f64>>,
}

/// The largest gap between the result's cost and the cost recomputed at its parameters taken as
/// the same likelihood, nats.
const MAX_COST_GAP_NATS: f64 = 0.5;

fn main() -> Fallible<()> {
    let args = Args::parse();
    let mut job = LoadedJob::load(&args.job)?;
    if let Some(n) = &args.noise {
        job.job.fit.likelihood.noise = match n.as_str() {
            "white" => NoiseSpectrum::White,
            "ar1" => NoiseSpectrum::Ar1,
            other => return Err(format!("--noise: expected white or ar1, got {other}").into()),
        };
    }
    let result: toml::Value = toml::from_str(&std::fs::read_to_string(&args.result)?)?;
    let model: Candidate = result["model"]
        .as_str()
        .ok_or("result without model")?
        .parse()?;
    let p = problem_for(&job, model)?;
    let fitted = |name: &str, key: &str| -> Option<f64> {
        result["parameters"]
            .as_array()?
            .iter()
            .find(|q| q["name"].as_str() == Some(name))?
            .get(key)?
            .as_float()
    };
    let mut u_fit = Vec::new();
    let mut u_true = Vec::new();
    for fp in &p.free {
        let name = fp.name.to_string();
        u_fit.push(fp.u_of(fitted(&name, "value").ok_or(format!("no fitted {name}"))?));
        let t = job.truth.get(&fp.name).ok_or(format!("no true {name}"))?;
        u_true.push(fp.u_of(*t));
    }
    let cost_fit = p.cost_at(&u_fit);
    let reported = result["cost"].as_float().ok_or("result without cost")?;
    println!("model {model}: cost at the fit {cost_fit:.4} nats (result {reported:.4})");
    // The cost is reproducible only to the simulation's own jitter: the parameters' round trip
    // through the result's decimal values can flip a step of the adaptive integrator (0.08 nats
    // on the main job, as its tolerance check's spread shows). A larger gap is another likelihood.
    if (cost_fit - reported).abs() > MAX_COST_GAP_NATS {
        return Err("the job's likelihood is not the one the fit ran (see --noise)".into());
    }
    segment(&p, &u_fit, &u_true, cost_fit);
    let spread = predicted_rise(&p, &u_fit, &u_true)?;
    if args.steps > 0 {
        posterior(&p, &job, &u_fit, spread, args.steps, args.temperatures)?;
    }
    Ok(())
}

/// The NLL along the straight line from the fit (s = 0) to the truth (s = 1).
fn segment(p: &SpectralProblem, u_fit: &[f64], u_true: &[f64], cost_fit: f64) {
    println!("segment from the fit (s = 0) to the truth (s = 1): rise of the NLL, nats");
    for i in 0..=10 {
        let s = f64::from(i) / 10.0;
        let u: Vec<f64> = u_fit
            .iter()
            .zip(u_true)
            .map(|(a, b)| a + s * (b - a))
            .collect();
        println!("  s = {s:.1}: {:+.4}", p.cost_at(&u) - cost_fit);
    }
}

/// `½ dᵀ C⁻¹ d` for the Fisher and the sandwich covariances at the fit, `d` = truth − fit;
/// returns the posterior's tempering `k/tr(F⁻¹V)` and the Cholesky factor of the sandwich (the
/// posterior's starting ball).
fn predicted_rise(p: &SpectralProblem, u_fit: &[f64], u_true: &[f64]) -> Fallible<Spread> {
    let lf = at_fit_smoothed(p, u_fit)?;
    let k = u_fit.len();
    let d = DVector::from_iterator(k, u_true.iter().zip(u_fit).map(|(t, f)| t - f));
    for (name, sigma, corr) in [
        ("Fisher F⁻¹", &lf.curvature_sigma_u, &lf.curvature_corr),
        ("sandwich F⁻¹VF⁻¹", &lf.sigma_u, &lf.corr),
    ] {
        let c = covariance_of(sigma, corr);
        match c.clone().try_inverse() {
            Some(ci) => println!(
                "{name}: ½ dᵀC⁻¹d = {:.2} (the rise a quadratic likelihood with this covariance puts at the truth)",
                0.5 * (d.transpose() * ci * &d)[(0, 0)]
            ),
            None => println!("{name}: singular"),
        }
        along_axes(&c, &d);
        if name.starts_with("Fisher") {
            probe_axes(p, u_fit, &c);
        }
    }
    let w = posterior_tempering(k, lf.nll.effective_parameters);
    println!(
        "tr(F⁻¹V) = {:.3}, tempering w = {w:.3}",
        lf.nll.effective_parameters.unwrap_or(f64::NAN)
    );
    laplace_and_secant(p, u_fit, u_true, &lf);
    Ok(Spread {
        tempering: w,
        ball: cholesky_of_covariance(&lf.sigma_u, &lf.corr),
    })
}

/// The Laplace intervals' 1σ (the sandwich's) with the truth's distance from the fit in them,
/// and the axes the fit's secant check (`wiperlab::likelihood::secant`) finds flatter than the quadratic.
fn laplace_and_secant(p: &SpectralProblem, u_fit: &[f64], u_true: &[f64], lf: &LocalFit) {
    let cost = p.cost_at(u_fit);
    for (i, fp) in p.free.iter().enumerate() {
        println!(
            "  {}: Laplace 1σ {:.2e} (normalised), the truth at {:+.1}σ",
            fp.name,
            lf.sigma_u[i],
            (u_true[i] - u_fit[i]) / lf.sigma_u[i]
        );
    }
    let fisher = (&lf.curvature_sigma_u[..], &lf.curvature_corr[..]);
    let cost_at = |u: &[f64]| Some(p.cost_at(u)).filter(|c| *c < FAILED_COST);
    for a in flat_axes(cost_at, u_fit, cost, fisher) {
        println!(
            "secant check: the axis of 1σ {:.2e} rises {:.3} nats at ±{SECANT_PROBE_SIGMA}σ: {:.1} times flatter in σ",
            a.fisher_sigma_u, a.rise_nats, a.stretch
        );
    }
}

/// `d` in the principal axes of the covariance `c`, widest first: each axis's 1σ (normalised
/// units) and `d`'s component along it in those σ.
fn along_axes(c: &DMatrix<f64>, d: &DVector<f64>) {
    let eig = c.clone().symmetric_eigen();
    let mut order: Vec<usize> = (0..d.len()).collect();
    order.sort_by(|a, b| eig.eigenvalues[*b].total_cmp(&eig.eigenvalues[*a]));
    let parts: Vec<String> = order
        .iter()
        .map(|&i| {
            let sd = eig.eigenvalues[i].max(0.0).sqrt();
            let along = eig.eigenvectors.column(i).dot(d);
            format!("1σ {sd:.2e}: {:+.1}σ", along / sd)
        })
        .collect();
    println!(
        "  the truth along its principal axes, widest first: {}",
        parts.join(", ")
    );
}

/// The NLL's rise along each principal axis of `c` at ±r of its 1σ against the quadratic's r²/2.
fn probe_axes(p: &SpectralProblem, u_fit: &[f64], c: &DMatrix<f64>) {
    let c0 = p.cost_at(u_fit);
    let eig = c.clone().symmetric_eigen();
    for r in [3.0f64, 5.0, 10.0] {
        let mut parts = Vec::new();
        for i in 0..u_fit.len() {
            let sd = eig.eigenvalues[i].max(0.0).sqrt();
            for sign in [1.0, -1.0] {
                let u: Vec<f64> = (0..u_fit.len())
                    .map(|a| u_fit[a] + sign * r * sd * eig.eigenvectors[(a, i)])
                    .collect();
                parts.push(format!("{:.2}", p.cost_at(&u) - c0));
            }
        }
        println!(
            "  rise at ±{r}σ along each axis (quadratic {:.1}): {}",
            r * r / 2.0,
            parts.join(" ")
        );
    }
}

/// The tempered posterior sample's 68 % and 95 % intervals and the truth's quantiles.
fn posterior(
    p: &SpectralProblem,
    job: &LoadedJob,
    u_fit: &[f64],
    spread: Spread,
    steps: usize,
    temperatures: usize,
) -> Fallible<()> {
    let w = spread.tempering;
    let k = u_fit.len();
    let inside = |u: &[f64]| u.iter().all(|x| (0.0..=1.0).contains(x));
    // The tempered log-likelihood and the flat prior of the box.
    let log_parts = |u: &[f64]| match inside(u).then(|| p.cost_at(u)) {
        Some(c) if c < FAILED_COST => (-w * c, 0.0),
        _ => (f64::NEG_INFINITY, 0.0),
    };
    let ball = spread
        .ball
        .unwrap_or_else(|| DMatrix::identity(k, k) * 0.01);
    let start = gaussian_ball_with(u_fit, &ball, WALKERS, 1, inside);
    let settings = EnsembleSettings::new(WALKERS, steps, 1);
    let started = std::time::Instant::now();
    let betas = geometric_ladder(temperatures, k);
    let run = sample_tempered(log_parts, start, &settings, &betas, |_| true)?;
    let chains = &run.cold;
    let burn_in = steps * 3 / 10;
    println!(
        "posterior sample: {WALKERS} walkers × {steps} steps ({burn_in} burn-in) × {temperatures} \
         temperatures (β down to {:.3}), acceptance {:.2}, swaps {:?}, {} evaluations, {:.0} s",
        betas.last().copied().unwrap_or(1.0),
        chains.accepted as f64 / (WALKERS * steps) as f64,
        run.swap_fractions()
            .iter()
            .map(|f| (f * 100.0).round() / 100.0)
            .collect::<Vec<_>>(),
        chains.evaluations,
        started.elapsed().as_secs_f64()
    );
    for (i, fp) in p.free.iter().enumerate() {
        let mut xs: Vec<f64> = chains.positions[burn_in..]
            .iter()
            .flat_map(|step| step.iter().map(move |walker| fp.value(walker[i])))
            .collect();
        xs.sort_by(f64::total_cmp);
        let q = |f: f64| xs[((xs.len() - 1) as f64 * f).round() as usize];
        let truth = job.truth[&fp.name];
        let below = xs.iter().filter(|x| **x < truth).count() as f64 / xs.len() as f64;
        println!(
            "  {}: 68 % [{:.4e}, {:.4e}], 95 % [{:.4e}, {:.4e}], truth {truth:.4e} at quantile {below:.3}",
            fp.name,
            q(0.1587),
            q(0.8413),
            q(0.025),
            q(0.975)
        );
    }
    Ok(())
}
