"""Scene files: valid scenes round-trip; every class of bad input names its field and rule."""

import math
from pathlib import Path

import pytest

from tailbeam.errors import InputError
from tailbeam.io.scene_dump import dumps_scene, scene_to_dict
from tailbeam.io.scene_file import load_scene, loads_scene
from tailbeam.physics.materials import COAL
from tailbeam.scene import DEFAULT_DAMPING, DEFAULT_PENETRATION, ModalPlateSettings

EXAMPLES = sorted((Path(__file__).parents[1] / "examples").glob("*.toml"))

BASE = """
duration = 1.0
[[balls]]
name = "a"
material = "coal"
radius = 0.03
position = [0.0, 0.0, 0.05]
velocity = [0.0, 0.0, -1.0]
"""


def test_minimal_scene_takes_defaults():
    scene = loads_scene(BASE)
    assert scene.plate_model == "rigid"
    assert scene.contact.damping == DEFAULT_DAMPING
    assert scene.contact.penetration == DEFAULT_PENETRATION
    assert scene.contact.clamp is True
    (ball,) = scene.balls
    assert ball.material == COAL and ball.radius == 0.03 and ball.velocity == (0.0, 0.0, -1.0)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_examples_round_trip(path):
    scene = load_scene(path)
    again = loads_scene(dumps_scene(scene))
    assert again == scene
    assert scene_to_dict(again) == scene_to_dict(scene)


def test_modal_keys_parsed():
    text = BASE.replace(
        "duration = 1.0",
        "duration = 1.0\n[plate]\nmodel = 'modal'\nboundary = 'cscf'\ntheory = 'mindlin'\n"
        "rayleigh = [1.0, 1e-6]\nfmax = 3000\nmesh_divisions = 12\nresidual_flexibility = false\n"
        "coupling = 'one-way'\n[[sensors]]\nname = 's'\nposition = [0.1, 0.1]\nbandwidth = 5000",
    )
    scene = loads_scene(text)
    assert scene.modal == ModalPlateSettings(
        boundary="CSCF",
        theory="mindlin",
        rayleigh=(1.0, 1e-6),
        fmax_hz=3000.0,
        mesh_divisions=12,
        residual_flexibility=False,
        coupling="one-way",
        tail_modes=32,  # the coupled solver's default, set by the scene
    )
    assert scene.sensors[0].bandwidth_hz == 5000.0
    assert loads_scene(dumps_scene(scene)) == scene


def test_full_precision_round_trip():
    scene = loads_scene(BASE.replace("-1.0]", "-1.3424507115881306]"))
    assert loads_scene(dumps_scene(scene)).balls[0].velocity[2] == -1.3424507115881306


def _error(text) -> InputError:
    with pytest.raises(InputError) as info:
        loads_scene(text, source="bad.toml")
    return info.value


@pytest.mark.parametrize(
    "old, new, field, rule_part",
    [
        ('material = "coal"', 'material = "granite"', "balls[1].material", "unknown material"),
        ("radius = 0.03", "radius = -0.03", "balls[1].radius", "> 0"),
        ("radius = 0.03", "radius = 0", "balls[1].radius", "> 0"),
        ("radius = 0.03", "radius = nan", "balls[1].radius", "finite"),
        ("radius = 0.03", 'radius = "0.03"', "balls[1].radius", "number"),
        ("0.0, 0.05]", "0.0, inf]", "balls[1].position[2]", "finite"),
        ("0.0, 0.05]", "0.0, 0.01]", "balls[1].position", "inside the plate"),
        ("[0.0, 0.0, 0.05]", "[0.5, 0.0, 0.05]", "balls[1].position", "over the plate"),
        ("[0.0, 0.0, 0.05]", "[0.0, 0.05]", "balls[1].position", "3 numbers"),
        ("radius = 0.03", "radus = 0.03", "balls[1].radus", "did you mean 'radius'"),
        ("radius = 0.03", "", "balls[1].radius", "required"),
        ("duration = 1.0", "duraton = 1.0", "duraton", "did you mean 'duration'"),
        ("duration = 1.0", "", "duration", "required"),
        ("duration = 1.0", "duration = 1.0\n[contact]\ndamping = -5", "contact.damping", ">= 0"),
        ("duration = 1.0", "duration = 1.0\n[contact]\ndampng = 5", "contact.dampng", "damping"),
        ("duration = 1.0", "duration = 1.0\n[contact]\nclamp = 1", "contact.clamp", "true or"),
        ("duration = 1.0", "duration = 1.0\n[plate]\nmodel = 'soft'", "plate.model", "rigid"),
        ("duration = 1.0", "duration = 1.0\n[plate]\nboundary = 'SSSS'", "plate.boundary", "modal"),
        ("duration = 1.0", "duration = 1.0\n[plate]\nsize = [0.6, 0.6]", "plate.size", "3"),
        (
            "duration = 1.0",
            "duration = 1.0\n[plate]\nmaterial = 'oak'",
            "plate.material",
            "unknown",
        ),
        ("duration = 1.0", "duration = -1.0", "duration", "> 0"),
        ("duration = 1.0", "duration = 1.0\nsample_rate = 0", "sample_rate", "> 0"),
        (
            "duration = 1.0",
            "duration = 1.0\n[materials.x]\ndensity = 1.0\nyoungs_modulus = 1e9",
            "materials.x.poisson_ratio",
            "required",
        ),
        (
            "duration = 1.0",
            "duration = 1.0\n[materials.x]\ndensity = 1.0\nyoungs_modulus = 1e9\n"
            "poisson_ratio = 0.7",
            "materials.x.poisson_ratio",
            "(-1, 0.5)",
        ),
        (
            "duration = 1.0",
            "duration = 1.0\n[[sensors]]\nname = 's'\nposition = [0, 0]",
            "sensors",
            "modal",
        ),
    ],
)
def test_bad_input_names_field_and_rule(old, new, field, rule_part):
    assert old in BASE
    err = _error(BASE.replace(old, new, 1))
    assert err.field == field
    assert rule_part in err.rule
    assert "\n" not in str(err)


