"""What an accepted step of the stream reference records: its contacts' peak force and
largest penetration, and the step series (time, total energy, states).

Peak force and largest penetration: the maximum of their Chebyshev interpolant on each step
(``tailbeam.solvers.numerics.step_events.interpolant_max``). Impulses (the normal force's and,
with friction, the tangential force's) and the energy friction dissipates: the integral of
the same interpolant over the step (Clenshaw-Curtis weights ``STEP_WEIGHTS``, exact for the
degree-14 polynomial through the 15 points; the force inside a region is smooth, so this is
as accurate as the interpolant).
"""

import numpy as np

from tailbeam.physics.contact_law import elastic_energy, impact_force_in_region
from tailbeam.solvers.numerics.step_events import (
    STEP_POINTS,
    chebyshev_coefficients,
    interpolant_max,
)
from tailbeam.solvers.stream.reference.friction import (
    FrictionTable,
    PairFriction,
    friction_of,
    kinematics_with_surface,
)
from tailbeam.solvers.stream.reference.pairs import law_table


def _weights() -> np.ndarray:
    """Quadrature weights on [0, 1] at ``STEP_POINTS``: the integral of the Chebyshev
    interpolant, int_-1^1 T_k = 2 / (1 - k^2) for even k, 0 for odd k, halved for [0, 1]."""
    k = np.arange(len(STEP_POINTS))
    moments = np.where(k % 2 == 0, 2.0 / (1.0 - np.where(k == 1, 0, k) ** 2), 0.0)
    return 0.5 * chebyshev_coefficients(np.eye(len(STEP_POINTS))) @ moments


STEP_WEIGHTS = _weights()
FIELDS = ("force", "torque_i", "torque_j", "slip", "roll", "power")  # PairFriction's


