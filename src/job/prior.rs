//! `[fit.priors]`: what a user knows about the fitted parameters before the recording, as the job
//! states it. A prior per parameter (normal, or log-normal for a positive magnitude) in the
//! parameter's own SI units, and a friction-rig curve μ(v) as a prior on the friction law
//! ([`FrictionCurvePrior`], read by [`super::rig`]). How they enter the fit: docs/priors.md, "Priors".

use super::rig::{self, RigCurve};
use super::{Check, Key, Objective};
use crate::Result;
use crate::model::ParamId;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// `[fit.priors]`: a prior per fitted parameter, by the names of `[fit.parameters]` (and `k1c`,
/// `theta_c` of a `+shoulder` candidate), and the rig curve.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq)]
#[serde(try_from = "RawPriors")]
pub struct PriorsSection {
    /// `[fit.priors.friction_curve]`: a rig's μ(v) as a prior on the friction law.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_curve: Option<FrictionCurvePrior>,
    /// Parameter → its prior, e.g. `theta_c = { normal = { mean = 0.08, sd = 0.01 } }`.
    #[serde(flatten)]
    pub parameters: BTreeMap<ParamId, ParamPrior>,
}

/// `[fit.priors]` as TOML has it: each parameter's prior read in [`PriorsSection::try_from`], so
/// that an error names the parameter's key.
#[derive(Deserialize)]
struct RawPriors {
    #[serde(default)]
    friction_curve: Option<FrictionCurvePrior>,
    #[serde(flatten)]
    parameters: BTreeMap<String, toml::Value>,
}

/// A `[fit.priors]` entry that is no prior: its key names no parameter, or its value is no
/// normal or log-normal table.
#[derive(Debug, thiserror::Error)]
pub enum PriorEntryError {
    /// The key names no parameter.
    #[error("[fit.priors] {0}")]
    UnknownParameter(#[from] crate::names::UnknownName),
    /// The value is not a prior table; `message` is the TOML reader's.
    #[error(
        "[fit.priors] {key}: {message} (write {key} = {{ normal = {{ mean = M, sd = S }} }} \
         or {key} = {{ lognormal = {{ median = M, sd_log = S }} }}, in {meaning})"
    )]
    NotAPrior {
        key: String,
        message: String,
        meaning: &'static str,
    },
}

impl TryFrom<RawPriors> for PriorsSection {
    type Error = PriorEntryError;
    fn try_from(raw: RawPriors) -> std::result::Result<Self, PriorEntryError> {
        let mut parameters = BTreeMap::new();
        for (key, value) in raw.parameters {
            let id: ParamId = key.parse()?;
            let prior: ParamPrior =
                value
                    .try_into()
                    .map_err(|e: toml::de::Error| PriorEntryError::NotAPrior {
                        message: e.message().to_string(),
                        meaning: id.meaning(),
                        key,
                    })?;
            parameters.insert(id, prior);
        }
        Ok(PriorsSection {
            friction_curve: raw.friction_curve,
            parameters,
        })
    }
}

impl PriorsSection {
    /// True when the job states no prior.
    pub fn is_empty(&self) -> bool {
        self.parameters.is_empty() && self.friction_curve.is_none()
    }
}

/// A prior on one parameter, in its own SI units (those of [`ParamId::meaning`]).
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum ParamPrior {
    /// Normal with this mean and standard deviation: `(θ − mean)²/(2 sd²)` nats.
    Normal { mean: f64, sd: f64 },
    /// Log-normal: `ln θ` normal about `ln median` with standard deviation `sd_log`,
    /// `(ln θ − ln median)²/(2 sd_log²)` nats. For a positive magnitude known to a factor
    /// (`sd_log = 0.3`: about ±35 % at 1σ).
    Lognormal { median: f64, sd_log: f64 },
}

impl ParamPrior {
    /// The prior's central 68.27 % interval: mean ± sd, or median·e^(±sd_log).
    pub fn interval(&self) -> [f64; 2] {
        match *self {
            ParamPrior::Normal { mean, sd } => [mean - sd, mean + sd],
            ParamPrior::Lognormal { median, sd_log } => {
                [median * (-sd_log).exp(), median * sd_log.exp()]
            }
        }
    }

