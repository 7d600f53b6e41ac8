"""Shared helpers of the Python package's tests: where the repository, the shipped data and the
``wiperlab`` command line are.

``tests/suite/python.rs`` runs this suite with ``WIPERLAB_BIN`` set to the command it built; run by hand
(``python -m pytest python/tests`` from the repository, the package installed), the suite uses
``target/release/wiperlab``.
"""

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DATA = REPO / "data" / "reversal"
SHARED = REPO.parent / "shared"

# The shipped recording and the settings of fits/reversal.toml that read it (but its t0_s, which
# `wiperlab import` takes from a spec file only).
SAMPLE = DATA / "wiper_reversal_sample_xypts.csv"
SAMPLE_SETTINGS = dict(
    format="dltdv",
    fps=10000.0,
    m_per_px=1.5e-5,
    origin_px=(200.0, 300.0),
    head="pt1",
    tip="pt2",
)
SAMPLE_T0_S = 0.9434198694385137


def cli_flags(settings: dict) -> list[str]:
    """``read_recording``'s keyword arguments as the ``wiperlab import`` flags of the same names."""
    flags = []
    for name, value in settings.items():
        flag = "--" + name.replace("_", "-")
        if isinstance(value, (tuple, list)):
            value = ",".join(repr(float(v)) for v in value)
        elif isinstance(value, float):
            value = repr(value)
        flags += [flag, str(value)]
    return flags


@pytest.fixture(scope="session")
def wiperlab_bin() -> Path:
    path = Path(os.environ.get("WIPERLAB_BIN", REPO / "target" / "release" / "wiperlab"))
    if not path.exists():
        pytest.skip(f"the wiperlab command is not built ({path}); cargo build --release")
    return path


@pytest.fixture(scope="session")
def run_cli(wiperlab_bin):
    """Runs ``wiperlab ARGS...``; returns the completed process, failing the test on an error."""

    def run(*args, check=True):
        out = subprocess.run(
            [str(wiperlab_bin), *map(str, args)], capture_output=True, text=True
        )
        if check and out.returncode != 0:
            pytest.fail(f"wiperlab {' '.join(map(str, args))} failed:\n{out.stderr}")
        return out

    return run
