"""What the stream driver does when a heap entry comes due (``heap``): a particle's release, a
new epoch, a plate touch, the first touch of two balls, an edge crossing. A touch makes its
balls join the active set (``membership``).

A particle whose release position is taken by a ball already there (the generator knows only
the free flights of earlier particles, not their rebounds) is released at its time at the
first free candidate of its stream's release volume (``ReleaseSlot.candidates``: drawn from
its seed and number alone), and only when none is free waits RELEASE_RETRY and tries again."""

import numpy as np

from tailbeam.results.records import EventKind
from tailbeam.solvers.stream.driver.balls import ACTIVE, FLY, GONE, SLEEP, SLIDE
from tailbeam.solvers.stream.driver.heap import EDGE, EPOCH, PAIR_TOUCH, PLATE_TOUCH, RELEASE

RELEASE_RETRY = 1e-3  # s: a particle that would overlap a ball at its release waits this long


class HeapEvents:
    """The handlers of the heap's entries.

    Parameters
    ----------
    balls : Balls
        The stream's balls.
    act : ActiveMembers
        The active set.
    clock : Clock
        The driver's time and counters.
    heap : Predictions
        The heap.
    membership : Membership
        Core, members and the set's horizon.
    records : ContactRecords
        The contacts and events.
    loads : PlateLoads
        The plate's loads.
    ledger : EnergyLedger
        The energy ledger.
    plate : StreamPlate or None
        The modal plate, or None.
    """

    def __init__(self, balls, act, clock, heap, membership, records, loads, ledger,
                 plate=None):  # fmt: skip
        self.balls, self.act, self.clock, self.heap = balls, act, clock, heap
        self.membership, self.records, self.loads, self.ledger = membership, records, loads, ledger
        self.plate = plate

    def handle(self, entry) -> None:
        """Handle the heap entry (t, kind, seq, i, j, vi, vj, edge) that came due."""
        t, kind, _seq, i, j, _vi, _vj, edge = entry
        b = self.balls
        self.clock.stats["heap_events"] += 1
        closed_form = (FLY, SLIDE, SLEEP)
        if kind == RELEASE:
            self._release(i)
        elif kind == EPOCH:
            self.heap.new_epoch()
        elif kind == PLATE_TOUCH and b.status[i] == FLY and not b.in_set[i]:
            if self.plate is None:
                self.membership.join([i], (i, -1))
            else:  # near the vibrating plate: the integrator finds the real start
                self.membership.land(i)
        elif kind == PAIR_TOUCH and not (b.in_set[i] and b.in_set[j]):
            if b.status[i] in closed_form and b.status[j] in closed_form:
                self.membership.join([i, j], (min(i, j), max(i, j)))
        elif kind == EDGE and b.status[i] in closed_form and not b.in_set[i]:
            self._leave(i, edge, t)

    def _release(self, i: int) -> None:
        b, t = self.balls, self.clock.t
        centres, reach = self._occupants(i)
        if _taken(centres, reach, b.x0[i][None, :])[0]:
            slot = self._free_slot(i, centres, reach)
            if slot is None:
                self.clock.stats["postponed_releases"] += b.t_release[i] == b.particles[i].t_release
                b.t_release[i] = t + RELEASE_RETRY
                self.heap.push(b.t_release[i], RELEASE, i)
                return
            b.x0[i] = b.release_position[i] = slot
            self.clock.stats["moved_releases"] += 1
        b.set_motion(i, FLY, t, b.x0[i].copy(), b.v0[i].copy())
        x, v = b.state(i, t)
        self.ledger.released(i, x, v)
        self.records.event(t, i, EventKind.RELEASE, "")
        self.heap.predict(i)
        if self.act.members:
            self.membership.refresh()

    def _occupants(self, i: int):
        """(centres (m, k x 3), reach (m, k)) of the balls present now: a centre closer than
        its reach to particle i's would overlap it."""
        b = self.balls
        others = b.closed_form()
        centres = b.states(others, self.clock.t)[0] if len(others) else np.empty((0, 3))
        core = [k for k in self.act.members if b.status[k] == ACTIVE]
        if core:
            centres = np.vstack([centres, self.act.positions(core)])
            others = np.concatenate([others, np.array(core, dtype=np.int64)])
        return centres, b.radius[others] + b.radius[i]

    def _free_slot(self, i: int, centres, reach):
        """The first candidate of particle i's release volume that no ball takes now (m), or
        None (none of them, or the particle has no release volume: a ``[[balls]]`` entry)."""
        slot = self.balls.particles[i].slot
        if slot is None:
            return None
        candidates = slot.candidates(self.balls.radius[i])
        free = np.flatnonzero(~_taken(centres, reach, candidates))
        return candidates[free[0]].copy() if len(free) else None

    def _leave(self, i: int, edge: str, t: float) -> None:
        """Closed-form ball i passes ``edge`` at t (s): gone."""
        b = self.balls
        self.ledger.left(i, *b.state(i, t))
        if b.status[i] == SLIDE:
            self.loads.dead_load(i, t)
        b.status[i] = GONE
        b.version[i] += 1
        self.records.leave(i, t, edge)


def _taken(centres, reach, points) -> np.ndarray:
    """For each of ``points`` (m, p x 3): does a ball of ``centres`` overlap it (distance
    below its ``reach``)?"""
    if not len(centres):
        return np.zeros(len(points), dtype=bool)
    d2 = np.sum((points[:, None, :] - centres[None, :, :]) ** 2, axis=2)
    return np.any(d2 < reach[None, :] ** 2, axis=1)
