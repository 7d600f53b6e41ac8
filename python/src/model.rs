//! `wiperlab.Blade`, `wiperlab.modes` and `wiperlab.simulate`.
//!
//! A blade crosses the FFI as a dict of [`BladeParams`]'s fields (its TOML fields, SI units), so
//! the Python class holds exactly what a blade file holds and the library checks it. The dict is
//! converted through [`toml::Value`] (floats pass as the very same `f64`; a text format would
//! need a correctly rounded parser on both sides).

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use wiperlab::cli::{BAUMGARTE_OMEGA_PER_S, StickChoice};
use wiperlab::job::{parse_toml, read_text};
use wiperlab::model::modes::OperatingPoint;
use wiperlab::model::{Blade, BladeParams, StickForm};
use wiperlab::simulate::blade::{ModelKind, contact_forces, default_window, simulate_model};
use wiperlab::simulate::{Method, SolverOptions};
use wiperlab::{Error, Result};

use crate::errors::{guard, input_error, value_error};

/// A Python value (dict, list, str, bool, int, float) as a TOML value; `what` names it in errors.
fn to_toml(py: Python<'_>, v: &Bound<'_, PyAny>, what: &str) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        Ok(toml::Value::Boolean(v.extract()?))
    } else if v.is_instance_of::<PyInt>() {
        Ok(toml::Value::Integer(v.extract()?))
    } else if v.is_instance_of::<PyFloat>() {
        Ok(toml::Value::Float(v.extract()?))
    } else if v.is_instance_of::<PyString>() {
        Ok(toml::Value::String(v.extract()?))
    } else if let Ok(d) = v.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, item) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| input_error(py, format!("{what}: a key that is not a string")))?;
            let inner = format!("{what}.{key}");
            table.insert(key, to_toml(py, &item, &inner)?);
        }
        Ok(toml::Value::Table(table))
    } else if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items: Vec<Bound<'_, PyAny>> = v.extract()?;
        Ok(toml::Value::Array(
            items
                .iter()
                .map(|i| to_toml(py, i, what))
                .collect::<PyResult<_>>()?,
        ))
    } else if let Ok(x) = v.extract::<f64>() {
        // NumPy scalars and other numbers.
        Ok(toml::Value::Float(x))
    } else {
        Err(input_error(
            py,
            format!(
                "{what}: expected a number, a string or a table, got {}",
                v.get_type().name()?
            ),
        ))
    }
}

/// A TOML value as the Python value.
fn to_py<'py>(py: Python<'py>, v: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        toml::Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        toml::Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        toml::Value::Float(x) => PyFloat::new(py, *x).into_any(),
        toml::Value::String(s) => PyString::new(py, s).into_any(),
        toml::Value::Array(a) => PyList::new(
            py,
            a.iter()
                .map(|i| to_py(py, i))
                .collect::<PyResult<Vec<_>>>()?,
        )?
        .into_any(),
        toml::Value::Table(t) => {
            let d = PyDict::new(py);
            for (k, item) in t {
                d.set_item(k, to_py(py, item)?)?;
            }
            d.into_any()
        }
        toml::Value::Datetime(d) => PyString::new(py, &d.to_string()).into_any(),
    })
}

/// The blade `params` (a dict from `wiperlab.Blade`), checked; a `wiperlab.InputError` naming the
/// field otherwise.
fn params_of(py: Python<'_>, params: &Bound<'_, PyDict>) -> PyResult<BladeParams> {
    let value = to_toml(py, params.as_any(), "Blade")?;
    let p: BladeParams = value.try_into().map_err(|e| {
        input_error(
            py,
            format!("Blade: {}", e.to_string().trim_end().replace('\n', " ")),
        )
    })?;
    p.validate()
        .map_err(|e| input_error(py, format!("Blade: {e}")))?;
    Ok(p)
}

/// `params` as a dict of its fields.
fn dict_of<'py>(py: Python<'py>, params: &BladeParams) -> PyResult<Bound<'py, PyAny>> {
    let value =
        toml::Value::try_from(params).expect("blade parameters are plain numbers and names");
    to_py(py, &value)
}

