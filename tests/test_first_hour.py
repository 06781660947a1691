"""A new user's first hour: install layout, command-line behaviour, preflight rules, outputs.

Each bad input must give one line naming the field, exit code 2 and no output, before any
work; the gravity key is checked against the closed-form fall and rebound.
"""

import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import tailbeam
from tailbeam.cachedir import source_fingerprint
from tailbeam.cli import main
from tailbeam.physics.hertz import free_fall_apex

ROOT = Path(__file__).resolve().parents[1]
RIGID = (ROOT / "examples" / "two_balls_rigid.toml").read_text()
MODAL = (ROOT / "examples" / "modal_plate.toml").read_text()


def run_cli(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def one_line_error(code, err, field):
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert f"error: {field}:" in err, err


# -- install layout -------------------------------------------------------------------------------


def test_numba_cache_lives_outside_the_package(tmp_path):
    """Compiled kernels go to the cache folder, never into the installed package (stale
    .nbi/.nbc files there turned site-packages/tailbeam into a namespace package that
    shadowed an editable reinstall)."""
    env = dict(os.environ, TAILBEAM_CACHE_DIR=str(tmp_path))
    env.pop("NUMBA_CACHE_DIR", None)
    code = (  # one cached kernel compiled in a fresh process: the folder is numba's, global
        "import tailbeam, numba; from tailbeam.physics.contact_law import impact_force_array; "
        "impact_force_array(1e-5, 0.0, 1e9, 1.5, 0.0, 1e-4, False); "
        "print(numba.config.CACHE_DIR)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert Path(out.stdout.strip()) == tmp_path / "numba" / source_fingerprint()
    assert any((tmp_path / "numba").rglob("*.nbi"))
    package = Path(tailbeam.__file__).parent
    assert not list(package.rglob("*.nbi")) and not list(package.rglob("*.nbc"))


def test_an_unwritable_cache_folder_is_said_and_kept_out_of_the_package(tmp_path):
    """A cache folder that cannot be created (here: under a file) gets one line naming
    TAILBEAM_CACHE_DIR, and the kernels go to the system's temporary folder, not into the
    package (where numba falls back to when its folder cannot be written)."""
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    env = dict(os.environ, TAILBEAM_CACHE_DIR=str(blocker / "cache"))
    env.pop("NUMBA_CACHE_DIR", None)
    code = "import tailbeam, numba; print(numba.config.CACHE_DIR)"
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    folder = Path(out.stdout.strip())
    assert folder.is_dir() and folder.name == source_fingerprint()
    assert Path(tailbeam.__file__).parent not in folder.parents
    assert out.stderr.count("\n") == 1 and "TAILBEAM_CACHE_DIR" in out.stderr


def test_numba_cache_follows_every_source_file(tmp_path):
    """numba checks a cached kernel against its own file only; the cache folder is keyed by
    every tailbeam source file, so editing any module (a helper a kernel calls or inlines, a
    constant it reads) gives a new folder, never a stale kernel."""
    package = tmp_path / "tailbeam"
    shutil.copytree(
        Path(tailbeam.__file__).parent, package, ignore=shutil.ignore_patterns("__pycache__")
    )
    code = "import tailbeam.cachedir as c; print(c.source_fingerprint())"

    def fingerprint():
        out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                             text=True, check=True)  # fmt: skip
        return out.stdout.strip()

    before = fingerprint()
    assert before == source_fingerprint()  # same sources, same folder (another checkout too)
    helper = package / "solvers" / "stream" / "active" / "compiled" / "pairs.py"
    helper.write_text(helper.read_text() + "\n# edited\n")
    assert fingerprint() != before


def test_ci_runs_the_readme_commands_verbatim():
    readme = (ROOT / "README.md").read_text()
    ci = (ROOT / ".ci" / "run").read_text()
    commands = [
        line.strip()
        for line in readme.splitlines()
        if line.strip().startswith("python3 -m venv .venv && ")
    ][:2]
    assert len(commands) == 2 and "tailbeam reproduce" in commands[0]
    assert "pytest" in commands[1]
    for command in commands:
        assert f"( {command} )" in ci


# -- command line ---------------------------------------------------------------------------------


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"tailbeam {tailbeam.__version__}"


@pytest.mark.parametrize(
    "argv, field",
    [
        (["simulate"], "scene"),
        (["modes", "--fmax", "abc"], "--fmax"),
        (["modes", "--theory", "kirchoff"], "--theory"),
        (["reproduce", "--bogus"], "--bogus"),
    ],
)
def test_argument_errors_are_one_line(argv, field, capsys):
    code, out, err = run_cli(argv, capsys)
    assert code == 2 and err.count("\n") == 1 and field in err and "usage" not in err


def test_quiet_silences_progress(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(RIGID)
    code, out, err = run_cli(["simulate", scene, "--out", tmp_path / "o", "--quiet"], capsys)
    assert code == 0 and err == ""


# -- bad input: one line, exit 2, nothing written, before the work --------------------------------

BAD = {
    "exponent_1e6": (RIGID, "exponent = 1.5 ", "exponent = 1e6 ", "contact.exponent"),
    "damping_1e300": (RIGID, "damping = 300.0 ", "damping = 1e300 ", "contact.damping"),
    "timeseries_too_big": (
        RIGID,
        "sample_rate = 20000.0",
        "sample_rate = 1e9",
        "sample_rate",
    ),
    "too_fast": (
        RIGID,
        "velocity = [0.0, 0.0, -1.0]     # m/s",
        "velocity = [0, 0, -80.0]",
        "balls[1].velocity",
    ),
    "negative_gravity": (RIGID, "duration = 1.0 ", "gravity = -9.8\nduration = 1.0 ", "gravity"),
    "sensor_slash": (MODAL, 'name = "acc_centre"', 'name = "a/b"', "sensors[1].name"),
    "sensor_rate_1e9": (
        MODAL,
        "sample_rate = 51200.0\nbandwidth",
        "sample_rate = 1e9\nbandwidth",
        "sensors[2].sample_rate",
    ),
    "sensor_too_few_samples": (
        MODAL,
        "sample_rate = 51200.0\nbandwidth = 10000.0",
        "sample_rate = 200.0",
        "sensors[2].sample_rate",
    ),
    "sensor_bandwidth_by_index": (
        MODAL,
        "bandwidth = 10000.0",
        "bandwidth = 30000.0",
        "sensors[2].bandwidth",
    ),
    "sensor_resonance_by_index": (
        MODAL,
        "bandwidth = 10000.0",
        "bandwidth = 10000.0\nmounted_resonance = 5000.0",
        "sensors[2].mounted_resonance",
    ),
    "sensor_duplicate": (MODAL, 'name = "acc_edge"', 'name = "acc_centre"', "sensors[2].name"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_scene_is_one_line_and_writes_nothing(case, tmp_path, capsys):
    text, old, new, field = BAD[case]
    assert old in text
    scene = tmp_path / "scene.toml"
    scene.write_text(text.replace(old, new, 1))
    out = tmp_path / "out"
    code, _, err = run_cli(["simulate", scene, "--out", out], capsys)
    one_line_error(code, err, field)
    assert not out.exists()


def test_byte_order_mark_is_accepted(tmp_path, capsys):
    scene = tmp_path / "bom.toml"
    scene.write_bytes(b"\xef\xbb\xbf" + RIGID.encode())
    code, out, err = run_cli(["simulate", scene, "--out", tmp_path / "o", "-q"], capsys)
    assert code == 0, err


def test_invalid_utf8_is_refused(tmp_path, capsys):
    scene = tmp_path / "bad.toml"
    scene.write_bytes(
        RIGID.replace('name = "coal"', 'name = "co\udcffal"').encode("utf-8", "surrogateescape")
    )
    code, _, err = run_cli(["simulate", scene, "--out", tmp_path / "o"], capsys)
    one_line_error(code, err, "bad.toml")
    assert "not UTF-8" in err and "line 19" in err


def test_not_a_mesh_is_one_line(tmp_path, capsys):
    bad = tmp_path / "x.msh"
    bad.write_text("hello\n")
    code, _, err = run_cli(["modes", "--mesh", bad, "--out", tmp_path / "o"], capsys)
    one_line_error(code, err, "--mesh")


# -- output folders -------------------------------------------------------------------------------


def test_out_is_checked_before_the_work(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(RIGID)
    a_file = tmp_path / "afile"
    a_file.write_text("keep me")
    code, _, err = run_cli(["simulate", scene, "--out", a_file], capsys)
    one_line_error(code, err, "--out")
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "thesis.tex").write_text("keep me")
    code, _, err = run_cli(["simulate", scene, "--out", foreign], capsys)
    one_line_error(code, err, "--out")
    assert (foreign / "thesis.tex").read_text() == "keep me"


def test_a_run_replaces_the_folder_whole(tmp_path, capsys):
    """A rigid run into a folder that held a modal run leaves none of the modal files."""
    out = tmp_path / "o"
    out.mkdir()
    (out / "manifest.json").write_text("{}")
    (out / "sensors.csv").write_text("old")
    (out / "sensor_old.png").write_text("old")
    scene = tmp_path / "s.toml"
    scene.write_text(RIGID)
    code, _, err = run_cli(["simulate", scene, "--out", out, "-q"], capsys)
    assert code == 0, err
    names = sorted(p.name for p in out.iterdir())
    assert names == [
        "impacts.csv",
        "impacts.json",
        "manifest.json",
        "particles.csv",
        "timeseries.csv",
    ]
    manifest = json.loads((out / "manifest.json").read_text())
    assert sorted(manifest["files"]) == [n for n in names if n != "manifest.json"]
    assert manifest["tailbeam_version"] == tailbeam.__version__
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".o.")]


# -- gravity is a scene key -----------------------------------------------------------------------


@pytest.mark.parametrize("gravity", [1.62, 9.80665, 24.79])
def test_gravity_key_matches_the_closed_form_fall(gravity, tmp_path, capsys):
    """Impact time of a ball dropped from rest at gap h: sqrt(2 h / g); the apex after the
    first rebound is v_out^2 / (2 g) (tailbeam.physics.hertz.free_fall_apex)."""
    text = RIGID.replace("duration = 1.0 ", f"gravity = {gravity!r}\nduration = 1.0 ")
    text = text.replace("velocity = [0.0, 0.0, -1.0]", "velocity = [0.0, 0.0, 0.0]")
    scene = tmp_path / "g.toml"
    scene.write_text(text)
    out = tmp_path / "o"
    code, _, err = run_cli(["simulate", scene, "--out", out, "-q"], capsys)
    assert code == 0, err
    data = json.loads((out / "impacts.json").read_text())
    assert data["scene"]["gravity"] == gravity
    first = data["impacts"][0]
    gap = 0.005
    assert first["t_start"] == pytest.approx(math.sqrt(2 * gap / gravity), rel=1e-9)
    assert first["v_in"] == pytest.approx(math.sqrt(2 * gravity * gap), rel=1e-9)
    apex = free_fall_apex(first["v_out"], gravity)
    assert first["next_apex_height"] == pytest.approx(apex, rel=1e-9)
