"""The slow stream reference (tailbeam.solvers.stream.reference.solver) against closed forms,
conservation laws and the rigid-plate solver.

Tolerances: at rtol 1e-12 the reference reproduces the Hertz closed form to ~1e-12 and
conserves energy to ~2e-11 (relative, measured); the bounds below are the brief's (1e-8,
1e-9) or stated per test.
"""

import math

import numpy as np
import pytest
from stream_scenes import static_penetration_on, ten_ball_scene

from tailbeam import CARBON_STEEL, COAL, SANDSTONE, Ball, Plate, ball_ball_law, ball_plate_law
from tailbeam.physics.hertz import hertz_contact_duration, hertz_max_penetration, hertz_peak_force
from tailbeam.physics.incline import InclinedPlate
from tailbeam.results.records import EventKind
from tailbeam.solvers.rigid.reference import simulate_rigid_reference
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference

NO_GRAVITY = InclinedPlate(gravity=0.0)


def _state_at(res, t):
    """(names, x, v) of the accepted step that ends at time t (events end steps)."""
    k = int(np.argmin(np.abs(res.times - t)))
    assert res.times[k] == pytest.approx(t, abs=1e-15)
    return res.states[k]


@pytest.fixture(scope="module")
def head_on():
    """Coal (30 mm, 1 m/s) meets sandstone (20 mm, -2 m/s) on the x axis, g = 0, c = 0."""
    a = Ball("a", COAL, 0.03, (-0.06, 0.0, 0.1), (1.0, 0.0, 0.0))
    b = Ball("b", SANDSTONE, 0.02, (0.06, 0.0, 0.1), (-2.0, 0.0, 0.0))
    return a, b, simulate_stream_reference([a, b], NO_GRAVITY, 0.05)


def test_head_on_matches_hertz_closed_form(head_on):
    a, b, res = head_on
    m_star = a.mass * b.mass / (a.mass + b.mass)
    k = ball_ball_law(COAL, a.radius, SANDSTONE, b.radius).stiffness  # R* = R1 R2 / (R1 + R2)
    v = 3.0  # approach speed
    recs = res.contacts
    assert [(r.ball, r.partner) for r in recs] == [("a", "b"), ("b", "a")]
    r = recs[0]
    assert r.approach_in == pytest.approx(v, rel=1e-14)
    assert r.peak_force == pytest.approx(hertz_peak_force(m_star, v, k), rel=1e-8)
    assert r.t_end - r.t_start == pytest.approx(hertz_contact_duration(m_star, v, k), rel=1e-8)
    assert r.max_penetration == pytest.approx(hertz_max_penetration(m_star, v, k), rel=1e-8)
    assert r.approach_out == pytest.approx(v, rel=1e-8)  # restitution 1 with c = 0
    assert r.t_start == pytest.approx((0.12 - 0.05) / v, rel=1e-12)  # closed-form flight


def test_head_on_conserves_momentum_and_energy(head_on):
    a, b, res = head_on
    m = np.array([a.mass, b.mass])
    p0 = m @ np.array([a.velocity, b.velocity])
    p_scale = float(np.sum(m * 3.0))
    for _, _, v in res.states:
        assert np.max(np.abs(m @ v - p0)) <= 1e-9 * p_scale
    e0 = res.energy[0]
    assert np.max(np.abs(res.energy - e0)) <= 1e-9 * e0
    # and the rebound velocities follow from the two conservation laws (1-D elastic collision)
    v_a = ((a.mass - b.mass) * 1.0 + 2.0 * b.mass * -2.0) / (a.mass + b.mass)
    assert res.contacts[0].v_out == pytest.approx(-v_a, rel=1e-9)  # normal points from b to a


