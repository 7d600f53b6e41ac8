//! The report page's opening summary: what was found (the chosen model, the friction law and the
//! neck stiffness with their intervals in words and units), whether the fit is good (the
//! goodness-of-fit test, the tolerance check, the peaks, the parameters the data determine, the
//! warnings that need attention), and what to do when it is not.

use super::html::num;
use super::warning::PageWarning;
use crate::fit::tolerance::Verdict;
use crate::fit::{FitResult, FitWarning, FittedParam, Severity};
use crate::model::ParamId;
use serde::Serialize;

/// Relative distance between the model's peak and the measured (or target) one above which the
/// summary marks the peaks as off: 2 %, the accuracy asked of the fitted model's lines.
pub const PEAK_OFF_FRACTION: f64 = 0.02;

/// One check of the fit: `status` is `"ok"`, `"bad"`, or `"none"` when the result holds no such
/// check.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    pub status: &'static str,
    pub text: String,
}

/// What the summary shows, already in words.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// The chosen model and how it was chosen.
    pub model: String,
    /// The fitted parameters in words: the friction law, the neck stiffness, then any other.
    pub findings: Vec<String>,
    pub checks: Vec<Check>,
    /// True when no check failed.
    pub good: bool,
    /// What to do, one item per failed check (empty when the fit is good).
    pub todo: Vec<String>,
}

/// The summary of result `r` with the page's `warnings`.
pub fn summary(r: &FitResult, warnings: &[PageWarning]) -> Summary {
    let checks_and_todo = checks(r, warnings);
    let good = checks_and_todo.iter().all(|(c, _)| c.status != "bad");
    let todo = checks_and_todo
        .iter()
        .filter_map(|(_, t)| t.clone())
        .collect();
    Summary {
        model: model_words(r),
        findings: findings(r),
        checks: checks_and_todo.into_iter().map(|(c, _)| c).collect(),
        good,
        todo,
    }
}

/// "Model blade2dof (…), chosen by TIC among N candidates; the next best …", and which candidates
/// the recording cannot tell from it (TIC within [`crate::fit::select::INDISTINGUISHABLE_TIC`]).
fn model_words(r: &FitResult) -> String {
    let label = super::html::model_label(r.model);
    let named = if label.is_empty() {
        format!("Model {}", r.model)
    } else {
        format!("Model {} ({label})", r.model)
    };
    let others: Vec<_> = r.model_trials.iter().filter(|t| !t.chosen).collect();
    if others.is_empty() {
        return format!("{named}, the only model fitted.");
    }
    // The criterion the choice read: TIC where the result has it, AIC in older results.
    let criterion = |e: &crate::fit::TrialEvidence| match e.delta_tic {
        Some(d) => ("TIC", d),
        None => ("AIC", e.delta_aic),
    };
    let next = others
        .iter()
        .filter_map(|t| t.evidence.as_ref().map(|e| (t, criterion(e))))
        .filter(|(_, (_, d))| d.is_finite())
        .min_by(|a, b| a.1.1.total_cmp(&b.1.1));
    let near = crate::fit::select::INDISTINGUISHABLE_TIC;
    // Which rule reported the chosen candidate before `t`: fewer parameters, or as many and the
    // lower TIC.
    let rule = |t: &crate::fit::ModelTrial| {
        let chosen_k = r
            .model_trials
            .iter()
            .find(|c| c.chosen)
            .map(|c| c.parameters.len());
        if chosen_k.is_some_and(|k| k < t.parameters.len()) {
            "with fewer parameters"
        } else {
            "with the lower TIC"
        }
    };
    match next {
        Some((t, ("TIC", d))) if d <= near => format!(
            "{named}, chosen by TIC among {} candidates; {} is not distinguishable by this \
             recording (TIC {d:+.1}, within {near}), and the {} {} is reported.",
            r.model_trials.len(),
            t.model,
            if t.model.law != r.model.law
                && (t.model.kind, t.model.shoulder) == (r.model.kind, r.model.shoulder)
            {
                "friction law"
            } else {
                "model"
            },
            rule(t)
        ),
        Some((t, (name, d))) => format!(
            "{named}, chosen by {name} among {} candidates; the next best, {}, has a {name} \
             {d:.1} higher.",
            r.model_trials.len(),
            t.model
        ),
        None => format!(
            "{named}, chosen among {} candidates (see the model comparison).",
            r.model_trials.len()
        ),
    }
}

