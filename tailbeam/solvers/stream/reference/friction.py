"""Friction and rolling resistance of the stream reference's contacts
(``tailbeam.physics.friction``), with the balls' rotation.

Each contact acts at one common point c on the line of centres: between two balls at the
fraction r_i / (r_i + r_j) of the centres' distance from ball i, on the plate at the foot of
the centre (the plate's surface). Ball i's lever arm is a_i = c - x_i, ball j's a_j = c - x_j,
so the slip velocity is the relative velocity of the two material points there,

    u = (v_i + w_i x a_i) - (v_j + w_j x a_j),   slip = u - (u . n) n

(v_j = w_j = 0 for the rigid plate), and the tangential force F_t (on i; -F_t on j) has the
torques a_i x F_t on i and a_j x (-F_t) on j. With the one point the pair's forces have no
net moment: linear and angular momentum are conserved to round-off. Rolling resistance acts
against w_roll, the part of w_i - w_j in the contact plane, with R = r_i r_j / (r_i + r_j)
(r_i on the plate); twisting about n is free. The power the pair dissipates,
-(F_t . slip) - (tau . w_roll), is >= 0 by construction: the energy ledger's friction line.
"""

from dataclasses import dataclass

import numpy as np

from tailbeam.physics.friction import rolling_torque, tangential_force


@dataclass(frozen=True)
class FrictionTable:
    """The friction parameters of pairs as arrays (P,): static, dynamic, v_s, v_d (m/s),
    rolling, ``share`` (r_i / (r_i + r_j), 1 on the plate) and the rolling radius (m)."""

    static: np.ndarray
    dynamic: np.ndarray
    v_s: np.ndarray
    v_d: np.ndarray
    rolling: np.ndarray
    share: np.ndarray
    roll_radius: np.ndarray

    @classmethod
    def of(cls, pairs, radius) -> "FrictionTable":
        """The table of ``pairs`` (each with a ``friction``); ``radius``: every ball's (m)."""
        f = [p.friction for p in pairs]
        keys = ("static", "dynamic", "stiction_velocity", "transition_velocity", "rolling")
        cols = [np.array([getattr(s, k) for s in f], dtype=float) for k in keys]
        ri = np.array([radius[p.i] for p in pairs], dtype=float)
        rj = np.array([radius[p.j] if p.j >= 0 else np.inf for p in pairs], dtype=float)
        roll = np.where(np.isinf(rj), ri, ri * rj / (ri + np.where(np.isinf(rj), 0.0, rj)))
        share = np.array([p.share for p in pairs], dtype=float)
        return cls(*cols, share, roll)


@dataclass(frozen=True)
class PairFriction:
    """Per pair (flattened as the kinematics): tangential force on ball i (N), torques on
    balls i and j (N m; j's unused on the plate), slip velocity (m/s), rolling angular
    velocity (rad/s) and dissipated power (W, >= 0), each (P', 3) or (P',)."""

    force: np.ndarray
    torque_i: np.ndarray
    torque_j: np.ndarray
    slip: np.ndarray
    roll: np.ndarray
    power: np.ndarray
    rolling: np.ndarray | None = None  # the rolling-resistance torque on ball i (Coulomb's law)


def pair_friction(table, kin, normal_force, xi, vi, wi, xj, vj, wj) -> PairFriction:
    """The friction of pairs with normal force ``normal_force`` (N) and kinematics ``kin``
    (``PairKinematics``), their balls' centres, velocities and angular velocities (P', 3)
    (the plate: its foot point, zero velocities). ``table``: a ``FrictionTable`` whose
    arrays broadcast with the flattened pairs (tiled over the leading axes)."""
    _d, a_i, a_j, _u, slip, roll = contact_motion(table, kin.normal, xi, vi, wi, xj, vj, wj)
    force = tangential_force(slip, normal_force, table.static, table.dynamic, table.v_s, table.v_d)
    tau = rolling_torque(roll, normal_force, table.rolling, table.roll_radius, table.v_s)
    torque_i = _cross(a_i, force) + tau
    torque_j = -_cross(a_j, force) - tau
    power = -np.einsum("pk,pk->p", force, slip) - np.einsum("pk,pk->p", tau, roll)
    return PairFriction(force, torque_i, torque_j, slip, roll, power)


