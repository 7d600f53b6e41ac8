"""The compiled half of wiperlab (python/src/); use the functions of ``wiperlab`` instead."""

from typing import Any

import numpy as np
import numpy.typing as npt

def welch(
    x: npt.NDArray[np.float64],
    fs: float = 1.0,
    window: str = "hann",
    nperseg: int | None = None,
    noverlap: int | None = None,
    nfft: int | None = None,
    detrend: str | bool | None = None,
    scaling: str = "density",
    average: str = "mean",
    max_fill: int | None = None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def find_peaks_in_band(
    f: npt.NDArray[np.float64], pxx: npt.NDArray[np.float64], band: tuple[float, float], n: int = 1
) -> list[tuple[float, float, int, float]]: ...
def read_recording(path: str, settings: dict[str, Any]) -> dict[str, Any]: ...
def blade_from_toml(path: str) -> dict[str, Any]: ...
def blade_check(params: dict[str, Any]) -> dict[str, Any]: ...
def blade_default_window(params: dict[str, Any]) -> tuple[float, float]: ...
def modes(blade: dict[str, Any], speeds: list[float] | None = None) -> dict[str, Any]: ...
def simulate(
    blade: dict[str, Any],
    t_span: tuple[float, float] | None,
    t_eval: list[float] | None,
    fps: float,
    rtol: float,
    atol: float,
    method: str,
    stick: str,
    model: str,
) -> dict[str, Any]: ...
def fit(job: str, progress: bool = True, out_dir: str | None = None) -> tuple[str, str, str]: ...
def _check_panic_guard() -> None: ...
