//! The model-choice scenes: nine recordings the model makes (rtol 1e-10) from the shipped sample's
//! blade (`data/reversal/blade_true.toml`) with one thing changed per scene, written as DLTdv files
//! through the sample's camera model with Gaussian tracking noise of 0.1 px per coordinate (as the
//! sample: data/reversal/README.md) and 1 % of the frames dropped in runs of 1–3 (the job fills up
//! to 5), each with a job that fits it with the main job's settings (`fits/reversal.toml`: bands,
//! solver, swarm, 5 restarts, the three candidates, A, B, C, k1 and the shoulder's bounds) and
//! Laplace intervals. Used by `tests/suite/model_choice.rs` and `examples/model_choice.rs` (the
//! confusion table).

use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use wiperlab::job::Candidate;
use wiperlab::job::LoadedJob;
use wiperlab::model::{BladeParams, FrictionLaw, Shoulder, StickForm};
use wiperlab::simulate::SolverOptions;
use wiperlab::simulate::blade::{ModelKind, default_window, simulate_model};

use super::{dltdv_recording, frame_times, spectrum_bands, true_blade, write_dltdv};

/// One recording: what made it.
pub struct Scene {
    pub name: &'static str,
    /// The model that made it, as a candidate.
    pub truth_model: Candidate,
    /// The simulated model (the shoulder comes from `shoulder`).
    pub kind: ModelKind,
    /// The sweep's angular frequency as a multiple of the sample's.
    pub speed: f64,
    /// Free neck stiffness, N·m/rad.
    pub k1: f64,
    /// Shoulder: (contact angle, rad; stiffness in contact, N·m/rad).
    pub shoulder: Option<(f64, f64)>,
    /// Preload (the head's drop hd) as a multiple of the sample's; the job's blade has it too.
    pub hd_scale: f64,
}

/// The candidates that made the scenes.
const BLADE: Candidate = Candidate {
    kind: ModelKind::Blade2dof,
    shoulder: false,
    law: None,
};
const BLADE_ON_SHOULDER: Candidate = Candidate {
    kind: ModelKind::Blade2dof,
    shoulder: true,
    law: None,
};
const HEAD: Candidate = Candidate {
    kind: ModelKind::Head1dof,
    shoulder: false,
    law: None,
};

