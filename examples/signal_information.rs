//! How much each tracked signal, and the signals together, tell about the freed parameters: the
//! Fisher information of a Whittle likelihood at the truth of a job with a `[truth]`, for each
//! signal alone (the univariate Whittle likelihood the fit reads, with `[spectrum] signal`) and for
//! the signals together (the multivariate Whittle likelihood of their Welch cross-spectral matrix).
//!
//! Per band and interior bin `k` the expected cross-spectral matrix is `S_k = S_sim,k + N`: the
//! simulation's Welch cross-spectra ([`WelchPlan::cross_spectra`]) plus the tracking noise's, and
//! the information is [`MultivariateWhittle::fisher`]'s, `(ν/2)/φ · Σ_k Re tr(S_k⁻¹ ∂_i S_k S_k⁻¹ ∂_j S_k)`.
//! For one signal it is the fit's own Gauss–Newton information `(α/φ)·Σ_k (∂ln S_k)²`
//! (`src/search/evidence.rs`). Derivatives are central differences of step [`FISHER_STEP_U`] in the
//! search's normalised coordinates. A row "sum, no cross-spectra" adds the signals' own
//! informations, as if their ordinates were independent.
//!
//! The tracking noise is read as white and independent between the tracked coordinates, each with
//! its own σ̂ from the recording (`1.4826·MAD(Δ²x)/√6`, as the fit estimates its signal's): each
//! signal's noise and the noise two signals share (tip − head y and head y share the head's y)
//! follow from which coordinates they difference. The simulated signals miss the samples the
//! recording misses, short gaps filled as the fit fills them ([`WelchPlan::cross_spectra_gappy`]).
//! The sandwich's `V` is the variance of the score over noise replicates of the truth's signals,
//! as the fit's sandwich draws them.
//!
//! Prints, per configuration, each parameter's 1σ from `F⁻¹` and from the sandwich (normalised
//! units, and relative to the truth's value), and how much narrower than the first signal's alone.
//!
//! ```sh
//! cargo run --release --example signal_information -- JOB.toml --model blade2dof+shoulder \
//!     --signals tip_rel_x,head_y,tip_rel_y
//! ```

use clap::Parser;
#[path = "common/campaign.rs"]
mod campaign;
use campaign::{JobSource, truth_u};
use nalgebra::{Complex, DMatrix};
use std::path::PathBuf;
use wiperlab::job::{Candidate, LoadedJob};
use wiperlab::likelihood::covariance::sample_covariance;
use wiperlab::likelihood::multivariate::MultivariateWhittle;
use wiperlab::likelihood::{interior_bin, tracking_noise_sigma};
use wiperlab::search::evidence::{FISHER_STEP_U, NOISE_REPLICATES, NOISE_SEED};
use wiperlab::search::{SpectralProblem, problem_for};
use wiperlab::spectrum::features::SignalKind;
use wiperlab::spectrum::welch::{CrossSpectra, WelchConfig, WelchPlan};
use wiperlab::trace::Role;

#[derive(Parser)]
struct Args {
    #[command(flatten)]
    source: JobSource,
    /// The signals, the fit's own first.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "tip_rel_x,head_y,tip_rel_y"
    )]
    signals: Vec<String>,
    /// Append one row per configuration, spread and parameter to this CSV (`job,model,signals,
    /// spread,parameter,truth,sigma_u,relative_sigma`; a header when the file is new).
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Noise replicates for the sandwich's variability.
    #[arg(long, default_value_t = NOISE_REPLICATES)]
    replicates: usize,
}

type Fallible<T> = Result<T, Box<dyn std::error::Error>>;

/// One band's cross-spectral matrices, one per bin (row-major entries).
type BandMatrices = Vec<Vec<Complex<f64>>>;

