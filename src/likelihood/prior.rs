//! What a user knows, as a negative log prior in nats beside the recording's NLL
//! (`[fit.priors]`, [`crate::job::prior`]; docs/priors.md, "Priors").
//!
//! Every prior term is a Gaussian pseudo-observation: a prediction `g(θ)` of the fitted
//! parameters, an observed value `y` and its 1σ `s`, entering as `z²/2` with `z = (g(θ) − y)/s`:
//!
//! * a normal prior on θ: `g = θ`, `y` its mean, `s` its sd;
//! * a log-normal prior on θ: `g = ln θ`, `y = ln median`, `s = sd_log` (a normal prior on `ln θ`);
//! * a rig point at slip speed `v_i`: `g = μ_d(v_i; θ)`, the fitted law's own dynamic coefficient
//!   ([`crate::model::FrictionLaw::mu_slip`]), `y = μ_i`, `s = s_i`.
//!
//! The terms are the negative log densities up to constants that do not depend on θ (Gelman et al.,
//! *Bayesian Data Analysis*, 3rd ed. 2013, §2.5 for the normal prior and its precision-weighted
//! posterior). As pseudo-observations they have a Gauss–Newton information `JᵀJ` in the search's
//! coordinates ([`Prior::information_u`]), exact for a prior linear in the coordinate, and a score
//! whose variance is the same `JᵀJ`: the Laplace interval adds it to both `F` and `V` of the
//! sandwich (docs/priors.md, "Priors").

use crate::job::{FreeParam, ParamPrior, PriorsSection, RigCurve, RigPoint};
use crate::model::{BladeParams, ParamId};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// One prior term (module docs).
#[derive(Debug, Clone, PartialEq)]
pub enum PriorTerm {
    /// A prior on one fitted parameter.
    Parameter { id: ParamId, prior: ParamPrior },
    /// A rig point: μ_d at its speed observed as its coefficient ± its 1σ.
    Rig(RigPoint),
}

impl PriorTerm {
    /// The standardised residual `z = (g(θ) − y)/s` at `p` (0 for a parameter `p` lacks).
    pub fn z(&self, p: &BladeParams) -> f64 {
        match self {
            PriorTerm::Parameter { id, prior } => match (*prior, id.get(p)) {
                (_, None) => 0.0,
                (ParamPrior::Normal { mean, sd }, Some(x)) => (x - mean) / sd,
                (ParamPrior::Lognormal { median, sd_log }, Some(x)) => {
                    (x.ln() - median.ln()) / sd_log
                }
            },
            PriorTerm::Rig(r) => (p.friction.mu_slip(r.speed_m_per_s) - r.coefficient) / r.sd,
        }
    }

    /// `∂z/∂θ` at `p` for each parameter θ the term reads, by its id.
    fn gradient(&self, p: &BladeParams) -> Vec<(ParamId, f64)> {
        match self {
            PriorTerm::Parameter { id, prior } => match (*prior, id.get(p)) {
                (_, None) => Vec::new(),
                (ParamPrior::Normal { sd, .. }, Some(_)) => vec![(*id, 1.0 / sd)],
                (ParamPrior::Lognormal { sd_log, .. }, Some(x)) => vec![(*id, 1.0 / (x * sd_log))],
            },
            PriorTerm::Rig(r) => p
                .friction
                .mu_slip_gradient(r.speed_m_per_s)
                .into_iter()
                .map(|(id, g)| (id, g / r.sd))
                .collect(),
        }
    }

    /// The parameters the term reads.
    fn reads(&self, id: ParamId) -> bool {
        match self {
            PriorTerm::Parameter { id: own, .. } => *own == id,
            PriorTerm::Rig(_) => id.is_friction(),
        }
    }
}

/// The prior of one candidate's fit: the terms of `[fit.priors]` that read a parameter it frees.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Prior {
    pub terms: Vec<PriorTerm>,
}

