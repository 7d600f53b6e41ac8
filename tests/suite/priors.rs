//! `[fit.priors]`: the posterior a prior gives against closed forms (the precision-weighted normal
//! posterior, a log-normal prior's own density on either search scale), the rig-curve reader on a
//! small fixture and on a real rotary-tribometer log (`../shared/realdata/friction/`, skipped with
//! a printed reason when absent), its refusals of bad rows, and a job with priors loaded and read
//! by the cost and the Laplace curvature. The terms' and Hessians' closed forms are unit tests in
//! `src/likelihood/prior.rs`; the job errors a user sees are in `tests/suite/bad_input.rs`.

use crate::common;

use crate::common::{root, shared, temp_dir, write};
use wiperlab::job::{FreeParam, ParamPrior, PriorsSection};
use wiperlab::job::{FrictionCurvePrior, LoadedJob, rig};
use wiperlab::likelihood::prior::{Prior, PriorTerm};
use wiperlab::model::{BladeParams, ParamId};

fn spec(toml_text: &str) -> FrictionCurvePrior {
    toml::from_str(toml_text).expect("a friction_curve table")
}

/// A rig log as rig software writes one: a preamble line, the header with a trailing comma,
/// rows with trailing commas, a blank line and a footer.
const SMALL: &str = "\
Rig log, operator X\r\n\
Step, speed (mm/s), mu, mu_sd,\r\n\
1, 10, 0.50, 0.02,\n\
1, 20, 0.54, 0.02,\n\
1, 30, 0.46, 0.02,\n\
2, 100, 0.30, 0.01,\n\
2, 110, 0.34, 0.01,\n\
\r\n\
TotalTime\r\n\
00:01:00\r\n";

/// Row by row: each row a point at its speed in m/s with its own 1σ column; in file order, with
/// the line of its row (1-based: the header is line 2).
#[test]
fn rows_are_points_with_their_own_sd() {
    let dir = temp_dir("rig_rows");
    let path = write(dir.path(), "rig.csv", SMALL);
    let s = spec(
        "file = 'rig.csv'\nspeed_column = 'speed (mm/s)'\nspeed_unit = 'mm/s'\n\
         coefficient_column = 'mu'\nsd_column = 'mu_sd'",
    );
    let c = rig::read(&path, &s).unwrap();
    let got: Vec<(f64, f64, f64, u64)> = (c.points.iter())
        .map(|p| (p.speed_m_per_s, p.coefficient, p.sd, p.line))
        .collect();
    let want = [
        (0.010, 0.50, 0.02, 3),
        (0.020, 0.54, 0.02, 4),
        (0.030, 0.46, 0.02, 5),
        (0.100, 0.30, 0.01, 6),
        (0.110, 0.34, 0.01, 7),
    ];
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert!(
            (g.0 - w.0).abs() < 1e-15 && g.1 == w.1 && g.2 == w.2 && g.3 == w.3,
            "{g:?}"
        );
    }
}

/// Grouped by `Step`: each group one point at its mean speed and mean coefficient, its 1σ the
/// sample standard deviation of its coefficients (n − 1): group 1 has μ = (0.50, 0.54, 0.46),
/// mean 0.50, sd √((0 + 0.0016 + 0.0016)/2) = 0.04; group 2 (0.30, 0.34), mean 0.32, sd
/// √(0.0008) = 0.02√2. An `sd` replaces every group's.
#[test]
fn groups_are_points_at_their_mean_with_their_spread() {
    let dir = temp_dir("rig_groups");
    let path = write(dir.path(), "rig.csv", SMALL);
    let base = "file = 'rig.csv'\nspeed_column = 'speed (mm/s)'\nspeed_unit = 'mm/s'\n\
                coefficient_column = 'mu'\ngroup_by = 'Step'";
    let c = rig::read(&path, &spec(base)).unwrap();
    assert_eq!(c.points.len(), 2);
    let (g1, g2) = (&c.points[0], &c.points[1]);
    assert_eq!((g1.group.as_deref(), g1.rows, g1.line), (Some("1"), 3, 3));
    assert_eq!((g2.group.as_deref(), g2.rows, g2.line), (Some("2"), 2, 6));
    assert!((g1.speed_m_per_s - 0.020).abs() < 1e-15 && (g1.coefficient - 0.50).abs() < 1e-15);
    assert!((g1.sd - 0.04).abs() < 1e-15, "{}", g1.sd);
    assert!((g2.speed_m_per_s - 0.105).abs() < 1e-15 && (g2.coefficient - 0.32).abs() < 1e-15);
    assert!((g2.sd - 0.02 * 2f64.sqrt()).abs() < 1e-15, "{}", g2.sd);
    let c = rig::read(&path, &spec(&format!("{base}\nsd = 0.05"))).unwrap();
    assert!(c.points.iter().all(|p| p.sd == 0.05));
}

