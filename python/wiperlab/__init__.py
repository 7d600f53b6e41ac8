"""wiperlab: a wiper blade's tracked motion beside a stick-slip model of it.

NumPy in, NumPy out; SI units (m, s, Hz, N, rad) throughout. The Rust library does the work: each
function here converts its arguments and calls it with the GIL released, so other Python threads
run meanwhile.

* ``read_recording``: a tracking-tool export (DLTdv, Tracker, Kinovea, DeepLabCut, SLEAP,
  TrackMate, generic tables, wiperlab's canonical CSV) as arrays in metres and seconds.
* ``welch``, ``find_peaks_in_band``: Welch PSD as ``scipy.signal.welch``, and its peaks.
* ``Blade``, ``simulate``, ``modes``: the 2-DOF head/neck/lip blade model, its event-driven
  stick-slip simulation and its linearised modes.
* ``fit``: a fit job (``wiperlab fit``), with its result and files.

Errors are the exceptions of ``wiperlab.errors`` (``WiperlabError`` and its subclasses),
``FileNotFoundError``, ``ValueError`` and ``KeyboardInterrupt``; see that module.
"""

from __future__ import annotations

import copy
import json
import os
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from . import _wiperlab
from .errors import (
    FitError,
    InputError,
    ParseError,
    RecordingError,
    SimulationError,
    WiperlabError,
)

__all__ = [
    "read_recording",
    "Recording",
    "welch",
    "find_peaks_in_band",
    "Peak",
    "Blade",
    "simulate",
    "Simulation",
    "Transition",
    "modes",
    "fit",
    "FitResult",
    "WiperlabError",
    "InputError",
    "ParseError",
    "RecordingError",
    "SimulationError",
    "FitError",
]


def _samples(x, name: str) -> np.ndarray:
    """``x`` as a contiguous 1-D float64 array, or ``ValueError``."""
    a = np.ascontiguousarray(x, dtype=np.float64)
    if a.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D array, got shape {a.shape}")
    return a