/// Digits enough that the value and its interval's ends read apart (3 to 6 significant digits).
fn digits(values: &[f64]) -> usize {
    (3..=6)
        .find(|&d| {
            let s: Vec<String> = values.iter().map(|v| num(*v, d)).collect();
            s.iter()
                .enumerate()
                .all(|(i, a)| s[i + 1..].iter().all(|b| a != b))
        })
        .unwrap_or(6)
}

/// `x` with its unit, e.g. "70.6 s/m", or the number alone for a dimensionless parameter.
fn with_unit(x: String, id: ParamId) -> String {
    x + &id.unit_suffix()
}

/// A fitted parameter in words: its value, and its interval (or 1σ) with the level.
fn value_words(p: &FittedParam) -> String {
    if !p.determined {
        return format!(
            "{} = {} (not determined by the data: read it with care)",
            p.name,
            with_unit(num(p.value, 3), p.name)
        );
    }
    match &p.interval {
        Some(i) => {
            let d = digits(&[p.value, i.lo, i.hi]);
            format!(
                "{} = {} ({:.0} % interval {} to {})",
                p.name,
                with_unit(num(p.value, d), p.name),
                100.0 * i.level,
                num(i.lo, d),
                with_unit(num(i.hi, d), p.name)
            )
        }
        None if p.std_error.is_finite() => {
            let d = digits(&[p.value, p.value + p.std_error]);
            format!(
                "{} = {} ± {} (1σ)",
                p.name,
                with_unit(num(p.value, d), p.name),
                with_unit(num(p.std_error, 2), p.name)
            )
        }
        None => format!("{} = {}", p.name, with_unit(num(p.value, 3), p.name)),
    }
}

/// The fitted parameters in words: the friction law (with its value at rest and in fast slip when
/// the seed's A, B and C were all fitted, and the curve over the measured slip speeds), the neck
/// stiffness, then every other fitted parameter.
fn findings(r: &FitResult) -> Vec<String> {
    let get = |id: ParamId| r.parameters.iter().find(|p| p.name == id);
    let mut out = Vec::new();
    let law: Vec<&FittedParam> = r
        .parameters
        .iter()
        .filter(|p| p.name.is_friction())
        .collect();
    if !law.is_empty() {
        let formula = r
            .friction_curve
            .as_ref()
            .map_or(SEED_LAW, |c| law_formula(&c.fitted_law));
        let mut s = format!(
            "Friction law μ_d(v) = {formula}: {}.",
            law.iter()
                .map(|p| value_words(p))
                .collect::<Vec<_>>()
                .join(", ")
        );
        let abc = (get(ParamId::A), get(ParamId::B), get(ParamId::C));
        match (formula == SEED_LAW, abc) {
            (true, (Some(a), Some(b), Some(c))) => {
                s += &format!(
                    " The friction coefficient falls from {} at the onset of slip to {} in fast slip, \
                     half way by {} mm/s.",
                    num(a.value + c.value, 3),
                    num(c.value, 3),
                    num(std::f64::consts::LN_2 / b.value * 1e3, 2)
                );
            }
            (true, _) => s += " The law's other coefficients are held at the blade file's values.",
            (false, _) => {}
        }
        out.push(s);
    }
    out.extend(r.friction_curve.as_ref().map(curve_words));
    if let Some(k1) = get(ParamId::K1) {
        out.push(format!("Neck stiffness {}.", value_words(k1)));
    }
    let rest: Vec<String> = r
        .parameters
        .iter()
        .filter(|p| !p.name.is_friction() && p.name != ParamId::K1)
        .map(value_words)
        .collect();
    if !rest.is_empty() {
        out.push(format!("Also fitted: {}.", rest.join("; ")));
    }
    out
}

/// The seed's law in its coefficients' names.
const SEED_LAW: &str = "A·e^(−B·|v|) + C";

