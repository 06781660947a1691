"""Bodies and materials: derived quantities against hand values, bad input names its field."""

import math

import pytest

from tailbeam import CARBON_STEEL, COAL, Ball, InputError, Material, Plate, get_material
from tailbeam.physics.bodies import check_ball_above_plate


def test_ball_mass_and_plate_rigidity_by_hand():
    ball = Ball("a", COAL, 0.03, (0.0, 0.0, 0.1), (0.0, 0.0, -1.0))
    assert ball.mass == pytest.approx(1380.0 * 4.0 / 3.0 * math.pi * 0.03**3, rel=1e-15)
    assert ball.kinetic_energy == pytest.approx(0.5 * ball.mass, rel=1e-15)
    assert ball.gap == pytest.approx(0.07, rel=1e-15)
    plate = Plate()
    assert plate.bending_stiffness == pytest.approx(2.06e11 * 1e-6 / (12 * (1 - 0.28**2)))
    assert plate.mass_per_area == pytest.approx(78.5)
    assert plate.contains(0.3, -0.3) and not plate.contains(0.31, 0.0)


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: Ball("a", COAL, -0.03, (0, 0, 1)), "balls[a].radius"),
        (lambda: Ball("a", COAL, 0.0, (0, 0, 1)), "balls[a].radius"),
        (lambda: Ball("a", COAL, 0.03, (0, float("nan"), 1)), "balls[a].position[1]"),
        (lambda: Ball("a", COAL, 0.03, (0, 1)), "balls[a].position"),
        (lambda: Ball("a", COAL, 0.03, (0, 0, 1), (0, 0, "fast")), "balls[a].velocity[2]"),
        (lambda: Plate(thickness=-0.01), "plate.thickness"),
        (lambda: Material("m", 1000.0, 1e9, 0.5), "materials.m.poisson_ratio"),
        (lambda: Material("m", -1.0, 1e9, 0.3), "materials.m.density"),
        (lambda: get_material("granite"), "material"),
    ],
)
def test_bad_input_names_field(make, field):
    with pytest.raises(InputError) as err:
        make()
    assert err.value.field == field
    assert field in str(err.value) and "\n" not in str(err.value)


def test_ball_inside_plate_is_refused_and_touching_is_allowed():
    check_ball_above_plate(Ball("a", COAL, 0.03, (0, 0, 0.03)))
    with pytest.raises(InputError, match="inside the plate"):
        check_ball_above_plate(Ball("a", COAL, 0.03, (0, 0, 0.0299)))


def test_user_material_overrides_lookup():
    granite = Material("granite", 2700.0, 5e10, 0.25)
    assert get_material("granite", {"granite": granite}) is granite
    assert get_material("carbon_steel") is CARBON_STEEL