pub const SCENES: [Scene; 9] = [
    Scene {
        name: "no shoulder",
        truth_model: BLADE,
        kind: ModelKind::Blade2dof,
        speed: 1.0,
        k1: 0.029748408887917077,
        shoulder: None,
        hd_scale: 1.0,
    },
    Scene {
        name: "no shoulder, 0.7x speed",
        truth_model: BLADE,
        kind: ModelKind::Blade2dof,
        speed: 0.7,
        k1: 0.029748408887917077,
        shoulder: None,
        hd_scale: 1.0,
    },
    // Free neck 4x softer than the sample's, touching at 0.06 rad (tests/suite/shoulder_fit.rs's scene):
    // measured, 2 switches, the neck enters contact once and stays.
    Scene {
        name: "soft neck on a shoulder at 0.06 rad",
        truth_model: BLADE_ON_SHOULDER,
        kind: ModelKind::Blade2dof,
        speed: 1.0,
        k1: 0.0075,
        shoulder: Some((0.06, 0.03)),
        hd_scale: 1.0,
    },
    Scene {
        name: "soft neck on a shoulder at 0.06 rad, 0.7x speed",
        truth_model: BLADE_ON_SHOULDER,
        kind: ModelKind::Blade2dof,
        speed: 0.7,
        k1: 0.0075,
        shoulder: Some((0.06, 0.03)),
        hd_scale: 1.0,
    },
    // The issue's scene: a free neck a quarter of the sample's resting on the shoulder, contact
    // stiffness 3.25x the free one (measured: 2 switches).
    Scene {
        name: "soft neck on a shoulder at 0.025 rad",
        truth_model: BLADE_ON_SHOULDER,
        kind: ModelKind::Blade2dof,
        speed: 1.0,
        k1: 0.0075,
        shoulder: Some((0.025, 0.024375)),
        hd_scale: 1.0,
    },
    Scene {
        name: "soft neck on a shoulder at 0.025 rad, 0.7x speed",
        truth_model: BLADE_ON_SHOULDER,
        kind: ModelKind::Blade2dof,
        speed: 0.7,
        k1: 0.0075,
        shoulder: Some((0.025, 0.024375)),
        hd_scale: 1.0,
    },
    // The sample's neck with a shoulder near its largest |θ|: measured, 68 switches, crossed often.
    Scene {
        name: "sample neck, shoulder at 0.12 rad (crossed often)",
        truth_model: BLADE_ON_SHOULDER,
        kind: ModelKind::Blade2dof,
        speed: 1.0,
        k1: 0.029748408887917077,
        shoulder: Some((0.12, 0.09)),
        hd_scale: 1.0,
    },
    // The head's motion alone: the 1-DOF head model, neck and lip locked to it. With the sample's
    // preload it loses contact at the flip (measured: N ≤ 0 at 1.824 s; with 2× the preload at
    // 2.340 s); with 3× it keeps contact through the window (40 transitions).
    Scene {
        name: "head-only motion, 3x preload",
        truth_model: HEAD,
        kind: ModelKind::Head1dof,
        speed: 1.0,
        k1: 0.029748408887917077,
        shoulder: None,
        hd_scale: 3.0,
    },
    // The issue's own description: a free neck a quarter of the sample's resting on a shoulder at
    // 0.08 rad (the free neck's |θ| runs to 0.24 rad), contact stiffness 3.25x the free one. Last,
    // so the scenes before it keep their noise seeds.
    Scene {
        name: "soft neck resting on a shoulder at 0.08 rad",
        truth_model: BLADE_ON_SHOULDER,
        kind: ModelKind::Blade2dof,
        speed: 1.0,
        k1: 0.0075,
        shoulder: Some((0.08, 0.024375)),
        hd_scale: 1.0,
    },
];

pub fn truth_params(s: &Scene) -> BladeParams {
    let mut p = true_blade();
    p.drive_omega_rad_per_s *= s.speed;
    p.k1_nm_per_rad = s.k1;
    p.hd_m *= s.hd_scale;
    p.shoulder = s.shoulder.map(|(theta, k1c)| Shoulder {
        contact_angle_rad: theta,
        k1_contact_nm_per_rad: k1c,
    });
    p
}

