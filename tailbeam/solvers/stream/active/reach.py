"""How fast a ball of an isolated group can move within a horizon: certified speed bounds.

A group of balls touching one another (on the rigid plate) exchanges energy only among its
balls until it touches something else. Its kinetic (rotation included) and elastic energy
E(t) then grows by no more than the work of gravity, the friction and damping only take
energy away:

    E(t) <= E0 + g sum_k m_k |x_k(t) - x_k(0)| <= E0 + g h sum_k m_k V_k,

with V_k the largest speed of ball k over the horizon h. Each ball holds at most all of it,
V_k <= sqrt(2 E_max / m_k), so with U = sqrt(E_max) and c = g h sqrt(2) sum_k sqrt(m_k)

    U^2 <= E0 + c U,    U <= (c + sqrt(c^2 + 4 E0)) / 2,

and the speed of ball i stays below sqrt(2 / m_i) U over the horizon. A group at rest can
give a ball at most 2 g h sum_k sqrt(m_k / m_i) (a ball alone: 2 g h, twice free fall): the
work of gravity is bounded by the drops the bound itself allows, not by a fixed height.
"""

import math

import numpy as np


def group_speed_bounds(energy: float, mass, g: float, horizon: float) -> np.ndarray:
    """Speed bounds (m/s) of the balls of one isolated group over ``horizon``.

    Parameters
    ----------
    energy : float
        The group's kinetic (rotation included) and elastic energy now (J).
    mass : ndarray, shape (k,)
        Its balls' masses (kg).
    g : float
        Gravity's magnitude (m/s^2).
    horizon : float
        Time ahead (s).

    Returns
    -------
    ndarray, shape (k,)
        A bound on each ball's speed (m/s) over the horizon, while the group touches
        nothing else.
    """
    mass = np.asarray(mass, dtype=float)
    c = g * horizon * math.sqrt(2.0) * float(np.sum(np.sqrt(mass)))
    root = 0.5 * (c + math.sqrt(c * c + 4.0 * max(energy, 0.0)))
    return np.sqrt(2.0 / mass) * root
