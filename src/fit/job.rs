//! The fit job file (TOML): which recording, which blade, which parameters to free, and settings.
//!
//! Paths inside a job are relative to the job file. Example: `fits/reversal.toml`.

use super::features::{BandSpec, SignalKind, default_bands};
use crate::import::ImportSpec;
use crate::model::BladeParams;
use crate::simulate::SolverOptions;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A fit job as written in TOML.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FitJob {
    /// Name used for outputs (`fits/<name>.result.toml`, `reports/<name>/`); default: file stem.
    #[serde(default)]
    pub name: Option<String>,
    /// The recording to fit; a job gives either this or `[targets]`.
    #[serde(default)]
    pub recording: Option<RecordingSection>,
    /// Target peak frequencies instead of a recording (e.g. the seed paper's own numbers).
    #[serde(default)]
    pub targets: Option<TargetsSection>,
    /// Further recordings of the same blade (e.g. other sweep speeds) fitted together with
    /// `[recording]`: they share every freed parameter, each with its own drive.
    #[serde(default)]
    pub more_recordings: Vec<MoreRecording>,
    /// Blade parameter file (TOML with [`BladeParams`] fields); the freed parameters' values in it
    /// are ignored by the fit.
    pub blade: PathBuf,
    #[serde(default)]
    pub spectrum: SpectrumSection,
    /// Integrator settings for every model evaluation; default rtol 1e-7, atol 1e-9. With the
    /// default bands the fit's spectral peaks stay within 0.05 % of converged down to rtol 1e-5
    /// (`wiperlab bench`, reports/bench/spectra_vs_rtol.csv), and tests/fit_recovery.rs recovers C
    /// and k1 to 0.23 % and 0.32 % at 1e-6, 0.11 % and 0.22 % at 1e-7 (README, "Spectra against
    /// tolerance"). `[fit] swarm_rtol` may loosen it for the swarm stage only.
    #[serde(default = "fit_solver_default")]
    pub solver: SolverOptions,
    pub fit: FitSection,
    /// Optional true parameters (for synthetic recordings), to report relative errors.
    #[serde(default)]
    pub truth: Option<TruthSection>,
}

fn fit_solver_default() -> SolverOptions {
    SolverOptions {
        rtol: 1e-7,
        atol: 1e-9,
        ..SolverOptions::default()
    }
}

/// Target frequencies to reach instead of a recording.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TargetsSection {
    /// Where the numbers come from (shown in the result and report).
    pub source: String,
    /// Sampling rate of the simulated signal, Hz (default 20 kHz).
    #[serde(default = "d_target_fps")]
    pub fps_hz: f64,
    /// One target per band of `[spectrum]`, by band name.
    pub peaks: Vec<TargetPeak>,
}

fn d_target_fps() -> f64 {
    20_000.0
}

/// A band's target: one frequency, or a range the model's peak should fall in.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TargetPeak {
    pub band: String,
    #[serde(default)]
    pub freq_hz: Option<f64>,
    #[serde(default)]
    pub range_hz: Option<[f64; 2]>,
}

impl TargetPeak {
    /// The target's range (a single frequency is a zero-width range).
    pub fn range(&self) -> [f64; 2] {
        match (self.freq_hz, self.range_hz) {
            (Some(f), _) => [f, f],
            (None, Some(r)) => r,
            (None, None) => [f64::NAN, f64::NAN],
        }
    }
}

/// Where the recording is and how to read it.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RecordingSection {
    pub file: PathBuf,
    /// Import settings (format, fps, scale, roles); `t0_s` puts frame 1 on the model's clock,
    /// where the drive is `v = a(1 − cos ωt)`.
    pub import: ImportSpec,
}

/// Another recording in a joint fit: where it is, how to read it, and its drive.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MoreRecording {
    /// Label used in the result's peak table (e.g. "slow").
    pub name: String,
    pub file: PathBuf,
    pub import: ImportSpec,
    /// Drive amplitude of this recording, m (default: the blade file's).
    #[serde(default)]
    pub drive_a_m: Option<f64>,
    /// Drive angular frequency of this recording, rad/s (default: the blade file's).
    #[serde(default)]
    pub drive_omega_rad_per_s: Option<f64>,
}

/// Spectral estimator settings shared by measurement and model.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SpectrumSection {
    pub signal: SignalKind,
    pub bands: Vec<BandSpec>,
    /// Longest gap (samples) filled by linear interpolation before Welch; longer gaps split the
    /// record.
    pub max_fill: usize,
}

