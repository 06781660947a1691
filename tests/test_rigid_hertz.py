"""The rigid solver against Johnson's closed forms (c = 0, g = 0: an undamped Hertz impact).

Independent truth: tailbeam.physics.hertz (energy balance and the Beta-function contact duration).
With rtol = 1e-11 the solver is expected within 1e-8 relative (the brief's bar); the measured
errors are ~1e-12, so the bound has margin without being loose enough to hide a wrong order.
"""

import pytest

from tailbeam import CARBON_STEEL, COAL, SANDSTONE, Ball, ImpactLaw, Plate, ball_plate_law
from tailbeam.physics.hertz import hertz_contact_duration, hertz_max_penetration, hertz_peak_force
from tailbeam.solvers.rigid import simulate_rigid

GAP = 1e-3  # m between the ball and the plate at t = 0


def _one_impact(material, radius, speed, exponent, rtol):
    k = ball_plate_law(material, radius, CARBON_STEEL).stiffness
    law = ImpactLaw(k, exponent, damping=0.0, penetration=1e-4)
    ball = Ball("A", material, radius, (0.0, 0.0, radius + GAP), (0.0, 0.0, -speed))
    t_c = hertz_contact_duration(ball.mass, speed, k, exponent)
    res = simulate_rigid([ball], Plate(), [law], GAP / speed + 3.0 * t_c, rtol=rtol, gravity=0.0)
    assert len(res.impacts) == 1
    return res.impacts[0], ball.mass, k


@pytest.mark.parametrize("exponent", [1.0, 1.5, 2.2])
@pytest.mark.parametrize("speed", [0.3, 2.0, 20.0])
def test_undamped_impact_matches_closed_form(exponent, speed):
    imp, m, k = _one_impact(COAL, 0.03, speed, exponent, rtol=1e-11)
    dm = hertz_max_penetration(m, speed, k, exponent)
    fm = hertz_peak_force(m, speed, k, exponent)
    tc = hertz_contact_duration(m, speed, k, exponent)
    assert imp.t_start == pytest.approx(GAP / speed, rel=1e-14)  # closed-form flight
    assert imp.max_penetration == pytest.approx(dm, rel=1e-8)
    assert imp.peak_force == pytest.approx(fm, rel=1e-8)
    assert imp.t_end - imp.t_start == pytest.approx(tc, rel=1e-8)
    assert imp.t_peak - imp.t_start == pytest.approx(0.5 * tc, rel=1e-8)  # symmetric pulse
    assert imp.v_out == pytest.approx(speed, rel=1e-8)  # elastic: restitution 1
    assert imp.restitution == pytest.approx(1.0, abs=1e-8)


def test_contact_start_singularity_keeps_high_accuracy():
    # F ~ t^1.5 at first touch is not smooth; the start-up step control must not cap the
    # accuracy: at rtol = 1e-12 the closed form is met to 1e-10 (measured ~1e-12).
    imp, m, k = _one_impact(SANDSTONE, 0.03, 1.0, 1.5, rtol=1e-12)
    tc = hertz_contact_duration(m, 1.0, k, 1.5)
    assert imp.t_end - imp.t_start == pytest.approx(tc, rel=1e-10)
    assert imp.max_penetration == pytest.approx(hertz_max_penetration(m, 1.0, k, 1.5), rel=1e-10)
    assert imp.v_out == pytest.approx(1.0, rel=1e-10)
