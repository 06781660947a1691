"""The coupled driver's records: the contacts in progress, the events, the Impact record of
each finished contact (``close_contact``) and when each ball came to rest."""

import math

import numpy as np

from tailbeam.results.records import PLATE, Event, EventKind, Impact


class ContactBook:
    """The records of a run of ``balls`` (their names): ``events`` and ``impacts`` (both
    ``tailbeam.results.records``), the contacts in progress by ball (``open``: index, start
    time s, v_in m/s, first node, time limit s), each contact's point (``contact_points``:
    t_start s, ball, x m, y m, load radius m) and each ball's rest time (s, nan if none)."""

    def __init__(self, balls):
        self.balls = balls
        self.events, self.impacts, self.open, self.contact_points = [], [], {}, []
        self.counts = [0] * len(balls)
        self.rest_time = {b.name: math.nan for b in balls}

    def event(self, t: float, b: int, kind: EventKind) -> None:
        self.events.append(Event(t, self.balls[b].name, kind, PLATE))

    def start(self, b: int, t: float, point: tuple, v_in: float, node: int, t_limit: float):
        """Ball b's contact starts at t (s) at ``point`` (x m, y m, load radius m)."""
        self.contact_points.append((t, b, *point))
        self.counts[b] += 1
        self.open[b] = {"index": self.counts[b], "t_start": t, "v_in": v_in, "node": node,
                        "t_limit": t_limit}  # fmt: skip

    def rest(self, b: int, t: float) -> None:
        """Ball b came to rest at t (s)."""
        self.rest_time[self.balls[b].name] = t
        self.event(t, b, EventKind.REST)


def close_contact(info, b, ball, t_end, v_out, bufs, nbuf, radius, gravity, *, at_rest, z=math.nan):
    """The Impact record of a finished contact (peak refined by a parabola through 3 nodes)."""
    bt, _bz, _bvz, bF, bd = bufs
    i0 = info["node"]
    ts, fs, ds = bt[i0:nbuf], bF[i0:nbuf, b], bd[i0:nbuf, b]
    j = int(np.argmax(fs))
    peak, t_peak = float(fs[j]), float(ts[j])
    if 0 < j < len(fs) - 1:
        t0, t1, t2 = ts[j - 1 : j + 2]
        f0, f1, f2 = fs[j - 1 : j + 2]
        # vertex of the parabola through the three nodes (non-uniform spacing)
        d01, d12 = (f1 - f0) / (t1 - t0), (f2 - f1) / (t2 - t1)
        curv = (d12 - d01) / (t2 - t0)
        if curv < 0:
            tv = 0.5 * (t0 + t1) - d01 / (2 * curv)
            if t0 <= tv <= t2:
                fv = f1 + d01 * (tv - t1) + curv * (tv - t0) * (tv - t1)
                if fv >= peak:
                    peak, t_peak = float(fv), float(tv)
    v_in = float(info["v_in"])
    v_out = float(v_out)
    apex = math.nan
    if not at_rest and math.isfinite(v_out) and v_out > 0:
        apex = float(z) - radius + (v_out**2 / (2 * gravity) if gravity > 0 else math.inf)
    return Impact.single_ball(
        ball,
        index=info["index"],
        t_start=float(info["t_start"]),
        t_end=float(t_end),
        v_in=v_in,
        v_out=0.0 if at_rest else v_out,
        peak_force=peak,
        t_peak=t_peak,
        max_penetration=float(np.max(ds)) if len(ds) else math.nan,
        next_apex_height=apex,
        at_rest=bool(at_rest),
    )
