//! The two comparison methods of the work–precision study (`wiperlab bench`): a Moreau–Jean-type
//! semi-implicit time-stepping scheme and a smoothed-friction ODE, for the belt oscillator and the
//! blade. The event-driven integrator ([`super::hybrid`]) is the method wiperlab uses; these exist to
//! measure it against what users would otherwise write.
//!
//! **Moreau–Jean (semi-implicit Euler on velocity level).** Per step of size `h` from `(t_n, q_n,
//! u_n)`: the one-contact friction problem is solved exactly at velocity level. First the force that
//! makes the slip velocity zero at `t_{n+1}` is computed (for the blade with the joint solve of
//! `(θ̈, φ̈, N, f)`, physics.md §1.8); if it lies inside the static cone `|f| ≤ μ_s N` the step
//! sticks, otherwise the contact slips against it with `f = −s·μ_d(|γ_n|)·N` (the continuous part
//! of the law explicit, as in Leine's decomposition, physics.md §1.3 and §1.7). Then
//! `u_{n+1} = u_n + h·a` and `q_{n+1} = q_n + h·u_{n+1}`. It never misses or mislocates a transition
//! by more than a step, and converges at first order (Acary & Brogliato 2008; Leine's ENOC-2024
//! `dae_semi_implicit_euler.m`).
//!
//! **Smoothed friction.** The set-valued law is replaced by `f = −tanh(γ/ε)·μ_d(|γ|)·N` and the
//! resulting (stiff for small ε) ODE is integrated with DOPRI5 at a fixed tolerance. The stick phase
//! becomes a slow creep and departures shift by O(√ε) (physics.md §1.7).

use super::hybrid::{ModelFault, Phase, Stats};
use super::rk;
use crate::model::belt::Belt;
use crate::model::blade::Blade;
use crate::model::stick_slip::LinearSystem;
use crate::{Error, Result};

/// A model that both comparison methods can integrate. State as in its [`super::hybrid::StickSlipModel`]
/// implementation, with every component integrated (the blade's full `[θ, φ, θ̇, φ̇]`).
pub trait NonsmoothModel<const N: usize>: Sync {
    /// One Moreau–Jean step of size `h` from `(t, y)`; updates `y` and returns the step's phase.
    fn moreau_step(
        &self,
        t: f64,
        h: f64,
        y: &mut [f64; N],
    ) -> std::result::Result<Phase, ModelFault>;
    /// Right-hand side of the smoothed-friction ODE with regularisation speed `eps_m_per_s`.
    fn smoothed_rhs(
        &self,
        eps_m_per_s: f64,
        t: f64,
        y: &[f64; N],
        dy: &mut [f64; N],
    ) -> std::result::Result<(), ModelFault>;
    /// Slip velocity of the contact, m/s.
    fn slip_speed(&self, t: f64, y: &[f64; N]) -> f64;
    /// The observed coordinate compared in the work–precision study (belt: x; blade: tip v3), m.
    fn observable(&self, t: f64, y: &[f64; N]) -> f64;
}

/// Output of a comparison run: the observable at `sample_times`, the phase changes and counters.
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    pub t_s: Vec<f64>,
    pub observable_m: Vec<f64>,
    /// Phase changes `(t, from, to)`.
    pub transitions: Vec<(f64, Phase, Phase)>,
    pub stats: Stats,
}

fn sim_err<const N: usize>(
    t: f64,
    y: &[f64; N],
    cause: impl Into<super::error::StopCause>,
) -> Error {
    super::error::SimulationError::new(t, cause, format!("{y:?}")).into()
}

/// Moreau–Jean time-stepping with fixed step `h_s` over `[t0, t1]`, starting from `y0` (any phase;
/// the first step decides it). The observable is linearly interpolated to `sample_times`.
///
/// # Errors
/// [`super::SettingError`] for a non-positive step; [`super::SimulationError`] on contact loss or a singular
/// system.
pub fn moreau_jean<M: NonsmoothModel<N>, const N: usize>(
    model: &M,
    t0: f64,
    t1: f64,
    y0: [f64; N],
    h_s: f64,
    sample_times: &[f64],
) -> Result<Trajectory> {
    if !(h_s > 0.0 && h_s.is_finite()) {
        return Err(super::SettingError::TimeStep { h_s }.into());
    }
    let n_steps = ((t1 - t0) / h_s).ceil() as usize;
    let mut out = Trajectory::default();
    let mut y = y0;
    let mut obs_prev = model.observable(t0, &y);
    let mut phase: Option<Phase> = None;
    let mut next = sample_times.partition_point(|&s| s < t0);
    for i in 0..n_steps {
        let t = t0 + i as f64 * h_s;
        let t_next = (t0 + (i + 1) as f64 * h_s).min(t1);
        let h = t_next - t;
        let p = model
            .moreau_step(t, h, &mut y)
            .map_err(|e| sim_err(t, &y, e))?;
        out.stats.steps += 1;
        out.stats.rhs_evals += 1;
        if let Some(q) = phase
            && q != p
        {
            out.transitions.push((t_next, q, p));
        }
        phase = Some(p);
        let obs = model.observable(t_next, &y);
        while next < sample_times.len() && sample_times[next] <= t_next {
            let s = sample_times[next];
            let w = (s - t) / h;
            out.t_s.push(s);
            out.observable_m.push(obs_prev + w * (obs - obs_prev));
            next += 1;
        }
        obs_prev = obs;
    }
    Ok(out)
}

