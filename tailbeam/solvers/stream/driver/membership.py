"""Which balls the active set integrates and which move in closed form.

The CORE is the balls with a contact in progress (and, on the modal plate, the LANDING balls:
within the plate's deflection bound, touching nothing yet); the members are the core and
every closed-form ball that could reach a core ball within SET_HORIZON (certified bounds).
A core ball that touches nothing any more flies (or slides, resting on the plate) in closed
form again. A plate contact alone past its rest limit (``records``) is put at rest. On the
modal plate the set's horizon is also bounded by SHAPE_TRAVEL of lateral travel of its
landing balls (their mode shapes are refreshed then). With friction on the rigid plate,
resting groups of core balls are frozen, a sleeping ball that a core ball could reach is a
FIXED obstacle of the set, and a touch wakes it alone (``sleep``).
"""

import numpy as np

from tailbeam.results.records import End
from tailbeam.solvers.stream.driver.balls import ACTIVE, FLY, GONE, SLEEP, SLIDE

SET_HORIZON = 1e-3  # s: the active set looks this far ahead for balls that could reach it
SHAPE_TRAVEL = 1e-3  # m: modal plate: mode shapes refreshed after this much lateral travel
REACH_DROP = 0.01  # m: a core ball may gain the energy of a drop this high within SET_HORIZON