def welch(
    x,
    fs: float = 1.0,
    window: str = "hann",
    nperseg: int | None = None,
    noverlap: int | None = None,
    nfft: int | None = None,
    detrend="constant",
    scaling: str = "density",
    average: str = "mean",
    *,
    max_fill: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Welch's averaged-periodogram power spectral density, as ``scipy.signal.welch``.

    Same names, defaults and result as ``scipy.signal.welch(x, fs, window, nperseg, noverlap,
    nfft, detrend, scaling, average)`` with ``return_onesided=True`` (equal to 1e-10 relative,
    tested against SciPy in ``python/tests/test_welch.py``).

    Parameters
    ----------
    x : array_like, shape (n,)
        Uniformly sampled samples; finite unless ``max_fill`` is given.
    fs : float
        Sampling rate in Hz.
    window : {'hann', 'hamming', 'blackman', 'boxcar'}
        Periodic window of each segment (``scipy.signal.get_window(window, nperseg)``).
    nperseg : int, optional
        Segment length in samples; default 256, or n when the record is shorter.
    noverlap : int, optional
        Samples shared by consecutive segments; default ``nperseg // 2``.
    nfft : int, optional
        FFT length, ``>= nperseg`` (longer zero-pads); default ``nperseg``.
    detrend : {'constant', 'linear', False}
        What is subtracted from each segment before windowing.
    scaling : {'density', 'spectrum'}
        ``'density'``: PSD in units²/Hz; ``'spectrum'``: power spectrum in units².
    average : {'mean', 'median'}
        How the segments' periodograms are combined (median with SciPy's bias correction).
    max_fill : int, optional
        Not in SciPy: treat NaN samples as gaps, as ``wiperlab spectrum --max-fill`` does. Leading
        and trailing NaN are dropped, interior runs of at most ``max_fill`` NaN are filled by
        linear interpolation, longer runs split the record, and segments are taken within the
        finite runs only (never across a gap). A record without NaN gives exactly the result
        without ``max_fill``.

    Returns
    -------
    f : ndarray, shape (nfft // 2 + 1,)
        Bin frequencies in Hz, ``k * fs / nfft``.
    Pxx : ndarray, shape (nfft // 2 + 1,)
        One-sided PSD (units²/Hz) or power spectrum (units²).

    Raises
    ------
    ValueError
        An unknown option name, or ``x`` not 1-D.
    wiperlab.InputError
        Settings the estimate cannot use (``noverlap >= nperseg``, ``nfft < nperseg``, ``fs <= 0``,
        fewer than ``nperseg`` samples, a non-finite sample without ``max_fill``, no finite run of
        ``nperseg`` samples with it); the message gives the numbers.

    Source: P.D. Welch, IEEE Trans. Audio Electroacoust. 15(2):70-73, 1967; SciPy's conventions.
    """
    return _wiperlab.welch(
        _samples(x, "x"),
        float(fs),
        window,
        nperseg,
        noverlap,
        nfft,
        detrend,
        scaling,
        average,
        None if max_fill is None else int(max_fill),
    )


class Peak(NamedTuple):
    """One interpolated spectral peak (``find_peaks_in_band``)."""

    freq_hz: float
    """Peak frequency, Hz, refined by a parabola through ln Pxx at the three bins around it."""
    level: float
    """Pxx at the parabola's vertex, in Pxx's units."""
    bin: int
    """Index of the local-maximum bin in ``f``."""
    prominence: float
    """Pxx at the bin over the median Pxx within a factor 1.3 of the frequency (a power ratio)."""


def find_peaks_in_band(f, Pxx, band, n: int = 1) -> list[Peak]:
    """The ``n`` largest local maxima of a spectrum inside a band, largest first.

    The peak of ``wiperlab spectrum --band LO:HI`` is ``find_peaks_in_band(f, Pxx, (LO, HI))[0]``
    on the same spectrum. A local maximum is a bin above its left neighbour and not below its right
    one; its frequency and level are refined by a parabola through ln Pxx at the three bins (J.O.
    Smith, Spectral Audio Signal Processing, "Quadratic Interpolation of Spectral Peaks").

    Parameters
    ----------
    f : array_like, shape (m,)
        Uniform bin frequencies, Hz (``welch``'s ``f``).
    Pxx : array_like, shape (m,)
        The spectrum on ``f``.
    band : (float, float)
        ``(low, high)`` in Hz; bins with ``low <= f <= high`` are candidates.
    n : int
        How many peaks at most.

    Returns
    -------
    list of Peak
        Fewer than ``n`` (or none) when the band holds fewer local maxima.

    Raises
    ------
    ValueError
        ``f`` and ``Pxx`` of different lengths, or ``low > high``.
    """
    return [
        Peak(*p)
        for p in _wiperlab.find_peaks_in_band(
            _samples(f, "f"), _samples(Pxx, "Pxx"), (float(band[0]), float(band[1])), int(n)
        )
    ]


@dataclass(frozen=True)
class Recording:
    """A tracking-tool export read into SI units (``read_recording``).

    Attributes
    ----------
    path : str
        The file read.
    format : str
        The layout read (``'dltdv'``, ``'tracker'``, ...), detected or given.
    t : ndarray, shape (n,)
        Frame times, s.
    points : dict of str to ndarray, shape (n, 2)
        Every tracked point's (x, y) in metres, y up, NaN where the point was not tracked; in the
        file's order, named by their roles (``head``, ``tip``) where the settings map them.
    summary : dict
        The gap report and time base, as ``wiperlab import`` prints it: ``n_frames``,
        ``t_first_s``, ``t_last_s``, ``dt_median_s``, ``dt_min_s``, ``dt_max_s``, per point
        (``points``) ``nan_samples``, ``gap_runs``, ``longest_gap`` and ``fillable`` (NaN samples
        in interior gaps short enough for ``wiperlab spectrum`` to fill), ``notes`` (what the
        import did) and ``text`` (the printed summary).
    """

    path: str
    format: str
    t: np.ndarray
    points: dict[str, np.ndarray]
    summary: dict[str, Any] = field(repr=False)

    @property
    def head(self) -> np.ndarray | None:
        """The head's (x, y), shape (n, 2), m; None when no point is the head."""
        return self.points.get("head")

    @property
    def tip(self) -> np.ndarray | None:
        """The lip tip's (x, y), shape (n, 2), m; None when no point is the tip."""
        return self.points.get("tip")

    def __str__(self) -> str:
        return self.summary["text"]

    def to_pandas(self):
        """The recording as a ``pandas.DataFrame`` with the columns of ``wiperlab import``'s CSV.

        Columns ``t_s``, then ``<point>_x_m`` and ``<point>_y_m`` for every point. Raises
        ``ImportError`` when pandas is not installed.
        """
        import pandas as pd

        columns: dict[str, np.ndarray] = {"t_s": self.t}
        for name, xy in self.points.items():
            columns[f"{name}_x_m"] = xy[:, 0]
            columns[f"{name}_y_m"] = xy[:, 1]
        return pd.DataFrame(columns)


def read_recording(
    path: str | os.PathLike,
    format: str | None = None,
    fps: float | None = None,
    m_per_px: float | None = None,
    origin_px: tuple[float, float] | None = None,
    head: str | None = None,
    tip: str | None = None,
    *,
    spec: str | os.PathLike | None = None,
    units_to_m: float | None = None,
    y_down: bool | None = None,
    time_to_s: float | None = None,
    min_likelihood: float | None = None,
    camera: int | None = None,
    n_cameras: int | None = None,
    sweep_angle_deg: float | None = None,
    sweep_from_head: bool | None = None,
    scale_points_px: tuple[tuple[float, float], tuple[float, float]] | None = None,
    scale_distance_m: float | None = None,
    t0_s: float | None = None,
) -> Recording:
    """Reads a tracking-tool export into seconds and metres, as ``wiperlab import`` does.

    The settings are those of ``wiperlab import`` (``--format``, ``--fps``, ...) and of its
    sidecar TOML; a setting given here overrides the one in ``spec``.

    Parameters
    ----------
    path : str or path
        The export: DLTdv ``*xypts.csv`` and sparse, Tracker, Kinovea (CSV, TXT, kinematics),
        DeepLabCut, SLEAP, TrackMate, a generic table (mapped in ``spec``), or wiperlab's
        canonical trace CSV.
    format : str, optional
        ``'dltdv'``, ``'dltdv-sparse'``, ``'tracker'``, ``'kinovea-csv'``, ``'kinovea-txt'``,
        ``'kinovea-kinematics'``, ``'deeplabcut'``, ``'sleap'``, ``'trackmate'``, ``'generic'``,
        ``'canonical'``; default: detected from the content.
    fps : float, optional
        Frame rate, Hz (required for DLTdv, which has frame numbers only).
    m_per_px : float, optional
        Image scale, metres per pixel (files in pixels).
    origin_px : (float, float), optional
        Pixel coordinates of the physical origin (DLTdv).
    head, tip : str, optional
        The file's names of the points that are the head and the lip tip (``'pt1'``).
    spec : str or path, optional
        Sidecar TOML with any import settings (``format``, ``fps_hz``, ``[points]``, ...).
    units_to_m, y_down, time_to_s, min_likelihood, camera, n_cameras, sweep_angle_deg,
    sweep_from_head, scale_points_px, scale_distance_m, t0_s
        As the ``wiperlab import`` flags and sidecar fields of the same names.

    Returns
    -------
    Recording
        ``t`` (n,), ``points`` (name to (n, 2) in m, NaN for gaps), ``head`` and ``tip``, the
        format and the gap report (``summary``).

    Raises
    ------
    FileNotFoundError
        ``path`` or ``spec`` does not exist.
    wiperlab.ParseError
        A value in the file (or in ``spec``) is not what was expected; ``path``, ``line`` and
        ``column`` say where.
    wiperlab.RecordingError, wiperlab.InputError
        The file cannot be imported with these settings (unknown layout, a missing frame rate or
        scale, a point not in the file); the message says what is expected.
    ValueError
        An unknown ``format`` name.
    """
    settings = dict(
        spec=None if spec is None else os.fspath(spec),
        format=format,
        fps=fps,
        m_per_px=m_per_px,
        origin_px=origin_px,
        head=head,
        tip=tip,
        units_to_m=units_to_m,
        y_down=y_down,
        time_to_s=time_to_s,
        min_likelihood=min_likelihood,
        camera=camera,
        n_cameras=n_cameras,
        sweep_angle_deg=sweep_angle_deg,
        sweep_from_head=sweep_from_head,
        scale_points_px=scale_points_px,
        scale_distance_m=scale_distance_m,
        t0_s=t0_s,
    )
    raw = _wiperlab.read_recording(os.fspath(path), settings)
    points = {name: np.column_stack(xy) for name, xy in raw["points"].items()}
    return Recording(
        path=os.fspath(path),
        format=raw["summary"]["format"],
        t=raw["t"],
        points=points,
        summary=raw["summary"],
    )


class Blade:
    """The blade model's physical parameters, SI units: the fields of a blade TOML file.

    ``Blade(**params)`` takes every field of ``data/reversal/blade_true.toml`` by name (``l1_m``,
    ``head_mass_kg``, ``k1_nm_per_rad``, ..., ``friction`` as a dict such as ``{"law":
    "exponential", "a": 0.88, "b_s_per_m": 69.7, "c": 0.56}`` or any other law of docs/blade.md
    (``exponential_viscous``, ``stribeck``, ``coulomb``, ``leine``), optional ``shoulder``);
    ``Blade.from_toml(path)`` reads such a file. Each field is an attribute (``blade.k1_nm_per_rad``);
    ``to_dict()`` gives them all and ``replace(**changes)`` a changed copy. The library checks the
    values (positive lengths and masses, a valid friction law) and raises ``wiperlab.InputError``
    naming the field otherwise; ``wiperlab.ParseError`` for a file with a bad value.

    Source of the model: Unno et al., J. Sound Vib. 393 (2017) 76, eqs. (1)-(5), in SI units.
    """

    __slots__ = ("_params",)

    def __init__(self, **params: Any) -> None:
        object.__setattr__(self, "_params", _wiperlab.blade_check(params))

    @classmethod
    def from_toml(cls, path: str | os.PathLike) -> "Blade":
        """The blade of a parameter file (``data/reversal/blade_true.toml``)."""
        blade = cls.__new__(cls)
        object.__setattr__(blade, "_params", _wiperlab.blade_from_toml(os.fspath(path)))
        return blade

    def __getattr__(self, name: str) -> Any:
        try:
            return self._params[name]
        except KeyError:
            if name == "shoulder":
                return None  # optional: a single neck stiffness
            raise AttributeError(f"Blade has no parameter {name!r}") from None

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("Blade is immutable; use blade.replace(**changes)")

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self._params))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Blade) and self._params == other._params

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={v!r}" for k, v in self._params.items())
        return f"Blade({inner})"

    def to_dict(self) -> dict[str, Any]:
        """Every parameter by its field name (a copy)."""
        return copy.deepcopy(self._params)

    def replace(self, **changes: Any) -> "Blade":
        """A checked copy with ``changes`` applied (``friction`` replaces the whole law)."""
        params = self.to_dict()
        params.update(changes)
        return Blade(**params)

    def default_window(self) -> tuple[float, float]:
        """The default simulation window ``[pi/2, 3pi/2] / omega``, s: from the drive's fastest
        forward point through the reversal to its fastest backward point."""
        return _wiperlab.blade_default_window(self._params)


