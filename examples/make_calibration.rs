//! Writes a simulation-based calibration set: recordings of blades drawn from a stated prior,
//! filmed by cameras drawn from a stated range, with their truths, a conditions table and the
//! campaign that fits them with the main job (`fits/reversal.toml`).
//!
//! ```sh
//! cargo run --release --example make_calibration -- --set calibration
//! cargo run --release --example make_calibration -- --set development
//! ```
//!
//! `--set departures` draws shoulder-free blades from the same prior from seeds 950,000,000 + i,
//! each recorded with one departure from the fitted model, cycling through
//! [`Departure::ALL`] (default 2 of each): AR(1) tracking noise, tracks smoothed by a 5-frame
//! median (DeepLabCut's `filterpredictions` default), a viscous term in the friction law, a
//! Stribeck law with a shape exponent, and a drive whose speed has a second harmonic; it writes
//! `campaigns/calibration_departures.toml`, whose table scores the friction law as a curve.
//!
//! `--set calibration` draws from seeds 930,000,000 + i and writes `campaigns/calibration.toml`;
//! `--set development` from seeds 710,000,000 + i and writes
//! `campaigns/calibration_development.toml` (i = 0, 1, …: the two sets never share a seed, and
//! every hyperparameter of the estimator is to be chosen on the development set only). `--out DIR`
//! (default `data/calibration/<set>/`) receives:
//! - `recordings/<id>_xypts.csv`: DLTdv8 tracks (point 1 the head, point 2 the lip tip);
//! - `truths/<id>.json`: the model that made the recording, its fitted parameters' true values
//!   (`/params/A` …), the whole true blade, the camera and the motion's |θ| range;
//! - `truths/<id>.blade.toml`: the true blade as a blade file (with its `[shoulder]`);
//! - `blades/<id>.blade.toml`: the blade the fit knows, where it differs from the main job's (a
//!   head-only scene's preload), with the main job's nominal values of the fitted parameters;
//! - `conditions.csv`: per recording `t0_s`, `fps_hz`, `m_per_px`, `truth_json`, `blade_file`
//!   and labels.
//!
//! The composition (`--mix FREE,SHOULDER,HEAD`, default 60,30,10 for the calibration set and
//! 18,9,3 for the development set; `--count N` scales the default to N recordings):
//! shoulder-free blades (`blade2dof`), blades with a shoulder (`blade2dof+shoulder`) and head-only
//! scenes (`head1dof`: the neck and lip locked into one rigid link on the head's spring, see
//! `wiperlab::model::blade::LockedBlade`). The prior and the camera ranges are in `docs/campaigns.md`,
//! "The calibration campaign", and in `prior()` below; each draw that the model cannot simulate
//! (or whose shoulder the neck never reaches) is drawn again from the same stream, so the prior is
//! the box restricted to simulable scenes (the count of such redraws is in each truth file).
//!
//! Every recording is simulated with DOP853 at rtol 1e-10, atol 1e-12 over the default reversal
//! window (drive phase π/2 to 3π/2); the fits run DOPRI5 at rtol 1e-8 (1e-6 in the swarm), so no
//! model evaluation of a fit reproduces a recording.

#[path = "common/recording.rs"]
mod recording;

use clap::{Parser, ValueEnum};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use serde_json::json;
use std::f64::consts::TAU;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;
use wiperlab::model::{BladeParams, FrictionLaw, Shoulder};
use wiperlab::simulate::blade::{BladeSimulation, ModelKind};

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Set {
    /// Seeds 710,000,000 + i: where hyperparameters are chosen.
    Development,
    /// Seeds 930,000,000 + i: the set the calibration table reports.
    Calibration,
    /// Seeds 950,000,000 + i: shoulder-free blades recorded with departures from the model.
    Departures,
}

impl Set {
    fn seed_base(self) -> u64 {
        match self {
            Set::Development => 710_000_000,
            Set::Calibration => 930_000_000,
            Set::Departures => 950_000_000,
        }
    }
    /// The campaign's name (its file `campaigns/<name>.toml`, its table `reports/<name>/`).
    fn campaign(self) -> &'static str {
        match self {
            Set::Development => "calibration_development",
            Set::Calibration => "calibration",
            Set::Departures => "calibration_departures",
        }
    }
    fn dir(self) -> &'static str {
        match self {
            Set::Development => "development",
            Set::Calibration => "calibration",
            Set::Departures => "departures",
        }
    }
    fn id_prefix(self) -> &'static str {
        match self {
            Set::Development => "dev",
            Set::Calibration => "cal",
            Set::Departures => "dep",
        }
    }
    fn default_mix(self) -> [usize; 3] {
        match self {
            Set::Development => [18, 9, 3],
            Set::Calibration => [60, 30, 10],
            Set::Departures => [2 * Departure::ALL.len(), 0, 0],
        }
    }
}

