"""Balls at rest with friction: a resting cluster is frozen (asleep) and costs nothing.

With friction (rigid plate) no contact is put at rest by the frictionless rules: the
regularised law holds a ball by a creep below the stiction velocity v_s, so a resting lump
would be integrated (and creep) for as long as it rests. Instead, at every refresh of the
active set (at least every ``membership.SET_HORIZON``):

* a core ball is SLOW while it touches something and its centre speed is below SLEEP_SPEED
  (the frictionless rest speed: what is left then is mostly the normal oscillation of its
  contacts, lightly damped at the static penetration, and the creep of the regularised law,
  slip plus rolling at each contact; a spin, about a contact normal or not, is not looked
  at and is dropped when the ball is frozen);
* a CLUSTER is a connected set of core balls through touching ball-ball contacts, at least
  one of them touching the plate; it is frozen when every ball of it has been slow for
  SLEEP_DWELL, no core ball left awake could reach it within the set's horizon (it would be
  woken at once: it waits, ready, counted in ``sleep_deferred``), and the rigid statics of
  its contacts admit equilibrium within the Coulomb and rolling limits
  (``statics.in_equilibrium``; a contact slipping at its stiction velocity or faster is
  held to min(mu_s, mu_d), what sliding friction gives; refused: slow again from now). The
  statics, not the creep speeds, say whether the cluster can stand: in a statically
  indeterminate heap the regularised law creeps on at some contacts above v_s while a set
  of forces within the limits exists;
* frozen, its balls leave the active set and are ASLEEP (``balls.SLEEP``): velocity and
  angular velocity exactly zero, position fixed, their contacts at the penetrations they
  had (their records end as ``rest``; the kinetic energy dropped is counted in
  ``rest_energy_removed``, the contacts' elastic energy stays with the balls);
* a sleeping ball that something could reach (a closed-form ball's predicted touch, or a
  core ball within the set's reach: ``speed_bounds``) wakes its whole cluster: the balls
  rejoin the active set at rest with their contacts touching (resumed contact records) and
  are integrated until they are frozen again or move off.
"""

import numpy as np

from tailbeam.results.records import End
from tailbeam.solvers.stream.active.reach import group_speed_bounds
from tailbeam.solvers.stream.driver.balls import SLEEP
from tailbeam.solvers.stream.driver.membership import SET_HORIZON
from tailbeam.solvers.stream.driver.statics import in_equilibrium

SLEEP_DWELL = 0.02  # s: a cluster is frozen after its balls have been slow this long
SLEEP_SPEED = 0.01  # m/s: a slow ball's centre speed bound (its normal oscillation included)


