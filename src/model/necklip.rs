//! The neck/lip model on a prescribed head: the high-frequency member of the model hierarchy.
//!
//! The head follows the drive `v(t)` horizontally, as in the full model, and a **prescribed**
//! vertical drop `u_p(t)` (for a fit: the recording's own head track, smoothed). The neck and lip
//! keep their two angles; the tip stays on the glass, so the head height
//! `u = l1(1 − cos θ) + l2(1 − cos φ)` must equal `u_p(t)`, and the normal force `N` is the
//! multiplier of that constraint. Equations: rows (1) and (2) of the full model ([`Blade`], seed
//! eqs. 1–2; they do not contain the head mass) with row (3), the head's vertical balance, replaced
//! by the constraint's second derivative
//! `l1 sin θ θ̈ + l2 sin φ φ̈ = ü_p − l1 cos θ θ̇² − l2 cos φ φ̇² − 2ω_B(u̇ − u̇_p) − ω_B²(u − u_p)`
//! (Baumgarte 1972, critical damping ω_B = 1e4 s⁻¹ as for stick, physics.md §0.3). Stick adds the
//! tip constraint (Baumgarte too): `[θ̈, φ̈, N, f]` from a 4×4 system.
//!
//! With the full model's own `u(t)` prescribed, this model reproduces the full model's θ and φ
//! (`tests/suite/necklip.rs`): the head's dynamics enter only through `u`. What it drops is the head's
//! response to the tip: the low component is imposed from the data, not explained, so the fit
//! compares it on the high band.
//!
//! **The flip.** The constraint's gradient `(l1 sin θ, l2 sin φ)` vanishes at upright, where `N` is
//! undetermined, so the model cannot pass the blade's flip at the reversal. With the recorded lean
//! `d = v3 − v` ([`PrescribedHead::with_lean`]) the window is cut at the flip
//! ([`PrescribedHead::segments`], a guard of [`FLIP_GUARD_OF_REACH`] of the reach around the sign
//! change of `d`) and the run after it starts from the state the tracks give
//! ([`NeckLip::state_from_tracks`]). On the sample's blade the guard is 20 ms, and the neck angle
//! after the flip stays within 2.8e-4 rad of the full model's (`tests/suite/necklip.rs`).

use super::TrackError;
use super::blade::{Blade, BladeParams, Dynamics, StickForm};
use super::stick_slip::{Contact, LinearSystem, LinkModel, Mode, ModelFault, StickSlipModel};
use super::trig;
use nalgebra::{Matrix3, Vector3};

/// Baumgarte gain of the head-height constraint, s⁻¹ (physics.md §0.3).
const OMEGA_B: f64 = 1e4;

/// A smoothed, uniformly sampled track `x(t)` with its first two derivatives, from samples.
///
/// Built from a (possibly noisy) uniformly sampled track by a local quadratic least-squares fit over
/// `2·half_width + 1` samples at each sample (Savitzky & Golay 1964, Anal. Chem. 36:1627), which
/// gives `u`, `u̇`, `ü` there; between samples see [`SmoothedTrack::at`]. Missing (NaN) samples are
/// skipped by the local fits.
#[derive(Debug, Clone)]
pub struct SmoothedTrack {
    t0_s: f64,
    dt_s: f64,
    half_width: usize,
    u: Vec<f64>,
    ud: Vec<f64>,
    udd: Vec<f64>,
}