def _blade_params(blade: Blade | str | os.PathLike) -> dict[str, Any]:
    """``blade`` (a Blade or the path of a blade TOML) as the dict of its fields."""
    if not isinstance(blade, Blade):
        blade = Blade.from_toml(blade)
    return blade._params


class Transition(NamedTuple):
    """A change of the contact phase during a simulation."""

    t_s: float
    """When, s (located by the integrator's event detection)."""
    from_phase: str
    """``'slip+'``, ``'slip-'`` or ``'stick'``."""
    to_phase: str
    """``'slip+'``, ``'slip-'`` or ``'stick'``."""


@dataclass(frozen=True)
class Simulation:
    """A simulated blade reversal (``simulate``): the state at each sample time.

    Every array has shape (n,) for the n sample times ``t`` (s).

    Attributes
    ----------
    t : sample times, s.
    v : head horizontal position (the drive ``a(1 - cos wt)``), m.
    u : head drop ``l1(1 - cos theta) + l2(1 - cos phi)``, m, positive down.
    v3 : lip-tip horizontal position, m.
    theta, phi : neck and lip angles from the vertical, rad.
    theta_dot, phi_dot : their rates, rad/s.
    v3_dot : lip-tip velocity (the slip velocity; 0 in stick), m/s.
    normal_force : normal force of the glass on the lip tip, N.
    friction_force : friction force of the glass on the lip tip along +x, N.
    phase : int8 contact phase, 1 slip+, 0 stick, -1 slip-.
    transitions : list of Transition (time, from, to) in time order.
    stats : solver counters (``steps``, ``rejected``, ``rhs_evals``, ``event_evals``: event
        functions with the contact forces solved, ``kinematic_evals``: event functions of slip read
        from the state alone, ``transitions``).
    reach_m : lip-tip depth below the upright head, l1 + l2, m.
    """

    t: np.ndarray
    v: np.ndarray
    u: np.ndarray
    v3: np.ndarray
    theta: np.ndarray
    phi: np.ndarray
    theta_dot: np.ndarray
    phi_dot: np.ndarray
    v3_dot: np.ndarray
    normal_force: np.ndarray
    friction_force: np.ndarray
    phase: np.ndarray
    transitions: list[Transition]
    stats: dict[str, int]
    reach_m: float

    PHASES = {1: "slip+", 0: "stick", -1: "slip-"}
    """The names of the ``phase`` codes."""


