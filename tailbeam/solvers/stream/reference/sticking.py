"""Coulomb's law in the stream reference (``FrictionSettings.coulomb``: v_s = v_d = 0).

A contact with Coulomb's law is in one of two tangential modes, and so is its rolling:

- **sliding**: F_t = -mu_d |F_n| slip / |slip| (at zero slip, the direction of the step's
  start: ``Pair.slide_ref``); **stuck** (``Pair.stuck``): the slip is held at zero by
  whatever force that takes;
- **rolling**: the torque -mu_r R |F_n| w / |w| (``Pair.roll_ref`` at zero); **held**
  (``Pair.held``): the rolling angular velocity w is held at zero by whatever torque that
  takes.

The forces and torques of the stuck and held contacts of a set are the constraint forces
that keep the time derivatives of their slips and rolling velocities (two components each,
in the contact plane) at zero, given every other force: one linear system A lam = -c over
them (A = J M^-1 J^T, c the constraints' rates without them), solved by least squares (the
smallest forces where the system is indeterminate, as in a statically indeterminate heap).
The modes switch as events (``tailbeam.solvers.stream.reference.events``): a stuck contact
slips when its force reaches mu_s |F_n| (``SLIP``), a sliding one sticks when its slip
passes zero (``STICK``) if the force that holds it is within mu_s |F_n| (else it slides on,
the other way), and the same for rolling with mu_r R |F_n| (``ROLL_FREE``, ``ROLL_HOLD``).
"""

import numpy as np

from tailbeam.physics.contact_law import impact_force_in_region
from tailbeam.physics.friction import rolling_torque, tangential_force
from tailbeam.solvers.stream.reference.friction import (
    FrictionTable,
    PairFriction,
    _cross,
    contact_bodies,
    contact_motion,
)
from tailbeam.solvers.stream.reference.pairs import law_table

SLIP_TINY = 1e-12  # m/s: a slip (or R x rolling rate) below it takes the stored direction