impl Default for SpectrumSection {
    fn default() -> Self {
        SpectrumSection {
            signal: SignalKind::TipRelX,
            bands: default_bands(),
            max_fill: 5,
        }
    }
}

/// Cost weights (see [`super::SpectralProblem::cost_of`]).
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct Weights {
    /// Weight of the squared log peak-frequency error in units of 1 % (`(Δln f / 0.01)²`).
    pub peak: f64,
    /// Weight of the squared log peak-level error in units of a factor 2.
    pub level: f64,
    /// Weight of the mean squared log-PSD difference across each band.
    pub shape: f64,
    /// Weight of the instantaneous frequency against tip speed (spectrogram ridge, binned by
    /// speed; `(Δln f / 0.01)²` per bin, see [`super::instfreq`]). Default 0: off.
    pub freq_speed: f64,
    /// Weight of the time-domain error of the job's signal (means removed, relative to the
    /// measurement's variance; see [`super::instfreq::trace_error`]). Default 0: off.
    pub trace: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Weights {
            peak: 1.0,
            level: 1.0,
            shape: 1.0,
            freq_speed: 0.0,
            trace: 0.0,
        }
    }
}

/// Which parameters to fit and how.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FitSection {
    /// Parameter name → `[lower, upper]` bounds. Names: see [`PARAM_NAMES`].
    pub parameters: BTreeMap<String, [f64; 2]>,
    /// Particles of the global particle-swarm stage.
    #[serde(default = "d_particles")]
    pub particles: usize,
    /// Iterations of the particle-swarm stage.
    #[serde(default = "d_swarm")]
    pub swarm_iterations: u64,
    /// Iterations of the Nelder–Mead polish.
    #[serde(default = "d_polish")]
    pub polish_iterations: u64,
    /// Seed of the swarm's random generator (the fit is reproducible for a given seed).
    #[serde(default = "d_seed")]
    pub seed: u64,
    /// Independent swarm-and-polish runs; the lowest cost is kept (see `optimise` in
    /// [`crate::fit`]). Each run costs a full swarm and polish.
    #[serde(default = "d_restarts")]
    pub restarts: usize,
    /// Relative tolerance of the simulations in the particle-swarm stage (its absolute tolerance
    /// scaled by the same factor against `[solver]`): a cheaper coarse search. The polish, the
    /// reported cost, the curvature and everything after use `[solver]`. Default (`None`): the
    /// `[solver]` tolerance throughout.
    #[serde(default)]
    pub swarm_rtol: Option<f64>,
    #[serde(default)]
    pub weights: Weights,
    /// Models of the hierarchy to fit and compare, from [`MODEL_NAMES`], e.g. `["head1dof",
    /// "blade2dof", "blade2dof+shoulder"]`. Empty (the default): only the smallest model that can produce every
    /// band the job asks for (see [`crate::fit::smallest_capable_model`]). With several, each is
    /// fitted and the one with the lowest Akaike criterion (cost + 2k) is reported.
    #[serde(default)]
    pub models: Vec<String>,
    /// Bounds of the shoulder-contact parameters freed by the `+shoulder` candidates.
    #[serde(default)]
    pub shoulder: Option<ShoulderBounds>,
    /// Confidence intervals by parametric bootstrap (see [`crate::fit::bootstrap_intervals`]).
    #[serde(default)]
    pub uncertainty: UncertaintySection,
}

/// Settings of the parametric bootstrap that gives each fitted parameter an interval.
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct UncertaintySection {
    /// Bootstrap replicates (0: no intervals, only the curvature's 1σ).
    pub bootstrap: usize,
    /// Re-run the whole estimator (swarm and polish) on each replicate; otherwise only a
    /// Nelder–Mead polish from the optimum.
    pub full_refit: bool,
    /// Nelder–Mead iterations of a polish-only replicate.
    pub polish_iterations: u64,
    /// Seed of the replicates' noise.
    pub seed: u64,
}

impl Default for UncertaintySection {
    fn default() -> Self {
        UncertaintySection {
            bootstrap: 0,
            full_refit: true,
            polish_iterations: 30,
            seed: 7,
        }
    }
}

/// Bounds `[lower, upper]` of the shoulder parameters (see [`crate::model::Shoulder`]).
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShoulderBounds {
    /// Neck stiffness while touching the shoulder, N·m/rad.
    pub k1c: [f64; 2],
    /// Contact angle, rad.
    pub theta_c: [f64; 2],
}

