"""The active set's event restart across returns (grazing contacts).

An event the kernel applies leaves its row's function on 0 at that instant. Inside one
``advance`` call the row is searched from ``cheb_events.FRESH_S`` on in the next step (it is
"fresh"); a START or END returns to the caller, and the next call from that instant carries
the marker: a carried row whose crossing is found at the restart instant while it is back on
its side at FRESH_S is searched again (counted in ``stats["found_again"]``), so a crossing
sitting on 0 is not applied again at once, while a row on its wrong side there (a genuine
crossing, due now) and a genuine new crossing later are found as without the marker. The
truths here: where the rows sit and when they cross (closed forms of uniform motion and of a
free flight under gravity), and the kernel's own result without the marker"""

import math

import numpy as np
import pytest

from tailbeam import CARBON_STEEL, COAL, Ball, ball_ball_law, ball_plate_law
from tailbeam.physics.contacts import LawOptions, contact_table
from tailbeam.physics.incline import InclinedPlate
from tailbeam.results.records import EventCode
from tailbeam.solvers.stream.active.compiled.pairs import R_CONTACT
from tailbeam.solvers.stream.active.integrator.set import ActiveSet
from tailbeam.solvers.stream.active.members import ActiveMembers
from tailbeam.solvers.stream.driver.balls import Balls
from tailbeam.streams.generator import Particle

R = 0.02  # m, every ball here
BAND = 1e-12 * (2 * R) ** 2  # the contact row's dead band of a ball-ball pair (m^2)
T0 = 0.25  # s: the restart instant


def _touching_pair(f0: float, t0: float, fresh: bool) -> ActiveSet:
    """Two touching balls (g = 0) separating at 2 cm/s with f = d^2 - (2R)^2 = f0 at t0
    (the END row is band - f0); ``fresh``: its START was applied at t0 (the marker the
    kernel returns)."""
    d = math.sqrt((2 * R) ** 2 + f0)
    law = ball_ball_law(COAL, R, COAL, R)
    mass = Ball("a", COAL, R, (0, 0, 0)).mass
    s = ActiveSet(
        [(0.0, 0.0, 0.1), (d, 0.0, 0.1)], [(-0.01, 0.0, 0.0), (0.01, 0.0, 0.0)],
        [mass, mass], [R, R], [(0, 1)], [law], (0.0, 0.0, 0.0), (0.3, 0.3), rtol=1e-10,
    )  # fmt: skip
    s.contacts.touching[0] = True
    if fresh:
        s.io.set_fresh(t0, [(R_CONTACT, 0)])
    return s


@pytest.mark.parametrize("fresh", [False, True])
def test_a_row_past_its_crossing_at_the_restart_is_applied_there(fresh):
    """f0 = 1.5 bands: the END row is on its wrong side at the restart and beyond (the pair
    separates): a genuine crossing, applied at T0 with or without the marker (the markers
    never delay an event that is due)."""
    s = _touching_pair(1.5 * BAND, T0, fresh)
    out = s.advance(T0, T0 + 1e-3, h=1e-4)
    assert (out.code, out.t) == (EventCode.CONTACT_END, T0)
    assert s.stats["found_again"] == 0


def test_a_carried_row_found_at_the_restart_is_searched_again():
    """f0 = 0.5 band at t = 1000 s: the END row (0.5 band) reaches 0 after tau = 0.5 band /
    (df/dt) = 5.0e-13 s (closed form), within the restart window 4 eps t = 8.9e-13 s, so
    the search puts it at the restart. Without the marker it is applied there at once; with
    the START's marker carried it is found again (counted), searched again from FRESH_S of
    the step on (it is back on its side there), found at the same crossing, inside the
    window: applied at the restart, the same event as without the marker."""
    t0 = 1000.0
    s = _touching_pair(0.5 * BAND, t0, fresh=False)
    d = s.x[1, 0] - s.x[0, 0]
    tau = (BAND - (d * d - (2 * R) ** 2)) / (2.0 * d * 0.02)
    assert 4 * math.ulp(t0) < tau < 4.0 * np.finfo(float).eps * t0  # (the window)
    out = s.advance(t0, t0 + 1e-3, h=1e-4)
    assert (out.code, out.t, s.stats["found_again"]) == (EventCode.CONTACT_END, t0, 0)
    s = _touching_pair(0.5 * BAND, t0, fresh=True)
    out = s.advance(t0, t0 + 1e-3, h=1e-4)
    assert (out.code, out.t, s.stats["found_again"]) == (EventCode.CONTACT_END, t0, 1)


def test_markers_of_another_instant_are_not_carried():
    """Markers apply only to a restart at the instant they were applied at."""
    t0 = 1000.0
    s = _touching_pair(0.5 * BAND, t0, fresh=False)
    s.io.set_fresh(t0 - 1e-4, [(R_CONTACT, 0)])
    s.advance(t0, t0 + 1e-3, h=1e-4)
    assert s.stats["found_again"] == 0


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
        s.io.set_fresh(T0, [(R_CONTACT, 0)])
    out = s.advance(T0, T0 + 1.0, h=1.0)
    assert out.code == EventCode.CONTACT_START
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
    kind, key, t = act.next_event(0.0, 1.0)
    assert (kind, key) == (EventCode.CONTACT_START, (0, 1))
    assert t == pytest.approx((0.2 - 2 * R) / 2.0, rel=1e-9)  # (closed form, head on)
    assert act.set.io.fresh_rows() == (t, [(R_CONTACT, act.index[(0, 1)])])
    act.now = t
    act.add(2, particles[2].position, particles[2].velocity, quiet=False)  # (a rebuild)
    s = act._ready()
    assert act.index[(0, 1)] != 2  # (the pair's index changed: plate pairs come first)
    assert s.io.fresh_rows() == (t, [(R_CONTACT, act.index[(0, 1)])])
    kind, key, t_end = act.next_event(t, 1.0)
    assert (kind, key) == (EventCode.CONTACT_END, (0, 1)) and t_end > t


def _table(particles, incline):
    return contact_table(particles, LawOptions(1.5, 0.0, 1e-4, True), incline.plate.material)


def test_set_fresh_keeps_at_most_the_kernel_capacity():
    """More markers than the kernel holds are cut to its capacity (MAX_FRESH), not an error."""
    from tailbeam.solvers.stream.active.compiled.kernel import MAX_FRESH

    s = _touching_pair(0.5 * BAND, T0, fresh=False)
    s.io.set_fresh(T0, [(R_CONTACT, 0)] * (MAX_FRESH + 3))
    assert len(s.io.fresh_rows()[1]) == MAX_FRESH
    assert np.all(s.io.fresh[:, 0] == R_CONTACT)