/// The smoothed-friction ODE integrated by DOPRI5 at `rtol` (atol = rtol·1e-2 in state units) over
/// `[t0, t1]`. A phase is read off the slip speed: stick while `|γ| ≤ 2ε` (where `tanh` reaches
/// 0.96 of the saturated force), slip± outside; its changes are located by linear interpolation of
/// `|γ| − 2ε` between accepted steps.
///
/// # Errors
/// [`super::SimulationError`] if the step size collapses or the right-hand side fails.
pub fn smoothed<M: NonsmoothModel<N>, const N: usize>(
    model: &M,
    eps_m_per_s: f64,
    t0: f64,
    t1: f64,
    y0: [f64; N],
    rtol: f64,
    sample_times: &[f64],
) -> Result<Trajectory> {
    let mut out = Trajectory::default();
    let mut rhs =
        |t: f64, y: &[f64; N], dy: &mut [f64; N]| model.smoothed_rhs(eps_m_per_s, t, y, dy);
    let classify = |g: f64| smoothed_phase(g, eps_m_per_s);
    let mut t = t0;
    let mut y = y0;
    let mut f = [0.0; N];
    rhs(t, &y, &mut f).map_err(|e| sim_err(t, &y, e))?;
    out.stats.rhs_evals += 1;
    let mut g = model.slip_speed(t, &y);
    let mut phase = classify(g);
    let mut h = 1e-6 * (t1 - t0);
    let mut next = sample_times.partition_point(|&s| s < t0);
    while t < t1 {
        h = h.min(t1 - t);
        if h < 1e-15 * t.abs().max(1.0) {
            // Smoothed friction is stiff near zero slip speed.
            return Err(sim_err(
                t,
                &y,
                super::error::StopCause::StepSizeCollapse {
                    h_s: h,
                    phase: None,
                },
            ));
        }
        let a = match rk::attempt(&mut rhs, t, &y, &f, h, rtol, rtol * 1e-2) {
            Ok(a) => a,
            Err(_) => {
                h *= 0.25;
                out.stats.rejected += 1;
                continue;
            }
        };
        out.stats.rhs_evals += 6;
        if a.err > 1.0 {
            out.stats.rejected += 1;
            h = rk::next_step(h, a.err).min(0.9 * h);
            continue;
        }
        out.stats.steps += 1;
        let t_new = t + h;
        while next < sample_times.len() && sample_times[next] <= t_new {
            let s = sample_times[next];
            let ys = a.dense.eval(s);
            out.t_s.push(s);
            out.observable_m.push(model.observable(s, &ys));
            next += 1;
        }
        let g_new = model.slip_speed(t_new, &a.y_new);
        let p_new = classify(g_new);
        if p_new != phase {
            let t_cross = crossing_time(t, h, g, g_new, eps_m_per_s);
            out.transitions.push((t_cross, phase, p_new));
            phase = p_new;
        }
        g = g_new;
        t = t_new;
        y = a.y_new;
        f = a.f_new;
        h = rk::next_step(h, a.err);
    }
    Ok(out)
}

/// The phase [`smoothed`] reads off the slip speed `g`: stick while `|g| ≤ 2ε`, slip± outside.
fn smoothed_phase(g: f64, eps_m_per_s: f64) -> Phase {
    if g.abs() <= 2.0 * eps_m_per_s {
        Phase::Stick
    } else {
        Phase::slip(g)
    }
}

/// Time of the crossing of |γ| = 2ε between the step ends `(t, g)` and `(t + h, g_new)`, by
/// linear interpolation of `|γ| − 2ε`; the step's end when the two are equal.
fn crossing_time(t: f64, h: f64, g: f64, g_new: f64, eps_m_per_s: f64) -> f64 {
    let (ga, gb) = (g.abs() - 2.0 * eps_m_per_s, g_new.abs() - 2.0 * eps_m_per_s);
    let w = if (gb - ga).abs() > 0.0 {
        ga / (ga - gb)
    } else {
        1.0
    };
    t + w.clamp(0.0, 1.0) * h
}

