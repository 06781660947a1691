"""The inclined tail beam: a rigid rectangular plate tilted about its y axis.

Plate frame: x points downhill along the plate, y across it, z along the plate's outward
normal; the top surface is z = 0 and the plate spans x in [-a/2, a/2], y in [-b/2, b/2].
With the inclination theta (degrees, 0 = horizontal) gravity in this frame is

    g_vec = g (sin theta, 0, -cos theta)        (m/s^2).

A ball whose centre passes beyond an edge leaves the plate (it falls into the conveyor):
the edges are named ``x+`` (the lower, downhill edge), ``x-`` (the upper edge), ``y+``, ``y-``.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import InputError, require_nonnegative, require_real
from tailbeam.physics.bodies import STANDARD_GRAVITY, Plate

EDGES = ("x-", "x+", "y-", "y+")


@dataclass(frozen=True)
class InclinedPlate:
    """A rigid plate at ``inclination`` degrees under ``gravity`` m/s^2 (scene keys to come:
    ``plate.inclination``, ``gravity``)."""

    plate: Plate = field(default_factory=Plate)
    inclination: float = 0.0
    gravity: float = STANDARD_GRAVITY

    def __post_init__(self):
        theta = require_real("plate.inclination", self.inclination)
        if not 0.0 <= theta < 90.0:
            raise InputError("plate.inclination", f"must lie in [0, 90) degrees, got {theta!r}")
        object.__setattr__(self, "inclination", theta)
        object.__setattr__(self, "gravity", require_nonnegative("gravity", self.gravity))

    @property
    def gravity_vector(self) -> np.ndarray:
        """Gravity in the plate frame, m/s^2: g (sin theta, 0, -cos theta)."""
        t = math.radians(self.inclination)
        return self.gravity * np.array([math.sin(t), 0.0, -math.cos(t)])

    @property
    def half_sizes(self) -> tuple[float, float]:
        """(a/2, b/2) in m."""
        return 0.5 * self.plate.size_x, 0.5 * self.plate.size_y

    def edge_distances(self, xy) -> np.ndarray:
        """Signed distances in m of centres ``xy`` (..., 2) inside each edge, in ``EDGES``
        order (x + a/2, a/2 - x, y + b/2, b/2 - y): all >= 0 while over the plate."""
        xy = np.asarray(xy, dtype=float)
        ha, hb = self.half_sizes
        x, y = xy[..., 0], xy[..., 1]
        return np.stack([x + ha, ha - x, y + hb, hb - y], axis=-1)

    def potential_energy(self, masses, positions) -> float:
        """Gravitational potential energy in J, -sum m g_vec . x (zero at the origin)."""
        return float(-np.sum(np.asarray(masses) * (np.asarray(positions) @ self.gravity_vector)))