impl SmoothedTrack {
    /// From samples `u_m[k]` at `t0_s + k·dt_s` (any unit; the derivatives are per second).
    ///
    /// # Errors
    /// [`TrackError::Gap`] when fewer than 3 finite samples fall in some local window (a gap
    /// longer than the window), [`TrackError::TooShort`] when the step or the samples are not
    /// usable.
    pub fn from_samples(
        t0_s: f64,
        dt_s: f64,
        u_m: &[f64],
        half_width: usize,
    ) -> Result<Self, TrackError> {
        if !(dt_s > 0.0 && dt_s.is_finite()) || u_m.len() < 2 * half_width + 1 || half_width == 0 {
            return Err(TrackError::TooShort {
                dt_s,
                samples: u_m.len(),
                window: 2 * half_width + 1,
            });
        }
        let n = u_m.len();
        let (mut u, mut ud, mut udd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for k in 0..n {
            let lo = k.saturating_sub(half_width);
            let hi = (k + half_width).min(n - 1);
            // Least squares for u ≈ c0 + c1 τ + c2 τ² with τ = (j − k)·dt.
            let mut ata = Matrix3::<f64>::zeros();
            let mut atb = Vector3::<f64>::zeros();
            let mut count = 0;
            for (j, &uj) in u_m.iter().enumerate().take(hi + 1).skip(lo) {
                if !uj.is_finite() {
                    continue;
                }
                let tau = (j as f64 - k as f64) * dt_s;
                let row = Vector3::new(1.0, tau, tau * tau);
                ata += row * row.transpose();
                atb += row * uj;
                count += 1;
            }
            let c =
                (count >= 3)
                    .then(|| ata.lu().solve(&atb))
                    .flatten()
                    .ok_or(TrackError::Gap {
                        t_s: t0_s + k as f64 * dt_s,
                    })?;
            u[k] = c[0];
            ud[k] = c[1];
            udd[k] = 2.0 * c[2];
        }
        Ok(SmoothedTrack {
            t0_s,
            dt_s,
            half_width,
            u,
            ud,
            udd,
        })
    }

    /// `(x, ẋ, ẍ)` at `t` (held constant beyond the samples).
    ///
    /// Between samples: the quintic Hermite interpolant of the local fits' `(x, ẋ, ẍ)` at both ends,
    /// so the three are one C² function and its derivatives (consistent for the constraint's
    /// Baumgarte terms; an inconsistent set made the integrator take ten times the steps).
    pub fn at(&self, t: f64) -> (f64, f64, f64) {
        let n = self.u.len();
        let x = ((t - self.t0_s) / self.dt_s).clamp(0.0, (n - 1) as f64);
        let k = (x.floor() as usize).min(n - 2);
        let s = x - k as f64;
        let h = self.dt_s;
        let (p0, p1) = (self.u[k], self.u[k + 1]);
        let (m0, m1) = (h * self.ud[k], h * self.ud[k + 1]);
        let (a0, a1) = (h * h * self.udd[k], h * h * self.udd[k + 1]);
        // p(s) = Σ c_i s^i with p, p', p'' matching (p0, m0, a0) at s = 0 and (p1, m1, a1) at s = 1.
        let c2 = 0.5 * a0;
        let c3 = 10.0 * (p1 - p0) - 6.0 * m0 - 4.0 * m1 - 1.5 * a0 + 0.5 * a1;
        let c4 = -15.0 * (p1 - p0) + 8.0 * m0 + 7.0 * m1 + 1.5 * a0 - a1;
        let c5 = 6.0 * (p1 - p0) - 3.0 * m0 - 3.0 * m1 - 0.5 * a0 + 0.5 * a1;
        let u = p0 + s * (m0 + s * (c2 + s * (c3 + s * (c4 + s * c5))));
        let ud = (m0 + s * (2.0 * c2 + s * (3.0 * c3 + s * (4.0 * c4 + s * 5.0 * c5)))) / h;
        let udd = (2.0 * c2 + s * (6.0 * c3 + s * (12.0 * c4 + s * 20.0 * c5))) / (h * h);
        (u, ud, udd)
    }
}

/// A track smoothed by a Gaussian kernel of standard deviation `σ`: the Nadaraya–Watson estimate
/// `x(t) = Σ g(t − t_k) x_k / Σ g(t − t_k)` over the finite samples within 7σ (Nadaraya 1964,
/// Watson 1964), with its first two derivatives in closed form. Infinitely differentiable in `t`
/// (the kernel's tail beyond 7σ is 2e-11 of its peak). In the interior it is a convolution with
/// gain `exp(−(2πfσ)²/2)` at frequency `f`; near the ends and gaps it is one-sided. NaN where no
/// finite sample lies within 7σ.
#[derive(Debug, Clone)]
pub struct KernelTrack {
    t0_s: f64,
    dt_s: f64,
    x: Vec<f64>,
    sigma_s: f64,
}

impl KernelTrack {
    /// Kernel smooth of samples `x[k]` at `t0_s + k·dt_s` with standard deviation `sigma_s`.
    pub fn new(t0_s: f64, dt_s: f64, x: &[f64], sigma_s: f64) -> Self {
        KernelTrack {
            t0_s,
            dt_s,
            x: x.to_vec(),
            sigma_s,
        }
    }

