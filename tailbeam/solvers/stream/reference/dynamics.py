"""The right-hand side of the stream reference's ODE: gravity and every pair in contact,
each with its current region's smooth force (``impact_force_in_region``), on the balls and,
on the modal plate, on the modes (``tailbeam.solvers.stream.reference.plate``).
"""

import numpy as np

from tailbeam.physics.contact_law import impact_force_in_region
from tailbeam.solvers.stream.reference.friction import FrictionTable, friction_of
from tailbeam.solvers.stream.reference.pairs import law_table
from tailbeam.solvers.stream.reference.sticking import coulomb_friction


class Dynamics:
    """Builds the right-hand side f(t, y) for the current contacts and their regions.

    Parameters
    ----------
    layout : StateLayout
        Where each ball and the modes sit in the state.
    kinematics : Kinematics
        The pairs' contact kinematics.
    pairs : PairSet
        The watched pairs (those in contact exert forces).
    mass : ndarray
        Mass of every ball of the scene (kg).
    gravity : ndarray
        Gravity in the plate frame (3,) (m/s^2).
    plate : ReferencePlate or None
        The modal plate, or None for the rigid plate.
    radius : ndarray, optional
        Radius of every ball (m): with friction (``layout.spin``) the lever arms and the
        moments of inertia 2/5 m r^2.
    """

    def __init__(self, layout, kinematics, pairs, mass, gravity, plate, radius=None):
        self.layout = layout
        self.kinematics = kinematics
        self.pairs = pairs
        self.mass = mass
        self.gravity = gravity
        self.plate = plate
        self.radius = radius

    def rhs(self):
        """f(t, y) of the state layout, contacts and regions as they are now (a new one is
        needed after any of them changes)."""
        pairs = self.pairs.in_contact()
        laws = law_table(pairs)
        ramp = np.array([p.ramp for p in pairs], dtype=bool)
        clamped = np.array([p.clamped for p in pairs], dtype=bool)
        m = self.mass[self.layout.active]
        ix = self.kinematics.index(pairs)
        if self.plate is not None:
            return self._modal_rhs(pairs, laws, ramp, clamped, m, ix)
        if self.layout.spin:
            return self._friction_rhs(pairs, laws, ramp, clamped, m, ix)
        split, kinematics, g = self.layout.split, self.kinematics, self.gravity

        def rhs(t, y):
            x, v = split(y)
            acc = np.tile(g, (len(m), 1))
            if pairs:
                kin, li, lj, is_plate = kinematics.of(ix, x, v)
                f = impact_force_in_region(kin.penetration, kin.rate, laws, ramp, clamped)
                fn = f[:, None] * kin.normal
                np.add.at(acc, li, fn / m[li, None])
                ball = ~is_plate
                np.add.at(acc, lj[ball], -fn[ball] / m[lj[ball], None])
            return np.concatenate([v.ravel(), acc.ravel()])

        return rhs

    def _friction_rhs(self, pairs, laws, ramp, clamped, m, ix):
        """The right-hand side with friction on the rigid plate: the state holds the angular
        velocities; every contact adds its tangential force and the torques
        (``tailbeam.solvers.stream.reference.friction``; with Coulomb's law, the stuck
        contacts' constraint forces: ``tailbeam.solvers.stream.reference.sticking``)."""
        layout, kinematics, g = self.layout, self.kinematics, self.gravity
        inertia = 0.4 * m * self.radius[layout.active] ** 2
        table = FrictionTable.of(pairs, self.radius) if pairs else None
        coulomb = any(p.coulomb for p in pairs)

        def rhs(t, y):
            x, v = layout.split(y)
            w = layout.spins(y)
            acc = np.tile(g, (len(m), 1))
            alpha = np.zeros_like(w)
            if pairs:
                kin, li, lj, is_plate = kinematics.of(ix, x, v)
                f = impact_force_in_region(kin.penetration, kin.rate, laws, ramp, clamped)
                if coulomb:  # (stuck contacts' forces hold them: a set-wide solve)
                    fr = coulomb_friction(table, pairs, ix, kin, f, x, v, w, m, inertia, g)
                else:
                    fr = friction_of(table, ix, kin, x[None], v[None], w[None], f)
                force = f[:, None] * kin.normal + fr.force
                np.add.at(acc, li, force / m[li, None])
                np.add.at(alpha, li, fr.torque_i / inertia[li, None])
                ball = ~is_plate
                np.add.at(acc, lj[ball], -force[ball] / m[lj[ball], None])
                np.add.at(alpha, lj[ball], fr.torque_j[ball] / inertia[lj[ball], None])
            return np.concatenate([v.ravel(), acc.ravel(), alpha.ravel()])

        return rhs

    def _modal_rhs(self, pairs, laws, ramp, clamped, m, ix):
        """The right-hand side with the modal plate: the contacts' generalised forces on the
        balls (normal and slope) and on the modes."""
        plate, layout, kinematics, g = self.plate, self.layout, self.kinematics, self.gravity

        # A DOP853 trial step far too long for a stiff contact can overflow in its stages;
        # the error estimate is then nan and DOP853 rejects the step and shrinks it (only
        # accepted steps are used), so those warnings are silenced here.
        def rhs(t, y):
            with np.errstate(over="ignore", invalid="ignore"):
                return modal_rhs(t, y)

        spin = layout.spin
        if spin:
            inertia = 0.4 * m * self.radius[layout.active] ** 2
            table = FrictionTable.of(pairs, self.radius) if pairs else None
            half = 0.5 * plate.basis.plate.thickness

        def modal_rhs(t, y):
            x, v = layout.split(y)
            q, qd = layout.modes(y)
            w = layout.spins(y)
            alpha = None if w is None else np.zeros_like(w)
            acc = np.tile(g, (len(m), 1))
            modal_force = np.zeros(plate.n_modes)
            if pairs:
                kin, li, lj, is_plate, slope, phi, grad = kinematics.modal(ix, x, v, (q, qd))
                f = impact_force_in_region(kin.penetration, kin.rate, laws, ramp, clamped)
                fn = f[:, None] * kin.normal
                fn[:, :2] -= f[:, None] * slope  # zero slope for ball-ball pairs
                modal_force = -(f @ phi)
                if spin:
                    surface = kinematics.surface_velocity(grad, qd, len(is_plate))
                    fr = friction_of(table, ix, kin, x[None], v[None], w[None], f, surface)
                    fn = fn + fr.force
                    np.add.at(alpha, li, fr.torque_i / inertia[li, None])
                    np.add.at(
                        alpha, lj[~is_plate], fr.torque_j[~is_plate] / inertia[lj[~is_plate], None]
                    )
                    modal_force += half * np.einsum("pk,pmk->m", fr.force[:, :2], grad)
                np.add.at(acc, li, fn / m[li, None])
                ball = ~is_plate
                np.add.at(acc, lj[ball], -fn[ball] / m[lj[ball], None])
            qdd = plate.acceleration(q, qd, modal_force)
            if spin:
                return np.concatenate([v.ravel(), acc.ravel(), alpha.ravel(), qd, qdd])
            return np.concatenate([v.ravel(), acc.ravel(), qd, qdd])

        return rhs