/// Bad rows are refused with the file, the line and what was expected.
#[test]
fn bad_rows_are_refused_with_file_and_line() {
    let dir = temp_dir("rig_bad");
    let rows = "file = 'rig.csv'\nspeed_column = 'speed (mm/s)'\nspeed_unit = 'mm/s'\n\
                coefficient_column = 'mu'\nsd_column = 'mu_sd'";
    let grouped = "file = 'rig.csv'\nspeed_column = 'speed (mm/s)'\nspeed_unit = 'mm/s'\n\
                   coefficient_column = 'mu'\ngroup_by = 'Step'";
    let cases: [(&str, String, &str, &[&str]); 7] = [
        (
            "a cell that is no number",
            SMALL.replace("1, 20, 0.54", "1, 20, 0.5x4"),
            rows,
            &["rig.csv:4:", "'mu'", "0.5x4"],
        ),
        (
            "a negative coefficient",
            SMALL.replace("2, 110, 0.34", "2, 110, -0.34"),
            rows,
            &["rig.csv:7:", "'mu'", ">= 0"],
        ),
        (
            "a zero 1σ",
            SMALL.replace("0.54, 0.02", "0.54, 0"),
            rows,
            &["rig.csv:4:", "'mu_sd'", "> 0"],
        ),
        (
            "a short row inside the table",
            SMALL.replace("1, 30, 0.46, 0.02,\n", "1, 30\n"),
            rows,
            &["rig.csv:5:", "inside the table"],
        ),
        (
            "no header naming the columns",
            SMALL.replace("mu_sd", "sigma"),
            rows,
            &["rig.csv", "no header row", "'mu_sd'"],
        ),
        (
            "no data rows",
            "Step, speed (mm/s), mu, mu_sd,\r\n".to_string(),
            rows,
            &["rig.csv", "no data rows", "line 1"],
        ),
        (
            "a group of one row without sd",
            SMALL.replace("2, 110, 0.34, 0.01,\n", ""),
            grouped,
            &["rig.csv:6:", "group '2'", "give sd"],
        ),
    ];
    for (what, text, settings, keys) in cases {
        let path = write(dir.path(), "rig.csv", &text);
        let e = rig::read(&path, &spec(settings)).expect_err(what);
        assert!(e.is_input_error(), "{what}: {e}");
        let e = e.to_string();
        for k in keys {
            assert!(e.contains(k), "{what}: {e:?} lacks {k:?}");
        }
    }
}

