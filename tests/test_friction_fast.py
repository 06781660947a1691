"""Friction and rotation in the fast stream solver (rigid plate) against the independent
stream reference (scipy DOP853, every pair watched) on the same scenes, and against the
closed forms of rigid-body mechanics with Coulomb friction.

Agreement is measured as relative differences at matching times: positions over the ball's
radius plus the distance travelled, velocities over the scene's speed scale, angular
velocities over that scale per radius, impulses over the largest normal impulse; both
solvers at rtol 1e-11. The closed-form bounds are those of tests/test_friction_reference.py
(derived from v_s and v_d, not fitted).
"""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.friction import FrictionModel, FrictionSettings, coefficient
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import CARBON_STEEL, get_material
from tailbeam.solvers.stream.active.compiled import friction as compiled
from tailbeam.solvers.stream.active.compiled.kernel import cc_weight
from tailbeam.solvers.stream.driver.loop import solve_stream
from tailbeam.solvers.stream.reference.friction import FrictionTable, pair_friction
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference
from tailbeam.solvers.stream.reference.steps import STEP_POINTS, STEP_WEIGHTS
from tailbeam.streams.generator import Particle, default_label

G = STANDARD_GRAVITY
R = 0.03
COAL = get_material("coal")
SANDSTONE = get_material("sandstone")
DAMPING = 300.0
RTOL = 1e-11
AGREE = 1e-6  # the fast solver against the reference, relative (see the module docstring)


def resting_ball(theta_deg, velocity=(0.0, 0.0, 0.0), spin=(0.0, 0.0, 0.0), name="a"):
    """A coal ball on the plate inclined by theta, at its static penetration (no bounce)."""
    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=DAMPING)
    m = Ball("m", COAL, R, (0.0, 0.0, R)).mass
    delta = (m * G * math.cos(math.radians(theta_deg)) / law.stiffness) ** (1.0 / law.exponent)
    return Ball(name, COAL, R, (-0.25, 0.0, R - delta), velocity, spin)


def both(balls, theta, friction, duration, *, gravity=G, damping=DAMPING):
    """(fast run, reference result) of ``balls`` on the plate inclined by theta (deg)."""
    incline = InclinedPlate(Plate(), theta, gravity)
    model = FrictionModel(friction)
    particles = [Particle.from_ball(b, default_label(b)) for b in balls]
    fast = solve_stream(particles, incline, duration, damping=damping, rtol=RTOL,
                        friction=model, progress=False)  # fmt: skip
    ref = simulate_stream_reference(balls, incline, duration, friction=model, rtol=RTOL,
                                    damping=damping, max_steps=10**5)  # fmt: skip
    return fast, ref


def final_differences(fast, ref, balls, v_scale, duration) -> dict:
    """Largest relative differences of the final positions, velocities and angular
    velocities of the balls still on the plate (see the module docstring)."""
    names, x, v = ref.states[-1]
    assert sorted(names) == sorted(fast.final)
    radius = {b.name: b.radius for b in balls}
    out = {"x": 0.0, "v": 0.0, "w": 0.0}
    for k, name in enumerate(names):
        xf, vf = fast.final[name]
        wf, wr = fast.angular_velocity[name], ref.angular_velocity[name]
        r = radius[name]
        out["x"] = max(out["x"], np.max(np.abs(xf - x[k])) / (r + v_scale * duration))
        out["v"] = max(out["v"], np.max(np.abs(vf - v[k])) / v_scale)
        out["w"] = max(out["w"], np.max(np.abs(wf - wr)) * r / v_scale)
    return out


def record_differences(fast, ref, v_scale, duration) -> dict:
    """Largest relative differences of the matching contact records: start and end times
    (over the duration), normal and tangential impulses (over the largest normal impulse),
    rebound speeds (over v_scale); how each ended tangentially must be the same."""
    a = sorted(fast.contacts, key=lambda r: (r.t_start, r.ball))
    b = sorted(ref.contacts, key=lambda r: (r.t_start, r.ball))
    assert [(r.ball, r.partner) for r in a] == [(r.ball, r.partner) for r in b]
    assert [r.tangential_end for r in a] == [r.tangential_end for r in b]
    j = max(abs(r.normal_impulse) for r in b)
    out = {"t": 0.0, "jn": 0.0, "jt": 0.0, "v_out": 0.0}
    for p, q in zip(a, b, strict=True):
        for key, value in (("t", p.t_start - q.t_start), ("t", _nan0(p.t_end - q.t_end))):
            out[key] = max(out[key], abs(value) / duration)
        out["jn"] = max(out["jn"], abs(p.normal_impulse - q.normal_impulse) / j)
        out["jt"] = max(out["jt"], abs(p.tangential_impulse - q.tangential_impulse) / j)
        out["v_out"] = max(out["v_out"], abs(_nan0(p.v_out - q.v_out)) / v_scale)
    return out