class Sleepers:
    """The slow balls, the frozen clusters, freezing and waking.

    Parameters
    ----------
    balls : Balls
        The stream's balls (``SLEEP``: asleep).
    act : ActiveMembers
        The active set (with friction: ``act.friction``).
    clock : Clock
        The driver's time and counters (``sleeps``, ``wakes``, ``sleep_refused``).
    heap : Predictions
        The closed-form balls' predictions (a frozen ball's touches are predicted).
    records : ContactRecords
        The contacts (ended at freezing, resumed at waking).
    loads : PlateLoads
        The plate's loads (a frozen ball's force history is flushed).
    ledger : EnergyLedger
        The kinetic energy dropped by freezing.
    """

    def __init__(self, balls, act, clock, heap, records, loads, ledger):
        self.balls, self.act, self.clock, self.heap = balls, act, clock, heap
        self.records, self.loads, self.ledger = records, loads, ledger
        self.slow_since = {}  # core ball -> time (s) since which it has been slow
        self.cluster = {}  # sleeping ball -> the tuple of its frozen cluster
        self.reach = {}  # core ball -> its speed bound (m/s) at the last check

    # --- freezing -----------------------------------------------------------------------------
    def check(self, core, excluded) -> list:
        """Freeze the clusters of ``core`` (set of ball numbers) ready to sleep; balls in
        ``excluded`` are not frozen now. Returns the balls frozen."""
        t = self.clock.t
        order = sorted(core)
        self.reach = dict(zip(order, self.speed_bounds(order, SET_HORIZON).tolist(), strict=True))
        touching = {}
        for key in self.act.touching_keys():
            for k in key:
                if k >= 0:
                    touching.setdefault(k, []).append(key)
        slow = set()
        for i in core:
            if self._is_slow(i, touching.get(i, [])):
                slow.add(i)
                self.slow_since.setdefault(i, t)
            else:
                self.slow_since.pop(i, None)
        ready = {i for i in slow if t - self.slow_since[i] >= SLEEP_DWELL} - set(excluded)
        clusters = [(c, k) for c, k in self._clusters(ready, touching) if any(q[1] < 0 for q in k)]
        reached = self._reached([c for c, _ in clusters], core)
        frozen = []
        for (comp, keys), near in zip(clusters, reached, strict=True):
            if near:  # an awake ball could touch it before the next check: it would be woken
                self.clock.count("sleep_deferred")
                continue
            if not self._holds(comp, keys):
                self.clock.count("sleep_refused")
                for i in comp:
                    self.slow_since[i] = t
                continue
            self._freeze(comp, keys)
            frozen.extend(comp)
        return frozen

    def _reached(self, comps, core) -> list:
        """For each cluster of ``comps`` (lists of balls, all frozen now): could a ball of
        ``core`` left awake touch it within the set's horizon (``speed_bounds``)? Such a
        cluster would be woken at once (``membership``): it stays awake, its balls ready."""
        if not comps:
            return []
        awake = sorted(set(core) - {i for c in comps for i in c})
        if not awake:
            return [False] * len(comps)
        b, h = self.balls, SET_HORIZON
        xa = self.act.positions(awake)
        reach = b.radius[awake] + self.reach_bounds(awake) * h
        out = []
        for comp in comps:
            xs = self.act.positions(comp)
            d2 = np.sum((xs[:, None, :] - xa[None, :, :]) ** 2, axis=2)
            out.append(bool(np.any(d2 <= (b.radius[comp][:, None] + reach[None, :]) ** 2)))
        return out

    def _is_slow(self, i: int, keys) -> bool:
        """Ball i touches something (``keys``) and its centre moves slower than SLEEP_SPEED.
        How its contacts creep is left to the statics (``_holds``)."""
        if not keys:
            return False
        _, v = self.act.state(i)
        return float(v @ v) < SLEEP_SPEED * SLEEP_SPEED

    def _slip(self, key) -> float:
        """Slip speed (m/s) at the model's contact point of contact ``key`` now."""
        act = self.act
        a, c = key
        xa, va = act.state(a)
        partner = () if c < 0 else (*act.state(c), act.spin(c))
        return act.friction.slip(key, xa, va, act.spin(a), *partner)

    def _clusters(self, ready, touching):
        """Connected clusters (sorted ball list, their touching keys) of touching balls
        (``touching``: ball -> its touching keys), kept only when every ball of the cluster
        is in ``ready``."""
        seen, out = set(), []
        for start in sorted(ready):
            if start in seen:
                continue
            comp, keys, todo, whole = [], set(), [start], True
            seen.add(start)
            while todo:
                i = todo.pop()
                comp.append(i)
                for key in touching.get(i, []):
                    keys.add(key)
                    for k in key:
                        if k >= 0 and k not in seen:
                            seen.add(k)
                            whole &= k in ready
                            todo.append(k)
            if whole:
                out.append((sorted(comp), sorted(keys)))
        return out

    def _holds(self, comp, keys) -> bool:
        """The rigid statics of cluster ``comp`` admit equilibrium (``statics``): a contact
        that slips at its stiction velocity or faster is held to the least friction the law
        gives a sliding contact, min(mu_s, mu_d) (sliding friction cannot hold more)."""
        local = {i: q for q, i in enumerate(comp)}
        x = np.array([self.act.state(i)[0] for i in comp])
        rows = []
        for key in keys:
            s, row = self.act.friction.settings(key), self.act.friction.row(key)
            mu = s.static
            if self._slip(key) >= s.stiction_velocity:
                mu = min(s.static, s.dynamic)
            i, j = key
            rows.append((local[i], -1 if j < 0 else local[j], row[5], mu, s.rolling, row[6]))
        b = self.balls
        return in_equilibrium(x, b.mass[comp], b.g, rows)

    def _freeze(self, comp, keys) -> None:
        """Cluster ``comp`` (touching through ``keys``) is asleep from now."""
        b, act, t, ledger = self.balls, self.act, self.clock.t, self.ledger
        removed = 0.0
        for key in keys:
            if self.records.is_open(key):
                self.records.close(key, End.REST)
        states = {}
        for i in comp:
            x, v = act.state(i)
            w = act.spin(i)
            removed += 0.5 * b.mass[i] * float(v @ v)
            removed += 0.2 * b.mass[i] * b.radius[i] ** 2 * float(w @ w)
            ledger.asleep[i] = act.elastic_energy_of(i)
            states[i] = x
        ledger.removed_at_rest(removed)
        members = tuple(comp)
        for i in comp:
            self.loads.flush(i)
            act.remove(i)
            b.in_set[i] = False
            b.w[i] = 0.0
            b.set_motion(i, SLEEP, t, states[i], np.zeros(3))
            self.cluster[i] = members
            self.slow_since.pop(i, None)
        for i in comp:
            self.heap.predict(i)
        self.clock.count("sleeps")
        self.clock.count("balls_put_to_sleep", len(comp))

    # --- reach ---------------------------------------------------------------------------------
    def speed_bounds(self, core, h: float) -> np.ndarray:
        """Speed bounds (m/s, one per ball of ``core``) over the next ``h`` s: those of the
        ball's touching cluster as an isolated group (``reach.group_speed_bounds``: its
        kinetic, rotation included, and elastic energy plus the work gravity can do on it
        within h). Until the active set's next event (where this is computed again) its
        touching pairs stay as they are, so energy moves only within a touching cluster: a
        resting lump far from the moving ones wakes none of its sleeping neighbours."""
        act, b = self.act, self.balls
        g = float(np.linalg.norm(b.g))
        root = {}

        def find(i):
            while root.get(i, i) != i:
                i = root[i]
            return i

        for i, j in act.touching_keys():
            if j >= 0 and find(i) != find(j):
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
        ``check`` (nothing has moved since, and a frozen cluster pools with no awake ball),
        else computed now."""
        if all(int(i) in self.reach for i in core):
            return np.array([self.reach[int(i)] for i in core])
        return self.speed_bounds(core, SET_HORIZON)

    # --- waking -------------------------------------------------------------------------------
    def wake(self, i: int, make_core) -> list:
        """Sleeping ball i is about to be touched: its cluster rejoins the active set at rest,
        its contacts touching (their records start again); ``make_core(k)`` makes each ball
        core. Returns the cluster's balls."""
        b, act = self.balls, self.act
        comp = self.cluster[i]
        for k in comp:
            act.add(k, b.x0[k].copy(), np.zeros(3), quiet=False)
            b.in_set[k] = True
            self.cluster.pop(k, None)
            self.ledger.asleep.pop(k, None)
        for k in comp:
            make_core(k)  # (status ACTIVE; its plate contact's record)
        for k in comp:
            for key in act.touching_pairs(k):
                if key[1] >= 0 and not self.records.is_open(key):
                    self.records.start(key)
        self.clock.count("wakes")
        return list(comp)

    def asleep(self) -> int:
        """How many balls are asleep now."""
        return int(np.count_nonzero(self.balls.status == SLEEP))
