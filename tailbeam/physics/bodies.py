"""The bodies of a scene: balls (coal or gangue particles) and the plate (the tail beam).

Coordinates: the plate's top surface is z = 0 and its mid-surface is z = -h/2; the plate spans
x in [-a/2, a/2], y in [-b/2, b/2] (centred on the origin). z points up, gravity is -z.
"""

import math
from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError, require_positive, require_vector
from tailbeam.physics.materials import CARBON_STEEL, Material

STANDARD_GRAVITY = 9.80665  # m/s^2


@dataclass(frozen=True)
class Ball:
    """A homogeneous elastic sphere.

    radius in m, position of the centre [x, y, z] in m, velocity [vx, vy, vz] in m/s,
    angular_velocity [wx, wy, wz] in rad/s (moment of inertia 2/5 m r^2, ``inertia``).
    """

    name: str
    material: Material
    radius: float
    position: tuple[float, float, float]
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    angular_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self):
        field = f"balls[{self.name}]"
        if not isinstance(self.material, Material):
            raise InputError(f"{field}.material", "must be a Material")
        object.__setattr__(self, "radius", require_positive(f"{field}.radius", self.radius))
        object.__setattr__(self, "position", require_vector(f"{field}.position", self.position, 3))
        object.__setattr__(self, "velocity", require_vector(f"{field}.velocity", self.velocity, 3))
        spin = require_vector(f"{field}.angular_velocity", self.angular_velocity, 3)
        object.__setattr__(self, "angular_velocity", spin)

    @property
    def mass(self) -> float:
        """kg"""
        return self.material.density * 4.0 / 3.0 * math.pi * self.radius**3

    @property
    def inertia(self) -> float:
        """Moment of inertia of the homogeneous sphere, 2/5 m r^2 (kg m^2)."""
        return 0.4 * self.mass * self.radius**2

    @property
    def kinetic_energy(self) -> float:
        """J, at the initial velocity"""
        return 0.5 * self.mass * float(np.dot(self.velocity, self.velocity))

    @property
    def gap(self) -> float:
        """Initial height of the ball's lowest point above the plate's top surface, m."""
        return self.position[2] - self.radius


@dataclass(frozen=True)
class Plate:
    """A rectangular plate: size_x a, size_y b, thickness h in m; top surface at z = 0."""

    material: Material = CARBON_STEEL
    size_x: float = 0.6
    size_y: float = 0.6
    thickness: float = 0.01

    def __post_init__(self):
        if not isinstance(self.material, Material):
            raise InputError("plate.material", "must be a Material")
        for name in ("size_x", "size_y", "thickness"):
            object.__setattr__(self, name, require_positive(f"plate.{name}", getattr(self, name)))

    @property
    def bending_stiffness(self) -> float:
        """Kirchhoff flexural rigidity D = E h^3 / (12 (1 - nu^2)) in N m."""
        m = self.material
        return m.youngs_modulus * self.thickness**3 / (12.0 * (1.0 - m.poisson_ratio**2))

    @property
    def mass_per_area(self) -> float:
        """rho h in kg/m^2"""
        return self.material.density * self.thickness

    def contains(self, x: float, y: float) -> bool:
        """Whether (x, y) lies over the plate (edges included)."""
        return abs(x) <= 0.5 * self.size_x and abs(y) <= 0.5 * self.size_y


def check_ball_above_plate(ball: Ball, plate: Plate | None = None) -> None:
    """A ball must start clear of (or just touching) the plate's top surface."""
    if ball.gap < 0.0:
        raise InputError(
            f"balls[{ball.name}].position",
            f"the ball starts inside the plate: centre height z = {ball.position[2]!r} m is below "
            f"its radius {ball.radius!r} m (the plate's top surface is z = 0)",
        )
