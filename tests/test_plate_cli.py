"""`tailbeam modes`: table, frequencies.csv, VTU and PNG; bad input -> one line, exit 2."""

import csv

import meshio
import numpy as np

from tailbeam.cli import main
from tailbeam.io.output import MANIFEST
from tailbeam.physics.bodies import Plate
from tailbeam.plate.closed_forms import ssss_modes


def test_modes_command_writes_outputs(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("TAILBEAM_CACHE_DIR", str(tmp_path / "cache"))
    out = tmp_path / "out"
    code = main(
        ["modes", "--count", "6", "--theory", "kirchhoff", "--divisions", "8", "--out", str(out)]
        + ["--vtu", "--png"]
    )
    assert code == 0
    printed = capsys.readouterr().out
    assert "closed form SSSS kirchhoff" in printed
    with (out / "frequencies.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["mode"]) for r in rows] == list(range(1, 7))
    ref = ssss_modes(Plate(), "kirchhoff", count=6).frequencies_hz
    got = np.array([float(r["frequency_hz"]) for r in rows])
    np.testing.assert_allclose(got, ref, rtol=1e-5)
    np.testing.assert_allclose([float(r["reference_hz"]) for r in rows], ref, rtol=1e-9)
    assert all(abs(float(r["rel_error"])) < 1e-5 and r["theory"] == "kirchhoff" for r in rows)
    vtu = meshio.read(out / "modes.vtu")
    assert len(vtu.point_data) == 6
    assert (out / "modes.png").stat().st_size > 10_000


def test_bad_boundary_code_is_one_line_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "out"
    code = main(["modes", "--bc", "SSQS", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "--bc:" in err
    assert not out.exists()


def test_default_output_is_frequencies_only(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("TAILBEAM_CACHE_DIR", str(tmp_path / "cache"))
    out = tmp_path / "out"
    code = main(
        ["modes", "--count", "3", "--theory", "kirchhoff", "--divisions", "6", "--out", str(out)]
    )
    assert code == 0
    assert sorted(p.name for p in out.iterdir()) == ["frequencies.csv", MANIFEST]


def test_too_large_band_names_the_option_before_work(tmp_path, capsys):
    # fmax: the mesh the band needs is beyond the mesh limit; count: the estimated solve is
    # far beyond the memory/time limits (tailbeam.plate.fe.cost). Both refused before assembly.
    for option, value in (("--fmax", "1e6"), ("--fmax", "72000"), ("--count", "5000")):
        out = tmp_path / "out"
        code = main(["modes", option, value, "--no-cache", "--out", str(out)])
        err = capsys.readouterr().err
        assert code == 2 and err.count("\n") == 1, err
        assert err.startswith(f"tailbeam modes: error: {option}:"), err
        assert "divisions:" not in err
        assert not out.exists()
