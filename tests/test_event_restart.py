"""The active set's event restart across returns (issue 7, grazing contacts).

An event the kernel applies leaves its row's function on 0 at that instant. Inside one
``advance`` call the row is searched from ``cheb_events.FRESH_S`` on in the next step (it is
"fresh"); a START or END returns to the caller, and the next call from that instant must carry
the marker too, else it finds the same crossing again at the same instant (a contact that
starts and ends at one time, over and over: the stall the stream driver once retried at a
tighter rtol). The markers must not hide a genuine new crossing: checked against the closed
form of a free flight. The truths here: where the row sits (computed from the state), the
closed-form flight under gravity, and the kernel's own result without the marker.
"""

import math

import numpy as np
import pytest

from tailbeam import CARBON_STEEL, COAL, Ball, ball_ball_law, ball_plate_law
from tailbeam.physics.contacts import LawOptions, contact_table
from tailbeam.physics.incline import InclinedPlate
from tailbeam.solvers.stream.active_members import ActiveMembers
from tailbeam.solvers.stream.active_pairs import R_CONTACT
from tailbeam.solvers.stream.active_set import ActiveSet
from tailbeam.solvers.stream.stream_state import Balls
from tailbeam.streams.generator import Particle

R = 0.02  # m, every ball here
BAND = 1e-12 * (2 * R) ** 2  # the contact row's dead band of a ball-ball pair (m^2)
T0 = 0.25  # s: the restart instant


def _pair_on_its_end_crossing(fresh: bool) -> ActiveSet:
    """Two touching balls (g = 0) separating at 1 mm/s whose contact row sits just past
    its END crossing at T0: f = d^2 - (2R)^2 = 1.5 x band, the state right after a START
    applied within the dead band (``active_kernel._apply_pending`` accepts up to 2 bands).
    ``fresh``: the START of this row was applied at T0 (the marker the kernel returns)."""
    d = math.sqrt((2 * R) ** 2 + 1.5 * BAND)
    law = ball_ball_law(COAL, R, COAL, R)
    mass = Ball("a", COAL, R, (0, 0, 0)).mass
    s = ActiveSet(
        [(0.0, 0.0, 0.1), (d, 0.0, 0.1)], [(-5e-4, 0.0, 0.0), (5e-4, 0.0, 0.0)],
        [mass, mass], [R, R], [(0, 1)], [law], (0.0, 0.0, 0.0), (0.3, 0.3), rtol=1e-10,
    )  # fmt: skip
    s.touching[0] = True
    if fresh:
        s.set_fresh(T0, [(R_CONTACT, 0)])
    return s


def test_an_event_just_applied_is_not_found_again_at_that_instant():
    """The mechanism of the stall. Without the marker, the row on its wrong side at the
    restart is applied there: END at T0 itself (a zero-length contact; after a START returned
    at T0 that is the same crossing found twice). With the marker carried from the return
    at T0, time moves on: the END comes at the next step's start, later than T0."""
    s = _pair_on_its_end_crossing(fresh=False)
    assert -(s.penetration(0)[0]) > 0.0  # (the balls are apart: the row's value checks)
    out = s.advance(T0, T0 + 1e-3, h=1e-6)
    assert (out.kind, out.t) == ("contact_end", T0)
    assert s.stats["found_again"] == 0

    s = _pair_on_its_end_crossing(fresh=True)
    out = s.advance(T0, T0 + 1e-3, h=1e-6)
    assert out.kind == "contact_end" and T0 < out.t <= T0 + 1e-6
    assert s.stats["found_again"] == 1  # (found at T0, searched again: at the next step)


def test_markers_of_another_instant_are_not_carried():
    """Markers apply only to a restart at the instant they were applied at."""
    s = _pair_on_its_end_crossing(fresh=False)
    s.set_fresh(T0 - 1e-4, [(R_CONTACT, 0)])
    out = s.advance(T0, T0 + 1e-3, h=1e-6)
    assert (out.kind, out.t) == ("contact_end", T0)