/// The blade file `path` (as `wiperlab simulate` reads it) as a dict of its parameters.
#[pyfunction]
pub fn blade_from_toml(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let p = guard(py, move || {
        let p: BladeParams = parse_toml(&path, &read_text(&path)?)?;
        p.validate()
            .map_err(|m| Error::input(&path, m.to_string()))?;
        Ok(p)
    })?;
    dict_of(py, &p)
}

/// The blade `params` checked and given back (every field, defaults filled in).
#[pyfunction]
pub fn blade_check<'py>(
    py: Python<'py>,
    params: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyAny>> {
    dict_of(py, &params_of(py, params)?)
}

/// The default simulation window `[π/2, 3π/2]/ω` of the blade `params`, s.
#[pyfunction]
pub fn blade_default_window(py: Python<'_>, params: &Bound<'_, PyDict>) -> PyResult<(f64, f64)> {
    Ok(default_window(&params_of(py, params)?))
}

/// The linearised blade's modes as columns (the docstring is `wiperlab.modes`'s).
#[pyfunction]
#[pyo3(signature = (blade, speeds=None))]
pub fn modes<'py>(
    py: Python<'py>,
    blade: &Bound<'py, PyDict>,
    speeds: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let params = params_of(py, blade)?;
    let modes = guard(py, move || {
        let model = Blade::new(params, StickForm::Reduced);
        match speeds {
            Some(v) => model.modes(&v),
            None => model.window_modes(),
        }
        .map_err(|e| {
            let input = matches!(
                e,
                wiperlab::model::modes::ModesError::SpeedOutOfReach { .. }
            );
            Error::stage(e, input)
        })
    })?;
    let column = |f: &dyn Fn(&wiperlab::model::modes::BladeMode) -> f64| {
        PyArray1::from_vec(py, modes.iter().map(f).collect())
    };
    let d = PyDict::new(py);
    let phase: Vec<&str> = modes
        .iter()
        .map(|m| match m.phase {
            OperatingPoint::Stick => "stick",
            OperatingPoint::Slip { .. } => "slip",
        })
        .collect();
    d.set_item("phase", phase)?;
    d.set_item(
        "speed_m_per_s",
        column(&|m| match m.phase {
            OperatingPoint::Stick => f64::NAN,
            OperatingPoint::Slip { speed_m_per_s } => speed_m_per_s,
        }),
    )?;
    d.set_item("freq_hz", column(&|m| m.freq_hz))?;
    d.set_item("damping_ratio", column(&|m| m.damping_ratio))?;
    d.set_item("head", column(&|m| m.participation.head))?;
    d.set_item("head_link", column(&|m| m.participation.head_link))?;
    d.set_item("neck_lip", column(&|m| m.participation.neck_lip))?;
    Ok(d)
}

/// The settings of one simulation, checked as `wiperlab simulate` checks its flags.
struct Run {
    params: BladeParams,
    window: (f64, f64),
    times: Vec<f64>,
    opts: SolverOptions,
    form: StickForm,
    kind: ModelKind,
}

