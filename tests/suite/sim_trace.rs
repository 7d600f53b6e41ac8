//! `wiperlab simulate`'s trace.csv carries the model's state and contact forces; these tests check
//! them on the written file against physics the model's code does not supply:
//! - the friction law of the seed paper (/work/shared/seed/wiper-reversal.md, eq. 4 in slip,
//!   eq. 5 in stick), evaluated here from the blade file's A, B, C;
//! - the normal force from Newton's law for the whole blade in the vertical (physics.md §2.3:
//!   N = k0(h_d − u) − c0·u̇ + Σ mᵢ·ÿᵢ over the head and the rods' centres of mass), with the
//!   accelerations taken by finite differences of the written positions and angles;
//! - the written rates θ̇, φ̇ against central differences of θ, φ, whose error must fall as h²
//!   (halving the sample interval divides it by ≈ 4).

use crate::common::{root, s, temp_dir, wiperlab};

use std::collections::BTreeMap;
use std::path::Path;

/// The written trace: numeric columns by name, the phase labels, the transition times.
struct Written {
    col: BTreeMap<String, Vec<f64>>,
    phase: Vec<String>,
    transitions_s: Vec<f64>,
}

impl Written {
    fn c(&self, name: &str) -> &[f64] {
        self.col
            .get(name)
            .unwrap_or_else(|| panic!("trace.csv has no column {name}"))
    }

    /// Whether the stencil k−1, k, k+1 lies inside one phase segment (no transition in it).
    fn smooth_at(&self, k: usize) -> bool {
        let t = self.c("t_s");
        k >= 1
            && k + 1 < t.len()
            && self.phase[k - 1] == self.phase[k]
            && self.phase[k + 1] == self.phase[k]
            && !self
                .transitions_s
                .iter()
                .any(|&te| te >= t[k - 1] && te <= t[k + 1])
    }
}

fn simulate(dir: &Path, extra: &[&str]) -> Written {
    let blade = root().join("data/reversal/blade_true.toml");
    wiperlab(["simulate", s(&blade)])
        .args(extra)
        .args(["--out-dir", s(dir)])
        .assert()
        .success();
    let text = std::fs::read_to_string(dir.join("trace.csv")).expect("trace.csv");
    let mut lines = text.lines();
    let names: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_string)
        .collect();
    let mut col: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let mut phase = Vec::new();
    for l in lines {
        for (name, cell) in names.iter().zip(l.split(',')) {
            if name == "phase" {
                phase.push(cell.to_string());
            } else {
                let v: f64 = cell.parse().unwrap_or_else(|_| panic!("{name}: {cell:?}"));
                col.entry(name.clone()).or_default().push(v);
            }
        }
    }
    let tr = std::fs::read_to_string(dir.join("transitions.csv")).expect("transitions.csv");
    let transitions_s = tr
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().expect("t_s"))
        .collect();
    Written {
        col,
        phase,
        transitions_s,
    }
}

fn blade() -> toml::Value {
    toml::from_str(
        &std::fs::read_to_string(root().join("data/reversal/blade_true.toml")).expect("blade"),
    )
    .expect("TOML")
}

fn num(v: &toml::Value, key: &str) -> f64 {
    v[key]
        .as_float()
        .unwrap_or_else(|| panic!("blade file: {key}"))
}

#[test]
fn trace_has_the_model_state_columns_with_units() {
    let dir = temp_dir("columns");
    let w = simulate(dir.path(), &["--window", "1.83,1.85"]);
    for c in [
        "t_s",
        "head_x_m",
        "head_y_m",
        "tip_x_m",
        "tip_y_m",
        "theta_rad",
        "phi_rad",
        "theta_dot_rad_per_s",
        "phi_dot_rad_per_s",
        "v3_dot_m_per_s",
        "normal_force_n",
        "friction_force_n",
    ] {
        let v = w.c(c);
        assert!(
            v.iter().all(|x| x.is_finite()),
            "{c} has a non-finite value"
        );
    }
    let n = w.c("t_s").len();
    assert_eq!(w.phase.len(), n);
    // Before the reversal at π/ω ≈ 1.887 s the tip slips forward and sticks.
    for p in ["slip+", "stick"] {
        assert!(
            w.phase.iter().any(|q| q == p),
            "no {p} sample in 1.83–1.85 s"
        );
    }
    assert!(
        w.phase
            .iter()
            .all(|q| ["slip+", "slip-", "stick"].contains(&q.as_str()))
    );
}