def contact_motion(table, n, xi, vi, wi, xj, vj, wj) -> tuple:
    """At the pairs' common contact points (module docstring), with unit normals n (P, 3):
    the centres' distance d (P,) m, the lever arms a_i, a_j (P, 3) m, the relative velocity
    u of the two material points, its tangential part (the slip) (P, 3) m/s, and the
    rolling angular velocity (P, 3) rad/s."""
    d = np.sqrt(np.einsum("pk,pk->p", xi - xj, xi - xj))
    a_i = -(d * table.share)[:, None] * n
    a_j = (d * (1.0 - table.share))[:, None] * n
    u = vi + _cross(wi, a_i) - vj - _cross(wj, a_j)
    slip = u - np.einsum("pk,pk->p", u, n)[:, None] * n
    w = wi - wj
    roll = w - np.einsum("pk,pk->p", w, n)[:, None] * n
    return d, a_i, a_j, u, slip, roll


def contact_bodies(ix, x, v, w, surface=None) -> tuple:
    """The centres, velocities and angular velocities (K x P, 3 each) of the pairs ``ix``'s
    balls i and j at K states x, v, w (K, n, 3), flattened state-major; the plate's side is
    the foot point of ball i's centre, at rest, or moving at ``surface`` (K x P, 3; the
    modal plate's top surface)."""
    k, p = x.shape[0], len(ix.li)
    if k == 1:
        rows, li, lj, plate = 0, ix.li, ix.lj, ix.is_plate
    else:
        rows = np.repeat(np.arange(k), p)
        li, lj, plate = np.tile(ix.li, k), np.tile(ix.lj, k), np.tile(ix.is_plate, k)
    xi, vi, wi = x[rows, li], v[rows, li], w[rows, li]
    xj, vj, wj = x[rows, lj], v[rows, lj], w[rows, lj]
    xj[plate] = xi[plate] * np.array([1.0, 1.0, 0.0])
    vj[plate], wj[plate] = 0.0, 0.0
    if surface is not None:
        vj[plate] = surface[plate]
    return xi, vi, wi, xj, vj, wj


def _cross(a, b) -> np.ndarray:
    """a x b of (P, 3) arrays (np.cross costs ~10x more on small arrays)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def tile(table: FrictionTable, k: int) -> FrictionTable:
    """``table`` repeated for k states (pairs flattened state-major, as the kinematics)."""
    return FrictionTable(*(np.tile(getattr(table, f), k) for f in table.__dataclass_fields__))


def friction_of(table, ix, kin, x, v, w, force, surface=None) -> PairFriction:
    """``PairFriction`` of the pairs of ``table`` (a ``FrictionTable``) and ``ix`` (their
    ``PairIndex``) with kinematics ``kin`` at states x, v, w (K, n, 3) and normal forces
    ``force`` (K x P flattened, N); ``surface``: the plate surface's velocity under each
    pair (K x P, 3; m/s) on the modal plate, None on the rigid plate."""
    k = x.shape[0]
    bodies = contact_bodies(ix, x, v, w, surface)
    return pair_friction(tile(table, k) if k > 1 else table, kin, force, *bodies)


def slip_speed(pair, kinematics, radius, x, v, w, modes=None) -> float:
    """The slip speed (m/s) of ``pair`` at positions x, velocities v and angular velocities
    w (n, 3) of the present balls (and the modal plate's (q, q')); nan without friction."""
    if w is None or pair.friction is None:
        return float("nan")
    ix = kinematics.index([pair])
    kin, _, _, _, surface = kinematics_with_surface(kinematics, ix, x[None], v[None], modes)
    table = FrictionTable.of([pair], radius)
    fr = friction_of(table, ix, kin, x[None], v[None], w[None], np.zeros(1), surface)
    return float(np.linalg.norm(fr.slip[0]))


def kinematics_with_surface(kinematics, ix, x, v, modes):
    """The kinematics of pairs ``ix`` at states x, v (K, n, 3) and, on the modal plate, the
    plate surface's velocity under them (K x P, 3; None on the rigid plate)."""
    if modes is None:
        return (*kinematics.of(ix, x, v), None)
    kin, li, lj, is_plate, _, _, grad = kinematics.modal(ix, x, v, modes)
    return kin, li, lj, is_plate, kinematics.surface_velocity(grad, modes[1], len(ix.li))