def test_oblique_collision_keeps_tangential_velocity():
    """Frictionless: the force is central (along the line of centres). So (1) each ball's
    velocity normal to the plane of the relative motion never changes, and (2) the relative angular
    momentum r x w is conserved, hence the tangential relative speed |w_t| = |r x w| / |r| is
    the same at first and last touch (|r| = R1 + R2 at both, to the 1e-12 relative dead band
    of the contact events), for any damping. Checked: r x w at first and last touch. In the centre
    of mass frame each ball's tangential velocity is unchanged."""
    a = Ball("a", COAL, 0.025, (-0.05, -0.012, 0.1), (1.5, 0.0, 0.3))
    b = Ball("b", SANDSTONE, 0.02, (0.05, 0.0, 0.1), (-1.0, 0.2, -0.4))
    for damping in (0.0, 600.0):
        res = simulate_stream_reference([a, b], NO_GRAVITY, 0.06, damping=damping)
        (r,) = [c for c in res.contacts if c.ball == "a"]
        _, x0, v0 = _state_at(res, r.t_start)
        _, x1, v1 = _state_at(res, r.t_end)
        plane = np.cross(x0[0] - x0[1], v0[0] - v0[1])
        plane /= np.linalg.norm(plane)  # normal of the plane of the relative motion
        np.testing.assert_allclose(v1 @ plane, v0 @ plane, rtol=0.0, atol=1e-14)

        def angular_momentum(x, v):  # of the relative motion, per unit reduced mass
            return np.cross(x[0] - x[1], v[0] - v[1])

        l0, l1 = angular_momentum(x0, v0), angular_momentum(x1, v1)
        w_t0 = np.linalg.norm(l0) / np.linalg.norm(x0[0] - x0[1])
        assert w_t0 > 0.1  # a genuinely oblique contact
        np.testing.assert_allclose(l1, l0, rtol=0.0, atol=1e-12 * np.linalg.norm(l0))
        if damping > 0.0:
            assert r.approach_out < 0.99 * r.approach_in  # the normal part did lose energy


@pytest.mark.parametrize("normal_speed", [0.0, -0.4])
@pytest.mark.parametrize("damping", [0.0, 500.0])
def test_inclined_slide_and_leave_time(normal_speed, damping):
    """Frictionless inclined plate: the along-slope motion is uncoupled from the normal one,
    x(t) = x0 + v0 t + g sin(theta) t^2 / 2, whether the ball sits at its static penetration
    (normal_speed 0) or bounces (-0.4 m/s), and it leaves over the lower edge x = a/2 at the
    root of that quadratic. Tolerance 1e-12 m and 1e-12 s: x is a quadratic, which DOP853
    integrates exactly, so only round-off remains (measured <= 5e-16); the leave time is a
    Newton-polished root of the step's interpolant (measured <= 3e-16 s)."""
    theta, r, x0, v0 = 30.0, 0.03, -0.2, 0.3
    incline = InclinedPlate(inclination=theta)
    if normal_speed == 0.0:
        z0 = r - static_penetration_on(COAL, r, incline)
    else:
        z0 = 0.05
    ball = Ball("s", COAL, r, (x0, 0.01, z0), (v0, 0.0, normal_speed))
    res = simulate_stream_reference([ball], incline, 1.0, damping=damping)
    acc = incline.gravity * math.sin(math.radians(theta))
    for t, (names, x, _) in zip(res.times, res.states, strict=True):
        if names:
            assert x[0, 0] == pytest.approx(x0 + v0 * t + 0.5 * acc * t * t, abs=1e-12)
    t_leave = (-v0 + math.sqrt(v0 * v0 + 2.0 * acc * (0.3 - x0))) / acc
    (leave,) = res.leaves
    assert leave.edge == "x+"
    assert leave.time == pytest.approx(t_leave, abs=1e-12)
    if normal_speed == 0.0:  # in contact all along, ended by leaving
        (rec,) = res.contacts
        assert rec.end == "left" and rec.t_end == leave.time
    else:
        assert len(res.contacts) >= 2  # bounces on the slope


@pytest.fixture(scope="module", params=[(0.0, 0.25), (2000.0, 0.1)], ids=["c=0", "c=2000"])
def ten_balls(request):
    """The ten-ball scene; with damping over 0.1 s only (every ball-ball contact is over by
    then; the many small bounces after cost ~4 ms per step in this pure-Python reference)."""
    damping, duration = request.param
    incline = InclinedPlate(inclination=15.0)
    res = simulate_stream_reference(
        ten_ball_scene(incline), incline, duration, damping=damping, penetration=2e-5
    )
    return damping, res


def test_ten_ball_scene_has_clusters(ten_balls):
    _, res = ten_balls
    pairs = {(c.ball, c.partner) for c in res.contacts}
    assert {("b1", "b2"), ("b3", "b2"), ("s2", "s1"), ("p1", "p2"), ("p3", "p4")} <= pairs
    b2 = [c for c in res.contacts if c.ball == "b2" and c.partner in ("b1", "b3")]
    assert b2[0].t_start == pytest.approx(b2[1].t_start, abs=1e-12)  # three balls at once
    s1 = {}
    for c in res.contacts:
        if c.ball == "s1":
            s1.setdefault(c.partner, c)  # the first contact with each partner
    assert s1["plate"].t_start == 0.0 and s1["s2"].t_start < s1["plate"].t_end  # overlapping


