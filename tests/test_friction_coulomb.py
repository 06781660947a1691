"""Coulomb's law (stiction_velocity = transition_velocity = 0) in the stream reference: stick
and slip, held and free rolling as events, against the closed forms of rigid-body mechanics
with Coulomb friction and against conservation laws.

The closed forms use the lever arm the model has: the contact point lies on the plate's
surface, l = r - delta below the centre of a ball pressed in by its weight (delta its static
penetration), so they hold to the integration's tolerance, not to delta / r.
"""

import math

import numpy as np
import pytest

from tailbeam.errors import InputError
from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, Plate
from tailbeam.physics.friction import FrictionModel, FrictionSettings
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import get_material
from tailbeam.results.records import EventKind
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference

G = STANDARD_GRAVITY
R = 0.03
COAL = get_material("coal")
RTOL = 1e-12


def coulomb(mu, rolling=0.0, dynamic=None):
    return FrictionSettings(mu, mu if dynamic is None else dynamic, 0.0, 0.0, rolling)


def resting(theta_deg, velocity=(0.0, 0.0, 0.0), name="a"):
    """A coal ball on the plate inclined by theta at its static penetration, and its lever
    arm l (m), mass (kg) and moment of inertia (kg m^2)."""
    from tailbeam.physics.contact_law import ball_plate_law
    from tailbeam.physics.materials import CARBON_STEEL

    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=300.0)
    m = Ball("m", COAL, R, (0.0, 0.0, R)).mass
    delta = (m * G * math.cos(math.radians(theta_deg)) / law.stiffness) ** (1.0 / law.exponent)
    return Ball(name, COAL, R, (-0.25, 0.0, R - delta), velocity), R - delta, m, 0.4 * m * R * R


def run(balls, theta_deg, friction, duration, gravity=G, damping=300.0):
    incline = InclinedPlate(Plate(), theta_deg, gravity)
    return simulate_stream_reference(
        balls, incline, duration, friction=FrictionModel(friction), rtol=RTOL,
        damping=damping, max_steps=10**5,
    )  # fmt: skip


def kinds(res):
    return [(str(e.kind), e.t) for e in res.events if e.kind != EventKind.CONTACT_START]


def state(res, k=-1):
    """Centre position, velocity and angular velocity of the first ball at step k."""
    return res.states[k][1][0], res.states[k][2][0], res.spins[k][0]


def test_a_ball_set_down_sliding_sticks_at_the_closed_form_time():
    """Horizontal plate, v0 = 1 m/s, mu = 0.4: the slip v - l w falls at mu g (1 + m l^2 / I)
    and sticks at t = v0 / (mu g (1 + m l^2 / I)) (2 v0 / (7 mu g) for l = r), the centre
    then rolling on at v0 - mu g t."""
    v0, mu = 1.0, 0.4
    ball, ell, m, inertia = resting(0.0, velocity=(v0, 0.0, 0.0))
    res = run([ball], 0.0, coulomb(mu), 0.09)
    t_stick = v0 / (mu * G * (1.0 + m * ell**2 / inertia))
    ((kind, t),) = kinds(res)
    assert kind == "stick" and abs(t - t_stick) <= 1e-10 * t_stick
    _x, v, w = state(res)
    assert abs(v[0] - (v0 - mu * G * t_stick)) <= 1e-11 * v0
    assert abs(v[0] - ell * w[1]) <= 1e-12 * v0  # it rolls: the slip is held at zero
    assert res.contacts[0].tangential_end == "sticking"


@pytest.mark.parametrize("theta", [10.0, 20.0])
def test_a_ball_rolls_down_without_slip_at_the_closed_form_rate(theta):
    """tan theta < 7/2 mu: the contact stays stuck from rest and the ball rolls at
    a = g sin theta / (1 + I / (m l^2)); no event."""
    ball, ell, m, inertia = resting(theta)
    res = run([ball], theta, coulomb(0.4), 0.1)
    a = G * math.sin(math.radians(theta)) / (1.0 + inertia / (m * ell**2))
    x, v, w = state(res)
    assert kinds(res) == []
    assert abs(x[0] - ball.position[0] - 0.5 * a * 0.1**2) <= 1e-10 * 0.5 * a * 0.1**2
    assert abs(v[0] - ell * w[1]) <= 1e-12 * abs(v[0])


