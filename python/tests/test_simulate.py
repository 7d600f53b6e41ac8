"""wiperlab.simulate, modes and Blade against the command line on the same blade: the same numbers
to the last digit (``wiperlab simulate`` writes each value's shortest round-trip decimal, so its
CSV parses to the very floats)."""

import csv
import json

import numpy as np
import pytest

import wiperlab
from conftest import DATA

BLADE = DATA / "blade_true.toml"


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return {name: [r[i] for r in rows[1:]] for i, name in enumerate(rows[0])}


def test_simulate_equals_cli_trace(run_cli, tmp_path):
    run_cli("simulate", BLADE, "--out-dir", tmp_path)
    cols = read_csv(tmp_path / "trace.csv")
    sim = wiperlab.simulate(BLADE)
    n = len(cols["t_s"])
    # The CLI's canonical trace: head at (v, -u), tip at (v3, -(l1 + l2)), then the state.
    pairs = {
        "t_s": sim.t,
        "head_x_m": sim.v,
        "head_y_m": -sim.u,
        "tip_x_m": sim.v3,
        "tip_y_m": np.full(n, -sim.reach_m),
        "theta_rad": sim.theta,
        "phi_rad": sim.phi,
        "theta_dot_rad_per_s": sim.theta_dot,
        "phi_dot_rad_per_s": sim.phi_dot,
        "v3_dot_m_per_s": sim.v3_dot,
        "normal_force_n": sim.normal_force,
        "friction_force_n": sim.friction_force,
    }
    for name, ours in pairs.items():
        assert ours.shape == (n,), name
        np.testing.assert_array_equal(ours, np.array(cols[name], dtype=np.float64), err_msg=name)
    labels = np.array([wiperlab.Simulation.PHASES[int(c)] for c in sim.phase])
    np.testing.assert_array_equal(labels, np.array(cols["phase"]))
    # Transitions: the CLI writes times with 17 significant digits, which round-trip exactly.
    cli = read_csv(tmp_path / "transitions.csv")
    assert [t.t_s for t in sim.transitions] == [float(t) for t in cli["t_s"]]
    assert [t.from_phase for t in sim.transitions] == cli["from"]
    assert [t.to_phase for t in sim.transitions] == cli["to"]
    assert sim.stats["transitions"] == len(sim.transitions) > 0


def test_simulate_options_match_cli(run_cli, tmp_path):
    blade = wiperlab.Blade.from_toml(BLADE)
    t0, t1 = blade.default_window()
    window = (t0 + 0.9, t0 + 1.0)
    run_cli(
        "simulate", BLADE, "--window", f"{window[0]!r},{window[1]!r}", "--fps", "20000",
        "--rtol", "1e-8", "--atol", "1e-10", "--method", "dopri5", "--out-dir", tmp_path,
    )
    cols = read_csv(tmp_path / "trace.csv")
    sim = wiperlab.simulate(blade, window, rtol=1e-8, atol=1e-10, method="dopri5", fps=20000)
    np.testing.assert_array_equal(sim.t, np.array(cols["t_s"], dtype=np.float64))
    np.testing.assert_array_equal(sim.v3, np.array(cols["tip_x_m"], dtype=np.float64))


def test_t_eval_samples_the_same_run():
    # Sampling does not steer the integrator: the states at a subset of the default grid are the
    # default run's states there.
    full = wiperlab.simulate(BLADE)
    some = wiperlab.simulate(BLADE, t_eval=full.t[::97])
    np.testing.assert_array_equal(some.t, full.t[::97])
    np.testing.assert_array_equal(some.theta, full.theta[::97])
    assert some.transitions == full.transitions


def test_simulate_physics():
    sim = wiperlab.simulate(BLADE)
    blade = wiperlab.Blade.from_toml(BLADE)
    # The drive v = a(1 - cos wt) is imposed.
    a, w = blade.drive_a_m, blade.drive_omega_rad_per_s
    np.testing.assert_allclose(sim.v, a * (1 - np.cos(w * sim.t)), rtol=0, atol=1e-15)
    # In stick the tip does not move (to rounding, against slip speeds of ~0.1 m/s); in slip
    # friction opposes the slip velocity.
    stick = sim.phase == 0
    assert stick.any() and (~stick).any()
    np.testing.assert_allclose(sim.v3_dot[stick], 0.0, rtol=0, atol=1e-15)
    slip = sim.phase != 0
    assert np.all(np.sign(sim.friction_force[slip]) == -sim.phase[slip])
    assert np.all(sim.normal_force > 0)


