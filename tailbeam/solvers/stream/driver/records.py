"""The stream driver's records: each contact as ``Impact`` records (one per ball), the
events in time order and the balls that left the plate.

A plate contact is also given a time limit, REST_CONTACT_FACTOR Hertz contact durations
after its start: a plate contact still alone past it is put at rest (``membership``).
"""

import math

import numpy as np

from tailbeam.physics.hertz import hertz_contact_duration
from tailbeam.results.records import PLATE, Event, EventKind, Impact, LeaveEvent
from tailbeam.solvers.stream.active.compiled.friction import IMP_N, IMP_T, IMP_WORK

REST_CONTACT_FACTOR = 50.0  # a plate contact longer than this many Hertz durations is at rest


class ContactRecords:
    """Contacts in progress and done, events and leaves of a run.

    Parameters
    ----------
    balls : Balls
        The stream's balls (names, radii, plate laws).
    act : ActiveMembers
        The active set (its members' states and pair accumulators).
    clock : Clock
        The driver's time.
    rest_speed : float
        Speed (m/s) below which a plate contact ends at rest.
    """

    def __init__(self, balls, act, clock, rest_speed: float):
        self.balls, self.act, self.clock, self.rest_speed = balls, act, clock, rest_speed
        self.open = {}  # pair key -> [Impact(s)] of the contacts in progress
        self.limit = {}  # ball -> time (s) at which its plate contact is declared at rest
        self.contacts, self.events, self.leaves = [], [], []

    # --- contacts ---------------------------------------------------------------------------
    def is_open(self, key) -> bool:
        """Whether contact ``key`` ((i, -1) on the plate, (i, j) two balls) is in progress."""
        return key in self.open

    def start(self, key) -> None:
        """Contact ``key`` starts now: its records, its event, its rest limit (plate)."""
        b, t = self.balls, self.clock.t
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
        if j < 0 and self.act.friction is None:  # (with friction: integrated while it lasts)
            self.limit[i] = t + REST_CONTACT_FACTOR * self._hertz_duration(i, recs[0].v_in)
        self.contacts.extend(recs)
        self.events.append(Event(t, b.names[i], EventKind.CONTACT_START, partner))

    def close(self, key, end) -> None:
        """Contact ``key`` ends now, how: ``end`` (an ``End``)."""
        if key[1] < 0:
            self.limit.pop(key[0], None)
        n, _pen, _xi, vi, vj = self._normal(key)
        recs = self.open.pop(key)
        w = vi - (vj if vj is not None else 0.0)
        outs = [float(vi @ n)] + ([float(-(vj @ n))] if vj is not None else [])
        peak, t_peak, pen = self.act.accumulators(key)
        t = self.clock.t
        for rec, v_out in zip(recs, outs, strict=True):
            rec.t_end, rec.v_out, rec.approach_out, rec.end = t, v_out, float(w @ n), end
            rec.peak_force, rec.t_peak, rec.max_penetration = peak, t_peak, pen
        self._friction(key, recs)
        self.events.append(Event(t, recs[0].ball, EventKind.CONTACT_END, recs[0].partner))

    def finish(self) -> None:
        """The end of the run: the contacts in progress get their peaks so far (their end
        stays ``End.DURATION``); the records in order of start and ball."""
        for key in list(self.open):
            recs = self.open.pop(key)
            peak, t_peak, pen = self.act.accumulators(key)
            for rec in recs:
                rec.peak_force, rec.t_peak, rec.max_penetration = peak, t_peak, pen
            self._friction(key, recs)
        self.contacts.sort(key=lambda r: (r.t_start, r.ball))

    def _friction(self, key, recs) -> None:
        """With friction: the contact's impulses, how it ended tangentially (its slip speed
        now against the stiction velocity) and the energy friction dissipated in it (to
        ``stats["energy_friction"]``)."""
        act = self.act
        if act.friction is None:
            return
        imp = act.impulses(key)
        i, j = key
        xi, vi = act.state(i)
        partner = (None, None, None) if j < 0 else (*act.state(j), act.spin(j))
        end = act.friction.end(key, xi, vi, act.spin(i), *partner,
                               surface=act.surface_velocity(key))  # fmt: skip
        tangential = float(np.linalg.norm(imp[IMP_T : IMP_T + 3]))
        for rec in recs:
            rec.normal_impulse, rec.tangential_impulse = float(imp[IMP_N]), tangential
            rec.tangential_end = end
        self.clock.stats["energy_friction"] += float(imp[IMP_WORK])

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

    def _hertz_duration(self, i: int, speed: float) -> float:
        """Hertz contact duration (s) of ball i on the plate at ``speed`` (>= rest_speed)."""
        law = self.balls.plate_law(i)
        speed = max(speed, self.rest_speed, 1e-3)
        return hertz_contact_duration(self.balls.mass[i], speed, law.stiffness, law.exponent)

    # --- rest limits ------------------------------------------------------------------------
    def due_rests(self, t: float) -> list:
        """Balls whose plate contact has reached its rest limit by t (s), in start order."""
        return [i for i, t_limit in self.limit.items() if t_limit <= t]

    def rest_limits(self, balls, t: float) -> list:
        """The rest limits (s) of ``balls`` still ahead of t (s)."""
        return [self.limit[i] for i in balls if i in self.limit and self.limit[i] > t]

    # --- events -----------------------------------------------------------------------------
    def event(self, t: float, i: int, kind, partner: str) -> None:
        """Ball i's event ``kind`` (an ``EventKind``) at t (s) with ``partner``."""
        self.events.append(Event(t, self.balls.names[i], kind, partner))

    def leave(self, i: int, t: float, edge: str) -> None:
        """Ball i left the plate over ``edge`` at t (s)."""
        self.leaves.append(LeaveEvent(self.balls.names[i], t, edge))
        self.event(t, i, EventKind.LEAVE, edge)
