//! `wiperlab.read_recording`: a tracking-tool export as NumPy arrays.

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wiperlab::import::{Format, ImportSpec, ImportSummary};
use wiperlab::job::{parse_toml, read_text};

use crate::errors::{guard_as, value_error};

/// The import settings of `wiperlab import`: the sidecar TOML `spec` (if any) overlaid with the
/// settings given by name, as the command's flags overlay `--spec`.
/// `wiperlab.read_recording` passes every one of them, `None` where not given.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct ImportSettings {
    spec: Option<PathBuf>,
    format: Option<String>,
    fps: Option<f64>,
    m_per_px: Option<f64>,
    origin_px: Option<[f64; 2]>,
    head: Option<String>,
    tip: Option<String>,
    units_to_m: Option<f64>,
    y_down: Option<bool>,
    time_to_s: Option<f64>,
    min_likelihood: Option<f64>,
    camera: Option<usize>,
    n_cameras: Option<usize>,
    sweep_angle_deg: Option<f64>,
    sweep_from_head: Option<bool>,
    scale_points_px: Option<[[f64; 2]; 2]>,
    scale_distance_m: Option<f64>,
    t0_s: Option<f64>,
}

impl ImportSettings {
    /// The [`ImportSpec`] these settings make; a format name that is not one is a `ValueError`.
    fn spec(&self) -> PyResult<wiperlab::Result<ImportSpec>> {
        let format = match &self.format {
            Some(name) => Some(Format::from_name(name).ok_or_else(|| {
                value_error(format!(
                    "format '{name}': expected one of {}",
                    Format::ALL.map(|f| format!("'{}'", f.name())).join(", ")
                ))
            })?),
            None => None,
        };
        let base = match &self.spec {
            Some(p) => match read_text(p).and_then(|text| parse_toml::<ImportSpec>(p, &text)) {
                Ok(s) => s,
                Err(e) => return Ok(Err(e)),
            },
            None => ImportSpec::default(),
        };
        let mut s = base;
        if format.is_some() {
            s.format = format;
        }
        macro_rules! overlay {
            ($($field:ident => $target:ident),* $(,)?) => {
                $(if let Some(v) = self.$field { s.$target = Some(v); })*
            };
        }
        overlay!(
            fps => fps_hz,
            m_per_px => m_per_px,
            units_to_m => units_to_m,
            y_down => y_down,
            time_to_s => time_to_s,
            min_likelihood => min_likelihood,
            sweep_angle_deg => sweep_angle_deg,
            scale_points_px => scale_points_px,
            scale_distance_m => scale_distance_m,
        );
        if let Some(o) = self.origin_px {
            s.origin_px = o;
        }
        if let Some(c) = self.camera {
            s.camera = c;
        }
        if let Some(n) = self.n_cameras {
            s.n_cameras = n;
        }
        if let Some(b) = self.sweep_from_head {
            s.sweep_from_head = b;
        }
        if let Some(t) = self.t0_s {
            s.t0_s = t;
        }
        if let Some(h) = &self.head {
            s.points.insert("head".into(), h.clone());
        }
        if let Some(t) = &self.tip {
            s.points.insert("tip".into(), t.clone());
        }
        Ok(Ok(s))
    }
}

/// The summary as a dict (`str(recording)`'s numbers): counts per point, time base, notes.
fn summary_dict<'py>(py: Python<'py>, s: &ImportSummary) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("format", s.format.map(|f| f.name()))?;
    d.set_item("n_frames", s.n_frames)?;
    d.set_item("t_first_s", s.t_first_s)?;
    d.set_item("t_last_s", s.t_last_s)?;
    d.set_item("dt_median_s", s.dt_median_s)?;
    d.set_item("dt_min_s", s.dt_min_s)?;
    d.set_item("dt_max_s", s.dt_max_s)?;
    let points = PyDict::new(py);
    for (i, (name, nan)) in s.points.iter().enumerate() {
        let p = PyDict::new(py);
        p.set_item("nan_samples", *nan)?;
        let (runs, longest) = s.gaps.get(i).copied().unwrap_or((0, 0));
        p.set_item("gap_runs", runs)?;
        p.set_item("longest_gap", longest)?;
        p.set_item("fillable", s.fillable.get(i).copied().unwrap_or(0))?;
        p.set_item("scalar", s.scalar.get(i).copied().unwrap_or(false))?;
        points.set_item(name, p)?;
    }
    d.set_item("points", points)?;
    d.set_item("notes", s.notes.clone())?;
    d.set_item("text", s.to_string())?;
    Ok(d)
}

/// Reads a recording (the docstring is `wiperlab.read_recording`'s): a dict with `t` (n,),
/// `points` (name → x and y arrays, m) and `summary`.
#[pyfunction]
pub fn read_recording<'py>(
    py: Python<'py>,
    path: PathBuf,
    settings: ImportSettings,
) -> PyResult<Bound<'py, PyDict>> {
    let spec = settings.spec()?;
    let (trace, summary) = guard_as(py, "RecordingError", move || {
        wiperlab::import::read_trace_with_summary(&path, &spec?)
    })?;
    let out = PyDict::new(py);
    out.set_item("t", PyArray1::from_vec(py, trace.t_s))?;
    // A dict keeps the trace's point order.
    let pd = PyDict::new(py);
    for p in trace.points {
        pd.set_item(
            p.name,
            (PyArray1::from_vec(py, p.x_m), PyArray1::from_vec(py, p.y_m)),
        )?;
    }
    out.set_item("points", pd)?;
    out.set_item("summary", summary_dict(py, &summary)?)?;
    Ok(out)
}
