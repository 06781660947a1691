"""The stream driver's records: contacts as ``Impact``, the plate's loads for the
sensors, and the energy ledger (``tailbeam.solvers.stream.driver.loop``; a mixin of its event loop,
which provides ``balls``, ``act``, ``t``, ``open``, ``contacts``, ``events``, ``loads``,
``dead_loads``, ``limit``, ``rest_speed`` and ``stats``)."""

import math

import numpy as np

from tailbeam.physics.contact_law import elastic_energy
from tailbeam.physics.hertz import hertz_contact_duration
from tailbeam.results.records import PLATE, Event, EventKind, Impact
from tailbeam.solvers.stream.driver.balls import GONE, PENDING, SLIDE

REST_CONTACT_FACTOR = 50.0  # a plate contact longer than this many Hertz durations is at rest


class StreamRecords:
    """Records, loads and the energy ledger of the stream driver."""

    def _normal(self, key):
        """Contact normal (from partner to ball i), penetration (m), the balls' states."""
        i, j = key
        xi, vi = self.act.state(i)
        if j < 0:
            return np.array([0.0, 0.0, 1.0]), self.balls.radius[i] - xi[2], xi, vi, None
        xj, vj = self.act.state(j)
        d = xi - xj
        dist = math.sqrt(d @ d)
        return d / dist, self.balls.radius[i] + self.balls.radius[j] - dist, xi, vi, vj

    def _open(self, key):
        b, t = self.balls, self.t
        i, j = key
        n, pen, xi, vi, vj = self._normal(key)
        point = xi - n * (b.radius[i] - 0.5 * max(pen, 0.0))
        w = vi - (vj if vj is not None else 0.0)
        rate = float(-(w @ n))
        partner = PLATE if j < 0 else b.names[j]
        recs = [
            Impact(ball=b.names[i], partner=partner, t_start=t, x=point[0], y=point[1],
                   v_in=float(-(vi @ n)), approach_in=rate)
        ]  # fmt: skip
        if j >= 0:
            recs.append(
                Impact(ball=b.names[j], partner=b.names[i], t_start=t, x=point[0], y=point[1],
                       v_in=float(vj @ n), approach_in=rate)
            )  # fmt: skip
        self.act.reset_accumulators(key)
        self.open[key] = recs
        if j < 0:
            self.limit[i] = t + REST_CONTACT_FACTOR * self._hertz_duration(i, recs[0].v_in)
        self.contacts.extend(recs)
        self.events.append(Event(t, b.names[i], EventKind.CONTACT_START, partner))

    def _hertz_duration(self, i: int, speed: float) -> float:
        """Hertz contact duration (s) of ball i on the plate at ``speed`` (>= rest_speed)."""
        law = self.balls.plate_law(i)
        speed = max(speed, self.rest_speed, 1e-3)
        return hertz_contact_duration(self.balls.mass[i], speed, law.stiffness, law.exponent)

    def _close(self, key, end: str):
        if key[1] < 0:
            self.limit.pop(key[0], None)
        n, _pen, _xi, vi, vj = self._normal(key)
        recs = self.open.pop(key)
        w = vi - (vj if vj is not None else 0.0)
        outs = [float(vi @ n)] + ([float(-(vj @ n))] if vj is not None else [])
        peak, t_peak, pen = self.act.accumulators(key)
        for rec, v_out in zip(recs, outs, strict=True):
            rec.t_end, rec.v_out, rec.approach_out, rec.end = self.t, v_out, float(w @ n), end
            rec.peak_force, rec.t_peak, rec.max_penetration = peak, t_peak, pen
        self.events.append(Event(self.t, recs[0].ball, EventKind.CONTACT_END, recs[0].partner))

    def _flush_nodes(self, i: int):
        """Hand the plate force history of ball i recorded so far to the loads."""
        piece = self.act.take_plate_forces(i)
        if piece is not None:
            self.loads.append(piece)

    def _dead_load(self, i: int, t_to: float, step: float = 2e-3):
        """Ball i slid from slide_since to t_to: its weight as constant loads on pieces of
        at most ``step`` m of travel (each at its middle point)."""
        b = self.balls
        t_from = b.slide_since[i]
        b.slide_since[i] = math.nan
        if not t_to > t_from:
            return
        x0, v0 = b.state(i, t_from)
        x1, _ = b.state(i, t_to)
        k = max(1, math.ceil(math.dist(x0[:2], x1[:2]) / step))
        edges = np.linspace(t_from, t_to, k + 1)
        mid, _ = b.states(np.full(k, i), 0.5 * (edges[:-1] + edges[1:]))
        weight = b.mass[i] * -b.g[2]
        for q in range(k):
            self.dead_loads.append((mid[q, 0], mid[q, 1], edges[q], edges[q + 1], weight))

    def _ball_energy(self, i: int, x, v) -> float:
        """Kinetic plus gravitational energy of ball i (J; potential 0 at the origin)."""
        b = self.balls
        return float(0.5 * b.mass[i] * (v @ v) - b.mass[i] * (b.g @ x))

    def _elastic(self, i: int) -> float:
        """Elastic energy (J) of the contacts of ball i: its plate contact (quiet or not) and
        half of each ball-ball contact (the other half is its partner's)."""
        if i not in self.act.members:
            if self.balls.status[i] != SLIDE:
                return 0.0
            return float(elastic_energy(self.balls.static_pen[i], self.balls.plate_law(i)))
        return self.act.elastic_energy_of(i)

    def _final_energy(self) -> float:
        b = self.balls
        total = 0.0
        for i in np.flatnonzero((b.status != GONE) & (b.status != PENDING)):
            i = int(i)
            x, v = self.act.state(i) if b.in_set[i] else b.state(i, self.t)
            total += self._ball_energy(i, x, v) + self._elastic(i)
        return total