fn main() -> Fallible<()> {
    let args = Args::parse();
    let jobs = args.source.paths()?;
    for path in &jobs {
        // A truth on the edge of contact loss may not simulate at a displaced point.
        if let Err(e) = information(&args, path) {
            let e = e.to_string();
            let short: String = e.chars().take(300).collect();
            println!("{}: skipped: {short}", path.display());
        }
    }
    Ok(())
}

/// The information table of one job (see the module docs).
fn information(args: &Args, path: &std::path::Path) -> Fallible<()> {
    let job = LoadedJob::load(path)?;
    let candidate = args.source.candidate(&job, path)?;
    let problem = problem_for(&job, candidate)?;
    let kinds: Vec<SignalKind> = args
        .signals
        .iter()
        .map(|s| s.parse::<SignalKind>())
        .collect::<Result<_, _>>()?;
    let truth = truth_u(&job, &problem)?;
    let (sigma, missing) = recording_noise(&job, &kinds)?;
    let noise = noise_matrix(&kinds, &sigma, problem.fs_hz);
    let bands = band_bins(&problem)?;
    let signals_at = |u: &[f64]| -> Fallible<Vec<Vec<f64>>> {
        let trace = problem.simulate(&problem.params_at(u))?.to_trace();
        Ok(kinds
            .iter()
            .map(|k| k.extract(&trace))
            .collect::<Result<_, _>>()?)
    };
    let spectra_of = |signals: &[Vec<f64>]| {
        cross_spectra(signals, &missing, &bands, problem.fs_hz, problem.max_fill)
    };
    let p = kinds.len();
    let clean = signals_at(&truth)?;
    let spectra = Spectra {
        centre: spectra_of(&clean)?,
        derivs: derivatives(&truth, |u| spectra_of(&signals_at(u)?))?,
        // The truth's signals plus fresh white noise on each tracked coordinate, as the fit's
        // sandwich draws them.
        replicates: (0..args.replicates)
            .map(|r| spectra_of(&with_noise(&clean, &kinds, &sigma, r as u64)))
            .collect::<Fallible<_>>()?,
        noise,
        p,
    };
    // Every band must hold enough segments for the signals together (else no row is written).
    for (c, (cfg, bins)) in spectra.centre.iter().zip(&bands) {
        MultivariateWhittle::new(cfg, c.n_segments, bins.len(), p)?;
    }
    println!(
        "{}: candidate {candidate}, σ̂ of head x, head y, tip x, tip y {:.2e}, {:.2e}, {:.2e}, \
         {:.2e} m, signals {}",
        path.display(),
        sigma[0],
        sigma[1],
        sigma[2],
        sigma[3],
        args.signals.join(", ")
    );
    let mut configs: Vec<Vec<usize>> = (0..p).map(|i| vec![i]).collect();
    if p > 1 {
        configs.push((0..p).collect());
    }
    let k = truth.len();
    let (mut first, mut first_sandwich) = (None, None);
    let mut single: Vec<(DMatrix<f64>, Vec<Vec<f64>>)> = Vec::new();
    for sel in configs {
        let (f, scores) = spectra.information_of(&sel, &bands, k)?;
        let label: Vec<&str> = sel.iter().map(|&i| args.signals[i].as_str()).collect();
        let mut rows = vec![(label.join(" + "), f.clone(), scores.clone())];
        if sel.len() == 1 {
            single.push((f, scores));
        } else {
            // The signals' own likelihoods summed, as if their ordinates were independent.
            let f_sum = single
                .iter()
                .fold(DMatrix::<f64>::zeros(k, k), |a, b| a + &b.0);
            let s_sum: Vec<Vec<f64>> = (0..spectra.replicates.len())
                .map(|r| {
                    (0..k)
                        .map(|i| single.iter().map(|s| s.1[r][i]).sum())
                        .collect()
                })
                .collect();
            rows.push((
                format!("{} (sum, no cross-spectra)", label.join(" + ")),
                f_sum,
                s_sum,
            ));
        }
        for (label, f, scores) in rows {
            let Some(inv) = f.clone().try_inverse() else {
                println!("  {label}: singular information");
                continue;
            };
            let sandwich = &inv * sample_covariance(&scores) * &inv;
            for (what, cov, first) in [
                ("Fisher", &inv, &mut first),
                ("sandwich", &sandwich, &mut first_sandwich),
            ] {
                let sigma = report(
                    &format!("{label} [{what}]"),
                    cov,
                    &problem.free,
                    &truth,
                    first,
                );
                if let Some(csv) = &args.csv {
                    append_csv(
                        csv,
                        path,
                        &candidate,
                        (&label, what),
                        &problem.free,
                        &truth,
                        &sigma,
                    )?;
                }
            }
        }
    }
    Ok(())
}