impl NonsmoothModel<2> for Belt {
    fn moreau_step(
        &self,
        _t: f64,
        h: f64,
        y: &mut [f64; 2],
    ) -> std::result::Result<Phase, ModelFault> {
        let (m, k, c, vb, n) = (
            self.mass_kg,
            self.k_n_per_m,
            self.c_ns_per_m,
            self.v_belt_m_per_s,
            self.normal_n,
        );
        // Friction that makes ẋ_{n+1} = v_b.
        let f_stick = m * (vb - y[1]) / h + k * y[0] + c * y[1];
        let (f, phase) = if f_stick.abs() <= self.law.mu_static() * n {
            (f_stick, Phase::Stick)
        } else {
            let s = -f_stick.signum();
            (-s * self.law.mu_slip(y[1] - vb) * n, Phase::slip(s))
        };
        y[1] += h * (-k * y[0] - c * y[1] + f) / m;
        if phase == Phase::Stick {
            y[1] = vb;
        }
        y[0] += h * y[1];
        Ok(phase)
    }

    fn smoothed_rhs(
        &self,
        eps: f64,
        _t: f64,
        y: &[f64; 2],
        dy: &mut [f64; 2],
    ) -> std::result::Result<(), ModelFault> {
        let g = y[1] - self.v_belt_m_per_s;
        let f = -(g / eps).tanh() * self.law.mu_slip(g) * self.normal_n;
        dy[0] = y[1];
        dy[1] = (-self.k_n_per_m * y[0] - self.c_ns_per_m * y[1] + f) / self.mass_kg;
        Ok(())
    }

    fn slip_speed(&self, _t: f64, y: &[f64; 2]) -> f64 {
        y[1] - self.v_belt_m_per_s
    }

    fn observable(&self, _t: f64, y: &[f64; 2]) -> f64 {
        y[0]
    }
}

impl NonsmoothModel<4> for Blade {
    fn moreau_step(
        &self,
        t: f64,
        h: f64,
        y: &mut [f64; 4],
    ) -> std::result::Result<Phase, ModelFault> {
        let rows = self.rows_with_kinematics(t, y, self.params.touches_shoulder(y[0]));
        let (a3, af, b3) = (rows.a, rows.af, rows.b);
        let (l1, l2) = (self.params.l1_m, self.params.l2_m);
        let [cth, cph] = rows.cos;
        let vd_next = self.drive(t + h).1;
        // Stick: tip velocity zero at t + h, i.e. l1 cθ θ̈ + l2 cφ φ̈ = −γ*/h with γ* the tip
        // velocity at t + h without this step's accelerations.
        let gamma_free = vd_next + l1 * cth * y[2] + l2 * cph * y[3];
        let z = self
            .solve_with_tip_constraint([cth, cph], &a3, &af, &b3, -gamma_free / h)
            .ok_or(ModelFault::Singular {
                system: LinearSystem::BladeStick,
            })?;
        let mu_s = self.params.friction.mu_static();
        let (acc, normal, phase) = if z[2] > 0.0 && z[3].abs() <= mu_s * z[2] {
            ([z[0], z[1]], z[2], Phase::Stick)
        } else {
            let s = -z[3].signum();
            let mu = self.params.friction.mu_slip(self.tip_velocity(t, y));
            let mut a = a3;
            for i in 0..3 {
                a[(i, 2)] += af[i] * (-s * mu);
            }
            let zs = a.lu().solve(&b3).ok_or(ModelFault::Singular {
                system: LinearSystem::BladeSlip,
            })?;
            ([zs[0], zs[1]], zs[2], Phase::slip(s))
        };
        if normal <= 0.0 {
            return Err(ModelFault::ContactLost { normal_n: normal });
        }
        y[2] += h * acc[0];
        y[3] += h * acc[1];
        y[0] += h * y[2];
        y[1] += h * y[3];
        Ok(phase)
    }

    fn smoothed_rhs(
        &self,
        eps: f64,
        t: f64,
        y: &[f64; 4],
        dy: &mut [f64; 4],
    ) -> std::result::Result<(), ModelFault> {
        let (a3, af, b3) = self.rows(t, y, self.params.touches_shoulder(y[0]));
        let g = self.tip_velocity(t, y);
        let coef = -(g / eps).tanh() * self.params.friction.mu_slip(g);
        let mut a = a3;
        for i in 0..3 {
            a[(i, 2)] += af[i] * coef;
        }
        let z = a.lu().solve(&b3).ok_or(ModelFault::Singular {
            system: LinearSystem::Smoothed,
        })?;
        if z[2] <= 0.0 {
            return Err(ModelFault::ContactLost { normal_n: z[2] });
        }
        dy[0] = y[2];
        dy[1] = y[3];
        dy[2] = z[0];
        dy[3] = z[1];
        Ok(())
    }

    fn slip_speed(&self, t: f64, y: &[f64; 4]) -> f64 {
        self.tip_velocity(t, y)
    }

    fn observable(&self, t: f64, y: &[f64; 4]) -> f64 {
        self.tip_position(t, y)
    }
}