def simulate(
    blade: Blade | str | os.PathLike,
    t_span: tuple[float, float] | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    method: str = "dop853",
    t_eval=None,
    *,
    fps: float = 10_000.0,
    stick: str = "reduced",
    model: str = "blade2dof",
) -> Simulation:
    """Simulates the blade over a drive window with the event-driven stick-slip integrator.

    The same simulation as ``wiperlab simulate`` with the same settings (the defaults are the
    command's): it starts from the quasi-static slip equilibrium at ``t_span[0]``, integrates each
    smooth phase with an embedded Runge-Kutta pair and locates every stick/slip transition as an
    event.

    Parameters
    ----------
    blade : Blade or str or path
        The blade, or the path of its parameter TOML.
    t_span : (float, float), optional
        ``(t0, t1)`` on the model clock, s; default ``blade.default_window()``.
    rtol, atol : float
        Tolerances of the local error test.
    method : {'dop853', 'dopri5'}
        Runge-Kutta pair of the smooth phases.
    t_eval : array_like, shape (n,), optional
        Strictly increasing sample times inside ``t_span``, s; default a grid at ``fps`` from
        ``t0`` (as ``wiperlab simulate --fps``).
    fps : float
        Sampling rate of the default grid, Hz.
    stick : {'reduced', 'baumgarte'}
        Form of the stick-phase equations.
    model : {'blade2dof', 'head1dof'}
        The full head/neck/lip model, or the head alone (neck and lip locked).

    Returns
    -------
    Simulation
        Arrays ``t``, ``theta``, ``phi``, ``v``, ``u``, ``v3``, ``normal_force``,
        ``friction_force``, ``phase`` ... of shape (n,), and the ``transitions``.

    Raises
    ------
    wiperlab.SimulationError
        The integration failed (contact lost, a singular slip system, too many steps); the
        message names the time and the state.
    wiperlab.InputError
        Parameters the model cannot use.
    ValueError
        A bad window, tolerance, time grid or option name.
    """
    t_eval_list = None
    if t_eval is not None:
        t_eval_list = _samples(t_eval, "t_eval").tolist()
    raw = _wiperlab.simulate(
        _blade_params(blade),
        None if t_span is None else (float(t_span[0]), float(t_span[1])),
        t_eval_list,
        float(fps),
        float(rtol),
        float(atol),
        method,
        stick,
        model,
    )
    raw["transitions"] = [Transition(*t) for t in raw["transitions"]]
    return Simulation(**raw)


