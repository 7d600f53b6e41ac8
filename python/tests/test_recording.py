"""wiperlab.read_recording against the canonical trace CSV that ``wiperlab import`` writes for the
same file and settings: the same numbers to the last digit (the CSV holds each value's shortest
round-trip decimal, so parsing it gives the very float), the same points and gap report."""

import numpy as np
import pytest

import wiperlab
from conftest import DATA, SAMPLE, SAMPLE_SETTINGS, SAMPLE_T0_S, SHARED, cli_flags


def read_canonical(path):
    """The canonical CSV as (t, {point: (n, 2)}), NaN for the CSV's NaN cells."""
    with open(path) as f:
        header = f.readline().strip().split(",")
    table = np.genfromtxt(path, delimiter=",", skip_header=1, dtype=np.float64, ndmin=2)
    assert header[0] == "t_s"
    points = {}
    for i in range(1, len(header), 2):
        name = header[i][: -len("_x_m")]
        assert header[i + 1] == f"{name}_y_m"
        points[name] = table[:, i : i + 2]
    return table[:, 0], points


def assert_same_as_cli(run_cli, tmp_path, path, settings):
    rec = wiperlab.read_recording(path, **settings)
    out = tmp_path / "trace.csv"
    run_cli("import", path, *cli_flags(settings), "-o", out)
    t, points = read_canonical(out)
    np.testing.assert_array_equal(rec.t, t)
    assert list(rec.points) == list(points)
    for name, xy in points.items():
        assert rec.points[name].shape == (len(t), 2)
        # Bit for bit, NaN where the CLI writes NaN.
        np.testing.assert_array_equal(rec.points[name], xy)
    return rec


def test_shipped_recording_matches_cli(run_cli, tmp_path):
    rec = assert_same_as_cli(run_cli, tmp_path, SAMPLE, SAMPLE_SETTINGS)
    assert rec.format == "dltdv"
    assert rec.head is rec.points["head"] and rec.tip is rec.points["tip"]
    # The gap report: NaN samples per point are the NaN rows of the arrays.
    for name, xy in rec.points.items():
        assert rec.summary["points"][name]["nan_samples"] == int(np.isnan(xy).any(axis=1).sum())
    assert rec.summary["n_frames"] == len(rec.t)
    # 10,000 frames/s from frame 1 at t0_s (data/reversal/README.md).
    # DLTdv has frame numbers: t = (frame - 1) / fps.
    np.testing.assert_array_equal(rec.t, np.arange(len(rec.t)) / 10000.0)
    assert "dltdv: " in str(rec)
    # t0_s moves the clock (fits/reversal.toml puts frame 1 at the drive phase pi/2).
    shifted = wiperlab.read_recording(SAMPLE, **SAMPLE_SETTINGS, t0_s=SAMPLE_T0_S)
    assert shifted.t[0] == SAMPLE_T0_S
    np.testing.assert_allclose(shifted.t - SAMPLE_T0_S, rec.t, rtol=0, atol=1e-12)


def test_shipped_tracker_export_matches_cli(run_cli, tmp_path):
    rec = assert_same_as_cli(
        run_cli, tmp_path, DATA / "wiper_reversal_sample_tracker.txt", {}
    )
    assert rec.format == "tracker"


def test_canonical_csv_reads_back(run_cli, tmp_path):
    out = tmp_path / "sample.trace.csv"
    run_cli("import", SAMPLE, *cli_flags(SAMPLE_SETTINGS), "-o", out)
    a = wiperlab.read_recording(SAMPLE, **SAMPLE_SETTINGS)
    b = wiperlab.read_recording(out)
    assert b.format == "canonical"
    np.testing.assert_array_equal(a.t, b.t)
    for name in a.points:
        np.testing.assert_array_equal(a.points[name], b.points[name])