    /// `(x, ẋ, ẍ)` at `t`.
    pub fn at(&self, t: f64) -> (f64, f64, f64) {
        let s2 = self.sigma_s * self.sigma_s;
        let reach = (7.0 * self.sigma_s / self.dt_s).ceil() as isize;
        let c = ((t - self.t0_s) / self.dt_s).round() as isize;
        let (mut s0, mut s1, mut s2w, mut n0, mut n1, mut n2) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for k in (c - reach).max(0)..=(c + reach).min(self.x.len() as isize - 1) {
            let xk = self.x[k as usize];
            if !xk.is_finite() {
                continue;
            }
            let tau = t - (self.t0_s + k as f64 * self.dt_s);
            let g = (-0.5 * tau * tau / s2).exp();
            let g1 = -tau / s2 * g;
            let g2 = (tau * tau / (s2 * s2) - 1.0 / s2) * g;
            s0 += g;
            s1 += g1;
            s2w += g2;
            n0 += xk * g;
            n1 += xk * g1;
            n2 += xk * g2;
        }
        let u = n0 / s0;
        let ud = (n1 - u * s1) / s0;
        let udd = (n2 - 2.0 * ud * s1 - u * s2w) / s0;
        (u, ud, udd)
    }
}

/// The recorded head that drives the neck/lip model: its drop `u_p(t)` (m, positive down) and,
/// optionally, the blade's lean `d(t) = v3 − v` (tip x relative to head x, m), both smoothed by
/// [`SmoothedTrack`]. The lean locates the flip at the reversal (where `d` changes sign), which the
/// model cannot pass ([`PrescribedHead::segments`]), and gives the state after it
/// ([`NeckLip::state_from_tracks`]).
#[derive(Debug, Clone)]
pub struct PrescribedHead {
    pub drop: DropTrack,
    pub lean: Option<SmoothedTrack>,
}

/// How the head drop is smoothed.
#[derive(Debug, Clone)]
pub enum DropTrack {
    /// Local quadratic fits with a C² quintic between samples: follows a clean track closely.
    Local(SmoothedTrack),
    /// A Gaussian kernel smooth: infinitely differentiable, for noisy (tracked) recordings.
    Kernel(KernelTrack),
}

impl DropTrack {
    /// `(u_p, u̇_p, ü_p)` at `t`.
    fn at(&self, t: f64) -> (f64, f64, f64) {
        match self {
            DropTrack::Local(s) => s.at(t),
            DropTrack::Kernel(k) => k.at(t),
        }
    }

    /// The sample grid `(t0_s, dt_s)` the track was built on.
    fn grid(&self) -> (f64, f64) {
        match self {
            DropTrack::Local(s) => (s.t0_s, s.dt_s),
            DropTrack::Kernel(k) => (k.t0_s, k.dt_s),
        }
    }

