"""The active set as the stream driver sees it: members by ball number, pairs by key.

``integrator.set.ActiveSet`` integrates a fixed list of balls and pairs.
Here members come and go (a ball lands, a neighbour comes within reach, a ball flies off), so
the set is rebuilt on the next use after a change, carrying over each pair's state (touching,
region flags, peak force, maximum penetration) by its key: (i, -1) for ball i on the plate,
(i, j) with i < j for two balls. Every pair among the members is watched (sets are small: the
balls near a contact). A set rebuilt at the instant of an event carries the rows whose events
were applied then (``carry.CarriedRows``), so that it does not apply the same event again at
once (``kernel.advance``).

With friction a set may also carry FIXED obstacles (``set_fixed``): sleeping balls held
where they are, whose pairs with the members act on the members only (the kernel's
``pairs.FIXED``); two of them never form a pair.

Its parts: the plate force histories (``plate.forces.PlateForces``), putting a member at rest
(``plate.rest``) and, on the modal plate, the plate pairs' shapes, compliance and tails
(``plate.pairs.PlatePairs``).
"""

import math

import numpy as np

from tailbeam.physics.contact_law import law_table
from tailbeam.physics.contacts import PLATE
from tailbeam.physics.incline import EDGES
from tailbeam.results.records import EventCode
from tailbeam.solvers.stream.active import friction_pairs
from tailbeam.solvers.stream.active.carry import CarriedRows
from tailbeam.solvers.stream.active.compiled.pairs import first_contact_step
from tailbeam.solvers.stream.active.integrator.set import ActiveSet
from tailbeam.solvers.stream.active.plate.forces import THIN, THIN_FRICTION, PlateForces
from tailbeam.solvers.stream.active.plate.pairs import PlatePairs
from tailbeam.solvers.stream.active.plate.rest import excess_energy, place_at_rest, static_height

LAZY_ROWS = 50_000  # with ``lazy_forces``: force rows a set holds before they are drained