/// Names of the candidate models a job may list in `[fit] models`.
pub const MODEL_NAMES: &[&str] = &[
    "head1dof",
    "necklip",
    "necklip+shoulder",
    "blade2dof",
    "blade2dof+shoulder",
];

fn d_particles() -> usize {
    12
}
fn d_swarm() -> u64 {
    8
}
fn d_polish() -> u64 {
    40
}
fn d_seed() -> u64 {
    1
}
fn d_restarts() -> usize {
    1
}

/// True parameter values from a JSON file (e.g. the sample's `truth.json`).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TruthSection {
    pub json: PathBuf,
    /// Parameter name → JSON pointer (RFC 6901), e.g. `A = "/params/A"`.
    pub keys: BTreeMap<String, String>,
}

/// Parameters a job may free, with their field in [`BladeParams`].
pub const PARAM_NAMES: &[(&str, &str)] = &[
    ("A", "friction A (seed eq. 4), 1"),
    ("B", "friction B, s/m"),
    ("C", "friction C, 1"),
    ("k1", "neck stiffness k1, N·m/rad"),
    ("k0", "head spring k0, N/m"),
    ("k2", "lip stiffness k2, N·m/rad"),
    ("c0", "head damper c0, N·s/m"),
    ("c1", "neck damper c1, N·m·s/rad"),
    ("c2", "lip damper c2, N·m·s/rad"),
    ("hd", "preload compression h_d, m"),
    (
        "k1c",
        "neck stiffness touching the shoulder, N·m/rad (needs a [shoulder] in the blade)",
    ),
    (
        "theta_c",
        "shoulder contact angle, rad (needs a [shoulder] in the blade)",
    ),
];

/// Reads parameter `name` of `p` (`None` for an unknown name).
pub fn get_param(p: &BladeParams, name: &str) -> Option<f64> {
    use crate::model::FrictionLaw::Exponential;
    let (a, b, c) = match p.friction {
        Exponential { a, b_s_per_m, c } => (a, b_s_per_m, c),
        _ => (f64::NAN, f64::NAN, f64::NAN),
    };
    Some(match name {
        "A" => a,
        "B" => b,
        "C" => c,
        "k1" => p.k1_nm_per_rad,
        "k0" => p.k0_n_per_m,
        "k2" => p.k2_nm_per_rad,
        "c0" => p.c0_ns_per_m,
        "c1" => p.c1_nms_per_rad,
        "c2" => p.c2_nms_per_rad,
        "hd" => p.hd_m,
        "k1c" => p.shoulder?.k1_contact_nm_per_rad,
        "theta_c" => p.shoulder?.contact_angle_rad,
        _ => return None,
    })
}

/// Sets parameter `name` of `p` (false for an unknown name).
pub fn set_param(p: &mut BladeParams, name: &str, v: f64) -> bool {
    use crate::model::FrictionLaw::Exponential;
    match name {
        "A" | "B" | "C" => {
            if let Exponential { a, b_s_per_m, c } = &mut p.friction {
                match name {
                    "A" => *a = v,
                    "B" => *b_s_per_m = v,
                    _ => *c = v,
                }
            } else {
                return false;
            }
        }
        "k1" => p.k1_nm_per_rad = v,
        "k0" => p.k0_n_per_m = v,
        "k2" => p.k2_nm_per_rad = v,
        "c0" => p.c0_ns_per_m = v,
        "c1" => p.c1_nms_per_rad = v,
        "c2" => p.c2_nms_per_rad = v,
        "hd" => p.hd_m = v,
        "k1c" | "theta_c" => match &mut p.shoulder {
            Some(sh) if name == "k1c" => sh.k1_contact_nm_per_rad = v,
            Some(sh) => sh.contact_angle_rad = v,
            None => return false,
        },
        _ => return false,
    }
    true
}

/// 1-based line of the first occurrence of `needle` in `text` (0 if absent).
pub(crate) fn line_of(text: &str, needle: &str) -> usize {
    text.find(needle)
        .map(|i| text[..i].matches('\n').count() + 1)
        .unwrap_or(0)
}

