"""What a stream delivered: its releases in its window against what it was asked for.

A solver releases a particle whose place a ball already there (a rebound) takes at another
free place of its release volume, or later than drawn when it finds none; ``delivery``
compares the particles as released with those drawn, per stream:

    rate                 the requested rate, particles/s
    window_s             [start, end] in s: the release window, cut at the simulated duration
    drawn_in_window      particles drawn with a release time in the window (a Poisson count of
                         mean rate x window)
    released_in_window   particles actually released in the window
    delivered_rate       released_in_window / (end - start), particles/s
    release_delay_max    largest delay of a release after its drawn time, s
    delayed_releases     particles released after their drawn time
    moved_releases       particles released at another place of the release volume
"""

import math

import numpy as np


def delivery(streams, drawn, released, duration: float) -> dict:
    """Per stream name, the entries of the module docstring.

    Parameters
    ----------
    streams : sequence of StreamSettings
        The scene's streams (``tailbeam.streams.generator``).
    drawn, released : sequence of Particle
        The particles as generated and as the solver released them, in the same order.
    duration : float
        Simulated time (s).
    """
    out = {}
    for s in streams:
        pairs = [(d, r) for d, r in zip(drawn, released, strict=True) if d.stream == s.name]
        t0, t1 = s.start, min(s.stop, duration)
        t_drawn = np.array([d.t_release for d, _ in pairs])
        t_real = np.array([r.t_release for _, r in pairs])
        in_window = int(np.count_nonzero((t_real >= t0) & (t_real < t1)))
        out[s.name] = {
            "rate": s.rate,
            "window_s": [t0, t1],
            "drawn_in_window": int(np.count_nonzero((t_drawn >= t0) & (t_drawn < t1))),
            "released_in_window": in_window,
            "delivered_rate": in_window / (t1 - t0) if t1 > t0 else math.nan,
            "release_delay_max": float(np.max(t_real - t_drawn, initial=0.0)),
            "delayed_releases": int(np.count_nonzero(t_real > t_drawn)),
            "moved_releases": sum(d.position != r.position for d, r in pairs),
        }
    return out


def delivery_line(name: str, d: dict) -> str:
    """One line saying what stream ``name`` delivered (``delivery``'s entry ``d``)."""
    t0, t1 = d["window_s"]
    return (
        f"stream {name}: delivered {d['delivered_rate']:.4g} particles/s of the {d['rate']:g} "
        f"asked ({d['released_in_window']} released in [{t0:g}, {t1:g}) s, "
        f"{d['drawn_in_window']} drawn); {d['moved_releases']} moved to a free place of the "
        f"release volume, {d['delayed_releases']} released late, largest release delay "
        f"{d['release_delay_max']:.3g} s"
    )
