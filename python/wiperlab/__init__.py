"""wiperlab: a wiper blade's tracked motion beside a stick-slip model of it.

NumPy in, NumPy out; SI units (m, s, Hz, N, rad) throughout. The Rust library does the work: each
function here converts its arguments and calls it with the GIL released.
"""

from __future__ import annotations

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
    "welch",
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
) -> tuple[np.ndarray, np.ndarray]:
    """Welch's averaged-periodogram power spectral density, as ``scipy.signal.welch``.

    Same names, defaults and result as ``scipy.signal.welch(x, fs, window, nperseg, noverlap,
    nfft, detrend, scaling, average)`` with ``return_onesided=True`` (equal to 1e-10 relative,
    tested against SciPy in ``python/tests/test_welch.py``).

    Parameters
    ----------
    x : array_like, shape (n,)
        Uniformly sampled, finite samples (no NaN: gaps must be filled or the record split).
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
        fewer than ``nperseg`` samples, a non-finite sample); the message gives the numbers.

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
    )
