//! The drive a fit uses, checked against the tracked head or read from it
//! ([`crate::model::drive`], `[fit] drive`).

use crate::Result;
use crate::error::Error;
use crate::estimate::warning::FitWarning;
use crate::job::{DriveSource, LoadedJob};
use crate::model::drive::{DriveCheck, read_drive};
use crate::trace::{Role, Trace};
use std::borrow::Cow;

/// The job whose blade carries the drive the fit uses, the check of that drive against the
/// recording's tracked head (`None` without a tracked head, or where it cannot be read and the job
/// does not ask for it), and the warning when the two differ ([`DriveCheck::harmonic_departs`],
/// [`DriveCheck::amplitude_departs`]). With `[fit] drive = "recording"` the blade's
/// `drive_speed_harmonic` is the one read from the head. Only the job's own recording is read
/// (not `more_recordings`).
///
/// # Errors
/// [`Error::Input`] when `[fit] drive = "recording"` and the head's track cannot give the drive.
pub(crate) fn fitted_drive<'a>(
    job: &'a LoadedJob,
    trace: &Trace,
) -> Result<(Cow<'a, LoadedJob>, Option<DriveCheck>, Option<FitWarning>)> {
    let wanted = job.job.fit.drive == DriveSource::Recording;
    let unchecked = || Ok((Cow::Borrowed(job), None, None));
    if job.job.targets.is_some() {
        return unchecked();
    }
    let reading = match trace.role(Role::Head) {
        Some(head) => read_drive(&trace.t_s, &head.x_m, job.blade.drive_omega_rad_per_s)
            .map_err(|e| e.to_string()),
        None => Err("the recording has no tracked head".to_string()),
    };
    let reading = match reading {
        Ok(r) => r,
        Err(why) if wanted => {
            return Err(Error::input(
                &job.recording_path,
                format!("[fit] drive = \"recording\": {why}"),
            ));
        }
        Err(_) => return unchecked(),
    };
    let blade_speed_harmonic = job.blade.drive_speed_harmonic;
    let mut job = Cow::Borrowed(job);
    if wanted {
        if reading.speed_harmonic.abs() >= 0.5 {
            return Err(Error::input(
                &job.recording_path,
                format!(
                    "[fit] drive = \"recording\": the tracked head's second harmonic h = {:.3} \
                     is not a drive's (|h| < 0.5 of the peak speed): the head's track does not \
                     follow the blade file's drive frequency",
                    reading.speed_harmonic
                ),
            ));
        }
        job.to_mut().blade.drive_speed_harmonic = reading.speed_harmonic;
    }
    let check = DriveCheck {
        reading,
        blade_amplitude_m: job.blade.drive_a_m,
        blade_speed_harmonic,
        fitted_speed_harmonic: job.blade.drive_speed_harmonic,
    };
    let warning = (check.harmonic_departs() || check.amplitude_departs())
        .then_some(FitWarning::DriveDeparts(check));
    Ok((job, Some(check), warning))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::likelihood::measure::measure;

    fn main_job() -> LoadedJob {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        LoadedJob::load(&root.join("fits/reversal.toml")).expect("main job")
    }

    /// The shipped sample was made with the drive a(1 − cos ωt), a = 0.1 m, h = 0, frame 1 at
    /// the job's t0_s (data/reversal/truth.json, `camera`; data/reversal/README.md): read back
    /// from its tracked head, a, h and the clock offset lie within 4 standard errors of those, and
    /// nothing is reported as departing; the residuals are the tracking noise, 0.1 px of 15 µm
    /// (`camera.noise_sigma_px`, `camera.scale_m_per_px`), within 5 %.
    #[test]
    fn the_samples_head_shows_the_drive_it_was_made_with() {
        let job = main_job();
        let meas = measure(&job).expect("measure");
        let (used, check, warning) = fitted_drive(&job, &meas.trace).expect("drive");
        let c = check.expect("a tracked head");
        let r = c.reading;
        assert!(
            ((r.amplitude_m - 0.1) / r.amplitude_se_m).abs() < 4.0,
            "{r:?}"
        );
        assert!(
            (r.speed_harmonic / r.speed_harmonic_se).abs() < 4.0,
            "{r:?}"
        );
        assert!(
            (r.clock_offset_s / r.clock_offset_se_s).abs() < 4.0,
            "{r:?}"
        );
        assert!((r.residual_rms_m / 1.5e-6 - 1.0).abs() < 0.05, "{r:?}");
        assert!(warning.is_none() && matches!(used, Cow::Borrowed(_)));
        assert_eq!(c.fitted_speed_harmonic, 0.0);
    }

    /// `drive = "recording"` fits with the head's harmonic, and the check records the blade
    /// file's beside it; without a tracked head it is an error that names the recording.
    #[test]
    fn recording_drive_takes_the_heads_harmonic_or_says_why_not() {
        let mut job = main_job();
        job.job.fit.drive = DriveSource::Recording;
        let meas = measure(&job).expect("measure");
        let (used, check, _) = fitted_drive(&job, &meas.trace).expect("drive");
        let c = check.expect("a tracked head");
        assert_eq!(used.blade.drive_speed_harmonic, c.reading.speed_harmonic);
        assert_eq!(c.fitted_speed_harmonic, c.reading.speed_harmonic);
        assert_eq!(c.blade_speed_harmonic, 0.0);
        let mut headless = meas.trace.clone();
        headless.points.retain(|p| p.name != Role::Head.name());
        let err = fitted_drive(&job, &headless).unwrap_err().to_string();
        assert!(err.contains("no tracked head"), "{err}");
        assert!(err.contains("wiper_reversal_sample_xypts.csv"), "{err}");
    }
}
