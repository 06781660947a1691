"""The stream reference's bookkeeping: pairs, contacts, leaves and releases (a mixin of
``tailbeam.solvers.stream.reference.solver._Reference``, which provides ``balls``, ``mass``,
``incline``, ``table``, ``plate``, ``rtol``, ``active``, ``waiting``, ``pairs``, ``t``,
``y``, ``contacts``, ``leaves``, ``events`` and the state layout of ``reference_state``).

Every pair is a ``_Pair`` (ball-ball or ball-plate: its law, its region flags, its open
records); an event found by ``reference_events`` is applied here (``apply``): a contact
starts or ends (one ``Impact`` per ball), a region flag flips, or a ball leaves over
an edge and is dropped from the state.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from tailbeam.physics.contact_law import (
    ImpactLaw,
    clamp_indicator,
)
from tailbeam.physics.hertz import hertz_max_penetration
from tailbeam.physics.incline import EDGES
from tailbeam.results.records import PLATE, Event, EventKind, Impact, LeaveEvent


@dataclass
class _Pair:
    """A watched pair: ball i and ball j (j = -1: the plate), its law and region flags."""

    i: int
    j: int
    law: ImpactLaw
    radius_sum: float
    in_contact: bool = False
    ramp: bool = True
    clamped: bool = False
    records: list = field(default_factory=list)
    peak: float = 0.0
    t_peak: float = math.nan
    pen: float = 0.0
    phi0: np.ndarray | None = None  # shapes kept by a frozen plate contact (modal plate)

    @property
    def kinked(self) -> bool:
        """Whether the law has a STEP kink at delta = d (it does only with damping)."""
        return self.law.damping > 0.0


class ReferenceContacts:
    """Pairs, contacts, leaves and releases of the stream reference."""

    def apply(self, key, t, y):
        """Apply event ``key`` at time t with state y; returns the next first step (s)."""
        self.t, self.y = float(t), y
        t = self.t
        kind, k = key
        if kind == EventKind.LEAVE:
            self.leave(k[0], EDGES[k[1]], t)
            return None
        p = self.pairs[k]
        x, v = self.split(y)
        kin, li, lj, _ = self.kinematics([p], x, v, self.modes(y))
        if kind == EventKind.CONTACT_START:
            self.open_contact(p, t, kin, x[li[0]], v, li[0], lj[0])
            return self.first_contact_step(p, kin.rate[0])
        if kind == EventKind.CONTACT_END:
            self.close_contact(p, t, kin, v, li[0], lj[0], "separated")
            return None
        if kind == EventKind.FULL_DAMPING:
            p.ramp = not p.ramp
        else:
            p.clamped = not p.clamped
            kind = EventKind.CLAMP_ON if p.clamped else EventKind.CLAMP_OFF
        self.log(t, kind, p)
        return None

    def log(self, t, kind, p):
        self.events.append(Event(t, self.balls[p.i].name, kind, self.partner_name(p)))

    def partner_name(self, p):
        return PLATE if p.j < 0 else self.balls[p.j].name

    def first_contact_step(self, p, rate):
        """tau^(e+2) reaches rtol at t_s rtol^(1/(e+2)) (as in the rigid reference)."""
        m_i = self.mass[p.i]
        m = m_i if p.j < 0 else m_i * self.mass[p.j] / (m_i + self.mass[p.j])
        speed = max(rate, 1e-3)
        t_s = hertz_max_penetration(m, speed, p.law.stiffness, p.law.exponent) / speed
        return min(
            t_s * self.rtol ** (1.0 / (p.law.exponent + 2.0)), 0.5 * p.law.penetration / speed
        )

    def open_contact(self, p, t, kin, x_i, v, li, lj):
        p.in_contact, p.ramp, p.clamped = True, True, False
        p.peak, p.t_peak, p.pen = 0.0, math.nan, max(0.0, float(kin.penetration[0]))
        if p.j < 0 and self.plate is not None and self.plate.frozen:
            p.phi0 = self.plate.shapes_at(x_i[:2])[0]
        n = kin.normal[0]
        point = x_i - n * (self.balls[p.i].radius - 0.5 * max(kin.penetration[0], 0.0))
        rate = float(kin.rate[0]) if p.j >= 0 or self.plate is None else float(-v[li] @ n)
        p.records = [
            Impact(ball=self.balls[p.i].name, partner=self.partner_name(p), t_start=t,
                   x=point[0], y=point[1], v_in=float(-v[li] @ n), approach_in=rate)
        ]  # fmt: skip
        if p.j >= 0:
            p.records.append(
                Impact(ball=self.balls[p.j].name, partner=self.balls[p.i].name, t_start=t,
                       x=point[0], y=point[1], v_in=float(v[lj] @ n), approach_in=rate)
            )  # fmt: skip
        self.contacts.extend(p.records)
        self.log(t, EventKind.CONTACT_START, p)

    def close_contact(self, p, t, kin, v, li, lj, end):
        n = kin.normal[0]
        outs = [float(v[li] @ n)] + ([float(-v[lj] @ n)] if p.j >= 0 else [])
        # approach speeds of a plate row: the ball's (as v_in, v_out), also on the modal plate
        out = -float(kin.rate[0]) if p.j >= 0 or self.plate is None else outs[0]
        for rec, v_out in zip(p.records, outs, strict=True):
            rec.t_end, rec.v_out, rec.approach_out, rec.end = t, v_out, out, end
            rec.peak_force, rec.t_peak, rec.max_penetration = p.peak, p.t_peak, p.pen
        p.in_contact, p.records, p.phi0 = False, [], None
        self.log(t, EventKind.CONTACT_END, p)

    def leave(self, ball, edge, t):
        x, v = self.split(self.y)
        modes = self.modes(self.y)
        for pk in [pk for pk in self.pairs if ball in pk]:
            p = self.pairs.pop(pk)
            if p.in_contact:
                kin, li, lj, _ = self.kinematics([p], x, v, modes)
                self.close_contact(p, t, kin, v, li[0], lj[0], "left")
        self.leaves.append(LeaveEvent(self.balls[ball].name, t, edge))
        self.events.append(Event(t, self.balls[ball].name, EventKind.LEAVE, edge))
        keep = [q for q, b in enumerate(self.active) if b != ball]
        self.active = [self.active[q] for q in keep]
        self.y = self.join(x[keep], v[keep], modes)

    def next_stop(self, duration):
        """Where the integration must stop next: the next release time or the end."""
        return min(duration, self.waiting[0][0]) if self.waiting else duration

    def release_due(self, t, y):
        """Add the balls whose release time is t (their given state), with their pairs."""
        self.t, self.y = t, y
        x, v = self.split(y)
        modes = self.modes(y)
        new = []
        while self.waiting and self.waiting[0][0] <= t:
            _, i = self.waiting.pop(0)
            ball = self.balls[i]
            self.active.append(i)
            x = np.vstack([x, ball.position])
            v = np.vstack([v, ball.velocity])
            new.extend(self.add_pairs(i))
            self.events.append(Event(t, ball.name, EventKind.RELEASE, ""))
        self.y = self.join(x, v, modes)
        self.touch(new, t)
        return None

    def add_pairs(self, i):
        """Create the pairs of ball i with the plate and with every other active ball."""
        a, made = self.balls[i], []
        law = self.table.law(i, PLATE)
        made.append(self.pairs.setdefault((i, -1), _Pair(i, -1, law, a.radius)))
        for j in self.active:
            if j != i:
                lo, hi = min(i, j), max(i, j)
                b, c = self.balls[lo], self.balls[hi]
                law = self.table.law(lo, hi)
                pair = _Pair(lo, hi, law, b.radius + c.radius)
                made.append(self.pairs.setdefault((lo, hi), pair))
        return made

    def touch(self, pairs, t):
        """Pairs overlapping when they appear start in contact (e.g. a ball placed at its
        static penetration)."""
        x, v = self.split(self.y)
        for p in pairs:
            kin, li, lj, _ = self.kinematics([p], x, v, self.modes(self.y))
            if kin.penetration[0] > 0.0:
                self.open_contact(p, t, kin, x[li[0]], v, li[0], lj[0])
                p.ramp = bool(kin.penetration[0] < p.law.penetration) or not p.kinked
                ind = clamp_indicator(kin.penetration[0], kin.rate[0], p.law, p.ramp)
                p.clamped = bool(p.law.clamp and p.kinked and ind < 0.0)