/// Each tracked coordinate's white-noise σ̂ in the job's recording (head x, head y, tip x, tip y;
/// [`tracking_noise_sigma`], m) and where each of the signals `kinds` is missing.
fn recording_noise(job: &LoadedJob, kinds: &[SignalKind]) -> Fallible<(Vec<f64>, Vec<Vec<bool>>)> {
    let rec = job
        .job
        .recording
        .as_ref()
        .ok_or("a job without a recording")?;
    let trace = wiperlab::import::read_trace(&job.recording_path, &rec.import)?;
    let (head, tip) = (
        trace.role(Role::Head).ok_or("no head point")?,
        trace.role(Role::Tip).ok_or("no tip point")?,
    );
    let sigma: Vec<f64> = [&head.x_m, &head.y_m, &tip.x_m, &tip.y_m]
        .iter()
        .map(|c| tracking_noise_sigma(c))
        .collect::<Result<_, _>>()?;
    let missing = kinds
        .iter()
        .map(|k| Ok(k.extract(&trace)?.iter().map(|v| !v.is_finite()).collect()))
        .collect::<Fallible<_>>()?;
    Ok((sigma, missing))
}

/// The one-sided cross-spectral density of white tracking noise of `sigma` (per coordinate) in
/// the signals `kinds` sampled at `fs_hz`: `2·Cov/fs`, row-major `p × p`.
fn noise_matrix(kinds: &[SignalKind], sigma: &[f64], fs_hz: f64) -> Vec<Complex<f64>> {
    let p = kinds.len();
    (0..p * p)
        .map(|ab| {
            let (ca, cb) = (kinds[ab / p].coordinates(), kinds[ab % p].coordinates());
            let cov: f64 = (0..4).map(|c| ca[c] * cb[c] * sigma[c] * sigma[c]).sum();
            Complex::new(2.0 * cov / fs_hz, 0.0)
        })
        .collect()
}

/// Each band's Welch settings and its interior bins inside its range (indices of the FFT bins).
fn band_bins(problem: &SpectralProblem) -> Fallible<Vec<(WelchConfig, Vec<usize>)>> {
    problem
        .bands
        .iter()
        .map(|b| {
            let cfg = b.welch_config()?;
            let bins = (0..cfg.n_freqs())
                .filter(|&k| {
                    let f = k as f64 * problem.fs_hz / cfg.nfft as f64;
                    f >= b.range_hz[0] && f <= b.range_hz[1] && interior_bin(f, problem.fs_hz, &cfg)
                })
                .collect();
            Ok((cfg, bins))
        })
        .collect()
}

/// Every band's cross-spectra of `signals` with the samples `missing` (per signal) missing, short
/// gaps filled as the fit fills them.
fn cross_spectra(
    signals: &[Vec<f64>],
    missing: &[Vec<bool>],
    bands: &[(WelchConfig, Vec<usize>)],
    fs_hz: f64,
    max_fill: usize,
) -> Fallible<Vec<CrossSpectra>> {
    let masked: Vec<Vec<f64>> = signals
        .iter()
        .zip(missing)
        .map(|(x, m)| {
            x.iter()
                .zip(m)
                .map(|(v, m)| if *m { f64::NAN } else { *v })
                .collect()
        })
        .collect();
    let refs: Vec<&[f64]> = masked.iter().map(Vec::as_slice).collect();
    bands
        .iter()
        .map(|(cfg, bins)| {
            Ok(WelchPlan::new(*cfg)?.cross_spectra_gappy(&refs, fs_hz, bins, max_fill)?)
        })
        .collect()
}