/// The law's formula in its coefficients' names.
fn law_formula(law: &crate::model::FrictionLaw) -> &'static str {
    use crate::model::FrictionLaw as L;
    match law {
        L::Exponential { .. } => SEED_LAW,
        L::ExponentialViscous { .. } => "A·e^(−B·|v|) + C + D·|v|",
        L::Stribeck { .. } => "C + A·e^(−(|v|/v_s)^δ)",
        L::Coulomb { .. } => "μ_k",
        L::Leine { .. } => "μ_s/(1 + δ·|v|)",
    }
}

/// The fitted law over the measured slip speeds in words: the range, μ_d at its ends with their
/// 1σ, and how far the truth lies when known.
fn curve_words(c: &crate::model::friction_curve::FrictionCurve) -> String {
    let [lo, hi] = c.measured_range_m_per_s;
    let at = |i: usize| match c.mu_d_sigma.get(i) {
        Some(s) => format!("{} ± {}", num(c.mu_d[i], 3), num(*s, 2)),
        None => num(c.mu_d[i], 3),
    };
    let mut s = format!(
        "Where the fitted motion slips ({}–{} mm/s, the 10th–90th percentile of its slip speeds), \
         μ_d runs from {} to {}{}.",
        num(1e3 * lo, 3),
        num(1e3 * hi, 3),
        at(0),
        at(c.mu_d.len() - 1),
        if c.mu_d_sigma.is_empty() {
            ""
        } else {
            " (1σ)"
        }
    );
    if let Some([lo, hi]) = c.band_edges().filter(|_| c.band_widened()) {
        let n = c.mu_d.len() - 1;
        s += &format!(
            " Points the search evaluated that are as likely as the fit within μ_d's profile \
             rise limit widen that band to {}–{} at the slowest and {}–{} at the fastest of \
             these speeds: the recording determines μ_d less well than its curvature says.",
            num(lo[0], 3),
            num(hi[0], 3),
            num(lo[n], 3),
            num(hi[n], 3)
        );
    }
    if let (Some(first), Some(last)) = (c.mu_d_envelope.first(), c.mu_d_envelope.last()) {
        s += &format!(
            " With the {} model(s) the recording does not distinguish from this one, μ_d lies \
             within {}–{} at the slowest and {}–{} at the fastest of these speeds.",
            c.alternative_laws.len(),
            num(first[0], 3),
            num(first[1], 3),
            num(last[0], 3),
            num(last[1], 3)
        );
        if let Some(open) = c.open_rel_half_width() {
            s += &format!(
                " Over the range they leave ±{} of μ_d open (the envelope's median half-width).",
                pct_abs(open)
            );
        }
    }
    if let Some(rms) = c.rms_rel_diff_to_truth {
        s += &format!(" It lies {} rms from the true law there", pct_abs(rms));
        if let Some(f) = c.truth_within_band {
            s += &format!(", inside the band at {} of the speeds", pct_abs(f));
        }
        if let Some(f) = c.truth_within_envelope {
            s += &format!(", inside that envelope at {}", pct_abs(f));
        }
        s += ".";
    }
    s
}

fn ok(text: String) -> (Check, Option<String>) {
    (Check { status: "ok", text }, None)
}

fn none(text: String) -> (Check, Option<String>) {
    (
        Check {
            status: "none",
            text,
        },
        None,
    )
}

fn bad(text: String, todo: &str) -> (Check, Option<String>) {
    (
        Check {
            status: "bad",
            text,
        },
        Some(todo.to_string()),
    )
}

/// Each check with what to do when it failed.
fn checks(r: &FitResult, warnings: &[PageWarning]) -> Vec<(Check, Option<String>)> {
    let mut out = vec![
        goodness_of_fit_check(r),
        tolerance_check(r),
        peak_check(r),
        determined_check(r),
        warnings_check(warnings),
    ];
    out.extend(interrupted_check(warnings));
    out
}

