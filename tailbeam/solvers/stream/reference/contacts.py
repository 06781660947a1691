"""What the stream reference writes out: the contact records (one ``Impact`` per ball per
contact), the leaves and the event log; a pair's contact opens and closes here.
"""

from tailbeam.results.records import PLATE, Event, EventKind, Impact, LeaveEvent


class ContactLog:
    """The records of a run: ``contacts`` (``Impact``), ``leaves`` (``LeaveEvent``) and
    ``events`` (``Event``), each in time order.

    Parameters
    ----------
    balls : list of Ball
        The scene's balls (names, radii in m).
    plate : ReferencePlate or None
        The modal plate (a frozen contact keeps its shapes), or None for the rigid plate.
    """

    def __init__(self, balls, plate):
        self.balls = balls
        self.plate = plate
        self.contacts = []
        self.leaves = []
        self.events = []
        self.spin_at_leave = {}  # name -> angular velocity (3,) rad/s when it left (friction)

    def log(self, t, kind, pair) -> None:
        """Log event ``kind`` (``EventKind``) of ``pair`` at time t (s)."""
        self.events.append(Event(t, self.balls[pair.i].name, kind, self.partner_name(pair)))

    def partner_name(self, pair) -> str:
        """The name of ball i's partner in ``pair``: ``PLATE`` or ball j's name."""
        return PLATE if pair.j < 0 else self.balls[pair.j].name

    def open(self, pair, t, kin, x_i, v, li, lj) -> None:
        """Start the contact of ``pair`` at time t (s) with its records (one per ball).

        kin: the pair's ``PairKinematics`` at t; x_i: ball i's centre (m); v: velocities
        (n, 3) of the present balls (m/s); li, lj: state positions of balls i and j.
        """
        n = kin.normal[0]
        point = x_i - n * (self.balls[pair.i].radius - 0.5 * max(kin.penetration[0], 0.0))
        v_in = float(-v[li] @ n)
        # approach speed of a plate row: the ball's (as v_in), also on the modal plate
        rate = float(kin.rate[0]) if pair.j >= 0 or self.plate is None else v_in
        records = [
            Impact(ball=self.balls[pair.i].name, partner=self.partner_name(pair), t_start=t,
                   x=point[0], y=point[1], v_in=v_in, approach_in=rate)
        ]  # fmt: skip
        if pair.j >= 0:
            records.append(
                Impact(ball=self.balls[pair.j].name, partner=self.balls[pair.i].name,
                       t_start=t, x=point[0], y=point[1], v_in=float(v[lj] @ n),
                       approach_in=rate)
            )  # fmt: skip
        phi0 = grad0 = None
        if pair.j < 0 and self.plate is not None and self.plate.frozen:
            phi0, grad0 = (a[0] for a in self.plate.shapes_and_gradients(x_i[:2]))
        pair.start(records, float(kin.penetration[0]), phi0, grad0)
        self.contacts.extend(records)
        self.log(t, EventKind.CONTACT_START, pair)

    def close(self, pair, t, kin, v, li, lj, end, slip=float("nan")) -> None:
        """End the contact of ``pair`` at time t (s) as ``end`` (an ``End``); arguments as
        ``open``; ``slip``: the slip speed at the end (m/s, with friction)."""
        n = kin.normal[0]
        outs = [float(v[li] @ n)] + ([float(-v[lj] @ n)] if pair.j >= 0 else [])
        # approach speeds of a plate row: the ball's (as v_in, v_out), also on the modal plate
        out = -float(kin.rate[0]) if pair.j >= 0 or self.plate is None else outs[0]
        for rec, v_out in zip(pair.records, outs, strict=True):
            rec.t_end, rec.v_out, rec.approach_out, rec.end = t, v_out, out, end
        pair.stop(slip)
        self.log(t, EventKind.CONTACT_END, pair)

    def left(self, ball, edge, t, spin=None) -> None:
        """Record that ``ball`` (index) left over ``edge`` (``x+``, ...) at time t (s), with
        angular velocity ``spin`` (3,) rad/s (with friction; else None)."""
        name = self.balls[ball].name
        if spin is not None:
            self.spin_at_leave[name] = spin.copy()
        self.leaves.append(LeaveEvent(name, t, edge))
        self.events.append(Event(t, name, EventKind.LEAVE, edge))

    def released(self, ball, t) -> None:
        """Record that ``ball`` (index) entered the scene at time t (s)."""
        self.events.append(Event(t, self.balls[ball].name, EventKind.RELEASE, ""))