def _nan0(x):
    return 0.0 if math.isnan(x) else x


def assert_agree(diffs):
    assert max(diffs.values()) <= AGREE, diffs


# --- the compiled law is the law ---------------------------------------------------------------


def test_the_compiled_coefficient_is_the_friction_law():
    """Every regime of mu(v): rise, fall, plateau, and the ends of the intervals."""
    v_s, v_d = 1e-3, 3e-3
    speeds = np.concatenate([np.linspace(0.0, 5e-3, 501), [v_s, v_d, 1.0]])
    expected = coefficient(speeds, 0.5, 0.3, v_s, v_d)
    got = [compiled.coefficient(s, 0.5, 0.3, v_s, v_d) for s in speeds]
    assert np.array_equal(got, expected)


def test_the_compiled_pair_friction_is_the_references():
    """Force, torques and dissipated power of ball-ball and ball-plate pairs at random
    states (slips below v_s, between v_s and v_d, and above) against the reference's
    numpy formulas (``reference.friction.pair_friction``), to round-off."""
    rng = np.random.default_rng(7)
    settings = FrictionSettings(0.5, 0.3, 0.05, 0.2, rolling=0.1)
    for trial in range(40):
        plate = trial % 2 == 0
        ri, rj = 0.03, 0.02
        xi = rng.normal(size=3) * 0.1
        xi[2] = 0.029 if plate else xi[2]
        scale = 10.0 ** rng.uniform(-3, 0)
        vi, wi = rng.normal(size=3) * scale, rng.normal(size=3) * scale / ri
        if plate:
            n, xj, vj, wj = np.array([0.0, 0.0, 1.0]), xi * [1, 1, 0], np.zeros(3), np.zeros(3)
            share, roll, j = 1.0, ri, -1
        else:
            direction = rng.normal(size=3)
            n = direction / np.linalg.norm(direction)
            xj = xi - n * (ri + rj - 1e-5)
            vj, wj = rng.normal(size=3) * scale, rng.normal(size=3) * scale / rj
            share, roll, j = ri / (ri + rj), ri * rj / (ri + rj), 1
        fn = rng.uniform(0.1, 100.0)
        row = [0.5, 0.3, 0.05, 0.2, 0.1, share, roll]
        table = FrictionTable(*[np.array([c]) for c in row])
        kin = SimpleNamespace(normal=n[None])  # (all pair_friction reads of the kinematics)
        ref = pair_friction(table, kin, np.array([fn]), xi[None], vi[None], wi[None], xj[None],
                            vj[None], wj[None])  # fmt: skip
        y = np.concatenate([xi, xj, vi, vj, wi, wj])
        got = compiled.pair_friction(y, 2, 12, 0, j, 0, *n, fn, np.array([row]))
        size = settings.static * fn
        np.testing.assert_allclose(got[0:3], ref.force[0], rtol=0, atol=1e-13 * size)
        np.testing.assert_allclose(got[3:6], ref.torque_i[0], rtol=0, atol=1e-13 * size * ri)
        if not plate:
            np.testing.assert_allclose(got[6:9], ref.torque_j[0], rtol=0, atol=1e-13 * size * ri)
        assert got[9] == pytest.approx(ref.power[0], rel=1e-12, abs=1e-14 * size * scale)


def test_the_kernels_quadrature_weights_are_the_references():
    """Clenshaw-Curtis weights of the 15 step points: the reference's, and they integrate
    s^k exactly (k <= 14)."""
    from tailbeam.solvers.numerics.chebyshev import tables

    pts, vinv = tables()
    w = np.array([cc_weight(vinv, q) for q in range(len(pts))])
    np.testing.assert_allclose(pts, STEP_POINTS, rtol=0, atol=0)
    np.testing.assert_allclose(w, STEP_WEIGHTS, rtol=0, atol=1e-15)
    for k in range(15):
        assert w @ pts**k == pytest.approx(1.0 / (k + 1), rel=1e-13)


# --- the same scenes through both solvers ------------------------------------------------------