impl Prior {
    /// The terms of `priors` and of the rig curve `rig` that read one of the parameters `free`:
    /// a parameter's prior when it is freed, every rig point when a friction coefficient is.
    pub fn new(priors: &PriorsSection, rig: Option<&RigCurve>, free: &[FreeParam]) -> Prior {
        let mut terms: Vec<PriorTerm> = priors
            .parameters
            .iter()
            .map(|(&id, &prior)| PriorTerm::Parameter { id, prior })
            .collect();
        if priors.friction_curve.is_some() {
            terms.extend(
                rig.iter()
                    .flat_map(|c| c.points.iter().cloned().map(PriorTerm::Rig)),
            );
        }
        terms.retain(|t| free.iter().any(|f| t.reads(f.name)));
        Prior { terms }
    }

    /// True without terms: the prior is flat.
    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    /// The negative log prior at `p`, nats: `Σ z²/2`.
    pub fn nats(&self, p: &BladeParams) -> f64 {
        self.terms.iter().map(|t| 0.5 * t.z(p).powi(2)).sum()
    }

    /// `∂z_i/∂u_j` at the search's normalised coordinates `u` of `free` (over `base`): one row per
    /// term, one column per coordinate.
    pub fn jacobian_u(&self, free: &[FreeParam], base: &BladeParams, u: &[f64]) -> DMatrix<f64> {
        let p = params_at(free, base, u);
        let mut j = DMatrix::zeros(self.terms.len(), free.len());
        for (i, t) in self.terms.iter().enumerate() {
            for (id, g) in t.gradient(&p) {
                if let Some(k) = free.iter().position(|f| f.name == id) {
                    j[(i, k)] = g * free[k].slope(u[k]);
                }
            }
        }
        j
    }

    /// The prior's information in the normalised coordinates: `JᵀJ` with `J` =
    /// [`Prior::jacobian_u`]. For a normal prior on a parameter searched on a linear scale it is
    /// the exact Hessian of [`Prior::nats`], `((upper − lower)/sd)²`.
    pub fn information_u(&self, free: &[FreeParam], base: &BladeParams, u: &[f64]) -> DMatrix<f64> {
        let j = self.jacobian_u(free, base, u);
        j.transpose() * j
    }

    /// `ln |dx/du|` summed over the parameter priors, with `x = θ` for a normal prior and
    /// `x = ln θ` for a log-normal one (up to a constant): what turns the flat density in `u` of a
    /// posterior sample into the prior's own density in θ (or ln θ), whatever scale the search
    /// uses for the parameter.
    pub fn log_jacobian_u(&self, free: &[FreeParam], u: &[f64]) -> f64 {
        let mut sum = 0.0;
        for t in &self.terms {
            let PriorTerm::Parameter { id, prior } = t else {
                continue;
            };
            let Some(k) = free.iter().position(|f| f.name == *id) else {
                continue;
            };
            let slope = free[k].slope(u[k]);
            sum += match prior {
                ParamPrior::Normal { .. } => slope.ln(),
                ParamPrior::Lognormal { .. } => (slope / free[k].value(u[k])).ln(),
            };
        }
        sum
    }

    /// The log density (up to a constant) a posterior sample draws at `u`, from the fit's cost
    /// there (`cost_nats`: the recording's NLL plus [`Prior::nats`]): the likelihood tempered by
    /// `w` ([`crate::uncertainty::posterior_tempering`]), the prior not, and the prior's parameters
    /// distributed with its own density in θ or ln θ ([`Prior::log_jacobian_u`]).
    pub fn log_posterior(
        &self,
        cost_nats: f64,
        w: f64,
        free: &[FreeParam],
        base: &BladeParams,
        u: &[f64],
    ) -> f64 {
        let (ell, pi) = self.log_parts(cost_nats, w, free, base, u);
        ell + pi
    }

