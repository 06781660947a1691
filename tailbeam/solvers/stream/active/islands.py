"""The active set split into islands, each integrated with its own step (rigid plate).

One ``ActiveMembers`` integrates all its members with one DOP853 state: every member pays
the step of the stiffest contact among them. On the rigid plate the members fall into
islands that cannot touch each other before the horizon (``group``): each island is its
own ``ActiveMembers``, stepped on its own, and only the earliest event of all is returned.

Grouping is certified, not guessed. Until a contact between two islands starts, the
energy an island's ball can receive is bounded by its island's kinetic (rotation included)
and elastic energy plus the work gravity can do on the island within the horizon
(``reach``), so its speed is bounded (``speed_bounds``); islands whose balls, moving at
those speeds, stay more than their radii apart over the horizon cannot touch within it
(merged until no two can: the bound of a merged island pools both). The grouping is made
again at the first call past its horizon and after a change of the members; two islands
whose balls start a contact found outside (``start_contact``) are merged at once.

All islands are at one time between calls. ``next_event`` advances each island in turn
up to the earliest event found so far; an island that went past an event found later is
put back (``ActiveSet.snapshot``) and advanced again up to it, so each island's steps are
its own and events come in time order, as from one set. Two islands' events at the same
instant are returned one per call.

Sleeping balls an island's members could touch within the horizon are its FIXED obstacles
(``ActiveMembers.set_fixed``; assigned at each grouping, ``group``): a FIXED ball moves
neither, so it joins no two islands, and it may be an obstacle of several.

The modal plate couples every contact through its modes: there the driver keeps one set.
"""

import numpy as np

from tailbeam.results.records import EventCode
from tailbeam.solvers.stream.active.members import ActiveMembers
from tailbeam.solvers.stream.active.reach import group_speed_bounds

HORIZON = 1e-3  # s: the islands are grouped for at least this long (the driver's horizon)


