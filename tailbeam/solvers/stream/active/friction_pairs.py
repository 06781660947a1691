"""The friction of a stream's pairs for the active sets: each pair key's row of the compiled
friction table (``compiled.friction``) from the scene's ``FrictionModel``, and the slip speed
that says how a contact ended (``sliding`` or ``sticking``).

Pair keys as the driver's: (i, -1) ball i on the plate (the plate's material), (i, j) two
balls. The contact point is the stream reference's (``compiled.friction``).
"""

import math

import numpy as np

from tailbeam.solvers.stream.active.compiled.friction import F_COLUMNS


class FrictionPairs:
    """Friction rows by pair key.

    Parameters
    ----------
    model : FrictionModel
        The scene's friction (``tailbeam.physics.friction``).
    materials : sequence of str
        Every ball's material name.
    radius : array_like, shape (n,)
        Every ball's radius (m).
    plate_material : str
        The plate's material name.
    """

    def __init__(self, model, materials, radius, plate_material: str):
        self.model = model
        self.materials = list(materials)
        self.radius = np.asarray(radius, dtype=float)
        self.plate_material = plate_material

    def settings(self, key):
        """The ``FrictionSettings`` of pair ``key``."""
        i, j = key
        other = self.plate_material if j < 0 else self.materials[j]
        return self.model.between(self.materials[i], other)

    def row(self, key) -> np.ndarray:
        """The pair's row (F_COLUMNS,): mu_s, mu_d, v_s, v_d, mu_r, share, rolling radius."""
        s = self.settings(key)
        i, j = key
        ri = self.radius[i]
        if j < 0:
            share, rolling_radius = 1.0, ri
        else:
            rj = self.radius[j]
            share, rolling_radius = ri / (ri + rj), ri * rj / (ri + rj)
        row = [s.static, s.dynamic, s.stiction_velocity, s.transition_velocity, s.rolling,
               share, rolling_radius]  # fmt: skip
        return np.array(row, dtype=float).reshape(F_COLUMNS)

    def table(self, keys) -> np.ndarray:
        """(P, F_COLUMNS) rows of ``keys``."""
        return np.array([self.row(k) for k in keys], dtype=float).reshape(-1, F_COLUMNS)

    def end(self, key, xi, vi, wi, xj=None, vj=None, wj=None) -> str:
        """How contact ``key`` ends tangentially: ``sticking`` if its slip speed (``slip``)
        is below the stiction velocity, else ``sliding``."""
        speed = self.slip(key, xi, vi, wi, xj, vj, wj)
        return "sticking" if speed < self.settings(key).stiction_velocity else "sliding"

    def slip(self, key, xi, vi, wi, xj=None, vj=None, wj=None) -> float:
        """Slip speed (m/s) at the contact point of pair ``key`` from the balls' centres,
        velocities and angular velocities (3,) (j's None on the plate)."""
        share = self.row(key)[5]
        if xj is None:
            xj, vj, wj = np.array([xi[0], xi[1], 0.0]), np.zeros(3), np.zeros(3)
        d = xi - xj
        dist = math.sqrt(float(d @ d))
        n = d / dist
        u = vi + np.cross(wi, -dist * share * n) - vj - np.cross(wj, dist * (1.0 - share) * n)
        slip = u - (u @ n) * n
        return float(math.sqrt(slip @ slip))
