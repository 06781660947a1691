"""Hard cases of the rigid solver: each against a conservation law or an exact property.

Energy facts used (m du/dt = m g - F in contact): dE/dt = u (k delta^e - F) <= 0, so no impact
may return more speed than it got, the maximum penetration obeys
k delta_m^(e+1) / (e+1) <= m v_in^2 / 2 + m g delta_m, and the energy lost in a contact equals
the integral of (F - k delta^e) u dt (the damping power, incl. the clamp's share).
"""

import math

import numpy as np
import pytest
from scipy.integrate import simpson

from tailbeam import CARBON_STEEL, COAL, Ball, ImpactLaw, Plate, ball_plate_law
from tailbeam.physics.bodies import STANDARD_GRAVITY as G
from tailbeam.solvers.rigid import simulate_rigid

R = 0.03
PLATE = Plate()
K_COAL = ball_plate_law(COAL, R, CARBON_STEEL).stiffness


def _law(c=800.0, d=1e-4, e=1.5, clamp=True):
    return ImpactLaw(K_COAL, e, damping=c, penetration=d, clamp=clamp)


def _ball(v, gap=1e-3, name="A", x=0.0, vx=0.0):
    return Ball(name, COAL, R, (x, 0.0, R + gap), (vx, 0.0, -v))


def _check_physical(res, law, gravity=G):
    m = res.particles[0].mass
    for imp in res.impacts:
        for name in ("t_start", "v_in", "peak_force", "t_peak", "max_penetration"):
            assert math.isfinite(getattr(imp, name)), name
        if math.isfinite(imp.v_out):
            assert imp.v_out <= imp.v_in * (1.0 + 1e-9)  # no energy gain
        dm = imp.max_penetration
        elastic = law.stiffness * dm ** (law.exponent + 1) / (law.exponent + 1)
        assert elastic <= (0.5 * m * imp.v_in**2 + m * gravity * dm) * (1.0 + 1e-8)
    s = res.sample(np.linspace(0.0, res.duration, 2001))["A"]
    assert all(np.all(np.isfinite(v)) for v in s.values())
    if law.clamp:
        assert np.all(s["force"] >= 0.0)


@pytest.mark.parametrize("d", [1e-9, 1e-6, 1e-4, 1e-3])
@pytest.mark.parametrize("speed", [0.01, 0.1, 1.0, 10.0, 30.0])
def test_speeds_and_ramp_depths(speed, d):
    law = _law(d=d)
    res = simulate_rigid([_ball(speed, gap=0.0)], PLATE, [law], 0.3)
    assert res.status == 0 and res.impacts
    assert res.impacts[0].v_in == speed
    _check_physical(res, law)


@pytest.mark.parametrize("e", [1.0, 1.5, 2.2])
@pytest.mark.parametrize("clamp", [True, False])
def test_exponents_damped(e, clamp):
    law = ImpactLaw(K_COAL if e == 1.5 else 1e7 if e == 1.0 else 1e11, e, 800.0, 1e-4, clamp)
    res = simulate_rigid([_ball(2.0, gap=0.1)], PLATE, [law], 0.6)
    assert len(res.impacts) >= 2
    _check_physical(res, law)
    apex = [i.next_apex_height for i in res.impacts if math.isfinite(i.next_apex_height)]
    assert np.all(np.diff(apex) < 0.0)


def test_undamped_bounces_conserve_energy():
    # c = 0: 100+ bounces, every impact and rebound speed equal to the first to 1e-9
    # (measured 1.7e-10 at rtol 1e-12; 3e-8 at rtol 1e-10: error grows with the count)
    res = simulate_rigid([_ball(0.3)], PLATE, [_law(c=0.0)], 7.0, rtol=1e-12)
    v_in = np.array([i.v_in for i in res.impacts])
    v_out = np.array([i.v_out for i in res.impacts])
    assert len(v_in) >= 100
    v0 = math.sqrt(0.3**2 + 2.0 * G * 1e-3)
    assert np.max(np.abs(v_in / v0 - 1.0)) < 1e-9
    assert np.max(np.abs(v_out[np.isfinite(v_out)] / v0 - 1.0)) < 1e-9


def test_very_large_damping_comes_to_rest_at_static_penetration():
    law = _law(c=1e6)
    res = simulate_rigid([_ball(1.0)], PLATE, [law], 0.1)
    m = res.particles[0].mass
    assert len(res.impacts) == 1
    imp = res.impacts[0]
    assert imp.ends_at_rest and imp.v_out == 0.0 and math.isnan(imp.next_apex_height)
    assert res.states.rest_time["A"] == imp.t_end < 0.1
    assert res.events[-1].kind == "rest"
    delta_s = (m * G / law.stiffness) ** (1.0 / law.exponent)
    s = res.sample([imp.t_end, 0.1])["A"]
    np.testing.assert_allclose(s["z"], R - delta_s, rtol=1e-15)
    np.testing.assert_allclose(s["force"], m * G, rtol=1e-15)
    assert np.all(s["vz"] == 0.0)
    # just before it was declared at rest its energy above the rest state was below e_trap
    # (it could no longer leave): m u^2/2 + k delta^(e+1)/(e+1) - m g delta - V_s <= e_trap
    t = imp.t_end * (1.0 - 1e-12)
    before = res.sample([t])["A"]
    delta, u = R - before["z"][0], -before["vz"][0]
    e_ex = 0.5 * m * u * u + law.stiffness * delta**2.5 / 2.5 - m * G * (delta - delta_s)
    e_ex -= law.stiffness * delta_s**2.5 / 2.5
    assert e_ex <= m * G * delta_s * 1.5 / 2.5 * (1.0 + 1e-6)


