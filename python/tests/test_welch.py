"""wiperlab.welch against scipy.signal.welch on the same random inputs, every option.

Reference: SciPy's own ``scipy.signal.welch`` (an independent implementation of the same
definition); equal to 1e-10 relative, frequencies bit for bit.
"""

import itertools

import numpy as np
import pytest

import wiperlab

signal = pytest.importorskip("scipy.signal")

RTOL = 1e-10


def assert_same(ours, theirs):
    f, p = ours
    f_ref, p_ref = theirs
    np.testing.assert_array_equal(f, f_ref)
    # Relative to the largest bin, so that bins near zero (DC after detrending) do not divide by 0.
    scale = np.max(np.abs(p_ref))
    assert p.shape == p_ref.shape
    assert np.max(np.abs(p - p_ref)) <= RTOL * scale, np.max(np.abs(p - p_ref)) / scale


@pytest.mark.parametrize(
    "window,detrend,scaling,average",
    list(
        itertools.product(
            ["hann", "hamming", "blackman", "boxcar"],
            ["constant", "linear", False],
            ["density", "spectrum"],
            ["mean", "median"],
        )
    ),
)
def test_every_option_matches_scipy(window, detrend, scaling, average):
    rng = np.random.default_rng(abs(hash((window, str(detrend), scaling, average))) % 2**32)
    x = rng.normal(size=3001) + 0.3 * np.sin(2 * np.pi * 0.07 * np.arange(3001)) + 2.0
    kw = dict(window=window, nperseg=300, detrend=detrend, scaling=scaling, average=average)
    assert_same(wiperlab.welch(x, 2500.0, **kw), signal.welch(x, 2500.0, **kw))


@pytest.mark.parametrize(
    "n,nperseg,noverlap,nfft",
    [
        (1000, 256, None, None),
        (1000, 255, None, None),  # odd segment
        (1000, 256, 0, None),  # no overlap
        (1000, 256, 255, None),  # largest overlap
        (1000, 200, 50, 512),  # zero padding, even nfft
        (1000, 200, 100, 401),  # odd nfft
        (257, 257, None, None),  # one segment
        (4096, 1024, 768, 2048),
    ],
)
def test_segmenting_matches_scipy(n, nperseg, noverlap, nfft):
    x = np.random.default_rng(n + nperseg).normal(size=n)
    kw = dict(nperseg=nperseg, noverlap=noverlap, nfft=nfft)
    assert_same(wiperlab.welch(x, 10_000.0, **kw), signal.welch(x, 10_000.0, **kw))


def test_defaults_match_scipy():
    # SciPy: nperseg 256, window 'hann', detrend 'constant', density, mean; fs defaults to 1.
    x = np.random.default_rng(7).normal(size=5000)
    assert_same(wiperlab.welch(x), signal.welch(x))
    assert_same(wiperlab.welch(x, 1e4), signal.welch(x, 1e4))


def test_short_record_uses_whole_record_as_scipy():
    # SciPy shrinks the default nperseg = 256 to the record's length (with a warning).
    x = np.random.default_rng(3).normal(size=100)
    with pytest.warns(UserWarning):
        ref = signal.welch(x, 50.0)
    assert_same(wiperlab.welch(x, 50.0), ref)


def test_accepts_lists_and_strided_arrays():
    x = np.random.default_rng(11).normal(size=(2, 2000))
    strided = x[:, ::1][1, ::2]  # non-contiguous view
    assert_same(wiperlab.welch(strided, 100.0, nperseg=128), signal.welch(strided, 100.0, nperseg=128))
    assert_same(
        wiperlab.welch(list(strided), 100.0, nperseg=128), signal.welch(strided, 100.0, nperseg=128)
    )


def test_sinusoid_power_is_half_amplitude_squared():
    # Parseval: the density integrates to the mean square, A²/2 for a sinusoid of amplitude A.
    fs, a = 1000.0, 0.002
    t = np.arange(20_000) / fs
    f, p = wiperlab.welch(a * np.sin(2 * np.pi * 125.0 * t), fs, nperseg=1000)
    assert abs(np.sum(p) * (f[1] - f[0]) - a**2 / 2) < 1e-3 * a**2 / 2


@pytest.mark.parametrize(
    "kw,message",
    [
        (dict(nperseg=64, noverlap=64), "noverlap = 64 must be less than nperseg = 64"),
        (dict(nperseg=64, nfft=32), "nfft = 32 must be at least nperseg = 64"),
        (dict(nperseg=1), "nperseg = 1 must be at least 2"),
        (dict(nperseg=5000), "record has 1000 samples, expected at least nperseg = 5000"),
    ],
)
def test_bad_settings_raise_input_error(kw, message):
    x = np.zeros(1000)
    with pytest.raises(wiperlab.InputError, match=message):
        wiperlab.welch(x, 100.0, **kw)
    # InputError is a ValueError, as SciPy raises for bad settings.
    with pytest.raises(ValueError):
        wiperlab.welch(x, 100.0, **kw)


def test_bad_values_raise():
    x = np.zeros(1000)
    with pytest.raises(wiperlab.InputError, match="sampling rate fs = -1 Hz"):
        wiperlab.welch(x, -1.0)
    x_nan = x.copy()
    x_nan[10] = np.nan
    with pytest.raises(wiperlab.InputError, match="sample 10 of 1000 is NaN"):
        wiperlab.welch(x_nan, 100.0)
    with pytest.raises(ValueError, match="window 'kaiser'"):
        wiperlab.welch(x, 100.0, window="kaiser")
    with pytest.raises(ValueError, match="scaling 'psd'"):
        wiperlab.welch(x, 100.0, scaling="psd")
    with pytest.raises(ValueError, match="average 'max'"):
        wiperlab.welch(x, 100.0, average="max")
    with pytest.raises(ValueError, match="detrend 'quadratic'"):
        wiperlab.welch(x, 100.0, detrend="quadratic")
    with pytest.raises(ValueError, match="expected a 1-D array"):
        wiperlab.welch(np.zeros((10, 10)), 100.0)
