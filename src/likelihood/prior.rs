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
    /// `w` ([`crate::fit::posterior_tempering`]), the prior not, and the prior's parameters
    /// distributed with its own density in θ or ln θ ([`Prior::log_jacobian_u`]).
    pub fn log_posterior(
        &self,
        cost_nats: f64,
        w: f64,
        free: &[FreeParam],
        base: &BladeParams,
        u: &[f64],
    ) -> f64 {
        let prior = self.nats(&params_at(free, base, u));
        -w * (cost_nats - prior) - prior + self.log_jacobian_u(free, u)
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
}