def test_modes_equal_cli(run_cli):
    out = json.loads(run_cli("modes", BLADE, "--json").stdout)
    table = wiperlab.modes(BLADE)
    assert list(table["phase"]) == [m["phase"] for m in out]
    np.testing.assert_array_equal(table["freq_hz"], [m["freq_hz"] for m in out])
    np.testing.assert_array_equal(table["damping_ratio"], [m["damping_ratio"] for m in out])
    np.testing.assert_array_equal(
        table["speed_m_per_s"], [m.get("speed_m_per_s", np.nan) for m in out]
    )
    for key in ("head", "head_link", "neck_lip"):
        np.testing.assert_array_equal(table[key], [m["participation"][key] for m in out])
    speeds = wiperlab.modes(BLADE, speeds=[0.05, 0.1])
    assert list(speeds["phase"]) == ["stick"] + ["slip"] * 4


def test_blade_round_trip():
    blade = wiperlab.Blade.from_toml(BLADE)
    assert wiperlab.Blade(**blade.to_dict()) == blade
    assert blade.k1_nm_per_rad == 0.029748408887917077  # the file's value, exactly
    stiffer = blade.replace(k1_nm_per_rad=0.05)
    assert stiffer.k1_nm_per_rad == 0.05 and blade.k1_nm_per_rad != 0.05
    with pytest.raises(AttributeError):
        blade.k1_nm_per_rad = 1.0
    with pytest.raises(AttributeError, match="no parameter 'k9'"):
        blade.k9
    # A stiffer neck raises the neck-lip mode in stick.
    assert wiperlab.modes(stiffer)["freq_hz"][0] > wiperlab.modes(blade)["freq_hz"][0]


def test_blade_and_simulate_errors(tmp_path):
    blade = wiperlab.Blade.from_toml(BLADE)
    with pytest.raises(wiperlab.InputError, match="Blade: missing field `l2_m`"):
        wiperlab.Blade(l1_m=0.002)
    with pytest.raises(wiperlab.InputError, match="Blade: unknown field `k9`"):
        blade.replace(k9=1.0)
    with pytest.raises(wiperlab.InputError, match="l1_m = -1 must be finite and > 0"):
        blade.replace(l1_m=-1.0)
    with pytest.raises(FileNotFoundError):
        wiperlab.Blade.from_toml(tmp_path / "missing.toml")
    bad = tmp_path / "blade.toml"
    bad.write_text(BLADE.read_text().replace("l1_m = 0.002", "l1_m = \"two\""))
    with pytest.raises(wiperlab.ParseError) as e:
        wiperlab.Blade.from_toml(bad)
    assert e.value.line == 5
    with pytest.raises(ValueError, match="unknown method 'rk4'"):
        wiperlab.simulate(blade, method="rk4")
    with pytest.raises(ValueError, match="t_span"):
        wiperlab.simulate(blade, (2.0, 1.0))
    with pytest.raises(ValueError, match="tolerance"):
        wiperlab.simulate(blade, rtol=0.0)
    with pytest.raises(ValueError, match="t_eval"):
        wiperlab.simulate(blade, (1.0, 1.1), t_eval=[1.05, 1.02])
    with pytest.raises(wiperlab.InputError, match="not reached by the drive"):
        wiperlab.modes(blade, speeds=[100.0])


def test_simulation_failure_is_simulation_error():
    # A drive 12 times faster and 10 times wider throws the lip tip off the glass: the library
    # stops with the time and the state.
    blade = wiperlab.Blade.from_toml(BLADE).replace(drive_a_m=1.0, drive_omega_rad_per_s=20.0)
    with pytest.raises(wiperlab.SimulationError, match="contact lost"):
        wiperlab.simulate(blade)