def modes(blade: Blade | str | os.PathLike, speeds=None) -> dict[str, np.ndarray]:
    """The linearised blade's modes in stick and in steady slip, as ``wiperlab modes``.

    Parameters
    ----------
    blade : Blade or str or path
        The blade, or the path of its parameter TOML.
    speeds : array_like, optional
        Slip speeds, m/s; default 25, 50 and 100 % of the drive's peak head speed ``a*omega``.

    Returns
    -------
    dict of str to ndarray, shape (k,)
        One entry per mode (a table: ``pandas.DataFrame(wiperlab.modes(blade))``):
        ``phase`` (``'stick'`` or ``'slip'``), ``speed_m_per_s`` (NaN in stick), ``freq_hz``,
        ``damping_ratio`` (negative: self-excited in slip), and the participation of the head,
        the head-link and the neck-lip coordinates (``head``, ``head_link``, ``neck_lip``).

    Raises
    ------
    wiperlab.InputError
        A speed the blade cannot reach.
    """
    raw = _wiperlab.modes(
        _blade_params(blade), None if speeds is None else _samples(speeds, "speeds").tolist()
    )
    raw["phase"] = np.array(raw["phase"])
    return raw


@dataclass(frozen=True)
class FitResult:
    """The result of a fit (``fit``): what ``<name>.result.toml`` holds.

    Attributes
    ----------
    model : str
        The model whose parameters are reported (``'blade2dof'``, ``'blade2dof+shoulder'``, ...).
    parameters : dict of str to dict
        Per fitted parameter (``A``, ``B``, ``C``, ``k1``, ...): ``value``, ``lower``, ``upper``
        (search bounds), ``std_error`` (1 sigma), ``determined`` and, when computed, ``interval``
        (``lo``, ``hi``, ``level``, ``method``).
    peaks : list of dict
        Per band: ``band``, ``measured_hz``, ``model_hz``, ``rel_diff``, levels.
    warnings : list of str
        One sentence each, as the command prints them.
    cost : float
        The fit's cost (negative log-likelihood in nats where the job has one).
    interrupted : bool
        True for the best-so-far result of an interrupted fit.
    result_path : str
        The result file written beside the job.
    report_dir : str
        The directory of the fit's figures and data files.
    """

    model: str
    parameters: dict[str, dict[str, Any]]
    peaks: list[dict[str, Any]]
    warnings: list[str]
    cost: float
    interrupted: bool
    result_path: str
    report_dir: str
    _raw: dict[str, Any] = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        """Every field of the result file (as ``wiperlab fit --json`` prints it)."""
        return json.loads(json.dumps(self._raw))


