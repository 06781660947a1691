"""The IMPACT law pieces against their definitions (Adams STEP, Hertz eqs. 4-6)."""

import math

import numpy as np
import pytest

from tailbeam import CARBON_STEEL, COAL, SANDSTONE, InputError
from tailbeam.physics.contact_law import (
    ImpactLaw,
    ball_ball_law,
    ball_plate_law,
    impact_force,
    impact_force_scalar,
    step,
    step_scalar,
)
from tailbeam.physics.materials import effective_modulus


def test_step_endpoints_and_c1_continuity():
    x0, h0, x1, h1 = 0.2, -1.0, 0.7, 3.0
    assert step_scalar(x0, x0, h0, x1, h1) == h0
    assert step_scalar(x1, x0, h0, x1, h1) == h1
    assert step_scalar(x0 - 1.0, x0, h0, x1, h1) == h0
    assert step_scalar(x1 + 1.0, x0, h0, x1, h1) == h1
    assert step_scalar(0.45, x0, h0, x1, h1) == pytest.approx(0.5 * (h0 + h1), rel=1e-15)
    # one-sided difference quotients at both ends: the slope tends to 0 (C1) linearly in eps
    for eps in (1e-3, 1e-5):
        inner0 = (step_scalar(x0 + eps, x0, h0, x1, h1) - h0) / eps
        inner1 = (h1 - step_scalar(x1 - eps, x0, h0, x1, h1)) / eps
        slope_scale = 6.0 * (h1 - h0) / (x1 - x0) ** 2
        assert abs(inner0) == pytest.approx(slope_scale * eps / 2, rel=1e-2)
        assert abs(inner1) == pytest.approx(slope_scale * eps / 2, rel=1e-2)
    xs = np.linspace(-1, 2, 101)
    np.testing.assert_array_equal(
        step(xs, x0, h0, x1, h1), [step_scalar(x, x0, h0, x1, h1) for x in xs]
    )


def test_hertz_stiffness_matches_eqs_4_to_6():
    # hand evaluation of eqs. 4-6 for coal (R = 0.03 m) on carbon steel
    inv = (1 - 0.32**2) / 5.3e9 + (1 - 0.28**2) / 2.06e11
    k_hand = 4.0 / 3.0 / inv * math.sqrt(0.03)
    law = ball_plate_law(COAL, 0.03, CARBON_STEEL)
    assert law.stiffness == pytest.approx(k_hand, rel=1e-14)
    assert effective_modulus(SANDSTONE, CARBON_STEEL) > effective_modulus(COAL, CARBON_STEEL)
    pair = ball_ball_law(COAL, 0.03, COAL, 0.03)
    inv2 = 2 * (1 - 0.32**2) / 5.3e9
    assert pair.stiffness == pytest.approx(4.0 / 3.0 / inv2 * math.sqrt(0.015), rel=1e-14)


def test_clamp_removes_adhesive_pull_only():
    law = ImpactLaw(1e9, 1.5, damping=800.0, penetration=1e-4)
    eq1 = ImpactLaw(1e9, 1.5, damping=800.0, penetration=1e-4, clamp=False)
    delta, rate = 5e-5, -2.0  # separating fast with a small penetration: eq. 1 pulls
    raw = 1e9 * delta**1.5 + 800.0 * 0.5 * rate
    assert raw < 0
    assert impact_force_scalar(delta, rate, 1e9, 1.5, 800.0, 1e-4, False) == pytest.approx(raw)
    assert impact_force_scalar(delta, rate, 1e9, 1.5, 800.0, 1e-4, True) == 0.0
    assert float(law.force(delta, rate)) == 0.0
    assert float(eq1.force(delta, rate)) == pytest.approx(raw)
    # no contact, no force, whatever the rate
    assert float(impact_force(-1e-6, 5.0, eq1)) == 0.0
    # approaching: both agree and damping adds to the spring
    assert float(law.force(2e-4, 1.0)) == pytest.approx(1e9 * 2e-4**1.5 + 800.0)


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"stiffness": -1.0}, "contact.stiffness"),
        ({"stiffness": 1e9, "exponent": 0.5}, "contact.exponent"),
        ({"stiffness": 1e9, "damping": -1.0}, "contact.damping"),
        ({"stiffness": 1e9, "penetration": 0.0}, "contact.penetration"),
        ({"stiffness": float("nan")}, "contact.stiffness"),
    ],
)
def test_bad_law_parameters_name_the_field(kwargs, field):
    with pytest.raises(InputError) as err:
        ImpactLaw(**kwargs)
    assert err.value.field == field