/// Simulates the blade (the docstring is `wiperlab.simulate`'s): a dict of arrays, the
/// transitions and the solver's counters.
#[pyfunction]
#[pyo3(signature = (blade, t_span, t_eval, fps, rtol, atol, method, stick, model))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    blade: &Bound<'py, PyDict>,
    t_span: Option<(f64, f64)>,
    t_eval: Option<Vec<f64>>,
    fps: f64,
    rtol: f64,
    atol: f64,
    method: &str,
    stick: &str,
    model: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let params = params_of(py, blade)?;
    let method: Method = method.parse().map_err(|e| value_error(format!("{e}")))?;
    let stick: StickChoice = stick.parse().map_err(|e| value_error(format!("{e}")))?;
    let kind: ModelKind = model.parse().map_err(|e| value_error(format!("{e}")))?;
    let window = t_span.unwrap_or_else(|| default_window(&params));
    if !(window.0.is_finite() && window.1.is_finite() && window.0 < window.1) {
        return Err(value_error(format!(
            "t_span ({}, {}): expected finite t0 < t1 in s",
            window.0, window.1
        )));
    }
    for (name, value) in [("rtol", rtol), ("atol", atol)] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(value_error(format!(
                "{name} {value}: expected a positive, finite tolerance"
            )));
        }
    }
    let times = match t_eval {
        Some(t) => {
            let inside = t.iter().all(|&s| s >= window.0 && s <= window.1);
            let ascending = t.windows(2).all(|w| w[0] < w[1]);
            if !(inside && ascending) {
                return Err(value_error(format!(
                    "t_eval: expected strictly increasing times inside t_span ({}, {})",
                    window.0, window.1
                )));
            }
            t
        }
        None => {
            if !(fps > 0.0 && fps.is_finite()) {
                return Err(value_error(format!("fps must be > 0 (got {fps})")));
            }
            // The grid of `wiperlab simulate --fps`.
            let n = ((window.1 - window.0) * fps).floor() as usize + 1;
            (0..n).map(|k| window.0 + k as f64 / fps).collect()
        }
    };
    let form = match stick {
        StickChoice::Baumgarte => StickForm::Baumgarte {
            omega_b_per_s: BAUMGARTE_OMEGA_PER_S,
        },
        StickChoice::Reduced => StickForm::Reduced,
    };
    let run = Run {
        params,
        window,
        times,
        opts: SolverOptions {
            rtol,
            atol,
            method,
            ..SolverOptions::default()
        },
        form,
        kind,
    };
    let (sim, forces) = guard(py, move || -> Result<_> {
        let sim = simulate_model(
            run.kind,
            &run.params,
            run.window,
            &run.times,
            &run.opts,
            run.form,
        )?;
        let forces = contact_forces(run.kind, &run.params, run.form, &sim)?;
        Ok((sim, forces))
    })?;
    let d = PyDict::new(py);
    let n_transitions = sim.transitions.len();
    let transitions: Vec<(f64, &str, &str)> = sim
        .transitions
        .iter()
        .map(|t| (t.t_s, t.from.label(), t.to.label()))
        .collect();
    d.set_item("transitions", transitions)?;
    let phase: Vec<i8> = sim.phase.iter().map(|p| p.code()).collect();
    d.set_item("phase", PyArray1::from_vec(py, phase))?;
    let stats = PyDict::new(py);
    stats.set_item("steps", sim.stats.steps)?;
    stats.set_item("rejected", sim.stats.rejected)?;
    stats.set_item("rhs_evals", sim.stats.rhs_evals)?;
    stats.set_item("event_evals", sim.stats.event_evals)?;
    stats.set_item("kinematic_evals", sim.stats.kinematic_evals)?;
    stats.set_item("transitions", n_transitions)?;
    d.set_item("stats", stats)?;
    d.set_item("reach_m", sim.reach_m)?;
    // The vectors move into NumPy arrays without a copy.
    d.set_item("t", PyArray1::from_vec(py, sim.t_s))?;
    d.set_item("v", PyArray1::from_vec(py, sim.v_m))?;
    d.set_item("u", PyArray1::from_vec(py, sim.u_m))?;
    d.set_item("v3", PyArray1::from_vec(py, sim.v3_m))?;
    d.set_item("theta", PyArray1::from_vec(py, sim.theta_rad))?;
    d.set_item("phi", PyArray1::from_vec(py, sim.phi_rad))?;
    d.set_item("theta_dot", PyArray1::from_vec(py, sim.theta_dot_rad_per_s))?;
    d.set_item("phi_dot", PyArray1::from_vec(py, sim.phi_dot_rad_per_s))?;
    d.set_item("v3_dot", PyArray1::from_vec(py, sim.v3_dot_m_per_s))?;
    d.set_item("normal_force", PyArray1::from_vec(py, forces.normal_n))?;
    d.set_item("friction_force", PyArray1::from_vec(py, forces.friction_n))?;
    Ok(d)
}