/// The truth's cross-spectra of all `p` signals, their derivatives, the noise replicates' and the
/// noise's own.
struct Spectra {
    centre: Vec<CrossSpectra>,
    /// `[parameter][band]`.
    derivs: Vec<Vec<BandMatrices>>,
    /// `[replicate][band]`.
    replicates: Vec<Vec<CrossSpectra>>,
    noise: Vec<Complex<f64>>,
    p: usize,
}

impl Spectra {
    /// The Fisher information (`k × k`) of the signals `sel` read together, and the score of each
    /// noise replicate.
    fn information_of(
        &self,
        sel: &[usize],
        bands: &[(WelchConfig, Vec<usize>)],
        k: usize,
    ) -> Fallible<(DMatrix<f64>, Vec<Vec<f64>>)> {
        let p = self.p;
        // The entries of the selected signals, row-major.
        let pick = |m: &[Complex<f64>]| -> Vec<Complex<f64>> {
            sel.iter()
                .flat_map(|&a| sel.iter().map(move |&b| m[a * p + b]))
                .collect()
        };
        let mut f = DMatrix::<f64>::zeros(k, k);
        let mut scores = vec![vec![0.0; k]; self.replicates.len()];
        for (band, (c, (cfg, bins))) in self.centre.iter().zip(bands).enumerate() {
            let model: BandMatrices = c
                .matrices
                .iter()
                .map(|m| {
                    pick(
                        &m.iter()
                            .zip(&self.noise)
                            .map(|(s, n)| s + n)
                            .collect::<Vec<_>>(),
                    )
                })
                .collect();
            let d: Vec<BandMatrices> = self
                .derivs
                .iter()
                .map(|di| di[band].iter().map(|m| pick(m)).collect())
                .collect();
            let w = MultivariateWhittle::new(cfg, c.n_segments, bins.len(), sel.len())?;
            f += w.fisher(&model, &d)?;
            for (score, rep) in scores.iter_mut().zip(&self.replicates) {
                let measured: BandMatrices = rep[band].matrices.iter().map(|m| pick(m)).collect();
                for (s, g) in score.iter_mut().zip(w.score(&measured, &model, &d)?) {
                    *s += g;
                }
            }
        }
        Ok((f, scores))
    }
}

/// The central differences, step [`FISHER_STEP_U`] (one-sided at a bound), of the cross-spectral
/// matrices `spectra_at` gives: `[parameter][band][bin]`.
fn derivatives(
    u0: &[f64],
    spectra_at: impl Fn(&[f64]) -> Fallible<Vec<CrossSpectra>>,
) -> Fallible<Vec<Vec<BandMatrices>>> {
    (0..u0.len())
        .map(|i| {
            let (lo, hi) = (
                (u0[i] - FISHER_STEP_U).max(0.0),
                (u0[i] + FISHER_STEP_U).min(1.0),
            );
            let mut u = u0.to_vec();
            u[i] = lo;
            let a = spectra_at(&u)?;
            u[i] = hi;
            let b = spectra_at(&u)?;
            Ok(a.iter()
                .zip(&b)
                .map(|(a, b)| {
                    a.matrices
                        .iter()
                        .zip(&b.matrices)
                        .map(|(ma, mb)| {
                            ma.iter()
                                .zip(mb)
                                .map(|(x, y)| (y - x) / (hi - lo))
                                .collect()
                        })
                        .collect()
                })
                .collect())
        })
        .collect()
}

