"""Friction in scene files and in the solver choice: the keys, their defaults and errors, the
refusals of the solvers without friction, and spins passed through frictionless runs."""

import csv
import json

import numpy as np
import pytest

import tailbeam
from tailbeam.cli.main import main
from tailbeam.errors import InputError
from tailbeam.io.scene_dump import dumps_scene
from tailbeam.io.scene_file import loads_scene
from tailbeam.physics.friction import FrictionSettings
from tailbeam.simulation import choose_solver

BASE = """
duration = 0.05
[[balls]]
name = "a"
material = "coal"
radius = 0.03
position = [0.0, 0.0, 0.035]
velocity = [0.5, 0.0, -1.0]
angular_velocity = [1.0, -2.0, 3.0]
"""
FRICTION = """
[contact.friction]
static = 0.5
dynamic = 0.4
"""


def test_friction_keys_defaults_and_pairs():
    scene = loads_scene(BASE + FRICTION)
    assert scene.friction.default == FrictionSettings(0.5, 0.4, 0.1, 1.0, 0.0)
    assert scene.balls[0].angular_velocity == (1.0, -2.0, 3.0)
    text = BASE + FRICTION + "rolling = 0.1\nstiction_velocity = 1e-3\n"
    text += "transition_velocity = 2e-3\n[[contact.friction.pairs]]\n"
    text += 'materials = ["coal", "carbon_steel"]\ndynamic = 0.3\n'
    scene = loads_scene(text)
    pair = scene.friction.between("carbon_steel", "coal")
    assert (pair.static, pair.dynamic, pair.rolling, pair.stiction_velocity) == (
        0.5, 0.3, 0.1, 1e-3,
    )  # fmt: skip
    assert scene.friction.between("coal", "coal").dynamic == 0.4
    assert loads_scene(dumps_scene(scene)) == scene
    assert loads_scene(BASE).friction is None  # absent: frictionless


@pytest.mark.parametrize(
    "extra, field",
    [
        ("static = 0.5\n", "contact.friction.dynamic"),  # required
        ("static = 0.5\ndynamic = 0.6\n", "contact.friction.dynamic"),
        ("static = 0.5\ndynamic = 0.4\nrolling = -1\n", "contact.friction.rolling"),
        ("static = 0.5\ndynamic = 0.4\nstiction = 1\n", "contact.friction.stiction"),
        (
            'static = 0.5\ndynamic = 0.4\n[[contact.friction.pairs]]\nmaterials = ["coal"]\n',
            "contact.friction.pairs[1].materials",
        ),
        (
            'static = 0.5\ndynamic = 0.4\n[[contact.friction.pairs]]\nmaterials = ["coal", '
            '"unobtainium"]\n',
            "contact.friction.pairs[1].materials",
        ),
        (
            'static = 0.5\ndynamic = 0.4\n[[contact.friction.pairs]]\nmaterials = ["coal", '
            '"coal"]\nstatic = 0.1\n',
            "contact.friction.pairs[1].dynamic",
        ),
    ],
)
def test_bad_friction_values_name_their_key(extra, field):
    with pytest.raises(InputError) as err:
        loads_scene(BASE + "[contact.friction]\n" + extra)
    assert err.value.field == field


