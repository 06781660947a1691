"""The stream driver's membership of the active set: which balls are integrated and which
move in closed form (a mixin of ``tailbeam.solvers.stream.driver.loop._Stream``, which provides
``balls``, ``act``, ``t``, ``core``, ``hold``, ``landing``, ``limit``, ``open``, ``plate``,
``set_end``, ``w_margin``, ``stats``, the heap of ``stream_heap`` and the handlers of
``stream_set_events``).

The CORE is the balls with a contact in progress; the members are the core and every
closed-form ball that could reach a core ball within SET_HORIZON (certified bounds). A core
ball that touches nothing any more flies (or slides, resting on the plate) in closed form
again. On the modal plate the set's horizon is also bounded by SHAPE_TRAVEL of lateral
travel of its landing balls (their mode shapes are refreshed), and plate touches are
predicted above the plate's deflection bound (``w_margin``).
"""

import numpy as np

from tailbeam.solvers.stream.driver.balls import ACTIVE, FLY, SLIDE
from tailbeam.solvers.stream.driver.heap import _PLATE

SET_HORIZON = 1e-3  # s: the active set looks this far ahead for balls that could reach it
SHAPE_TRAVEL = 1e-3  # m: modal plate: mode shapes refreshed after this much lateral travel


class StreamMembership:
    """Core, members and the closed-form balls of the stream driver."""

    def _persistent_to_rest(self):
        """Plate contacts older than their limit, with no other contact: at rest (their
        normal oscillation is dropped: bounded work; the energy is counted)."""
        for i, t_limit in list(self.limit.items()):
            if t_limit <= self.t and self.act.touching_pairs(i) == [(i, -1)]:
                self._on_settle(i)

    def _is_core(self, i: int) -> bool:
        if i in self.landing or self.hold.get(i) == self.t:
            return True
        return any(key in self.open for key in self.act.touching_pairs(i))

    def _make_core(self, i: int):
        """Ball i takes part in a contact: its closed-form motion ends; a ball resting on the
        plate gets its plate contact back as a record (v_in ~ 0: a resumed contact)."""
        b = self.balls
        if b.status[i] != ACTIVE:
            b.status[i] = ACTIVE
            b.version[i] += 1
        self.core.add(i)
        self.act.wake(i)
        plate = (i, -1)
        if plate not in self.open and plate in self.act.touching_pairs(i):
            self._open(plate)

    def _absorb(self, i: int):
        b = self.balls
        if b.status[i] == SLIDE:
            self._dead_load(i, self.t)
        x, v = b.state(i, self.t)
        self._audit_overlap(i, x)
        self.act.add(i, x, v, quiet=b.status[i] == SLIDE)
        b.in_set[i] = True

    def _audit_overlap(self, i: int, x):
        """Count a ball that enters the set already overlapping a member or the plate (a
        missed start: must never happen after its release; tests check stats)."""
        b = self.balls
        if self.t == b.t_release[i]:
            return
        depth = b.radius[i] - (x[2] - self._plate_deflection(x)) if b.status[i] == FLY else 0.0
        what = "plate"
        if self.act.members:
            m = np.array(self.act.members)
            d = np.linalg.norm(self.act.positions(m) - x, axis=1)
            overlap = b.radius[m] + b.radius[i] - d
            if overlap.max() > depth:
                depth, what = float(overlap.max()), b.names[int(m[np.argmax(overlap)])]
        if depth > 1e-12:
            self.stats["late_starts"] += 1
            log = self.stats.setdefault("late_start_log", [])
            if len(log) < 10:
                log.append((self.t, b.names[i], what, depth))

    def _plate_deflection(self, x) -> float:
        """The modal plate's deflection (m) under the point x now (0 for the rigid plate)."""
        if self.plate is None:
            return 0.0
        self.plate.propagate(self.t)
        return float(self.plate.shapes(x[:2])[0] @ self.plate.q)

    def _release_from_core(self, i: int):
        """Core ball i touches nothing any more (or only rests on the plate): closed form."""
        b = self.balls
        x, v = self.act.state(i)
        quiet = (i, -1) in self.act.touching_pairs(i)
        if not quiet and self.plate is not None and self._stays_near_plate(i, x, v):
            self.landing.add(i)  # it comes back within the plate's deflection bound
            return
        b.set_motion(i, SLIDE if quiet else FLY, self.t, x, v)
        if quiet:
            b.slide_since[i] = self.t
        self.core.discard(i)
        self._predict(i)

    def _stays_near_plate(self, i: int, x, v) -> bool:
        """Modal plate: does ball i's flight keep it within the margin above the plate?"""
        gn = -self.balls.g[2]
        apex = x[2] + (v[2] ** 2 / (2.0 * gn) if v[2] > 0.0 and gn > 0.0 else 0.0)
        return apex < self.balls.radius[i] + self.w_margin

    def _check_margin(self):
        """Modal plate: keep the plate-touch predictions above the plate's deflection bound;
        when it has grown past the margin, double the margin and predict again."""
        if self.plate is None:
            return
        bound = self.plate.deflection_bound()
        if bound <= self.w_margin:
            return
        self.w_margin = max(2.0 * bound, 1e-9)
        self.stats["margin_updates"] = self.stats.get("margin_updates", 0) + 1
        b = self.balls
        for i in np.flatnonzero((b.status == FLY) & ~b.in_set):
            for t_ev, what, _edge in b.own_events(int(i), self.t, self.w_margin):
                if what == "plate":
                    self.push(t_ev, _PLATE, int(i))

    def _resting_outside(self):
        """(xy (p, 2) m, weights (p,) N) of the balls resting on the plate outside the set."""
        b = self.balls
        idx = np.flatnonzero((b.status == SLIDE) & ~b.in_set)
        if not len(idx):
            return np.empty((0, 2)), np.empty(0)
        x, _ = b.states(idx, self.t)
        return x[:, :2], b.mass[idx] * -b.g[2]

    def _exit(self, i: int):
        b = self.balls
        self._flush_nodes(i)
        self.act.remove(i)
        b.in_set[i] = False
        if b.status[i] == SLIDE:
            b.slide_since[i] = self.t
        # its own events (a plate touch or edge crossing that came due while the set watched
        # it was dropped then) and its pairs with the balls the set watched
        self._predict(i)

    def _refresh_set(self):
        """Core = members with a contact in progress; members = core + every closed-form
        ball that could reach a core ball within SET_HORIZON (certified bounds)."""
        b, t = self.balls, self.t
        self.hold = {i: th for i, th in self.hold.items() if th == t}
        self._persistent_to_rest()
        for i in [i for i in self.core if not self._is_core(i)]:
            self._release_from_core(i)
        core = np.array(sorted(self.core), dtype=np.int64)
        cand = b.closed_form()
        if not len(core):
            for i in cand[b.in_set[cand]]:
                self._exit(int(i))
            self.set_end = t
            return
        h = SET_HORIZON
        # (a limit already reached waits for the ball's other contacts to end)
        limits = [self.limit[i] for i in core if i in self.limit and self.limit[i] > t]
        self.set_end = min([t + h] + limits)
        if self.plate is not None:  # mode shapes where the landing balls will touch
            self.act.refresh_shapes()
            for i in self.landing:
                lateral = float(np.hypot(*self.act.state(i)[1][:2]))
                if lateral > 0.0:
                    self.set_end = min(self.set_end, t + SHAPE_TRAVEL / lateral)
        xc = self.act.positions(core)
        # energy a core ball can receive: the core's kinetic and elastic energy, plus what
        # gravity can give in h (a 1 cm drop of every core ball: far more than they fall)
        g = np.linalg.norm(b.g)
        energy = self.act.energy(core) + np.sum(b.mass[core]) * g * 0.01
        sc = np.sqrt(2.0 * energy / b.mass[core]) + g * h
        if not len(cand):
            return
        x, _ = b.states(cand, t)
        s = b.speed_bounds(cand, t, h)
        d2 = np.sum((x[:, None, :] - xc[None, :, :]) ** 2, axis=2)
        reach = b.radius[cand][:, None] + b.radius[core][None, :] + (s[:, None] + sc) * h
        near = np.any(d2 <= reach**2, axis=1)
        for i in cand[near & ~b.in_set[cand]]:
            self._absorb(int(i))
        for i in cand[~near & b.in_set[cand]]:
            self._exit(int(i))