class ActiveMembers:
    """The members of the active set and their pairs, by ball number and pair key.

    Parameters
    ----------
    balls : Balls
        The stream's balls (``tailbeam.solvers.stream.driver.balls``; ``balls.table``: the
        laws of the pairs).
    rtol : float
        Relative tolerance of the set's integrator.
    settle_energy : callable
        Ball number -> the energy (J) below which its plate contact settles (SETTLE).
    plate : StreamPlate, optional
        The two-way modal plate (None: the rigid plate).
    dead_loads : callable, optional
        () -> (xy (p, 2) m, weights (p,) N) of the balls resting on the plate outside the
        set (modal plate).
    friction : FrictionPairs, optional
        The pairs' friction (``friction_pairs``; on the modal plate with the slip against
        the plate's surface and the moment into the modes): the sets integrate the
        members' angular velocities (``balls.w`` holds them while a ball is not in a built
        set). None: frictionless.

    Attributes
    ----------
    members : list of int
        Ball numbers, in the set's order.
    keys, index : list, dict
        The pair keys in the set's order, and key -> pair.
    now : float
        The driver's time (s), where a rebuilt set starts.
    kinks : list
        (t s, ``EventKind``, pair key) of the kinks of the last ``next_event``.
    forces : PlateForces
        The members' plate force histories.
    """

    def __init__(self, balls, rtol, settle_energy, plate=None, dead_loads=None, friction=None):
        self.balls, self.rtol = balls, rtol
        self.friction = friction
        self.plate = plate
        self.settle_energy = settle_energy
        self.modal = None if plate is None else PlatePairs(plate, balls, rtol, dead_loads)
        thin = (0.0, 0.0) if friction is None else (THIN, THIN_FRICTION)
        self.forces = PlateForces(self._friction_lever(), thin)
        self.lazy_forces = False  # True: force rows drained only when needed (flush_forces)
        self.carried = CarriedRows()
        self.now = 0.0
        self.members, self.quiet = [], set()  # quiet: members resting on the plate
        self.fixed = []  # FIXED obstacles: sleeping balls the members may touch (``fix``)
        self.keys, self.index, self.local, self.pairs_of = [], {}, {}, {}
        self.set, self.dirty, self.h = None, True, 0.0
        self.watch = None  # ball pairs watched (None: every pair of members; ``rewatch``)
        self.kinks = []
        self._x, self._v = {}, {}  # states of the members while the set is not built
        self._pairs = {}  # pair key -> its state in the set last synced
        self.totals = dict.fromkeys(
            ("kernel_steps", "kernel_attempts", "kernel_nfev", "rebuilds", "events_found_again"),
            0,
        )

    def _friction_lever(self) -> float:
        """h/2 (m) where friction's moment drives the modal plate (its loads for the
        sensors, ``forces``), else 0."""
        if self.friction is None or self.plate is None or not friction_pairs._PLATE_MOMENT:
            return 0.0
        return 0.5 * self.plate.basis.plate.thickness

    # --- membership and rebuilds ------------------------------------------------------------
    def add(self, i: int, x, v, *, quiet: bool):
        """Ball i joins at position x (m) and velocity v (m/s); ``quiet``: resting on the
        plate."""
        self._sync()
        self.members.append(i)
        self._x[i], self._v[i] = np.array(x, dtype=float), np.array(v, dtype=float)
        if quiet:
            self.quiet.add(i)
        self.dirty = True

    def set_fixed(self, balls) -> None:
        """The sleeping balls ``balls`` are the set's FIXED obstacles from now: held where
        they are (``balls.x0``, at rest), acting on the members that touch them and feeling
        nothing; pairs of two of them are not in the set (rebuilt on its next use)."""
        balls = list(dict.fromkeys(int(k) for k in balls))
        if balls == self.fixed:
            return
        self._sync()
        self.fixed = balls
        self.dirty = True

    def to_fixed(self, i: int) -> None:
        """Member i, frozen now (its velocity and spin set to 0 by the caller), stays in the
        set as a FIXED obstacle, its touching pairs with the members going on."""
        self._sync()
        self.members.remove(i)
        self._x.pop(i, None)
        self._v.pop(i, None)
        self.quiet.discard(i)
        self.fixed.append(i)
        self.dirty = True

    def add_fixed(self, k: int, owner=None) -> None:
        """Sleeping ball k is a FIXED obstacle of the set (``set_fixed``; ``owner``: as
        ``Islands.add_fixed``)."""
        if k not in self.fixed:
            self.set_fixed(self.fixed + [k])

    def remove_fixed(self, k: int) -> None:
        """Ball k is no FIXED obstacle any more."""
        if k in self.fixed:
            self.set_fixed([f for f in self.fixed if f != k])

    def from_fixed(self, i: int) -> bool:
        """FIXED obstacle i becomes a member, at rest where it is, its pairs going on (False:
        not an obstacle of the set)."""
        if i not in self.fixed:
            return False
        self._sync()
        self.fixed.remove(i)
        self.members.append(i)
        self._x[i], self._v[i] = self.balls.x0[i].copy(), np.zeros(3)
        self.dirty = True
        return True

    def remove(self, i: int):
        """Ball i leaves the set."""
        self._drop_tail((i, -1))
        self._sync()
        self.members.remove(i)
        self._x.pop(i, None)
        self._v.pop(i, None)
        self.quiet.discard(i)
        self.dirty = True

    def _sync(self):
        """Keep the current states of the built set's members before a change."""
        s = self.set
        if s is None or self.dirty:
            return
        for q, i in enumerate(self.members):
            self._x[i], self._v[i] = s.x[q].copy(), s.v[q].copy()
        self._sync_spins()
        self._pairs = {k: s.contacts.of(p) for k, p in self.index.items()}
        self.carried.save(s, self.members, self.keys)
        if self.modal is not None:  # each plate pair keeps its mode shapes (its contact point)
            self.modal.save(s, self.index)

    def _sync_spins(self):
        """With friction: the built set's angular velocities into ``balls.w``."""
        s = self.set
        if self.friction is None or s is None or self.dirty:
            return
        for q, i in enumerate(self.members):
            self.balls.w[i] = s.w[q]

    def spin(self, i: int) -> np.ndarray:
        """Angular velocity (3,) rad/s of ball i now (0 without friction)."""
        if self.friction is None:
            return np.zeros(3)
        if self.dirty or self.set is None or i not in self.local:
            return self.balls.w[i].copy()
        return self.set.w[self.local[i]].copy()

    def sync_spins(self):
        """Bring ``balls.w`` up to date with the set (the end of the run)."""
        self._sync_spins()

    def _ready(self) -> ActiveSet:
        """The built set (rebuilt first after a change)."""
        if self.dirty:
            self._build()
        return self.set

    def export(self) -> dict:
        """The members' state (positions, velocities, pair states by key, resting members,
        carried rows, next step), for an ``adopt`` by another set (an island's members
        regrouped, ``islands``); spins go to ``balls.w``."""
        self._sync()
        mine, fixed = set(self.members), set(self.fixed)
        pairs = {
            k: st for k, st in self._pairs.items()
            if (k[0] in mine or k[1] in mine) and all(i < 0 or i in mine or i in fixed for i in k)
        }  # fmt: skip
        return dict(x=dict(self._x), v=dict(self._v), pairs=pairs,
                    quiet=set(self.quiet), carried=(self.carried.t, list(self.carried.rows)),
                    h=self.h)  # fmt: skip

    def adopt(self, members, parts) -> None:
        """Take ``members`` with their state from ``parts`` (``export``s of the sets they
        were in, at this set's time): the set is built with them on its next use. The
        smallest step suggested by a part is the first step; the rows carried are those of
        the latest part."""
        self.members = list(members)
        for part in parts:
            for i in self.members:
                if i in part["x"]:
                    self._x[i], self._v[i] = part["x"][i], part["v"][i]
            self._pairs.update(part["pairs"])
            self.quiet |= part["quiet"] & set(self.members)
        steps = [p["h"] for p in parts if p["h"]]
        self.h = min(steps) if steps else 0.0
        t = max((p["carried"][0] for p in parts if not math.isnan(p["carried"][0])),
                default=math.nan)  # fmt: skip
        self.carried.t = t
        self.carried.rows = [r for p in parts if p["carried"][0] == t for r in p["carried"][1]]
        self.dirty = True

    def flush_forces(self) -> None:
        """Move the force rows the built set still holds into the histories (``forces``;
        with ``lazy_forces`` they wait there until a ball's history is taken, the set is
        rebuilt or dropped, or LAZY_ROWS have gathered)."""
        s = self.set
        if s is None or not len(s.force_rows()):
            return
        self.forces.drain(s, self.keys, self.local)
        s.io.clear_rows()

    def _build(self):
        self.flush_forces()  # (the rows name the pairs of the set replaced)
        b, m = self.balls, self.members + self.fixed
        old = self._pairs
        self.keys = [(i, -1) for i in self.members] + self._ball_pairs(old)
        local = {i: q for q, i in enumerate(m)}
        pairs = [(local[i], -1 if j < 0 else local[j]) for i, j in self.keys]
        laws = [b.table.law(i, PLATE if j < 0 else j) for i, j in self.keys]
        settle = [0.0 if i in self.quiet else self.settle_energy(i) for i in self.members]
        settle += [0.0] * len(self.fixed)
        x = [self._x[i] for i in self.members] + [b.x0[i] for i in self.fixed]
        v = [self._v[i] for i in self.members] + [np.zeros(3)] * len(self.fixed)
        self._count()
        modal = {} if self.modal is None else self.modal.block(m, self.keys, self._x,
                                                                self.quiet, self.now)  # fmt: skip
        if self.friction is not None:
            table = self.friction.table(self.keys, **self._plate_friction(modal))
            modal = {**modal, "friction": table, "w": b.w[m]}
        self.set = s = ActiveSet(
            x, v, b.mass[m], b.radius[m],
            np.array(pairs, dtype=np.int64).reshape(-1, 2), law_table(laws), b.g, b.half,
            settle_energy=np.array(settle), rtol=self.rtol, **modal,
        )  # fmt: skip
        for i in self.fixed:
            s.model.fix(local[i])
        self.index = {k: p for p, k in enumerate(self.keys)}
        self.pairs_of = {}  # ball -> its pairs, in the set's order
        for p, (i, j) in enumerate(self.keys):
            self.pairs_of.setdefault(i, []).append(p)
            if j >= 0:
                self.pairs_of.setdefault(j, []).append(p)
        for k, p in self.index.items():
            if k in old:
                s.contacts.put(p, old[k])
        s.h = self.h
        self.local = local
        if old or self.carried.rows:
            self.carried.restore(s, local, self.index)
        self.dirty = False
        self.totals["rebuilds"] += 1

    def _ball_pairs(self, old) -> list:
        """The ball-ball pair keys the set watches: every pair of members and of a member and
        a FIXED obstacle, or those in ``watch`` and those touching (``old``: the pair states
        by key)."""
        m = self.members
        keys = [(min(i, j), max(i, j)) for a, i in enumerate(m) for j in m[a + 1 :]]
        keys += [(min(i, k), max(i, k)) for i in m for k in self.fixed]
        if self.watch is None:
            return keys
        return [k for k in keys if k in self.watch or (k in old and old[k][0])]

    def rewatch(self, watch) -> None:
        """Watch only the ball pairs in ``watch`` (a set of keys (i, j), i < j, that holds
        every pair of members that can touch until the caller says otherwise; None: every
        pair): the set is rebuilt on its next use."""
        self._sync()
        self.watch = watch
        self.dirty = True

    def _plate_friction(self, modal) -> dict:
        """With friction on the modal plate: what the friction table of a set rebuilt with the
        modal inputs ``modal`` takes for its plate pairs (``FrictionPairs.table``)."""
        if self.modal is None:
            return {}
        grads = {k: self.modal.gradient(k) for k in self.keys if k[1] < 0}
        half = 0.5 * self.plate.basis.plate.thickness
        return dict(gradients=grads, n_modes=modal["phi"].shape[1], half=half)

    def surface_velocity(self, key):
        """With friction on the modal plate: the in-plane velocity (3,) m/s of the plate's top
        surface at plate pair ``key``'s contact point now, -(h/2) grad phi . q' (None on the
        rigid plate)."""
        if self.modal is None or key[1] >= 0:
            return None
        s, n = self._ready(), self.plate.n_modes
        out = np.zeros(3)
        out[:2] = -0.5 * self.plate.basis.plate.thickness * (s.qd[:n] @ self.modal.gradient(key))
        return out

    def _count(self):
        """Add the work counters of the built set to the totals (and reset them there)."""
        if self.set is not None:
            st = self.set.stats
            self.totals["kernel_steps"] += st["steps"]
            self.totals["kernel_attempts"] += st["attempts"]
            self.totals["kernel_nfev"] += st["nfev"]
            self.totals["events_found_again"] += st["found_again"]
            self.set.io.reset_stats()

    # --- integration ------------------------------------------------------------------------
    def next_event(self, t: float, t_stop: float):
        """Integrate the members from t to t_stop (s) or their first event.

        Returns
        -------
        code : EventCode
            NONE (t_stop reached), CONTACT_START, CONTACT_END, LEAVE or REST (a plate
            contact settled).
        key
            The pair key (start, end), (ball, edge name) (leave), the ball (rest), or None.
        t : float
            The time reached (s).
        """
        return self.report(self.advance(t, t_stop))

    def advance(self, t: float, t_stop: float):
        """Integrate the members from t to t_stop (s) or their first event, keeping the force
        rows and kinks in the set (``report`` takes them; ``restore`` drops them): the
        set's ``Outcome``."""
        s = self._ready()
        out = s.advance(t, t_stop, self.h or None)
        self.h = s.h
        return out

    def snapshot(self) -> tuple:
        """What ``advance`` changes, for ``restore`` (the built set's ``snapshot``)."""
        return self._ready().snapshot(), self.h

    def restore(self, snap) -> int:
        """Undo the ``advance`` calls since ``snapshot`` (their steps stay counted); returns
        the steps undone."""
        steps = self.set.stats
        self.set.restore(snap[0])
        self.h = snap[1]
        for name, key in (
            ("steps", "kernel_steps"),
            ("attempts", "kernel_attempts"),
            ("nfev", "kernel_nfev"),
            ("found_again", "events_found_again"),
        ):
            self.totals[key] += steps[name] - self.set.stats[name]  # fmt: skip
        return steps["steps"] - self.set.stats["steps"]

    def report(self, out):
        """Take the force rows and kinks of the calls since the last report and translate
        ``out`` (an ``Outcome``) as ``next_event`` returns it."""
        s = self.set
        rows = not self.lazy_forces or len(s.force_rows()) > LAZY_ROWS
        if rows:
            self.forces.drain(s, self.keys, self.local)
        self.kinks = [(t_k, kind, self.keys[p]) for t_k, kind, p in s.kink_log()]
        s.clear_outputs(rows)
        if self.plate is not None:
            n = self.plate.n_modes
            self.plate.take(s.q[:n], s.qd[:n], out.t)
        code = out.code
        if code == EventCode.NONE:
            return code, None, out.t
        if code in (EventCode.CONTACT_START, EventCode.CONTACT_END):
            key = self.keys[out.index]
            if code == EventCode.CONTACT_START:
                self._set_compliance(key)
            return code, key, out.t
        ball = self.members[out.index]
        return code, (ball, EDGES[out.edge]) if code == EventCode.LEAVE else ball, out.t

    def steps(self) -> int:
        """Kernel steps so far (accepted)."""
        return self.totals["kernel_steps"] + (self.set.stats["steps"] if self.set else 0)

    def stats(self) -> dict:
        """The work counters: kernel steps, attempts, right-hand sides, rebuilds, events
        found again at the instant they were applied."""
        self._count()
        return dict(self.totals)

    # --- state ------------------------------------------------------------------------------
    def state(self, i: int):
        """Position (m) and velocity (m/s) of member i now (a FIXED obstacle's: where it is
        held, at rest)."""
        if i in self.fixed:
            return self.balls.x0[i].copy(), np.zeros(3)
        if self.dirty:
            return self._x[i], self._v[i]
        q = self.local[i]
        return self.set.x[q].copy(), self.set.v[q].copy()

    def positions(self, idx) -> np.ndarray:
        """Positions (len(idx), 3) m of members ``idx`` now."""
        return np.array([self.state(int(i))[0] for i in idx]).reshape(-1, 3)

    def energy(self, balls) -> float:
        """Kinetic energy of ``balls`` (members; with friction their rotation's too, which
        friction can turn into translation) plus the elastic energy of all contacts (J): what
        a contact among them can give to one of them."""
        s = self._ready()
        q = [self.local[int(i)] for i in balls]
        kinetic = 0.5 * float(np.sum(s.model.mass[q] * np.sum(s.v[q] * s.v[q], axis=1)))
        if self.friction is not None:
            inertia = 0.4 * s.model.mass[q] * s.model.radius[q] ** 2
            kinetic += 0.5 * float(np.sum(inertia * np.sum(s.w[q] * s.w[q], axis=1)))
        elastic = sum(s.contact_energy(p) for p in np.flatnonzero(s.contacts.touching))
        return kinetic + elastic

    def ball_energies(self, balls) -> np.ndarray:
        """Per ball of ``balls`` (members): its kinetic energy (rotation included with
        friction), its plate contact's elastic energy and half of each of its touching
        ball-ball pairs' (all of a pair with a FIXED obstacle, which takes none) (J): summed
        over a group holding both balls of each of its pairs, the group's kinetic and elastic
        energy."""
        s = self._ready()
        q = np.array([self.local[int(i)] for i in balls], dtype=np.int64)
        m = s.model.mass[q]
        out = 0.5 * m * np.sum(s.v[q] * s.v[q], axis=1)
        if self.friction is not None:
            out += 0.2 * m * s.model.radius[q] ** 2 * np.sum(s.w[q] * s.w[q], axis=1)
        touching = np.flatnonzero(s.contacts.touching)
        if not len(touching):
            return out
        energies = s.contact_energies()
        where = {int(i): k for k, i in enumerate(balls)}
        fixed = set(self.fixed)
        for p in touching.tolist():
            i, j = self.keys[p]
            e = energies[p] if j < 0 or i in fixed or j in fixed else 0.5 * energies[p]
            for k in (i, j):
                if k in where:
                    out[where[k]] += e
        return out

    def elastic_energy_of(self, i: int, ball_share: float = 0.5) -> float:
        """Elastic energy (J) of member i's touching plate pair plus ``ball_share`` of each of
        its touching ball-ball pairs (half: the other half is its partner's; 1: the pairs
        vanish with i, as when it leaves over an edge); all of a pair with a FIXED obstacle
        (the ledger books none of it with the obstacle)."""
        s = self._ready()
        total = 0.0
        for key in self.touching_pairs(i):
            alone = key[1] < 0 or key[0] in self.fixed or key[1] in self.fixed
            share = 1.0 if alone else ball_share
            total += share * s.contact_energy(self.index[key])
        return total

    def contact_loads(self, key) -> tuple:
        """Touching pair ``key``'s loads now: (force (3,) N, torque (3,) N m) on each of its
        balls (the second None on the plate) (``ActiveSet.contact_loads``)."""
        fi, ti, fj, tj = self._ready().contact_loads(self.index[key])
        return (fi, ti), (None if key[1] < 0 else (fj, tj))

    def pair_energy(self, key) -> float:
        """Elastic energy (J) of pair ``key`` now (0 when not touching)."""
        return self._ready().contact_energy(self.index[key])

    def touching_keys(self) -> list:
        """Keys of every pair in contact now."""
        s = self._ready()
        touching = s.contacts.touching
        return [k for k, p in self.index.items() if touching[p]]

    def touching_pairs(self, i: int) -> list:
        """Keys of member i's pairs in contact now."""
        s = self._ready()
        touching = s.contacts.touching
        return [self.keys[p] for p in self.pairs_of.get(i, ()) if touching[p]]

    # --- contacts ---------------------------------------------------------------------------
    def start_contact(self, key):
        """Pair ``key`` starts touching now (its start was found in closed form)."""
        s = self._ready()
        p = self.index[key]
        s.contacts.start(p, s.penetration(p)[0])
        s.io.forget_fresh(p)
        self._set_compliance(key)
        step = first_contact_step(s.y, s.model.arrays(), p, self.rtol)
        self.h = min(self.h, step) if self.h else step

    def impulses(self, key) -> np.ndarray:
        """With friction: pair ``key``'s (normal impulse N s, tangential impulse on its first
        ball (3) N s, energy friction dissipated J) so far (``compiled.friction.IMP_*``)."""
        s = self._ready()
        return s.contacts.imp[self.index[key]].copy()

    def reset_accumulators(self, key):
        """Peak force and maximum penetration of pair ``key`` start again from now."""
        s = self._ready()
        p = self.index[key]
        s.contacts.reset_accumulators(p, s.penetration(p)[0])

    def accumulators(self, key):
        """(peak force N, its time s, maximum penetration m) of pair ``key``."""
        s = self._ready()
        return s.contacts.accumulators(self.index[key])

    def make_quiet(self, i: int) -> float:
        """Put ball i at rest on the plate (``plate.rest``); returns the normal excess energy (J)
        this removes."""
        s = self._ready()
        q, p = self.local[i], self.index[(i, -1)]
        removed = excess_energy(s, q, p)
        w, wd, cres = 0.0, 0.0, 0.0
        if self.modal is not None:  # at rest: the static spring of the whole tail, no oscillators
            w, wd = self.modal.deflection(s, p)
            cres = self.modal.compliance((i, -1))
            s.model.set_compliance(p, cres)
        place_at_rest(s, q, p, static_height(self.balls, i, cres) + w, wd,
                      self.balls.static_pen[i])  # fmt: skip
        self.quiet.add(i)
        self._drop_tail((i, -1))
        return removed

    def wake(self, i: int):
        """Ball i takes part in a contact again: SETTLE may end its plate contact again."""
        if i in self.quiet:
            self.quiet.discard(i)
            s = self._ready()
            s.model.settle_energy[self.local[i]] = self.settle_energy(i)

    # --- the modal plate's pairs (``plate.pairs``) ------------------------------------------
    def refresh_shapes(self):
        """Modal plate: the mode shapes of every plate pair not touching, at its ball's
        position now (a touching pair keeps those of its contact point)."""
        if self.modal is None or not self.members:
            return
        s = self._ready()
        touching = s.contacts.touching
        free = [(q, i) for q, i in enumerate(self.members) if not touching[self.index[(i, -1)]]]
        if not free:
            return
        moved = self.modal.refresh(s, free, self.index)
        if self.friction is not None:  # the friction table's shape gradients follow the shapes
            for key in moved:
                s.model.set_gradients(self.index[key], self.modal.gradient(key))
        for key in moved:  # (after the set's own changes: dropping syncs and rebuilds it)
            self._drop_tail(key)

    def _set_compliance(self, key):
        """Modal plate: plate pair ``key`` (touching from now) gets its tail (``_start_tail``)
        or its residual compliance."""
        if self.modal is not None and key[1] < 0 and not self._start_tail(key):
            self.set.model.set_compliance(self.index[key], self.modal.compliance(key))

    def _start_tail(self, key) -> bool:
        """Plate pair ``key`` (touching from now) gets the oscillators of its contact point, at
        rest, and the spring of the modes above the tail's band; the set is rebuilt with them
        before the next step. A pair that touches again at the same point (its shapes not
        refreshed since) keeps its oscillators, still moving. False without a tail."""
        tails = self.modal.tails
        if key in tails:
            self.set.model.set_compliance(self.index[key], tails.modes(key).compliance)
            return True
        tail = self.modal.new_tail(key)
        if tail is None:
            return False
        self.set.model.set_compliance(self.index[key], tail.compliance)
        self._sync()
        self.modal.add_tail(key, tail)
        self.dirty = True
        return True

    def _drop_tail(self, key) -> None:
        """Drop plate pair ``key``'s oscillators (its ball moved on to new shapes, was put at
        rest or left; not when its contact ends: the plate under the ball would jump):
        their energy goes to ``tail_energy_dropped``."""
        if self.modal is None or key not in self.modal.tails:
            return
        self._sync()
        self.modal.tails.drop(key)
        self.dirty = True

    @property
    def tail_energy_dropped(self) -> float:
        """Energy (J) the tails held when they were dropped."""
        return self.modal.tails.dropped if self.modal is not None else 0.0

    def tail_energy(self) -> float:
        """Energy (J) held by the tails of the contacts in progress."""
        if self.modal is None:
            return 0.0
        if self.modal.tails.states:
            self._sync()
        return self.modal.tails.energy()
