"""wiperlab.simulate from Python against the same simulation through the command line, side by
side in one run.

Alternates ROUNDS times (default 15): `wiperlab simulate BLADE --out-dir TMP` (its own printed
time of the simulation, "simulated ... in X s", which covers the integration and the contact
forces and not the process start or the files), then `wiperlab.simulate(BLADE)` timed around the
call (the integration, the contact forces and the hand-over of the arrays to NumPy). Prints each
side's median and the median of the per-round ratios Python/CLI. Both run the same settings
(the command's defaults: dop853, rtol 1e-10, atol 1e-12, 10,000 samples/s over the default
window) and must give the same number of integrator steps.

    python examples/python/simulate_speed.py [BLADE_TOML] [ROUNDS]

The `wiperlab` command is taken from WIPERLAB_BIN, else target/release/wiperlab.
"""

import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import wiperlab

REPO = Path(__file__).resolve().parents[2]


def main() -> None:
    blade = Path(sys.argv[1]) if len(sys.argv) > 1 else REPO / "data/reversal/blade_true.toml"
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 15
    cli = os.environ.get("WIPERLAB_BIN", str(REPO / "target/release/wiperlab"))
    pattern = re.compile(r"in ([0-9.]+) s: (\d+) transitions, (\d+) steps")
    wiperlab.simulate(blade)  # warm-up: the first call loads the page cache and NumPy's C API
    cli_s, py_s, ratios = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(rounds):
            out = subprocess.run(
                [cli, "simulate", str(blade), "--out-dir", tmp],
                capture_output=True, text=True, check=True,
            ).stdout
            m = pattern.search(out)
            t = time.perf_counter()
            sim = wiperlab.simulate(blade)
            py = time.perf_counter() - t
            assert int(m[3]) == sim.stats["steps"], "the two runs differ"
            cli_s.append(float(m[1]))
            py_s.append(py)
            ratios.append(py / float(m[1]))
    med = statistics.median
    print(f"blade {blade}: {sim.stats['steps']} steps, {len(sim.transitions)} transitions, "
          f"{len(sim.t)} samples; {rounds} rounds, CLI and Python in turn")
    print(f"CLI    simulation: median {med(cli_s):.4f} s (min {min(cli_s):.4f}, max {max(cli_s):.4f})")
    print(f"Python simulation: median {med(py_s):.4f} s (min {min(py_s):.4f}, max {max(py_s):.4f})")
    print(f"Python/CLI per round: median {med(ratios):.3f} (min {min(ratios):.3f}, max {max(ratios):.3f})")


if __name__ == "__main__":
    main()