class StepSeries:
    """Per accepted step: ``times`` (s), total ``energy`` (J), ``states`` (names of the balls
    present, positions (n, 3) m, velocities (n, 3) m/s) and, on the modal plate,
    ``plate_states`` ((q, q')); and the peaks of the contacts in progress.

    Parameters
    ----------
    layout : StateLayout
        Which balls are present.
    pairs : PairSet
        The watched pairs.
    kinematics : Kinematics
        The pairs' contact kinematics.
    balls : list of Ball
        The scene's balls (names).
    mass : ndarray
        Mass of every ball (kg).
    incline : InclinedPlate
        Gravity's potential energy.
    plate : ReferencePlate or None
        The modal plate (its energy), or None for the rigid plate.

    With friction (``layout.spin``) it also records per step ``spins`` (angular velocities
    (n, 3), rad/s) and ``dissipated``, the energy friction has dissipated since the start (J).
    """

    def __init__(self, layout, pairs, kinematics, balls, mass, incline, plate):
        self.layout = layout
        self.pairs = pairs
        self.kinematics = kinematics
        self.names = [b.name for b in balls]
        self.mass = mass
        self.radius = np.array([b.radius for b in balls], dtype=float)
        self.incline = incline
        self.plate = plate
        self.times, self.energy, self.states, self.plate_states = [], [], [], []
        self.spins, self.dissipated, self.friction_work = [], [], 0.0
        self.coulomb = None  # a CoulombState where a pair has Coulomb's law (set by the solver)

    def update_peaks(self, dense, t0, t1) -> None:
        """Update the peak force, largest penetration and impulses of the contacts (and with
        friction the dissipated energy) on the accepted step [t0, t1] (s) with dense output
        ``dense``."""
        pairs = self.pairs.in_contact()
        if not pairs or t1 <= t0:
            return
        times = t0 + STEP_POINTS * (t1 - t0)
        states = self.layout.states_at(dense, times)
        force, delta = self.pair_forces(pairs, *states)
        impulse = force @ STEP_WEIGHTS * (t1 - t0)
        for q, p in enumerate(pairs):
            p.normal_impulse += float(impulse[q])
        if self.layout.spin:
            self.friction_step(pairs, states, force, self.layout.spins_at(dense, times), t1 - t0)
        # Refined only where the node maximum comes within 1 % of the record so far: between
        # nodes the interpolant cannot exceed them by more (a step resolved to rtol 1e-12
        # spans ~(1e-12)^(1/8) of the force's time scale; the overshoot is ~1e-6).
        for q, p in enumerate(pairs):
            if force[q].max() >= 0.99 * p.peak:
                s_peak, peak = interpolant_max(force[q])
                if peak > p.peak:
                    p.peak, p.t_peak = peak, t0 + s_peak * (t1 - t0)
            if delta[q].max() >= 0.99 * p.pen:
                p.pen = max(p.pen, interpolant_max(delta[q])[1])

    def friction_step(self, pairs, states, force, w, h) -> None:
        """Add the step's tangential impulses (on each pair's ball i) and the energy friction
        dissipated on it: ``force`` (P, K) normal forces (N) at the step's points, ``states``
        and ``w`` the states there, h the step (s)."""
        x, v, modes = states
        if self.coulomb is not None and any(p.coulomb for p in pairs):
            fr = self._coulomb_friction(x, v, w)
        else:
            ix = self.kinematics.index(pairs)
            kin, _, _, _, surface = kinematics_with_surface(self.kinematics, ix, x, v, modes)
            table = FrictionTable.of(pairs, self.radius)
            fr = friction_of(table, ix, kin, x, v, w, force.T.ravel(), surface)
        k = len(STEP_POINTS)
        tangential = fr.force.reshape(k, len(pairs), 3)
        impulse = np.einsum("k,kpc->pc", STEP_WEIGHTS, tangential) * h
        for q, p in enumerate(pairs):
            p.tangential_impulse = p.tangential_impulse + impulse[q]
        self.friction_work += float(STEP_WEIGHTS @ fr.power.reshape(k, len(pairs)).sum(axis=1)) * h

    def _coulomb_friction(self, x, v, w) -> PairFriction:
        """The friction of the pairs in contact at the states x, v, w (K, n, 3), with
        Coulomb's law's constraint forces (``CoulombState``), flattened state-major."""
        parts = [self.coulomb.at(x[k], v[k], w[k])[2] for k in range(x.shape[0])]
        return PairFriction(*(np.concatenate([getattr(p, f) for p in parts]) for f in FIELDS))

    def pair_forces(self, pairs, x, v, modes=None):
        """Force (N) and penetration (m) of ``pairs`` at states x, v (K, n, 3) (and modes):
        (P, K) each."""
        kin, _, _, _ = self.kinematics.of(pairs, x, v, modes)
        laws = law_table(pairs)
        ramp = np.array([p.ramp for p in pairs])
        clamped = np.array([p.clamped for p in pairs])
        k = x.shape[0]
        delta = kin.penetration.reshape(k, len(pairs))
        rate = kin.rate.reshape(k, len(pairs))
        force = impact_force_in_region(delta, rate, laws, ramp, clamped)
        return force.T, delta.T

    def total_energy(self, y) -> float:
        """Kinetic + gravitational + elastic (+ modal) energy (J) at state vector y."""
        x, v = self.layout.split(y)
        m = self.mass[self.layout.active]
        energy = 0.5 * float(np.sum(m[:, None] * v * v))
        w = self.layout.spins(y)
        if w is not None:
            inertia = 0.4 * m * self.radius[self.layout.active] ** 2
            energy += 0.5 * float(np.sum(inertia[:, None] * w * w))
        energy += self.incline.potential_energy(m, x)
        modes = self.layout.modes(y)
        if modes is not None:
            energy += self.plate.energy(*modes)
            modes = tuple(a[None] for a in modes)
        pairs = self.pairs.in_contact()
        if pairs:
            kin, _, _, _ = self.kinematics.of(pairs, x[None], v[None], modes)
            energy += float(np.sum(elastic_energy(kin.penetration, law_table(pairs))))
        return energy

    def record(self, t, y) -> None:
        """Append the step ending at time t (s) with state vector y to the series."""
        self.times.append(t)
        self.energy.append(self.total_energy(y))
        x, v = self.layout.split(y)
        names = tuple(self.names[b] for b in self.layout.active)
        self.states.append((names, x.copy(), v.copy()))
        if self.layout.spin:
            self.spins.append(self.layout.spins(y).copy())
            self.dissipated.append(self.friction_work)
        modes = self.layout.modes(y)
        if modes is not None:
            self.plate_states.append(tuple(a.copy() for a in modes))