    /// [`Prior::log_posterior`]'s two terms apart: the tempered log-likelihood `−w·NLL` and the
    /// log-prior with its Jacobian, which parallel tempering (`crate::posterior::tempering`)
    /// weighs differently.
    pub fn log_parts(
        &self,
        cost_nats: f64,
        w: f64,
        free: &[FreeParam],
        base: &BladeParams,
        u: &[f64],
    ) -> (f64, f64) {
        let prior = self.nats(&params_at(free, base, u));
        (
            -w * (cost_nats - prior),
            -prior + self.log_jacobian_u(free, u),
        )
    }

    /// The prior with every observed value drawn anew about the prediction at `p` (`y' = g(θ̂) +
    /// s·ε`): the pseudo-observations' replicate for a parametric bootstrap.
    pub fn replicate(&self, p: &BladeParams, rng: &mut impl rand::Rng) -> Prior {
        use rand_distr::{Distribution, StandardNormal};
        let terms = self
            .terms
            .iter()
            .map(|t| {
                let e: f64 = StandardNormal.sample(rng);
                match t {
                    PriorTerm::Parameter { id, prior } => {
                        let x = id.get(p).unwrap_or(f64::NAN);
                        let prior = match *prior {
                            ParamPrior::Normal { sd, .. } => ParamPrior::Normal {
                                mean: x + sd * e,
                                sd,
                            },
                            ParamPrior::Lognormal { sd_log, .. } => ParamPrior::Lognormal {
                                median: x * (sd_log * e).exp(),
                                sd_log,
                            },
                        };
                        PriorTerm::Parameter { id: *id, prior }
                    }
                    PriorTerm::Rig(r) => PriorTerm::Rig(RigPoint {
                        coefficient: p.friction.mu_slip(r.speed_m_per_s) + r.sd * e,
                        ..r.clone()
                    }),
                }
            })
            .collect();
        Prior { terms }
    }

    /// The prior beside the fit for the result: `p` the fitted parameters, `intervals` each fitted
    /// parameter's interval, `rig` the rig curve's file.
    pub fn report(
        &self,
        p: &BladeParams,
        intervals: &[(ParamId, Option<[f64; 2]>)],
        rig: Option<&RigCurve>,
    ) -> PriorsReport {
        let mut parameters = Vec::new();
        let mut points = Vec::new();
        for t in &self.terms {
            match t {
                PriorTerm::Parameter { id, prior } => parameters.push(ParamPriorReport {
                    name: *id,
                    prior: *prior,
                    prior_interval: prior.interval(),
                    value: id.get(p).unwrap_or(f64::NAN),
                    interval: intervals
                        .iter()
                        .find(|(i, _)| i == id)
                        .and_then(|(_, iv)| *iv),
                    z: t.z(p),
                }),
                PriorTerm::Rig(r) => points.push(RigPointReport {
                    speed_m_per_s: r.speed_m_per_s,
                    coefficient: r.coefficient,
                    sd: r.sd,
                    mu_d_fit: p.friction.mu_slip(r.speed_m_per_s),
                    z: t.z(p),
                }),
            }
        }
        PriorsReport {
            nats_at_fit: self.nats(p),
            parameters,
            friction_curve: (!points.is_empty()).then(|| RigCurveReport {
                file: rig.map(|c| c.file.clone()).unwrap_or_default(),
                points,
            }),
        }
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

/// The priors of a fit beside its result (the result file's `[priors]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PriorsReport {
    /// The negative log prior at the fit, nats: the fit's cost is the recording's NLL plus this.
    pub nats_at_fit: f64,
    /// One per parameter prior.
    #[serde(default)]
    pub parameters: Vec<ParamPriorReport>,
    /// The rig curve's points beside the fitted law.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_curve: Option<RigCurveReport>,
}

/// A parameter's prior beside its fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamPriorReport {
    pub name: ParamId,
    pub prior: ParamPrior,
    /// The prior's central 68.27 % interval ([`ParamPrior::interval`]).
    pub prior_interval: [f64; 2],
    /// The fitted value.
    pub value: f64,
    /// The fitted interval, when the fit has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interval: Option<[f64; 2]>,
    /// The fitted value's distance from the prior's centre in prior standard deviations.
    pub z: f64,
}

