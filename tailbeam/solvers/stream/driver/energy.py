"""The stream driver's energy ledger (J): released = left + at the end + removed at rest +
dissipated. Kinetic plus gravitational energy of the balls (potential 0 at the origin of the
plate frame) and the elastic energy of their contacts. With friction the kinetic energy
includes the rotation's 1/2 I w^2 and friction's dissipation is its own line,
``energy_friction`` (summed over the contacts as they end, ``records``)."""

import numpy as np

from tailbeam.physics.contact_law import elastic_energy
from tailbeam.solvers.stream.driver.balls import GONE, PENDING, SLIDE

ENTRIES = ("rest_energy_removed", "energy_released", "energy_left", "energy_final")


class EnergyLedger:
    """The energy entries of the run's counters.

    Parameters
    ----------
    balls : Balls
        The stream's balls.
    act : ActiveMembers
        The active set (the states and contact energies of its members).
    stats : dict
        The run's counters; the entries ``ENTRIES`` (J) are added to it.
    """

    def __init__(self, balls, act, stats: dict):
        self.balls, self.act, self.stats = balls, act, stats
        self.asleep = {}  # sleeping ball -> elastic energy (J) of its frozen contacts' share
        for key in ENTRIES:
            stats[key] = 0.0
        if act.friction is not None:
            stats["energy_friction"] = 0.0

    def released(self, i: int, x, v) -> None:
        """Ball i enters the scene at x (m), v (m/s), possibly pressing on the plate."""
        b = self.balls
        on_plate = float(elastic_energy(b.radius[i] - x[2], b.plate_law(i)))
        self.stats["energy_released"] += self.ball_energy(i, x, v) + on_plate

    def left(self, i: int, x, v) -> None:
        """Ball i leaves the plate over an edge at x (m), v (m/s). Its contacts end with it,
        so the whole elastic energy of each leaves too, its partners' halves included."""
        whole = self.act.elastic_energy_of(i, 1.0) if i in self.act.members else self.elastic(i)
        self.stats["energy_left"] += self.ball_energy(i, x, v) + whole

    def removed_at_rest(self, energy: float) -> None:
        """A ball put at rest lost ``energy`` (J) of normal motion."""
        self.stats["rest_energy_removed"] += energy

    def ball_energy(self, i: int, x, v) -> float:
        """Kinetic plus gravitational energy (J) of ball i at x (m), v (m/s)."""
        b = self.balls
        energy = float(0.5 * b.mass[i] * (v @ v) - b.mass[i] * (b.g @ x))
        if self.act.friction is not None:
            w = self.act.spin(i)
            energy += float(0.2 * b.mass[i] * b.radius[i] ** 2 * (w @ w))
        return energy

    def elastic(self, i: int) -> float:
        """Elastic energy (J) of the contacts of ball i: its plate contact (resting, asleep or
        not) and half of each ball-ball contact (the other half is its partner's)."""
        if i not in self.act.members:
            if i in self.asleep:
                return self.asleep[i]
            if self.balls.status[i] != SLIDE:
                return 0.0
            return float(elastic_energy(self.balls.static_pen[i], self.balls.plate_law(i)))
        return self.act.elastic_energy_of(i)

    def final(self, t: float) -> None:
        """The energy (J) of the balls still on the plate at the end, time t (s)."""
        b = self.balls
        total = 0.0
        for i in np.flatnonzero((b.status != GONE) & (b.status != PENDING)):
            i = int(i)
            x, v = self.act.state(i) if b.in_set[i] else b.state(i, t)
            total += self.ball_energy(i, x, v) + self.elastic(i)
        self.stats["energy_final"] = total