/// Whether the model explains the recording's spectra to their noise.
fn goodness_of_fit_check(r: &FitResult) -> (Check, Option<String>) {
    match &r.goodness_of_fit {
        Some(g) if g.fits() => ok(format!(
            "The model explains the recording's spectra to their noise (goodness of fit p = \
             {:.2}).",
            g.p_value
        )),
        Some(g) => bad(
            format!(
                "The model does not explain the recording's spectra to their noise (goodness of \
                 fit p = {:.3}): the spectra hold structure the model lacks, or the search missed \
                 a basin.{}",
                g.p_value,
                misfit_shape_words(r)
            ),
            "Fit more candidate models (e.g. with shoulder contact), check that each band holds \
             the line it is meant for, or bound a parameter known from the blade's drawing \
             (docs/likelihood.md, \"Goodness of fit\").",
        ),
        None if r.target_job => {
            none("No goodness-of-fit test: a target job has no measurement noise.".into())
        }
        None if r.interrupted => none("No goodness-of-fit test: the fit was interrupted.".into()),
        None => none("No goodness-of-fit test in this result (a joint fit has none).".into()),
    }
}

/// Where the misfit sits, as a sentence after the check's (empty when the result does not say).
fn misfit_shape_words(r: &FitResult) -> String {
    r.warnings
        .0
        .iter()
        .find_map(|w| match w {
            FitWarning::Misfit { shape, .. } => crate::likelihood::misfit::describe(shape),
            _ => None,
        })
        .map(|w| {
            let mut c = w.chars();
            let first: String = c
                .next()
                .map(|f| f.to_uppercase().collect())
                .unwrap_or_default();
            format!(" {first}{}.", c.as_str())
        })
        .unwrap_or_default()
}

/// Whether the integrator resolves the likelihood at the optimum.
fn tolerance_check(r: &FitResult) -> (Check, Option<String>) {
    match &r.tolerance_check {
        Some(t) => {
            let rtols = match (t.points.first(), t.points.last()) {
                (Some(a), Some(b)) => format!("rtol {:e} to {:e}", a.rtol, b.rtol),
                _ => String::new(),
            };
            match t.verdict() {
                Verdict::Resolved => ok(format!(
                    "The integrator resolves the likelihood at the optimum (the cost moves {} \
                     nats over {rtols}).",
                    num(t.spread_nats, 2)
                )),
                Verdict::Unresolved => bad(
                    format!(
                        "The integrator does not resolve the likelihood at the optimum (the cost \
                         moves {} nats over {rtols}): the intervals understate the uncertainty.",
                        num(t.spread_nats, 2)
                    ),
                    "Tighten [solver] rtol tenfold and refit (docs/likelihood.md, \"Tolerance check\").",
                ),
                Verdict::NotProbed => bad(
                    "The tolerance check could not run: every tighter simulation failed.".into(),
                    "Raise [solver] max_steps and refit, so the tolerance check can run.",
                ),
            }
        }
        None => none("No tolerance check in this result.".into()),
    }
}

/// Whether the model's peaks lie within [`PEAK_OFF_FRACTION`] of the measured ones (or the
/// targets) in every band.
fn peak_check(r: &FitResult) -> (Check, Option<String>) {
    let worst = r
        .peaks
        .iter()
        .filter(|p| p.rel_diff.is_finite())
        .max_by(|a, b| a.rel_diff.abs().total_cmp(&b.rel_diff.abs()));
    let against = if r.target_job {
        "the targets"
    } else {
        "the measured ones"
    };
    match worst {
        Some(p) if p.rel_diff.abs() <= PEAK_OFF_FRACTION => ok(format!(
            "The model's peaks lie within {} of {against} in every band.",
            pct_abs(p.rel_diff)
        )),
        Some(p) => bad(
            format!(
                "The model's peak in band '{}' lies {} from {against} (more than {:.0} %).",
                p.band,
                pct_abs(p.rel_diff),
                100.0 * PEAK_OFF_FRACTION
            ),
            "Compare the PSD figures: check that the band holds the line it is meant for and that \
             the search bounds let the model reach it.",
        ),
        None => none("No peaks to compare.".into()),
    }
}