/// Writes a simulation-based calibration set and its campaign.
#[derive(Debug, Parser)]
struct Args {
    /// Which set: its seeds, default size and campaign name.
    #[arg(long, value_enum)]
    set: Set,
    /// Output directory (default: data/calibration/<set>/ under the crate root).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Number of recordings, split as the set's default mix (60 % shoulder-free, 30 % shoulder,
    /// 10 % head-only).
    #[arg(long, conflicts_with = "mix")]
    count: Option<usize>,
    /// Numbers of shoulder-free, shoulder and head-only recordings, e.g. 60,30,10.
    #[arg(long, value_delimiter = ',')]
    mix: Option<Vec<usize>>,
}

/// The three kinds of scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scene {
    ShoulderFree,
    Shoulder,
    HeadOnly,
}

impl Scene {
    fn label(self) -> &'static str {
        match self {
            Scene::ShoulderFree => "shoulder_free",
            Scene::Shoulder => "shoulder",
            Scene::HeadOnly => "head_only",
        }
    }
    /// The model that makes the recording, as `[fit] models` names it.
    fn model(self) -> &'static str {
        match self {
            Scene::ShoulderFree => "blade2dof",
            Scene::Shoulder => "blade2dof+shoulder",
            Scene::HeadOnly => "head1dof",
        }
    }
    fn kind(self) -> ModelKind {
        match self {
            Scene::HeadOnly => ModelKind::Head1dof,
            _ => ModelKind::Blade2dof,
        }
    }
}

/// How a departures-set recording departs from the model the main job fits.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Departure {
    /// AR(1) tracking noise per coordinate, lag-one correlation `rho`, the camera's marginal σ.
    Ar1 { rho: f64 },
    /// White tracking noise, then each coordinate through a centred 5-frame median filter.
    MedianSmoothed,
    /// The friction law plus `D|v|`, `D` such that the term is `share` of μ_d at the median
    /// slip speed of the recording's own slipping samples.
    Viscous { share: f64 },
    /// Stribeck's law `C + A e^(−(|v|/v_s)^δ)` with `v_s = 1/B`.
    Stribeck { delta: f64 },
    /// The drive's speed with a second harmonic, a fraction `h` of its peak.
    Drive { h: f64 },
}

impl Departure {
    /// The kinds, in the order the set cycles through them.
    const ALL: [&'static str; 5] = ["ar1", "median_smoothed", "viscous", "stribeck", "drive"];

    fn label(self) -> &'static str {
        match self {
            Departure::Ar1 { .. } => "ar1",
            Departure::MedianSmoothed => "median_smoothed",
            Departure::Viscous { .. } => "viscous",
            Departure::Stribeck { .. } => "stribeck",
            Departure::Drive { .. } => "drive",
        }
    }

    /// Departure `i mod 5` with its size drawn from [`prior`]'s departure ranges.
    fn draw(i: usize, rng: &mut StdRng) -> Departure {
        match Departure::ALL[i % Departure::ALL.len()] {
            "ar1" => Departure::Ar1 {
                rho: uniform(rng, prior::AR1_RHO),
            },
            "median_smoothed" => Departure::MedianSmoothed,
            "viscous" => Departure::Viscous {
                share: uniform(rng, prior::VISCOUS_SHARE),
            },
            "stribeck" => Departure::Stribeck {
                delta: if rng.random_bool(0.5) {
                    uniform(rng, prior::STRIBECK_DELTA_LOW)
                } else {
                    uniform(rng, prior::STRIBECK_DELTA_HIGH)
                },
            },
            _ => Departure::Drive {
                h: uniform(rng, prior::DRIVE_HARMONIC)
                    * if rng.random_bool(0.5) { 1.0 } else { -1.0 },
            },
        }
    }

    /// The departure's size, for the truth file.
    fn size(self) -> serde_json::Value {
        match self {
            Departure::Ar1 { rho } => json!({ "rho": rho }),
            Departure::MedianSmoothed => json!({ "median_window_frames": prior::MEDIAN_WINDOW }),
            Departure::Viscous { share } => json!({ "share_of_mu_d_at_median_slip_speed": share }),
            Departure::Stribeck { delta } => json!({ "delta": delta }),
            Departure::Drive { h } => json!({ "drive_speed_harmonic": h }),
        }
    }
}