    /// Why the prior is unusable for a parameter searched within `[lower, upper]`, if it is.
    fn problem(&self, lower: f64) -> Option<String> {
        match *self {
            ParamPrior::Normal { mean, sd } => {
                if !mean.is_finite() {
                    Some(format!("normal prior: mean must be finite (got {mean})"))
                } else if !(sd.is_finite() && sd > 0.0) {
                    Some(format!("normal prior: sd must be > 0 (got {sd})"))
                } else {
                    None
                }
            }
            ParamPrior::Lognormal { median, sd_log } => {
                if !(median.is_finite() && median > 0.0) {
                    Some(format!(
                        "log-normal prior: median must be > 0 (got {median})"
                    ))
                } else if !(sd_log.is_finite() && sd_log > 0.0) {
                    Some(format!(
                        "log-normal prior: sd_log must be > 0 (got {sd_log})"
                    ))
                } else if lower <= 0.0 {
                    Some(format!(
                        "log-normal prior on a parameter whose bounds include values <= 0 (lower \
                         bound {lower}): a log-normal density is zero there; raise the lower bound \
                         above 0 or use a normal prior"
                    ))
                } else {
                    None
                }
            }
        }
    }
}

crate::names::named_enum! {
    /// The unit of a rig curve's speed column.
    #[derive(Default)]
    pub enum SpeedUnit: "speed unit" {
        /// Metres per second.
        #[default]
        MetresPerSecond => "m/s",
        /// Millimetres per second.
        MillimetresPerSecond => "mm/s",
        /// Revolutions per minute of a rotary rig: `v = rpm·2π r/60` with the track radius `r`
        /// (`track_radius_m`).
        Rpm => "rpm",
    }
}

/// A rotary rig's track radius: one for every row, or one per group of `group_by`.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum TrackRadius {
    /// The radius of every row, m.
    All(f64),
    /// Group value (as the file spells it) → radius, m.
    PerGroup(BTreeMap<String, f64>),
}

/// `[fit.priors.friction_curve]`: a CSV of slip speed and friction coefficient from a rig, as a
/// prior on the fitted law's dynamic coefficient μ_d(v). Columns are chosen by their header names.
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FrictionCurvePrior {
    /// The CSV, relative to the job file.
    pub file: PathBuf,
    /// Header of the slip-speed column.
    pub speed_column: String,
    /// Unit of the speed column (default `m/s`).
    #[serde(default)]
    pub speed_unit: SpeedUnit,
    /// `speed_unit = "rpm"`: the track radius, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub track_radius_m: Option<TrackRadius>,
    /// Header of the friction-coefficient column.
    pub coefficient_column: String,
    /// Header of the coefficient's 1σ column (rows used one by one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sd_column: Option<String>,
    /// One 1σ of the coefficient for every point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sd: Option<f64>,
    /// Header of a column whose value groups the rows (a rig's step): each group is one point at
    /// its mean speed, with its mean coefficient and their sample standard deviation as 1σ.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group_by: Option<String>,
}

impl FrictionCurvePrior {
    /// The columns the file's header must name, in the order speed, coefficient, 1σ, group.
    pub fn columns(&self) -> Vec<&str> {
        let mut c = vec![self.speed_column.as_str(), self.coefficient_column.as_str()];
        c.extend(self.sd_column.as_deref());
        c.extend(self.group_by.as_deref());
        c
    }

    /// Why the settings do not describe a curve, and at which key.
    fn problem(&self) -> Option<(&'static str, String)> {
        let radius_ok = |r: f64| r.is_finite() && r > 0.0;
        match (&self.sd_column, self.sd, &self.group_by) {
            (Some(_), Some(_), _) => {
                return Some(("sd", "give sd_column or sd, not both".into()));
            }
            (Some(_), None, Some(_)) => {
                return Some((
                    "sd_column",
                    "with group_by each group's 1σ is its rows' standard deviation (or sd); \
                     sd_column reads rows one by one"
                        .into(),
                ));
            }
            (None, None, None) => {
                return Some((
                    "sd",
                    "the coefficient's 1σ is missing: give sd_column (a column of 1σ), sd (one 1σ \
                     for every point) or group_by (each group's standard deviation)"
                        .into(),
                ));
            }
            _ => {}
        }
        if let Some(s) = self.sd
            && !(s.is_finite() && s > 0.0)
        {
            return Some(("sd", format!("sd must be > 0 (got {s})")));
        }
        match (self.speed_unit, &self.track_radius_m) {
            (SpeedUnit::Rpm, None) => Some((
                "track_radius_m",
                "speed_unit = \"rpm\" needs track_radius_m (m), to give v = rpm·2π r/60".into(),
            )),
            (SpeedUnit::Rpm, Some(TrackRadius::All(r))) if !radius_ok(*r) => Some((
                "track_radius_m",
                format!("track_radius_m must be > 0 (got {r})"),
            )),
            (SpeedUnit::Rpm, Some(TrackRadius::PerGroup(m))) => {
                if self.group_by.is_none() {
                    Some((
                        "track_radius_m",
                        "a radius per group needs group_by (the column whose values it names)"
                            .into(),
                    ))
                } else {
                    m.iter().find(|(_, r)| !radius_ok(**r)).map(|(g, r)| {
                        (
                            "track_radius_m",
                            format!("track_radius_m of group '{g}' must be > 0 (got {r})"),
                        )
                    })
                }
            }
            (SpeedUnit::Rpm, Some(_)) => None,
            (_, Some(_)) => Some((
                "track_radius_m",
                "track_radius_m converts rpm: set speed_unit = \"rpm\"".into(),
            )),
            (_, None) => None,
        }
    }
}

