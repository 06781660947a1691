"""The stream driver's stepping of the active set and what the set reports (a mixin of
``tailbeam.solvers.stream.driver.loop._Stream``, which provides ``balls``, ``act``, ``t``,
``set_end``, ``open``, ``hold``, ``grazing``, ``landing``, ``rest_speed``, ``events``,
``leaves``, ``stats``, the records of ``stream_records`` and the membership of
``stream_membership``).

The active set (``tailbeam.solvers.stream.active.members``) integrates its members up to a
target time, its horizon or its own next event: a contact start or end, a plate contact
settling, a ball leaving over an edge, with the kinks it passed (logged as events). A plate
contact that ends slower than ``rest_speed`` (or that ends and starts again at one instant,
grazing) leaves the ball at rest on the plate.
"""

from tailbeam.results.records import PLATE, Event, EventKind, LeaveEvent
from tailbeam.solvers.stream.driver.balls import GONE


class StreamSetEvents:
    """Advancing the active set and handling its events."""

    def _advance_set(self, target: float) -> bool:
        """Advance the active set towards ``target``; True if it stopped earlier (an event
        of its own, or its horizon: the loop then starts over)."""
        stop = min(target, self.set_end)
        kind, key, t_new = self.act.advance(self.t, stop)
        self.stats["set_calls"] += 1
        self.t = self.act.now = t_new
        self._check_margin()
        self._log_kinks()
        if kind is not None:
            self.stats["set_events"] += 1
            getattr(self, f"_on_{kind}")(key)
            self._refresh_set()
            return True
        if stop < target:
            self._refresh_set()
            return True
        return False

    def _log_kinks(self):
        for t, name, p in self.act.kinks:
            i, j = self.act.keys[p]
            partner = PLATE if j < 0 else self.balls.names[j]
            self.events.append(Event(t, self.balls.names[i], EventKind(name), partner))

    def _on_start(self, key):
        self.landing.discard(key[0])
        self._open(key)
        for k in key:
            if k >= 0:
                self._make_core(k)

    def _on_end(self, key):
        i, j = key
        for k in key:  # the set keeps its members until time moves on (no rebuild at the end
            if k >= 0:  # instant: a rebuilt set could find the same contact starting again)
                self.hold[k] = self.t
        if key not in self.open:  # a pair the set found overlapping (counted in late_starts)
            return
        if j >= 0:
            self._close(key, "separated")
            return
        others = [p for p in self.act.touching_pairs(i) if p != key]
        v_out = self.act.state(i)[1][2]
        slow = 0.0 <= v_out < self.rest_speed and self.balls.g[2] < 0.0
        if self._grazing(i):  # ends and starts again at one instant: it rests on the plate
            slow = True
            self.stats["grazing_rests"] = self.stats.get("grazing_rests", 0) + 1
        self._close(key, "rest" if slow and not others else "separated")
        self._flush_nodes(i)
        if slow and not others:
            self.stats["rest_energy_removed"] += self.act.make_quiet(i)

    def _grazing(self, i: int) -> bool:
        """The plate contact of ball i ended at this instant before (it started again at
        once: zero speed relative to the vibrating plate): the second time, True."""
        t_prev, count = self.grazing.get(i, (None, 0))
        count = count + 1 if t_prev == self.t else 1
        self.grazing[i] = (self.t, count)
        return count >= 2

    def _on_settle(self, i):
        self._close((i, -1), "rest")
        self.stats["rest_energy_removed"] += self.act.make_quiet(i)

    def _on_leave(self, what):
        i, edge = what
        b = self.balls
        self.stats["energy_left"] += self._ball_energy(i, *self.act.state(i)) + self._elastic(i)
        for key in self.act.touching_pairs(i):
            if key in self.open:
                self._close(key, "left")
        self._flush_nodes(i)
        self.act.remove(i)
        b.in_set[i] = False
        b.status[i] = GONE
        b.version[i] += 1
        self.core.discard(i)
        self.landing.discard(i)
        self.leaves.append(LeaveEvent(b.names[i], self.t, edge))
        self.events.append(Event(self.t, b.names[i], EventKind.LEAVE, edge))