def test_a_ball_slides_where_friction_cannot_hold_it():
    """tan theta > 7/2 mu (40 deg, mu = 0.2): the stuck start breaks loose at once (SLIP at
    t = 0) and the ball slides at g (sin theta - mu_d cos theta), its spin growing at
    mu_d m g cos theta l / I."""
    theta, mu = 40.0, 0.2
    ball, ell, m, inertia = resting(theta)
    res = run([ball], theta, coulomb(mu), 0.1)
    assert kinds(res) == [("slip", 0.0)]
    c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))
    _x, v, w = state(res)
    assert abs(v[0] - G * (s - mu * c) * 0.1) <= 1e-10 * v[0]
    assert abs(w[1] - mu * m * G * c * ell / inertia * 0.1) <= 1e-10 * abs(w[1])


def test_rolling_resistance_holds_a_ball_exactly_where_tan_theta_is_below_mu_r():
    """4 deg, mu_r = 0.1: slip stuck and rolling held from rest; the ball stays exactly where
    it was for 0.1 s (the regularised law creeps below v_s there)."""
    ball, _ell, _m, _i = resting(4.0)
    res = run([ball], 4.0, coulomb(0.5, rolling=0.1), 0.1)
    x, v, w = state(res)
    assert kinds(res) == []
    assert np.max(np.abs(x - ball.position)) <= 1e-13 and np.max(np.abs(v)) <= 1e-12
    assert np.max(np.abs(w)) <= 1e-10


def test_two_touching_balls_are_held_together_by_one_constraint_solve():
    """Two coal balls touching side by side (1 nm overlap) on 10 deg, mu_r = 0.2 > tan
    theta: both plate contacts stuck and held, the ball-ball contact too (its rolling,
    under a ~1e-4 N normal force, breaks loose at once): the constraint forces of the three
    contacts come from one (singular) system, and both balls stay at rest."""
    a, _ell, _m, _i = resting(10.0, name="a")
    b = Ball("b", COAL, R, (a.position[0] + 2 * R - 1e-9, 0.0, a.position[2]))
    res = run([a, b], 10.0, coulomb(0.5, rolling=0.2), 0.02)
    assert [(str(e.kind), e.partner) for e in res.events if e.kind != EventKind.CONTACT_START] == [
        ("roll_free", "b")
    ]  # fmt: skip
    _n, x, v = res.states[-1]
    assert np.max(np.abs(v)) <= 1e-12 and np.max(np.abs(res.spins[-1])) <= 1e-10
    assert np.max(np.abs(x - np.array([a.position, b.position]))) <= 1e-13


def test_rolling_resistance_lets_go_and_slows_the_roll_at_the_closed_form_rate():
    """20 deg, mu_r = 0.1 < tan theta: the held rolling breaks loose at once (ROLL_FREE at
    t = 0) and the ball rolls at a = g (sin theta - mu_r (r / l) cos theta) / (1 + I / (m l^2))
    (R = r on the plate)."""
    theta = 20.0
    ball, ell, m, inertia = resting(theta)
    res = run([ball], theta, coulomb(0.5, rolling=0.1), 0.1)
    assert kinds(res) == [("roll_free", 0.0)]
    c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))
    a = G * (s - 0.1 * (R / ell) * c) / (1.0 + inertia / (m * ell**2))
    _x, v, _w = state(res)
    assert abs(v[0] - a * 0.1) <= 1e-10 * a * 0.1


def oblique(friction, duration):
    """A coal ball striking the horizontal plate at v_n = 1, v_t = 0.5 m/s, no gravity."""
    ball = Ball("a", COAL, R, (0.0, 0.0, R + 1e-4), (0.5, 0.0, -1.0))
    return ball, run([ball], 0.0, friction, duration, gravity=0.0)