def test_a_sliding_ball_starts_rolling_as_the_reference_and_the_closed_form():
    """Horizontal plate, v0 = 1 m/s, mu = 0.4, v_s = 1e-3, v_d = 2e-3 m/s. While the slip is
    above v_d the centre decelerates at mu g exactly (Coulomb): at 50 ms v = v0 - mu g t
    (the lever arm r - delta moves it by ~delta / r ~ 4e-5). After the onset it rolls at
    5/7 v0, so the onset time implied by the final speed, (v0 - v) / (mu g), is
    2 v0 / (7 mu g) within v_d / (7/2 mu g) (the reference test's bound)."""
    v0, mu = 1.0, 0.4
    friction = FrictionSettings(mu, mu, 1e-3, 2e-3)
    ball = resting_ball(0.0, velocity=(v0, 0.0, 0.0))
    for duration in (0.05, 0.09):
        fast, ref = both([ball], 0.0, friction, duration)
        assert_agree(final_differences(fast, ref, [ball], v0, duration))
        assert_agree(record_differences(fast, ref, v0, duration))
        v = fast.final["a"][1][0]
        if duration == 0.05:
            assert v == pytest.approx(v0 - mu * G * duration, rel=1e-4)
            assert fast.contacts[0].tangential_end == "sliding"
    t_onset = (v0 - v) / (mu * G)
    assert abs(t_onset - 2.0 * v0 / (7.0 * mu * G)) <= 2e-3 / (3.5 * mu * G)
    assert v == pytest.approx(5.0 / 7.0 * v0, abs=1e-4 * v0)
    (rec,) = fast.contacts
    assert rec.tangential_end == "sticking"
    assert rec.tangential_impulse == pytest.approx(ball.mass * (v0 - v), rel=1e-6)
    # friction's ledger line: what the rotation and the roll do not hold any more
    work = 0.5 * ball.mass * (v0**2 - v**2 * 7.0 / 5.0)
    assert fast.stats["energy_friction"] == pytest.approx(work, rel=1e-3)


def test_a_ball_rolls_down_twenty_degrees_as_the_reference_and_at_five_sevenths_g_sin():
    """theta = 20 deg, mu = 0.4 (tan theta < 7/2 mu): rolls. Both solvers at 40 and 80 ms;
    the acceleration between them is 5/7 g sin theta (rel 1e-4, the reference test's)."""
    theta = 20.0
    friction = FrictionSettings(0.4, 0.4, 1e-3, 2e-3)
    ball = resting_ball(theta)
    scale = 5.0 / 7.0 * G * math.sin(math.radians(theta)) * 0.08
    speeds = []
    for duration in (0.04, 0.08):
        fast, ref = both([ball], theta, friction, duration)
        assert_agree(final_differences(fast, ref, [ball], scale, duration))
        assert_agree(record_differences(fast, ref, scale, duration))
        speeds.append(fast.final["a"][1][0])
        x, w = fast.final["a"][1][0], fast.angular_velocity["a"][1]
        assert abs(x - w * R) < 1e-3  # rolling: slip below v_d
    expected = 5.0 / 7.0 * G * math.sin(math.radians(theta))
    assert (speeds[1] - speeds[0]) / 0.04 == pytest.approx(expected, rel=1e-4)


def test_an_oblique_impact_in_gross_slip_as_the_reference_and_mu_times_normal():
    """No gravity, v_t = 3 m/s, v_n = 1 m/s, mu = 0.2: sliding throughout, J_t = mu J_n
    and both impulses the momentum changes."""
    mu = 0.2
    ball = Ball("a", COAL, R, (-0.2, 0.0, R + 1e-4), (3.0, 0.0, -1.0))
    fast, ref = both([ball], 0.0, FrictionSettings(mu, mu, 1e-3, 2e-3), 2e-3, gravity=0.0)
    assert_agree(final_differences(fast, ref, [ball], 3.0, 2e-3))
    assert_agree(record_differences(fast, ref, 3.0, 2e-3))
    (rec,) = fast.contacts
    assert rec.tangential_end == "sliding"
    assert rec.tangential_impulse == pytest.approx(mu * rec.normal_impulse, rel=1e-9)
    v = fast.final["a"][1]
    assert rec.normal_impulse == pytest.approx(ball.mass * (v[2] + 1.0), rel=1e-9)
    assert rec.tangential_impulse == pytest.approx(ball.mass * (3.0 - v[0]), rel=1e-9)