    /// How far from the track's ends the smooth is one-sided, s: the local fits' half-width, or
    /// 3σ of the kernel.
    fn edge_s(&self) -> f64 {
        match self {
            DropTrack::Local(s) => s.half_width as f64 * s.dt_s,
            DropTrack::Kernel(k) => 3.0 * k.sigma_s,
        }
    }
}

impl PrescribedHead {
    /// The head drop from samples `u_m[k]` at `t0_s + k·dt_s`, without a lean track (the model then
    /// runs one segment, which must not cross the flip). See [`SmoothedTrack::from_samples`].
    ///
    /// # Errors
    /// As [`SmoothedTrack::from_samples`].
    pub fn from_samples(
        t0_s: f64,
        dt_s: f64,
        u_m: &[f64],
        half_width: usize,
    ) -> Result<Self, TrackError> {
        Ok(PrescribedHead {
            drop: DropTrack::Local(SmoothedTrack::from_samples(t0_s, dt_s, u_m, half_width)?),
            lean: None,
        })
    }

    /// Adds the lean track `d_m[k] = v3 − v` at the same times as the drop.
    ///
    /// # Errors
    /// As [`SmoothedTrack::from_samples`].
    pub fn with_lean(mut self, d_m: &[f64], half_width: usize) -> Result<Self, TrackError> {
        let (t0_s, dt_s) = self.drop.grid();
        self.lean = Some(SmoothedTrack::from_samples(t0_s, dt_s, d_m, half_width)?);
        Ok(self)
    }

    /// The head drop from tracked (noisy) samples, smoothed by a Gaussian kernel of standard
    /// deviation `sigma_s` ([`KernelTrack`]), without a lean track.
    ///
    /// # Errors
    /// [`TrackError::Kernel`] when `dt_s` or `sigma_s` is not positive, or fewer than 3 samples
    /// are finite.
    pub fn from_tracked_samples(
        t0_s: f64,
        dt_s: f64,
        u_m: &[f64],
        sigma_s: f64,
    ) -> Result<Self, TrackError> {
        let finite = u_m.iter().filter(|v| v.is_finite()).count();
        if !(dt_s > 0.0 && sigma_s > 0.0 && sigma_s.is_finite()) || finite < 3 {
            return Err(TrackError::Kernel {
                dt_s,
                sigma_s,
                finite,
            });
        }
        Ok(PrescribedHead {
            drop: DropTrack::Kernel(KernelTrack::new(t0_s, dt_s, u_m, sigma_s)),
            lean: None,
        })
    }

    /// `(u_p, u̇_p, ü_p)` at `t` (held constant beyond the samples).
    pub fn at(&self, t: f64) -> (f64, f64, f64) {
        self.drop.at(t)
    }