def test_spec_file_and_overrides(tmp_path):
    spec = tmp_path / "sample.import.toml"
    spec.write_text(
        'format = "dltdv"\nfps_hz = 10000.0\nm_per_px = 1.5e-5\norigin_px = [200.0, 300.0]\n'
        "[points]\nhead = \"pt1\"\ntip = \"pt2\"\n"
    )
    a = wiperlab.read_recording(SAMPLE, spec=spec)
    b = wiperlab.read_recording(SAMPLE, spec=spec, m_per_px=3e-5)
    # The scale given by name overrides the spec's: every position doubles about the origin.
    np.testing.assert_allclose(b.head, 2 * a.head, rtol=1e-12)


def test_to_pandas():
    pd = pytest.importorskip("pandas")
    rec = wiperlab.read_recording(SAMPLE, **SAMPLE_SETTINGS)
    df = rec.to_pandas()
    assert isinstance(df, pd.DataFrame)
    assert list(df.columns) == ["t_s", "head_x_m", "head_y_m", "tip_x_m", "tip_y_m"]
    np.testing.assert_array_equal(df["tip_y_m"].to_numpy(), rec.tip[:, 1])


# ../shared/realdata: every real export with the settings it needs (SOURCES.md there).
REALDATA = [
    ("tracker/8047.txt", {}),
    ("tracker/8049.txt", {}),
    ("tracker/8054.txt", {}),
    ("kinovea/pas_camera_01.txt", dict(units_to_m=0.01)),
    ("kinovea/trop_camera_03.txt", dict(units_to_m=0.01)),
    ("kinovea/v1.csv", dict(units_to_m=0.01)),
    ("dltdv/LapsanskyArmstrong2022_data_xypts.csv", dict(fps=100.0, m_per_px=1e-3)),
    (
        "deeplabcut/IL5-519-Cam2_2020-06-25_000124Track9DLC_resnet50_Austin2020_accuracy_testApr7shuffle3_1150000.csv",
        dict(fps=30.0, m_per_px=1e-3),
    ),
    (
        "deeplabcut/AFAMcarollia_1Apr2021_0790C_Bane_Y20210401H145003.312743000_F1_croppedDLC_resnet50_Brown2021_accuracy_testJan28shuffle1_450000.csv",
        dict(fps=30.0, m_per_px=1e-3),
    ),
    ("sleap/sleap_csv_example.EXCERPT_first11lines.csv", dict(fps=30.0, m_per_px=1e-3)),
    ("trackmate/Spots in tracks statistics.csv", dict(fps=30.0, m_per_px=1e-3)),
]


@pytest.mark.parametrize("name,settings", REALDATA, ids=[n for n, _ in REALDATA])
def test_realdata_matches_cli(run_cli, tmp_path, name, settings):
    path = SHARED / "realdata" / name
    if not path.exists():
        pytest.skip(f"{path} is not here (../shared/realdata beside the repository)")
    assert_same_as_cli(run_cli, tmp_path, path, settings)


def test_recording_errors(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        wiperlab.read_recording(tmp_path / "missing.csv")
    assert e.value.filename == str(tmp_path / "missing.csv")
    # DLTdv has frame numbers only: the message says which setting is missing.
    with pytest.raises(wiperlab.RecordingError, match="set the camera's frame rate"):
        wiperlab.read_recording(SAMPLE)
    with pytest.raises(wiperlab.InputError):
        wiperlab.read_recording(SAMPLE)
    not_a_track = tmp_path / "notes.txt"
    not_a_track.write_text("hello\nworld\n")
    with pytest.raises(wiperlab.RecordingError, match="unknown tracking-file format"):
        wiperlab.read_recording(not_a_track)
    with pytest.raises(ValueError, match="format 'xypts': expected one of 'dltdv'"):
        wiperlab.read_recording(SAMPLE, format="xypts")
    # A bad value in a canonical CSV: file, line and column.
    bad = tmp_path / "bad.trace.csv"
    bad.write_text("t_s,head_x_m,head_y_m\n0,0.1,0.2\n0.001,abc,0.2\n")
    with pytest.raises(wiperlab.ParseError) as e:
        wiperlab.read_recording(bad)
    assert (e.value.path, e.value.line) == (str(bad), 3)
    assert e.value.column > 0
    assert str(e.value).startswith(f"{bad}:3:")