def test_a_glancing_ball_ball_collision_as_the_reference_conserving_momenta():
    """Two spinning balls of different materials and sizes, no gravity, far above the plate,
    glancing with friction (c = 0): both solvers agree, and the fast solver's final linear
    and angular momentum (about the origin) equal the initial ones to round-off."""
    a = Ball("a", COAL, R, (-0.02, 0.0, 0.2), (2.0, 0.0, 0.0), (0.0, 0.0, 30.0))
    b = Ball("b", SANDSTONE, 0.02, (0.03, 0.02, 0.2), (-1.0, 0.2, 0.1), (10.0, -5.0, 0.0))
    friction = FrictionSettings(0.5, 0.3, 1e-2, 2e-2)
    fast, ref = both([a, b], 0.0, friction, 0.02, gravity=0.0, damping=0.0)
    assert_agree(final_differences(fast, ref, [a, b], 2.0, 0.02))
    assert_agree(record_differences(fast, ref, 2.0, 0.02))
    assert fast.contacts[0].tangential_impulse > 0.0
    p0, h0, p1, h1, scale_p, scale_h = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), 0, 0
    for ball in (a, b):
        m, inertia = ball.mass, 0.4 * ball.mass * ball.radius**2
        x, v, w = (np.array(c) for c in (ball.position, ball.velocity, ball.angular_velocity))
        p0 += m * v
        h0 += m * np.cross(x, v) + inertia * w
        scale_p += m * np.linalg.norm(v)
        scale_h += m * np.linalg.norm(np.cross(x, v)) + inertia * np.linalg.norm(w)
        xf, vf = fast.final[ball.name]
        p1 += m * vf
        h1 += m * np.cross(xf, vf) + inertia * fast.angular_velocity[ball.name]
    assert np.max(np.abs(p1 - p0)) <= 1e-13 * scale_p
    assert np.max(np.abs(h1 - h0)) <= 1e-13 * scale_h


def stream_balls():
    """Six balls (coal and sandstone, two sizes, some spinning) dropped onto the 20 deg
    plate close enough to collide with each other while they bounce and roll."""
    spec = [
        ("c1", COAL, 0.03, (-0.20, 0.00, 0.05), (0.5, 0.0, -1.0), (0.0, 0.0, 0.0)),
        ("c2", COAL, 0.025, (-0.12, 0.01, 0.04), (-0.3, 0.0, -0.5), (0.0, 20.0, 0.0)),
        ("s1", SANDSTONE, 0.03, (-0.05, -0.01, 0.06), (0.0, 0.1, -1.5), (5.0, 0.0, 10.0)),
        ("s2", SANDSTONE, 0.02, (0.03, 0.02, 0.035), (-0.8, 0.0, -0.2), (0.0, -30.0, 0.0)),
        ("c3", COAL, 0.02, (0.10, -0.02, 0.03), (0.2, 0.2, -0.4), (0.0, 0.0, 0.0)),
        ("s3", SANDSTONE, 0.025, (-0.28, 0.06, 0.08), (1.0, -0.4, 0.0), (0.0, 0.0, -15.0)),
    ]
    return [Ball(*s) for s in spec]


def test_a_few_ball_stream_with_friction_as_the_reference():
    """Six balls bouncing, colliding and rolling on 20 deg with friction and rolling
    resistance, per material pair (coal-steel, sandstone-steel, coal-sandstone): every
    contact record (times, impulses, rebound, how it ended) and the final states agree."""
    default = FrictionSettings(0.5, 0.4, 1e-2, 2e-2, rolling=0.05)
    model = FrictionModel(
        default,
        (
            (("sandstone", CARBON_STEEL.name), FrictionSettings(0.6, 0.5, 1e-2, 2e-2, 0.1)),
            (("coal", "sandstone"), FrictionSettings(0.7, 0.6, 1e-2, 2e-2)),
        ),
    )
    balls = stream_balls()
    incline = InclinedPlate(Plate(), 20.0, G)
    duration = 0.07  # (the ball-ball contacts start at 58-59 ms)
    particles = [Particle.from_ball(b, default_label(b)) for b in balls]
    fast = solve_stream(particles, incline, duration, damping=DAMPING, rtol=RTOL,
                        friction=model, progress=False)  # fmt: skip
    ref = simulate_stream_reference(balls, incline, duration, friction=model, rtol=RTOL,
                                    damping=DAMPING, max_steps=10**5)  # fmt: skip
    assert sum(r.partner != "plate" for r in fast.contacts) >= 2  # ball-ball contacts
    assert_agree(final_differences(fast, ref, balls, 1.5, duration))
    assert_agree(record_differences(fast, ref, 1.5, duration))