/// The bounds of every parameter a candidate of the job may fit: `[fit.parameters]`, the
/// coefficients a law of `[fit] laws` adds with its default bounds, and the shoulder's two from
/// `[fit.shoulder]` when a `+shoulder` candidate is listed.
fn fittable(job: &super::FitJob, free: &[(ParamId, f64, f64)]) -> BTreeMap<ParamId, [f64; 2]> {
    let mut out: BTreeMap<ParamId, [f64; 2]> =
        free.iter().map(|&(id, lo, hi)| (id, [lo, hi])).collect();
    for &law in &job.fit.laws {
        for f in super::laws::law_free(free, law) {
            out.entry(f.name).or_insert([f.lower, f.upper]);
        }
    }
    if let Some(sb) = job.fit.shoulder
        && job.fit.models.iter().any(|m| m.shoulder)
    {
        out.entry(ParamId::K1c).or_insert(sb.k1c);
        out.entry(ParamId::ThetaC).or_insert(sb.theta_c);
    }
    out
}

impl Check<'_> {
    /// `[fit.priors]` checked against the fitted parameters `free`, and the rig curve read (`dir`:
    /// the job's directory).
    ///
    /// # Errors
    /// [`Error::Parse`] at the offending key: a prior on a parameter no candidate fits, a
    /// non-positive sd, a log-normal prior on a parameter whose bounds include values ≤ 0, a rig
    /// curve without a fitted friction coefficient, priors beside the features objective or a
    /// target job; the rig file's own errors ([`rig::read`]).
    pub(super) fn priors(
        &self,
        free: &[(ParamId, f64, f64)],
        dir: &Path,
    ) -> Result<Option<RigCurve>> {
        let priors = &self.job.fit.priors;
        if priors.is_empty() {
            return Ok(None);
        }
        let at_priors = [Key::Name("fit"), Key::Name("priors")];
        if self.job.fit.objective != Objective::Likelihood || self.job.targets.is_some() {
            return Err(self.error(
                &at_priors,
                "[fit.priors] add a negative log prior to the recording's likelihood: they need a \
                 [recording] and [fit] objective = \"likelihood\" (the default)",
            ));
        }
        let fittable = fittable(self.job, free);
        for (id, prior) in &priors.parameters {
            let at = [Key::Name("fit"), Key::Name("priors"), Key::Name(id.name())];
            let Some(&[lower, _]) = fittable.get(id) else {
                return Err(self.error(
                    &at,
                    format!(
                        "[fit.priors] {id}: the job does not fit '{id}' ({}); a prior is given \
                         only for a parameter of [fit.parameters], a coefficient of a law in \
                         [fit] laws, or k1c, theta_c of a listed +shoulder candidate",
                        id.meaning()
                    ),
                ));
            };
            if let Some(why) = prior.problem(lower) {
                return Err(self.error(&at, format!("[fit.priors] {id}: {why}")));
            }
        }
        let Some(curve) = &priors.friction_curve else {
            return Ok(None);
        };
        let at = |key: &'static str| {
            [
                Key::Name("fit"),
                Key::Name("priors"),
                Key::Name("friction_curve"),
                Key::Name(key),
            ]
        };
        if !fittable.keys().any(|id| id.is_friction()) {
            return Err(self.error(
                &at("file"),
                "[fit.priors.friction_curve] is a prior on the friction law's μ_d(v): free at \
                 least one of its coefficients (A, B, C, ...) in [fit.parameters]",
            ));
        }
        if let Some((key, why)) = curve.problem() {
            return Err(self.error(&at(key), format!("[fit.priors.friction_curve] {why}")));
        }
        rig::read(&dir.join(&curve.file), curve).map(Some)
    }
}
