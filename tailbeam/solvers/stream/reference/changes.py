"""Changes of the stream reference's scene at an event or a release: a contact starts or
ends, a region flag of a pair flips, a ball leaves over an edge (dropped from the state with
its pairs) or enters at its release time (added with its pairs).
"""

import numpy as np

from tailbeam.physics.contact_law import clamp_indicator
from tailbeam.physics.hertz import hertz_max_penetration
from tailbeam.physics.incline import EDGES
from tailbeam.results.records import End, EventKind
from tailbeam.solvers.stream.reference.events import COULOMB, FORCE_BAND
from tailbeam.solvers.stream.reference.friction import slip_speed


class SceneChanges:
    """Applies events and releases to the pairs, the state layout and the state vector.

    Parameters
    ----------
    layout : StateLayout
        Which balls are present.
    pairs : PairSet
        The watched pairs.
    kinematics : Kinematics
        The pairs' contact kinematics.
    log : ContactLog
        The records written out.
    balls : list of Ball
        The scene's balls (a released ball starts at its given position and velocity).
    mass : ndarray
        Mass of every ball (kg).
    rtol : float
        DOP853's relative tolerance (sets the first step of a contact).
    waiting : list of (float, int)
        Release time (s) and index of the balls not yet present, in time order.
    """

    def __init__(self, layout, pairs, kinematics, log, balls, mass, rtol, waiting):
        self.layout = layout
        self.pairs = pairs
        self.kinematics = kinematics
        self.log = log
        self.balls = balls
        self.mass = mass
        self.rtol = rtol
        self.waiting = list(waiting)
        self.radius = np.array([b.radius for b in balls], dtype=float)
        self.coulomb = None  # a CoulombState where a pair has Coulomb's law (set by the solver)

    def slip(self, pair, y) -> float:
        """The slip speed (m/s) of ``pair`` at state vector y (nan without friction)."""
        x, v = self.layout.split(y)
        modes = self.layout.modes(y)
        modes = None if modes is None else tuple(a[None] for a in modes)
        return slip_speed(pair, self.kinematics, self.radius, x, v, self.layout.spins(y), modes)

    def next_stop(self, duration):
        """Where the integration must stop next (s): the next release time or ``duration``."""
        return min(duration, self.waiting[0][0]) if self.waiting else duration

    def apply(self, key, t, y):
        """Apply the event of row ``key`` (``RowKey``) at time t (s) with state vector y.

        Returns the state vector after it and the first step (s) to try next (None: the
        solver's choice).
        """
        kind, k = key
        if kind == EventKind.LEAVE:
            return self.leave(k[0], EDGES[k[1]], t, y), None
        p = self.pairs[k]
        x, v = self.layout.split(y)
        kin, li, lj, _ = self.kinematics.of([p], x, v, self.layout.modes(y))
        if kind == EventKind.CONTACT_START:
            self.log.open(p, t, kin, x[li[0]], v, li[0], lj[0])
            self.start_modes(p, y)
            return y, first_contact_step(p, self.mass, self.rtol, kin.rate[0])
        if kind == EventKind.CONTACT_END:
            self.log.close(p, t, kin, v, li[0], lj[0], End.SEPARATED, self.slip(p, y))
            return y, None
        if kind in COULOMB:
            self.switch(kind, p, t, y)
            return y, None
        if kind == EventKind.FULL_DAMPING:
            p.ramp = not p.ramp
        else:
            p.clamped = not p.clamped
            kind = EventKind.CLAMP_ON if p.clamped else EventKind.CLAMP_OFF
        self.log.log(t, kind, p)
        return y, None

    def _friction_of(self, p, y):
        """(normal force N, ``PairFriction`` row, rolling radius m) of pair ``p`` in contact
        at state vector y, with Coulomb's law's constraint forces (``CoulombState``)."""
        x, v = self.layout.split(y)
        pairs, f, fr, table = self.coulomb.at(x, v, self.layout.spins(y))
        q = next(k for k, other in enumerate(pairs) if other is p)
        one = type(fr)(*(getattr(fr, name)[q] for name in fr.__dataclass_fields__))
        return abs(f[q]), one, table.roll_radius[q]

    def start_modes(self, p, y) -> None:
        """Coulomb's law: a contact starts stuck if its slip is exactly zero (else sliding
        along it), its rolling held if its rolling velocity is exactly zero (with mu_r > 0)."""
        if not p.coulomb:
            return
        _fn, fr, radius = self._friction_of(p, y)
        speed, rate = np.linalg.norm(fr.slip), radius * np.linalg.norm(fr.roll)
        p.stuck = bool(speed == 0.0 and p.friction.static > 0.0)
        p.slide_dir = fr.slip / speed if speed > 0.0 else np.zeros(3)
        p.held = bool(rate == 0.0 and p.friction.rolling > 0.0)
        p.roll_dir = radius * fr.roll / rate if rate > 0.0 else np.zeros(3)

    def switch(self, kind, p, t, y) -> None:
        """Apply Coulomb's law's event ``kind`` of pair ``p`` at time t (s), state y: a stuck
        contact (held rolling) breaks loose opposite to the force (torque) that held it; a
        sliding (rolling) one sticks (is held) if the force (torque) that keeps it so is
        within mu_s |F_n| (mu_r R |F_n|), else it slides (rolls) on, opposite to it."""
        sliding = kind in (EventKind.STICK, EventKind.SLIP)
        if kind in (EventKind.STICK, EventKind.ROLL_HOLD):
            setattr(p, "stuck" if sliding else "held", True)
        fn, fr, radius = self._friction_of(p, y)
        load = fr.force if sliding else fr.rolling
        size = float(np.linalg.norm(load))
        limit = (p.friction.static if sliding else p.friction.rolling * radius) * fn
        holds = kind in (EventKind.STICK, EventKind.ROLL_HOLD) and size <= limit + FORCE_BAND
        if not holds:
            direction = -load / size if size > 0.0 else np.zeros(3)
            if sliding:
                p.stuck, p.slide_dir = False, direction
            else:
                p.held, p.roll_dir = False, direction
        if holds or kind in (EventKind.SLIP, EventKind.ROLL_FREE):
            self.log.log(t, kind, p)

    def leave(self, ball, edge, t, y):
        """Ball ``ball`` (index) leaves over ``edge`` at time t (s): its contacts end, it and
        its pairs are dropped. Returns the state vector without it."""
        x, v = self.layout.split(y)
        modes, w = self.layout.modes(y), self.layout.spins(y)
        for p in self.pairs.drop_ball(ball):
            if p.in_contact:
                kin, li, lj, _ = self.kinematics.of([p], x, v, modes)
                self.log.close(p, t, kin, v, li[0], lj[0], End.LEFT, self.slip(p, y))
        self.log.left(ball, edge, t, None if w is None else w[self.layout.active.index(ball)])
        keep = self.layout.remove(ball)
        return self.layout.join(x[keep], v[keep], modes, None if w is None else w[keep])

    def release_due(self, t, y):
        """Add the balls whose release time is t (s), at their given position and velocity,
        with their pairs. Returns the state vector with them."""
        x, v = self.layout.split(y)
        modes, w = self.layout.modes(y), self.layout.spins(y)
        new = []
        while self.waiting and self.waiting[0][0] <= t:
            _, i = self.waiting.pop(0)
            self.layout.add(i)
            x = np.vstack([x, self.balls[i].position])
            v = np.vstack([v, self.balls[i].velocity])
            if w is not None:
                w = np.vstack([w, self.balls[i].angular_velocity])
            new.extend(self.pairs.add_ball(i, self.layout.active))
            self.log.released(i, t)
        y = self.layout.join(x, v, modes, w)
        self.touch(new, t, y)
        return y

    def touch(self, pairs, t, y) -> None:
        """Pairs overlapping at state y when they appear (time t, s) start in contact, in the
        region of their penetration (e.g. a ball placed at its static penetration)."""
        x, v = self.layout.split(y)
        for p in pairs:
            kin, li, lj, _ = self.kinematics.of([p], x, v, self.layout.modes(y))
            if kin.penetration[0] > 0.0:
                self.log.open(p, t, kin, x[li[0]], v, li[0], lj[0])
                p.ramp = bool(kin.penetration[0] < p.law.penetration) or not p.kinked
                ind = clamp_indicator(kin.penetration[0], kin.rate[0], p.law, p.ramp)
                p.clamped = bool(p.law.clamp and p.kinked and ind < 0.0)
        for p in pairs:
            if p.in_contact:
                self.start_modes(p, y)


def first_contact_step(pair, mass, rtol, rate):
    """First step (s) after ``pair`` touches at penetration rate ``rate`` (m/s): tau^(e+2)
    reaches rtol at t_s rtol^(1/(e+2)) (t_s: the Hertz contact time scale), at most the
    time to penetrate d / 2.

    Parameters
    ----------
    pair : Pair
        The pair (its balls' masses from ``mass``, kg, and its law).
    mass : ndarray
        Mass of every ball (kg).
    rtol : float
        DOP853's relative tolerance.
    rate : float
        Penetration rate at the touch (m/s); at least 1e-3 m/s is assumed.
    """
    m_i = mass[pair.i]
    m = m_i if pair.j < 0 else m_i * mass[pair.j] / (m_i + mass[pair.j])
    speed = max(rate, 1e-3)
    law = pair.law
    t_s = hertz_max_penetration(m, speed, law.stiffness, law.exponent) / speed
    return min(t_s * rtol ** (1.0 / (law.exponent + 2.0)), 0.5 * law.penetration / speed)
