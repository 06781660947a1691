"""The stream driver's heap: releases, epochs and the predictions of the closed-form balls
(a mixin of ``tailbeam.solvers.stream.driver.loop._Stream``, which provides ``balls``, ``act``,
``t``, ``heap``, ``seq``, ``epoch``, ``epoch_end``, ``duration``, ``plate``, ``landing``,
``w_margin``, ``events``, ``leaves``, ``stats`` and the membership of ``stream_membership``).

Balls that touch nothing move in closed form (``tailbeam.solvers.numerics.flight``) and carry
predictions in one heap, each tagged with the balls' versions (a prediction whose ball has
changed its motion since is stale and skipped): a particle's release (postponed by
RELEASE_RETRY while it would overlap a ball already there), a new epoch (its certified
candidate pairs, ``tailbeam.solvers.stream.driver.broadphase``), a plate touch, the first touch of
two balls, an edge crossing. A touch makes its balls join the active set.
"""

import heapq
import math

import numpy as np

from tailbeam.physics.contact_law import elastic_energy
from tailbeam.results.records import Event, EventKind, LeaveEvent
from tailbeam.solvers.stream.driver.balls import ACTIVE, FLY, GONE, SLIDE
from tailbeam.solvers.stream.driver.broadphase import candidate_pairs

RELEASE_RETRY = 1e-3  # s: a particle that would overlap a ball at its release waits this long
# heap event kinds (the order breaks ties at equal times: releases first)
_RELEASE, _EPOCH, _PLATE, _PAIR, _EDGE = range(5)


class StreamHeap:
    """The heap events of the stream driver and the closed-form balls' predictions."""

    def push(self, t, kind, i=-1, j=-1, edge=""):
        vi = self.balls.version[i] if i >= 0 else 0
        vj = self.balls.version[j] if j >= 0 else 0
        self.seq += 1
        heapq.heappush(self.heap, (t, kind, self.seq, i, j, vi, vj, edge))

    def _handle(self, entry):
        t, kind, _seq, i, j, vi, vj, edge = entry
        b = self.balls
        if (i >= 0 and b.version[i] != vi) or (j >= 0 and b.version[j] != vj):
            self.stats["stale"] += 1
            return
        self.stats["heap_events"] += 1
        if kind == _RELEASE:
            self._release(i)
        elif kind == _EPOCH:
            self._new_epoch()
        elif kind == _PLATE and b.status[i] == FLY and not b.in_set[i]:
            if self.plate is None:
                self._join([i], t, (i, -1))
            else:  # near the vibrating plate: the integrator finds the real start
                self._absorb(i)
                self.landing.add(i)
                self._make_core(i)
                self._refresh_set()
        elif kind == _PAIR and not (b.in_set[i] and b.in_set[j]):
            if b.status[i] in (FLY, SLIDE) and b.status[j] in (FLY, SLIDE):
                self._join([i, j], t, (min(i, j), max(i, j)))
        elif kind == _EDGE and b.status[i] in (FLY, SLIDE) and not b.in_set[i]:
            self._leave(i, edge, t)

    # --- heap events --------------------------------------------------------------------------
    def _release(self, i: int):
        b = self.balls
        if self._overlaps_at_release(i):
            self.stats["postponed_releases"] += b.t_release[i] == b.particles[i].t_release
            b.t_release[i] = self.t + RELEASE_RETRY
            self.push(b.t_release[i], _RELEASE, i)
            return
        b.set_motion(i, FLY, self.t, b.x0[i].copy(), b.v0[i].copy())
        x, v = b.state(i, self.t)
        on_plate = float(elastic_energy(b.radius[i] - x[2], b.plate_law(i)))  # released there
        self.stats["energy_released"] += self._ball_energy(i, x, v) + on_plate
        self.events.append(Event(self.t, b.names[i], EventKind.RELEASE, ""))
        self._predict(i)
        if self.act.members:
            self._refresh_set()

    def _overlaps_at_release(self, i: int) -> bool:
        """Does particle i, released now, overlap a ball already there (the generator
        only knows the free flights of earlier particles, not their rebounds)?"""
        b = self.balls
        others = b.closed_form()
        centres = b.states(others, self.t)[0] if len(others) else np.empty((0, 3))
        core = [k for k in self.act.members if b.status[k] == ACTIVE]
        if core:
            centres = np.vstack([centres, self.act.positions(core)])
            others = np.concatenate([others, np.array(core, dtype=np.int64)])
        reach = b.radius[others] + b.radius[i]
        return bool(np.any(np.sum((centres - b.x0[i]) ** 2, axis=1) < reach**2))

    def _new_epoch(self):
        """Certified candidate pairs of the closed-form balls over the next epoch."""
        b, t = self.balls, self.t
        self.stats["epochs"] += 1
        self.epoch_end = min(t + self.epoch, self.duration)
        if self.epoch_end < self.duration:
            self.push(self.epoch_end, _EPOCH)
        idx = b.closed_form()
        if len(idx) < 2:
            return
        horizon = self.epoch_end - t
        x, _ = b.states(idx, t)
        pairs = candidate_pairs(x, b.radius[idx], b.speed_bounds(idx, t, horizon), horizon)
        for a, c in pairs:
            i, j = int(idx[a]), int(idx[c])
            if not (b.in_set[i] and b.in_set[j]):
                self._predict_pair(i, j, horizon)

    def _predict(self, i: int):
        """Own events of closed-form ball i, and its touches with the other closed-form
        balls within the epoch."""
        for t_ev, what, edge in self.balls.own_events(i, self.t, self.w_margin):
            self.push(t_ev, _PLATE if what == "plate" else _EDGE, i, edge=edge)
        self._predict_pairs(i)

    def _predict_pairs(self, i: int):
        """Touches of closed-form ball i with the others within the epoch (not the pairs
        the active set watches)."""
        b, t = self.balls, self.t
        horizon = self.epoch_end - t
        others = b.closed_form()
        others = others[(others != i) & ~(b.in_set[others] & b.in_set[i])]
        if horizon <= 0.0 or not len(others):
            return
        xo, _ = b.states(others, t)
        xi, _ = b.state(i, t)
        reach = (
            b.radius[others] + b.radius[i]
            + (b.speed_bounds(others, t, horizon) + b.speed_bounds([i], t, horizon)) * horizon
        )  # fmt: skip
        for j in others[np.sum((xo - xi) ** 2, axis=1) <= reach**2]:
            self._predict_pair(i, int(j), horizon)

    def _predict_pair(self, i: int, j: int, horizon: float):
        t_ev = self.balls.pair_event(i, j, self.t, horizon)
        if math.isfinite(t_ev):
            self.push(t_ev, _PAIR, min(i, j), max(i, j))

    def _join(self, ids, t: float, key):
        """Closed-form balls ``ids`` start the contact ``key`` at time t."""
        for i in ids:
            if not self.balls.in_set[i]:
                self._absorb(i)
        self.act.start_contact(key)
        self._on_start(key)
        self._refresh_set()

    def _leave(self, i: int, edge: str, t: float):
        b = self.balls
        self.stats["energy_left"] += self._ball_energy(i, *b.state(i, t)) + self._elastic(i)
        if b.status[i] == SLIDE:
            self._dead_load(i, t)
        b.status[i] = GONE
        b.version[i] += 1
        self.leaves.append(LeaveEvent(b.names[i], t, edge))
        self.events.append(Event(t, b.names[i], EventKind.LEAVE, edge))