/// The prior box (docs/campaigns.md, "The calibration campaign", gives the physics behind each
/// range). Friction law μ = A e^{−B|v|} + C; neck stiffnesses through the neck's natural frequency
/// f = √(k/m_θ)/2π with the main job's blade's m_θ, so that a range of stiffness reads as a range
/// of frequency.
mod prior {
    /// A ~ U(0.3, 1.2).
    pub const A: [f64; 2] = [0.3, 1.2];
    /// B ~ log-U(12, 250) s/m.
    pub const B_S_PER_M: [f64; 2] = [12.0, 250.0];
    /// C ~ U(0.15, 0.8).
    pub const C: [f64; 2] = [0.15, 0.8];
    /// Neck frequency of a shoulder-free blade, log-U(280, 1100) Hz.
    pub const F_NECK_HZ: [f64; 2] = [280.0, 1100.0];
    /// Free-neck frequency of a blade with a shoulder, log-U(280, 600) Hz.
    pub const F_NECK_FREE_HZ: [f64; 2] = [280.0, 600.0];
    /// Neck frequency while touching the shoulder, log-U(max(1.5 f_free, 500), 1150) Hz.
    pub const F_CONTACT_HZ: [f64; 2] = [500.0, 1150.0];
    pub const CONTACT_OVER_FREE: f64 = 1.5;
    /// Contact angle θ_c ~ U(0.025, min(0.9·max|θ|, 0.19)) rad, max|θ| the motion of the same
    /// blade without shoulder.
    pub const THETA_C_RAD: [f64; 2] = [0.025, 0.19];
    pub const THETA_C_OF_REACH: f64 = 0.9;
    /// Preload of a head-only scene, log-U(2, 4) times the main job's blade's (its h_d scaled):
    /// the locked link keeps its tip on the glass through the reversal only when pressed harder.
    pub const LOCKED_PRELOAD_FACTOR: [f64; 2] = [2.0, 4.0];
    /// Neck stiffness of a head-only scene: k1 = r·N0·(l1 + l2), r ~ U(1.1, 2), so that the
    /// locked link stands upright (its static stiffness k1 − N0·(l1 + l2) is positive).
    pub const LOCKED_STIFFNESS_OVER_PRELOAD: [f64; 2] = [1.1, 2.0];
    /// Frame rate ~ U(5, 20) kHz, rounded to 1 Hz.
    pub const FPS_HZ: [f64; 2] = [5_000.0, 20_000.0];
    /// Image scale ~ log-U(8, 30) µm per pixel.
    pub const M_PER_PX: [f64; 2] = [8e-6, 30e-6];
    /// Tracking noise σ ~ U(0.05, 0.3) px, white, each coordinate.
    pub const NOISE_PX: [f64; 2] = [0.05, 0.3];
    /// Isolated lost frames: U{0, …, 12}, each losing the head, the tip or both.
    pub const LOST_SINGLE_MAX: usize = 12;
    /// Runs of lost frames (both points): U{0, …, 3} runs of U{2, …, 12} frames.
    pub const LOST_RUNS_MAX: usize = 3;
    pub const LOST_RUN_LEN: [usize; 2] = [2, 12];
    /// Redraws allowed before the generator gives up on a recording.
    pub const MAX_DRAWS: usize = 50;
    /// Departures set: AR(1) lag-one correlation ρ ~ U(0.3, 0.8) (sub-pixel fits and autotrackers
    /// correlate neighbouring frames).
    pub const AR1_RHO: [f64; 2] = [0.3, 0.8];
    /// Departures set: the median filter's window, frames (DeepLabCut `filterpredictions`).
    pub const MEDIAN_WINDOW: usize = 5;
    /// Departures set: the viscous term's share of μ_d at the median slip speed ~ U(3 %, 10 %).
    pub const VISCOUS_SHARE: [f64; 2] = [0.03, 0.10];
    /// Departures set: Stribeck's exponent δ ~ U(0.5, 0.8) or U(1.25, 2), equally likely (δ = 1
    /// is the exponential law the fit has).
    pub const STRIBECK_DELTA_LOW: [f64; 2] = [0.5, 0.8];
    pub const STRIBECK_DELTA_HIGH: [f64; 2] = [1.25, 2.0];
    /// Departures set: the drive speed's second harmonic |h| ~ U(2 %, 5 %) of the peak, either
    /// sign.
    pub const DRIVE_HARMONIC: [f64; 2] = [0.02, 0.05];
}

fn uniform(rng: &mut StdRng, r: [f64; 2]) -> f64 {
    rng.random_range(r[0]..r[1])
}

fn log_uniform(rng: &mut StdRng, r: [f64; 2]) -> f64 {
    rng.random_range(r[0].ln()..r[1].ln()).exp()
}

/// Stiffness of a neck of natural frequency `f_hz` on `base`'s m_θ, N·m/rad.
fn stiffness(base: &BladeParams, f_hz: f64) -> f64 {
    base.mass_coefficients().mth * (TAU * f_hz).powi(2)
}

fn set_friction(p: &mut BladeParams, a: f64, b: f64, c: f64) {
    p.friction = FrictionLaw::Exponential { a, b_s_per_m: b, c };
}

fn max_abs_theta(sim: &BladeSimulation) -> f64 {
    sim.theta_rad.iter().fold(0.0, |m: f64, t| m.max(t.abs()))
}