@pytest.mark.parametrize("fresh", [False, True])
def test_a_genuine_new_crossing_is_still_found(fresh):
    """A ball whose plate contact just ended (END at T0, carried marker) rising at 0.2 m/s
    under g: its next START is the closed-form landing t = T0 + 2 v / g, found inside the
    first step (one 1 s step: free flight is exact), with and without the marker."""
    incline = InclinedPlate(inclination=0.0)
    g = incline.gravity
    v = 0.2
    law = ball_plate_law(COAL, R, CARBON_STEEL)
    z = R * math.sqrt(1.0 + 1.5e-12)  # just past the END crossing (f = 1.5 bands)
    ball = Ball("a", COAL, R, (0.0, 0.0, z), (0.0, 0.0, v))
    s = ActiveSet([ball.position], [ball.velocity], [ball.mass], [R], [(0, -1)], [law],
                  incline.gravity_vector, incline.half_sizes, rtol=1e-10)  # fmt: skip
    if fresh:
        s.set_fresh(T0, [(R_CONTACT, 0)])
    out = s.advance(T0, T0 + 1.0, h=1.0)
    assert out.kind == "contact_start"
    # the landing: z + v t - g t^2 / 2 = R sqrt(1 - 1e-12) (the START crossing, f = -band)
    zc = R * math.sqrt(1.0 - 1e-12)
    t_land = (v + math.sqrt(v * v + 2.0 * g * (z - zc))) / g
    assert out.t - T0 == pytest.approx(t_land, rel=1e-12)


def test_a_start_returns_its_marker_and_a_rebuilt_set_keeps_it():
    """After a START return the set gives the START's row as applied at the returned time;
    the driver's set (``ActiveMembers``), rebuilt at that instant with a new member, carries
    it to the new set under the pair's new index."""
    incline = InclinedPlate(gravity=0.0)
    mass = Ball("a", COAL, R, (0, 0, 0)).mass

    def particle(k, x, vx):
        return Particle(f"p{k}", "s", "coal", COAL, R, mass, 0.0, (x, 0.0, 0.1), (vx, 0, 0))

    particles = [particle(0, -0.1, 1.0), particle(1, 0.1, -1.0), particle(2, 0.2, 0.0)]
    balls = Balls(particles, incline, _table(particles, incline))
    act = ActiveMembers(balls, 1e-10, lambda i: 0.0)
    for i in (0, 1):
        act.add(i, particles[i].position, particles[i].velocity, quiet=False)
    kind, key, t = act.advance(0.0, 1.0)
    assert (kind, key) == ("start", (0, 1))
    assert t == pytest.approx((0.2 - 2 * R) / 2.0, rel=1e-9)  # (closed form, head on)
    assert act.set.fresh_rows() == (t, [(R_CONTACT, act.index[(0, 1)])])
    act.now = t
    act.add(2, particles[2].position, particles[2].velocity, quiet=False)  # (a rebuild)
    s = act._ready()
    assert act.index[(0, 1)] != 2  # (the pair's index changed: plate pairs come first)
    assert s.fresh_rows() == (t, [(R_CONTACT, act.index[(0, 1)])])
    kind, key, t_end = act.advance(t, 1.0)
    assert (kind, key) == ("end", (0, 1)) and t_end > t


def _table(particles, incline):
    return contact_table(particles, LawOptions(1.5, 0.0, 1e-4, True), incline.plate.material)


def test_set_fresh_keeps_at_most_the_kernel_capacity():
    """More markers than the kernel holds are cut to its capacity (MAX_FRESH), not an error."""
    from tailbeam.solvers.stream.active_kernel import MAX_FRESH

    s = _pair_on_its_end_crossing(fresh=False)
    s.set_fresh(T0, [(R_CONTACT, 0)] * (MAX_FRESH + 3))
    assert len(s.fresh_rows()[1]) == MAX_FRESH
    assert np.all(s.fresh[:, 0] == R_CONTACT)
