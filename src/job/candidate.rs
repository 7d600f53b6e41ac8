//! The model hierarchy a fit chooses from: candidates ([`Candidate`]) and which bands each can
//! produce.

use crate::model::LawKind;
use crate::simulate::blade::ModelKind;
use crate::spectrum::features::BandSpec;
use serde::Serialize;

/// Lower edge of a band, Hz, at or above which the band asks for the neck–lip mode. The head
/// model ([`ModelKind::Head1dof`]) has only the head's low mode (tens of Hz, seed §0.1: 12.9 and
/// 78.4 Hz) and the stick–slip it drives; the neck–lip component sits at hundreds of Hz (seed: 359–692
/// and ~900 Hz; free neck 195 Hz).
pub const NECK_BAND_MIN_HZ: f64 = 150.0;

/// One candidate of the model hierarchy: a model kind, with or without shoulder contact, and the
/// friction law it is fitted with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Candidate {
    pub kind: ModelKind,
    pub shoulder: bool,
    /// The friction law when the job compares laws (`[fit] laws`); `None`: the blade file's law.
    pub law: Option<LawKind>,
}

impl Candidate {
    /// Every model a job may list in `[fit] models`, smallest first, each with the blade file's
    /// law.
    pub fn all() -> Vec<Candidate> {
        ModelKind::ALL
            .iter()
            .flat_map(|&kind| {
                let shoulders: &[bool] = if kind.has_neck_mode() {
                    &[false, true]
                } else {
                    &[false]
                };
                shoulders.iter().map(move |&shoulder| Candidate {
                    kind,
                    shoulder,
                    law: None,
                })
            })
            .collect()
    }

    /// The name used in jobs and reports: the model's name, with `+shoulder` when it has one and
    /// `@<law>` when the job compares friction laws (`blade2dof+shoulder@exponential_viscous`).
    pub fn name(&self) -> String {
        self.to_string()
    }

    /// Every candidate the job's `models` and `laws` make: each model with each law (models in
    /// their order, laws nested first: [`LawKind`]'s order), or the models as they are when
    /// `laws` is empty (each with the blade file's law).
    pub fn with_laws(models: &[Candidate], laws: &[LawKind]) -> Vec<Candidate> {
        if laws.is_empty() {
            return models.to_vec();
        }
        let mut laws = laws.to_vec();
        laws.sort();
        laws.dedup();
        models
            .iter()
            .flat_map(|m| {
                laws.iter().map(move |&law| Candidate {
                    law: Some(law),
                    ..*m
                })
            })
            .collect()
    }

    /// Whether this candidate contains `smaller` as a special case, one step up the hierarchy:
    /// the same model and law with the shoulder added, or the same model and shoulder with a law
    /// that contains the smaller one's ([`LawKind::contains`]). The smaller model's optimum is then
    /// a point of this one's parameter space (the shoulder above every angle the neck reaches,
    /// D = 0, δ = 1 with v_s = 1/B), where its search starts and which its fit cannot end below.
    pub fn extends(&self, smaller: &Candidate) -> bool {
        if self.kind != smaller.kind {
            return false;
        }
        let shoulder_added = self.shoulder && !smaller.shoulder && self.law == smaller.law;
        let law_widened = self.shoulder == smaller.shoulder
            && matches!((self.law, smaller.law), (Some(l), Some(s)) if l.contains(s));
        shoulder_added || law_widened
    }

    /// Whether this candidate takes one of `bands` from the recording's head track (the neck/lip
    /// model on a prescribed head, for a band below [`NECK_BAND_MIN_HZ`]): its likelihood there is
    /// not a model's, so it cannot be compared with the others'.
    pub fn imposes_a_band(&self, bands: &[BandSpec]) -> bool {
        !self.kind.has_head_mode() && bands.iter().any(|b| b.range_hz[0] < NECK_BAND_MIN_HZ)
    }

    /// Why this candidate cannot produce `bands` (None if it can).
    pub fn cannot_produce(&self, bands: &[BandSpec]) -> Option<String> {
        if !self.kind.has_head_mode() {
            return bands
                .iter()
                .find(|b| b.range_hz[0] < NECK_BAND_MIN_HZ)
                .map(|b| {
                    format!(
                        "imposes band '{}' ({:.0}–{:.0} Hz) from the recording's head track instead of modelling it",
                        b.name, b.range_hz[0], b.range_hz[1]
                    )
                });
        }
        if self.kind.has_neck_mode() {
            return None;
        }
        bands
            .iter()
            .find(|b| b.range_hz[0] >= NECK_BAND_MIN_HZ)
            .map(|b| {
                format!(
                    "has no neck–lip mode for band '{}' ({:.0}–{:.0} Hz)",
                    b.name, b.range_hz[0], b.range_hz[1]
                )
            })
    }
}