/// Seed eq. (4): in slip f = −sign(v̇3)(A e^(−B|v̇3|) + C)·N; eq. (5): in stick |f| ≤ (A + C)·N and
/// the tip does not move (v̇3 = 0, v3 constant through the stick phase). N > 0 throughout (the tip
/// stays on the glass, the paper's assumption).
#[test]
fn friction_force_obeys_the_papers_law_in_slip_and_its_bound_in_stick() {
    let dir = temp_dir("friction");
    let w = simulate(dir.path(), &[]);
    let b = blade();
    let fr = &b["friction"];
    let (a, bb, c) = (num(fr, "a"), num(fr, "b_s_per_m"), num(fr, "c"));
    let (n, f, vd, v3) = (
        w.c("normal_force_n"),
        w.c("friction_force_n"),
        w.c("v3_dot_m_per_s"),
        w.c("tip_x_m"),
    );
    for p in ["slip+", "slip-", "stick"] {
        assert!(
            w.phase.iter().any(|q| q == p),
            "no {p} sample in the window"
        );
    }
    let (mut slip, mut stick, mut worst_slip, mut worst_ratio) = (0, 0, 0.0f64, 0.0f64);
    for k in 0..n.len() {
        assert!(n[k] > 0.0, "N = {} at t = {}", n[k], w.c("t_s")[k]);
        match w.phase[k].as_str() {
            "stick" => {
                stick += 1;
                worst_ratio = worst_ratio.max(f[k].abs() / ((a + c) * n[k]));
                assert!(
                    f[k].abs() <= (a + c) * n[k] * (1.0 + 1e-12),
                    "stick at t = {}: |f| = {} > (A + C) N = {}",
                    w.c("t_s")[k],
                    f[k].abs(),
                    (a + c) * n[k]
                );
                assert!(vd[k].abs() <= 1e-12, "stick: v̇3 = {}", vd[k]);
                let t = w.c("t_s");
                let same_stick = k > 0
                    && w.phase[k - 1] == "stick"
                    && !w
                        .transitions_s
                        .iter()
                        .any(|&te| te >= t[k - 1] && te <= t[k]);
                // v3 = v + l1 sin θ + l2 sin φ held at its anchor, to rounding (≈ 0.2 m, ulp 3e-17 m).
                if same_stick {
                    assert!(
                        (v3[k] - v3[k - 1]).abs() <= 1e-14,
                        "the tip moved in stick: {} m at t = {}",
                        v3[k] - v3[k - 1],
                        t[k]
                    );
                }
            }
            p => {
                slip += 1;
                let s = if p == "slip+" { 1.0 } else { -1.0 };
                // The slip direction is the tip velocity's (up to rounding right after a transition).
                assert!(s * vd[k] > -1e-12, "{p} with v̇3 = {}", vd[k]);
                let want = -s * (a * (-bb * vd[k].abs()).exp() + c) * n[k];
                let rel = (f[k] - want).abs() / want.abs();
                worst_slip = worst_slip.max(rel);
                assert!(
                    rel <= 1e-12,
                    "slip at t = {}: f = {} against eq. (4) {want}",
                    w.c("t_s")[k],
                    f[k]
                );
            }
        }
    }
    assert!(
        slip > 1000 && stick > 100,
        "{slip} slip, {stick} stick samples"
    );
    println!(
        "{slip} slip samples: largest relative deviation from eq. (4) {worst_slip:.2e}; {stick} stick samples: largest |f|/((A+C)N) {worst_ratio:.4}"
    );
}

