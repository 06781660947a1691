"""Friction and rotation in the stream reference (rigid plate) against closed forms of rigid
body mechanics with Coulomb friction, conservation laws and the energy ledger.

Each closed form is the Coulomb limit; the regularised law (tailbeam.physics.friction)
differs from it only while the slip speed is below the transition velocity v_d, so each
tolerance is a bound derived from v_s, v_d (stated per test), not a fitted number.
"""

import math

import numpy as np
import pytest

from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.friction import FrictionModel, FrictionSettings
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import CARBON_STEEL, get_material
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference

G = STANDARD_GRAVITY
R = 0.03
COAL = get_material("coal")
DAMPING = 300.0


def resting_ball(theta_deg, velocity=(0.0, 0.0, 0.0), spin=(0.0, 0.0, 0.0), name="a"):
    """A coal ball on the plate inclined by theta, at its static penetration (no bounce)."""
    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=DAMPING)
    m = Ball("m", COAL, R, (0.0, 0.0, R)).mass
    delta = (m * G * math.cos(math.radians(theta_deg)) / law.stiffness) ** (1.0 / law.exponent)
    return Ball(name, COAL, R, (-0.25, 0.0, R - delta), velocity, spin)


def run(balls, theta_deg, friction, duration, *, gravity=G, rtol=1e-11, damping=DAMPING):
    incline = InclinedPlate(Plate(), theta_deg, gravity)
    model = FrictionModel(friction)
    return simulate_stream_reference(
        balls, incline, duration, friction=model, rtol=rtol, damping=damping, max_steps=10**5
    )


def series(res, k=0):
    """Centre velocity (T, 3) and angular velocity (T, 3) of ball k."""
    v = np.array([s[2][k] for s in res.states])
    w = np.array([s[k] for s in res.spins])
    return v, w


def assert_no_energy_gain(res, scale):
    """Total energy + friction's dissipated energy never grows (beyond the integration's
    tolerance, 1e-8 of the energy scale)."""
    ledger = res.energy + res.dissipated
    assert np.all(np.diff(ledger) <= 1e-8 * scale)
    assert np.all(np.diff(res.dissipated) >= -1e-15)


def late_acceleration(res, t0):
    """Slope (m/s^2) of the downhill centre velocity after t0 (least squares)."""
    v, _ = series(res)
    keep = res.times >= t0
    return np.polyfit(res.times[keep], v[keep, 0], 1)[0]


def test_a_ball_set_down_sliding_starts_rolling_at_the_closed_form_time():
    """Horizontal plate, v0 = 1 m/s, mu_d = 0.4: slip v - w r falls at 7/2 mu_d g until it
    reaches zero at t = 2 v0 / (7 mu_d g), then v = 5/7 v0. Above v_d the law is Coulomb's
    exactly; below it mu lies between 0 and mu_s, so the slip reaches v_s within
    v_d / (7/2 mu_d g) of the Coulomb time. Angular momentum about the contact line gives
    v = (5 v0 + 2 slip) / 7 there, within 2/7 v_s of 5/7 v0 (and ~delta / r ~ 3e-5 from the
    lever arm r - delta of the penetrated ball)."""
    v0, mu, v_s, v_d = 1.0, 0.4, 1e-3, 2e-3
    ball = resting_ball(0.0, velocity=(v0, 0.0, 0.0))
    res = run([ball], 0.0, FrictionSettings(mu, mu, v_s, v_d), 0.09)
    v, w = series(res)
    slip = v[:, 0] - w[:, 1] * R
    k = int(np.argmax(slip <= v_s))
    t_roll = 2.0 * v0 / (7.0 * mu * G)
    assert 0.0 <= t_roll - res.times[k] <= v_d / (3.5 * mu * G)
    assert abs(v[k, 0] - 5.0 / 7.0 * v0) <= 2.0 / 7.0 * v_s + 1e-4 * v0
    assert abs(v[-1, 0] - 5.0 / 7.0 * v0) <= 1e-4 * v0  # and rolls on (slip -> 0)
    rec = res.contacts[0]
    m = ball.mass
    assert rec.tangential_impulse == pytest.approx(m * (v0 - v[-1, 0]), rel=1e-6)
    assert rec.tangential_end == "sticking"
    assert_no_energy_gain(res, 0.5 * m * v0**2)
    assert res.dissipated[-1] == pytest.approx(0.5 * m * (v0**2 - v[-1, 0] ** 2 * 7 / 5), rel=1e-3)


