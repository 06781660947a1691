"""The active set as the stream driver sees it: members by ball number, pairs by key.

``tailbeam.solvers.stream.active.set.ActiveSet`` integrates a fixed list of balls and pairs. Here
members come and go (a ball lands, a neighbour comes within reach, a ball flies off), so the
set is rebuilt on the next ``advance`` after a change, carrying over each pair's state
(touching, region flags, peak force, maximum penetration) by its key: (i, -1) for ball i on
the plate, (i, j) with i < j for two balls. Every pair among the members is watched (sets are
small: the balls near a contact). A set rebuilt at the instant of an event carries the rows
whose events were applied then (``ActiveSet.fresh_rows``, by key), so that it does not
apply the same event again at once (``active_kernel.advance``).

On the modal plate each plate pair also gets the residual compliance (m/N) of the truncated
modes at the point of its mode shapes (``StreamPlate.compliance``, cached by point): when its
contact starts (the force is 0 then, so nothing jumps) or it is put at rest; carried over
with the shapes while it touches.
"""

import math

import numpy as np

from tailbeam.physics.contact_law import law_table
from tailbeam.physics.contact_patch import load_radius
from tailbeam.physics.contacts import PLATE
from tailbeam.physics.incline import EDGES
from tailbeam.solvers.stream.active.kernel import IO_AGAIN
from tailbeam.solvers.stream.active.pairs import (
    L_CRES,
    R_EDGE,
    first_contact_step,
    settle_excess,
)
from tailbeam.solvers.stream.active.set import ActiveSet
from tailbeam.solvers.stream.active.tails import Tails

SHAPE_REUSE = 2.5e-4  # m: mode shapes computed within this distance are reused (modal plate)
_KIND = {"contact_start": "start", "contact_end": "end", "leave": "leave", "settle": "settle"}