def fit(
    job: str | os.PathLike,
    progress: bool = True,
    out_dir: str | os.PathLike | None = None,
) -> FitResult:
    """Runs a fit job as ``wiperlab fit`` does, writing the same files.

    Writes ``<name>.result.toml`` beside the job and the figures and data files in the job's
    report directory (``<reports_dir>/<name>/``, or ``out_dir``).

    Ctrl-C (SIGINT) stops the fit: as on the command line, the best result so far is written to
    ``<name>.interrupted.result.toml`` (a previous complete result stays) and ``KeyboardInterrupt``
    is raised, its message naming that file. The fit runs with the GIL released; one fit runs at a
    time in a process.

    Parameters
    ----------
    job : str or path
        The fit job TOML (``fits/reversal.toml``).
    progress : bool
        Show the fit's progress on the process's stderr, as ``wiperlab fit``: a bar on a
        terminal, otherwise a line every 5 s.
    out_dir : str or path, optional
        Directory of the figures and data files instead of the job's report directory.

    Returns
    -------
    FitResult

    Raises
    ------
    FileNotFoundError
        The job, or a file it names, does not exist.
    wiperlab.ParseError, wiperlab.InputError, wiperlab.RecordingError
        A job or recording that cannot be used; the message says where and what is expected.
    wiperlab.FitError
        The fit failed.
    KeyboardInterrupt
        Ctrl-C stopped the fit.
    """
    text, result_path, report_dir = _wiperlab.fit(
        os.fspath(job), bool(progress), None if out_dir is None else os.fspath(out_dir)
    )
    raw = json.loads(text)
    return FitResult(
        model=raw["model"],
        parameters={p["name"]: {k: v for k, v in p.items() if k != "name"} for p in raw["parameters"]},
        peaks=raw["peaks"],
        warnings=raw["warnings"],
        cost=raw["cost"],
        interrupted=bool(raw.get("interrupted", False)),
        result_path=os.fspath(result_path),
        report_dir=os.fspath(report_dir),
        _raw=raw,
    )
