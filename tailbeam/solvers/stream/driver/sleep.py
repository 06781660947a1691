"""Balls at rest with friction: resting balls are frozen (asleep) and cost nothing.

With friction (rigid plate) no contact is put at rest by the frictionless rules: the
regularised law holds a ball by a creep below the stiction velocity v_s, so a resting lump
would be integrated (and creep) for as long as it rests. Instead, at every refresh of the
active set (at least every ``membership.SET_HORIZON``):

* a core ball is SLOW while it touches something and its centre speed is below SLEEP_SPEED
  (the frictionless rest speed: what is left then is mostly the normal oscillation of its
  contacts, lightly damped at the static penetration, and the creep of the regularised law,
  slip plus rolling at each contact; a spin, about a contact normal or not, is not looked
  at and is dropped when the ball is frozen);
* a GROUP is a connected set of core balls slow for SLEEP_DWELL (READY) through touching
  ball-ball contacts; while a slow ball outside it touches it, it waits, at most another
  SLEEP_DWELL (counted in ``sleep_deferred``: it is frozen with that ball, in one statics,
  when that one is ready too, rather than under its load of the moment); it is frozen
  when the rigid statics (``statics.in_equilibrium``) of the group together with the
  frozen balls it touches (their whole frozen groups) admit equilibrium within the
  Coulomb and rolling limits, the contacts of the awake balls that touch them acting as
  given loads, as they are now (normal force, friction, rolling torque). A contact
  slipping at its stiction velocity or faster is held to min(mu_s, mu_d), what sliding
  friction gives. Refused: slow again from now. The statics, not the creep speeds, say
  whether it can stand;
* frozen, its balls leave the active set and are ASLEEP (``balls.SLEEP``): velocity and
  angular velocity exactly zero, position fixed, their contacts with one another and the
  plate at the penetrations they had (their records end as ``rest``; the kinetic energy
  dropped is counted in ``rest_energy_removed``; the elastic energy of those contacts
  stays in the ledger, half of a ball-ball contact with each ball);
* a sleeping ball that an awake ball touches or could reach within the set's horizon is
  a FIXED obstacle of the active set (``ActiveMembers.set_fixed``): the awake ball feels
  its contact (normal force, friction, rolling resistance) as from a ball that does not
  move, the sleeping ball feels nothing and costs no steps (the ledger books all of such a
  contact's elastic energy with the awake ball; its friction's work as any contact's);
* a contact that starts between an awake ball and a sleeping one faster than WAKE_SPEED
  (an impact: a fixed obstacle would reflect what the struck ball should take; found by
  the set or predicted in closed form) wakes the sleeping ball alone: it rejoins the active set at
  rest with its contacts touching (resumed contact records); the sleeping balls it touches
  stay asleep, FIXED obstacles for it;
* at the first check of every SET_HORIZON (1 ms) each group of sleeping balls touched by
  awake balls (connected through their frozen contacts) must still stand under those
  balls' contact loads then (the same statics): where it does not, its balls touched by
  awake balls wake, and what is left of it is checked again under their loads, until what
  is left stands.
"""

import numpy as np

from tailbeam.results.records import End
from tailbeam.solvers.stream.active.reach import group_speed_bounds
from tailbeam.solvers.stream.driver.balls import ACTIVE, SLEEP
from tailbeam.solvers.stream.driver.membership import SET_HORIZON
from tailbeam.solvers.stream.driver.statics import in_equilibrium

SLEEP_DWELL = 0.02  # s: a group is frozen after its balls have been slow this long
SLEEP_SPEED = 0.01  # m/s: a slow ball's centre speed bound (its normal oscillation included)
WAKE_SPEED = 0.01  # m/s: a contact starting faster than this with a sleeping ball wakes it


