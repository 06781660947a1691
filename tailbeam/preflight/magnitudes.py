"""Plausible magnitudes: values a unit slip (millimetres for metres, mm/s for m/s, g/cm^3 for
kg/m^3, GPa for Pa) makes 1000 times too large or too small are refused before any work,
with the unit the value probably meant.

Every bound is far outside what a coal or gangue lump on a tail beam can be, and far inside
what a slip gives (docs/scene-files.md, "Plausible ranges"):

- a ball (or a stream's largest radius) larger than half the plate's smaller side: it could
  not lie on the plate; 30 (mm) read as metres is a 30 m ball;
- a speed above ``MAX_SPEED`` m/s: free fall from 100 m gives 44 m/s; mm/s give 1000x;
- a height (ball centre or stream release gap) above ``MAX_HEIGHT_PLATES`` times the plate's
  larger side: a caving height is a few metres over a ~1 m beam;
- a plate thinner than ``MIN_THICKNESS`` or thicker than its smaller side, or a side longer
  than ``MAX_PLATE_SIDE`` m;
- a density outside ``DENSITY_RANGE`` kg/m^3 (no solid is lighter than cork or denser than
  osmium, 22 590; every solid in g/cm^3 is below 23); a Young's modulus outside
  ``MODULUS_RANGE`` Pa (soft foam to diamond; GPa or MPa written as Pa falls below);
- gravity above ``MAX_GRAVITY`` m/s^2 (9806.65 is g in mm/s^2).
"""

import math

from tailbeam.errors import InputError

MAX_SPEED = 100.0  # m/s
MAX_HEIGHT_PLATES = 10.0  # x the plate's larger side
MIN_THICKNESS = 1e-6  # m
MAX_PLATE_SIDE = 100.0  # m
DENSITY_RANGE = (100.0, 25_000.0)  # kg/m^3
MODULUS_RANGE = (1e5, 1.2e12)  # Pa
MAX_GRAVITY = 100.0  # m/s^2


def _mm(value: float) -> str:
    """``value`` read as millimetres, written in metres: '30 mm = 0.03'."""
    return f"{value:g} mm = {value / 1000.0:g}"


def check_radius(field: str, radius: float, plate) -> None:
    """A radius (m) no larger than half the plate's smaller side."""
    limit = 0.5 * min(plate.size_x, plate.size_y)
    if radius > limit:
        raise InputError(
            field,
            f"{radius:g} m is larger than the plate ({plate.size_x:g} x {plate.size_y:g} m; "
            f"a radius must be <= {limit:g} m); radii are in metres ({_mm(radius)})",
        )


def check_speed(field: str, velocity) -> None:
    """A velocity (m/s, a vector or a spread) no faster than MAX_SPEED."""
    speed = math.sqrt(sum(v * v for v in velocity))
    if speed > MAX_SPEED:
        raise InputError(
            field,
            f"{speed:g} m/s is faster than rock falls onto a tail beam (limit {MAX_SPEED:g} m/s); "
            f"velocities are in m/s ({speed:g} mm/s = {speed / 1000.0:g})",
        )


def check_height(field: str, height: float, plate) -> None:
    """A height above the plate (m) within MAX_HEIGHT_PLATES x its larger side."""
    limit = MAX_HEIGHT_PLATES * max(plate.size_x, plate.size_y)
    if height > limit:
        raise InputError(
            field,
            f"{height:g} m above the plate is more than {MAX_HEIGHT_PLATES:g} x its size "
            f"(limit {limit:g} m); positions are in metres ({_mm(height)})",
        )


def check_plate(plate) -> None:
    """Sides within MAX_PLATE_SIDE, thickness between MIN_THICKNESS and the smaller side."""
    for i, side in enumerate((plate.size_x, plate.size_y)):
        if side > MAX_PLATE_SIDE:
            raise InputError(
                f"plate.size[{i}]",
                f"{side:g} m is longer than a tail beam can be (limit {MAX_PLATE_SIDE:g} m); "
                f"sizes are in metres ({_mm(side)})",
            )
    h, side = plate.thickness, min(plate.size_x, plate.size_y)
    if h < MIN_THICKNESS:
        raise InputError(
            "plate.size[2]", f"a thickness of {h:g} m is thinner than {MIN_THICKNESS:g} m (1 um)"
        )
    if h > side:
        raise InputError(
            "plate.size[2]",
            f"a thickness of {h:g} m is more than the plate's side ({side:g} m); sizes are in "
            f"metres ({_mm(h)})",
        )


def check_material(material, field: str) -> None:
    """Density and Young's modulus within DENSITY_RANGE and MODULUS_RANGE."""
    lo, hi = DENSITY_RANGE
    if not lo <= material.density <= hi:
        raise InputError(
            f"{field}.density",
            f"{material.density:g} kg/m^3 is outside [{lo:g}, {hi:g}] (cork to osmium); "
            f"densities are in kg/m^3 ({material.density:g} g/cm^3 = "
            f"{material.density * 1000.0:g})",
        )
    lo, hi = MODULUS_RANGE
    if not lo <= material.youngs_modulus <= hi:
        e = material.youngs_modulus
        raise InputError(
            f"{field}.youngs_modulus",
            f"{e:g} Pa is outside [{lo:g}, {hi:g}] (soft foam to diamond); the modulus is in "
            f"Pa ({e:g} GPa = {e * 1e9:g}, {e:g} MPa = {e * 1e6:g})",
        )


def check_gravity(gravity: float) -> None:
    """g no larger than MAX_GRAVITY."""
    if gravity > MAX_GRAVITY:
        raise InputError(
            "gravity",
            f"{gravity:g} m/s^2 is more than {MAX_GRAVITY:g} (Earth: 9.80665); gravity is in "
            f"m/s^2 ({gravity:g} mm/s^2 = {gravity / 1000.0:g})",
        )


def check_magnitudes(scene) -> None:
    """Every rule above for a whole ``scene`` (balls, streams, plate, materials, gravity)."""
    check_gravity(scene.gravity)
    check_plate(scene.plate)
    check_material(scene.plate.material, f"materials.{scene.plate.material.name}")
    for i, ball in enumerate(scene.balls, start=1):
        check_material(ball.material, f"materials.{ball.material.name}")
        check_radius(f"balls[{i}].radius", ball.radius, scene.plate)
        check_height(f"balls[{i}].position", ball.position[2], scene.plate)
        check_speed(f"balls[{i}].velocity", ball.velocity)
    for s in scene.streams:
        check_stream(s, scene.plate)


def check_stream(s, plate) -> None:
    """The rules for one stream's settings (``tailbeam.streams.generator.StreamSettings``)."""
    for material in (s.coal_material, s.gangue_material):
        check_material(material, f"materials.{material.name}")
    check_radius(f"{s.field}.radius", s.radius[1], plate)
    check_height(f"{s.field}.height", s.height[1], plate)
    check_speed(f"{s.field}.velocity", s.velocity)
    check_speed(f"{s.field}.velocity_spread", (s.velocity_spread,))
