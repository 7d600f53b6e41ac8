"""The package as a whole: the exception hierarchy, the panic guard, the type stubs and the
quickstart example."""

import ast
import inspect
import re
import subprocess
import sys
from pathlib import Path

import pytest

import wiperlab
from conftest import REPO


def test_exception_hierarchy():
    assert issubclass(wiperlab.InputError, wiperlab.WiperlabError)
    assert issubclass(wiperlab.InputError, ValueError)
    for cls in (wiperlab.ParseError, wiperlab.RecordingError):
        assert issubclass(cls, wiperlab.InputError)
    for cls in (wiperlab.SimulationError, wiperlab.FitError):
        assert issubclass(cls, wiperlab.WiperlabError) and not issubclass(cls, ValueError)


def test_a_panic_becomes_wiperlab_error():
    with pytest.raises(wiperlab.WiperlabError, match="internal error in wiperlab .*_check_panic_guard"):
        wiperlab._wiperlab._check_panic_guard()
    # The process goes on: the library still works after the panic.
    f, p = wiperlab.welch([0.0, 1.0, 0.0, -1.0] * 64, 4.0, nperseg=64)
    assert f[p.argmax()] == 1.0


def stub_signatures(path):
    tree = ast.parse(Path(path).read_text())
    return {
        node.name: [a.arg for a in node.args.args + node.args.kwonlyargs]
        for node in tree.body
        if isinstance(node, ast.FunctionDef)
    }


def test_stubs_match_the_functions():
    stubs = stub_signatures(Path(wiperlab.__file__).with_suffix(".pyi"))
    for name in wiperlab.__all__:
        obj = getattr(wiperlab, name)
        if inspect.isfunction(obj):
            params = list(inspect.signature(obj).parameters)
            assert stubs.get(name) == params, name
    assert set(stubs) == {n for n in wiperlab.__all__ if inspect.isfunction(getattr(wiperlab, n))}


def test_quickstart_runs(tmp_path):
    out = subprocess.run(
        [sys.executable, str(REPO / "examples" / "python" / "quickstart.py"), str(tmp_path)],
        capture_output=True,
        text=True,
        check=True,
    )
    # The true blade made the recording (data/reversal/README.md): its low line is the recording's.
    low = re.search(r"band +low .*: measured +([0-9.]+) Hz, model +([0-9.]+) Hz", out.stdout)
    measured, model = float(low[1]), float(low[2])
    assert abs(model - measured) < 0.01 * measured
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        assert "matplotlib is not installed: no plot" in out.stdout
    else:
        assert (tmp_path / "quickstart_psd.svg").read_text().startswith("<?xml")