    /// The parts of `window` the model can run on: maximal intervals on the track's sample grid
    /// where the smoothed lean keeps `|d| ≥ guard_m`. The flip at the reversal (a sign change of `d`)
    /// and a guard around it are left out, and so are the tracks' first and last smoothing
    /// half-widths (3σ for a kernel smooth). Without a lean track: the whole window.
    pub fn segments(&self, window: (f64, f64), guard_m: f64) -> Vec<(f64, f64)> {
        let Some(lean) = &self.lean else {
            return vec![window];
        };
        let (t0, dt) = (lean.t0_s, lean.dt_s);
        let k0 = ((window.0 - t0) / dt).ceil().max(0.0) as usize;
        let k1 = (((window.1 - t0) / dt).floor() as usize).min(lean.u.len() - 1);
        let mut out = Vec::new();
        let mut cur: Option<(f64, f64, f64)> = None; // (start, last sample inside, sign of d)
        for k in k0..=k1 {
            let t = t0 + k as f64 * dt;
            let d = lean.u[k];
            let inside = d.abs() >= guard_m;
            if let Some((a, b, sign)) = cur
                && !(inside && d.signum() == sign)
            {
                if b > a {
                    out.push((a, b));
                }
                cur = None;
            }
            if inside {
                cur = Some(match cur {
                    Some((a, _, sign)) => (a, t, sign),
                    None => (t, t, d.signum()),
                });
            }
        }
        if let Some((a, b, _)) = cur
            && b > a
        {
            out.push((a, b));
        }
        // The grid may start or end within a sample of the window's ends.
        if let Some(f) = out.first_mut()
            && f.0 - window.0 < dt
        {
            f.0 = window.0;
        }
        if let Some(l) = out.last_mut()
            && window.1 - l.1 < dt
        {
            l.1 = window.1;
        }
        // Within `edge` of the tracks' ends the smooths are one-sided and their rates unreliable
        // (a start state taken there made the normal force negative): keep out of it.
        let edge = (lean.half_width as f64 * dt).max(self.drop.edge_s());
        let (lo, hi) = (t0 + edge, t0 + (lean.u.len() - 1) as f64 * dt - edge);
        for sgm in &mut out {
            sgm.0 = sgm.0.max(lo);
            sgm.1 = sgm.1.min(hi);
        }
        out.retain(|sgm| sgm.1 > sgm.0);
        out
    }
}

/// Fraction of the reach `l1 + l2` below which the lean `|d|` counts as the flip: the head-height
/// constraint's gradient `(l1 sin θ, l2 sin φ)` has at least the length `|d|/√2` (Cauchy–Schwarz on
/// `d = l1 sin θ + l2 sin φ`), so outside the guard it stays above 0.035 (l1 + l2), clear of the 0.02
/// (l1 + l2) at which [`NeckLip`] refuses to evaluate.
pub const FLIP_GUARD_OF_REACH: f64 = 0.05;

/// The neck/lip model on a prescribed head; state `[θ, φ, θ̇, φ̇]` as the full model's.
#[derive(Debug, Clone)]
pub struct NeckLip {
    pub blade: Blade,
    pub head: PrescribedHead,
}

impl NeckLip {
    /// The model of `params` on `head`.
    pub fn new(params: BladeParams, head: PrescribedHead) -> Self {
        NeckLip {
            blade: Blade::new(
                params,
                StickForm::Baumgarte {
                    omega_b_per_s: OMEGA_B,
                },
            ),
            head,
        }
    }

    /// The state `[θ, φ, θ̇, φ̇]` at `t` from the recorded tracks, and the slip direction there (the
    /// sign of the tip's velocity `v̇ + ḋ`), to start a segment after the flip.
    ///
    /// `θ, φ` solve `l1 sin θ + l2 sin φ = d` and `l1(1 − cos θ) + l2(1 − cos φ) = u_p` (Newton). The
    /// two equations have two solution branches (to second order `θ, φ = d/L ± (l2, −l1)·e` with
    /// `L = l1 + l2`); the one whose ratio `φ/θ` is nearer the blade's quasi-static slip equilibrium
    /// at `t` is taken. If the drop is below the least one the lean allows (tracking noise near the
    /// flip), `θ = φ = asin(d/L)`, and the Baumgarte term pulls the height onto `u_p`. The rates
    /// solve the same equations differentiated, with `ḋ, u̇_p` from the smoothed tracks.
    ///
    /// # Errors
    /// [`ModelFault::NoLeanTrack`] without a lean track, [`ModelFault::LeanBeyondReach`] with a lean
    /// beyond the reach, [`ModelFault::AlignedLinks`] where the rates are undetermined
    /// (`sin(φ − θ) ≈ 0`).
    pub fn state_from_tracks(&self, t: f64) -> Result<([f64; 4], f64), ModelFault> {
        let lean = self.head.lean.as_ref().ok_or(ModelFault::NoLeanTrack)?;
        let p = &self.blade.params;
        let (l1, l2) = (p.l1_m, p.l2_m);
        let reach = l1 + l2;
        let (d, dd, _) = lean.at(t);
        let (u, ud, _) = self.head.at(t);
        if d.is_nan() || d.abs() >= reach {
            return Err(ModelFault::LeanBeyondReach {
                t_s: t,
                lean_m: d,
                reach_m: reach,
            });
        }
        let solve = |mut th: f64, mut ph: f64| {
            for _ in 0..30 {
                let (st, ct) = trig::sin_cos(th);
                let (sp, cp) = trig::sin_cos(ph);
                let f = [l1 * st + l2 * sp - d, l1 * (1.0 - ct) + l2 * (1.0 - cp) - u];
                let det = l1 * l2 * (ct * sp - st * cp);
                if det.abs() < 1e-300 || f[0].abs().max(f[1].abs()) < 1e-16 * reach {
                    break;
                }
                th -= (l2 * sp * f[0] - l2 * cp * f[1]) / det;
                ph -= (-l1 * st * f[0] + l1 * ct * f[1]) / det;
            }
            (th, ph)
        };
        let mid = (d / reach).asin();
        let e2 = (2.0 * u - d * d / reach) / (l1 * l2 * reach);
        let (th, ph) = if e2 > 0.0 {
            let e = e2.sqrt();
            let a = solve(mid + l2 * e, mid - l1 * e);
            let b = solve(mid - l2 * e, mid + l1 * e);
            let eq = self.blade.slip_equilibrium(t)?;
            // Distance from the equilibrium's direction in (θ, φ): |θ φ_eq − φ θ_eq| / |·|.
            let miss = |(th, ph): (f64, f64)| (th * eq[1] - ph * eq[0]).abs() / th.hypot(ph);
            if miss(a) <= miss(b) { a } else { b }
        } else {
            (mid, mid)
        };
        let (st, ct) = trig::sin_cos(th);
        let (sp, cp) = trig::sin_cos(ph);
        let det = l1 * l2 * (ct * sp - st * cp);
        if det.abs() < 1e-6 * l1 * l2 {
            return Err(ModelFault::AlignedLinks {
                t_s: t,
                theta_rad: th,
                phi_rad: ph,
            });
        }
        let thd = (l2 * sp * dd - l2 * cp * ud) / det;
        let phd = (-l1 * st * dd + l1 * ct * ud) / det;
        let tip_speed = self.blade.drive(t).1 + dd;
        let dir = if tip_speed >= 0.0 { 1.0 } else { -1.0 };
        Ok(([th, ph, thd, phd], dir))
    }