/// The real rotary-tribometer log (`../shared/realdata/SOURCES.md`, "friction/" item 2: a
/// metadata line with a bare CR inside, a header, trailing commas, a `TotalTime` footer; 4 steps
/// of 3 min at 119.2/159.1/179.0/191.0 rpm, "75–300 mm/s at 6–15 mm radius"). Grouped by `Step`
/// with the radii 6, 9, 12, 15 mm (75, 150, 225, 300 mm/s at those rpm), the four points lie at
/// `rpm·2π r/60` within 0.3 % (the step means include each step's spin-up from its first rows and
/// SOURCES.md rounds the rpm to 0.1). The group sizes, mean COF and their sample standard
/// deviations were computed independently with Python's `csv` and `statistics` modules on the
/// same file (1799 rows per step; means 0.1688460, 0.1927910, 0.2038785, 0.2090591; sd 0.0079647,
/// 0.0058827, 0.0055818, 0.0046784).
#[test]
fn the_real_tribometer_log_gives_four_steps_at_their_speeds() {
    let Some(path) = shared(
        "realdata/friction/013_FX2_316SS_0.25in_Rotary_3N_4tests_75-300mm-s_6-15mm-radius_3min-each.csv",
    ) else {
        return;
    };
    let s = spec(
        "file = 'x.csv'\nspeed_column = 'Rotary.Velocity (rpm)'\nspeed_unit = 'rpm'\n\
         coefficient_column = 'DAQ.COF ()'\ngroup_by = 'Step'\n\
         track_radius_m = { '4' = 0.006, '7' = 0.009, '10' = 0.012, '13' = 0.015 }",
    );
    let c = rig::read(&path, &s).unwrap();
    let rpm = [119.2, 159.1, 179.0, 191.0];
    let radius = [0.006, 0.009, 0.012, 0.015];
    let mean = [0.1688460, 0.1927910, 0.2038785, 0.2090591];
    let sd = [0.0079647, 0.0058827, 0.0055818, 0.0046784];
    assert_eq!(c.points.len(), 4);
    for (i, p) in c.points.iter().enumerate() {
        let v = rpm[i] * std::f64::consts::TAU * radius[i] / 60.0;
        println!(
            "step {:?}: {} rows, v {:.5} m/s (expected {v:.5}), COF {:.5} ± {:.5}",
            p.group, p.rows, p.speed_m_per_s, p.coefficient, p.sd
        );
        assert_eq!(p.rows, 1799);
        assert!((p.speed_m_per_s / v - 1.0).abs() < 3e-3, "step {i}");
        assert!((p.coefficient - mean[i]).abs() < 1e-6, "step {i}");
        assert!((p.sd - sd[i]).abs() < 1e-6, "step {i}");
    }
    // One radius for a file whose steps ran at four: the job must say which; a missing group's
    // radius is named with its line.
    let partial = spec(
        "file = 'x.csv'\nspeed_column = 'Rotary.Velocity (rpm)'\nspeed_unit = 'rpm'\n\
         coefficient_column = 'DAQ.COF ()'\ngroup_by = 'Step'\n\
         track_radius_m = { '4' = 0.006, '7' = 0.009 }",
    );
    let e = rig::read(&path, &partial).unwrap_err().to_string();
    assert!(
        e.contains("group '10'") && e.contains("track_radius_m"),
        "{e}"
    );
}

/// The shipped main job with `[fit.priors]` appended (paths made absolute), written to `dir`.
fn main_job_with(dir: &std::path::Path, priors: &str) -> LoadedJob {
    let text = std::fs::read_to_string(root().join("fits/reversal.toml"))
        .unwrap()
        .replace(
            "\"../data/",
            &format!("\"{}/", root().join("data").display()),
        )
        .replace("reports_dir = \"../reports\"", "");
    let path = write(dir, "job.toml", &format!("{text}\n{priors}"));
    LoadedJob::load(&path).unwrap()
}

