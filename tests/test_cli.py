"""The command line: `tailbeam simulate` and `tailbeam reproduce`, run as a user would."""

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tailbeam.cli.main import main
from tailbeam.results.result import IMPACT_COLUMNS, IMPACT_TABLE_COLUMNS

ROOT = Path(__file__).parents[1]
EXAMPLE = ROOT / "examples" / "two_balls_rigid.toml"


def tailbeam(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "tailbeam", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=3600,  # a hang guard, not a timing: a loaded machine may take many minutes
    )


def read_csv(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    out = tmp_path_factory.mktemp("sim") / "out"
    proc = tailbeam("simulate", EXAMPLE, "--out", out)
    assert proc.returncode == 0, proc.stderr
    return out


def test_simulate_writes_impacts(simulated):
    header, rows = read_csv(simulated / "impacts.csv")
    assert tuple(header[:12]) == IMPACT_COLUMNS  # the historical columns first, unchanged
    assert tuple(header) == IMPACT_TABLE_COLUMNS
    assert {r[0] for r in rows} == {"coal", "sandstone"}
    data = json.loads((simulated / "impacts.json").read_text())  # strict JSON (no NaN)
    assert len(data["impacts"]) == len(rows)
    assert data["scene"]["contact"]["damping"] == 300.0
    assert set(data["rest_time"]) == {"coal", "sandstone"}
    # Full precision: the CSV holds the same floats as the JSON.
    for row, imp in zip(rows, data["impacts"], strict=True):
        assert float(row[header.index("peak_force")]) == imp["peak_force"]
        # restitution is the ratio of the two speeds in the same row
        v_in, v_out = float(row[4]), float(row[5])
        assert math.isclose(float(row[6]), v_out / v_in, rel_tol=1e-12)


def test_simulate_timeseries_is_uniform_and_samples_every_pulse(simulated):
    """timeseries.csv is on the uniform grid k / fs (so an FFT of it is valid); the manifest
    gives fs and units; each force pulse is sampled near its peak (the exact peak is in
    impacts.csv): a pulse of duration T ~ 350 us sampled every 50 us has a sample within
    25 us of its peak, where a half-sine is >= cos(pi 25/350) = 0.975 of the peak."""
    header, rows = read_csv(simulated / "timeseries.csv")
    assert header == ["t", "z_coal", "vz_coal", "force_coal"] + [
        "z_sandstone",
        "vz_sandstone",
        "force_sandstone",
    ]
    fs = 20000.0  # examples/two_balls_rigid.toml
    t = np.array([float(r[0]) for r in rows])
    assert np.array_equal(t, np.arange(len(t)) / fs) and math.isclose(t[-1], 1.0)
    manifest = json.loads((simulated / "manifest.json").read_text())
    meta = manifest["files"]["timeseries.csv"]
    assert meta["sample_rate_hz"] == fs and meta["grid"] == "uniform"
    assert meta["units"]["force_coal"] == "N" and meta["units"]["t"] == "s"
    _, impacts = read_csv(simulated / "impacts.csv")
    for imp in impacts:
        force = np.array([float(r[header.index(f"force_{imp[0]}")]) for r in rows])
        inside = (t >= float(imp[2])) & (t <= float(imp[3]))
        peak = float(imp[7])
        assert force[inside].max() <= peak * (1 + 1e-12)
        assert force[inside].max() >= 0.95 * peak


BAD_SCENES = {
    "unknown_material": ('material = "coal"', 'material = "granit"', "balls[1].material"),
    "negative_radius": ("radius = 0.03\n", "radius = -0.03\n", "balls[1].radius"),
    "inside_plate": ("0.0, 0.035]", "0.0, 0.02]", "balls[1].position"),
    "nan": ("radius = 0.03\n", "radius = nan\n", "balls[1].radius"),
    "misspelled": ("damping = 300.0", "dampin = 300.0", "contact.dampin"),
    "wrong_type": ("duration = 1.0", 'duration = "1 s"', "duration"),
    "unparseable": ("duration = 1.0", "duration = 1.0 s", "bad.toml"),
}


@pytest.mark.parametrize("case", sorted(BAD_SCENES))
def test_bad_scene_exit_2_one_line_no_output(tmp_path, case, capsys):
    """In this process (``main``, as the console script calls it); the tests below start a
    ``tailbeam`` process for what only a process shows."""
    old, new, field = BAD_SCENES[case]
    text = EXAMPLE.read_text()
    assert old in text
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace(old, new, 1))
    out = tmp_path / "out"
    code = main(["simulate", str(bad), "--out", str(out)])
    stderr = capsys.readouterr().err
    assert code == 2
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    assert "Traceback" not in stderr
    assert field in lines[0]
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]  # no temp dirs left


