"""A minimal driver for tests: every ball of a small scene in ONE active set, all pairs watched,
restarted after every event; writes the same Impact / LeaveEvent records as the stream
reference (not a test module; the fast solver's real driver is
tailbeam/solvers/stream/driver/loop.py)."""

import math

import numpy as np

from tailbeam.physics.incline import EDGES
from tailbeam.physics.pair import pair_kinematics, plate_foot
from tailbeam.results.records import PLATE, EventCode, Impact, LeaveEvent
from tailbeam.solvers.stream.active.compiled.pairs import GONE
from tailbeam.solvers.stream.active.integrator.set import ActiveSet


def reference_pairs(n):
    """Pairs in the order the reference creates them: (i, plate), then (min, max) with every
    other ball."""
    pairs = []
    for i in range(n):
        pairs.append((i, -1))
        for j in range(n):
            if j != i and (min(i, j), max(i, j)) not in pairs:
                pairs.append((min(i, j), max(i, j)))
    return pairs


class SceneRun:
    """Runs ``balls`` on ``incline`` for ``duration`` s; ``contacts``, ``leaves``, ``times``,
    ``energy`` (J) and ``states`` (x, v, touching) at every return of ``advance`` (events and
    every ``sample`` s)."""

    def __init__(self, balls, incline, duration, *, sample=None, settle_energy=None, **kwargs):
        self.balls, self.incline = balls, incline
        self.names = [b.name for b in balls]
        law_keys = ("damping", "penetration", "clamp", "exponent")
        options = {k: kwargs.pop(k) for k in law_keys if k in kwargs}
        pairs = reference_pairs(len(balls))
        self.set = ActiveSet.from_balls(
            balls, pairs, incline, settle_energy=settle_energy, **options, **kwargs
        )
        self.contacts, self.leaves, self.settled = [], [], []
        self.open = {}
        self.times, self.energy, self.returns, self.states = [], [], [], []
        for p in np.flatnonzero(self.set.contacts.touching):
            self.start(int(p), 0.0)
        self.run(duration, sample or duration)

    def kin(self, p):
        s = self.set
        i, j = int(s.model.pi[p]), int(s.model.pj[p])
        xj = plate_foot(s.x[i][None]) if j < 0 else s.x[j][None]
        vj = np.zeros((1, 3)) if j < 0 else s.v[j][None]
        return i, j, pair_kinematics(s.x[i][None], s.v[i][None], xj, vj, [s.model.rsum[p]])

    def start(self, p, t):
        i, j, kin = self.kin(p)
        n = kin.normal[0]
        point = self.set.x[i] - n * (self.set.model.radius[i] - 0.5 * max(kin.penetration[0], 0.0))
        rate = float(kin.rate[0])
        partner = PLATE if j < 0 else self.names[j]
        recs = [Impact(ball=self.names[i], partner=partner, t_start=t, x=point[0], y=point[1],
                       v_in=float(-self.set.v[i] @ n), approach_in=rate)]  # fmt: skip
        if j >= 0:
            recs.append(Impact(ball=self.names[j], partner=self.names[i], t_start=t,
                               x=point[0], y=point[1], v_in=float(self.set.v[j] @ n),
                               approach_in=rate))  # fmt: skip
        self.contacts.extend(recs)
        self.open[p] = recs

    def end(self, p, t, how):
        i, j, kin = self.kin(p)
        n = kin.normal[0]
        outs = [float(self.set.v[i] @ n)] + ([float(-self.set.v[j] @ n)] if j >= 0 else [])
        for rec, v_out in zip(self.open.pop(p), outs, strict=True):
            rec.t_end, rec.v_out, rec.approach_out, rec.end = t, v_out, -float(kin.rate[0]), how
            self.finish(rec, p)

    def finish(self, rec, p):
        c = self.set.contacts
        rec.peak_force, rec.t_peak, rec.max_penetration = c.peak[p], c.t_peak[p], c.pen[p]

    def record(self, t):
        s = self.set
        m, alive = s.model.mass, s.model.alive != GONE
        e = 0.5 * float(np.sum(m[alive, None] * s.v[alive] ** 2))
        e -= float(np.sum(m[alive] * (s.x[alive] @ s.model.g)))
        for p in np.flatnonzero(s.contacts.touching):
            k, ex = s.model.law[p, 0], s.model.law[p, 1]
            delta = s.penetration(p)[0]
            e += k * max(delta, 0.0) ** (ex + 1.0) / (ex + 1.0)
        self.times.append(t)
        self.energy.append(e)
        self.states.append((s.x.copy(), s.v.copy(), s.contacts.touching.copy()))

    def run(self, duration, sample):
        t = 0.0
        self.record(t)
        while t < duration:
            out = self.set.advance(t, min(duration, (math.floor(t / sample + 1e-9) + 1) * sample))
            t = out.t
            self.returns.append(out)
            if out.code == EventCode.CONTACT_START:
                self.start(out.index, t)
            elif out.code == EventCode.CONTACT_END:
                self.end(out.index, t, "separated")
            elif out.code == EventCode.LEAVE:
                b = out.index
                for p in [
                    p for p in self.open if b in (self.set.model.pi[p], self.set.model.pj[p])
                ]:
                    self.end(p, t, "left")
                self.leaves.append(LeaveEvent(self.names[b], t, EDGES[out.edge]))
                self.set.remove_ball(b)
            elif out.code == EventCode.REST:
                self.settled.append((self.names[out.index], t))
                break
            self.record(t)
        for p, recs in self.open.items():
            for rec in recs:
                self.finish(rec, p)