/// A job's priors reach each candidate's cost problem: θ_c's prior only the shoulder candidate's,
/// the rig curve every candidate that frees a friction coefficient; the cost at a point is the
/// likelihood's plus the prior's nats there; the Laplace curvature adds the prior's information,
/// so a prior far sharper than the recording pins k1's 1σ to the prior's sd (the sandwich
/// `(F + H)⁻¹(V + H)(F + H)⁻¹` → `H⁻¹` as `H` dominates), and model choice's `tr(F⁻¹V)` stays the
/// likelihood's own.
#[test]
fn a_jobs_priors_enter_the_cost_and_the_curvature() {
    let dir = temp_dir("priors_job");
    write(
        dir.path(),
        "rig.csv",
        "v,mu\n0.01,0.5\n0.02,0.45\n0.05,0.40\n",
    );
    let plain = main_job_with(dir.path(), "");
    let k1_true = plain.truth[&ParamId::K1];
    let priors = format!(
        "[fit.priors]\n\
         theta_c = {{ normal = {{ mean = 0.08, sd = 0.01 }} }}\n\
         k1 = {{ lognormal = {{ median = {k1_true}, sd_log = 0.0005 }} }}\n\
         [fit.priors.friction_curve]\n\
         file = 'rig.csv'\nspeed_column = 'v'\ncoefficient_column = 'mu'\nsd = 0.05\n"
    );
    let job = main_job_with(dir.path(), &priors);
    assert_eq!(job.rig_curve.as_ref().unwrap().points.len(), 3);
    // The settings the result records read back the same.
    let text = toml::to_string_pretty(&job.job.fit).unwrap();
    let back: wiperlab::job::FitSection = toml::from_str(&text).unwrap();
    assert_eq!(back, job.job.fit, "{text}");
    let cands = job.candidates();
    let shoulder = *cands.iter().find(|c| c.shoulder).unwrap();
    let blade = *cands.iter().find(|c| c.name() == "blade2dof").unwrap();
    let p = wiperlab::search::problem_for(&job, shoulder).unwrap();
    assert_eq!(p.prior.terms.len(), 5);
    let q = wiperlab::search::problem_for(&job, blade).unwrap();
    assert_eq!(q.prior.terms.len(), 4);
    let q0 = wiperlab::search::problem_for(&plain, blade).unwrap();
    assert!(q0.prior.is_empty());
    let u = vec![0.5; q.free.len()];
    let expected = q0.cost_at(&u) + q.prior.nats(&q.params_at(&u));
    assert!(
        (q.cost_at(&u) - expected).abs() < 1e-9,
        "{} vs {expected}",
        q.cost_at(&u)
    );
    // At the truth, k1 at its prior's median; its coordinate's 1σ in u: sd_log / ln(0.15/0.005).
    let u: Vec<f64> = (q.free.iter())
        .map(|f| f.u_of(job.truth[&f.name]))
        .collect();
    let k1 = q.free.iter().position(|f| f.name == ParamId::K1).unwrap();
    let with = wiperlab::search::evidence::at_fit(&q, &u).unwrap();
    let without = wiperlab::search::evidence::at_fit(&q0, &u).unwrap();
    let prior_sigma_u = 0.0005 / 30f64.ln();
    println!(
        "k1 σ_u: {:.3e} with the prior, {:.3e} without, prior alone {prior_sigma_u:.3e}",
        with.sigma_u[k1], without.sigma_u[k1]
    );
    assert!(without.sigma_u[k1] > 10.0 * prior_sigma_u);
    assert!((with.sigma_u[k1] / prior_sigma_u - 1.0).abs() < 0.02);
    assert_eq!(
        with.nll.effective_parameters,
        without.nll.effective_parameters
    );
}

/// The shipped sample's true blade with a shoulder, so that θ_c can be freed.
fn blade() -> BladeParams {
    let mut p = common::true_blade();
    p.shoulder = Some(wiperlab::model::Shoulder {
        contact_angle_rad: 0.1,
        k1_contact_nm_per_rad: 0.05,
    });
    p
}

fn priors(entries: &[(ParamId, ParamPrior)]) -> PriorsSection {
    PriorsSection {
        friction_curve: None,
        parameters: entries.iter().copied().collect(),
    }
}

/// Blade parameters at normalised coordinates `u` of `free` over `base`.
fn params_at(free: &[FreeParam], base: &BladeParams, u: &[f64]) -> BladeParams {
    let mut p = *base;
    for (f, ui) in free.iter().zip(u) {
        f.name.set(&mut p, f.value(*ui));
    }
    p
}

