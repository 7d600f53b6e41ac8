//! A commented fit-job template for a recording (`wiperlab init`).
//!
//! The template is a complete job in the format of [`super::FitJob`] with every setting a
//! user has to decide written out and explained. What the recording and the command line could
//! not tell is marked: `MISSING` (the job does not run until it is filled in: the blade file, a
//! frame rate for a file without times, a scale for a file in pixels) and `CHECK` (a guess that
//! runs but may be wrong: which point is the head and which the tip, `t0_s`, the bands).
//!
//! Band rule: the default bands of a 10,000 frames/s recording (low 30–300 Hz at nperseg 4096,
//! high 500–5000 Hz at nperseg 512, i.e. 2.4 Hz and 19.5 Hz bins) are scaled to the recording's
//! frame rate by keeping the bin widths, rounded to a power of two no longer than half the
//! record, and clipped at the Nyquist frequency (half the frame rate).

use crate::Result;
use crate::import::{ImportSpec, ImportSummary};
use crate::trace::Role;
use serde::Serialize;
use std::path::Path;

const TEMPLATE: &str = include_str!("templates/job.toml");

/// What the template is written from.
pub struct TemplateInput<'a> {
    /// Job name: a plain file stem (outputs `<name>.result.toml`, `reports/<name>/`).
    pub name: &'a str,
    /// The recording as the job should spell it: relative to the job file's directory, or absolute.
    pub recording: &'a Path,
    /// The import settings given so far, with the detected format filled in. Its `points` map
    /// roles (`head`, `tip`) to the file's point names when the user gave them.
    pub import: &'a ImportSpec,
    /// What the recording holds, from a description that may stand in frames for seconds and file
    /// units for metres (see [`ImportSummary::uncalibrated`]).
    pub summary: &'a ImportSummary,
}

/// One Welch band of the template.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TemplateBand {
    pub name: &'static str,
    pub range_hz: [f64; 2],
    pub nperseg: usize,
}

/// Bands for a recording of `n_frames` at `fps_hz` by the module's band rule; empty when the
/// frame rate is unknown (the defaults apply) and without `high` when the frame rate is too low
/// for a band above 500 Hz.
pub fn bands_for(fps_hz: Option<f64>, n_frames: usize) -> Vec<TemplateBand> {
    let Some(fps) = fps_hz.filter(|f| f.is_finite() && *f > 0.0) else {
        return Vec::new();
    };
    let top = 0.5 * fps;
    let longest = (n_frames / 2).max(8);
    let nperseg = |bin_hz: f64| -> usize {
        let exact = (fps / bin_hz).max(8.0);
        let p = 2f64.powf(exact.log2().round()) as usize;
        let mut cap = 8;
        while cap * 2 <= longest {
            cap *= 2;
        }
        p.min(cap)
    };
    let mut bands = Vec::new();
    if top > 60.0 {
        bands.push(TemplateBand {
            name: "low",
            range_hz: [30.0, top.min(300.0)],
            nperseg: nperseg(10_000.0 / 4096.0),
        });
    }
    if top > 1000.0 {
        bands.push(TemplateBand {
            name: "high",
            range_hz: [500.0, top.min(5000.0)],
            nperseg: nperseg(10_000.0 / 512.0),
        });
    }
    bands
}

/// Which of the file's points is the head and which the tip: the user's mapping, else names
/// containing "head" / "tip" (any case), else the first two points. The flag says it was guessed.
fn roles(spec: &ImportSpec, summary: &ImportSummary) -> (Option<String>, Option<String>, bool) {
    let names: Vec<&str> = summary
        .points
        .iter()
        .zip(summary.scalar.iter().chain(std::iter::repeat(&false)))
        .filter(|(_, scalar)| !**scalar)
        .map(|((n, _), _)| n.as_str())
        .collect();
    let given = |role: Role| spec.points.get(role.name()).cloned();
    if given(Role::Head).is_some() || given(Role::Tip).is_some() {
        return (given(Role::Head), given(Role::Tip), false);
    }
    let find = |role: Role| {
        names
            .iter()
            .find(|n| n.to_lowercase().contains(role.name()))
            .map(|n| n.to_string())
    };
    let head = find(Role::Head).or_else(|| names.first().map(|n| n.to_string()));
    let tip = find(Role::Tip).or_else(|| {
        names
            .iter()
            .find(|n| Some(n.to_string()) != head)
            .map(|n| n.to_string())
    });
    (head, tip, true)
}

/// A TOML value as it is written in a file (strings quoted and escaped).
fn toml_value<T: Serialize>(v: &T) -> Result<String> {
    let wrapped = toml::to_string(&std::collections::BTreeMap::from([("v", v)]))
        .map_err(super::JobError::TomlValue)?;
    Ok(wrapped.trim_start_matches("v = ").trim_end().to_string())
}