/// The rig curve beside the fitted law.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigCurveReport {
    pub file: PathBuf,
    pub points: Vec<RigPointReport>,
}

/// One rig point beside the fitted law's μ_d there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigPointReport {
    pub speed_m_per_s: f64,
    pub coefficient: f64,
    pub sd: f64,
    /// The fitted law's μ_d at the point's speed.
    pub mu_d_fit: f64,
    /// `(μ_d − coefficient)/sd`.
    pub z: f64,
}

/// |z| beyond which the fit and a prior disagree: two prior standard deviations, outside which a
/// value falls with probability 4.55 % (two-sided) when the prior is right, the usual 5 % level.
pub const PRIOR_CONFLICT_Z: f64 = 2.0;

/// The two-sided tail probability of [`PRIOR_CONFLICT_Z`] under a standard normal, `erfc(2/√2)`:
/// the level at which the rig curve as a whole disagrees ([`PriorsReport::rig_conflict`]).
pub fn prior_conflict_level() -> f64 {
    statrs::function::erf::erfc(PRIOR_CONFLICT_Z / std::f64::consts::SQRT_2)
}

/// A parameter fitted more than [`PRIOR_CONFLICT_Z`] prior standard deviations from its prior's
/// centre (on the log scale for a log-normal prior): the recording pulls it away from the prior.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamConflict {
    pub parameter: ParamId,
    pub prior: ParamPrior,
    /// The fitted value, the parameter's unit.
    pub value: f64,
    /// `(θ − mean)/sd`, or `(ln θ − ln median)/sd_log`.
    pub z: f64,
}

/// A rig curve the fitted law misses as a whole: `Σ z_i²` over its `n` points beyond what a χ²
/// with `n` degrees of freedom exceeds with probability [`prior_conflict_level`]
/// ([`PriorsReport::rig_conflict`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigConflict {
    pub file: PathBuf,
    pub points: usize,
    /// `Σ z_i²` at the fit.
    pub chi2: f64,
    /// `P(χ²_n ≥ chi2)`.
    pub p_value: f64,
    /// `√(Σ z_i²/n)`.
    pub rms_z: f64,
    /// The point farthest from the fitted law: its slip speed (m/s), coefficient and z.
    pub worst_speed_m_per_s: f64,
    pub worst_coefficient: f64,
    pub worst_z: f64,
}

impl PriorsReport {
    /// The parameters whose fitted value lies beyond [`PRIOR_CONFLICT_Z`] of their prior.
    pub fn parameter_conflicts(&self) -> Vec<ParamConflict> {
        (self.parameters.iter())
            .filter(|p| p.z.abs() > PRIOR_CONFLICT_Z)
            .map(|p| ParamConflict {
                parameter: p.name,
                prior: p.prior,
                value: p.value,
                z: p.z,
            })
            .collect()
    }

    /// The rig curve, when the fitted law misses it as a whole. Its points are read together, not
    /// one by one: of 20 points that each sit where the prior puts them, one is expected beyond
    /// |z| = 2, so a per-point check would warn on a good fit. `Σ z_i²` over `n` independent
    /// points is χ² with `n` degrees of freedom when the rig's μ is the blade's μ_d, and the
    /// curve disagrees when it reaches a value that χ²_n exceeds with probability
    /// [`prior_conflict_level`], the same level as |z| > [`PRIOR_CONFLICT_Z`] for one parameter
    /// (for one point the two are the same check). At the fit the law is pulled toward the
    /// points, so `Σ z_i²` is below its value at the blade's true law and the check errs on the
    /// quiet side.
    pub fn rig_conflict(&self) -> Option<RigConflict> {
        let curve = self.friction_curve.as_ref()?;
        let n = curve.points.len();
        let chi2: f64 = curve.points.iter().map(|p| p.z * p.z).sum();
        let p_value = statrs::distribution::ChiSquared::new(n as f64)
            .ok()
            .map(|d| statrs::distribution::ContinuousCDF::sf(&d, chi2))?;
        if p_value.is_nan() || p_value >= prior_conflict_level() {
            return None;
        }
        let worst = (curve.points.iter()).max_by(|a, b| a.z.abs().total_cmp(&b.z.abs()))?;
        Some(RigConflict {
            file: curve.file.clone(),
            points: n,
            chi2,
            p_value,
            rms_z: (chi2 / n as f64).sqrt(),
            worst_speed_m_per_s: worst.speed_m_per_s,
            worst_coefficient: worst.coefficient,
            worst_z: worst.z,
        })
    }
}

