"""What an accepted step of the stream reference records: its contacts' peak force and
maximum penetration, the total energy and the states (a mixin of
``tailbeam.solvers.stream.reference.solver._Reference``, which provides ``pairs``,
``active``, ``mass``, ``incline``, ``plate``, ``balls``, the step series ``times``,
``energy``, ``states``, ``plate_states`` and the state layout of ``reference_state``).

Peak force and maximum penetration: the maximum of their Chebyshev interpolant on each step
(``tailbeam.solvers.numerics.step_events.interpolant_max``).
"""

import numpy as np

from tailbeam.physics.contact_law import elastic_energy, impact_force_in_region
from tailbeam.solvers.numerics.step_events import STEP_POINTS, interpolant_max
from tailbeam.solvers.stream.reference.state import _law_table


class ReferenceSteps:
    """Peaks, energy and states of the accepted steps of the stream reference."""

    def accept(self, dense, t0, t1):
        """Update the peak force and maximum penetration of the contacts on [t0, t1]."""
        pairs = [p for p in self.pairs.values() if p.in_contact]
        if not pairs or t1 <= t0:
            return
        force, delta = self.pair_forces(pairs, *self.states_at(dense, t0 + STEP_POINTS * (t1 - t0)))
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

    def pair_forces(self, pairs, x, v, modes=None):
        """Force (N) and penetration (m) of ``pairs`` at states x, v (K, n, 3) (and modes):
        (P, K) each."""
        kin, _, _, _ = self.kinematics(pairs, x, v, modes)
        laws = _law_table(pairs)
        ramp = np.array([p.ramp for p in pairs])
        clamped = np.array([p.clamped for p in pairs])
        k = x.shape[0]
        delta = kin.penetration.reshape(k, len(pairs))
        rate = kin.rate.reshape(k, len(pairs))
        force = impact_force_in_region(delta, rate, laws, ramp, clamped)
        return force.T, delta.T

    def total_energy(self, y):
        """Kinetic + gravitational + elastic energy in J of the active balls at state y."""
        x, v = self.split(y)
        m = self.mass[self.active]
        energy = 0.5 * float(np.sum(m[:, None] * v * v))
        energy += self.incline.potential_energy(m, x)
        modes = self.modes(y)
        if modes is not None:
            energy += self.plate.energy(*modes)
            modes = tuple(a[None] for a in modes)
        pairs = [p for p in self.pairs.values() if p.in_contact]
        if pairs:
            kin, _, _, _ = self.kinematics(pairs, x[None], v[None], modes)
            energy += float(np.sum(elastic_energy(kin.penetration, _law_table(pairs))))
        return energy

    def record_step(self, t, y):
        self.times.append(t)
        self.energy.append(self.total_energy(y))
        x, v = self.split(y)
        names = tuple(self.balls[b].name for b in self.active)
        self.states.append((names, x.copy(), v.copy()))
        if self.plate is not None:
            self.plate_states.append(tuple(a.copy() for a in self.modes(y)))

    def finish(self):
        for p in self.pairs.values():
            for rec in p.records:
                rec.peak_force, rec.t_peak, rec.max_penetration = p.peak, p.t_peak, p.pen