def test_bad_scene_leaves_existing_output_alone(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "impacts.csv").write_text("old")
    bad = tmp_path / "bad.toml"
    bad.write_text(EXAMPLE.read_text().replace("radius = 0.03\n", "radius = 0\n", 1))
    proc = tailbeam("simulate", bad, "--out", out)
    assert proc.returncode == 2
    assert [p.name for p in out.iterdir()] == ["impacts.csv"]
    assert (out / "impacts.csv").read_text() == "old"


def test_missing_scene_file(tmp_path):
    proc = tailbeam("simulate", tmp_path / "nope.toml", "--out", tmp_path / "out")
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_modal_scene_writes_sensors(tmp_path):
    out = tmp_path / "out"
    proc = tailbeam("simulate", ROOT / "examples" / "modal_plate.toml", "--out", out)
    assert proc.returncode == 0, proc.stderr
    header, rows = read_csv(out / "sensors.csv")
    assert header == ["t", "acc_centre", "acc_edge"]
    t = [float(r[0]) for r in rows]
    assert t[1] - t[0] == pytest.approx(1 / 51200.0)
    # the spectrum file holds each sensor's one-sided amplitude spectrum of the sampled series
    spec_header, spec_rows = read_csv(out / "sensor_spectra.csv")
    assert spec_header == ["freq_acc_centre", "amp_acc_centre", "freq_acc_edge", "amp_acc_edge"]
    a = np.array([float(r[1]) for r in rows])
    amp = np.abs(np.fft.rfft(a)) / len(a)
    amp[1:] *= 2.0
    if len(a) % 2 == 0:
        amp[-1] *= 0.5
    got = np.array([float(r[1]) for r in spec_rows[: len(amp)]])
    np.testing.assert_allclose(got, amp, rtol=1e-9, atol=1e-12 * amp.max())
    freq = np.array([float(r[0]) for r in spec_rows[: len(amp)]])
    np.testing.assert_allclose(freq, np.fft.rfftfreq(len(a), 1 / 51200.0), rtol=1e-12)
    for name in ("acc_centre", "acc_edge"):
        assert (out / f"sensor_{name}.png").stat().st_size > 0


def test_reproduce(tmp_path):
    out = tmp_path / "rep"
    proc = tailbeam("reproduce", "--out", out)
    header, rows = read_csv(out / "claims.csv")
    verdicts = [r[header.index("verdict")] for r in rows]
    # Exit code 0 exactly when every claim holds (1 otherwise).
    assert proc.returncode == (0 if all(v == "PASS" for v in verdicts) else 1), proc.stderr
    assert len(rows) >= 19 and set(verdicts) <= {"PASS", "FAIL"}
    for key in ("velocity", "material", "energy"):
        for name in ("impacts.csv", "particles.csv", "impacts.json", "timeseries.csv"):
            assert (out / key / name).stat().st_size > 0
    assert len(list(out.glob("fig*.png"))) == 9
    assert (out / "claims.md").read_text().count("\n") == len(rows) + 2
    for r in rows:  # the printed table shows every claim with its verdict
        assert f"{r[2]:7}  {r[0]}" in proc.stdout
    off_header, off_rows = read_csv(out / "claims_clamp_off.csv")
    assert off_header == header and [r[0] for r in off_rows] == [r[0] for r in rows]
    assert "without Adams' clamp" in proc.stdout
