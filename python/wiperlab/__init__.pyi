"""Type stubs of wiperlab (the docstrings are in wiperlab/__init__.py)."""

import os
from typing import Any, ClassVar, Literal, NamedTuple, Sequence

import numpy as np
import numpy.typing as npt

from .errors import (
    FitError as FitError,
    InputError as InputError,
    ParseError as ParseError,
    RecordingError as RecordingError,
    SimulationError as SimulationError,
    WiperlabError as WiperlabError,
)

_Path = str | os.PathLike[str]
_Array = npt.NDArray[np.float64]
_ArrayLike = npt.ArrayLike

def welch(
    x: _ArrayLike,
    fs: float = 1.0,
    window: Literal["hann", "hamming", "blackman", "boxcar"] = "hann",
    nperseg: int | None = None,
    noverlap: int | None = None,
    nfft: int | None = None,
    detrend: Literal["constant", "linear", False] = "constant",
    scaling: Literal["density", "spectrum"] = "density",
    average: Literal["mean", "median"] = "mean",
    *,
    max_fill: int | None = None,
) -> tuple[_Array, _Array]: ...

class Peak(NamedTuple):
    freq_hz: float
    level: float
    bin: int
    prominence: float

def find_peaks_in_band(
    f: _ArrayLike, Pxx: _ArrayLike, band: tuple[float, float], n: int = 1
) -> list[Peak]: ...

class Recording:
    path: str
    format: str
    t: _Array
    points: dict[str, _Array]
    summary: dict[str, Any]
    @property
    def head(self) -> _Array | None: ...
    @property
    def tip(self) -> _Array | None: ...
    def to_pandas(self) -> Any: ...

def read_recording(
    path: _Path,
    format: str | None = None,
    fps: float | None = None,
    m_per_px: float | None = None,
    origin_px: tuple[float, float] | None = None,
    head: str | None = None,
    tip: str | None = None,
    *,
    spec: _Path | None = None,
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
) -> Recording: ...

class Blade:
    l1_m: float
    l2_m: float
    head_mass_kg: float
    neck_mass_kg: float
    lip_mass_kg: float
    neck_com_m: float
    lip_com_m: float
    neck_inertia_kg_m2: float
    lip_inertia_kg_m2: float
    k0_n_per_m: float
    k1_nm_per_rad: float
    k2_nm_per_rad: float
    c0_ns_per_m: float
    c1_nms_per_rad: float
    c2_nms_per_rad: float
    hd_m: float
    friction: dict[str, Any]
    drive_a_m: float
    drive_omega_rad_per_s: float
    shoulder: dict[str, float] | None
    def __init__(self, **params: Any) -> None: ...
    @classmethod
    def from_toml(cls, path: _Path) -> Blade: ...
    def to_dict(self) -> dict[str, Any]: ...
    def replace(self, **changes: Any) -> Blade: ...
    def default_window(self) -> tuple[float, float]: ...

class Transition(NamedTuple):
    t_s: float
    from_phase: str
    to_phase: str

class Simulation:
    t: _Array
    v: _Array
    u: _Array
    v3: _Array
    theta: _Array
    phi: _Array
    theta_dot: _Array
    phi_dot: _Array
    v3_dot: _Array
    normal_force: _Array
    friction_force: _Array
    phase: npt.NDArray[np.int8]
    transitions: list[Transition]
    stats: dict[str, int]
    reach_m: float
    PHASES: ClassVar[dict[int, str]]

def simulate(
    blade: Blade | _Path,
    t_span: tuple[float, float] | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    method: Literal["dop853", "dopri5"] = "dop853",
    t_eval: _ArrayLike | None = None,
    *,
    fps: float = 10_000.0,
    stick: Literal["reduced", "baumgarte"] = "reduced",
    model: Literal["blade2dof", "head1dof"] = "blade2dof",
) -> Simulation: ...
def modes(blade: Blade | _Path, speeds: Sequence[float] | _ArrayLike | None = None) -> dict[str, np.ndarray]: ...

class FitResult:
    model: str
    parameters: dict[str, dict[str, Any]]
    peaks: list[dict[str, Any]]
    warnings: list[str]
    cost: float
    interrupted: bool
    result_path: str
    report_dir: str
    def to_dict(self) -> dict[str, Any]: ...

def fit(job: _Path, progress: bool = True, out_dir: _Path | None = None) -> FitResult: ...
