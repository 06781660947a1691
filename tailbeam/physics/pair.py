"""Normal kinematics of a contact pair, written once for ball-ball and ball-plate contacts.

A pair is (body i, body j): body i is a ball (centre x_i, velocity v_i); body j is another ball
or the plate. The plate enters as a partner of radius 0 at the foot point (x_i, y_i, 0) of
ball i, moving with the plate's velocity there (0 for a rigid plate), so both kinds share
one formula:

    d = x_i - x_j,  n = d / |d|  (unit normal from j to i, the direction of the force on i)
    delta = r_i + r_j - |d|      (penetration, m)
    w = v_i - v_j                (relative velocity, m/s)
    delta_dot = -w . n           (penetration rate, > 0 while approaching)
    w_t = w - (w . n) n          (tangential slip velocity: where Coulomb friction will enter)

The force of the pair is F n on i and -F n on j, with F from the IMPACT law
(``tailbeam.physics.contact_law``). Friction and rotation add a tangential force from w_t (plus
omega x r terms in w) here, without changing the callers.
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PairKinematics:
    """Arrays over pairs: normal (P, 3), penetration (P,), rate (P,), tangential (P, 3)."""

    normal: np.ndarray
    penetration: np.ndarray
    rate: np.ndarray
    tangential: np.ndarray


def pair_kinematics(x_i, v_i, x_j, v_j, radius_sum) -> PairKinematics:
    """Normal, penetration (m), penetration rate (m/s) and tangential velocity of pairs.

    x_i, v_i, x_j, v_j: (P, 3) in m and m/s; radius_sum: (P,) r_i + r_j in m (r_i for the
    plate).
    """
    d = np.asarray(x_i, dtype=float) - np.asarray(x_j, dtype=float)
    dist = np.sqrt(np.einsum("pk,pk->p", d, d))
    n = d / dist[:, None]
    w = np.asarray(v_i, dtype=float) - np.asarray(v_j, dtype=float)
    wn = np.einsum("pk,pk->p", w, n)
    return PairKinematics(n, np.asarray(radius_sum) - dist, -wn, w - wn[:, None] * n)


def plate_foot(x_i) -> np.ndarray:
    """The plate partner of balls at centres ``x_i`` (P, 3): the foot points (x, y, 0)."""
    foot = np.array(x_i, dtype=float)
    foot[:, 2] = 0.0
    return foot