/// Whether the data determine every fitted parameter.
fn determined_check(r: &FitResult) -> (Check, Option<String>) {
    let undetermined: Vec<String> = r
        .parameters
        .iter()
        .filter(|p| !p.determined)
        .map(|p| p.name.to_string())
        .collect();
    if undetermined.is_empty() {
        ok(format!(
            "The data determine every fitted parameter ({}).",
            r.parameters
                .iter()
                .map(|p| p.name.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ))
    } else {
        bad(
            format!(
                "The data leave {} undetermined.",
                crate::names::join(&undetermined, ", ")
            ),
            "Fix the undetermined parameters from another measurement, or narrow their bounds, \
             and refit.",
        )
    }
}

/// Whether any warning needs the reader's attention (and how many notes are for information).
fn warnings_check(warnings: &[PageWarning]) -> (Check, Option<String>) {
    let attention = warnings
        .iter()
        .filter(|w| w.severity() == Severity::Attention)
        .count();
    let information = warnings.len() - attention;
    let info = match information {
        0 => String::new(),
        1 => " (1 note for information, below)".into(),
        n => format!(" ({n} notes for information, below)"),
    };
    match attention {
        0 => ok(format!("No warning needs your attention{info}.")),
        n => bad(
            format!(
                "{n} warning{} need{} your attention{info}.",
                if n == 1 { "" } else { "s" },
                if n == 1 { "s" } else { "" }
            ),
            "Read the warnings under \"Needs your attention\": each says what to do.",
        ),
    }
}

/// The interrupted fit's check, when it was interrupted.
fn interrupted_check(warnings: &[PageWarning]) -> Option<(Check, Option<String>)> {
    if warnings
        .iter()
        .any(|w| matches!(w, PageWarning::Fit(FitWarning::Interrupted)))
    {
        Some(bad(
            "The fit was interrupted: the values are the best point the search had reached.".into(),
            "Run the fit again to the end.",
        ))
    } else {
        None
    }
}

/// |x| as a percentage with two significant digits, e.g. "0.089 %".
fn pct_abs(x: f64) -> String {
    format!("{} %", num(100.0 * x.abs(), 2))
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::fit::tolerance::{ToleranceCheck, TolerancePoint};
    use crate::likelihood::GoodnessOfFit;

    fn point(rtol: f64, cost_nats: f64) -> TolerancePoint {
        TolerancePoint {
            rtol,
            atol: rtol * 1e-2,
            cost_nats,
            transitions: 146,
        }
    }

    /// The curve's sentence: the range in mm/s, μ_d at its ends with 1σ, and the truth's rms
    /// difference (a fitted law 2 % above the truth everywhere: 2.0 %) with the band's coverage.
    #[test]
    fn the_friction_curve_is_said_in_words() {
        use crate::model::FrictionLaw;
        use crate::model::friction_curve::{FrictionCurve, Spread};
        let law = FrictionLaw::ExponentialViscous {
            a: 0.816,
            b_s_per_m: 10.0,
            c: 0.204,
            d_s_per_m: 0.0,
        };
        let truth = FrictionLaw::Exponential {
            a: 0.8,
            b_s_per_m: 10.0,
            c: 0.2,
        };
        let speeds: Vec<f64> = (0..=100).map(|i| i as f64 * 0.001).collect();
        let spread = Spread {
            ids: &[ParamId::C],
            sigma: &[0.001],
            corr: &[vec![1.0]],
        };
        let mut r = crate::report::html::tests::result();
        r.friction_curve = FrictionCurve::new(law, &speeds, Some(spread), Some(truth));
        let words = curve_words(r.friction_curve.as_ref().unwrap());
        assert!(
            words.starts_with(
                "Where the fitted motion slips (10.0–90.0 mm/s, the 10th–90th percentile of its \
                 slip speeds), μ_d runs from 0.942 ± 0.0010 to 0.536 ± 0.0010 (1σ)."
            ),
            "{words}"
        );
        assert!(
            words.ends_with(
                "It lies 2.0 % rms from the true law there, inside the band at 0 % of the speeds."
            ),
            "{words}"
        );
        // The truth as a point the search evaluated 0.3 nats above the fit, inside a 0.5-nat rise
        // limit: the band reaches it (the numbers of the envelope below) and covers the truth.
        let curve = r.friction_curve.clone().unwrap();
        let limits = [0.5; crate::model::friction_curve::CURVE_POINTS];
        let widened = curve_words(&curve.clone().with_near_best(&[(0.3, truth)], &limits));
        assert!(
            widened.contains(
                "widen that band to 0.924–0.943 at the slowest and 0.525–0.537 at the fastest"
            ) && widened.ends_with("inside the band at 100 % of the speeds."),
            "{widened}"
        );
        // 0.6 nats above the fit it lies beyond the limit: the words are those without it.
        assert_eq!(
            curve_words(&curve.with_near_best(&[(0.6, truth)], &limits)),
            words
        );
        let s = summary(&r, &[]);
        assert!(s.findings.contains(&words), "{:?}", s.findings);
        assert!(
            s.findings[0].starts_with("Friction law μ_d(v) = A·e^(−B·|v|) + C + D·|v|: "),
            "{:?}",
            s.findings
        );
        // The truth as the one other candidate: the envelope runs from it (0.8 e^(−0.1) + 0.2 =
        // 0.924 at 10 mm/s, 0.525 at 90 mm/s) to the fitted μ_d + 1σ (0.943, 0.537).
        let c = r.friction_curve.unwrap();
        let other = c.alternative(truth, None, &[], &[]);
        let c = c.with_alternatives(&[other]);
        let words = curve_words(&c);
        assert!(
            words.contains(
                "With the 1 model(s) the recording does not distinguish from this one, μ_d lies \
                 within 0.924–0.943 at the slowest and 0.525–0.537 at the fastest of these speeds."
            ) && words.ends_with("of the speeds, inside that envelope at 100 %."),
            "{words}"
        );
        // What the envelope leaves open, as FrictionCurve::open_rel_half_width reads it (its
        // closed forms are friction_curve's tests): a share of μ_d between 0 and 5 % here.
        let open = c.open_rel_half_width().unwrap();
        assert!(open > 0.0 && open < 0.05, "{open}");
        assert!(
            words.contains(&format!(
                " Over the range they leave ±{} of μ_d open",
                pct_abs(open)
            )),
            "{words}"
        );
    }

    /// Laws as candidates: the chosen exponential law with the viscous one 1.2 below it in TIC is
    /// "not distinguishable", and the sentence says the friction law with fewer parameters is
    /// reported; a shoulder in the same place is a model; a model of as many parameters trails
    /// the chosen one's lower TIC.
    #[test]
    fn an_indistinguishable_law_is_said_in_words() {
        let mut r = crate::report::html::tests::result();
        let trial = |model: &str, chosen: bool, delta_tic: f64| crate::fit::ModelTrial {
            model: model.parse().unwrap(),
            parameters: if model.contains("viscous") {
                vec![ParamId::A, ParamId::B, ParamId::C, ParamId::D, ParamId::K1]
            } else {
                vec![ParamId::A, ParamId::B, ParamId::C, ParamId::K1]
            },
            cost: 78.3,
            wall_time_s: 4.0,
            model_evaluations: 10,
            failed_evaluations: 0,
            chosen,
            reason: String::new(),
            not_distinguishable: false,
            evidence: Some(crate::fit::TrialEvidence {
                log_likelihood_nats: 5805.8,
                spectral_nll_nats: vec![],
                time_nll_nats: None,
                residual_rms_m: 1e-5,
                n_effective: 1e3,
                effective_parameters: None,
                tic: Some(delta_tic),
                delta_tic: Some(delta_tic),
                aic: delta_tic,
                bic: delta_tic,
                delta_aic: delta_tic,
                delta_bic: delta_tic,
                lrt: None,
            }),
            friction: None,
        };
        r.model = "blade2dof@exponential".parse().unwrap();
        r.model_trials = vec![
            trial("blade2dof@exponential", true, 0.0),
            trial("blade2dof@exponential_viscous", false, -1.2),
        ];
        let words = model_words(&r);
        assert!(
            words.contains(
                "blade2dof@exponential_viscous is not distinguishable by this recording (TIC \
                 -1.2, within 2), and the friction law with fewer parameters is reported"
            ),
            "{words}"
        );
        r.model_trials[1].model = "blade2dof+shoulder@exponential".parse().unwrap();
        assert!(
            model_words(&r).contains("the model with fewer parameters"),
            "{words}"
        );
        // As many parameters (head1dof against blade2dof, A, B, C, k1 each): the lower TIC.
        r.model = "head1dof".parse().unwrap();
        r.model_trials = vec![trial("head1dof", true, 0.0), trial("blade2dof", false, 0.9)];
        let words = model_words(&r);
        assert!(
            words.contains("within 2), and the model with the lower TIC is reported"),
            "{words}"
        );
    }

    #[test]
    fn a_good_fit_says_so_and_a_doubtful_one_says_what_to_do() {
        // The report's unit result: k1 with an interval, B undetermined, no test, no check.
        let mut r = crate::report::html::tests::result();
        let s = summary(&r, &[]);
        assert_eq!(
            s.findings[1],
            "Neck stiffness k1 = 0.0300 N·m/rad (68 % interval 0.0280 to 0.0320 N·m/rad)."
        );
        assert!(
            s.findings[0].contains("B = 0.0300 s/m (not determined by the data"),
            "{:?}",
            s.findings
        );
        assert!(s.findings[0].ends_with("held at the blade file's values."));
        assert!(!s.good);
        let status = |s: &Summary| s.checks.iter().map(|c| c.status).collect::<Vec<_>>();
        // Test, tolerance check, peaks (1.0 % off), determined, warnings.
        assert_eq!(status(&s), ["none", "none", "ok", "bad", "ok"]);
        assert_eq!(s.todo.len(), 1, "{:?}", s.todo);

        // Determined, a test the fit passes and a resolved check: good, nothing to do.
        r.parameters[1].determined = true;
        r.goodness_of_fit = Some(GoodnessOfFit {
            excess_nll_nats: 78.3,
            replicate_mean_nats: 75.7,
            replicate_sd_nats: 7.8,
            replicates: 999,
            p_value: 0.341,
        });
        let resolved = ToleranceCheck::of(
            vec![point(1e-8, 78.34), point(1e-9, 78.32), point(1e-10, 78.32)],
            vec![],
        );
        r.tolerance_check = Some(resolved);
        let info = PageWarning::FailedEvaluations {
            failed: 2,
            evaluations: 30,
            first: None,
        };
        let s = summary(&r, std::slice::from_ref(&info));
        assert!(s.good && s.todo.is_empty(), "{s:?}");
        assert_eq!(status(&s), ["ok"; 5]);
        assert_eq!(
            s.checks[4].text,
            "No warning needs your attention (1 note for information, below)."
        );

        // A misfit and an unresolved optimum: each failed check says what to do.
        r.goodness_of_fit.as_mut().unwrap().p_value = 0.001;
        r.tolerance_check = Some(ToleranceCheck::of(
            vec![point(1e-8, 66.8), point(1e-9, 68.4)],
            vec![],
        ));
        let shape = vec![crate::likelihood::misfit::BandMisfit {
            band: "low".into(),
            excess_nats: 120.0,
            regions: vec![],
        }];
        let misfit = FitWarning::Misfit {
            test: r.goodness_of_fit.unwrap(),
            shoulder_listed: false,
            shape,
        };
        r.warnings.0.push(misfit.clone());
        let s = summary(&r, &[PageWarning::Fit(misfit), info]);
        assert!(
            s.checks
                .iter()
                .any(|c| c.status == "bad" && c.text.contains(" The excess lies in the low band")),
            "the check says where the misfit sits: {:?}",
            s.checks
        );
        assert!(!s.good);
        assert_eq!(status(&s), ["bad", "bad", "ok", "ok", "bad"]);
        assert_eq!(s.todo.len(), 3, "{:?}", s.todo);
        assert!(
            s.todo[1].starts_with("Tighten [solver] rtol"),
            "{:?}",
            s.todo
        );
    }

    #[test]
    fn digits_grow_until_the_interval_ends_read_apart() {
        // 0.02954 in [0.02923, 0.02985]: three digits tell them apart.
        assert_eq!(digits(&[0.029542, 0.029231, 0.029845]), 3);
        // 70.551 in [70.53, 70.58]: four are needed (70.6, 70.5, 70.6 at three).
        assert_eq!(digits(&[70.551, 70.53, 70.58]), 4);
    }
}