/// Writes the scene's recording (noise and drops) and job; returns the job's path and how many
/// shoulder switches the recording has.
pub fn write_scene(
    dir: &std::path::Path,
    i: usize,
    s: &Scene,
) -> Result<(std::path::PathBuf, usize), String> {
    let truth = truth_params(s);
    let (t0, t1) = default_window(&truth);
    let times = frame_times(t0, t1, 1e4);
    let sim = simulate_model(
        s.kind,
        &truth,
        (t0, *times.last().unwrap()),
        &times,
        &SolverOptions {
            rtol: 1e-10,
            atol: 1e-12,
            ..SolverOptions::default()
        },
        StickForm::Reduced,
    )
    .map_err(|e| format!("cannot be simulated: {e}"))?;
    let mut rng = rand::rngs::StdRng::seed_from_u64(4000 + i as u64);
    let noise = Normal::new(0.0, 0.1).unwrap();
    let rec = dir.join(format!("scene{i}_xypts.csv"));
    write_dltdv(&rec, &sim, &mut || noise.sample(&mut rng));
    // Drops: 1 % of the frames, in runs of 1–3, written as DLTdv writes a lost point (NaN).
    let text = std::fs::read_to_string(&rec).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let frames = lines.len() - 1;
    let mut dropped = 0;
    while dropped < frames / 100 {
        let start = 1 + rng.random_range(10..frames - 10);
        let len = rng.random_range(1..=3);
        for line in lines.iter_mut().skip(start).take(len) {
            *line = "NaN,NaN,NaN,NaN".into();
        }
        dropped += len;
    }
    std::fs::write(&rec, lines.join("\n") + "\n").unwrap();
    // The job: the main job's, with this scene's drive in its blade and its own truth.
    let mut blade = true_blade();
    blade.drive_omega_rad_per_s = truth.drive_omega_rad_per_s;
    blade.hd_m = truth.hd_m;
    std::fs::write(
        dir.join(format!("blade{i}.toml")),
        toml::to_string(&blade).unwrap(),
    )
    .unwrap();
    let (a, b, c) = match truth.friction {
        FrictionLaw::Exponential { a, b_s_per_m, c } => (a, b_s_per_m, c),
        _ => panic!("the sample's friction law is exponential"),
    };
    let (theta, k1c) = s.shoulder.unwrap_or((f64::NAN, f64::NAN));
    std::fs::write(
        dir.join(format!("truth{i}.json")),
        format!(
            "{{\"A\": {a}, \"B\": {b}, \"C\": {c}, \"k1\": {}, \"k1c\": {}, \"theta_c\": {}}}",
            s.k1,
            if k1c.is_nan() {
                "null".into()
            } else {
                k1c.to_string()
            },
            if theta.is_nan() {
                "null".into()
            } else {
                theta.to_string()
            },
        ),
    )
    .unwrap();
    let keys = if s.shoulder.is_some() {
        "A = \"/A\", B = \"/B\", C = \"/C\", k1 = \"/k1\", k1c = \"/k1c\", theta_c = \"/theta_c\""
    } else {
        "A = \"/A\", B = \"/B\", C = \"/C\", k1 = \"/k1\""
    };
    let job = format!(
        r#"name = "scene{i}"
blade = "blade{i}.toml"
{recording}{spectrum}[solver]
rtol = 1e-8
atol = 1e-10
[fit]
particles = 24
swarm_iterations = 25
polish_iterations = 60
seed = 1
restarts = 5
swarm_rtol = 1e-6
models = ["head1dof", "blade2dof", "blade2dof+shoulder"]
[fit.uncertainty]
method = "laplace"
[fit.shoulder]
k1c = [0.005, 0.15]
theta_c = [0.02, 0.2]
[fit.parameters]
A = [0.2, 1.5]
B = [10.0, 300.0]
C = [0.1, 1.0]
k1 = [0.005, 0.15]
[truth]
json = "truth{i}.json"
keys = {{ {keys} }}
"#,
        recording = dltdv_recording(&format!("scene{i}_xypts.csv"), t0),
        spectrum = spectrum_bands(&[("low", [30.0, 300.0], 4096), ("high", [500.0, 5000.0], 512)]),
    );
    let path = dir.join(format!("scene{i}.toml"));
    std::fs::write(&path, job).unwrap();
    Ok((path, sim.switches.len()))
}

/// ln L of the recording at the truth, nats: the true model's likelihood (its job's, spectral
/// terms) at the parameters that made the recording, simulated at the job's tolerance. A fit whose
/// ln L is below it stopped short of the truth's likelihood (a search that missed); one above it
/// found parameters the recording likes better than the truth (the recording does not determine
/// them that closely).
pub fn log_likelihood_at_truth(job: &LoadedJob, s: &Scene) -> Result<f64, String> {
    let p = wiperlab::search::problem_for(job, s.truth_model).map_err(|e| e.to_string())?;
    let lik = p.likelihood.as_ref().map_err(|e| e.to_string())?;
    let sim = p.simulate(&truth_params(s)).map_err(|e| e.to_string())?;
    let parts = lik.nll(&p, &sim).map_err(|e| e.to_string())?;
    Ok(-parts.total())
}