/// Second derivative of `f` at `u` along coordinate `k`, central differences of step `h`.
fn second(f: impl Fn(&[f64]) -> f64, u: &[f64], k: usize, h: f64) -> f64 {
    let at = |d: f64| {
        let mut v = u.to_vec();
        v[k] += d;
        f(&v)
    };
    (at(h) - 2.0 * at(0.0) + at(-h)) / (h * h)
}

/// The posterior of a quadratic likelihood `(θ − a)²/(2σ²)` times a normal prior `N(m, s²)` is
/// normal with the precision-weighted mean `(a/σ² + m/s²)/(1/σ² + 1/s²)` and variance
/// `1/(1/σ² + 1/s²)` (Gelman et al. 2013, BDA3 §2.5). Its mode is where the gradient of
/// likelihood plus prior vanishes; the ensemble sampler on [`Prior::log_posterior`] draws its
/// mean and sd, also with the likelihood tempered by `w` (which scales `1/σ²` by `w`).
#[test]
fn a_normal_prior_on_a_quadratic_likelihood_gives_the_precision_weighted_posterior() {
    let free = [FreeParam::new(ParamId::ThetaC, 0.0, 0.3)];
    let base = blade();
    let (a, sigma, m, s) = (0.12, 0.02, 0.08, 0.01);
    let prior = Prior::new(
        &priors(&[(ParamId::ThetaC, ParamPrior::Normal { mean: m, sd: s })]),
        None,
        &free,
    );
    let theta = |u: f64| free[0].value(u);
    let nll = |u: f64| (theta(u) - a).powi(2) / (2.0 * sigma * sigma);
    // The fit's cost: NLL plus the prior's nats.
    let cost = |u: &[f64]| nll(u[0]) + prior.nats(&params_at(&free, &base, u));
    for w in [1.0, 0.5] {
        let precision = w / (sigma * sigma) + 1.0 / (s * s);
        let mean = (w * a / (sigma * sigma) + m / (s * s)) / precision;
        // The mode of the tempered posterior: a Newton step from anywhere lands on it (the
        // log density is exactly quadratic in θ, and θ is linear in u).
        let u0 = [0.5];
        let h = 1e-5;
        let logp = |v: &[f64]| prior.log_posterior(cost(v), w, &free, &base, v);
        let g = (logp(&[u0[0] + h]) - logp(&[u0[0] - h])) / (2.0 * h);
        let hess = second(logp, &u0, 0, 1e-3);
        let mode = theta(u0[0] - g / hess);
        assert!((mode - mean).abs() < 1e-6, "w {w}: mode {mode} vs {mean}");
        let settings = wiperlab::posterior::EnsembleSettings {
            walkers: 16,
            steps: 3000,
            stretch: 2.0,
            seed: 3,
        };
        let start = wiperlab::posterior::ensemble::ball(&[0.3], 0.02, 16, 3);
        let chains = wiperlab::posterior::sample(logp, start, &settings, |_| true).unwrap();
        let draws: Vec<f64> = (chains.coordinate(0, 500).concat().iter())
            .map(|&u| theta(u))
            .collect();
        let n = draws.len() as f64;
        let mu = draws.iter().sum::<f64>() / n;
        let sd = (draws.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / n).sqrt();
        let sd_closed = precision.sqrt().recip();
        // 40,000 correlated draws (τ ≈ 10 steps here): the mean's standard error is about
        // sd·√(τ/n) ≈ 0.016 sd; 0.1 sd is six of them.
        assert!(
            (mu - mean).abs() < 0.1 * sd_closed,
            "w {w}: mean {mu} vs {mean}"
        );
        assert!(
            (sd / sd_closed - 1.0).abs() < 0.1,
            "w {w}: sd {sd} vs {sd_closed}"
        );
    }
}

