"""Advancing the active set and handling what it reports.

The active set (``tailbeam.solvers.stream.active.members``) integrates its members up to a
target time, its horizon or its own next event (an ``EventCode``): a contact start or end,
a plate contact settling (REST), a ball leaving over an edge; the kinks it passed are logged
as events. A plate contact that ends slower than ``rest_speed`` (or that ends and starts
again at one instant, grazing) leaves the ball at rest on the plate; with friction (rigid
plate, sleeping on) a plate contact ending slower than ``rest_speed`` goes on: the ball is
held on the plate at its static penetration and integrated on (rolling, sliding or held).
"""

from tailbeam.results.records import PLATE, End, EventCode


class SetEvents:
    """The stepping of the active set and its events.

    Parameters
    ----------
    balls : Balls
        The stream's balls.
    act : ActiveMembers
        The active set.
    clock : Clock
        The driver's time and counters.
    heap : Predictions
        The closed-form balls' predictions (their plate-touch margin follows the plate).
    membership : Membership
        Core, members and the set's horizon.
    records : ContactRecords
        The contacts and events.
    loads : PlateLoads
        The plate's loads.
    ledger : EnergyLedger
        The energy ledger.
    rest_speed : float
        Speed (m/s) below which a plate contact that ends leaves the ball at rest.
    """

    def __init__(self, balls, act, clock, heap, membership, records, loads, ledger,
                 rest_speed: float):  # fmt: skip
        self.balls, self.act, self.clock, self.heap = balls, act, clock, heap
        self.membership, self.records, self.loads, self.ledger = membership, records, loads, ledger
        self.rest_speed = rest_speed
        self.grazing = {}  # ball -> (time s of its last plate contact end, how many then)
        self.handlers = {
            EventCode.CONTACT_START: membership.start,
            EventCode.CONTACT_END: self._on_end,
            EventCode.REST: membership.settle,
            EventCode.LEAVE: self._on_leave,
        }

    def advance(self, target: float) -> bool:
        """Advance the active set towards ``target`` (s); True if it stopped earlier (an
        event of its own, or its horizon: the loop then starts over)."""
        stop = min(target, self.membership.set_end)
        code, key, t_new = self.act.next_event(self.clock.t, stop)
        self.clock.stats["set_calls"] += 1
        self.clock.t = self.act.now = t_new
        self.heap.check_margin()
        self._log_kinks()
        if code != EventCode.NONE:
            self.clock.stats["set_events"] += 1
            self.handlers[code](key)
            self.membership.refresh()
            return True
        if stop < target:
            self.membership.refresh()
            return True
        return False

    def _log_kinks(self) -> None:
        for t, kind, (i, j) in self.act.kinks:
            self.records.event(t, i, kind, PLATE if j < 0 else self.balls.names[j])

    def _on_end(self, key) -> None:
        i, j = key
        for k in key:
            if k >= 0:
                self.membership.hold(k)
        if not self.records.is_open(key):  # a pair the set found overlapping (late_starts)
            return
        if j >= 0:
            self.records.close(key, End.SEPARATED)
            return
        others = [p for p in self.act.touching_pairs(i) if p != key]
        v_out = self.act.state(i)[1][2]
        slow = 0.0 <= v_out < self.rest_speed and self.balls.g[2] < 0.0
        if self._grazing(i) and self.act.friction is None:  # ends and starts again at one
            # instant: it rests on the plate (with friction it rolls or is held on)
            slow = True
            self.clock.count("grazing_rests")
        if slow and not others and self.act.friction is not None:
            # with friction: held on the plate, its contact going on (rolling, sliding or
            # held by friction: ``sleep``); the slow rebound's energy is removed
            self.ledger.removed_at_rest(self.act.make_quiet(i))
            self.clock.count("slow_rebounds_held")
            return
        self.records.close(key, End.REST if slow and not others else End.SEPARATED)
        self.loads.flush(i)
        if slow and not others:
            self.ledger.removed_at_rest(self.act.make_quiet(i))

    def _grazing(self, i: int) -> bool:
        """The plate contact of ball i ended at this instant before (it started again at
        once: zero speed relative to the vibrating plate): the second time, True."""
        t = self.clock.t
        t_prev, count = self.grazing.get(i, (None, 0))
        count = count + 1 if t_prev == t else 1
        self.grazing[i] = (t, count)
        return count >= 2

    def _on_leave(self, what) -> None:
        i, edge = what
        self.ledger.left(i, *self.act.state(i))
        for key in self.act.touching_pairs(i):
            if self.records.is_open(key):
                self.records.close(key, End.LEFT)
        self.loads.flush(i)
        self.membership.leave(i)
        self.records.leave(i, self.clock.t, edge)