def test_ten_ball_energy(ten_balls):
    """c = 0: kinetic + potential + elastic energy conserved to 1e-9 of the kinetic energy
    scale; c > 0: it never increases (beyond 1e-12 of that scale, round-off)."""
    damping, res = ten_balls
    masses = dict(zip(res.names, res.masses, strict=True))
    scale = max(
        sum(0.5 * masses[n] * float(v_ @ v_) for n, v_ in zip(names, v, strict=True))
        for names, _, v in res.states
    )
    if damping == 0.0:
        assert np.max(np.abs(res.energy - res.energy[0])) <= 1e-9 * scale
    else:
        assert np.max(np.diff(res.energy)) <= 1e-12 * scale
        assert res.energy[-1] < res.energy[0] - 1e-3 * scale  # it did dissipate
        kinds = {e.kind for e in res.events}
        assert {EventKind.FULL_DAMPING, EventKind.CLAMP_ON, EventKind.CLAMP_OFF} <= kinds


def test_single_ball_matches_rigid_solver():
    """A coal ball bouncing on a horizontal plate with damping, STEP ramp and clamp: the
    separately written rigid-plate reference (1-D contact ODE; its fast solver agrees with it
    to 3e-11) is the truth; the contact tables agree to 1e-9 (measured ~1e-13). This test
    caught a late contact end after a clamp-off (fixed: a redone step is checked again)."""
    law = ball_plate_law(COAL, 0.03, CARBON_STEEL, damping=800.0, penetration=1e-4)
    ball = Ball("A", COAL, 0.03, (0.0, 0.0, 0.13), (0.0, 0.0, -2.0))
    rigid = simulate_rigid_reference([ball], Plate(), [law], 1.0, rest_speed=0.0)
    res = simulate_stream_reference([ball], InclinedPlate(), 1.0, damping=800.0)
    done = [c for c in res.contacts if c.end == "separated"]
    assert len(done) >= 3
    for ours, theirs in zip(done, rigid.impacts, strict=False):
        for name in ("t_start", "t_end", "t_peak"):
            assert getattr(ours, name) == pytest.approx(getattr(theirs, name), abs=1e-9)
        for name in ("v_in", "v_out", "peak_force", "max_penetration"):
            assert getattr(ours, name) == pytest.approx(getattr(theirs, name), rel=1e-9)


def test_release_times_and_a_generated_stream():
    """A ball released at t_r from rest with gap h first touches the plate at
    t_r + sqrt(2 h / g) at speed sqrt(2 g h) (free fall, closed form); and a generated
    stream runs through the reference: every particle enters at its release time and,
    with damping, the energy never increases between releases."""
    from tailbeam.streams.generator import generate_particles

    incline = InclinedPlate()
    late = Ball("late", COAL, 0.02, (0.0, 0.0, 0.02 + 0.05), (0.0, 0.0, 0.0))
    res = simulate_stream_reference([late], incline, 0.2, release_times=[0.03])
    (first, *_) = res.contacts
    g = incline.gravity
    assert first.t_start == pytest.approx(0.03 + math.sqrt(2 * 0.05 / g), abs=1e-12)
    assert first.v_in == pytest.approx(math.sqrt(2 * g * 0.05), rel=1e-12)

    stream = {"name": "s", "rate": 60.0, "start": 0.0, "stop": 0.1, "gangue_fraction": 0.5,
              "radius": [0.01, 0.02], "area": [[-0.05, 0.05], [-0.05, 0.05]],
              "height": [0.01, 0.03], "seed": 3}  # fmt: skip
    particles = generate_particles([stream], InclinedPlate(inclination=20.0))
    assert len(particles) >= 3
    balls = [p.ball() for p in particles]
    res = simulate_stream_reference(
        balls, InclinedPlate(inclination=20.0), 0.25, damping=1000.0,
        release_times=[p.t_release for p in particles],
    )  # fmt: skip
    released = {e.ball: e.t for e in res.events if e.kind == EventKind.RELEASE}
    for p in particles:
        if p.t_release > 0.0:
            assert released[p.name] == p.t_release
    on_plate = {c.ball for c in res.contacts if c.partner == "plate"}
    assert on_plate == {p.name for p in particles}  # every particle reached the plate
    cuts = sorted(released.values())
    for a, b in zip([0.0, *cuts], [*cuts, math.inf], strict=True):
        inside = (res.times > a) & (res.times < b)
        assert np.all(np.diff(res.energy[inside]) <= 1e-12 * np.max(np.abs(res.energy)))