def test_persistent_contact_work_is_bounded():
    # rest disabled, ball placed on the plate: it rocks in persistent contact between delta = 0
    # and delta_1 = 2.5^(2/3) delta_s (m g delta_1 = k delta_1^2.5 / 2.5; the ramp damping is
    # tiny there) for the whole run
    res = simulate_rigid([Ball("A", COAL, R, (0, 0, R))], PLATE, [_law()], 0.05, rest_speed=0.0)
    m = res.particles[0].mass
    delta_s = (m * G / K_COAL) ** (1 / 1.5)
    assert len(res.impacts) == 1 and math.isnan(res.impacts[0].v_out)
    assert res.stats["n_steps"] < 5000
    s = res.sample(np.linspace(0, 0.05, 20001))["A"]
    delta = R - s["z"]
    delta_1 = 2.5 ** (2.0 / 3.0) * delta_s
    assert delta.min() >= -1e-12 * R and delta.max() <= delta_1 * (1.0 + 1e-6)
    assert delta.max() > 0.98 * delta_1  # it does oscillate (no artificial settling)


def test_ball_starting_at_rest_on_plate():
    res = simulate_rigid([Ball("A", COAL, R, (0, 0, R))], PLATE, [_law()], 0.1)
    assert res.states.rest_time["A"] == 0.0
    m = res.particles[0].mass
    s = res.sample([0.0, 0.05, 0.1])["A"]
    np.testing.assert_allclose(s["z"], R - (m * G / K_COAL) ** (1 / 1.5), rtol=1e-15)
    np.testing.assert_allclose(s["force"], m * G, rtol=1e-15)


def test_simultaneous_impacts_are_independent():
    a, b = _ball(1.0, gap=0.05, name="A", x=-0.1), _ball(1.0, gap=0.05, name="B", x=0.1)
    both = simulate_rigid([a, b], PLATE, [_law(), _law()], 0.5)
    alone = simulate_rigid([a], PLATE, [_law()], 0.5)
    imps_a = both.impacts_of("A")
    assert imps_a == alone.impacts
    assert [i.t_start for i in both.impacts_of("B")] == [i.t_start for i in imps_a]
    t = both.time_grid(51200.0)
    sa, sb, s1 = both.sample(t)["A"], both.sample(t)["B"], alone.sample(t)["A"]
    for key in ("z", "vz", "force"):
        assert np.array_equal(sa[key], s1[key]) and np.array_equal(sb[key], s1[key])


def test_ball_missing_the_plate_falls_freely():
    far = _ball(1.0, gap=0.05, x=0.5)  # beside the plate
    leaving = _ball(1.0, gap=0.05, x=0.28, vx=1.0)  # slides off the edge before touching
    for ball in (far, leaving):
        res = simulate_rigid([ball], PLATE, [_law()], 0.5)
        assert res.impacts == [] and res.events == []
        t = np.linspace(0, 0.5, 11)
        z = res.sample(t)["A"]["z"]
        np.testing.assert_allclose(z, R + 0.05 - 1.0 * t - 0.5 * G * t * t, rtol=1e-14)
    arriving = _ball(1.0, gap=0.05, x=0.33, vx=-1.0)  # slides onto the plate
    assert len(simulate_rigid([arriving], PLATE, [_law()], 0.1).impacts) == 1


def _dissipated_by_damping(res, law, imp):
    """Integral of (F - k delta^e) u over the contact (composite Simpson, fine grid)."""
    t = np.linspace(imp.t_start, imp.t_end, 200001)
    s = res.sample(t)["A"]
    delta = np.maximum(R - s["z"], 0.0)
    power = (s["force"] - law.stiffness * delta**law.exponent) * (-s["vz"])
    return simpson(power, x=t)


def test_adams_clamp_versus_paper_equation_1():
    # coal thrown down at 2 m/s from 0.1 m: with the clamp the raw force dips below zero in
    # rebound; eq. 1 (no clamp) keeps that adhesive pull and so loses more energy
    ball = _ball(2.0, gap=0.1)
    out = {}
    for clamp in (True, False):
        law = _law(clamp=clamp)
        res = simulate_rigid([ball], PLATE, [law], 0.1, rtol=1e-12)
        imp = res.impacts[0]
        s = res.sample(np.linspace(imp.t_start, imp.t_end, 20001))["A"]
        m = res.particles[0].mass
        lost = 0.5 * m * (imp.v_in**2 - imp.v_out**2)
        assert lost > 0.0
        assert _dissipated_by_damping(res, law, imp) == pytest.approx(lost, rel=1e-7)
        out[clamp] = (imp, s["force"].min())
    assert out[True][1] == 0.0  # clamped: never pulls
    assert out[False][1] < -1.0  # eq. 1: a pull of more than 1 N at the end of rebound
    assert out[False][0].restitution < out[True][0].restitution


def test_stored_trajectory_is_continuous_across_pieces():
    # the motion is C1 in z (velocity continuous) and the force continuous at every contact
    # start/end and kink: evaluating the pieces on both sides of each event must agree
    res = simulate_rigid([_ball(2.0, gap=0.1)], PLATE, [_law()], 0.5, rtol=1e-12)
    times = np.array([e.t for e in res.events if e.kind != "rest"])
    assert times.size >= 10
    eps = 1e-13  # s; over it z moves < 3e-13 m and vz by < 3e-9 m/s (|a| < 3e4 m/s^2)
    before = res.sample(times - eps)["A"]
    after = res.sample(times + eps)["A"]
    np.testing.assert_allclose(before["z"], after["z"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(before["vz"], after["vz"], rtol=0, atol=1e-8)
    peak = max(i.peak_force for i in res.impacts)
    np.testing.assert_allclose(before["force"], after["force"], rtol=0, atol=1e-8 * peak)