def test_on_an_incline_a_ball_rolls_at_five_sevenths_g_sin_theta():
    """theta = 20 deg, mu = 0.4 (tan theta = 0.36 < 7/2 mu): rolling needs a friction force
    2/7 m g sin theta, held at a steady slip below v_s; with the slip steady the centre
    accelerates at exactly 5/7 g sin theta."""
    theta = 20.0
    res = run([resting_ball(theta)], theta, FrictionSettings(0.4, 0.4, 1e-3, 2e-3), 0.08)
    expected = 5.0 / 7.0 * G * math.sin(math.radians(theta))
    assert late_acceleration(res, 0.03) == pytest.approx(expected, rel=1e-4)
    v, w = series(res)
    assert np.max(np.abs(v[res.times > 0.03, 0] - w[res.times > 0.03, 1] * R)) < 1e-3


def test_on_a_steep_incline_a_ball_slides_at_g_times_sin_minus_mu_cos():
    """theta = 40 deg, mu = 0.2 (tan theta = 0.84 > 7/2 mu): gross slip; once the slip
    exceeds v_d the law is Coulomb's: a = g (sin theta - mu_d cos theta), and the spin
    grows at 5/2 mu_d g cos theta / r."""
    theta, mu = 40.0, 0.2
    res = run([resting_ball(theta)], theta, FrictionSettings(mu, mu, 1e-3, 2e-3), 0.06)
    c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))
    assert late_acceleration(res, 0.02) == pytest.approx(G * (s - mu * c), rel=1e-4)
    _, w = series(res)
    keep = res.times >= 0.02
    alpha = np.polyfit(res.times[keep], w[keep, 1], 1)[0]
    assert alpha == pytest.approx(2.5 * mu * G * c / R, rel=1e-4)


def test_rolling_resistance_slows_the_roll_and_holds_a_ball_on_a_gentle_slope():
    """mu_r = 0.1: on 20 deg a = 5/7 g (sin theta - mu_r cos theta); on 4 deg
    (tan theta = 0.07 < mu_r) the ball is held: the regularised torque balances the slope at
    a rolling speed below v_s (the model's creep, bounded by v_s)."""
    fr = FrictionSettings(0.5, 0.5, 1e-3, 2e-3, rolling=0.1)
    theta = 20.0
    res = run([resting_ball(theta)], theta, fr, 0.06)
    c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))
    assert late_acceleration(res, 0.03) == pytest.approx(5.0 / 7.0 * G * (s - 0.1 * c), rel=1e-4)
    res = run([resting_ball(4.0)], 4.0, fr, 0.06)
    v, _ = series(res)
    speed = np.linalg.norm(v[:, :2], axis=1)
    assert np.max(speed[res.times > 0.02]) < fr.stiction_velocity
    assert_no_energy_gain(res, Ball("m", COAL, R, (0, 0, R)).mass * G * R)


def test_an_oblique_impact_in_gross_slip_has_tangential_impulse_mu_times_normal():
    """No gravity, v_n = 1 m/s, v_t = 3 m/s > 7/2 mu (1 + e) v_n: the slip stays above v_d
    through the whole contact, so mu = mu_d throughout and J_t = mu_d J_n (the impulses are
    the step quadratures of the forces)."""
    mu = 0.2
    ball = Ball("a", COAL, R, (-0.2, 0.0, R + 1e-4), (3.0, 0.0, -1.0))
    res = run([ball], 0.0, FrictionSettings(mu, mu, 1e-3, 2e-3), 2e-3, gravity=0.0)
    (rec,) = res.contacts
    assert rec.tangential_end == "sliding"
    assert rec.tangential_impulse == pytest.approx(mu * rec.normal_impulse, rel=1e-9)
    m = ball.mass  # and the impulses are the momentum changes
    v = res.states[-1][2][0]
    assert rec.normal_impulse == pytest.approx(m * (v[2] + 1.0), rel=1e-9)
    assert rec.tangential_impulse == pytest.approx(m * (3.0 - v[0]), rel=1e-9)