/// `x` to 4 significant digits, written as short as that allows.
fn short(x: f64) -> f64 {
    format!("{x:.3e}").parse().unwrap_or(x)
}

impl std::fmt::Display for ParamConflict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (id, unit) = (self.parameter, self.parameter.unit_suffix());
        let (prior, from) = match self.prior {
            ParamPrior::Normal { mean, sd } => (
                format!("normal, mean {mean}{unit}, sd {sd}{unit}"),
                "its prior's mean",
            ),
            ParamPrior::Lognormal { median, sd_log } => (
                format!("log-normal, median {median}{unit}, sd_log {sd_log}"),
                "its prior's median on the log scale",
            ),
        };
        write!(
            f,
            "{id} = {}{unit} lies z = {:+.2} prior standard deviations from {from} ({prior}; \
             [fit.priors]): the recording pulls {id} away from the prior, so either the prior or \
             the model is wrong for this blade",
            short(self.value),
            self.z
        )
    }
}

impl std::fmt::Display for RigConflict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the fitted law's μ_d misses the rig curve {} as a whole: Σz² = {:.1} over {} points \
             (rms z {:.2}; P(χ²_{} ≥ Σz²) = {:.2e}, below the {:.3} of |z| > {PRIOR_CONFLICT_Z}), \
             worst at {} m/s where the rig has μ = {} and z = {:+.2}: the recording pulls the \
             friction law away from the rig's μ(v), so either the prior or the model is wrong \
             for this blade",
            self.file.display(),
            self.chi2,
            self.points,
            self.rms_z,
            self.points,
            self.p_value,
            prior_conflict_level(),
            short(self.worst_speed_m_per_s),
            short(self.worst_coefficient),
            self.worst_z
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::job::PriorsSection;
    use crate::model::FrictionLaw;

    /// The shipped main job's blade (exponential law), with a shoulder so that θ_c can be freed.
    fn blade() -> BladeParams {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/reversal/blade.toml");
        let mut p: BladeParams = toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        p.shoulder = Some(crate::model::Shoulder {
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

    /// Second derivative of `f` at `u` along coordinate `k`, central differences of step `h`.
    fn second(f: impl Fn(&[f64]) -> f64, u: &[f64], k: usize, h: f64) -> f64 {
        let at = |d: f64| {
            let mut v = u.to_vec();
            v[k] += d;
            f(&v)
        };
        (at(h) - 2.0 * at(0.0) + at(-h)) / (h * h)
    }

    /// A normal prior on θ_c (linear scale, bounds [0.03, 0.2]) is `(θ − m)²/(2 sd²)`, its
    /// information in u is `((0.2 − 0.03)/sd)²` (θ linear in u: the exact Hessian, checked by
    /// central differences of the nats), and a parameter it does not read adds nothing.
    #[test]
    fn a_normal_prior_has_its_closed_form_term_and_hessian() {
        let free = [
            FreeParam::new(ParamId::K1, 0.005, 0.15),
            FreeParam::new(ParamId::ThetaC, 0.03, 0.2),
        ];
        assert!(free[0].log && !free[1].log);
        let (m, sd) = (0.08, 0.01);
        let prior = Prior::new(
            &priors(&[(ParamId::ThetaC, ParamPrior::Normal { mean: m, sd })]),
            None,
            &free,
        );
        let base = blade();
        let u = [0.4, 0.5];
        let theta = 0.03 + 0.5 * 0.17;
        let p = params_at(&free, &base, &u);
        let expected = (theta - m).powi(2) / (2.0 * sd * sd);
        assert!(
            (prior.nats(&p) - expected).abs() < 1e-12,
            "{}",
            prior.nats(&p)
        );
        let info = prior.information_u(&free, &base, &u);
        let h_closed = (0.17 / sd).powi(2);
        assert!((info[(1, 1)] - h_closed).abs() < 1e-9 * h_closed);
        assert_eq!([info[(0, 0)], info[(0, 1)], info[(1, 0)]], [0.0; 3]);
        let nats = |v: &[f64]| prior.nats(&params_at(&free, &base, v));
        let fd = second(nats, &u, 1, 1e-4);
        assert!(
            (fd - h_closed).abs() < 1e-6 * h_closed,
            "{fd} vs {h_closed}"
        );
        // The gradient Jᵀz is the first derivative: (θ − m)/sd² · dθ/du.
        let j = prior.jacobian_u(&free, &base, &u);
        let z = (theta - m) / sd;
        let grad = j[(0, 1)] * z;
        assert!((grad - (theta - m) / (sd * sd) * 0.17).abs() < 1e-9);
        // A prior on a parameter none of `free` is: no term.
        let other = Prior::new(
            &priors(&[(ParamId::C0, ParamPrior::Normal { mean: 1.0, sd: 1.0 })]),
            None,
            &free,
        );
        assert!(other.is_empty() && other.nats(&p) == 0.0);
    }

    /// A log-normal prior on k1 searched on a log scale ([0.005, 0.15]) is `(ln θ − ln median)²/
    /// (2 sd_log²)`, and since ln θ is linear in u there, its information is the constant
    /// `(ln 30 / sd_log)²`, the Hessian of the nats.
    #[test]
    fn a_lognormal_prior_is_normal_in_the_log_with_its_closed_form_hessian() {
        let free = [FreeParam::new(ParamId::K1, 0.005, 0.15)];
        let (median, sd_log) = (0.02, 0.3);
        let prior = Prior::new(
            &priors(&[(ParamId::K1, ParamPrior::Lognormal { median, sd_log })]),
            None,
            &free,
        );
        let base = blade();
        for u in [0.1, 0.5, 0.9] {
            let k1 = 0.005 * 30f64.powf(u);
            let p = params_at(&free, &base, &[u]);
            let expected = (k1 / median).ln().powi(2) / (2.0 * sd_log * sd_log);
            assert!((prior.nats(&p) - expected).abs() < 1e-12);
            let h_closed = (30f64.ln() / sd_log).powi(2);
            let info = prior.information_u(&free, &base, &[u]);
            assert!((info[(0, 0)] - h_closed).abs() < 1e-9 * h_closed);
            let nats = |v: &[f64]| prior.nats(&params_at(&free, &base, v));
            let fd = second(nats, &[u], 0, 1e-4);
            assert!(
                (fd - h_closed).abs() < 1e-6 * h_closed,
                "{fd} vs {h_closed}"
            );
        }
        assert_eq!(
            ParamPrior::Lognormal { median, sd_log }.interval(),
            [median * (-0.3f64).exp(), median * 0.3f64.exp()]
        );
    }

    /// A rig point enters as `(μ_d(v) − μ)²/(2 s²)` with the fitted law's own μ_d, and its
    /// Jacobian is the law's closed-form gradient (e^(−Bv), −A v e^(−Bv), 1)/s times dθ/du (A
    /// linear in u, B and C on log scales: dθ/du = θ ln(upper/lower)).
    #[test]
    fn a_rig_point_reads_the_laws_own_mu_d() {
        let free = [
            FreeParam::new(ParamId::A, 0.2, 1.5),
            FreeParam::new(ParamId::B, 10.0, 300.0),
            FreeParam::new(ParamId::C, 0.1, 1.0),
        ];
        let point = RigPoint {
            speed_m_per_s: 0.02,
            coefficient: 0.9,
            sd: 0.05,
            rows: 1,
            group: None,
            line: 2,
        };
        let rig = RigCurve {
            file: "rig.csv".into(),
            points: vec![point],
        };
        let mut section = priors(&[]);
        section.friction_curve = Some(
            toml::from_str(
                "file = 'rig.csv'\nspeed_column = 'v'\ncoefficient_column = 'mu'\nsd = 0.05",
            )
            .unwrap(),
        );
        let prior = Prior::new(&section, Some(&rig), &free);
        assert_eq!(prior.terms.len(), 1);
        let base = blade();
        let u = [0.5, 0.5, 0.5];
        let p = params_at(&free, &base, &u);
        let (a, b, c) = (0.85, 10.0 * 30f64.sqrt(), 0.1 * 10f64.sqrt());
        assert!(matches!(p.friction, FrictionLaw::Exponential { .. }));
        let mu = a * (-b * 0.02f64).exp() + c;
        let nats = (mu - 0.9f64).powi(2) / (2.0 * 0.05 * 0.05);
        assert!((prior.nats(&p) - nats).abs() < 1e-9, "{}", prior.nats(&p));
        let j = prior.jacobian_u(&free, &base, &u);
        let e = (-b * 0.02f64).exp();
        let expected = [e * 1.3, -a * 0.02 * e * b * 30f64.ln(), c * 10f64.ln()];
        for k in 0..3 {
            assert!((j[(0, k)] - expected[k] / 0.05).abs() < 1e-9, "{k}");
        }
        // Without a freed friction coefficient the curve reads nothing.
        let k1_only = [FreeParam::new(ParamId::K1, 0.005, 0.15)];
        assert!(Prior::new(&section, Some(&rig), &k1_only).is_empty());
    }

    /// The report of `prior` at θ_c = `theta_c` (and k1 = `k1`) on the test blade.
    fn conflicts_at(prior: ParamPrior, id: ParamId, value: f64) -> Vec<ParamConflict> {
        let free = [FreeParam::new(id, 0.005, 0.2)];
        let prior = Prior::new(&priors(&[(id, prior)]), None, &free);
        let mut p = blade();
        id.set(&mut p, value);
        prior.report(&p, &[], None).parameter_conflicts()
    }

    /// A normal prior warns from |z| > 2 on, not at 1.9 (z = (θ − mean)/sd, closed form), on
    /// either side, and the warning names the prior and the fitted value with their units.
    #[test]
    fn a_normal_prior_conflicts_beyond_two_sds() {
        let prior = ParamPrior::Normal {
            mean: 0.08,
            sd: 0.01,
        };
        assert!(conflicts_at(prior, ParamId::ThetaC, 0.08 + 1.9 * 0.01).is_empty());
        assert!(conflicts_at(prior, ParamId::ThetaC, 0.08 - 1.9 * 0.01).is_empty());
        let c = conflicts_at(prior, ParamId::ThetaC, 0.08 + 2.1 * 0.01);
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].parameter, ParamId::ThetaC);
        assert!((c[0].z - 2.1).abs() < 1e-9 && (c[0].value - 0.101).abs() < 1e-12);
        assert_eq!(
            c[0].to_string(),
            "theta_c = 0.101 rad lies z = +2.10 prior standard deviations from its prior's mean \
             (normal, mean 0.08 rad, sd 0.01 rad; [fit.priors]): the recording pulls theta_c \
             away from the prior, so either the prior or the model is wrong for this blade"
        );
        let below = conflicts_at(prior, ParamId::ThetaC, 0.08 - 2.1 * 0.01);
        assert!(below.len() == 1 && (below[0].z + 2.1).abs() < 1e-9);
    }

    /// A log-normal prior reads z on the log scale, `(ln θ − ln median)/sd_log`: θ =
    /// median·e^(±2.1·sd_log) warns, median·e^(1.9·sd_log) does not, although on the linear
    /// scale the upper value is farther from the median than the lower one.
    #[test]
    fn a_lognormal_prior_conflicts_beyond_two_sds_of_the_log() {
        let (median, sd_log) = (0.02, 0.3);
        let prior = ParamPrior::Lognormal { median, sd_log };
        let at = |z: f64| conflicts_at(prior, ParamId::K1, median * (z * sd_log).exp());
        assert!(at(1.9).is_empty() && at(-1.9).is_empty());
        for z in [2.1, -2.1] {
            let c = at(z);
            assert_eq!(c.len(), 1, "z = {z}");
            assert!((c[0].z - z).abs() < 1e-9, "{} vs {z}", c[0].z);
        }
        assert!(at(2.1)[0].to_string().starts_with(
            "k1 = 0.03755 N·m/rad lies z = +2.10 prior standard deviations from its prior's \
             median on the log scale (log-normal, median 0.02 N·m/rad, sd_log 0.3;"
        ));
    }

    /// The rig curve's report with points at the given z on the test blade's law (each point's
    /// coefficient μ_d(v) − z·s, so that its z is `z`).
    fn rig_report(zs: &[f64]) -> PriorsReport {
        let free = [FreeParam::new(ParamId::A, 0.2, 1.5)];
        let p = blade();
        let sd = 0.05;
        let points = (zs.iter().enumerate())
            .map(|(i, z)| {
                let v = 0.01 * (i + 1) as f64;
                RigPoint {
                    speed_m_per_s: v,
                    coefficient: p.friction.mu_slip(v) - z * sd,
                    sd,
                    rows: 1,
                    group: None,
                    line: 2 + i as u64,
                }
            })
            .collect();
        let rig = RigCurve {
            file: "rig.csv".into(),
            points,
        };
        let mut section = priors(&[]);
        section.friction_curve = Some(
            toml::from_str(
                "file = 'rig.csv'\nspeed_column = 'v'\ncoefficient_column = 'mu'\nsd = 0.05",
            )
            .unwrap(),
        );
        Prior::new(&section, Some(&rig), &free).report(&p, &[], Some(&rig))
    }

    /// The rig curve disagrees when Σz² over its n points passes the χ²_n value exceeded with the
    /// probability of |z| > 2. One point: the same as |z| > 2. Two points: χ²_2's tail is
    /// e^(−x/2) (closed form), so two points at z = 1.9 (Σz² = 7.22, tail e^(−3.61) = 0.027 <
    /// 0.0455) disagree together though each lies within 2, and two at 1.5 (Σz² = 4.5, tail
    /// e^(−2.25) = 0.105) do not.
    #[test]
    fn a_rig_curve_conflicts_as_a_whole_at_the_level_of_two_sds() {
        assert!((prior_conflict_level() - 0.0455003).abs() < 1e-6);
        assert!(rig_report(&[1.9]).rig_conflict().is_none());
        let one = rig_report(&[-2.1])
            .rig_conflict()
            .expect("one point at z = −2.1");
        assert_eq!(one.points, 1);
        assert!((one.chi2 - 4.41).abs() < 1e-9 && (one.worst_z + 2.1).abs() < 1e-9);
        assert!(rig_report(&[1.5, -1.5]).rig_conflict().is_none());
        let two = rig_report(&[1.9, 1.9])
            .rig_conflict()
            .expect("two points at z = 1.9");
        assert!((two.chi2 - 7.22).abs() < 1e-9);
        assert!(
            (two.p_value - (-3.61f64).exp()).abs() < 1e-12,
            "{}",
            two.p_value
        );
        assert!((two.rms_z - 1.9).abs() < 1e-9);
        assert!(two.to_string().starts_with(
            "the fitted law's μ_d misses the rig curve rig.csv as a whole: Σz² = 7.2 over 2 \
             points (rms z 1.90;"
        ));
        // No rig curve: nothing to disagree with.
        let mut none = rig_report(&[3.0]);
        none.friction_curve = None;
        assert!(none.rig_conflict().is_none());
    }
}