/// The commented job template for `input` (see the module docs for what is marked).
///
/// # Errors
/// [`super::JobError`] if a value cannot be written as TOML (a non-UTF-8 path).
pub fn job_template(input: &TemplateInput) -> Result<String> {
    let s = input.summary;
    let spec = input.import;
    let frames = s.uncalibrated.frames;
    let file_units = s.uncalibrated.file_units;
    let fps = spec.fps_hz.or((!frames).then(|| s.fps_median_hz()));
    let (head, tip, guessed) = roles(spec, s);
    let recording = input
        .recording
        .to_str()
        .ok_or_else(|| super::JobError::PathNotUtf8 {
            path: input.recording.to_path_buf(),
        })?;
    let ctx = minijinja::context! {
        name => toml_value(&input.name)?,
        file_name => recording,
        recording => toml_value(&recording)?,
        format => s.format.map(|f| f.name()),
        n_frames => s.n_frames,
        points => s.points.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(", "),
        fps_hz => spec.fps_hz,
        fps_from_file => (!frames && spec.fps_hz.is_none()).then(|| crate::names::significant(s.fps_median_hz(), 6)),
        needs_fps => frames && spec.fps_hz.is_none(),
        needs_scale => file_units,
        m_per_px => spec.m_per_px,
        scale_points_px => spec.scale_points_px.map(|p| toml_value(&p)).transpose()?,
        scale_distance_m => spec.scale_distance_m,
        units_to_m => spec.units_to_m,
        origin_px => toml_value(&spec.origin_px)?,
        y_down => spec.y_down,
        t0_s => spec.t0_s,
        head => head.as_ref().map(toml_value).transpose()?,
        tip => tip.as_ref().map(toml_value).transpose()?,
        guessed => guessed,
        signal => if tip.is_some() && head.is_some() { "tip_rel_x" } else { "head_y" },
        bands => bands_for(fps, s.n_frames),
    };
    let mut env = minijinja::Environment::new();
    env.set_trim_blocks(true);
    env.set_lstrip_blocks(true);
    env.add_template("job.toml", TEMPLATE)
        .and_then(|_| env.get_template("job.toml"))
        .and_then(|t| t.render(ctx))
        .map_err(|e| super::JobError::Template(e).into())
}

/// How many settings a template still marks: `(missing, check)`, counting the comment lines
/// that begin with `# MISSING` or `# CHECK` (one per setting; the header that explains the
/// marks is not counted).
pub fn count_marks(template: &str) -> (usize, usize) {
    let starting = |mark: &str| {
        template
            .lines()
            .filter(|l| l.trim_start().starts_with(mark))
            .count()
    };
    (starting("# MISSING"), starting("# CHECK"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At 10,000 frames/s the rule gives back the default bands (`default_bands`), which it is
    /// scaled from.
    #[test]
    fn bands_at_ten_kilohertz_are_the_defaults() {
        let b = bands_for(Some(10_000.0), 18_869);
        let d = crate::spectrum::features::default_bands();
        assert_eq!(b.len(), 2);
        for (t, d) in b.iter().zip(&d) {
            assert_eq!(t.name, d.name);
            assert_eq!(t.range_hz, d.range_hz);
            assert_eq!(t.nperseg, d.nperseg);
        }
    }

    /// 1000 frames/s: bins kept (1000/2.44 = 410 → 512; 1000/19.5 = 51 → 64), bands under 500 Hz,
    /// so no band above 500 Hz; a 300-frame record caps nperseg at 128 (≤ 150).
    #[test]
    fn bands_scale_with_the_frame_rate_and_the_record() {
        let b = bands_for(Some(1000.0), 100_000);
        assert_eq!(
            b,
            vec![TemplateBand {
                name: "low",
                range_hz: [30.0, 300.0],
                nperseg: 512
            }]
        );
        assert_eq!(bands_for(Some(1000.0), 300)[0].nperseg, 128);
        assert!(bands_for(None, 1000).is_empty());
        assert!(bands_for(Some(100.0), 1000).is_empty(), "Nyquist 50 Hz");
    }

    /// The header that explains the marks is not a mark; indented marks count.
    #[test]
    fn marks_are_counted_per_setting() {
        let t = "# Lines marked MISSING must be filled in;\n# lines marked CHECK are guesses.\n\
                 # MISSING: the blade\n  # CHECK: t0_s\n# CHECK: bands\nx = 1 # MISSING in a value\n";
        assert_eq!(count_marks(t), (1, 2));
    }
}