def test_a_glancing_ball_ball_collision_conserves_momentum_and_angular_momentum():
    """Two spinning balls, no gravity, far above the plate, glancing with friction (c = 0):
    linear momentum and angular momentum about the origin to round-off (measured 3.5e-16 and
    4.3e-16 of the summed magnitudes), energy + dissipated constant (measured 9.5e-13)."""
    a = Ball("a", COAL, R, (-0.02, 0.0, 0.2), (2.0, 0.0, 0.0), (0.0, 0.0, 30.0))
    b = Ball("b", get_material("sandstone"), 0.02, (0.03, 0.02, 0.2), (-1.0, 0.2, 0.1),
             (10.0, -5.0, 0.0))  # fmt: skip
    res = run([a, b], 0.0, FrictionSettings(0.5, 0.3, 1e-2, 2e-2), 0.02, gravity=0.0,
              rtol=1e-12, damping=0.0)  # fmt: skip
    assert [r.partner for r in res.contacts] == ["b", "a"]
    assert res.contacts[0].tangential_impulse > 0.0
    m = res.masses
    inertia = 0.4 * m * np.array([a.radius, b.radius]) ** 2
    p, h = [], []
    for (_, x, v), w in zip(res.states, res.spins, strict=True):
        p.append(np.sum(m[:, None] * v, axis=0))
        h.append(np.sum(m[:, None] * np.cross(x, v) + inertia[:, None] * w, axis=0))
    p, h = np.array(p), np.array(h)
    scale_p = np.sum(m * np.linalg.norm([a.velocity, b.velocity], axis=1))
    assert np.max(np.abs(p - p[0])) <= 1e-13 * scale_p
    x0, v0, w0 = [np.array(c) for c in (a.position, a.velocity, a.angular_velocity)]
    scale_h = sum(
        m[k] * np.linalg.norm(np.cross(x, v)) + inertia[k] * np.linalg.norm(w)
        for k, (x, v, w) in enumerate(
            [
                (x0, v0, w0),
                (np.array(b.position), np.array(b.velocity), np.array(b.angular_velocity)),
            ]
        )
    )
    assert np.max(np.abs(h - h[0])) <= 1e-13 * scale_h
    ledger = res.energy + res.dissipated
    assert np.max(np.abs(ledger - ledger[0])) <= 1e-10 * ledger[0]
    assert res.dissipated[-1] > 1e-3 * ledger[0]  # friction did work (measured 5.3e-3)


def test_on_the_modal_plate_friction_drives_the_modes_and_the_ledger_closes():
    """The closed-form SSSS plate to 1300 Hz, undamped, c = 0: a spinning ball lands
    obliquely. The friction force acts on the plate's top surface (h/2 above the mid-surface)
    and the slip is taken against that surface's motion, so balls + modes + contacts +
    dissipated is conserved (to the integration's tolerance); the same run without the
    plate's share (rigid plate) differs in the tangential impulse."""
    from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
    from tailbeam.solvers.stream.reference.plate import ReferencePlate

    basis = ssss_kirchhoff_basis(Plate(), 1300.0)
    ball = Ball("a", get_material("sandstone"), R, (0.05, -0.04, R + 1e-4), (1.5, 0.5, -2.0),
                (0.0, 40.0, 10.0))  # fmt: skip
    friction = FrictionModel(FrictionSettings(0.5, 0.4, 1e-2, 2e-2, rolling=0.05))
    res = simulate_stream_reference(
        [ball], InclinedPlate(), 5e-4, friction=friction, rtol=1e-11, damping=0.0,
        plate=ReferencePlate(basis, 0.0),
    )  # fmt: skip
    (rec,) = res.contacts
    assert rec.tangential_impulse > 0.0 and rec.end == "separated"
    ledger = res.energy + res.dissipated
    assert np.max(np.abs(ledger - ledger[0])) <= 1e-9 * ledger[0]
    assert res.dissipated[-1] > 1e-4 * ledger[0]
    q, qd = res.plate_states[-1]
    assert 0.5 * np.sum(qd**2 + (basis.omega * q) ** 2) > 1e-4 * ledger[0]


def test_without_friction_the_normal_impulse_is_the_momentum_change():
    """Frictionless (no friction model): the step quadrature of the normal force equals the
    ball's momentum balance m (v_in + v_out) + m g (t_end - t_start) on the horizontal plate
    to the integration's tolerance; no tangential impulse, spins untouched."""
    ball = Ball("a", COAL, R, (0.0, 0.0, R + 5e-3), (0.3, 0.0, -1.0), (1.0, 2.0, 3.0))
    res = simulate_stream_reference([ball], InclinedPlate(), 0.02, rtol=1e-11, damping=300.0)
    rec = res.contacts[0]
    m = ball.mass
    balance = m * (rec.v_in + rec.v_out) + m * G * (rec.t_end - rec.t_start)
    assert rec.normal_impulse == pytest.approx(balance, rel=1e-9)
    assert (rec.tangential_impulse, rec.tangential_end) == (0.0, "frictionless")
    assert list(res.angular_velocity["a"]) == [1.0, 2.0, 3.0] and res.spins == []
