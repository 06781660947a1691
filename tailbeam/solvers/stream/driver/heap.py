"""The stream driver's heap: releases, epochs and the predictions of the closed-form balls.

Balls that touch nothing move in closed form (``tailbeam.solvers.numerics.flight``) and carry
predictions in one heap, each tagged with the balls' versions (a prediction whose ball has
changed its motion since is stale and skipped): a particle's release, a new epoch (its
certified candidate pairs, ``broadphase``), a plate touch, the first touch of two balls, an
edge crossing. On the modal plate plate touches are predicted ``w_margin`` above the plate,
a margin kept above the plate's deflection bound. ``heap_events`` handles what comes due.
"""

import heapq
import math

import numpy as np

from tailbeam.solvers.stream.driver.balls import FLY, SLEEP
from tailbeam.solvers.stream.driver.broadphase import candidate_pairs

# kinds of heap entries (the order breaks ties at equal times: releases first)
RELEASE, EPOCH, PLATE_TOUCH, PAIR_TOUCH, EDGE = range(5)
MIN_EPOCH = 1e-4  # s: the shortest epoch


class Predictions:
    """The heap of the closed-form balls' events and the broad phase's epochs.

    Parameters
    ----------
    balls : Balls
        The stream's balls.
    clock : Clock
        The driver's time and counters.
    plate : StreamPlate or None
        The modal plate (its deflection bound sets the plate-touch margin), or None.
    """

    def __init__(self, balls, clock, plate=None):
        self.balls, self.clock, self.plate = balls, clock, plate
        self.heap, self.seq = [], 0
        self.epoch = epoch_length(balls, clock.duration)  # s
        self.epoch_end = 0.0  # s
        self.w_margin = 0.0  # m: plate touches are predicted this far above the plate

    def start(self) -> None:
        """The releases of every particle and the first epoch."""
        for i, t in enumerate(self.balls.t_release):
            self.push(float(t), RELEASE, i)
        self.push(0.0, EPOCH)

    def push(self, t: float, kind: int, i: int = -1, j: int = -1, edge: str = "") -> None:
        """Entry ``kind`` of balls i (and j) at t (s), tagged with their versions now."""
        vi = self.balls.version[i] if i >= 0 else 0
        vj = self.balls.version[j] if j >= 0 else 0
        self.seq += 1
        heapq.heappush(self.heap, (t, kind, self.seq, i, j, vi, vj, edge))

    def next_time(self) -> float:
        """Time (s) of the first entry (inf when empty)."""
        return self.heap[0][0] if self.heap else math.inf

    def pop(self):
        """The first entry (t, kind, seq, i, j, vi, vj, edge), or None when it is stale."""
        entry = heapq.heappop(self.heap)
        _t, _kind, _seq, i, j, vi, vj, _edge = entry
        b = self.balls
        if (i >= 0 and b.version[i] != vi) or (j >= 0 and b.version[j] != vj):
            self.clock.stats["stale"] += 1
            return None
        return entry

    def new_epoch(self) -> None:
        """Certified candidate pairs of the closed-form balls over the next epoch."""
        b, t = self.balls, self.clock.t
        self.clock.stats["epochs"] += 1
        self.epoch_end = min(t + self.epoch, self.clock.duration)
        if self.epoch_end < self.clock.duration:
            self.push(self.epoch_end, EPOCH)
        idx = b.closed_form()
        if len(idx) < 2:
            return
        horizon = self.epoch_end - t
        x, _ = b.states(idx, t)
        pairs = candidate_pairs(x, b.radius[idx], b.speed_bounds(idx, t, horizon), horizon)
        asleep = b.status[idx] == SLEEP
        if len(pairs) and asleep.any():  # two sleeping balls stand still: never a new touch
            pairs = pairs[~(asleep[pairs[:, 0]] & asleep[pairs[:, 1]])]
        for a, c in pairs:
            i, j = int(idx[a]), int(idx[c])
            if not (b.in_set[i] and b.in_set[j]):
                self._predict_pair(i, j, horizon)

    def predict(self, i: int) -> None:
        """Own events of closed-form ball i, and its touches with the other closed-form
        balls within the epoch."""
        for t_ev, what, edge in self.balls.own_events(i, self.clock.t, self.w_margin):
            self.push(t_ev, PLATE_TOUCH if what == "plate" else EDGE, i, edge=edge)
        self._predict_pairs(i)

    def _predict_pairs(self, i: int) -> None:
        """Touches of closed-form ball i with the others within the epoch (not the pairs
        the active set watches)."""
        b, t = self.balls, self.clock.t
        horizon = self.epoch_end - t
        others = b.closed_form()
        others = others[(others != i) & ~(b.in_set[others] & b.in_set[i])]
        if b.status[i] == SLEEP:  # (two sleeping balls stand still)
            others = others[b.status[others] != SLEEP]
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

    def _predict_pair(self, i: int, j: int, horizon: float) -> None:
        t_ev = self.balls.pair_event(i, j, self.clock.t, horizon)
        if math.isfinite(t_ev):
            self.push(t_ev, PAIR_TOUCH, min(i, j), max(i, j))

    def check_margin(self) -> None:
        """Modal plate: keep the plate-touch predictions above the plate's deflection bound;
        when it has grown past the margin, double the margin and predict again."""
        if self.plate is None:
            return
        bound = self.plate.deflection_bound()
        if bound <= self.w_margin:
            return
        self.w_margin = max(2.0 * bound, 1e-9)
        self.clock.count("margin_updates")
        b = self.balls
        for i in np.flatnonzero((b.status == FLY) & ~b.in_set):
            for t_ev, what, _edge in b.own_events(int(i), self.clock.t, self.w_margin):
                if what == "plate":
                    self.push(t_ev, PLATE_TOUCH, int(i))


def epoch_length(balls, duration: float) -> float:
    """Epochs (s) short enough that balls move about their radius in one: O(1) candidate
    pairs per ball."""
    if not len(balls.names):
        return duration
    speed = np.linalg.norm(balls.v0, axis=1).max() + 1.0
    return float(min(duration, max(MIN_EPOCH, 0.5 * balls.radius.min() / speed)))