def _cross3(a, b) -> np.ndarray:
    """a x b of two (3,) vectors (np.cross costs ~20x more on them)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def tangent_basis(n) -> tuple:
    """Two unit vectors (3,) spanning the plane normal to the unit vector ``n`` (3,)."""
    e = np.zeros(3)
    e[int(np.argmin(np.abs(n)))] = 1.0
    t1 = e - (e @ n) * n
    t1 /= np.linalg.norm(t1)
    return t1, _cross3(n, t1)


class Geometry:
    """One state's contact points: balls' centres, velocities and spins (P, 3) of each
    pair's ball i and j (the plate: the foot point, at rest), the unit normal n (from j to
    i), the lever arms a_i, a_j and their rates, the normal's rate, slip and rolling
    velocity."""

    def __init__(self, table, ix, kin, x, v, w):
        self.li, self.lj, self.plate = ix.li, ix.lj, ix.is_plate
        xi, vi, self.wi, xj, vj, self.wj = contact_bodies(ix, x[None], v[None], w[None])
        n = self.n = kin.normal
        d, self.a_i, self.a_j, u, self.slip, self.roll = contact_motion(
            table, n, xi, vi, self.wi, xj, vj, self.wj
        )
        rel = vi - vj
        d_rate = np.einsum("pk,pk->p", rel, n)
        n_rate = (rel - d_rate[:, None] * n) / d[:, None]
        n_rate[self.plate] = 0.0  # (the foot point moves with the ball: the normal stays z)
        self.n_rate = n_rate
        share = table.share
        arm_rate = d_rate[:, None] * n + d[:, None] * n_rate
        self.a_i_rate, self.a_j_rate = -share[:, None] * arm_rate, (1 - share)[:, None] * arm_rate
        self.u_n = np.einsum("pk,pk->p", u, n)
        self.w_n = np.einsum("pk,pk->p", self.wi - self.wj, n)


def coulomb_friction(table, pairs, ix, kin, normal, x, v, w, mass, inertia, gravity):
    """``PairFriction`` of ``pairs`` (in contact; the table ``table``, index ``ix``,
    kinematics ``kin``) at one state: positions x, velocities v, angular velocities w (n, 3)
    of the present balls, normal forces ``normal`` (P,) N; ``mass``, ``inertia`` (n,) of
    the present balls (kg, kg m^2), ``gravity`` (3,) m/s^2. Regularised pairs get the law's
    force; Coulomb pairs the module docstring's."""
    geo = Geometry(table, ix, kin, x, v, w)
    fn = np.abs(normal)
    force = tangential_force(geo.slip, normal, table.static, table.dynamic, table.v_s, table.v_d)
    tau = rolling_torque(geo.roll, normal, table.rolling, table.roll_radius, table.v_s)
    coulomb = table.v_s == 0.0
    stuck = coulomb & np.array([p.stuck for p in pairs], dtype=bool)
    held = coulomb & np.array([p.held for p in pairs], dtype=bool)
    for q, p in enumerate(pairs):
        if coulomb[q] and not p.stuck:
            force[q] = -table.dynamic[q] * fn[q] * _direction(geo.slip[q], p.slide_ref)
        if coulomb[q] and not p.held:
            size = table.rolling[q] * table.roll_radius[q] * fn[q]
            tau[q] = -size * _direction(table.roll_radius[q] * geo.roll[q], p.roll_ref)
    force[stuck], tau[held] = 0.0, 0.0
    if stuck.any() or held.any():
        acc, alpha = _accelerations(geo, normal, force, tau, mass, inertia, gravity)
        lam_force, lam_tau = _constraint_forces(geo, stuck, held, acc, alpha, mass, inertia)
        force, tau = force + lam_force, tau + lam_tau
    torque_i = _cross(geo.a_i, force) + tau
    torque_j = -_cross(geo.a_j, force) - tau
    power = -np.einsum("pk,pk->p", force, geo.slip) - np.einsum("pk,pk->p", tau, geo.roll)
    return PairFriction(force, torque_i, torque_j, geo.slip, geo.roll, power, tau)


def _direction(velocity, ref) -> np.ndarray:
    """The unit direction Coulomb's law opposes for a slip (or R x rolling) ``velocity``
    (3,) m/s of a sliding contact whose direction at the step's start was ``ref``: the
    velocity's, continued smoothly past its zero along ``ref`` (so that a step which
    overshoots the ``STICK`` event stays smooth and the event is located exactly), and
    ``ref`` itself below ``SLIP_TINY``."""
    speed = float(np.linalg.norm(velocity))
    if speed < SLIP_TINY:
        return ref
    return np.copysign(1.0, velocity @ ref) * velocity / speed


def _accelerations(geo, normal, force, tau, mass, inertia, gravity):
    """The balls' accelerations and angular accelerations (n, 3) under gravity, the normal
    forces and the given tangential forces and torques (on ball i; reversed on j)."""
    total = normal[:, None] * geo.n + force
    acc = np.tile(gravity, (len(mass), 1))
    alpha = np.zeros((len(mass), 3))
    ball = ~geo.plate
    np.add.at(acc, geo.li, total / mass[geo.li, None])
    np.add.at(acc, geo.lj[ball], -total[ball] / mass[geo.lj[ball], None])
    np.add.at(alpha, geo.li, (_cross(geo.a_i, force) + tau) / inertia[geo.li, None])
    torque_j = -_cross(geo.a_j, force) - tau
    np.add.at(alpha, geo.lj[ball], torque_j[ball] / inertia[geo.lj[ball], None])
    return acc, alpha