/// One drawn scene: the true blade, its simulation and the motion's facts.
struct Drawn {
    blade: BladeParams,
    sim: BladeSimulation,
    t0_s: f64,
    draws: usize,
    max_abs_theta_rad: f64,
    /// Frames with the neck on the shoulder, as a fraction (0 without shoulder).
    touch_fraction: f64,
    /// The departure from the fitted model it is recorded with (the departures set).
    departure: Option<Departure>,
}

/// Draws a scene of kind `scene` from the prior on `base` (the main job's blade: its masses,
/// springs other than the neck, dampers, preload and drive), simulated at `fps_hz`; redraws what
/// cannot be simulated or (a shoulder) is never touched.
fn draw_scene(
    rng: &mut StdRng,
    base: &BladeParams,
    scene: Scene,
    fps_hz: f64,
) -> Result<Drawn, String> {
    let mut last_error = String::new();
    for draws in 1..=prior::MAX_DRAWS {
        let mut p = *base;
        p.shoulder = None;
        if scene == Scene::HeadOnly {
            p.hd_m *= log_uniform(rng, prior::LOCKED_PRELOAD_FACTOR);
        }
        set_friction(
            &mut p,
            uniform(rng, prior::A),
            log_uniform(rng, prior::B_S_PER_M),
            uniform(rng, prior::C),
        );
        let f_neck = match scene {
            Scene::ShoulderFree => log_uniform(rng, prior::F_NECK_HZ),
            Scene::Shoulder => log_uniform(rng, prior::F_NECK_FREE_HZ),
            Scene::HeadOnly => {
                let r = uniform(rng, prior::LOCKED_STIFFNESS_OVER_PRELOAD);
                let k1 = r * p.preload_n() * (p.l1_m + p.l2_m);
                (k1 / base.mass_coefficients().mth).sqrt() / TAU
            }
        };
        p.k1_nm_per_rad = stiffness(base, f_neck);
        let contact = (scene == Scene::Shoulder).then(|| {
            let lo = prior::F_CONTACT_HZ[0].max(prior::CONTACT_OVER_FREE * f_neck);
            log_uniform(rng, [lo, prior::F_CONTACT_HZ[1]])
        });
        let free = match recording::simulate_model_window(scene.kind(), &p, fps_hz) {
            Ok(s) => s,
            Err(e) => {
                last_error = e.to_string();
                continue;
            }
        };
        let Some(f_contact) = contact else {
            let reach = max_abs_theta(&free.0);
            return Ok(Drawn {
                blade: p,
                sim: free.0,
                t0_s: free.1,
                draws,
                max_abs_theta_rad: reach,
                touch_fraction: 0.0,
                departure: None,
            });
        };
        let reach_free = max_abs_theta(&free.0);
        let hi = (prior::THETA_C_OF_REACH * reach_free).min(prior::THETA_C_RAD[1]);
        if hi <= prior::THETA_C_RAD[0] {
            last_error = format!("the free neck reaches only {reach_free:.4} rad");
            continue;
        }
        p.shoulder = Some(Shoulder {
            contact_angle_rad: uniform(rng, [prior::THETA_C_RAD[0], hi]),
            k1_contact_nm_per_rad: stiffness(base, f_contact),
        });
        match recording::simulate_model_window(scene.kind(), &p, fps_hz) {
            Ok((sim, t0_s)) => {
                let theta_c = p.shoulder.map_or(f64::INFINITY, |s| s.contact_angle_rad);
                let touching = sim.theta_rad.iter().filter(|t| t.abs() > theta_c).count();
                if touching == 0 {
                    last_error = format!("the neck never reaches θ_c = {theta_c:.4} rad");
                    continue;
                }
                return Ok(Drawn {
                    blade: p,
                    max_abs_theta_rad: max_abs_theta(&sim),
                    touch_fraction: touching as f64 / sim.theta_rad.len() as f64,
                    departure: None,
                    sim,
                    t0_s,
                    draws,
                });
            }
            Err(e) => last_error = e.to_string(),
        }
    }
    Err(format!(
        "no simulable {} scene in {} draws (last: {last_error})",
        scene.label(),
        prior::MAX_DRAWS
    ))
}

