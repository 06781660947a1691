"""The friction of a stream's pairs for the active sets: each pair key's row of the compiled
friction table (``compiled.friction``) from the scene's ``FrictionModel``, and the slip speed
that says how a contact ended (``sliding`` or ``sticking``).

Pair keys as the driver's: (i, -1) ball i on the plate (the plate's material), (i, j) two
balls. The contact point is the stream reference's (``compiled.friction``). On the modal
plate a plate pair's row goes on with the levers h/2 and its mode shapes' gradients
(``compiled.friction``: the slip against the plate's top surface, the force's moment into
the modes).
"""

import math

import numpy as np

from tailbeam.solvers.stream.active.compiled.friction import F_COLUMNS, F_GRAD, F_LEVER, F_MOMENT

# Whether the friction force's moment drives the plate's modes (always, but for measuring
# what leaving it out changes: benchmarks/bench_friction_stream.py)
_PLATE_MOMENT = True


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

    def table(self, keys, gradients=None, n_modes: int = 0, half: float = 0.0) -> np.ndarray:
        """(P, F_COLUMNS) rows of ``keys``; on the modal plate (``gradients``: plate pair key
        -> its mode shapes' gradients (k, 2) 1/(m sqrt(kg)) at its contact point, k <=
        ``n_modes`` the set's modes, the rest 0) (P, F_GRAD + 2 n_modes) with the levers
        ``half`` (h/2, m) of its plate pairs."""
        rows = np.array([self.row(k) for k in keys], dtype=float).reshape(-1, F_COLUMNS)
        if gradients is None:
            return rows
        out = np.zeros((len(keys), F_GRAD + 2 * n_modes))
        out[:, :F_COLUMNS] = rows
        for p, key in enumerate(keys):
            if key[1] >= 0:
                continue
            out[p, F_LEVER] = half
            out[p, F_MOMENT] = half if _PLATE_MOMENT else 0.0
            grad = np.asarray(gradients[key], dtype=float).reshape(-1, 2)
            out[p, F_GRAD : F_GRAD + len(grad)] = grad[:, 0]
            out[p, F_GRAD + n_modes : F_GRAD + n_modes + len(grad)] = grad[:, 1]
        return out

    def end(self, key, xi, vi, wi, xj=None, vj=None, wj=None, surface=None) -> str:
        """How contact ``key`` ends tangentially: ``sticking`` if its slip speed (``slip``)
        is below the stiction velocity, else ``sliding``. ``surface``: on the modal plate the
        velocity (3,) m/s of the plate's top surface under a plate pair (None: at rest)."""
        if surface is not None:
            vj = np.asarray(surface, dtype=float)
        speed = self.slip(key, xi, vi, wi, xj, vj, wj)
        return "sticking" if speed < self.settings(key).stiction_velocity else "sliding"

    def slip(self, key, xi, vi, wi, xj=None, vj=None, wj=None) -> float:
        """Slip speed (m/s) at the contact point of pair ``key`` from the balls' centres,
        velocities and angular velocities (3,) (j's None on the plate, where ``vj`` may give
        the surface's velocity)."""
        share = self.row(key)[5]
        if xj is None:  # the plate (its surface's velocity vj, zero on the rigid plate)
            xj, wj = np.array([xi[0], xi[1], 0.0]), np.zeros(3)
            vj = np.zeros(3) if vj is None else vj
        d = xi - xj
        dist = math.sqrt(float(d @ d))
        n = d / dist
        u = vi + _cross(wi, -dist * share * n) - vj - _cross(wj, dist * (1.0 - share) * n)
        slip = u - (u @ n) * n
        return float(math.sqrt(slip @ slip))


def _cross(a, b) -> np.ndarray:
    """a x b of two 3-vectors (``np.cross``'s arithmetic, without its overhead on tiny
    arrays: the driver calls it for every contact at every refresh)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])  # fmt: skip