/// Parses TOML `text` from `path` into `T`, turning syntax and schema errors into
/// [`Error::Parse`] with line and column.
pub fn parse_toml<T: serde::de::DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    toml::from_str(text).map_err(|e| {
        let (line, col) = match e.span() {
            Some(sp) => {
                let before = &text[..sp.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let col = before
                    .rsplit('\n')
                    .next()
                    .map(|s| s.chars().count())
                    .unwrap_or(0)
                    + 1;
                (line, col)
            }
            None => (0, 0),
        };
        Error::parse(path, line, col, e.message().to_string())
    })
}

/// Reads a file to a string, naming it on failure.
pub fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| Error::io(path, "cannot read", e))
}

/// A loaded, validated job with its paths resolved.
#[derive(Debug, Clone)]
pub struct LoadedJob {
    pub job: FitJob,
    pub name: String,
    pub path: PathBuf,
    pub recording_path: PathBuf,
    pub blade: BladeParams,
    /// Freed parameters in a fixed order: (name, lower, upper).
    pub free: Vec<(String, f64, f64)>,
    /// True values of freed parameters, when the job names a truth file.
    pub truth: BTreeMap<String, f64>,
}

impl LoadedJob {
    /// Loads and validates the job at `path`.
    ///
    /// # Errors
    /// [`Error::Io`] for unreadable files; [`Error::Parse`] (file, line, column) for TOML syntax,
    /// unknown fields, an unknown parameter name or bounds the wrong way round.
    pub fn load(path: &Path) -> Result<LoadedJob> {
        let text = read_text(path)?;
        let job: FitJob = parse_toml(path, &text)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let name = job.name.clone().unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "fit".into())
        });
        let blade_path = dir.join(&job.blade);
        let blade_text = read_text(&blade_path)?;
        let blade: BladeParams = parse_toml(&blade_path, &blade_text)?;
        blade.validate().map_err(|m| Error::input(&blade_path, m))?;
        let mut free = Vec::new();
        for (pname, [lo, hi]) in &job.fit.parameters {
            let line =
                line_of(&text, &format!("{pname} =")).max(line_of(&text, &format!("{pname}=")));
            if (pname == "k1c" || pname == "theta_c") && blade.shoulder.is_none() {
                return Err(Error::parse(
                    path,
                    line,
                    1,
                    format!(
                        "[fit.parameters]: '{pname}' is a shoulder parameter but the blade file {} has no [shoulder] section (or list \"blade2dof+shoulder\" in [fit] models with [fit.shoulder] bounds)",
                        blade_path.display()
                    ),
                ));
            }
            if get_param(&blade, pname).is_none() {
                return Err(Error::parse(
                    path,
                    line,
                    1,
                    format!(
                        "[fit.parameters]: unknown parameter '{pname}' (known: {})",
                        PARAM_NAMES
                            .iter()
                            .map(|(n, _)| *n)
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            }
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(Error::parse(
                    path,
                    line,
                    1,
                    format!(
                        "[fit.parameters]: bounds of '{pname}' must be finite with lower < upper (got [{lo}, {hi}])"
                    ),
                ));
            }
            if *lo < 0.0 {
                return Err(Error::parse(
                    path,
                    line,
                    1,
                    format!(
                        "[fit.parameters]: '{pname}' is a physical magnitude; its lower bound must be >= 0 (got {lo})"
                    ),
                ));
            }
            free.push((pname.clone(), *lo, *hi));
        }
        if free.is_empty() {
            return Err(Error::parse(
                path,
                line_of(&text, "[fit"),
                1,
                "[fit.parameters] frees no parameter",
            ));
        }
        if job.fit.particles < 2 {
            return Err(Error::parse(
                path,
                line_of(&text, "particles"),
                1,
                "[fit] particles must be >= 2",
            ));
        }
        for m in &job.fit.models {
            if !MODEL_NAMES.contains(&m.as_str()) {
                return Err(Error::parse(
                    path,
                    line_of(&text, "models"),
                    1,
                    format!(
                        "[fit] models: unknown model '{m}' (known: {})",
                        MODEL_NAMES.join(", ")
                    ),
                ));
            }
            if m.ends_with("+shoulder") && job.fit.shoulder.is_none() {
                return Err(Error::parse(
                    path,
                    line_of(&text, "models"),
                    1,
                    format!(
                        "[fit] models lists \"{m}\": give its bounds in [fit.shoulder] (k1c = [lo, hi], theta_c = [lo, hi])"
                    ),
                ));
            }
        }
        if let Some(sb) = &job.fit.shoulder {
            for (name, [lo, hi]) in [("k1c", sb.k1c), ("theta_c", sb.theta_c)] {
                if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo < hi) {
                    return Err(Error::parse(
                        path,
                        line_of(&text, "[fit.shoulder]"),
                        1,
                        format!("[fit.shoulder] {name}: need 0 < lower < upper (got [{lo}, {hi}])"),
                    ));
                }
            }
        }
        match (&job.recording, &job.targets) {
            (Some(_), None) => {}
            (None, Some(t)) => {
                for tp in &t.peaks {
                    let line = line_of(&text, &format!("\"{}\"", tp.band));
                    if !job.spectrum.bands.iter().any(|b| b.name == tp.band) {
                        return Err(Error::parse(
                            path,
                            line,
                            1,
                            format!(
                                "[targets] peak for band '{}', which [spectrum] does not define",
                                tp.band
                            ),
                        ));
                    }
                    let [lo, hi] = tp.range();
                    if tp.freq_hz.is_some() == tp.range_hz.is_some() || !(lo > 0.0 && lo <= hi) {
                        return Err(Error::parse(
                            path,
                            line,
                            1,
                            format!(
                                "[targets] band '{}': give exactly one of freq_hz = F or range_hz = [LO, HI] with 0 < LO <= HI",
                                tp.band
                            ),
                        ));
                    }
                }
                if !(t.fps_hz.is_finite() && t.fps_hz > 0.0) {
                    return Err(Error::parse(
                        path,
                        line_of(&text, "fps_hz"),
                        1,
                        "[targets] fps_hz must be > 0",
                    ));
                }
            }
            _ => {
                return Err(Error::parse(
                    path,
                    1,
                    1,
                    "a fit job gives either [recording] (a tracked recording) or [targets] (frequencies to reach), and exactly one of them",
                ));
            }
        }
        if !job.more_recordings.is_empty() && job.recording.is_none() {
            return Err(Error::parse(
                path,
                line_of(&text, "[[more_recordings]]"),
                1,
                "[[more_recordings]] needs a [recording] to join (not a [targets] job)",
            ));
        }
        for m in &job.more_recordings {
            for (what, v) in [
                ("drive_a_m", m.drive_a_m),
                ("drive_omega_rad_per_s", m.drive_omega_rad_per_s),
            ] {
                if let Some(x) = v
                    && !(x.is_finite() && x > 0.0)
                {
                    return Err(Error::parse(
                        path,
                        line_of(&text, &m.name),
                        1,
                        format!(
                            "[[more_recordings]] '{}': {what} must be > 0 (got {x})",
                            m.name
                        ),
                    ));
                }
            }
        }
        job.solver.validate()?;
        if let Some(r) = job.fit.swarm_rtol
            && !(r.is_finite() && r > 0.0 && r < 1.0)
        {
            return Err(Error::parse(
                path,
                line_of(&text, "swarm_rtol"),
                1,
                format!("[fit] swarm_rtol must be in (0, 1) (got {r})"),
            ));
        }
        for b in &job.spectrum.bands {
            if !(b.range_hz[0] >= 0.0 && b.range_hz[0] < b.range_hz[1]) || b.nperseg < 8 {
                return Err(Error::parse(
                    path,
                    line_of(&text, &b.name),
                    1,
                    format!(
                        "[spectrum] band '{}': need 0 <= lower < upper and nperseg >= 8 (got {:?}, nperseg {})",
                        b.name, b.range_hz, b.nperseg
                    ),
                ));
            }
        }
        let mut truth = BTreeMap::new();
        if let Some(t) = &job.truth {
            let tp = dir.join(&t.json);
            let v: serde_json::Value = serde_json::from_str(&read_text(&tp)?).map_err(|e| {
                Error::parse(&tp, e.line(), e.column(), format!("not valid JSON: {e}"))
            })?;
            for (k, ptr) in &t.keys {
                let x = v.pointer(ptr).and_then(|x| x.as_f64()).ok_or_else(|| {
                    Error::input(&tp, format!("no number at JSON pointer {ptr} (for '{k}')"))
                })?;
                truth.insert(k.clone(), x);
            }
        }
        Ok(LoadedJob {
            recording_path: match &job.recording {
                Some(r) => dir.join(&r.file),
                // A target job's input is the job file itself (its hash is the provenance).
                None => path.to_path_buf(),
            },
            job,
            name,
            path: path.to_path_buf(),
            blade,
            free,
            truth,
        })
    }
}