/// A log-normal prior is a density in ln θ whatever scale the search uses: with a flat
/// likelihood the sampler's draws of ln k1 have mean ln median and sd sd_log on a log-scaled
/// coordinate (no Jacobian) and on a linear one (where [`Prior::log_jacobian_u`] supplies
/// `−ln θ`; without it the draws would follow θ·lognormal, whose log-mean is
/// `ln median + sd_log²`, 0.09 higher).
#[test]
fn a_lognormal_prior_is_sampled_with_its_own_density_on_either_scale() {
    let base = blade();
    let (median, sd_log) = (0.03, 0.3);
    for free in [
        [FreeParam::new(ParamId::K1, 0.005, 0.15)],
        [FreeParam::new(ParamId::K1, 0.005, 0.045)],
    ] {
        let prior = Prior::new(
            &priors(&[(ParamId::K1, ParamPrior::Lognormal { median, sd_log })]),
            None,
            &free,
        );
        // The bounds cut the prior at about ±1.8 sd_log (linear) or beyond (log): compare
        // with the truncated normal's moments in ln θ.
        let [lo, hi] = [free[0].lower.ln(), free[0].upper.ln()].map(|x| (x - median.ln()) / sd_log);
        let phi = |x: f64| (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt();
        let cdf = |x: f64| 0.5 * (1.0 + statrs::function::erf::erf(x / 2f64.sqrt()));
        let z = cdf(hi) - cdf(lo);
        let mean_closed = median.ln() + sd_log * (phi(lo) - phi(hi)) / z;
        let var_closed = sd_log.powi(2)
            * (1.0 + (lo * phi(lo) - hi * phi(hi)) / z - ((phi(lo) - phi(hi)) / z).powi(2));
        let logp = |v: &[f64]| {
            if !(0.0..=1.0).contains(&v[0]) {
                return f64::NEG_INFINITY;
            }
            let cost = prior.nats(&params_at(&free, &base, v));
            prior.log_posterior(cost, 0.7, &free, &base, v)
        };
        let settings = wiperlab::posterior::EnsembleSettings {
            walkers: 16,
            steps: 3000,
            stretch: 2.0,
            seed: 5,
        };
        let start = wiperlab::posterior::ensemble::ball(&[free[0].u_of(median)], 0.01, 16, 5);
        let chains = wiperlab::posterior::sample(logp, start, &settings, |_| true).unwrap();
        let logs: Vec<f64> = (chains.coordinate(0, 500).concat().iter())
            .map(|&u| free[0].value(u).ln())
            .collect();
        let n = logs.len() as f64;
        let mu = logs.iter().sum::<f64>() / n;
        let var = logs.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / n;
        assert!(
            (mu - mean_closed).abs() < 0.1 * sd_log,
            "{:?}: {mu} vs {mean_closed}",
            free[0]
        );
        assert!(
            (var.sqrt() / var_closed.sqrt() - 1.0).abs() < 0.1,
            "{var} vs {var_closed}"
        );
    }
}

/// A prior may name a coefficient that a law of `[fit] laws` adds (D of `exponential_viscous`,
/// bounded by default from 0): accepted with that law listed, refused without it, and a
/// log-normal prior on it refused since its bounds include 0.
#[test]
fn a_prior_on_a_listed_laws_coefficient() {
    let dir = temp_dir("priors_laws");
    let text = std::fs::read_to_string(root().join("fits/reversal.toml"))
        .unwrap()
        .replace(
            "\"../data/",
            &format!("\"{}/", root().join("data").display()),
        )
        .replace("reports_dir = \"../reports\"", "");
    let load = |laws: &str, prior: &str| {
        let job = text.replace("[fit.uncertainty]", &format!("{laws}\n[fit.uncertainty]"));
        let path = write(
            dir.path(),
            "job.toml",
            &format!("{job}\n[fit.priors]\n{prior}\n"),
        );
        LoadedJob::load(&path)
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    let laws = "laws = [\"exponential\", \"exponential_viscous\"]";
    let normal = "D = { normal = { mean = 0.0, sd = 0.2 } }";
    assert_eq!(load(laws, normal), Ok(()));
    let e = load("", normal).unwrap_err();
    assert!(e.contains("does not fit 'D'"), "{e}");
    let e = load(laws, "D = { lognormal = { median = 0.1, sd_log = 0.5 } }").unwrap_err();
    assert!(e.contains("log-normal") && e.contains("<= 0"), "{e}");
}

/// With several `[fit] laws`, a prior on one law's coefficient applies to the candidates whose law
/// has that coefficient and is left out of the others, without an error: D's prior only to
/// `exponential_viscous`, B's to the two exponential laws and not to Stribeck's (which fits v_s in
/// B's place), v_s's only to Stribeck's, and k1's (every candidate fits k1) to all. Checked on the
/// cost problems a fit builds for the main job's `blade2dof` with each law; D's term at D = 1 s/m
/// (u = 0.5 of its default bounds [0, 2] s/m, a linear scale) has the closed form
/// z = (1 − 0)/0.2 = 5.
#[test]
fn a_prior_on_one_laws_coefficient_applies_to_that_laws_candidates() {
    let dir = temp_dir("priors_per_law");
    let text = std::fs::read_to_string(root().join("fits/reversal.toml"))
        .unwrap()
        .replace(
            "\"../data/",
            &format!("\"{}/", root().join("data").display()),
        )
        .replace("reports_dir = \"../reports\"", "")
        .replace(
            "[fit.uncertainty]",
            "laws = [\"exponential\", \"exponential_viscous\", \"stribeck\"]\n[fit.uncertainty]",
        );
    let priors = "[fit.priors]\n\
                  D = { normal = { mean = 0.0, sd = 0.2 } }\n\
                  B = { normal = { mean = 70.0, sd = 20.0 } }\n\
                  v_s = { lognormal = { median = 0.014, sd_log = 0.5 } }\n\
                  k1 = { lognormal = { median = 0.03, sd_log = 0.5 } }\n";
    let path = write(dir.path(), "job.toml", &format!("{text}\n{priors}"));
    let job = LoadedJob::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let expected = [
        ("blade2dof@exponential", vec![ParamId::B, ParamId::K1]),
        (
            "blade2dof@exponential_viscous",
            vec![ParamId::B, ParamId::D, ParamId::K1],
        ),
        ("blade2dof@stribeck", vec![ParamId::Vs, ParamId::K1]),
    ];
    let cands = job.candidates();
    for (name, ids) in expected {
        let c = *cands
            .iter()
            .find(|c| c.name() == name)
            .unwrap_or_else(|| panic!("no candidate {name} in {cands:?}"));
        let p = wiperlab::search::problem_for(&job, c).unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut got: Vec<ParamId> = (p.prior.terms.iter())
            .map(|t| match t {
                PriorTerm::Parameter { id, .. } => *id,
                PriorTerm::Rig(_) => panic!("no rig curve in this job"),
            })
            .collect();
        got.sort();
        let mut want = ids.clone();
        want.sort();
        assert_eq!(got, want, "{name}");
        // Every term reads a parameter the candidate frees.
        for id in &got {
            assert!(p.free.iter().any(|f| f.name == *id), "{name}: {id}");
        }
        if p.free.iter().any(|f| f.name == ParamId::D) {
            let at = p.params_at(&vec![0.5; p.free.len()]);
            assert_eq!(at.friction.name(), "exponential_viscous", "{name}");
            assert!(
                (ParamId::D.get(&at).unwrap() - 1.0).abs() < 1e-12,
                "D at u = 0.5"
            );
            let d = p
                .prior
                .terms
                .iter()
                .find(|t| matches!(t, PriorTerm::Parameter { id, .. } if *id == ParamId::D));
            let z = d.expect("D's term").z(&at);
            assert!((z - 5.0).abs() < 1e-12, "{name}: z = {z}");
        }
    }
}
