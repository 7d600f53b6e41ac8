//! Parameters the model cannot run with: [`ParamError`], naming the parameter and its value; a
//! friction table whose law or keys are wrong: [`FrictionTableError`]; and recorded tracks the
//! neck/lip model cannot be driven by: [`TrackError`].

/// A blade or friction parameter that is not finite or not physical. Always an input error: the
/// parameters come from the user's blade file or job.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    /// A blade parameter (its key in the blade file) that must be finite and > 0 (`strictly`) or
    /// ≥ 0.
    #[error(
        "blade parameter {name} = {value} must be finite and {}",
        if *strictly { "> 0" } else { ">= 0" }
    )]
    Blade {
        name: &'static str,
        value: f64,
        strictly: bool,
    },
    /// The drive's speed harmonic outside `|h| < 0.5`: a linkage departs from a sine by a few per
    /// cent; at half the peak speed the drive is no longer a perturbed sine.
    #[error(
        "blade parameter drive_speed_harmonic = {value} must be finite with |h| < 0.5 (a fraction of the drive's peak speed aω)"
    )]
    DriveHarmonic { value: f64 },
    /// A shoulder parameter (`shoulder.<name>`) that must be finite and > 0.
    #[error("blade parameter shoulder.{name} = {value} must be finite and > 0")]
    Shoulder { name: &'static str, value: f64 },
    /// Neck and lip without mass or inertia: the effective masses m_θ, m_φ are not positive.
    #[error("blade: the neck and lip need mass or inertia (m_θ, m_φ > 0)")]
    NoMass { m_theta: f64, m_phi: f64 },
    /// The exponential law's coefficients.
    #[error(
        "friction law: A, B, C must be finite and >= 0 with A + C > 0 (got A = {a}, B = {b_s_per_m}, C = {c})"
    )]
    Exponential { a: f64, b_s_per_m: f64, c: f64 },
    /// The exponential law with a viscous term.
    #[error(
        "friction law exponential_viscous: a, b_s_per_m, c, d_s_per_m must be finite and >= 0 with a + c > 0 (got a = {a}, b_s_per_m = {b_s_per_m}, c = {c}, d_s_per_m = {d_s_per_m})"
    )]
    ExponentialViscous {
        a: f64,
        b_s_per_m: f64,
        c: f64,
        d_s_per_m: f64,
    },
    /// Stribeck's law with a shape exponent.
    #[error(
        "friction law stribeck: a, c must be finite and >= 0 with a + c > 0, v_s_m_per_s and delta finite and > 0 (got a = {a}, c = {c}, v_s_m_per_s = {v_s_m_per_s}, delta = {delta})"
    )]
    Stribeck {
        a: f64,
        c: f64,
        v_s_m_per_s: f64,
        delta: f64,
    },
    /// Coulomb's coefficients.
    #[error(
        "Coulomb friction: need 0 <= mu_k <= mu_s, mu_s > 0 (got mu_s = {mu_s}, mu_k = {mu_k})"
    )]
    Coulomb { mu_s: f64, mu_k: f64 },
    /// Leine's coefficients.
    #[error("Leine friction: need mu_s > 0, delta >= 0 (got {mu_s}, {delta_s_per_m})")]
    Leine { mu_s: f64, delta_s_per_m: f64 },
}

impl From<ParamError> for crate::Error {
    fn from(e: ParamError) -> Self {
        crate::Error::stage(e, true)
    }
}

impl ParamError {
    /// The model stage's parameter error inside `e`, if it is one.
    pub fn of(e: &crate::Error) -> Option<&ParamError> {
        e.stage_error()
    }
}

/// Samples that cannot be smoothed into a track for the neck/lip model's prescribed head
/// ([`crate::model::necklip::SmoothedTrack`], [`crate::model::necklip::PrescribedHead`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TrackError {
    /// A local-quadratic smooth without a positive step or with fewer samples than one window.
    #[error(
        "smoothed track: need dt > 0 and at least {window} samples (got dt = {dt_s}, {samples} samples)"
    )]
    TooShort {
        dt_s: f64,
        samples: usize,
        window: usize,
    },
    /// Fewer than 3 finite samples in the local window around `t_s` (a gap longer than the window).
    #[error("smoothed track: too few samples around t = {t_s:.6} s for a local fit")]
    Gap { t_s: f64 },
    /// A kernel smooth without a positive step or width, or with fewer than 3 finite samples.
    #[error(
        "prescribed head: need dt > 0, σ > 0 and at least 3 finite samples (got dt = {dt_s}, σ = {sigma_s}, {finite} finite)"
    )]
    Kernel {
        dt_s: f64,
        sigma_s: f64,
        finite: usize,
    },
}

/// A friction table (`[friction]` of a blade file, or a truth's law) whose law or keys are wrong
/// ([`crate::model::FrictionLaw::from_coefficients`]). `known` lists the law's own keys.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FrictionTableError {
    /// A law name that is none of [`crate::model::FrictionLaw::LAWS`].
    #[error(
        "unknown friction law `{law}` (known: {}); the keys each needs: {}",
        known_laws(),
        law_keys()
    )]
    UnknownLaw { law: String },
    /// A key the law does not have.
    #[error("friction law `{law}` has no key `{key}` (known: {}){}", known.join(", "), missing_suffix(missing))]
    UnknownKey {
        law: &'static str,
        key: String,
        known: Vec<&'static str>,
        missing: Vec<&'static str>,
    },
    /// Keys the law needs that the table lacks.
    #[error("friction law `{law}` needs {}{}", known.join(", "), missing_suffix(missing))]
    MissingKeys {
        law: &'static str,
        known: Vec<&'static str>,
        missing: Vec<&'static str>,
    },
}

/// The laws' names, comma-separated.
fn known_laws() -> String {
    crate::model::FrictionLaw::LAWS.map(|(n, _)| n).join(", ")
}

/// Each law with its keys: `exponential (a, b_s_per_m, c); …`.
fn law_keys() -> String {
    crate::model::FrictionLaw::LAWS
        .iter()
        .map(|(n, k)| format!("{n} ({})", k.join(", ")))
        .collect::<Vec<_>>()
        .join("; ")
}

/// `; missing a, b` for missing keys, nothing without.
fn missing_suffix(missing: &[&str]) -> String {
    if missing.is_empty() {
        String::new()
    } else {
        format!("; missing {}", missing.join(", "))
    }
}
