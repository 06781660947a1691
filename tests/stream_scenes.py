"""Scenes shared by the stream tests (not a test module)."""

import math

from tailbeam import COAL, SANDSTONE, Ball, ball_plate_law
from tailbeam.physics.materials import CARBON_STEEL

MIN_APPROACH = 0.1  # m/s: an impact approaches faster than this


def static_penetration_on(material, radius, incline) -> float:
    """Penetration in m at which a ball of ``material``, ``radius`` rests on ``incline``
    (normal force m g cos theta; the closed form of tailbeam.physics.hertz)."""
    law = ball_plate_law(material, radius, CARBON_STEEL)
    ball = Ball("probe", material, radius, (0.0, 0.0, 1.0))
    normal_load = ball.mass * incline.gravity * math.cos(math.radians(incline.inclination))
    return law.static_penetration(normal_load)


def ten_ball_scene(incline):
    """Ten balls, several ball-ball contacts, a 3-ball cluster and a stacked pair.

    - b1, b2, b3 in a row along y, level, in flight: b1 and b3 reach b2 at the same time
      (three balls touching at once);
    - s1 rests on the plate (static penetration) and s2 falls onto it (ball-ball and
      ball-plate contact at once); both slide downhill alike (frictionless);
    - p1/p2 meet head-on in flight, p3 (sandstone)/p4 (coal) obliquely; f1 falls alone.
    """
    r_s1 = 0.03
    z_s1 = r_s1 - static_penetration_on(COAL, r_s1, incline)
    return [
        Ball("b1", COAL, 0.02, (-0.1, -0.1, 0.15), (0.0, 1.0, 0.0)),
        Ball("b2", COAL, 0.02, (-0.1, 0.0, 0.15), (0.0, 0.0, 0.0)),
        Ball("b3", COAL, 0.02, (-0.1, 0.1, 0.15), (0.0, -1.0, 0.0)),
        Ball("s1", COAL, r_s1, (0.1, 0.1, z_s1), (0.0, 0.0, 0.0)),
        Ball("s2", SANDSTONE, 0.02, (0.1, 0.1, 0.12), (0.0, 0.0, -0.5)),
        Ball("p1", COAL, 0.025, (0.15, -0.15, 0.1), (0.0, 0.5, 0.0)),
        Ball("p2", COAL, 0.015, (0.15, -0.05, 0.1), (0.0, -0.5, 0.0)),
        Ball("p3", SANDSTONE, 0.02, (-0.15, 0.2, 0.08), (0.6, 0.0, 0.0)),
        Ball("p4", COAL, 0.025, (0.0, 0.21, 0.08), (-0.6, 0.0, 0.0)),
        Ball("f1", SANDSTONE, 0.035, (-0.2, -0.2, 0.1), (0.2, 0.1, -1.0)),
    ]


def modal_scene(incline):
    """Seven balls whose contacts all end within 28 ms (short runs of the slow reference
    on the modal plate, where the modes bound its steps):

    - b1, b2, b3 in a row along y, falling at 1 m/s: b1 and b3 reach b2 at once (~20 ms,
      a 3-ball cluster), then all three land (~26 ms);
    - s1 rests on the plate (static penetration), s2 falls onto it (~14 ms: ball-ball and
      ball-plate contact at once);
    - f1 lands obliquely (~8 ms) and p1 lands near an edge (~15 ms), exciting the plate
      under the others.
    """
    r_s1 = 0.03
    z_s1 = r_s1 - static_penetration_on(COAL, r_s1, incline)
    return [
        Ball("b1", COAL, 0.02, (-0.1, -0.06, 0.05), (0.0, 1.0, -1.0)),
        Ball("b2", COAL, 0.02, (-0.1, 0.0, 0.05), (0.0, 0.0, -1.0)),
        Ball("b3", COAL, 0.02, (-0.1, 0.06, 0.05), (0.0, -1.0, -1.0)),
        Ball("s1", COAL, r_s1, (0.1, 0.1, z_s1), (0.0, 0.0, 0.0)),
        Ball("s2", SANDSTONE, 0.02, (0.1, 0.1, 0.09), (0.0, 0.0, -0.5)),
        Ball("f1", SANDSTONE, 0.035, (-0.15, -0.2, 0.05), (0.3, 0.2, -2.0)),
        Ball("p1", COAL, 0.025, (0.2, -0.2, 0.05), (-0.2, 0.3, -1.5)),
    ]


def leave_scene(incline):
    """Four balls on a steep incline that leave the plate (30 deg suits them):

    - r1 sits at its static penetration and slides off the lower edge x+ (in contact all
      along: its plate contact ends "left");
    - r4 falls onto r1 (ball-ball contact while r1 touches the plate);
    - r2 bounces across the plate and leaves over y+;
    - r3 is thrown uphill and leaves over x- in flight.
    """
    r1 = 0.03
    z1 = r1 - static_penetration_on(COAL, r1, incline)
    return [
        Ball("r1", COAL, r1, (0.15, 0.0, z1), (0.3, 0.0, 0.0)),
        Ball("r2", SANDSTONE, 0.02, (0.0, 0.2, 0.05), (0.0, 0.8, -0.3)),
        Ball("r3", COAL, 0.025, (-0.25, -0.1, 0.06), (-1.0, -0.3, 0.0)),
        Ball("r4", SANDSTONE, 0.015, (0.16, 0.0, z1 + 0.06), (0.3, 0.0, -0.3)),
    ]


def _firsts(contacts) -> dict:
    """Each ball's first contact that is an impact (ends separated, approach > MIN_APPROACH:
    the chatter of a ball settling on the plate or on another is not an impact)."""
    out = {}
    for c in sorted(contacts, key=lambda c: (c.t_start, c.ball, c.partner)):
        if c.ball not in out and c.end == "separated" and c.approach_in > MIN_APPROACH:
            out[c.ball] = c
    return out


def first_impact_difference(contacts, truth):
    """(common prefix length, truth's contacts, first impacts compared, worst relative
    difference over them). A ball's first impact is compared when it is, in both runs, the
    same impact (same partner, start within 1 % of its duration)."""

    def order(cs):
        return sorted(cs, key=lambda c: (c.t_start, c.ball, c.partner))

    a, b = order(contacts), order(truth)
    n = 0
    while n < min(len(a), len(b)) and (a[n].ball, a[n].partner) == (b[n].ball, b[n].partner):
        n += 1
    worst, compared = 0.0, 0
    got = _firsts(contacts)
    for ball, y in _firsts(truth).items():
        x = got.get(ball)
        dur_y = y.t_end - y.t_start
        if x is None or x.partner != y.partner or abs(x.t_start - y.t_start) > 0.01 * dur_y:
            continue
        compared += 1
        worst = max(worst, abs((x.t_end - x.t_start) - dur_y) / dur_y)
        worst = max(worst, abs(x.peak_force - y.peak_force) / y.peak_force)
        worst = max(worst, abs(x.approach_out - y.approach_out) / y.approach_in)
    return n, len(b), compared, worst
