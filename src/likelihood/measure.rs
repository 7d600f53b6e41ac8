//! The measured side of a fit: the recording read, its features per band and its noise floors, or
//! a target job's targets.

use super::instfreq;
use super::{MeasureError, NoHeadTrack};
use crate::job::{self, LoadedJob};
use crate::model::BladeParams;
use crate::spectrum::features::{self, Features, features, noise_floor};
use crate::trace::{Role, Trace};
use crate::{Error, Result};
use std::sync::Arc;

/// Sampling rate of a trace: the recording's fps if given, else from the time column. Errors if
/// the frame times are not uniform to 1e-6 relative (resample first).
pub(crate) fn sampling_rate(trace: &Trace, fps: Option<f64>) -> Result<f64> {
    let fs = match fps {
        Some(f) => f,
        None => crate::spectrum::median_rate_hz(&trace.t_s),
    };
    if !(fs.is_finite() && fs > 0.0) {
        return Err(MeasureError::NoFrameRate { median_rate_hz: fs }.into());
    }
    let dt = 1.0 / fs;
    for w in trace.t_s.windows(2) {
        if ((w[1] - w[0]) - dt).abs() > 1e-6 * dt.max(1e-12) * 1e3 {
            return Err(MeasureError::NonUniformFrames {
                fs_hz: fs,
                step_s: w[1] - w[0],
            }
            .into());
        }
    }
    Ok(fs)
}

/// Standard deviation of the Gaussian kernel that smooths a recorded head drop for the neck/lip
/// model, s. Its gain `exp(−(2πfσ)²/2)` is 0.988 at the sample's 49 Hz low component and 0.02 at
/// 900 Hz, where the heavy head hardly moves. A piecewise interpolant (local quadratic fits) would
/// make the integrator cut its step at every sample, where its derivatives jump; the kernel smooth
/// is infinitely differentiable, so the integrator takes long steps through it.
pub const HEAD_KERNEL_SIGMA_S: f64 = 5e-4;

/// The measured side of a fit, shared by every candidate.
pub(crate) struct Measurement {
    /// The head drop `−y` of the `head` point and the lean (tip x − head x), smoothed, for the
    /// neck/lip model; why not, when the recording cannot give them.
    pub(crate) head: std::result::Result<Arc<crate::model::necklip::PrescribedHead>, NoHeadTrack>,
    /// Target ranges per band (a target job), instead of measured peaks.
    pub(crate) targets: Option<Vec<[f64; 2]>>,
    /// Time-domain objectives (frequency against tip speed, trace error) when weighted.
    pub(crate) time_targets: Option<instfreq::TimeTargets>,
    pub(crate) trace: Trace,
    pub(crate) x: Vec<f64>,
    pub(crate) fs_hz: f64,
    pub(crate) measured: Features,
    pub(crate) floors: Vec<f64>,
}

/// The measurement as the neck/lip model sees it: the samples in the guard around the blade's flip
/// (where the model does not run, [`crate::model::necklip::PrescribedHead::segments`]) are masked,
/// and the measured features and noise floors are taken again without them, so that measurement
/// and model are compared on the same samples. Returns `(features, floors, NaN mask)`.
pub(crate) fn necklip_view(
    job: &LoadedJob,
    m: &Measurement,
    base: &BladeParams,
) -> Result<(Features, Vec<f64>, Vec<bool>)> {
    let head = m
        .head
        .as_ref()
        .map_err(|e| MeasureError::NecklipNeedsTracks { reason: e.clone() })?;
    let t = &m.trace.t_s;
    let window = (t[0], *t.last().unwrap_or(&t[0]));
    let guard = crate::model::necklip::FLIP_GUARD_OF_REACH * (base.l1_m + base.l2_m);
    let segments = head.segments(window, guard);
    let mask: Vec<bool> = t
        .iter()
        .zip(&m.x)
        .map(|(ti, xi)| !xi.is_finite() || !segments.iter().any(|s| s.0 <= *ti && *ti <= s.1))
        .collect();
    let x: Vec<f64> =
        m.x.iter()
            .zip(&mask)
            .map(|(v, masked)| if *masked { f64::NAN } else { *v })
            .collect();
    let measured = features(
        &x,
        m.fs_hz,
        &job.job.spectrum.bands,
        job.job.spectrum.max_fill,
    )?;
    let floors = measured.bands.iter().map(noise_floor).collect();
    Ok((measured, floors, mask))
}

/// Every band of the job fits the recording at `path` (`n` frames at `fs_hz`): its segment is no
/// longer than the record and its upper edge lies below Nyquist. Checked before any FFT plan is
/// made or any simulation runs.
fn check_bands(job: &LoadedJob, path: &std::path::Path, n: usize, fs_hz: f64) -> Result<()> {
    use job::Key;
    let nyquist = 0.5 * fs_hz;
    for (i, b) in job.job.spectrum.bands.iter().enumerate() {
        let at = [Key::Name("spectrum"), Key::Name("bands"), Key::Index(i)];
        if b.nperseg > n {
            return Err(job.error_at(
                &at,
                format!(
                    "[spectrum] band '{}': nperseg = {} is longer than the recording {} ({n} frames)",
                    b.name,
                    b.nperseg,
                    path.display()
                ),
            ));
        }
        if b.range_hz[1] > nyquist {
            return Err(job.error_at(
                &at,
                format!(
                    "[spectrum] band '{}': range_hz upper edge {} Hz is above the Nyquist frequency \
                     {} Hz of the recording {} ({} frames/s)",
                    b.name,
                    b.range_hz[1],
                    crate::names::significant(nyquist, 6),
                    path.display(),
                    crate::names::significant(fs_hz, 6)
                ),
            ));
        }
    }
    Ok(())
}