def test_balls_must_be_tables():
    err = _error("duration = 1.0\nballs = 3\n")
    assert err.field == "balls" and "array of tables" in err.rule
    assert _error("duration = 1.0\nballs = []\n").field == "balls"


MODAL = BASE.replace("duration = 1.0", "duration = 1.0\n[plate]\nmodel = 'modal'")


def test_balls_whose_paths_touch():
    """Balls that may touch go to the stream solver, on the rigid plate and on the modal
    plate."""
    second = BASE.split("duration = 1.0")[1].replace('name = "a"', 'name = "b"')
    # Directly above the first ball: they would collide.
    above = second.replace("0.0, 0.0, 0.05", "0.0, 0.0, 0.2")
    assert loads_scene(MODAL + above).needs_stream_solver
    assert loads_scene(BASE + above).needs_stream_solver
    # 0.1 m apart but moving towards each other at 0.1 m/s: within 2 R = 0.06 m at t = 0.4 s.
    moving = second.replace("[0.0, 0.0, 0.05]", "[0.1, 0.0, 0.05]").replace(
        "[0.0, 0.0, -1.0]", "[-0.1, 0.0, -1.0]"
    )
    assert loads_scene(MODAL + moving).needs_stream_solver
    assert loads_scene(BASE + moving).first_ball_contact() == (1, 0, pytest.approx(0.4))
    # Side by side, 0.1 m apart, vertical motion only: valid, and the single-ball solver's.
    apart = loads_scene(BASE + second.replace("0.0, 0.0, 0.05", "0.1, 0.0, 0.05"))
    assert len(apart.balls) == 2 and not apart.needs_stream_solver


def test_duplicate_ball_names():
    text = BASE + BASE.split("duration = 1.0")[1].replace("0.0, 0.0, 0.05", "0.1, 0.0, 0.05")
    assert _error(text).field == "balls"


def test_unparseable_toml_reports_line():
    err = _error(BASE.replace("radius = 0.03", "radius = = 0.03"))
    assert err.field == "bad.toml"
    assert "line 6" in err.rule


def test_sensor_off_plate():
    text = BASE.replace("duration = 1.0", "duration = 1.0\n[plate]\nmodel = 'modal'") + (
        "[[sensors]]\nname = 's'\nposition = [0.4, 0.0]\n"
    )
    err = _error(text)
    assert err.field == "sensors[1].position"


def test_defined_material_used_by_ball():
    text = BASE.replace('material = "coal"', 'material = "shale"') + (
        "[materials.shale]\ndensity = 2600.0\nyoungs_modulus = 2e10\npoisson_ratio = 0.2\n"
    )
    scene = loads_scene(text)
    assert scene.balls[0].material.density == 2600.0
    assert math.isclose(scene.balls[0].mass, 2600.0 * 4 / 3 * math.pi * 0.03**3)
    assert "shale" in scene_to_dict(scene)["materials"]