def test_an_oblique_impact_sticks_and_the_ledger_never_gains():
    """mu = 0.4, mu_r = 0.05: the rolling held at the touch breaks loose at once (no spin,
    F_n ~ 0), the slip stops within the impact (STICK) and breaks loose as F_n falls to zero
    before the ball leaves (SLIP); total energy plus friction's dissipated energy never
    grows; the tangential impulse is the momentum's change."""
    ball, res = oblique(coulomb(0.4, rolling=0.05), 0.01)
    assert [k for k, _t in kinds(res)] == [
        "roll_free", "stick", "full_damping", "full_damping", "slip", "contact_end"
    ]  # fmt: skip
    ledger = res.energy + res.dissipated
    assert np.all(np.diff(ledger) <= 1e-10 * ledger[0]) and res.dissipated[-1] > 0.0
    rec = res.contacts[0]
    _x, v, _w = state(res)
    assert abs(rec.tangential_impulse - ball.mass * (0.5 - v[0])) <= 1e-9 * ball.mass * 0.5


def test_the_regularised_law_converges_to_coulombs():
    """The same impact with the regularised law at v_s = 1e-2 and 1e-3 m/s (v_d = 2 v_s):
    its end state (positions / r, velocities / |v0|, spins r / |v0|) and tangential impulse
    approach Coulomb's at least at order 0.9 in v_s (measured 1.2 and 1.1)."""

    def end(friction):
        ball, res = oblique(friction, 0.002)
        x, v, w = state(res)
        speed = math.hypot(0.5, 1.0)
        return np.concatenate([x / R, v / speed, w * R / speed]), res.contacts[0]

    exact, rec = end(coulomb(0.4, rolling=0.05))
    errors = []
    for v_s in (1e-2, 1e-3):
        e, r = end(FrictionSettings(0.4, 0.4, v_s, 2 * v_s, 0.05))
        errors.append(
            (np.max(np.abs(e - exact)), abs(r.tangential_impulse - rec.tangential_impulse))
        )
    for before, after in zip(errors[0], errors[1], strict=True):
        assert after <= before / 10**0.9


def test_a_glancing_collision_of_two_balls_conserves_momentum_and_angular_momentum():
    """Two spinning coal balls in a glancing collision, Coulomb's law on their contact (it
    sticks and slips), c = 0, no gravity, no plate contact: linear momentum and angular
    momentum about the origin are conserved to round-off, energy + dissipated constant."""
    a = Ball("a", COAL, R, (-0.1, 0.0, 0.2), (1.0, 0.0, 0.0), (0.0, 0.0, 40.0))
    b = Ball("b", COAL, R, (0.0, 0.045, 0.2), (0.0, 0.0, 0.0), (10.0, 0.0, 0.0))
    res = run([a, b], 0.0, coulomb(0.3, rolling=0.05), 0.12, gravity=0.0, damping=0.0)
    assert any(k == "stick" for k, _t in kinds(res)) or any(k == "slip" for k, _t in kinds(res))
    m, inertia = a.mass, 0.4 * a.mass * R * R

    def momenta(k):
        _n, x, v = res.states[k]
        w = res.spins[k]
        p = m * v.sum(axis=0)
        L = m * np.cross(x, v).sum(axis=0) + inertia * w.sum(axis=0)
        scale_p = m * np.abs(v).sum()
        scale_l = m * np.abs(np.cross(x, v)).sum() + inertia * np.abs(w).sum()
        return p, L, scale_p, scale_l

    p0, l0, sp, sl = momenta(0)
    p1, l1, _, _ = momenta(-1)
    assert np.max(np.abs(p1 - p0)) <= 1e-13 * sp
    assert np.max(np.abs(l1 - l0)) <= 1e-13 * sl
    ledger = res.energy + res.dissipated
    assert np.max(np.abs(ledger - ledger[0])) <= 1e-9 * ledger[0]


def test_coulomb_needs_zero_transition_velocity_and_the_fast_solver_refuses_it():
    with pytest.raises(InputError, match="transition_velocity"):
        FrictionSettings(0.5, 0.4, 0.0, 1e-3)
    import tailbeam
    from tailbeam.io.scene_file import loads_scene

    text = """
duration = 0.01
[contact.friction]
static = 0.5
dynamic = 0.4
stiction_velocity = 0.0
transition_velocity = 0.0
[plate]
model = "rigid"
[[balls]]
name = "a"
material = "coal"
radius = 0.03
position = [0.0, 0.0, 0.05]
"""
    scene = loads_scene(text)
    with pytest.raises(InputError, match="stream-reference"):
        tailbeam.simulate(scene, solver="stream", progress=False)
    res = tailbeam.simulate(scene, progress=False)
    assert res.info["solver_choice"] == "stream-reference"
