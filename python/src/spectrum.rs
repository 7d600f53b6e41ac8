//! `wiperlab.welch` and `wiperlab.find_peaks_in_band`.

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use wiperlab::spectrum::{Average, Detrend, Scaling, WelchConfig, Window};

use crate::errors::{guard, value_error};

/// A pair of NumPy arrays (frequencies and values).
type ArrayPair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// `detrend`: `'constant'`, `'linear'` or `False` (as SciPy).
fn detrend_of(detrend: &Bound<'_, PyAny>) -> PyResult<Detrend> {
    if let Ok(b) = detrend.extract::<bool>() {
        return if b {
            Err(value_error(
                "detrend=True is not a detrend; expected 'constant', 'linear' or False",
            ))
        } else {
            Ok(Detrend::None)
        };
    }
    match detrend.extract::<String>()?.as_str() {
        "constant" => Ok(Detrend::Constant),
        "linear" => Ok(Detrend::Linear),
        other => Err(value_error(format!(
            "detrend '{other}': expected 'constant', 'linear' or False"
        ))),
    }
}

/// Welch PSD as `scipy.signal.welch` (the docstring is in `wiperlab/__init__.py`).
#[pyfunction]
#[pyo3(signature = (x, fs=1.0, window="hann", nperseg=None, noverlap=None, nfft=None,
    detrend=None, scaling="density", average="mean", max_fill=None))]
#[allow(clippy::too_many_arguments)]
pub fn welch<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    fs: f64,
    window: &str,
    nperseg: Option<usize>,
    noverlap: Option<usize>,
    nfft: Option<usize>,
    detrend: Option<Bound<'py, PyAny>>,
    scaling: &str,
    average: &str,
    max_fill: Option<usize>,
) -> PyResult<ArrayPair<'py>> {
    let window = Window::from_scipy_name(window).ok_or_else(|| {
        value_error(format!(
            "window '{window}': expected one of {}",
            Window::ALL
                .map(|w| format!("'{}'", w.scipy_name()))
                .join(", ")
        ))
    })?;
    let detrend = match &detrend {
        Some(d) => detrend_of(d)?,
        None => Detrend::Constant,
    };
    let scaling = match scaling {
        "density" => Scaling::Density,
        "spectrum" => Scaling::Spectrum,
        other => {
            return Err(value_error(format!(
                "scaling '{other}': expected 'density' or 'spectrum'"
            )));
        }
    };
    let average = match average {
        "mean" => Average::Mean,
        "median" => Average::Median,
        other => {
            return Err(value_error(format!(
                "average '{other}': expected 'mean' or 'median'"
            )));
        }
    };
    let x = x.as_slice()?;
    // SciPy's default segment is 256 samples, or the whole record when it is shorter.
    let nperseg = nperseg.unwrap_or(256.min(x.len()));
    let mut cfg = WelchConfig::new(nperseg)
        .with_window(window)
        .with_detrend(detrend)
        .with_scaling(scaling)
        .with_average(average);
    if let Some(n) = noverlap {
        cfg.noverlap = n;
    }
    if let Some(n) = nfft {
        cfg.nfft = n;
    }
    let psd = guard(py, || match max_fill {
        None => wiperlab::spectrum::welch(x, fs, &cfg),
        Some(m) => wiperlab::spectrum::welch_gappy(x, fs, &cfg, m).map(|(psd, _)| psd),
    })?;
    Ok((
        PyArray1::from_vec(py, psd.freq_hz),
        PyArray1::from_vec(py, psd.density),
    ))
}

/// The `n` largest local maxima of `pxx` in `band` (the docstring is
/// `wiperlab.find_peaks_in_band`'s): `(freq_hz, level, bin, prominence)` each, largest first.
#[pyfunction]
#[pyo3(signature = (f, pxx, band, n=1))]
pub fn find_peaks_in_band<'py>(
    f: PyReadonlyArray1<'py, f64>,
    pxx: PyReadonlyArray1<'py, f64>,
    band: (f64, f64),
    n: usize,
) -> PyResult<Vec<(f64, f64, usize, f64)>> {
    let (f, pxx) = (f.as_slice()?, pxx.as_slice()?);
    if f.len() != pxx.len() {
        return Err(value_error(format!(
            "f has {} bins but Pxx {} (expected the pair welch returns)",
            f.len(),
            pxx.len()
        )));
    }
    if band.0.is_nan() || band.1.is_nan() || band.0 > band.1 {
        return Err(value_error(format!(
            "band ({}, {}): expected low <= high in Hz",
            band.0, band.1
        )));
    }
    Ok(wiperlab::spectrum::top_peaks(f, pxx, band, n)
        .into_iter()
        .map(|p| (p.freq_hz, p.level, p.bin, p.prominence))
        .collect())
}
