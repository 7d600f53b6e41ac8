"""wiperlab from Python: the shipped recording's spectrum beside the shipped blade's simulation.

Loads the shipped high-speed-video track (data/reversal/, DLTdv layout, 10,000 frames/s), takes
the Welch PSD of the lip tip relative to the head (tip x - head x), simulates the shipped blade
(data/reversal/blade_true.toml, the parameters that made the recording) over the same reversal,
and prints both spectra's peaks in the low and the high band. With matplotlib installed it plots
both PSDs into quickstart_psd.svg (in the directory given as the first argument, default the
current one); without it the plot is skipped.

Run from the repository, with the package installed (pip install ./python):

    python examples/python/quickstart.py [OUTPUT_DIR]
"""

import sys
from pathlib import Path

import numpy as np

import wiperlab

REPO = Path(__file__).resolve().parents[2]
DATA = REPO / "data" / "reversal"
BANDS = {"low": (30.0, 300.0), "high": (500.0, 5000.0)}  # Hz, as fits/reversal.toml
FS_HZ = 10_000.0
NPERSEG = 4096


def main(out_dir: Path) -> None:
    # The recording: DLTdv has frame numbers and pixels, so the frame rate, the scale and the
    # origin come from the camera (data/reversal/README.md); pt1 is the head, pt2 the lip tip.
    rec = wiperlab.read_recording(
        DATA / "wiper_reversal_sample_xypts.csv",
        fps=FS_HZ,
        m_per_px=1.5e-5,
        origin_px=(200.0, 300.0),
        head="pt1",
        tip="pt2",
        t0_s=0.9434198694385137,  # frame 1 on the model's clock
    )
    print(rec)
    tip_rel = rec.tip[:, 0] - rec.head[:, 0]  # m; a few single-frame gaps are NaN
    f_meas, p_meas = wiperlab.welch(tip_rel, FS_HZ, nperseg=NPERSEG, max_fill=5)

    # The model: the same reversal window, sampled at the camera's rate.
    blade = wiperlab.Blade.from_toml(DATA / "blade_true.toml")
    sim = wiperlab.simulate(blade, (rec.t[0], rec.t[-1]), fps=FS_HZ)
    print(
        f"simulated {sim.t[0]:.4f} .. {sim.t[-1]:.4f} s: {len(sim.transitions)} stick/slip "
        f"transitions, {sim.stats['steps']} steps"
    )
    f_sim, p_sim = wiperlab.welch(sim.v3 - sim.v, FS_HZ, nperseg=NPERSEG)

    for band, (lo, hi) in BANDS.items():
        meas = wiperlab.find_peaks_in_band(f_meas, p_meas, (lo, hi))
        model = wiperlab.find_peaks_in_band(f_sim, p_sim, (lo, hi))
        show = lambda peaks: f"{peaks[0].freq_hz:8.2f} Hz" if peaks else "    none"
        print(f"band {band:>4} [{lo:g}, {hi:g}] Hz: measured {show(meas)}, model {show(model)}")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot")
        return
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.loglog(f_meas[1:], p_meas[1:], label="measured (tip - head)")
    ax.loglog(f_sim[1:], p_sim[1:], label="model (v3 - v)", alpha=0.8)
    for lo, hi in BANDS.values():
        ax.axvspan(lo, hi, color="0.9", zorder=0)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("PSD [m²/Hz]")
    ax.set_title("lip tip relative to head: Welch PSD, nperseg 4096")
    ax.legend()
    out = out_dir / "quickstart_psd.svg"
    fig.savefig(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path.cwd())
