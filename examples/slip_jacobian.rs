//! Eigenvalues of the slip right-hand side's Jacobian (forward differences) along the true blade's
//! default window (`data/reversal/blade_true.toml`, DOP853 at rtol 1e-10): every 0.05 s of slip,
//! the time, the step that ended there and each eigenvalue with |h·λ| (docs/validation.md,
//! "DOP853 against DOPRI5"):
//!
//! ```sh
//! cargo run --release --example slip_jacobian
//! ```
use wiperlab::model::{BladeParams, StickForm, blade::Blade};
use wiperlab::simulate::blade::default_window;
use wiperlab::simulate::hybrid::{HybridSolver, Mode, StickSlipModel, StopReason};
use wiperlab::simulate::{Method, Phase, SolverOptions};

fn main() {
    let text = std::fs::read_to_string("data/reversal/blade_true.toml").expect("blade file");
    let p: BladeParams = toml::from_str(&text).expect("blade parameters");
    let blade = Blade::new(p, StickForm::Reduced);
    let (t0, t1) = default_window(&p);
    let y0 = blade.slip_equilibrium(t0).expect("slip equilibrium");
    let opts = SolverOptions {
        method: Method::Dop853,
        ..SolverOptions::default()
    };
    let mode0 = Mode::new(Phase::SlipPos, 0.0);
    let mut s = HybridSolver::new(&blade, t0, y0, mode0, t1, &opts).expect("solver");
    let (mut t_prev, mut next) = (t0, 1.0);
    loop {
        let r = s.step().expect("step");
        let (t, y, mode) = s.current();
        let h = t - t_prev;
        t_prev = t;
        if matches!(r, StopReason::StopTime { .. }) {
            break;
        }
        if t < next || mode.phase == Phase::Stick {
            continue;
        }
        next += 0.05;
        let mut f0 = [0.0; 4];
        blade.rhs(&mode, t, &y, &mut f0).expect("rhs");
        let mut j = nalgebra::Matrix4::<f64>::zeros();
        for c in 0..4 {
            let mut yp = y;
            let d = 1e-7 * y[c].abs().max(1e-6);
            yp[c] += d;
            let mut f1 = [0.0; 4];
            blade.rhs(&mode, t, &yp, &mut f1).expect("rhs");
            for r in 0..4 {
                j[(r, c)] = (f1[r] - f0[r]) / d;
            }
        }
        let ev: Vec<String> = j
            .complex_eigenvalues()
            .iter()
            .map(|e| format!("{:.0}{:+.0}i |hl|={:.2}", e.re, e.im, h * e.norm()))
            .collect();
        println!("t {t:.3} h {h:.3e} {:?}: {}", mode.phase, ev.join(", "));
    }
}
