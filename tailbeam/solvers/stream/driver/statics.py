"""Static equilibrium of a cluster of balls within the Coulomb limits of its contacts.

Rigid-body statics: each contact k (ball i on the plate, or balls i and j) carries a normal
force f_n >= 0 along its normal n (from the partner to ball i), a tangential force f_t in the
contact plane and a rolling-resistance torque m_r in the contact plane (no twisting torque:
twisting is free in the friction model). The contact point is the friction model's (on the
plate's surface below the centre; between two balls at r_i / (r_i + r_j) of the centres'
distance from i), so f_t has the model's lever arms. The cluster holds still if forces exist
with every ball's forces and torques (weight included) balancing and, at every contact,

    |f_t| <= mu_s f_n    and    |m_r| <= mu_r R_roll f_n.

The discs are replaced by the regular octagons inscribed in them (vertices on the tangent
axes, faces cos(pi/8) = 0.924 of the radius away): a linear feasibility problem
(``scipy.optimize.linprog``, HiGHS). The octagon lies inside the disc, so a cluster found in
equilibrium is in equilibrium under the model's limits; one whose forces need more than
0.924 of a limit in a direction between the axes may be refused (it is then integrated on).
"""

import math

import numpy as np
from scipy.optimize import linprog

N_SIDES = 8  # the inscribed polygon's sides
_ANGLES = (np.arange(N_SIDES) + 0.5) * 2.0 * math.pi / N_SIDES
_FACES = np.stack([np.cos(_ANGLES), np.sin(_ANGLES)], axis=1)  # face normals (unit)
_REACH = math.cos(math.pi / N_SIDES)  # face distance per radius


def tangent_basis(n) -> tuple:
    """Two unit vectors (3,) completing the unit normal ``n`` to a right-handed basis; on the
    plate (n = z) they are x (downhill) and y, so a load along the slope meets a vertex."""
    n = np.asarray(n, dtype=float)
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = a - (a @ n) * n
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1)


def in_equilibrium(x, mass, gravity, contacts, loads=None) -> bool:
    """Whether balls at positions ``x`` can stand still on their contacts.

    Parameters
    ----------
    x : ndarray, shape (n, 3)
        Centres (m, plate frame, plate surface z = 0).
    mass : ndarray, shape (n,)
        Masses (kg).
    gravity : ndarray, shape (3,)
        Gravity (m/s^2, plate frame).
    contacts : list of tuple
        (i, j, share, mu_s, mu_r, rolling_radius): ball i (local index) touching the plate
        (j = -1) or ball j; ``share`` the contact point's fraction r_i / (r_i + r_j) of the
        centres' distance from i (1 on the plate); mu_s, mu_r dimensionless; rolling radius m.
    loads : ndarray, shape (n, 6), optional
        Given external loads on each ball besides its weight: force (N) and torque about its
        centre (N m), plate frame (the contacts of balls outside the cluster, as they are).
    """
    x = np.asarray(x, dtype=float).reshape(-1, 3)
    n_balls, n_c = x.shape[0], len(contacts)
    if not n_c:
        return False
    a_eq = np.zeros((6 * n_balls, 5 * n_c))
    a_ub = np.zeros((2 * N_SIDES * n_c, 5 * n_c))
    for k, (i, j, share, mu_s, mu_r, rolling_radius) in enumerate(contacts):
        if j < 0:
            n, arm_i, arm_j = np.array([0.0, 0.0, 1.0]), x[i, 2], 0.0
        else:
            d = x[i] - x[j]
            dist = math.sqrt(float(d @ d))
            n, arm_i, arm_j = d / dist, dist * share, dist * (1.0 - share)
        t1, t2 = tangent_basis(n)
        cols = slice(5 * k, 5 * k + 5)
        # per unknown (f_n, f_1, f_2, m_1, m_2): force and torque on ball i
        force = np.stack([n, t1, t2, np.zeros(3), np.zeros(3)], axis=1)
        lever = -arm_i * n
        torque = np.stack([np.zeros(3), np.cross(lever, t1), np.cross(lever, t2), t1, t2], axis=1)
        a_eq[6 * i : 6 * i + 3, cols] += force
        a_eq[6 * i + 3 : 6 * i + 6, cols] += torque
        if j >= 0:  # the reactions on ball j, its lever arm on the other side of the point
            lever_j = arm_j * n
            torque_j = np.stack([np.zeros(3), np.cross(lever_j, t1), np.cross(lever_j, t2),
                                 t1, t2], axis=1)  # fmt: skip
            a_eq[6 * j : 6 * j + 3, cols] -= force
            a_eq[6 * j + 3 : 6 * j + 6, cols] -= torque_j
        rows = 2 * N_SIDES * k
        for s, (limit, c0) in enumerate(((mu_s, 1), (mu_r * rolling_radius, 3))):
            block = slice(rows + s * N_SIDES, rows + (s + 1) * N_SIDES)
            a_ub[block, 5 * k] = -limit * _REACH
            a_ub[block, 5 * k + c0 : 5 * k + c0 + 2] = _FACES
    b_eq = np.zeros(6 * n_balls)
    for i in range(n_balls):
        b_eq[6 * i : 6 * i + 3] = -np.asarray(mass)[i] * np.asarray(gravity, dtype=float)
    if loads is not None:
        b_eq -= np.asarray(loads, dtype=float).reshape(6 * n_balls)
    bounds = [(0.0, None) if c % 5 == 0 else (None, None) for c in range(5 * n_c)]
    scale = float(np.max(np.abs(b_eq))) or 1.0
    res = linprog(np.zeros(5 * n_c), A_ub=a_ub, b_ub=np.zeros(len(a_ub)), A_eq=a_eq,
                  b_eq=b_eq / scale, bounds=bounds, method="highs")  # fmt: skip
    return bool(res.status == 0)
