"""The vocabulary of the paper's claims: the Claim record, thresholds and bounce sequences.

The claims themselves are in tailbeam.paper.claims (registry) with their checks in
tailbeam.paper.claims_velocity (4.1) and tailbeam.paper.claims_material (4.2, 4.3).

Rebound height = apex of the ball's lowest point above the plate after a collision
(Impact.next_apex_height); rebound speed = Impact.v_out; only collisions followed by a flight
have either.
"""

import math
from dataclasses import dataclass

from tailbeam.physics.bodies import STANDARD_GRAVITY

# "Very short" contact: at most a tenth of the flight that follows (an order of magnitude).
SHORT_CONTACT_RATIO = 0.1
# "Basically the same" restitution: |e_A - e_B| <= 0.05, the scatter of measured coefficients of
# restitution of rock particles dropped repeatedly on steel (a few hundredths to 0.1).
SAME_RESTITUTION_TOL = 0.05
# "Much larger" force: at least 1.5 times (Hertz alone predicts ~2x at equal speed, section 4.2).
MUCH_LARGER_FACTOR = 1.5


@dataclass(frozen=True)
class Claim:
    """One checked claim. ``values`` holds the numbers behind the verdict (SI units)."""

    id: str
    section: str
    statement: str
    quantity: str
    values: dict
    threshold: str
    passed: bool

    def numbers(self, digits: int = 4) -> str:
        """The values as one compact line, e.g. ``A=[0.05, 0.03] B=[0.2, 0.1]``."""
        return " ".join(f"{k}={_fmt(v, digits)}" for k, v in self.values.items())


def _fmt(value, digits):
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_fmt(v, digits) for v in value) + "]"
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


# -- per-ball sequences -------------------------------------------------------------------------


def impacts(result, name):
    return list(result.impacts_of(name))


def apex_heights(result, name) -> list[float]:
    """Rebound height (m) after each collision that is followed by a flight."""
    return [i.next_apex_height for i in impacts(result, name) if math.isfinite(i.next_apex_height)]


def rebound_speeds(result, name) -> list[float]:
    """Rebound speed v_out (m/s) of each collision followed by a flight."""
    return [i.v_out for i in impacts(result, name) if math.isfinite(i.next_apex_height)]


def restitutions(result, name) -> list[float]:
    return [i.restitution for i in impacts(result, name) if math.isfinite(i.next_apex_height)]


def peak_forces(result, name) -> list[float]:
    """Peak contact force (N) of every collision that ended inside the simulated time (a contact
    cut off by the end of the run has v_out = nan and only a partial peak)."""
    return [i.peak_force for i in impacts(result, name) if not math.isnan(i.v_out)]


def apex_times(result, name) -> list[float]:
    """Time (s) of the apex after each collision followed by a flight: t_end + v_out / g."""
    return [
        i.t_end + i.v_out / STANDARD_GRAVITY
        for i in impacts(result, name)
        if math.isfinite(i.next_apex_height)
    ]


def collision_intervals(result, name) -> list[float]:
    """Time (s) between the starts of consecutive collisions."""
    imp = impacts(result, name)
    return [b.t_start - a.t_start for a, b in zip(imp, imp[1:], strict=False)]


def common(a, b):
    n = min(len(a), len(b))
    return list(a[:n]), list(b[:n])


def strictly_decreasing(seq):
    return all(y < x for x, y in zip(seq, seq[1:], strict=False))


def all_greater(a, b):
    """a[n] > b[n] at every common n (and there is at least one)."""
    a, b = common(a, b)
    return bool(a) and all(x > y for x, y in zip(a, b, strict=True))


def first_few(seq, count=6):
    return [float(v) for v in seq[:count]]
