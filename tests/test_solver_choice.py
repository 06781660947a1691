"""The solver as a swappable part: ``tailbeam.simulate(scene, solver=...)`` and
``tailbeam simulate --solver``.

Independent truth: three separate solvers on the same balls. The rigid single-ball solver
(event-located, exact to ~1e-11), the fast stream solver (active sets, numba) and the stream
reference (scipy DOP853, every pair watched) share no integration code, so the same impacts
from all three check each of them. Tolerance 1e-7 relative: the stream solvers run at
rtol 1e-10 and their error grows over a ball's successive bounces (measured here, worst over
the 9 impacts and 7 fields: 1.8e-9 stream, 2.8e-9 stream reference; 5e-9 after eight
bounces each of two balls in ``examples/two_balls_rigid.toml``).
"""

import math

import pytest

import tailbeam
from tailbeam.cli import main
from tailbeam.errors import InputError
from tailbeam.io.scene_dump import dumps_scene
from tailbeam.physics.bodies import Ball
from tailbeam.physics.materials import COAL, SANDSTONE
from tailbeam.scene import ModalPlateSettings, Scene
from tailbeam.simulation import CHOICES, choose_solver

FIELDS = ("t_start", "t_end", "v_in", "v_out", "peak_force", "t_peak", "max_penetration")
TOL = 1e-7


def two_balls(inclination=0.0, plate_model="rigid"):
    a = Ball("coal", COAL, 0.03, (-0.15, 0.0, 0.04), (0.0, 0.0, 0.0))
    b = Ball("rock", SANDSTONE, 0.025, (0.15, 0.1, 0.03), (0.0, 0.0, 0.0))
    modal = ModalPlateSettings() if plate_model == "modal" else None
    return Scene(
        (a, b), duration=0.3, inclination=inclination, plate_model=plate_model, modal=modal
    )


@pytest.fixture(scope="module")
def runs():
    scene = two_balls()
    return {s: tailbeam.simulate(scene, solver=s, progress=False) for s in CHOICES}


def by_ball(result) -> dict:
    table = result.impacts_table()
    out = {}
    for k in range(len(table["ball"])):
        out.setdefault(table["ball"][k], []).append({f: float(table[f][k]) for f in FIELDS})
    return out


def test_auto_runs_the_single_ball_solver_where_it_can(runs):
    assert runs["auto"].info["solver_choice"] == "single-ball"
    assert runs["auto"].info["solver"].startswith("tailbeam DOP853 (numba)")  # its own words
    assert type(runs["auto"]) is type(runs["single-ball"])
    assert choose_solver(two_balls(inclination=10.0)).name == "stream"


@pytest.mark.parametrize("solver", ["stream", "stream-reference"])
def test_three_solvers_give_the_same_impacts(runs, solver):
    exact, other = by_ball(runs["single-ball"]), by_ball(runs[solver])
    assert runs[solver].info["solver_choice"] == solver
    assert sorted(exact) == sorted(other) == ["coal", "rock"]
    for name in exact:
        assert len(exact[name]) == len(other[name]) >= 3  # several bounces each
        for a, b in zip(exact[name], other[name], strict=True):
            for f in FIELDS:
                assert math.isclose(a[f], b[f], rel_tol=TOL), (name, f, a[f], b[f])


def test_a_solver_that_cannot_run_the_scene_is_refused_before_any_work():
    with pytest.raises(InputError, match=r"^solver: must be one of auto, single-ball"):
        tailbeam.simulate(two_balls(), solver="fast")
    with pytest.raises(InputError, match=r"^solver: 'single-ball' cannot run this scene "
                                         r"\(plate inclined 10 degrees\)"):  # fmt: skip
        tailbeam.simulate(two_balls(inclination=10.0), solver="single-ball")
    with pytest.raises(InputError, match=r"^solver: 'stream-reference' runs on the rigid"):
        tailbeam.simulate(two_balls(plate_model="modal"), solver="stream-reference")


def test_cli_solver_option(tmp_path, capsys):
    scene = tmp_path / "two.toml"
    scene.write_text(dumps_scene(two_balls(inclination=10.0)))
    out = tmp_path / "out"
    assert main(["simulate", str(scene), "--out", str(out), "--solver", "single-ball"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("tailbeam simulate: error: --solver: 'single-ball' cannot run")
    assert len(err.splitlines()) == 1 and not out.exists()
    assert main(["simulate", str(scene), "--out", str(out), "--solver", "stream-reference"]) == 0
    assert (out / "impacts.csv").read_text().count("\n") > 2