    /// Row 3 replaced: the head-height constraint at acceleration level, `(coefficients, rhs)`.
    fn height_row(&self, t: f64, y: &[f64; 4]) -> (Vector3<f64>, f64) {
        let p = &self.blade.params;
        let (l1, l2) = (p.l1_m, p.l2_m);
        let (sth, cth) = trig::sin_cos(y[0]);
        let (sph, cph) = trig::sin_cos(y[1]);
        let u = l1 * (1.0 - cth) + l2 * (1.0 - cph);
        let ud = l1 * sth * y[2] + l2 * sph * y[3];
        let (up, udp, uddp) = self.head.at(t);
        let rhs = uddp
            - l1 * cth * y[2] * y[2]
            - l2 * cph * y[3] * y[3]
            - 2.0 * OMEGA_B * (ud - udp)
            - OMEGA_B * OMEGA_B * (u - up);
        (Vector3::new(l1 * sth, l2 * sph, 0.0), rhs)
    }

    /// Accelerations and contact forces in `mode`, and the tip velocity v̇3 (m/s) from the same
    /// sines and cosines (bitwise [`Blade::tip_velocity`]).
    fn dynamics(&self, t: f64, y: &[f64; 4], mode: &Mode) -> Result<(Dynamics, f64), ModelFault> {
        let touching = mode.region & 1 != 0;
        let rows = self.blade.rows_with_kinematics(t, y, touching);
        let (a3, af, b3) = (rows.a, rows.af, rows.b);
        let (hrow, hrhs) = self.height_row(t, y);
        // N is the multiplier of the height constraint, whose gradient (l1 sin θ, l2 sin φ) vanishes
        // at upright: there N is undetermined and the model cannot pass the blade's flip.
        let (l1, l2) = (self.blade.params.l1_m, self.blade.params.l2_m);
        if hrow[0].hypot(hrow[1]) < 0.02 * (l1 + l2) {
            return Err(ModelFault::UprightDegenerate {
                theta_rad: y[0],
                phi_rad: y[1],
            });
        }
        // Scale the constraint rows to the size of the others.
        let w = a3[(0, 0)].abs().max(a3[(1, 1)].abs())
            / self.blade.params.l1_m.max(self.blade.params.l2_m);
        match mode.phase.slip_dir() {
            Some(s) => {
                let mu = self
                    .blade
                    .params
                    .friction
                    .mu_slip_along(s, rows.tip_velocity);
                let build = |mu_s: f64| {
                    Matrix3::new(
                        a3[(0, 0)],
                        a3[(0, 1)],
                        a3[(0, 2)] + af[0] * mu_s,
                        a3[(1, 0)],
                        a3[(1, 1)],
                        a3[(1, 2)] + af[1] * mu_s,
                        w * hrow[0],
                        w * hrow[1],
                        0.0,
                    )
                };
                let a0 = build(0.0);
                let a = build(-s * mu);
                let (det0, det) = (a0.determinant(), a.determinant());
                if det * det0 <= 0.0 || det.abs() < 1e-9 * det0.abs() {
                    return Err(ModelFault::Painleve {
                        model: LinkModel::NeckLip,
                        det_with_friction: det,
                        det_frictionless: det0,
                        mu,
                    });
                }
                let z = a.lu().solve(&Vector3::new(b3[0], b3[1], w * hrhs)).ok_or(
                    ModelFault::Singular {
                        system: LinearSystem::NeckLipSlip,
                    },
                )?;
                Ok((
                    Dynamics {
                        theta_dd: z[0],
                        phi_dd: z[1],
                        normal_n: z[2],
                        friction_n: -s * mu * z[2],
                    },
                    rows.tip_velocity,
                ))
            }
            None => {
                // Row 3 replaced by the height constraint, then the tip constraint (Baumgarte).
                let mut a = a3;
                a[(2, 0)] = w * hrow[0];
                a[(2, 1)] = w * hrow[1];
                a[(2, 2)] = 0.0;
                let f = Vector3::new(af[0], af[1], 0.0);
                let b = Vector3::new(b3[0], b3[1], w * hrhs);
                let tip_rhs = rows.tip_constraint_rhs(mode.anchor, OMEGA_B);
                let z = self
                    .blade
                    .solve_with_tip_constraint(rows.cos, &a, &f, &b, tip_rhs)
                    .ok_or(ModelFault::Singular {
                        system: LinearSystem::NeckLipStick,
                    })?;
                Ok((
                    Dynamics {
                        theta_dd: z[0],
                        phi_dd: z[1],
                        normal_n: z[2],
                        friction_n: z[3],
                    },
                    rows.tip_velocity,
                ))
            }
        }
    }
}

impl StickSlipModel<4> for NeckLip {
    fn rhs(
        &self,
        mode: &Mode,
        t: f64,
        y: &[f64; 4],
        dy: &mut [f64; 4],
    ) -> Result<Contact, ModelFault> {
        let (d, tip_velocity) = self.dynamics(t, y, mode)?;
        *dy = [y[2], y[3], d.theta_dd, d.phi_dd];
        Ok(Contact {
            normal: d.normal_n,
            friction: d.friction_n,
            limit: self.blade.params.friction.mu_static() * d.normal_n,
            // The slip event reuses it instead of recomputing it (only slip phases read it).
            slip_velocity: mode.phase.slip_dir().map(|_| tip_velocity),
        })
    }