/// The median |slip speed| over the slipping samples of `sim`, m/s.
fn median_slip_speed(sim: &BladeSimulation) -> f64 {
    let mut v = sim.slip_speeds();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Changes the drawn blade `d` as `dep` says (its friction law or drive) and simulates it again;
/// a noise departure changes nothing here.
fn apply_departure(d: &mut Drawn, dep: Departure, fps_hz: f64) -> Result<(), String> {
    let FrictionLaw::Exponential { a, b_s_per_m: b, c } = d.blade.friction else {
        return Err("a departure starts from the exponential law".into());
    };
    let simulate = |p: &BladeParams| {
        recording::simulate_model_window(ModelKind::Blade2dof, p, fps_hz).map_err(|e| e.to_string())
    };
    match dep {
        Departure::Ar1 { .. } | Departure::MedianSmoothed => return Ok(()),
        Departure::Stribeck { delta } => {
            d.blade.friction = FrictionLaw::Stribeck {
                a,
                c,
                v_s_m_per_s: 1.0 / b,
                delta,
            };
        }
        Departure::Drive { h } => d.blade.drive_speed_harmonic = h,
        Departure::Viscous { share } => {
            // D·v_med = share·μ_d(v_med): D = share/(1 − share)·(A e^(−B v_med) + C)/v_med, with
            // v_med the median slip speed of the blade's own motion, which moves with D: three
            // fixed-point steps (make_departures measures the median settling to ~1e-4 in two).
            let mut sim = d.sim.clone();
            for _ in 0..3 {
                let v_med = median_slip_speed(&sim);
                let d_s_per_m = share / (1.0 - share) * (a * (-b * v_med).exp() + c) / v_med;
                d.blade.friction = FrictionLaw::ExponentialViscous {
                    a,
                    b_s_per_m: b,
                    c,
                    d_s_per_m,
                };
                sim = simulate(&d.blade)?.0;
            }
        }
    }
    let (sim, t0_s) = simulate(&d.blade)?;
    d.max_abs_theta_rad = max_abs_theta(&sim);
    d.sim = sim;
    d.t0_s = t0_s;
    Ok(())
}

/// The tracking noise of a recording of `n` frames, pixels, per column (head x, head y, tip x,
/// tip y): white of σ `sigma_px`, or AR(1) of marginal σ `sigma_px` for [`Departure::Ar1`]
/// (`ε_t = ρ ε_{t−1} + η_t`, `η ~ N(0, σ²(1 − ρ²))`, started from its stationary law).
fn tracking_noise(
    rng: &mut StdRng,
    n: usize,
    sigma_px: f64,
    dep: Option<Departure>,
) -> Vec<[f64; 4]> {
    let rho = match dep {
        Some(Departure::Ar1 { rho }) => rho,
        _ => 0.0,
    };
    let unit = Normal::new(0.0, 1.0).expect("a unit normal");
    let innovation = sigma_px * (1.0 - rho * rho).sqrt();
    let mut e: [f64; 4] = std::array::from_fn(|_| sigma_px * unit.sample(rng));
    (0..n)
        .map(|i| {
            if i > 0 {
                for x in &mut e {
                    *x = rho * *x + innovation * unit.sample(rng);
                }
            }
            e
        })
        .collect()
}

/// Each column of `rows` through a centred median of [`prior::MEDIAN_WINDOW`] frames over the
/// frames it has (a lost frame, NaN, stays lost and is not part of its neighbours' medians).
fn median_smoothed(rows: &[[f64; 4]]) -> Vec<[f64; 4]> {
    let half = prior::MEDIAN_WINDOW / 2;
    (0..rows.len())
        .map(|i| {
            std::array::from_fn(|c| {
                if rows[i][c].is_nan() {
                    return f64::NAN;
                }
                let lo = i.saturating_sub(half);
                let hi = (i + half + 1).min(rows.len());
                let mut w: Vec<f64> = rows[lo..hi]
                    .iter()
                    .map(|r| r[c])
                    .filter(|v| !v.is_nan())
                    .collect();
                w.sort_by(f64::total_cmp);
                if w.len() % 2 == 1 {
                    w[w.len() / 2]
                } else {
                    0.5 * (w[w.len() / 2 - 1] + w[w.len() / 2])
                }
            })
        })
        .collect()
}

/// A camera: frame rate, scale, noise and which points are lost in which frames.
struct Camera {
    fps_hz: f64,
    m_per_px: f64,
    noise_px: f64,
    /// (first frame, frames, which: 0 head, 1 tip, 2 both), 0-based.
    lost: Vec<(usize, usize, usize)>,
}

fn draw_camera(rng: &mut StdRng) -> Camera {
    Camera {
        fps_hz: uniform(rng, prior::FPS_HZ).round(),
        m_per_px: log_uniform(rng, prior::M_PER_PX),
        noise_px: uniform(rng, prior::NOISE_PX),
        lost: Vec::new(),
    }
}

/// Draws the lost frames of a recording of `n` frames into `camera`.
fn draw_lost(rng: &mut StdRng, camera: &mut Camera, n: usize) {
    let singles = rng.random_range(0..=prior::LOST_SINGLE_MAX);
    for _ in 0..singles {
        camera
            .lost
            .push((rng.random_range(0..n), 1, rng.random_range(0..3)));
    }
    let runs = rng.random_range(0..=prior::LOST_RUNS_MAX);
    for _ in 0..runs {
        let len = rng.random_range(prior::LOST_RUN_LEN[0]..=prior::LOST_RUN_LEN[1]);
        camera.lost.push((rng.random_range(0..n - len), len, 2));
    }
    camera.lost.sort_unstable();
}

/// Whether coordinate column `c` (head x, head y, tip x, tip y) is lost at frame `i`.
fn is_lost(camera: &Camera, c: usize, i: usize) -> bool {
    let point = c / 2;
    camera
        .lost
        .iter()
        .any(|&(first, len, which)| i >= first && i < first + len && (which == 2 || which == point))
}

/// `to` as seen from directory `from` (both absolute): relative when `to` lies under `root`
/// (where `from` also lies), else absolute.
fn relative(from: &Path, to: &Path, root: &Path) -> String {
    match (from.strip_prefix(root), to.strip_prefix(root)) {
        (Ok(f), Ok(t)) => {
            let ups = f.components().count();
            let mut s = "../".repeat(ups);
            s.push_str(&t.to_string_lossy());
            s
        }
        _ => to.to_string_lossy().into_owned(),
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = Args::parse();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let set = args.set;
    let mix: [usize; 3] = match (&args.mix, args.count) {
        (Some(m), _) => match m[..] {
            [free, shoulder, head] => [free, shoulder, head],
            _ => return Err(format!("--mix: three counts FREE,SHOULDER,HEAD (got {m:?})").into()),
        },
        (None, Some(n)) => {
            let d = set.default_mix();
            let total: usize = d.iter().sum();
            let free = (n * d[0] + total / 2) / total;
            let shoulder = ((n * d[1] + total / 2) / total).min(n - free);
            [free, shoulder, n - free - shoulder]
        }
        (None, None) => set.default_mix(),
    };
    let count: usize = mix.iter().sum();
    if count == 0 || count > 1_000_000 {
        return Err(
            format!("--count/--mix: between 1 and 1,000,000 recordings (got {count})").into(),
        );
    }
    let out = std::path::absolute(
        args.out
            .clone()
            .unwrap_or_else(|| root.join("data/calibration").join(set.dir())),
    )?;
    for d in ["recordings", "truths", "blades"] {
        std::fs::create_dir_all(out.join(d))?;
    }
    let base: BladeParams = toml::from_str(&std::fs::read_to_string(
        root.join("data/reversal/blade.toml"),
    )?)?;
    let mut conditions = String::from(
        "recording,t0_s,fps_hz,m_per_px,truth_json,blade_file,scene,departure,noise_px,lost_frames,seed\n",
    );
    let started = Instant::now();
    let mut bytes = 0u64;
    let scenes = std::iter::repeat_n(Scene::ShoulderFree, mix[0])
        .chain(std::iter::repeat_n(Scene::Shoulder, mix[1]))
        .chain(std::iter::repeat_n(Scene::HeadOnly, mix[2]));
    for (i, scene) in scenes.enumerate() {
        let seed = set.seed_base() + i as u64;
        let mut rng = StdRng::seed_from_u64(seed);
        let id = format!("{}_{i:03}_{}", set.id_prefix(), scene.label());
        let mut camera = draw_camera(&mut rng);
        let mut d = draw_scene(&mut rng, &base, scene, camera.fps_hz)
            .map_err(|e| format!("{id} (seed {seed}): {e}"))?;
        let departure = (set == Set::Departures).then(|| Departure::draw(i, &mut rng));
        let id = match departure {
            Some(dep) => format!("{}_{i:03}_{}", set.id_prefix(), dep.label()),
            None => id,
        };
        if let Some(dep) = departure {
            apply_departure(&mut d, dep, camera.fps_hz)
                .map_err(|e| format!("{id} (seed {seed}): {e}"))?;
            d.departure = Some(dep);
        }
        let n = d.sim.t_s.len();
        draw_lost(&mut rng, &mut camera, n);
        let noise = tracking_noise(&mut rng, n, camera.noise_px, departure);
        let mut rows: Vec<[f64; 4]> = recording::clean_px_rows(&d.sim, camera.m_per_px)
            .into_iter()
            .enumerate()
            .map(|(i, clean)| {
                std::array::from_fn(|c| {
                    if is_lost(&camera, c, i) {
                        f64::NAN
                    } else {
                        clean[c] + noise[i][c]
                    }
                })
            })
            .collect();
        if departure == Some(Departure::MedianSmoothed) {
            rows = median_smoothed(&rows);
        }
        let text = recording::dltdv_text_of_rows(&rows);
        let file = format!("{id}_xypts.csv");
        std::fs::write(out.join("recordings").join(&file), &text)?;
        bytes += text.len() as u64;
        write_truth(&out, &id, scene, &d, &camera, seed, set)?;
        // The fit's blade: the main job's, with what differs for this recording and a lab would
        // know (a head-only scene's preload); the fitted parameters keep the main job's nominal
        // values, so no truth reaches the fit through it.
        let blade_file = if d.blade.hd_m == base.hd_m {
            String::new()
        } else {
            let mut known = base;
            known.hd_m = d.blade.hd_m;
            let rel = format!("blades/{id}.blade.toml");
            std::fs::write(
                out.join(&rel),
                format!(
                    "# The blade the fit of {id} knows: data/reversal/blade.toml with its preload (h_d) x {:.4}.\n\
                     # A, B, C and k1 are the main job's nominal values, not the truth (truths/{id}.json).\n{}",
                    d.blade.hd_m / base.hd_m,
                    toml::to_string(&known)?
                ),
            )?;
            rel
        };
        let lost_frames: usize = camera.lost.iter().map(|l| l.1).sum();
        let _ = writeln!(
            conditions,
            "{file},{:?},{:?},{:?},truths/{id}.json,{blade_file},{},{},{:.4},{lost_frames},{seed}",
            d.t0_s,
            camera.fps_hz,
            camera.m_per_px,
            scene.label(),
            d.departure.map_or("none", Departure::label),
            camera.noise_px,
        );
        println!(
            "{id}: {n} frames at {:.0} fps, {:.1} µm/px, {:.3} px noise, {lost_frames} lost, max|θ| {:.4} rad{}",
            camera.fps_hz,
            camera.m_per_px * 1e6,
            camera.noise_px,
            d.max_abs_theta_rad,
            if scene == Scene::Shoulder {
                format!(
                    ", on the shoulder {:.0} % of frames",
                    100.0 * d.touch_fraction
                )
            } else {
                String::new()
            }
        );
    }
    std::fs::write(out.join("conditions.csv"), conditions)?;
    let campaign = write_campaign(root, &out, set, mix)?;
    println!(
        "{count} recordings ({} shoulder-free, {} shoulder, {} head-only), {:.1} MB of tracks, in {:.0} s; campaign {}",
        mix[0],
        mix[1],
        mix[2],
        bytes as f64 / 1e6,
        started.elapsed().as_secs_f64(),
        campaign.display()
    );
    Ok(())
}

/// Which points a lost-frames entry loses.
const POINTS: [&str; 3] = ["head", "tip", "both"];

/// `truths/<id>.json` and `truths/<id>.blade.toml`.
fn write_truth(
    out: &Path,
    id: &str,
    scene: Scene,
    d: &Drawn,
    camera: &Camera,
    seed: u64,
    set: Set,
) -> Result<(), Box<dyn std::error::Error>> {
    // A, B, C are the fitted law's coefficients only when the true law is that law; else null:
    // the recording's law is scored as a curve (`/friction_law`), not coefficient by coefficient.
    let (a, b, c) = match d.blade.friction {
        FrictionLaw::Exponential { a, b_s_per_m, c } => (json!(a), json!(b_s_per_m), json!(c)),
        _ => (json!(null), json!(null), json!(null)),
    };
    // A scene without shoulder is the shoulder model whose contact changes nothing (k1c = k1)
    // and is never reached (θ_c = 1 rad): its true θ_c and k1c let a fit that chose a shoulder
    // price the truth; the calibration table does not score them.
    let (theta_c, k1c) = match d.blade.shoulder {
        Some(s) => (s.contact_angle_rad, s.k1_contact_nm_per_rad),
        None => (1.0, d.blade.k1_nm_per_rad),
    };
    let truth = json!({
        "what": format!("{} recording {id} of wiperlab's simulation-based calibration ({} set): examples/make_calibration.rs", scene.label(), set.dir()),
        "model": scene.model(),
        "params": { "A": a, "B": b, "C": c, "k1": d.blade.k1_nm_per_rad, "theta_c": theta_c, "k1c": k1c },
        "scored": if scene == Scene::Shoulder { json!(["A", "B", "C", "k1", "theta_c", "k1c"]) } else { json!(["A", "B", "C", "k1"]) },
        "friction_law": d.blade.friction,
        "departure": d.departure.map(Departure::label),
        "departure_size": d.departure.map(Departure::size),
        "blade": d.blade,
        "seed": seed,
        "draws": d.draws,
        "camera": {
            "fps_hz": camera.fps_hz,
            "m_per_px": camera.m_per_px,
            "origin_px": [200.0, 300.0],
            "noise_sigma_px": camera.noise_px,
            "t0_s": d.t0_s,
            "frames": d.sim.t_s.len(),
            "lost": camera.lost.iter().map(|&(first, len, which)| json!({
                "first_frame_0based": first,
                "frames": len,
                "points": POINTS[which],
            })).collect::<Vec<_>>(),
        },
        "motion": {
            "max_abs_theta_rad": d.max_abs_theta_rad,
            "shoulder_touch_fraction": d.touch_fraction,
            "transitions": d.sim.transitions.len(),
        },
        "simulation": { "method": "dop853", "rtol": 1e-10, "atol": 1e-12, "model": scene.kind().name() },
    });
    std::fs::write(
        out.join("truths").join(format!("{id}.json")),
        serde_json::to_string_pretty(&truth)? + "\n",
    )?;
    let blade = format!(
        "# The true blade of {id} ({} scene, simulated by the {} model): examples/make_calibration.rs.\n{}",
        scene.label(),
        scene.kind().name(),
        toml::to_string(&d.blade)?
    );
    std::fs::write(out.join("truths").join(format!("{id}.blade.toml")), blade)?;
    Ok(())
}

/// `campaigns/<name>.toml`: the main job on the set's recordings; returns its path.
fn write_campaign(
    root: &Path,
    out: &Path,
    set: Set,
    mix: [usize; 3],
) -> Result<PathBuf, Box<dyn std::error::Error>> {
    let campaigns = root.join("campaigns");
    let at = relative(&campaigns, out, root);
    let name = set.campaign();
    let args = format!("--set {}", set.dir());
    let notes = match set {
        Set::Development => format!(
            "**Development set** ({} recordings, seeds {} + i): the estimator's hyperparameters may be \
             chosen on it; it is not the calibration set. Recordings: \
             `cargo run --release --example make_calibration -- {args}`; prior and cameras: \
             docs/campaigns.md, \"The calibration campaign\".\n",
            mix.iter().sum::<usize>(),
            set.seed_base()
        ),
        Set::Departures => format!(
            "**Departures set** ({} shoulder-free recordings, seeds {} + i), each made with one departure \
             from the fitted model (AR(1) or median-smoothed tracking noise, a viscous term or a Stribeck \
             exponent in the friction law, a drive speed with a second harmonic; `/departure` of each \
             truth file). A, B, C are scored only where the true law is the fitted one; the friction law \
             is scored as a curve over the measured slip speeds. Recordings: \
             `cargo run --release --example make_calibration -- {args}`.\n",
            mix.iter().sum::<usize>(),
            set.seed_base()
        ),
        Set::Calibration => format!(
            "**Calibration set** ({} recordings, seeds {} + i): every hyperparameter of the search and \
             of the intervals is chosen on the development set (campaigns/calibration_development.toml, \
             seeds {} + i), never on this one. Recordings: \
             `cargo run --release --example make_calibration -- {args}`; prior and cameras: \
             docs/campaigns.md, \"The calibration campaign\".\n",
            mix.iter().sum::<usize>(),
            set.seed_base(),
            Set::Development.seed_base()
        ),
    };
    let law = if set == Set::Departures {
        "# Each recording's true friction law (its truth file's /friction_law): the fitted law is\n\
         # scored as a curve over the measured slip speeds.\n\
         truth_friction_law = \"/friction_law\"\n\n"
    } else {
        ""
    };
    let text = format!(
        "# Simulation-based calibration of the main job ({} set): {} shoulder-free, {} shoulder and {} head-only\n\
         # recordings drawn from the prior of docs/campaigns.md, \"The calibration campaign\", seeds {} + i.\n\
         # Regenerate the recordings (not kept in git) with one command:\n\
         #   cargo run --release --example make_calibration -- {args}\n\
         # then fit and tabulate:\n\
         #   wiperlab campaign run campaigns/{name}.toml --jobs 1\n\
         #   wiperlab campaign collect campaigns/{name}.toml   # -> reports/{name}/calibration.md\n\
         template = \"../fits/reversal.toml\"\n\
         recordings = [\"{at}/recordings/*_xypts.csv\"]\n\
         conditions = \"{at}/conditions.csv\"\n\
         reports_dir = \"../reports\"\n\
         notes = \"\"\"\n{notes}\"\"\"\n\
         # The cameras run at 5–20 kHz: the main job's bands keep their bin widths at each frame rate.\n\
         bands_follow_frame_rate = true\n\n\
         # Each recording's true model (its truth file's /model): the truth's cost is read in that\n\
         # model's fit, so the search shortfall is measured whichever model the fit chooses.\n\
         truth_model = \"/model\"\n\n\
         {law}\
         [truth_keys]               # the main job's [truth] names A, B, C and k1; a shoulder's are added\n\
         theta_c = \"/params/theta_c\"\n\
         k1c = \"/params/k1c\"\n\n\
         [slurm]\n\
         cpus_per_task = 2\n\
         time = \"00:30:00\"\n",
        set.dir(),
        mix[0],
        mix[1],
        mix[2],
        set.seed_base(),
    );
    let path = campaigns.join(format!("{name}.toml"));
    std::fs::write(&path, text)?;

    Ok(path)
}