/// Reads the recording and its features.
pub(crate) fn measure_recording(
    job: &LoadedJob,
    path: &std::path::Path,
    spec: &crate::import::ImportSpec,
) -> Result<Measurement> {
    let trace = crate::import::read_trace(path, spec)?;
    let fs_hz = sampling_rate(&trace, spec.fps_hz)?;
    check_bands(job, path, trace.t_s.len(), fs_hz)?;
    let signal = job.job.spectrum.signal;
    let x = signal.extract(&trace)?;
    let measured = features(
        &x,
        fs_hz,
        &job.job.spectrum.bands,
        job.job.spectrum.max_fill,
    )?;
    for b in &measured.bands {
        if b.peak.is_none() {
            return Err(Error::input(
                path,
                format!(
                    "the measured {} has no spectral peak in band '{}' {:?} Hz",
                    signal.label(),
                    b.spec.name,
                    b.spec.range_hz
                ),
            ));
        }
    }
    let floors: Vec<f64> = measured.bands.iter().map(noise_floor).collect();
    // The head drop u = −y (the import puts y up with the origin at the upright head), for the
    // neck/lip model, smoothed by a Gaussian kernel (HEAD_KERNEL_SIGMA_S).
    // The lean d = tip x − head x, smoothed alike, locates the blade's flip (which the neck/lip model
    // cannot pass) and gives the model's state after it.
    let head = match trace.role(Role::Head).zip(trace.role(Role::Tip)) {
        Some((h, tip)) => {
            let u: Vec<f64> = h.y_m.iter().map(|y| -y).collect();
            let d: Vec<f64> = tip.x_m.iter().zip(&h.x_m).map(|(a, b)| a - b).collect();
            crate::model::necklip::PrescribedHead::from_tracked_samples(
                trace.t_s[0],
                1.0 / fs_hz,
                &u,
                HEAD_KERNEL_SIGMA_S,
            )
            .and_then(|p| p.with_lean(&d, 15))
            .map(Arc::new)
            .map_err(|source| NoHeadTrack::Track {
                path: path.to_path_buf(),
                source,
            })
        }
        None => Err(NoHeadTrack::NoPoints {
            path: path.to_path_buf(),
        }),
    };
    Ok(Measurement {
        head,
        time_targets: instfreq::TimeTargets::for_job(
            &job.job.fit.weights,
            &trace,
            &x,
            fs_hz,
            signal,
        )?,
        trace,
        x,
        fs_hz,
        measured,
        floors,
        targets: None,
    })
}

/// A target job's "measurement": the model's default reversal window sampled at the target rate, no
/// recorded points, and per band the target range.
pub(crate) fn measure_targets(job: &LoadedJob, t: &job::TargetsSection) -> Result<Measurement> {
    let (t0, t1) = crate::simulate::blade::default_window(&job.blade);
    let n = ((t1 - t0) * t.fps_hz).floor() as usize + 1;
    let times: Vec<f64> = (0..n).map(|k| t0 + k as f64 / t.fps_hz).collect();
    let mut targets = Vec::new();
    let mut bands = Vec::new();
    for b in &job.job.spectrum.bands {
        let tp =
            t.peaks
                .iter()
                .find(|p| p.band == b.name)
                .ok_or_else(|| MeasureError::NoTarget {
                    band: b.name.clone(),
                })?;
        let r = tp.range();
        targets.push(r);
        bands.push(features::BandFeatures {
            spec: b.clone(),
            freq_hz: Vec::new(),
            psd: Vec::new(),
            peak: Some(crate::spectrum::Peak {
                freq_hz: (r[0] * r[1]).sqrt(),
                level: f64::NAN,
                bin: 0,
                prominence: f64::NAN,
            }),
            full_freq_hz: Vec::new(),
            full_psd: Vec::new(),
            segments: 0,
        });
    }
    Ok(Measurement {
        x: vec![0.0; n],
        trace: Trace {
            t_s: times,
            points: Vec::new(),
        },
        fs_hz: t.fps_hz,
        measured: Features { bands, filled: 0 },
        floors: vec![0.0; job.job.spectrum.bands.len()],
        head: Err(NoHeadTrack::TargetJob),
        targets: Some(targets),
        time_targets: None,
    })
}

/// The job's measured side: its recording measured, or its targets.
pub(crate) fn measure(job: &LoadedJob) -> Result<Measurement> {
    match (&job.job.recording, &job.job.targets) {
        (Some(rec), _) => measure_recording(job, &job.recording_path, &rec.import),
        (None, Some(t)) => measure_targets(job, t),
        (None, None) => Err(MeasureError::NothingToFit.into()),
    }
}