class ActiveMembers:
    """Members (ball numbers of ``balls``: a ``stream_state.Balls``) and their pairs."""

    def __init__(self, balls, rtol, settle_energy, plate=None, dead_loads=None):
        self.balls, self.rtol = balls, rtol  # balls.table: the laws of the pairs
        self.plate = plate  # a StreamPlate (two-way modal plate) or None (rigid)
        self.dead_loads = dead_loads  # () -> (xy (p, 2), weights (p,)) of resting non-members
        self.now = 0.0  # the driver's time (s), where a rebuilt set starts
        self.settle_energy = settle_energy  # ball number -> J
        self.members = []
        self.quiet = set()  # members resting on the plate (no SETTLE for them)
        self.keys, self.index = [], {}
        self.set = None
        self.dirty = True
        self.h = 0.0
        self.nodes = {}  # ball -> [x, y, [t arrays], [F arrays]]
        self.totals = {"kernel_steps": 0, "kernel_attempts": 0, "kernel_nfev": 0, "rebuilds": 0}
        self.totals["events_found_again"] = 0  # at the instant they were applied (issue 7)
        self._shape_cache = {}  # ball -> (xy, mode shapes there): modal plate
        self._phi_xy = {}  # plate pair key -> the point (x, y) of its mode shapes
        self._load_radii = {}  # ball -> radius (m) of its load model (contact_patch)
        self._x = {}  # state of members added since the last build
        self.tails = Tails()  # the plate pairs' contact tails (modal plate), by key
        self._v = {}

    # --- membership -----------------------------------------------------------------------------
    def add(self, i: int, x, v, *, quiet: bool):
        self._sync()
        self.members.append(i)
        self._x[i], self._v[i] = np.array(x, dtype=float), np.array(v, dtype=float)
        if quiet:
            self.quiet.add(i)
        self.dirty = True

    def remove(self, i: int):
        self._drop_tail((i, -1))
        self._sync()
        self.members.remove(i)
        self._x.pop(i, None)
        self._v.pop(i, None)
        self.quiet.discard(i)
        self.dirty = True

    def _sync(self):
        """Keep the current states of the built set's members before a change."""
        if self.set is None or self.dirty:
            return
        for q, i in enumerate(self.members):
            self._x[i], self._v[i] = self.set.x[q].copy(), self.set.v[q].copy()
        self._pairs = {k: self._pair_state(p) for k, p in self.index.items()}
        self._fresh = self._fresh_by_key()
        if self.plate is not None:  # each plate pair keeps its mode shapes (its contact point)
            n = self.plate.n_modes
            self._phi = {k: self.set.phi[p, :n].copy() for k, p in self.index.items() if k[1] < 0}
            self.tails.save(self.set.q, self.set.qd)
            self._cres = {k: self.set.law[p, L_CRES] for k, p in self.index.items() if k[1] < 0}
            self._phi_xy = {k: xy for k, xy in self._phi_xy.items() if k in self._phi}

    def _pair_state(self, p):
        s = self.set
        return (s.touching[p], s.ramp[p], s.clamped[p], s.peak[p], s.t_peak[p], s.pen[p])

    def _build(self):
        b, m = self.balls, self.members
        old = getattr(self, "_pairs", {}) if self.set is not None else {}
        self.keys = [(i, -1) for i in m] + [
            (min(i, j), max(i, j)) for a, i in enumerate(m) for j in m[a + 1 :]
        ]
        local = {i: q for q, i in enumerate(m)}
        pairs = [(local[i], -1 if j < 0 else local[j]) for i, j in self.keys]
        laws = [b.table.law(i, PLATE if j < 0 else j) for i, j in self.keys]
        settle = [0.0 if i in self.quiet else self.settle_energy(i) for i in m]
        self._count()
        self.set = ActiveSet(
            [self._x[i] for i in m], [self._v[i] for i in m], b.mass[m], b.radius[m],
            np.array(pairs, dtype=np.int64).reshape(-1, 2), law_table(laws), b.g, b.half,
            settle_energy=np.array(settle), rtol=self.rtol, **self._modal_inputs(m),
        )  # fmt: skip
        self.index = {k: p for p, k in enumerate(self.keys)}
        s = self.set
        for k, p in self.index.items():
            if k in old:
                s.touching[p], s.ramp[p], s.clamped[p], s.peak[p], s.t_peak[p], s.pen[p] = old[k]
        s.h = self.h
        self.local = local
        self._carry_fresh(old)
        self.dirty = False
        self.totals["rebuilds"] += 1

    def _fresh_by_key(self) -> tuple[float, list]:
        """The built set's fresh rows (``ActiveSet.fresh_rows``: events just applied) by
        pair key, or (ball, edge) for an edge row."""
        t, rows = self.set.fresh_rows()
        return t, [
            (k, (self.members[i // 4], i % 4) if k == R_EDGE else self.keys[i]) for k, i in rows
        ]

    def _carry_fresh(self, old):
        """A rebuilt set carries the fresh rows of the set it replaces (a restart at the
        instant of an event must not find it again), translated to its own indices."""
        if not old:
            return
        t, rows = getattr(self, "_fresh", (math.nan, []))
        kept = []
        for k, key in rows:
            if k == R_EDGE:
                if key[0] in self.local:
                    kept.append((k, 4 * self.local[key[0]] + key[1]))
            elif key in self.index:
                kept.append((k, self.index[key]))
        self.set.set_fresh(t, kept)

    def _modal_inputs(self, members) -> dict:
        """The modal block of a rebuilt set: the plate's state now, the mode shapes under
        each member (rows of ball-ball pairs stay 0), the dead loads of resting non-members;
        resting members sit at their static penetration on the deflected plate."""
        plate = self.plate
        if plate is None:
            return {}
        plate.propagate(self.now)
        plate.set_dead_loads(*self.dead_loads())
        kept, kept_c = getattr(self, "_phi", {}), getattr(self, "_cres", {})
        new = [i for i in members if (i, -1) not in kept]
        new_phi, new_xy = self._shapes(new, [self._x[i][:2] for i in new])
        shapes = dict(zip(new, new_phi, strict=True))
        self._phi_xy.update({(i, -1): new_xy[k] for k, i in enumerate(new)})
        phi = np.zeros((len(self.keys), plate.n_modes))
        cres = np.zeros(len(self.keys))
        for q, i in enumerate(members):  # the plate pairs come first, in member order
            key = (i, -1)
            phi[q], cres[q] = (kept[key], kept_c[key]) if key in kept else (shapes[i], 0.0)
            if i in self.quiet:
                cres[q] = self._compliance(key)
                self._x[i][2] = self._static_height(i, cres[q]) + phi[q] @ plate.q
        atol_x = self.rtol * 1e-3
        scale = float(np.max(plate.phi_max))
        block = self.tails.block(plate, phi, self.keys.index)
        return dict(**block, atol_q=atol_x / scale, atol_qd=self.rtol / scale, compliance=cres)

    def _static_height(self, i: int, cres: float) -> float:
        """Height (m) of ball i resting on the undeflected plate: its static penetration,
        plus the residual spring's C m g_n in series (modal plate)."""
        b = self.balls
        return b.radius[i] - b.static_pen[i] - cres * b.mass[i] * -b.g[2]

    def _load_radius(self, i: int) -> float:
        """Radius (m) of the disc ball i's force is spread over in the residual compliance
        (tailbeam.physics.contact_patch: 0 on a Kirchhoff basis; the Hertz radius on Mindlin)."""
        if i not in self._load_radii:
            b = self.balls
            self._load_radii[i] = load_radius(self.plate.basis.theory, b.particles[i].ball(),
                                              b.plate_law(i), float(-b.g[2]))  # fmt: skip
        return self._load_radii[i]

    def refresh_shapes(self):
        """Modal plate: the mode shapes of every plate pair not touching, at its ball's
        position now (a touching pair keeps those of its contact point)."""
        if self.plate is None or not self.members:
            return
        s = self._ready()
        free = [(q, i) for q, i in enumerate(self.members) if not s.touching[self.index[(i, -1)]]]
        if not free:
            return
        shapes, points = self._shapes([i for _, i in free], [s.x[q, :2] for q, _ in free])
        moved = []
        for (_, i), shape, xy in zip(free, shapes, points, strict=True):
            p = self.index[(i, -1)]
            # only where the change of the plate under the ball cannot close its gap (a
            # ball just off the plate keeps its shapes: no start or end out of nothing); the
            # change includes the deflection of the tail of its last contact, dropped with them
            gap = -s.penetration(p)[0]
            n = len(shape)
            if gap > abs((shape - s.phi[p, :n]) @ s.q[:n] - s.phi[p, n:] @ s.q[n:]) + 1e-9:
                s.set_phi(p, np.concatenate([shape, np.zeros(s.phi.shape[1] - n)]))
                s.set_compliance(p, 0.0)  # (set when its contact starts)
                self._phi_xy[(i, -1)] = xy
                moved.append((i, -1))
        for key in moved:  # (after the set's own changes: dropping syncs and rebuilds it)
            self._drop_tail(key)

    def _compliance(self, key) -> float:
        """Residual compliance (m/N) of plate pair ``key`` at the point of its mode shapes."""
        i = key[0]
        return float(self.plate.compliance([self._phi_xy[key]], [self._load_radius(i)])[0])

    def _set_compliance(self, key):
        """Modal plate: plate pair ``key`` (touching from now) gets its tail (``_start_tail``)
        or its residual compliance."""
        if self.plate is not None and key[1] < 0 and not self._start_tail(key):
            self.set.set_compliance(self.index[key], self._compliance(key))

    # --- contact tails (tailbeam.plate.contact_tail, active_tails) -------------------
    def _start_tail(self, key) -> bool:
        """Plate pair ``key`` (touching from now) gets the oscillators of its contact point, at
        rest, and the spring of the modes above the tail's band; the set is rebuilt with them
        before the next step. A pair that touches again at the same point (its shapes not
        refreshed since) keeps its oscillators, still moving. False without a tail."""
        if key in self.tails:
            self.set.set_compliance(self.index[key], self.tails.modes(key).compliance)
            return True
        tail = self.plate.tail_at(self._phi_xy[key], self._load_radius(key[0]))
        if tail is None or not len(tail.nu):
            return False
        self.set.set_compliance(self.index[key], tail.compliance)
        self._sync()
        self._cres[key] = tail.compliance
        self.tails.add(key, tail)
        self.dirty = True
        return True

    def _drop_tail(self, key) -> None:
        """Drop plate pair ``key``'s oscillators (its ball moved on to new shapes, was put at
        rest or left; not when its contact ends: the plate under the ball would jump):
        their energy goes to ``tail_energy_dropped``."""
        if key not in self.tails:
            return
        self._sync()
        self.tails.drop(key)
        self.dirty = True

    @property
    def tail_energy_dropped(self) -> float:
        """Energy (J) the tails held when they were dropped."""
        return self.tails.dropped

    def tail_energy(self) -> float:
        """Energy (J) held by the tails of the contacts in progress."""
        if self.tails.states:
            self._sync()
        return self.tails.energy()

    def _shapes(self, balls, xy) -> tuple[np.ndarray, np.ndarray]:
        """Mode shapes (len, m) under ``balls`` at ``xy`` and the points (len, 2) they were
        computed at: each ball's cached row unless it moved more than SHAPE_REUSE since it
        was computed (one batched evaluation for the rest)."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        out = np.empty((len(balls), self.plate.n_modes))
        points = xy.copy()
        todo = []
        for k, i in enumerate(balls):
            cached = self._shape_cache.get(i)
            if cached is not None and np.hypot(*(cached[0] - xy[k])) <= SHAPE_REUSE:
                points[k], out[k] = cached
            else:
                todo.append(k)
        if todo:
            fresh = self.plate.shapes(xy[todo])
            for k, row in zip(todo, fresh, strict=True):
                out[k] = row
                self._shape_cache[balls[k]] = (xy[k].copy(), row)
        return out, points

    def _count(self):
        if self.set is not None:
            st = self.set.stats
            self.totals["kernel_steps"] += st["steps"]
            self.totals["kernel_attempts"] += st["attempts"]
            self.totals["kernel_nfev"] += st["nfev"]
            self.totals["events_found_again"] += st["found_again"]
            self.set.iout[3:6] = 0  # counted
            self.set.iout[IO_AGAIN] = 0

    def _ready(self):
        if self.dirty:
            self._build()
        return self.set

    # --- integration ----------------------------------------------------------------------------
    def advance(self, t: float, t_stop: float):
        """Integrate the members from t to t_stop or their first event: (kind, key, t_new),
        kind None (reached t_stop), "start"/"end" (key: pair key), "leave" (key: (ball, edge
        name)) or "settle" (key: ball)."""
        s = self._ready()
        out = s.advance(t, t_stop, self.h or None)
        self.h = s.h
        self._drain()
        if self.plate is not None:
            n = self.plate.n_modes
            self.plate.take(s.q[:n], s.qd[:n], out.t)
        kind = _KIND.get(out.kind)
        if kind is None:
            return None, None, out.t
        if kind in ("start", "end"):
            key = self.keys[out.index]
            if kind == "start":
                self._set_compliance(key)
            return kind, key, out.t
        ball = self.members[out.index]
        return kind, (ball, EDGES[out.edge]) if kind == "leave" else ball, out.t

    def _drain(self):
        """Move the plate force rows of the last advance into each ball's node lists."""
        s = self.set
        rows = s.force_rows()
        if len(rows):
            pairs = rows[:, 1].astype(np.int64)
            for p in np.unique(pairs):
                i = self.keys[p][0]
                sel = rows[pairs == p]
                entry = self.nodes.get(i)
                if entry is None:
                    x = s.x[self.local[i]]
                    entry = self.nodes[i] = [float(x[0]), float(x[1]), [], []]
                entry[2].append(sel[:, 0].copy())
                entry[3].append(sel[:, 2].copy())
        self.kinks = s.kink_log()
        s.clear_outputs()

    def take_plate_forces(self, i: int):
        """(x, y, t_nodes, forces) of ball i's plate force since the last take, or None."""
        entry = self.nodes.pop(i, None)
        if entry is None:
            return None
        t = np.concatenate(entry[2])
        f = np.concatenate(entry[3])
        order = np.argsort(t, kind="stable")
        if not t[order[-1]] > t[order[0]]:
            return None  # a single instant (a contact flushed as it started): no load
        return entry[0], entry[1], t[order], f[order]

    # --- state ----------------------------------------------------------------------------------
    def state(self, i: int):
        """Position (m) and velocity (m/s) of member i now."""
        if self.dirty:
            return self._x[i], self._v[i]
        q = self.local[i]
        return self.set.x[q].copy(), self.set.v[q].copy()

    def positions(self, idx) -> np.ndarray:
        return np.array([self.state(int(i))[0] for i in idx]).reshape(-1, 3)

    def energy(self, balls) -> float:
        """Kinetic energy of ``balls`` (members) plus the elastic energy of all contacts (J):
        what a contact among them can give to one of them."""
        s = self._ready()
        q = [self.local[int(i)] for i in balls]
        kinetic = 0.5 * float(np.sum(s.mass[q] * np.sum(s.v[q] * s.v[q], axis=1)))
        elastic = sum(s.contact_energy(p) for p in np.flatnonzero(s.touching))
        return kinetic + elastic

    def elastic_energy_of(self, i: int) -> float:
        """Elastic energy (J) of member i's touching plate pair plus half of each of its
        touching ball-ball pairs."""
        s = self._ready()
        total = 0.0
        for key in self.touching_pairs(i):
            share = 1.0 if key[1] < 0 else 0.5
            total += share * s.contact_energy(self.index[key])
        return total

    def touching_pairs(self, i: int) -> list:
        s = self._ready()
        return [k for k, p in self.index.items() if i in k[:1] + k[1:] and s.touching[p]]

    def start_contact(self, key):
        """Pair ``key`` starts touching now (its start was found in closed form)."""
        s = self._ready()
        p = self.index[key]
        delta, _ = s.penetration(p)
        s.touching[p], s.ramp[p], s.clamped[p] = True, True, False
        s.peak[p], s.t_peak[p], s.pen[p] = 0.0, math.nan, max(delta, 0.0)
        s.forget_fresh(p)
        self._set_compliance(key)
        step = first_contact_step(s.y, s.model(), p, self.rtol)
        self.h = min(self.h, step) if self.h else step

    def reset_accumulators(self, key):
        s = self._ready()
        p = self.index[key]
        s.peak[p], s.t_peak[p], s.pen[p] = 0.0, math.nan, max(s.penetration(p)[0], 0.0)

    def accumulators(self, key):
        """(peak force N, its time s, maximum penetration m) of pair ``key``."""
        s = self._ready()
        p = self.index[key]
        return float(s.peak[p]), float(s.t_peak[p]), float(s.pen[p])

    def make_quiet(self, i: int) -> float:
        """Put ball i at rest on the plate (static penetration, no normal speed); returns the
        normal excess energy (J) this removes."""
        s = self._ready()
        q, p = self.local[i], self.index[(i, -1)]
        removed = float(settle_excess(s.y, s.model(), p, q)) if s.touching[p] else 0.0
        if not s.touching[p]:  # a slow rebound: the energy of the normal motion above rest
            removed = 0.5 * s.mass[q] * s.v[q, 2] ** 2
        w, wd, cres = 0.0, 0.0, 0.0
        if self.plate is not None:  # at rest: the static spring of the whole tail, no oscillators
            n = self.plate.n_modes
            w, wd = s.phi[p, :n] @ s.q[:n], s.phi[p, :n] @ s.qd[:n]
            cres = self._compliance((i, -1))
            s.set_compliance(p, cres)
        s.x[q, 2] = self._static_height(i, cres) + w
        s.v[q, 2] = wd
        law = s.law[p]
        s.touching[p] = True
        s.ramp[p] = self.balls.static_pen[i] < law[3] or law[2] <= 0.0
        s.clamped[p] = False
        s.settle_energy[q] = 0.0
        s.forget_fresh(p)
        self.quiet.add(i)
        self._drop_tail((i, -1))
        return removed

    def wake(self, i: int):
        """Ball i takes part in a contact again: SETTLE may end its plate contact again."""
        if i in self.quiet:
            self.quiet.discard(i)
            s = self._ready()
            s.settle_energy[self.local[i]] = self.settle_energy(i)

    def steps(self) -> int:
        """Kernel steps so far (accepted)."""
        return self.totals["kernel_steps"] + (self.set.stats["steps"] if self.set else 0)

    def stats(self) -> dict:
        self._count()
        return dict(self.totals)
