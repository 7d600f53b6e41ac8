"""wiperlab.fit against ``wiperlab fit`` on the same job: the same result (every field but the
wall times and the time stamp) and the same files; Ctrl-C; the GIL released meanwhile.

The job is the shipped reversal job (fits/reversal.toml: the shipped recording, its bands and
solver) made small enough for a test suite: the features objective, two free parameters, one
restart and a handful of iterations (about 3 s of CPU). The full job takes about a minute
(docs/python.md says how to compare it by hand)."""

import json
import os
import re
import signal
import threading
import time

import pytest

import wiperlab
from conftest import DATA

SMALL_JOB = """
name = "small"
blade = "{data}/blade.toml"

[recording]
file = "{data}/wiper_reversal_sample_xypts.csv"

[recording.import]
format = "dltdv"
fps_hz = 10000.0
m_per_px = 1.5e-5
origin_px = [200.0, 300.0]
t0_s = 0.9434198694385137

[recording.import.points]
head = "pt1"
tip = "pt2"

[spectrum]
signal = "tip_rel_x"
max_fill = 5

[[spectrum.bands]]
name = "low"
range_hz = [30.0, 300.0]
nperseg = 4096

[[spectrum.bands]]
name = "high"
range_hz = [500.0, 5000.0]
nperseg = 512

[solver]
rtol = 1e-8
atol = 1e-10

[fit]
particles = {particles}
swarm_iterations = {swarm}
polish_iterations = {polish}
seed = 1
restarts = 1
models = ["blade2dof"]
objective = "features"

[fit.parameters]
A = [0.2, 1.5]
k1 = [0.005, 0.15]
"""


def write_job(directory, particles=6, swarm=3, polish=8):
    directory.mkdir(parents=True, exist_ok=True)
    job = directory / "small.toml"
    job.write_text(
        SMALL_JOB.format(
            data=DATA.as_posix(), particles=particles, swarm=swarm, polish=polish
        )
    )
    return job


FIRST = re.compile(r" \(first: .*\)\); ")


def without_run_times(result: dict) -> dict:
    """The result without what differs between two runs of the same fit, by the command line as
    much as here: wall times, when, and which failed evaluation came first (the swarm evaluates its
    particles on a thread pool, so two failures race; `wiperlab fit` twice shows either)."""
    out = {k: v for k, v in result.items() if k not in ("wall_time_s", "fitted_at")}
    out["model_trials"] = [
        {k: v for k, v in t.items() if k != "wall_time_s"} for t in result["model_trials"]
    ]
    out["first_failure"] = "first_failure" in result
    out["warnings"] = [FIRST.sub(" (first: ...)); ", w) for w in result["warnings"]]
    out["warning_details"] = [
        {**d, "warning": {k: v for k, v in d["warning"].items() if k != "first"}}
        for d in result.get("warning_details", [])
    ]
    return out


def files_under(directory):
    return sorted(
        os.path.relpath(os.path.join(root, f), directory)
        for root, _, files in os.walk(directory)
        for f in files
    )


def toml_without_run_times(path):
    return [
        FIRST.sub(" (first: ...)); ", line)
        for line in path.read_text().splitlines()
        if not line.startswith(("wall_time_s", "fitted_at", "first_failure", "first = "))
    ]


def test_fit_equals_cli(run_cli, tmp_path):
    cli_job = write_job(tmp_path / "cli")
    py_job = write_job(tmp_path / "py")
    cli = json.loads(run_cli("fit", cli_job, "--json", "--quiet").stdout)
    result = wiperlab.fit(py_job, progress=False)

    assert without_run_times(result.to_dict()) == without_run_times(cli)
    assert result.model == cli["model"] == "blade2dof"
    assert list(result.parameters) == ["A", "k1"]
    assert result.parameters["A"]["value"] == cli["parameters"][0]["value"]
    assert [p["band"] for p in result.peaks] == ["low", "high"]
    assert result.cost == cli["cost"]
    assert not result.interrupted
    assert len(result.warnings) == len(cli["warnings"]) > 0

    # The same files: the result beside the job, the figures in reports/small/.
    assert result.result_path == str(py_job.with_name("small.result.toml"))
    assert result.report_dir == str(tmp_path / "py" / "reports" / "small")
    assert files_under(tmp_path / "py") == files_under(tmp_path / "cli")
    assert "small.result.toml" in files_under(tmp_path / "py")
    assert toml_without_run_times(tmp_path / "py" / "small.result.toml") == toml_without_run_times(
        tmp_path / "cli" / "small.result.toml"
    )
    for name in ("psd_low.csv", "traces_model.csv"):
        assert (tmp_path / "py" / "reports" / "small" / name).read_bytes() == (
            tmp_path / "cli" / "reports" / "small" / name
        ).read_bytes()


def test_ctrl_c_keeps_best_so_far_and_next_fit_runs(tmp_path):
    # A long search (150 swarm iterations), interrupted by SIGINT (what Ctrl-C sends) after 2 s.
    job = write_job(tmp_path / "long", swarm=150)
    # Python's own Ctrl-C handler, also where the suite was started with SIGINT ignored (as a
    # background job of a non-interactive shell is, which Python then leaves ignored).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(2.0, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    started = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt) as e:
            wiperlab.fit(job, progress=False)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    # The fit stopped soon after the signal, not after its 150 iterations.
    assert time.monotonic() - started < 60
    interrupted = job.with_name("small.interrupted.result.toml")
    assert str(e.value) == f"interrupted; the best result so far is in {interrupted}"
    assert "interrupted = true" in interrupted.read_text()
    assert not job.with_name("small.result.toml").exists()

    # The stop request is withdrawn: the next fit in this process runs to its end.
    quick = write_job(tmp_path / "quick", particles=4, swarm=1, polish=2)
    assert not wiperlab.fit(quick, progress=False).interrupted


def test_simulate_releases_the_gil():
    # While simulations run on another thread, this thread keeps running Python: it stamps the time
    # every millisecond, and its stamps cover each call without a gap of half the call. With the
    # GIL held during a call this thread would wait for the call's end: one gap of the whole call.
    blade = wiperlab.Blade.from_toml(DATA / "blade_true.toml")
    calls = []

    def work():
        for _ in range(3):
            t = time.perf_counter()
            wiperlab.simulate(blade)
            calls.append((t, time.perf_counter()))

    worker = threading.Thread(target=work)
    stamps = []
    worker.start()
    while worker.is_alive():
        stamps.append(time.perf_counter())
        time.sleep(0.001)
    for t0, t1 in calls:
        cover = [t0] + [s for s in stamps if t0 < s < t1] + [t1]
        longest_gap = max(b - a for a, b in zip(cover, cover[1:]))
        assert longest_gap < 0.5 * (t1 - t0), (longest_gap, t1 - t0)


def test_fit_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        wiperlab.fit(tmp_path / "missing.toml")
    job = write_job(tmp_path / "bad")
    job.write_text(job.read_text().replace("particles = 6", "particles = \"six\""))
    with pytest.raises(wiperlab.ParseError) as e:
        wiperlab.fit(job, progress=False)
    assert e.value.path == str(job)
    assert e.value.line == job.read_text().splitlines().index('particles = "six"') + 1