impl Candidate {
    /// How reasons name `smaller`, a candidate this one [extends](Candidate::extends): "the model
    /// without shoulder" when this one adds the shoulder, else its name.
    pub fn nested_phrase(&self, smaller: &Candidate) -> String {
        if self.shoulder && !smaller.shoulder {
            "the model without shoulder".into()
        } else {
            smaller.to_string()
        }
    }
}

/// Suffix of a candidate's name that adds shoulder contact.
pub(super) const SHOULDER_SUFFIX: &str = "+shoulder";

/// What separates a candidate's model from its friction law in its name.
pub const LAW_SEPARATOR: char = '@';

impl std::fmt::Display for Candidate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.kind.name())?;
        if self.shoulder {
            f.write_str(SHOULDER_SUFFIX)?;
        }
        if let Some(law) = self.law {
            write!(f, "{LAW_SEPARATOR}{law}")?;
        }
        Ok(())
    }
}

impl std::str::FromStr for Candidate {
    type Err = crate::names::UnknownName;
    /// Parses a model name with an optional `+shoulder` (the head model has no shoulder) and an
    /// optional `@<law>`.
    fn from_str(name: &str) -> std::result::Result<Self, Self::Err> {
        let (model, law) = match name.split_once(LAW_SEPARATOR) {
            Some((model, law)) => (model, Some(law.parse::<LawKind>()?)),
            None => (name, None),
        };
        let (base, shoulder) = match model.strip_suffix(SHOULDER_SUFFIX) {
            Some(base) => (base, true),
            None => (model, false),
        };
        Candidate::all()
            .into_iter()
            .find(|c| c.shoulder == shoulder && c.kind.name() == base)
            .map(|c| Candidate { law, ..c })
            .ok_or_else(|| crate::names::UnknownName {
                kind: "model",
                given: model.to_string(),
                known: Candidate::all()
                    .iter()
                    .map(|c| c.to_string())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }
}

impl Serialize for Candidate {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for Candidate {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// The smallest model of the hierarchy that can produce every band in `bands`: the head model when
/// all bands lie below [`NECK_BAND_MIN_HZ`], else the full blade.
///
/// The neck/lip model on a prescribed head is not in this default chain, although it models less:
/// on a tracked recording it costs more, not less: the tracking noise in the prescribed head drives
/// extra stick–slip transitions and many more integrator steps per run, and fitted to the high band
/// alone it can match the peak with the wrong parameters (docs/validation.md). Name it in `[fit] models`
/// when the head's suspension (k0, c0, the head mass) is unknown: it takes the head's motion from
/// the recording instead.
pub fn smallest_capable_model(bands: &[BandSpec]) -> ModelKind {
    [ModelKind::Head1dof, ModelKind::Blade2dof]
        .into_iter()
        .find(|&kind| {
            Candidate {
                kind,
                shoulder: false,
                law: None,
            }
            .cannot_produce(bands)
            .is_none()
        })
        .unwrap_or(ModelKind::Blade2dof)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn band(name: &str, lo: f64, hi: f64) -> BandSpec {
        BandSpec::new(name, [lo, hi], 1024)
    }

    /// The default chain: the head model for low bands only, the full blade as soon as a band
    /// needs the neck–lip mode; the neck/lip model only when named.
    #[test]
    fn smallest_capable_model_follows_the_bands() {
        let low = band("low", 30.0, 300.0);
        let high = band("high", 500.0, 5000.0);
        assert_eq!(
            smallest_capable_model(std::slice::from_ref(&low)),
            ModelKind::Head1dof
        );
        assert_eq!(
            smallest_capable_model(std::slice::from_ref(&high)),
            ModelKind::Blade2dof
        );
        assert_eq!(
            smallest_capable_model(&[low.clone(), high]),
            ModelKind::Blade2dof
        );
        // The neck/lip model imposes a low band, so it cannot produce one.
        let nl = "necklip+shoulder".parse::<Candidate>().unwrap();
        assert!(nl.shoulder && nl.kind == ModelKind::Necklip);
        assert!(nl.cannot_produce(&[low]).is_some());
    }
}