def test_bad_value_on_the_command_line_is_one_line_and_exit_2(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text(BASE + "[contact.friction]\nstatic = 0.5\ndynamic = 'high'\n")
    assert main(["simulate", str(path), "--out", str(tmp_path / "o"), "-q"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "contact.friction.dynamic" in err
    assert not (tmp_path / "o").exists()


def test_single_ball_refuses_friction_and_auto_picks_the_fast_stream_solver():
    scene = loads_scene(BASE + FRICTION)
    with pytest.raises(InputError) as err:
        choose_solver(scene, "single-ball", "--solver")
    assert "contact.friction" in str(err.value) and "stream-reference" in str(err.value)
    assert choose_solver(scene, "stream", "--solver").name == "stream"
    assert choose_solver(scene).name == "stream"
    modal = loads_scene(BASE + FRICTION + "[plate]\nmodel = 'modal'\n")
    assert choose_solver(modal).name == "stream"
    assert choose_solver(modal, "stream", "--solver").name == "stream"
    with pytest.raises(InputError) as err:
        choose_solver(modal, "single-ball", "--solver")
    assert err.value.field == "--solver" and "contact.friction" in str(err.value)
    with pytest.raises(InputError) as err:
        choose_solver(modal, "stream-reference", "--solver")
    assert err.value.field == "--solver" and "rigid" in str(err.value)
    crowd = (
        BASE
        + FRICTION
        + "".join(
            f'[[balls]]\nname = "b{k}"\nmaterial = "coal"\nradius = 0.01\n'
            f"position = [{-0.25 + 0.025 * k}, 0.2, 0.05]\n"
            for k in range(20)
        )
    )
    assert choose_solver(loads_scene(crowd)).name == "stream"  # (no 20-body limit)


def test_spins_pass_through_a_frictionless_run_to_particles_csv(tmp_path):
    """Every solver's particles.csv writes the particles' spins (``Result.particles_table``)
    unless the solver followed them: frictionless, they are the scene's."""
    path = tmp_path / "s.toml"
    path.write_text(BASE)
    assert loads_scene(BASE).particles[0].angular_velocity == (1.0, -2.0, 3.0)
    argv = ["simulate", str(path), "--out", str(tmp_path / "o"), "--solver", "stream-reference"]
    assert main([*argv, "-q"]) == 0
    (row,) = csv.DictReader(open(tmp_path / "o" / "particles.csv"))
    assert [float(row[c]) for c in ("wx", "wy", "wz")] == [1.0, -2.0, 3.0]
    impacts = list(csv.DictReader(open(tmp_path / "o" / "impacts.csv")))
    assert {r["tangential_end"] for r in impacts} == {"frictionless"}
    assert {float(r["tangential_impulse"]) for r in impacts} == {0.0}
    units = json.loads((tmp_path / "o" / "manifest.json").read_text())
    text = json.dumps(units)
    assert '"wx": "rad/s"' in text and '"tangential_impulse": "N s"' in text


@pytest.mark.parametrize("solver", ["stream-reference", "auto"])
def test_the_friction_solvers_run_a_friction_scene_and_write_the_spin(tmp_path, solver):
    scene = loads_scene(BASE + FRICTION)
    result = tailbeam.simulate(scene, solver=solver, progress=False)
    assert result.info["solver_choice"] == ("stream" if solver == "auto" else solver)
    table = result.impacts_table()
    assert table["tangential_impulse"][0] > 0.0
    assert table["tangential_end"][0] in ("sliding", "sticking")
    spin = result.particles_table()
    assert (spin["wx"][0], spin["wy"][0], spin["wz"][0]) != (1.0, -2.0, 3.0)


STREAM = """
duration = 0.5
[[streams]]
name = "s"
rate = 400.0
stop = 0.5
gangue_fraction = 0.3
radius = [0.01, 0.02]
area = [[-0.25, 0.25], [-0.25, 0.25]]
height = [0.02, 0.3]
seed = 5
"""


def test_a_stream_spread_spins_its_particles_and_changes_nothing_else():
    """angular_velocity_spread: normal spins of that standard deviation (sample standard
    deviation of ~600 draws within 25 %, beyond 6 of its standard errors), drawn from a
    generator of their own: every other quantity of every particle is unchanged."""
    plain = loads_scene(STREAM).particles
    spun = loads_scene(STREAM + "angular_velocity_spread = 20.0\n").particles
    assert all(p.angular_velocity == (0.0, 0.0, 0.0) for p in plain)
    w = np.array([p.angular_velocity for p in spun])
    assert w.size > 450 and abs(np.std(w) / 20.0 - 1.0) < 0.25 and abs(np.mean(w)) < 6 * 20 / 21
    strip = [(p.name, p.t_release, p.radius, p.position, p.velocity, p.label) for p in plain]
    assert strip == [(p.name, p.t_release, p.radius, p.position, p.velocity, p.label) for p in spun]
    scene = loads_scene(STREAM + "angular_velocity_spread = 20.0\n")
    assert loads_scene(dumps_scene(scene)) == scene
