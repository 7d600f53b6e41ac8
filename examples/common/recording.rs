//! What the recording-writing examples share: the shipped sample's true blade, its reversal window
//! simulated at a tighter tolerance than any fit, and its camera model (data/reversal/README.md,
//! "Camera and coordinates": 15 µm per pixel, origin (200, 300) px, y down; point 1 the head,
//! point 2 the lip tip) writing DLTdv8 `xypts.csv` text.

use std::fmt::Write as _;
use std::path::Path;
use wiperlab::model::{BladeParams, StickForm};
use wiperlab::simulate::blade::{
    BladeSimulation, ModelKind, default_window, simulate_blade, simulate_model,
};
use wiperlab::simulate::{Method, SolverOptions};

/// Metres per pixel and the pixel origin of the sample's camera.
const M_PER_PX: f64 = 1.5e-5;
const ORIGIN_PX: (f64, f64) = (200.0, 300.0);
/// The camera's horizontal origin on the model's x axis, m (the sample's `a`).
const X_ORIGIN_M: f64 = 0.1;
/// Frames per second of the written recordings.
pub const FPS: f64 = 10_000.0;

/// `data/reversal/blade_true.toml` under the crate root `root`.
#[allow(dead_code)] // not used by make_calibration
pub fn true_blade(root: &Path) -> BladeParams {
    toml::from_str(
        &std::fs::read_to_string(root.join("data/reversal/blade_true.toml"))
            .expect("read data/reversal/blade_true.toml"),
    )
    .expect("parse blade_true.toml")
}

/// `p`'s default reversal window at `fps_hz` frames/s by model `kind`, simulated with DOP853 at
/// rtol 1e-10, atol 1e-12 (the fits run DOPRI5 at looser tolerances: no model evaluation of a fit
/// reproduces it); with the first frame's time.
#[allow(dead_code)] // used by make_calibration only
pub fn simulate_model_window(
    kind: ModelKind,
    p: &BladeParams,
    fps_hz: f64,
) -> wiperlab::Result<(BladeSimulation, f64)> {
    let (t0, t1) = default_window(p);
    let n = ((t1 - t0) * fps_hz) as usize;
    let times: Vec<f64> = (0..n).map(|k| t0 + k as f64 / fps_hz).collect();
    let opts = SolverOptions {
        rtol: 1e-10,
        atol: 1e-12,
        method: Method::Dop853,
        ..SolverOptions::default()
    };
    let window = (t0, *times.last().expect("frames"));
    let sim = simulate_model(kind, p, window, &times, &opts, StickForm::Reduced)?;
    Ok((sim, t0))
}

/// `p`'s default reversal window at [`FPS`], simulated at rtol 1e-10, atol 1e-12 (no model
/// evaluation of a fit reproduces it bit for bit); with the first frame's time.
#[allow(dead_code)] // not used by make_calibration
pub fn simulate_window(p: &BladeParams) -> wiperlab::Result<(BladeSimulation, f64)> {
    let (t0, t1) = default_window(p);
    let n = ((t1 - t0) * FPS) as usize;
    let times: Vec<f64> = (0..n).map(|k| t0 + k as f64 / FPS).collect();
    let opts = SolverOptions {
        rtol: 1e-10,
        atol: 1e-12,
        ..SolverOptions::default()
    };
    let window = (t0, *times.last().expect("frames"));
    let sim = simulate_blade(p, window, &times, &opts, StickForm::Reduced)?;
    Ok((sim, t0))
}

/// The simulation as DLTdv8 text: `x_px = X0 + (x − a)/S`, `y_px = Y0 − y/S` (y down) for the head
/// (x = v, y = −u) and the lip tip (x = v3, y = −reach, the glass), `%.4f`. `noise_px(c, i)` is the
/// tracking noise (pixels) of column `c` (head x, head y, tip x, tip y) at frame `i`, drawn row by
/// row.
#[allow(dead_code)] // not every example including this file writes through the sample's camera
pub fn dltdv_text(sim: &BladeSimulation, noise_px: impl FnMut(usize, usize) -> f64) -> String {
    dltdv_text_at(sim, M_PER_PX, noise_px)
}

/// [`dltdv_text`] through a camera of `m_per_px` metres per pixel (the same origin); a NaN noise
/// writes `NaN`, DLTdv's lost point.
pub fn dltdv_text_at(
    sim: &BladeSimulation,
    m_per_px: f64,
    mut noise_px: impl FnMut(usize, usize) -> f64,
) -> String {
    let rows: Vec<[f64; 4]> = clean_px_rows(sim, m_per_px)
        .into_iter()
        .enumerate()
        .map(|(i, clean)| std::array::from_fn(|c| clean[c] + noise_px(c, i)))
        .collect();
    dltdv_text_of_rows(&rows)
}

/// The noiseless pixel coordinates of every frame through a camera of `m_per_px` metres per pixel:
/// `x_px = X0 + (x − a)/S`, `y_px = Y0 − y/S` (y down) for the head (x = v, y = −u) and the lip
/// tip (x = v3, y = −reach, the glass), columns head x, head y, tip x, tip y.
pub fn clean_px_rows(sim: &BladeSimulation, m_per_px: f64) -> Vec<[f64; 4]> {
    let px_x = |x: f64| ORIGIN_PX.0 + (x - X_ORIGIN_M) / m_per_px;
    let px_y = |y: f64| ORIGIN_PX.1 - y / m_per_px;
    (0..sim.t_s.len())
        .map(|i| {
            [
                px_x(sim.v_m[i]),
                px_y(-sim.u_m[i]),
                px_x(sim.v3_m[i]),
                px_y(-sim.reach_m),
            ]
        })
        .collect()
}

/// Pixel rows (head x, head y, tip x, tip y) as DLTdv8 text, `%.4f`, NaN for a lost point.
pub fn dltdv_text_of_rows(rows: &[[f64; 4]]) -> String {
    let mut csv = String::from("pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y\n");
    for r in rows {
        let row: Vec<String> = r.iter().map(|v| format!("{v:.4}")).collect();
        let _ = writeln!(csv, "{}", row.join(","));
    }
    csv
}