class Membership:
    """Core, members and the set's horizon.

    Parameters
    ----------
    balls : Balls
        The stream's balls (status, closed-form motion, ``in_set``).
    act : ActiveMembers
        The active set.
    clock : Clock
        The driver's time and counters.
    heap : Predictions
        The closed-form balls' predictions (made again when a ball leaves the set).
    records : ContactRecords
        The contacts (opened and closed here; their rest limits).
    loads : PlateLoads
        The plate's loads (a member's force history, a slider's dead load).
    ledger : EnergyLedger
        The energy removed by putting a ball at rest.
    plate : StreamPlate or None
        The modal plate, or None.
    sleepers : Sleepers or None
        With friction on the rigid plate: freezing resting clusters (``sleep``); None: never.
    """

    def __init__(self, balls, act, clock, heap, records, loads, ledger, plate=None,
                 sleepers=None):  # fmt: skip
        self.balls, self.act, self.clock, self.plate = balls, act, clock, plate
        self.sleepers = sleepers
        self.heap, self.records, self.loads, self.ledger = heap, records, loads, ledger
        self.core = set()  # balls with a contact in progress (and landing balls)
        self.landing = set()  # modal plate: balls within the deflection bound, touching nothing
        self.held = {}  # ball -> time (s) of a contact end: core until time moves on
        self.set_end = 0.0  # s: the set's horizon
        if sleepers is not None:
            sleepers.make_core = self._make_core

    # --- contacts starting and ending -------------------------------------------------------
    def start(self, key) -> None:
        """Contact ``key`` starts now: its record; its balls are core (a sleeping one, a
        FIXED obstacle, stays asleep unless the touch wakes it: ``Sleepers.wakes_on_touch``)."""
        self.landing.discard(key[0])
        self.records.start(key)
        b = self.balls
        asleep = [k for k in key if k >= 0 and b.status[k] == SLEEP]
        for k in key:
            if k >= 0 and k not in asleep:
                self._make_core(k)
        if asleep and self.sleepers.wakes_on_touch(key):
            for k in asleep:
                self.sleepers.wake(k)

    def join(self, ids, key) -> None:
        """Closed-form balls ``ids`` start the contact ``key`` now (found in closed form); a
        sleeping one touched slowly stays asleep, a FIXED obstacle (``Sleepers``)."""
        b = self.balls
        asleep = [i for i in ids if b.status[i] == SLEEP]
        if len(asleep) == 1 and len(ids) == 2 and not self.sleepers.wakes_on_touch(key):
            other = ids[0] if ids[1] == asleep[0] else ids[1]
            if not b.in_set[other]:
                self._absorb(other)
            self.act.add_fixed(asleep[0], owner=other)
            ids = [other]
        for i in ids:
            if not b.in_set[i]:
                self._absorb(i)
        self.act.start_contact(key)
        self.start(key)
        self.refresh()

    def land(self, i: int) -> None:
        """Modal plate: flying ball i comes within the plate's deflection bound: the set
        integrates it, so that it finds the real start of its contact."""
        self._absorb(i)
        self.landing.add(i)
        self._make_core(i)
        self.refresh()

    def hold(self, i: int) -> None:
        """A contact of ball i ended now: it stays core until time moves on (a set rebuilt at
        that instant could find the same contact starting again)."""
        self.held[i] = self.clock.t

    def settle(self, i: int) -> None:
        """Ball i's plate contact ends at rest: it rests on the plate."""
        self.records.close((i, -1), End.REST)
        self.ledger.removed_at_rest(self.act.make_quiet(i))

    def leave(self, i: int) -> None:
        """Member i left over an edge: gone."""
        b = self.balls
        self.act.remove(i)
        b.in_set[i] = False
        b.status[i] = GONE
        b.version[i] += 1
        self.core.discard(i)
        self.landing.discard(i)

    # --- the set -------------------------------------------------------------------------------
    def refresh(self) -> None:
        """Core = members with a contact in progress; members = core + every closed-form
        ball that could reach a core ball within SET_HORIZON (certified bounds)."""
        b, t = self.balls, self.clock.t
        self.held = {i: th for i, th in self.held.items() if th == t}
        self._persistent_to_rest()
        if self.sleepers is not None and self.core:
            excluded = set(self.landing) | set(self.held)
            for i in self.sleepers.check(self.core, excluded):
                self.core.discard(i)
        for i in [i for i in self.core if not self._is_core(i)]:
            self._release_from_core(i)
        core = np.array(sorted(self.core), dtype=np.int64)
        cand = b.closed_form()
        if not len(core):
            for i in cand[b.in_set[cand]]:
                self._exit(int(i))
            self._obstacles(set())
            self.set_end = t
            return
        self.set_end = self._horizon(core)
        near = self._near(cand, core)
        if near is None:
            self._obstacles(set())
            return
        asleep = b.status[cand] == SLEEP
        self._obstacles({int(i) for i in cand[near & asleep]})
        for i in cand[near & ~b.in_set[cand] & ~asleep]:
            self._absorb_near(int(i))
        for i in cand[~near & b.in_set[cand]]:
            if b.status[i] != ACTIVE:  # (not a ball of a cluster woken just now)
                self._exit(int(i))

    def _obstacles(self, needed) -> None:
        """The sleeping balls ``needed`` (a core ball could reach them within SET_HORIZON)
        are the set's FIXED obstacles; the others are not (``Sleepers``)."""
        if self.sleepers is None:
            return
        for k in sorted(needed - set(self.act.fixed)):
            self.act.add_fixed(k)
            self.clock.count("fixed_obstacles")
        for k in sorted(set(self.act.fixed) - needed):
            self.act.remove_fixed(k)

    def _horizon(self, core) -> float:
        """The set's horizon (s): SET_HORIZON ahead, or a core ball's rest limit, or (modal
        plate) SHAPE_TRAVEL of a landing ball's lateral travel (shapes refreshed now)."""
        t = self.clock.t
        # (a limit already reached waits for the ball's other contacts to end)
        set_end = min([t + SET_HORIZON] + self.records.rest_limits(core, t))
        if self.plate is not None:  # mode shapes where the landing balls will touch
            self.act.refresh_shapes()
            for i in self.landing:
                lateral = float(np.hypot(*self.act.state(i)[1][:2]))
                if lateral > 0.0:
                    set_end = min(set_end, t + SHAPE_TRAVEL / lateral)
        return set_end

    def _near(self, cand, core):
        """Which closed-form balls ``cand`` could reach a ball of ``core`` within SET_HORIZON
        (bool array; None without candidates)."""
        b, t, h = self.balls, self.clock.t, SET_HORIZON
        xc = self.act.positions(core)
        # energy a core ball can receive: the core's kinetic and elastic energy, plus what
        # gravity can give in h (a drop of REACH_DROP of every core ball: far more than they
        # fall); with sleeping lumps, per touching cluster and gravity's work bounded by the
        # drops the bound itself allows (``Sleepers.speed_bounds``)
        g = np.linalg.norm(b.g)
        if self.sleepers is not None:
            sc = self.sleepers.reach_bounds(core)  # (those of the check just made)
        else:
            energy = self.act.energy(core) + np.sum(b.mass[core]) * g * REACH_DROP
            sc = np.sqrt(2.0 * energy / b.mass[core]) + g * h
        if not len(cand):
            return None
        x, _ = b.states(cand, t)
        s = b.speed_bounds(cand, t, h)
        d2 = np.sum((x[:, None, :] - xc[None, :, :]) ** 2, axis=2)
        reach = b.radius[cand][:, None] + b.radius[core][None, :] + (s[:, None] + sc) * h
        return np.any(d2 <= reach**2, axis=1)

    def _persistent_to_rest(self) -> None:
        """Plate contacts older than their limit, with no other contact: at rest (their
        normal oscillation is dropped: bounded work; the energy is counted)."""
        for i in self.records.due_rests(self.clock.t):
            if self.act.touching_pairs(i) == [(i, -1)]:
                self.settle(i)

    def _is_core(self, i: int) -> bool:
        if i in self.landing or self.held.get(i) == self.clock.t:
            return True
        return any(self.records.is_open(key) for key in self.act.touching_pairs(i))

    def _make_core(self, i: int) -> None:
        """Ball i takes part in a contact: its closed-form motion ends; a ball resting on the
        plate gets its plate contact back as a record (v_in ~ 0: a resumed contact)."""
        b = self.balls
        if b.status[i] != ACTIVE:
            b.status[i] = ACTIVE
            b.version[i] += 1
        self.core.add(i)
        self.act.wake(i)
        plate = (i, -1)
        if not self.records.is_open(plate) and plate in self.act.touching_pairs(i):
            self.records.start(plate)

    def _release_from_core(self, i: int) -> None:
        """Core ball i touches nothing any more (or only rests on the plate): closed form."""
        b, t = self.balls, self.clock.t
        x, v = self.act.state(i)
        quiet = (i, -1) in self.act.touching_pairs(i)
        if not quiet and self.plate is not None and self._stays_near_plate(i, x, v):
            self.landing.add(i)  # it comes back within the plate's deflection bound
            return
        b.set_motion(i, SLIDE if quiet else FLY, t, x, v)
        if quiet:
            b.slide_since[i] = t
        self.core.discard(i)
        self.heap.predict(i)

    def _stays_near_plate(self, i: int, x, v) -> bool:
        """Modal plate: does ball i's flight keep it within the margin above the plate?"""
        gn = -self.balls.g[2]
        apex = x[2] + (v[2] ** 2 / (2.0 * gn) if v[2] > 0.0 and gn > 0.0 else 0.0)
        return apex < self.balls.radius[i] + self.heap.w_margin

    # --- balls entering and leaving the set ---------------------------------------------------
    def _absorb(self, i: int) -> None:
        """Closed-form ball i becomes a member (a slider's dead load ends; a sleeping ball
        wakes its cluster)."""
        b, t = self.balls, self.clock.t
        if b.in_set[i]:  # (woken with its cluster)
            return
        if b.status[i] == SLEEP:
            self.sleepers.wake(i)
            return
        if b.status[i] == SLIDE:
            self.loads.dead_load(i, t)
        x, v = b.state(i, t)
        self._audit_overlap(i, x)
        self.act.add(i, x, v, quiet=b.status[i] == SLIDE)
        b.in_set[i] = True

    def _absorb_near(self, i: int) -> None:
        """Closed-form ball i, near a core ball, becomes a member; one released touching the
        rigid plate (its own touch due at this instant) starts that contact now: the set
        must know it, or it integrates the ball into the plate."""
        b = self.balls
        self._absorb(i)
        if b.status[i] == FLY and self.plate is None and self.act.state(i)[0][2] < b.radius[i]:
            self.act.start_contact((i, -1))
            self.start((i, -1))

    def _exit(self, i: int) -> None:
        """Member i (not core) moves in closed form again."""
        b = self.balls
        self.loads.flush(i)
        self.act.remove(i)
        b.in_set[i] = False
        if b.status[i] == SLIDE:
            b.slide_since[i] = self.clock.t
        # its own events (a plate touch or edge crossing that came due while the set watched
        # it was dropped then) and its pairs with the balls the set watched
        self.heap.predict(i)

    def _audit_overlap(self, i: int, x) -> None:
        """Count a ball that enters the set already overlapping a member or the plate (a
        missed start: must never happen after its release; tests check stats)."""
        b, t = self.balls, self.clock.t
        if t == b.t_release[i]:
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
            stats = self.clock.stats
            stats["late_starts"] += 1
            log = stats.setdefault("late_start_log", [])
            if len(log) < 10:
                log.append((t, b.names[i], what, depth))

    def _plate_deflection(self, x) -> float:
        """The modal plate's deflection (m) under the point x now (0 for the rigid plate)."""
        if self.plate is None:
            return 0.0
        self.plate.propagate(self.clock.t)
        return float(self.plate.shapes(x[:2])[0] @ self.plate.q)