/// `clean` (the signals `kinds`) plus white noise of `sigma_m[c]` on each tracked coordinate `c`
/// (head x, head y, tip x, tip y), drawn from seed [`NOISE_SEED`]` + r`: a signal differencing
/// two coordinates gets both their noises.
fn with_noise(clean: &[Vec<f64>], kinds: &[SignalKind], sigma_m: &[f64], r: u64) -> Vec<Vec<f64>> {
    use rand::SeedableRng;
    use rand_distr::Distribution;
    let mut rng = rand::rngs::StdRng::seed_from_u64(NOISE_SEED.wrapping_add(r));
    let n = clean.first().map_or(0, Vec::len);
    let coords: Vec<Vec<f64>> = sigma_m
        .iter()
        .map(|&s| {
            let normal = rand_distr::Normal::new(0.0, s).expect("a finite σ");
            (0..n).map(|_| normal.sample(&mut rng)).collect()
        })
        .collect();
    clean
        .iter()
        .zip(kinds)
        .map(|(x, &kind)| {
            let c = kind.coordinates();
            x.iter()
                .enumerate()
                .map(|(t, v)| v + (0..4).map(|j| c[j] * coords[j][t]).sum::<f64>())
                .collect()
        })
        .collect()
}

/// One configuration's rows of the CSV (see [`Args::csv`]).
fn append_csv(
    path: &std::path::Path,
    job: &std::path::Path,
    candidate: &Candidate,
    (label, what): (&str, &str),
    free: &[wiperlab::job::FreeParam],
    truth: &[f64],
    sigma: &[f64],
) -> Fallible<()> {
    let new = !path.exists();
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)?;
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(file);
    if new {
        w.write_record([
            "job",
            "model",
            "signals",
            "spread",
            "parameter",
            "truth",
            "sigma_u",
            "relative_sigma",
        ])?;
    }
    let name = job
        .file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned());
    for ((fp, u), s) in free.iter().zip(truth).zip(sigma) {
        w.write_record([
            name.clone(),
            candidate.to_string(),
            label.to_string(),
            what.to_string(),
            fp.name.to_string(),
            format!("{:.6e}", fp.value(*u)),
            format!("{s:.4e}"),
            format!("{:.4e}", relative(fp, *u, *s)),
        ])?;
    }
    w.flush()?;
    Ok(())
}

/// The 1σ `s` (normalised) at `u` as a fraction of the value: half the span of `u ± s` (clipped to
/// the box) over the value.
fn relative(fp: &wiperlab::job::FreeParam, u: f64, s: f64) -> f64 {
    (fp.value((u + s).min(1.0)) - fp.value((u - s).max(0.0))) / (2.0 * fp.value(u))
}

/// Prints each parameter's 1σ from the covariance `cov` at `truth` (normalised units and relative
/// to the value), and how much narrower than `first`'s (the first row's of its kind, which this
/// sets). Returns the 1σ.
fn report(
    label: &str,
    cov: &DMatrix<f64>,
    free: &[wiperlab::job::FreeParam],
    truth: &[f64],
    first: &mut Option<Vec<f64>>,
) -> Vec<f64> {
    let sigma: Vec<f64> = (0..truth.len())
        .map(|i| cov[(i, i)].max(0.0).sqrt())
        .collect();
    let cells: Vec<String> = free
        .iter()
        .zip(&sigma)
        .zip(truth)
        .enumerate()
        .map(|(i, ((fp, s), u))| {
            let rel = relative(fp, *u, *s);
            let ratio = first
                .as_ref()
                .map(|f0| format!(", {:.2}× narrower", f0[i] / s))
                .unwrap_or_default();
            format!("{} ±{s:.2e} u (±{:.2} %{ratio})", fp.name, 100.0 * rel)
        })
        .collect();
    println!("  {label}: {}", cells.join("; "));
    if first.is_none() {
        *first = Some(sigma.clone());
    }
    sigma
}