def _constraint_forces(geo, stuck, held, acc, alpha, mass, inertia):
    """The tangential forces of the ``stuck`` pairs and the torques of the ``held`` ones
    (P, 3 each, zero elsewhere) that hold their slips' and rolling velocities' rates at
    zero (module docstring), given the balls' accelerations ``acc`` and ``alpha`` under
    every other force: A lam = -c with A = J M^-1 J^T, J the constraints' rows."""
    rows = [(q, 0, t) for q in np.flatnonzero(stuck) for t in tangent_basis(geo.n[q])]
    rows += [(q, 1, t) for q in np.flatnonzero(held) for t in tangent_basis(geo.n[q])]
    j_acc, j_alpha = np.zeros((len(rows), len(mass), 3)), np.zeros((len(rows), len(mass), 3))
    c = np.empty(len(rows))
    for r, (q, kind, t) in enumerate(rows):
        i, j, ball = geo.li[q], geo.lj[q], not geo.plate[q]
        if kind == 0:  # the slip: t . (a_i + alpha_i x a_i - a_j - alpha_j x a_j)
            j_acc[r, i], j_alpha[r, i] = t, _cross3(geo.a_i[q], t)
            if ball:
                j_acc[r, j], j_alpha[r, j] = -t, -_cross3(geo.a_j[q], t)
            moving = _cross3(geo.wi[q], geo.a_i_rate[q]) - _cross3(geo.wj[q], geo.a_j_rate[q])
            c[r] = t @ (moving - geo.u_n[q] * geo.n_rate[q])
        else:  # the rolling velocity: t . (alpha_i - alpha_j)
            j_alpha[r, i] = t
            if ball:
                j_alpha[r, j] = -t
            c[r] = -(t @ geo.n_rate[q]) * geo.w_n[q]
    c += np.einsum("rbk,bk->r", j_acc, acc) + np.einsum("rbk,bk->r", j_alpha, alpha)
    A = np.einsum("rbk,sbk,b->rs", j_acc, j_acc, 1.0 / mass)
    A += np.einsum("rbk,sbk,b->rs", j_alpha, j_alpha, 1.0 / inertia)
    lam = np.linalg.lstsq(A, -c, rcond=None)[0]
    force, tau = np.zeros((len(stuck), 3)), np.zeros((len(stuck), 3))
    for (q, kind, t), value in zip(rows, lam, strict=True):
        (tau if kind else force)[q] += value * t
    return force, tau


class CoulombState:
    """``coulomb_friction`` of the pairs in contact at given states, for the event rows,
    the step's impulses and the events' switches.

    Parameters
    ----------
    layout, kinematics, pairs :
        The reference's state layout, pair kinematics and watched pairs.
    mass, radius : ndarray
        Every ball's mass (kg) and radius (m).
    gravity : ndarray
        Gravity in the plate frame (3,) m/s^2.
    """

    def __init__(self, layout, kinematics, pairs, mass, radius, gravity):
        self.layout, self.kinematics, self.pairs = layout, kinematics, pairs
        self.mass, self.radius, self.gravity = mass, radius, gravity

    def any(self) -> bool:
        """Whether a pair in contact has Coulomb's law."""
        return any(p.coulomb for p in self.pairs.in_contact())

    def at(self, x, v, w):
        """(pairs in contact, their normal forces (P,) N, their ``PairFriction``, their
        ``FrictionTable``) at one state (n, 3 each)."""
        pairs = self.pairs.in_contact()
        ix = self.kinematics.index(pairs)
        kin, _, _, _ = self.kinematics.of(ix, x[None], v[None])
        ramp = np.array([p.ramp for p in pairs], dtype=bool)
        clamped = np.array([p.clamped for p in pairs], dtype=bool)
        f = impact_force_in_region(kin.penetration, kin.rate, law_table(pairs), ramp, clamped)
        m = self.mass[self.layout.active]
        inertia = 0.4 * m * self.radius[self.layout.active] ** 2
        table = FrictionTable.of(pairs, self.radius)
        fr = coulomb_friction(table, pairs, ix, kin, f, x, v, w, m, inertia, self.gravity)
        return pairs, f, fr, table