class Sleepers:
    """The slow balls, the frozen balls and their contacts, freezing and waking.

    Parameters
    ----------
    balls : Balls
        The stream's balls (``SLEEP``: asleep).
    act : ActiveMembers or Islands
        The active set (with friction: ``act.friction``; its FIXED obstacles).
    clock : Clock
        The driver's time and counters (``sleeps``, ``wakes``, ``sleep_refused``,
        ``wakes_by_load``).
    heap : Predictions
        The closed-form balls' predictions (a frozen ball's touches are predicted).
    records : ContactRecords
        The contacts (ended at freezing, resumed at waking).
    loads : PlateLoads
        The plate's loads (a frozen ball's force history is flushed).
    ledger : EnergyLedger
        The kinetic energy dropped by freezing; ``ledger.asleep``: each sleeping ball's share
        of its frozen contacts' elastic energy.

    Attributes
    ----------
    make_core : callable
        Ball -> None: makes a woken ball core (set by ``Membership``).
    bonds : dict
        Frozen contact key ((i, -1) or (i, j), both asleep) -> (mu its statics use, elastic
        energy J).
    adj : dict
        Sleeping ball -> the set of its frozen partners (-1: the plate).
    """

    def __init__(self, balls, act, clock, heap, records, loads, ledger):
        self.balls, self.act, self.clock, self.heap = balls, act, clock, heap
        self.records, self.loads, self.ledger = records, loads, ledger
        self.slow_since = {}  # core ball -> time (s) since which it has been slow
        self.reach = {}  # core ball -> its speed bound (m/s) at the last check
        self.bonds, self.adj = {}, {}
        self.make_core = None
        self.next_recheck = 0.0  # s: the loaded sleeping groups' statics checked again then
        self._mus = {}  # contact key -> the mu of the last statics solved

    # --- the checks -----------------------------------------------------------------------------
    def check(self, core, excluded) -> list:
        """Wake the sleeping groups that no longer stand under the awake balls' loads, then
        freeze the groups of ``core`` (set of ball numbers) ready to sleep; balls in
        ``excluded`` are not frozen now. Returns the balls frozen."""
        t = self.clock.t
        order = sorted(core)
        self.reach = dict(zip(order, self.speed_bounds(order, SET_HORIZON).tolist(), strict=True))
        touching = self._touching()
        slow = set()
        for i in core:
            if self._is_slow(i, touching.get(i, [])):
                slow.add(i)
                self.slow_since.setdefault(i, t)
            else:
                self.slow_since.pop(i, None)
        if t >= self.next_recheck and self._recheck(touching):
            touching = self._touching()
        if t >= self.next_recheck:
            self.next_recheck = t + SET_HORIZON
        ready = {i for i in slow if t - self.slow_since.get(i, t) >= SLEEP_DWELL}
        ready = {i for i in ready - set(excluded) if self.balls.status[i] == ACTIVE}
        frozen = []
        for comp in self._groups(ready, touching):
            waited = t - max(self.slow_since[i] for i in comp) - SLEEP_DWELL
            if waited < SLEEP_DWELL and self._slow_neighbour(comp, touching, slow):
                self.clock.count("sleep_deferred")
                continue
            bodies, keys, loads = self._system(comp, touching)
            if not any(k[1] < 0 for k in keys) and not loads:
                continue
            if not self._holds(bodies, keys, loads):
                self.clock.count("sleep_refused")
                for i in comp:
                    self.slow_since[i] = t
                continue
            self._freeze(comp, touching)
            frozen.extend(comp)
        return frozen

    def _slow_neighbour(self, comp, touching, slow) -> bool:
        """Whether an awake ball touching group ``comp`` is slow but not in it (not ready
        yet, or held): the group waits to be frozen with it, in one statics, rather than
        under its load of the moment."""
        inside = set(comp)
        for i in comp:
            for key in touching.get(i, []):
                for k in key:
                    if k >= 0 and k not in inside and k in slow:
                        return True
        return False

    def _touching(self) -> dict:
        """Ball -> the keys of the active set's touching pairs it is in (members and FIXED
        obstacles)."""
        out = {}
        for key in self.act.touching_keys():
            for k in key:
                if k >= 0:
                    out.setdefault(k, []).append(key)
        return out

    def _is_slow(self, i: int, keys) -> bool:
        """Ball i touches something (``keys``) and its centre moves slower than SLEEP_SPEED.
        How its contacts creep is left to the statics (``_holds``)."""
        if not keys:
            return False
        _, v = self.act.state(i)
        return float(v @ v) < SLEEP_SPEED * SLEEP_SPEED

    def _groups(self, ready, touching) -> list:
        """Connected groups (sorted ball lists) of ``ready`` balls through their touching
        ball-ball contacts with one another."""
        seen, out = set(), []
        for start in sorted(ready):
            if start in seen:
                continue
            comp, todo = [], [start]
            seen.add(start)
            while todo:
                i = todo.pop()
                comp.append(i)
                for key in touching.get(i, []):
                    for k in key:
                        if k >= 0 and k in ready and k not in seen:
                            seen.add(k)
                            todo.append(k)
            out.append(sorted(comp))
        return out

    def _frozen_group(self, start: int) -> set:
        """The sleeping balls connected to sleeping ball ``start`` through frozen contacts."""
        comp, todo = {start}, [start]
        while todo:
            for k in self.adj.get(todo.pop(), ()):
                if k >= 0 and k not in comp:
                    comp.add(k)
                    todo.append(k)
        return comp

    def _system(self, comp, touching) -> tuple:
        """The statics of group ``comp`` with the sleeping groups it touches: (the balls,
        their contact keys (the active set's among them and the frozen ones), the loads
        (ball -> (6,) force N and torque N m) of the awake balls touching them)."""
        b = self.balls
        bodies = set(comp)
        for i in comp:
            for key in touching.get(i, []):
                for k in key:
                    if k >= 0 and k not in bodies and b.status[k] == SLEEP:
                        bodies |= self._frozen_group(k)
        return self._statics_of(bodies, touching)

    def _statics_of(self, bodies, touching) -> tuple:
        """(sorted balls, contact keys, loads) of the rigid statics of ``bodies`` (see
        ``_system``)."""
        keys, loads = set(), {}
        for i in bodies:
            for k in self.adj.get(i, ()):
                keys.add((i, -1) if k < 0 else (min(i, k), max(i, k)))
            for key in touching.get(i, []):
                other = key[1] if key[0] == i else key[0]
                if other < 0 or other in bodies:
                    keys.add(key)
                    continue
                side = self.act.contact_loads(key)[0 if key[0] == i else 1]
                loads[i] = loads.get(i, np.zeros(6)) + np.concatenate(side)
        return sorted(bodies), sorted(keys), loads

    def _recheck(self, touching) -> bool:
        """Every sleeping group touched by awake balls must stand under their loads now;
        where one does not, its balls touched by awake balls wake and the rest is checked
        again under their loads. Returns whether any ball woke."""
        b = self.balls
        todo = {k for k in touching if b.status[k] == SLEEP}
        woke, seen = False, set()
        while todo:
            comp = self._frozen_group(todo.pop())
            todo -= comp
            if comp & seen:
                continue
            bodies, keys, loads = self._statics_of(comp, touching)
            if self._holds(bodies, keys, loads):
                seen |= comp
                continue
            peel = [k for k in bodies if k in loads] or bodies
            for k in peel:
                self.wake(k)
                self.clock.count("wakes_by_load")
            woke = True
            touching = self._touching()
            todo |= {k for k in comp - set(peel) if k in touching}
        return woke

    def _mu(self, key) -> float:
        """The friction coefficient the statics give contact ``key``: a frozen contact's as
        when it froze; an integrated one's mu_s, or min(mu_s, mu_d) when it slips at its
        stiction velocity or faster (sliding friction cannot hold more)."""
        if key in self.bonds:
            return self.bonds[key][0]
        s = self.act.friction.settings(key)
        if self._slip(key) >= s.stiction_velocity:
            return min(s.static, s.dynamic)
        return s.static

    def _slip(self, key) -> float:
        """Slip speed (m/s) at the model's contact point of contact ``key`` now."""
        act = self.act
        a, c = key
        xa, va = act.state(a)
        partner = () if c < 0 else (*act.state(c), act.spin(c))
        return act.friction.slip(key, xa, va, act.spin(a), *partner)

    def _holds(self, bodies, keys, loads) -> bool:
        """The rigid statics of ``bodies`` on contacts ``keys`` under ``loads`` admit
        equilibrium (``statics``; the coefficients of ``_mu``)."""
        local = {i: q for q, i in enumerate(bodies)}
        x = np.array([self._position(i) for i in bodies])
        rows, self._mus = [], {}
        for key in keys:
            s, row = self.act.friction.settings(key), self.act.friction.row(key)
            mu = self._mus[key] = self._mu(key)
            i, j = key
            rows.append((local[i], -1 if j < 0 else local[j], row[5], mu, s.rolling, row[6]))
        ext = np.zeros((len(bodies), 6))
        for i, load in loads.items():
            ext[local[i]] = load
        b = self.balls
        return in_equilibrium(x, b.mass[bodies], b.g, rows, ext)

    def _position(self, i: int) -> np.ndarray:
        """Centre (m) of ball i now (asleep: where it is held)."""
        if self.balls.status[i] == SLEEP:
            return self.balls.x0[i]
        return self.act.state(i)[0]

    # --- freezing -------------------------------------------------------------------------------
    def _freeze(self, comp, touching) -> None:
        """Group ``comp`` is asleep from now (its statics just held: ``_holds``)."""
        b, act, t, ledger = self.balls, self.act, self.clock.t, self.ledger
        inside, awake_partner = set(comp), set()
        for i in comp:
            for key in touching.get(i, []):
                other = key[1] if key[0] == i else key[0]
                if other >= 0 and other not in inside and b.status[other] != SLEEP:
                    awake_partner.add(i)
                    continue
                if key in self.bonds:
                    continue
                self.bonds[key] = (self._mus.get(key, 0.0) or self._mu(key), act.pair_energy(key))
                self.adj.setdefault(i, set()).add(other)
                if other >= 0:
                    self.adj.setdefault(other, set()).add(i)
                if self.records.is_open(key):
                    self.records.close(key, End.REST)
        removed, states = 0.0, {}
        for i in comp:
            x, v = act.state(i)
            w = act.spin(i)
            removed += 0.5 * b.mass[i] * float(v @ v)
            removed += 0.2 * b.mass[i] * b.radius[i] ** 2 * float(w @ w)
            states[i] = x
        ledger.removed_at_rest(removed)
        for i in comp:
            self.loads.flush(i)
            b.x0[i] = states[i]
            if i in awake_partner:  # (it stays in its set as a FIXED obstacle)
                act.to_fixed(i)
            else:
                act.remove(i)
            b.in_set[i] = False
            b.w[i] = 0.0
            b.set_motion(i, SLEEP, t, states[i], np.zeros(3))
            self.slow_since.pop(i, None)
        self._book({k for i in comp for k in self.adj.get(i, ()) if k >= 0} | inside)
        for i in comp:
            self.heap.predict(i)
        self.clock.count("sleeps")
        self.clock.count("balls_put_to_sleep", len(comp))

    def _book(self, balls) -> None:
        """The ledger's share of each sleeping ball of ``balls`` in its frozen contacts'
        elastic energy: its plate contact's and half of each ball-ball contact's."""
        for i in balls:
            total = 0.0
            for k in self.adj.get(i, ()):
                key = (i, -1) if k < 0 else (min(i, k), max(i, k))
                total += self.bonds[key][1] * (1.0 if k < 0 else 0.5)
            self.ledger.asleep[i] = total

    # --- reach ---------------------------------------------------------------------------------
    def speed_bounds(self, core, h: float) -> np.ndarray:
        """Speed bounds (m/s, one per ball of ``core``) over the next ``h`` s: those of the
        ball's touching cluster of awake balls as an isolated group
        (``reach.group_speed_bounds``: its kinetic, rotation included, and elastic energy,
        all of that of its contacts with FIXED obstacles, plus the work gravity can do on it
        within h). Until the active set's next event (where this is computed again) its
        touching pairs stay as they are, so energy moves only within such a cluster (a
        FIXED obstacle takes none): a resting lump far from the moving ones is not reached."""
        act, b = self.act, self.balls
        g = float(np.linalg.norm(b.g))
        members = set(act.members)
        root = {}

        def find(i):
            while root.get(i, i) != i:
                i = root[i]
            return i

        for i, j in act.touching_keys():
            if j >= 0 and i in members and j in members and find(i) != find(j):
                root[find(i)] = find(j)
        groups = {}
        for i in {int(i) for i in core} | set(root):
            groups.setdefault(find(i), []).append(i)
        balls = [i for grp in groups.values() for i in grp]
        energy = dict(zip(balls, act.ball_energies(balls).tolist(), strict=True))
        bound = {}
        for grp in groups.values():
            pooled = sum(energy[i] for i in grp)
            for i, s in zip(grp, group_speed_bounds(pooled, b.mass[grp], g, h), strict=True):
                bound[i] = s
        return np.array([bound[int(i)] for i in core])

    def reach_bounds(self, core) -> np.ndarray:
        """``speed_bounds`` over SET_HORIZON of the balls ``core``: those found by the last
        ``check`` (nothing has moved since), else computed now."""
        if all(int(i) in self.reach for i in core):
            return np.array([self.reach[int(i)] for i in core])
        return self.speed_bounds(core, SET_HORIZON)

    # --- waking -------------------------------------------------------------------------------
    def wakes_on_touch(self, key) -> bool:
        """Whether contact ``key``, starting now between an awake ball and a sleeping one,
        wakes the sleeping one: its balls approach faster than WAKE_SPEED."""
        i, j = key
        xi, vi = self._state(i)
        xj, vj = self._state(j)
        d = xi - xj
        rate = -float((vi - vj) @ d) / float(np.sqrt(d @ d))
        return rate > WAKE_SPEED

    def _state(self, i: int):
        """Position (m) and velocity (m/s) of ball i now (in the set or in closed form)."""
        if self.balls.in_set[i] or i in self.act.fixed:
            return self.act.state(i)
        return self.balls.state(i, self.clock.t)

    def wake(self, i: int) -> list:
        """Sleeping ball i wakes alone: it rejoins the active set at rest where it is, its
        contacts touching (their records start again); the sleeping balls it touches are
        FIXED obstacles for it. Returns [i]."""
        b, act = self.balls, self.act
        partners = self.adj.pop(i, set())
        for k in partners:
            key = (i, -1) if k < 0 else (min(i, k), max(i, k))
            self.bonds.pop(key, None)
            if k >= 0:
                self.adj[k].discard(i)
        self.ledger.asleep.pop(i, None)
        self._book([k for k in partners if k >= 0])
        if not act.from_fixed(i):
            act.add(i, b.x0[i].copy(), np.zeros(3), quiet=False)
        b.in_set[i] = True
        for k in partners:
            if k >= 0:
                act.add_fixed(k, owner=i)
        self.make_core(i)  # (status ACTIVE; its plate contact's record)
        for key in act.touching_pairs(i):
            if key[1] >= 0 and not self.records.is_open(key):
                self.records.start(key)
        self.clock.count("wakes")
        return [i]

    def asleep(self) -> int:
        """How many balls are asleep now."""
        return int(np.count_nonzero(self.balls.status == SLEEP))
