"""The Impact record of a finished contact of the coupled driver."""

import math

import numpy as np

from tailbeam.results.records import Impact


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