class Islands:
    """The driver's active set as islands (``ActiveMembers`` each); the same interface.

    Parameters
    ----------
    balls, rtol, settle_energy, friction
        As ``ActiveMembers`` (rigid plate: no ``plate``, no ``dead_loads``).

    Attributes
    ----------
    members : list of int
        Every island's members.
    islands : list of ActiveMembers
        The islands (each with at least one member).
    kinks : list
        (t s, ``EventKind``, pair key) of the kinks of the last ``next_event``, in time
        order.
    forces : PlateForces
        The plate force histories of all the islands (shared).
    """

    plate = None
    modal = None
    tail_energy_dropped = 0.0

    def __init__(self, balls, rtol, settle_energy, friction=None):
        self.balls, self.rtol, self.friction = balls, rtol, friction
        self.settle_energy = settle_energy
        self.members, self.islands, self.kinks = [], [], []
        self.of = {}  # ball -> its island
        self.fixed = set()  # the FIXED obstacles (sleeping balls members may touch)
        self._now = 0.0
        self.forces = self._new().forces
        self.forces.pending = self._flush_of
        self.valid_until = -np.inf  # s: the grouping's horizon (stale: -inf)
        self.queued = []  # events of other islands at the instant last returned
        self.newcomers = None  # the island of the balls joining since the last call
        self.retired = dict.fromkeys(self._new().totals, 0)
        self.retired.update(
            island_regroups=0, island_replays=0, island_steps_undone=0, islands_max=0
        )

    def _new(self) -> ActiveMembers:
        act = ActiveMembers(self.balls, self.rtol, self.settle_energy, friction=self.friction)
        act.lazy_forces = True
        if hasattr(self, "forces"):
            act.forces = self.forces
        act.now = self._now
        return act

    @property
    def now(self) -> float:
        return self._now

    @now.setter
    def now(self, t: float) -> None:
        self._now = t
        for isl in self.islands:
            isl.now = t

    # --- membership -------------------------------------------------------------------------
    def add(self, i: int, x, v, *, quiet: bool):
        """Ball i joins the island of the balls joining since the last call (a woken cluster
        joins whole, its contacts touching) until the next grouping."""
        isl = self.newcomers
        if isl is None:
            isl = self.newcomers = self._new()
            self.islands.append(isl)
        isl.add(i, x, v, quiet=quiet)
        self.of[i] = isl
        self.members.append(i)
        self.valid_until = -np.inf

    # --- FIXED obstacles ---------------------------------------------------------------------
    def add_fixed(self, k: int, owner=None) -> None:
        """Sleeping ball k is a FIXED obstacle of the islands whose members could touch it
        (assigned at the next grouping, ``group``); ``owner``: a member touching it now,
        whose island holds it from now on."""
        if owner is not None:
            isl = self.of[owner]
            if k not in isl.fixed:
                isl.set_fixed(isl.fixed + [k])
        if k not in self.fixed:
            self.fixed.add(k)
            self.valid_until = -np.inf

    def remove_fixed(self, k: int) -> None:
        """Ball k is no FIXED obstacle any more."""
        self.fixed.discard(k)
        for isl in self.islands:
            if k in isl.fixed:
                isl.set_fixed([f for f in isl.fixed if f != k])

    def to_fixed(self, i: int) -> None:
        """Member i, frozen now, stays a FIXED obstacle of its island."""
        isl = self.of.pop(i)
        isl.to_fixed(i)
        self.members.remove(i)
        self.fixed.add(i)
        self.valid_until = -np.inf
        if not isl.members:
            self._retire(isl)

    def from_fixed(self, i: int) -> bool:
        """FIXED obstacle i wakes: the islands holding it merge into one, where it is a
        member at rest, its pairs going on. False if no island holds it."""
        holders = [isl for isl in self.islands if i in isl.fixed]
        self.fixed.discard(i)
        if not holders:
            return False
        if len(holders) > 1:
            merged = [m for isl in holders for m in isl.members]
            others = [isl.members for isl in self.islands if isl not in holders]
            self._regroup([merged] + others)
            holders = [self.of[merged[0]]]
        isl = holders[0]
        isl.from_fixed(i)
        self.of[i] = isl
        self.members.append(i)
        self.valid_until = -np.inf
        return True

    def remove(self, i: int):
        """Ball i leaves its island (an island left empty is dropped)."""
        isl = self.of.pop(i)
        isl.remove(i)
        self.members.remove(i)
        if not isl.members:
            self._retire(isl)

    def _flush_of(self, i: int) -> None:
        """The force rows of ball i's island into the histories (before i's are taken)."""
        isl = self.of.get(i)
        if isl is not None:
            isl.flush_forces()

    def _retire(self, isl) -> None:
        isl.flush_forces()
        for key, value in isl.stats().items():
            self.retired[key] += value
        self.islands.remove(isl)
        if isl is self.newcomers:
            self.newcomers = None

    def _regroup(self, groups, watch=None, fixed=None) -> None:
        """Make the islands ``groups`` (lists of balls): an island whose members stay
        together is kept as it is; the others are rebuilt from their balls' islands.
        ``watch``: the ball pairs that can touch (``group``; None: the new islands watch
        every pair of their members, the kept ones what they watched). ``fixed``: each
        group's FIXED obstacles (None: those of the islands its balls come from)."""
        kept = {frozenset(isl.members): isl for isl in self.islands}
        new = []
        for q, g in enumerate(groups):
            isl = kept.pop(frozenset(g), None)
            parts = list(dict.fromkeys(self.of[i] for i in g))
            obstacles = [k for p in parts for k in p.fixed] if fixed is None else fixed[q]
            if isl is None:
                isl = self._new()
                isl.adopt(g, [p.export() for p in parts])
                isl.watch = watch
                isl.set_fixed(obstacles)
            else:
                isl.set_fixed(obstacles)
                if watch is not None:
                    _narrow(isl, watch)
            new.append(isl)
        for isl in kept.values():  # (their members are in the new islands now)
            self._retire(isl)
        self.islands, self.newcomers = new, None
        for isl in new:
            for i in isl.members:
                self.of[i] = isl
        self.retired["islands_max"] = max(self.retired["islands_max"], len(new))

    def _merge(self, balls) -> ActiveMembers:
        """One island holding ``balls`` (their islands merged)."""
        parts = list(dict.fromkeys(self.of[i] for i in balls))
        if len(parts) == 1:
            return parts[0]
        merged = sorted({i for p in parts for i in p.members}, key=self.members.index)
        groups = [merged] + [isl.members for isl in self.islands if isl not in parts]
        self._regroup(groups)
        return self.of[balls[0]]

    # --- grouping ---------------------------------------------------------------------------
    def speed_bounds(self, groups, horizon: float, energy: dict) -> dict:
        """Ball -> speed bound (m/s) over ``horizon`` (s) while its group touches no other:
        the group's as an isolated group (``reach.group_speed_bounds``: its kinetic, rotation
        included, and elastic energy plus the work gravity can do on it within the
        horizon). ``energy``: ball -> its share of that energy now (``ball_energies``)."""
        b = self.balls
        g = float(np.linalg.norm(b.g))
        out = {}
        for grp in groups:
            pooled = sum(energy[i] for i in grp)
            for i, s in zip(grp, group_speed_bounds(pooled, b.mass[grp], g, horizon), strict=True):
                out[i] = float(s)
        return out

    def ball_energies(self, balls) -> np.ndarray:
        """As ``ActiveMembers.ball_energies``, the members ``balls`` in any islands."""
        out = np.zeros(len(balls))
        by = {}
        for k, i in enumerate(balls):
            by.setdefault(self.of[int(i)], []).append(k)
        for isl, ks in by.items():
            out[ks] = isl.ball_energies([balls[k] for k in ks])
        return out

    def group(self, horizon: float) -> tuple[list, set, list]:
        """The islands for the next ``horizon`` (s): touching balls together, then groups
        whose balls could come into contact within it (``speed_bounds``) merged until none
        can. Returns the islands (lists of balls, in member order), the pairs (i, j), i < j,
        that could touch within it (each island watches only those) and each island's FIXED
        obstacles (a FIXED ball joins no two islands: it moves neither)."""
        m = list(self.members)
        pos = {i: q for q, i in enumerate(m)}
        root = list(range(len(m)))

        def find(q):
            while root[q] != q:
                root[q] = root[root[q]]
                q = root[q]
            return q

        for isl in self.islands:
            for i, j in isl.touching_keys():
                if j >= 0 and i in pos and j in pos:  # (not through a FIXED obstacle)
                    root[find(pos[i])] = find(pos[j])
        x = self.positions(m)
        r = self.balls.radius[m]
        d2 = np.sum((x[:, None, :] - x[None, :, :]) ** 2, axis=2)
        energy = dict(zip(m, self.ball_energies(m).tolist(), strict=True))
        while True:
            groups = _groups(m, [find(q) for q in range(len(m))])
            s = self.speed_bounds(groups, horizon, energy)
            sv = np.array([s[i] for i in m])
            reach = r[:, None] + r[None, :] + (sv[:, None] + sv[None, :]) * horizon
            qi, qj = np.nonzero(np.triu(d2 <= reach**2, 1))
            joined = False
            for a, c in zip(qi, qj, strict=True):
                ra, rc = find(a), find(c)
                if ra != rc:
                    root[ra] = rc
                    joined = True
            if not joined:
                watch = {(min(m[a], m[c]), max(m[a], m[c])) for a, c in zip(qi, qj, strict=True)}
                fixed = self._obstacles(groups, m, x, r, sv, horizon, watch)
                return groups, watch, fixed

    def _obstacles(self, groups, m, x, r, sv, horizon: float, watch: set) -> list:
        """Each group's FIXED obstacles: those a member could touch within ``horizon`` at
        its speed bound ``sv`` (the members ``m`` at ``x``, radii ``r``); their pairs go into
        ``watch``."""
        out = [[] for _ in groups]
        if not self.fixed:
            return out
        fixed = sorted(self.fixed)
        xf = self.positions(fixed)
        rf = self.balls.radius[fixed]
        d2 = np.sum((x[:, None, :] - xf[None, :, :]) ** 2, axis=2)
        near = d2 <= (r[:, None] + rf[None, :] + sv[:, None] * horizon) ** 2
        group_of = {i: q for q, g in enumerate(groups) for i in g}
        for a, c in zip(*np.nonzero(near), strict=True):
            i, k = m[a], fixed[c]
            if k not in out[group_of[i]]:
                out[group_of[i]].append(k)
            watch.add((min(i, k), max(i, k)))
        return out

    # --- integration ------------------------------------------------------------------------
    def next_event(self, t: float, t_stop: float):
        """Integrate every island from t to t_stop (s) or the first event of any; returns as
        ``ActiveMembers.next_event``."""
        self.queued = [q for q in self.queued if self._still_members(q)]
        if self.queued:
            return self.queued.pop(0)
        self.newcomers = None
        if t_stop > self.valid_until:
            horizon = max(HORIZON, t_stop - t)
            self._regroup(*self.group(horizon))
            self.valid_until = t + horizon
            self.retired["island_regroups"] += 1
        outs = self._advance_all(t, t_stop)
        best = min(out.t for out in outs.values())
        results, self.kinks = [], []
        for isl in self.islands:
            out = outs[isl]
            res = isl.report(out)
            self.kinks += isl.kinks
            if res[0] != EventCode.NONE:
                results.append(res)
        self.kinks.sort(key=lambda k: k[0])
        if not results:
            return EventCode.NONE, None, best
        self.queued = results[1:]
        return results[0]

    def _advance_all(self, t: float, t_stop: float) -> dict:
        """Each island advanced from t to the earliest event of all (or t_stop): islands
        that went past it are put back and advanced again up to it."""
        if len(self.islands) == 1:  # (nothing to put back)
            return {isl: isl.advance(t, t_stop) for isl in self.islands}
        snaps = {isl: isl.snapshot() for isl in self.islands}
        outs = {}
        best = t_stop
        for isl in sorted(self.islands, key=_cost):  # (the dearest to put back last)
            outs[isl] = out = isl.advance(t, best)
            if out.code != EventCode.NONE:
                best = min(best, out.t)
        while True:
            late = [isl for isl, out in outs.items() if out.t > best]
            if not late:
                return outs
            for isl in late:
                self.retired["island_steps_undone"] += isl.restore(snaps[isl])
                self.retired["island_replays"] += 1
                outs[isl] = out = isl.advance(t, best)
                if out.code != EventCode.NONE:
                    best = min(best, out.t)

    def _still_members(self, event) -> bool:
        """Whether the balls of a queued event (code, key, t) are still members."""
        code, key, _ = event
        if code == EventCode.REST:
            return key in self.of
        if code == EventCode.LEAVE:
            return key[0] in self.of
        inside = [i in self.of for i in key if i >= 0]
        return any(inside) and all(i in self.of or i in self.fixed for i in key if i >= 0)

    def steps(self) -> int:
        """Kernel steps so far (accepted)."""
        return self.retired["kernel_steps"] + sum(isl.steps() for isl in self.islands)

    def stats(self) -> dict:
        """The work counters (``ActiveMembers.stats``) of every island, the groupings, the
        islands advanced again, and the most islands at once."""
        out = dict(self.retired)
        for isl in self.islands:
            for key, value in isl.stats().items():
                out[key] += value
            for key in isl.totals:
                isl.totals[key] = 0
        self.retired = dict(out)
        return out

    # --- state (by ball) ----------------------------------------------------------------------
    def state(self, i: int):
        """Position (m) and velocity (m/s) of member i now (a FIXED obstacle's: where it is
        held, at rest)."""
        isl = self.of.get(i)
        if isl is None:
            return self.balls.x0[i].copy(), np.zeros(3)
        return isl.state(i)

    def positions(self, idx) -> np.ndarray:
        """Positions (len(idx), 3) m of members ``idx`` now."""
        return np.array([self.state(int(i))[0] for i in idx]).reshape(-1, 3)

    def spin(self, i: int) -> np.ndarray:
        """Angular velocity (3,) rad/s of ball i now."""
        isl = self.of.get(i)
        return isl.spin(i) if isl is not None else self.balls.w[i].copy()

    def sync_spins(self):
        """Bring ``balls.w`` up to date with the islands."""
        for isl in self.islands:
            isl.sync_spins()

    def energy(self, balls) -> float:
        """Kinetic energy of ``balls`` (rotation included with friction) plus the elastic
        energy of all contacts of all islands (J)."""
        total = 0.0
        for isl in self.islands:
            total += isl.energy([i for i in balls if self.of.get(int(i)) is isl])
        return total

    def elastic_energy_of(self, i: int, ball_share: float = 0.5) -> float:
        """As ``ActiveMembers.elastic_energy_of``."""
        return self.of[i].elastic_energy_of(i, ball_share)

    def touching_keys(self) -> list:
        """Keys of every pair in contact now."""
        return [k for isl in self.islands for k in isl.touching_keys()]

    def touching_pairs(self, i: int) -> list:
        """Keys of member i's pairs in contact now (of a FIXED obstacle: in every island)."""
        if i in self.of:
            return self.of[i].touching_pairs(i)
        return [k for isl in self.islands if i in isl.fixed for k in isl.touching_pairs(i)]

    def _holder(self, key):
        """The island of pair ``key`` (that of its member: a FIXED partner is in several)."""
        return self.of[key[0]] if key[0] in self.of else self.of[key[1]]

    def contact_loads(self, key) -> tuple:
        """As ``ActiveMembers.contact_loads``."""
        return self._holder(key).contact_loads(key)

    def pair_energy(self, key) -> float:
        """As ``ActiveMembers.pair_energy``."""
        return self._holder(key).pair_energy(key)

    # --- contacts -------------------------------------------------------------------------------
    def start_contact(self, key):
        """Pair ``key`` starts touching now (found in closed form): its balls' islands merge."""
        balls = [k for k in key if k >= 0 and k in self.of]
        isl = self._merge(balls)
        if isl.watch is not None and key[1] >= 0 and key not in isl.watch:
            isl.rewatch(None)  # (not found by the island itself: watch every pair)
        isl.start_contact(key)

    def impulses(self, key) -> np.ndarray:
        return self._holder(key).impulses(key)

    def reset_accumulators(self, key):
        self._holder(key).reset_accumulators(key)

    def accumulators(self, key):
        return self._holder(key).accumulators(key)

    def make_quiet(self, i: int) -> float:
        return self.of[i].make_quiet(i)

    def wake(self, i: int):
        self.of[i].wake(i)

    def surface_velocity(self, key):
        """None: the rigid plate's surface does not move."""
        return None

    def refresh_shapes(self):
        """Nothing to do on the rigid plate."""

    def tail_energy(self) -> float:
        """0: no tails on the rigid plate."""
        return 0.0


def _cost(isl) -> float:
    """An island's expected cost per unit of time: members over its step (s; 0 before its
    first step)."""
    return len(isl.members) / isl.h if isl.h else 0.0


def _narrow(isl, watch) -> None:
    """Island ``isl`` (kept) watches the pairs of ``watch`` among its members: rebuilt when
    it misses one of them or watches more than twice as many (and 8) as needed."""
    members, both = set(isl.members), set(isl.members) | set(isl.fixed)
    need = {k for k in watch if (k[0] in members or k[1] in members) and set(k) <= both}
    have = {k for k in isl.keys if k[1] >= 0} if not isl.dirty else None
    if have is None or not need <= have or len(have) > 2 * len(need) + 8:
        isl.rewatch(watch)


def _groups(members, roots) -> list:
    """Members grouped by root, in member order."""
    out = {}
    for i, r in zip(members, roots, strict=True):
        out.setdefault(r, []).append(i)
    return list(out.values())