/// Largest deviations at the samples of the coarse run (every other sample of the fine run) where
/// both stencils are smooth: (θ̇ against the central difference of θ, φ̇ against φ's, N against
/// Newton's law with finite-difference accelerations).
fn fd_errors(w: &Written, step: usize, common: &[usize]) -> [f64; 3] {
    let b = blade();
    let (l1, l2) = (num(&b, "l1_m"), num(&b, "l2_m"));
    let (m_head, m1, m2) = (
        num(&b, "head_mass_kg"),
        num(&b, "neck_mass_kg"),
        num(&b, "lip_mass_kg"),
    );
    let (d1, d2) = (num(&b, "neck_com_m"), num(&b, "lip_com_m"));
    let (k0, c0, hd) = (
        num(&b, "k0_n_per_m"),
        num(&b, "c0_ns_per_m"),
        num(&b, "hd_m"),
    );
    let t = w.c("t_s");
    let (th, ph) = (w.c("theta_rad"), w.c("phi_rad"));
    let (thd, phd) = (w.c("theta_dot_rad_per_s"), w.c("phi_dot_rad_per_s"));
    let (head_y, n) = (w.c("head_y_m"), w.c("normal_force_n"));
    // Vertical positions (y up) of the head and the neck's and lip's centres of mass.
    let y_head = |k: usize| head_y[k];
    let y_neck = |k: usize| head_y[k] - d1 * th[k].cos();
    let y_lip = |k: usize| head_y[k] - l1 * th[k].cos() - d2 * ph[k].cos();
    let mut e = [0.0f64; 3];
    for &kc in common {
        let k = kc * step;
        let h = 0.5 * (t[k + 1] - t[k - 1]);
        let dd = |y: &dyn Fn(usize) -> f64| (y(k + 1) - 2.0 * y(k) + y(k - 1)) / (h * h);
        e[0] = e[0].max((thd[k] - (th[k + 1] - th[k - 1]) / (2.0 * h)).abs());
        e[1] = e[1].max((phd[k] - (ph[k + 1] - ph[k - 1]) / (2.0 * h)).abs());
        let u = -head_y[k];
        let u_dot = l1 * th[k].sin() * thd[k] + l2 * ph[k].sin() * phd[k];
        let n_newton =
            k0 * (hd - u) - c0 * u_dot + m_head * dd(&y_head) + m1 * dd(&y_neck) + m2 * dd(&y_lip);
        e[2] = e[2].max((n_newton - n[k]).abs());
    }
    e
}

#[test]
fn rates_and_normal_force_match_finite_differences_to_second_order() {
    let (coarse_dir, fine_dir) = (temp_dir("fd1"), temp_dir("fd2"));
    let args = |fps: &'static str| ["--window", "1.83,1.85", "--fps", fps, "--rtol", "1e-11"];
    let coarse = simulate(coarse_dir.path(), &args("100000"));
    let fine = simulate(fine_dir.path(), &args("200000"));
    let nc = coarse.c("t_s").len();
    assert_eq!(fine.c("t_s").len(), 2 * nc - 1);
    let common: Vec<usize> = (1..nc - 1)
        .filter(|&k| coarse.smooth_at(k) && fine.smooth_at(2 * k))
        .collect();
    assert!(common.len() > nc / 2, "{} of {nc} samples", common.len());
    let ec = fd_errors(&coarse, 1, &common);
    let ef = fd_errors(&fine, 2, &common);
    let n_max = coarse
        .c("normal_force_n")
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let thd_max = coarse
        .c("theta_dot_rad_per_s")
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    println!(
        "{} samples; h = 10 µs: θ̇ {:.3e} rad/s, φ̇ {:.3e} rad/s, N {:.3e} N; h = 5 µs: {:.3e}, {:.3e}, {:.3e} (max |θ̇| {thd_max:.3}, max N {n_max:.3})",
        common.len(),
        ec[0],
        ec[1],
        ec[2],
        ef[0],
        ef[1],
        ef[2]
    );
    for (i, what) in ["θ̇", "φ̇", "N"].iter().enumerate() {
        let ratio = ec[i] / ef[i];
        assert!(
            (3.0..=5.0).contains(&ratio),
            "{what}: halving h divides the error by {ratio:.2}, second order gives 4"
        );
    }
    assert!(ec[0] < 1e-3 * thd_max, "θ̇ error {} rad/s", ec[0]);
    assert!(ec[2] < 1e-2 * n_max, "N error {} N", ec[2]);
}