    fn slip_velocity(&self, t: f64, y: &[f64; 4]) -> f64 {
        self.blade.tip_velocity(t, y)
    }

    fn contact_position(&self, t: f64, y: &[f64; 4]) -> f64 {
        self.blade.tip_position(t, y)
    }

    fn enter_stick(&self, t: f64, y: &mut [f64; 4], anchor: f64) {
        self.blade.enter_stick(t, y, anchor);
    }

    fn switching_surfaces(&self) -> usize {
        self.blade.switching_surfaces()
    }

    fn switching_function(&self, i: usize, t: f64, y: &[f64; 4]) -> f64 {
        self.blade.switching_function(i, t, y)
    }

    fn describe(&self, t: f64, y: &[f64; 4]) -> String {
        let (up, _, _) = self.head.at(t);
        format!(
            "neck/lip on prescribed head (u_p = {up:.6e} m): {}",
            self.blade.describe(t, y)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Local quadratic fits reproduce a quadratic exactly, and so does the quintic between samples.
    #[test]
    fn smoothed_track_is_exact_on_a_quadratic() {
        let (t0, dt) = (0.5, 1e-3);
        let f = |t: f64| 3.0 + 2.0 * t - 7.0 * t * t;
        let x: Vec<f64> = (0..50).map(|k| f(t0 + k as f64 * dt)).collect();
        let tr = SmoothedTrack::from_samples(t0, dt, &x, 4).unwrap();
        for t in [0.5, 0.50037, 0.5213, 0.549] {
            let (u, ud, udd) = tr.at(t);
            assert!((u - f(t)).abs() < 1e-12, "u at {t}");
            assert!((ud - (2.0 - 14.0 * t)).abs() < 1e-9, "u̇ at {t}");
            assert!((udd + 14.0).abs() < 1e-6, "ü at {t}");
        }
    }

    /// In the interior the kernel smooth of a sinusoid is the sinusoid times the Gaussian's Fourier
    /// transform exp(−(2πfσ)²/2); its derivatives are those of the attenuated sinusoid.
    #[test]
    fn kernel_track_has_the_gaussian_gain() {
        let (dt, sigma) = (1e-4, 5e-4);
        for f_hz in [49.0, 300.0] {
            let w = 2.0 * std::f64::consts::PI * f_hz;
            let x: Vec<f64> = (0..4000).map(|k| (w * k as f64 * dt).sin()).collect();
            let tr = KernelTrack::new(0.0, dt, &x, sigma);
            let gain = (-0.5 * (w * sigma).powi(2)).exp();
            for t in [0.17, 0.20013, 0.23] {
                let (u, ud, udd) = tr.at(t);
                assert!(
                    (u - gain * (w * t).sin()).abs() < 1e-6,
                    "{f_hz} Hz: u at {t}"
                );
                assert!((ud - gain * w * (w * t).cos()).abs() < 1e-6 * w, "u̇");
                assert!(
                    (udd + gain * w * w * (w * t).sin()).abs() < 1e-6 * w * w,
                    "ü"
                );
            }
        }
    }

    /// A lean that crosses zero once gives two segments, cut where |d| < guard.
    #[test]
    fn segments_leave_out_the_flip() {
        let dt = 1e-3;
        // d = 1e-3 (t − 1) m on [0, 2] s: crosses zero at 1 s; guard 1e-4 m leaves out 0.9–1.1 s.
        let d: Vec<f64> = (0..=2000).map(|k| 1e-3 * (k as f64 * dt - 1.0)).collect();
        let u = vec![0.0; d.len()];
        let head = PrescribedHead::from_samples(0.0, dt, &u, 3)
            .unwrap()
            .with_lean(&d, 3)
            .unwrap();
        let seg = head.segments((0.0, 2.0), 1e-4);
        assert_eq!(seg.len(), 2, "{seg:?}");
        // The tracks' first and last 3 samples (the smoothing half-width) are left out too.
        assert!((seg[0].0 - 3.0 * dt).abs() < 1e-12, "{seg:?}");
        assert!((seg[0].1 - 0.9).abs() < 1.5 * dt, "{seg:?}");
        assert!((seg[1].0 - 1.1).abs() < 1.5 * dt, "{seg:?}");
        assert!((seg[1].1 - (2.0 - 3.0 * dt)).abs() < 1e-12, "{seg:?}");
        // Without a lean track: the whole window.
        let plain = PrescribedHead::from_samples(0.0, dt, &u, 3).unwrap();
        assert_eq!(plain.segments((0.2, 1.7), 1e-4), vec![(0.2, 1.7)]);
    }
}
