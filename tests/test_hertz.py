"""Closed forms of the undamped impact (tailbeam.physics.hertz) against independent derivations."""

import math

import pytest
from scipy.integrate import quad

from tailbeam.errors import InputError
from tailbeam.physics.hertz import (
    free_fall_apex,
    hertz_contact_duration,
    hertz_duration_factor,
    hertz_max_penetration,
    hertz_peak_force,
    static_penetration,
)


def test_johnson_constant_for_hertz_exponent():
    # Johnson, Contact Mechanics 11.4: t_c = 2.94 delta_m / v (2.9432..., truncated there)
    assert hertz_duration_factor(1.5) == pytest.approx(2.9432, abs=1e-4)


@pytest.mark.parametrize("e", [1.0, 1.5, 2.2, 3.0])
def test_duration_factor_against_quadrature(e):
    # 2 int_0^1 dx / sqrt(1 - x^(e+1)); x = 1 - s^2 removes the endpoint singularity
    val, _ = quad(
        lambda s: 2.0 * s / math.sqrt(1.0 - (1.0 - s * s) ** (e + 1.0)),
        0.0,
        1.0,
        epsabs=0.0,
        epsrel=1e-13,
    )
    assert hertz_duration_factor(e) == pytest.approx(2.0 * val, rel=1e-11)


def test_linear_spring_is_a_half_sine():
    # e = 1: a linear spring, t_c = pi sqrt(m/k), delta_m = v sqrt(m/k), F_m = k delta_m
    m, v, k = 0.3, 2.0, 5e6
    assert hertz_duration_factor(1.0) == pytest.approx(math.pi, rel=1e-14)
    assert hertz_contact_duration(m, v, k, 1.0) == pytest.approx(math.pi * math.sqrt(m / k), 1e-14)
    assert hertz_max_penetration(m, v, k, 1.0) == pytest.approx(v * math.sqrt(m / k), rel=1e-14)
    assert hertz_peak_force(m, v, k, 1.0) == pytest.approx(v * math.sqrt(m * k), rel=1e-14)


@pytest.mark.parametrize("e", [1.0, 1.5, 2.2])
def test_energy_balance_at_max_penetration(e):
    m, v, k = 0.156, 1.7, 1.3e9
    dm = hertz_max_penetration(m, v, k, e)
    assert k * dm ** (e + 1) / (e + 1) == pytest.approx(0.5 * m * v * v, rel=1e-13)
    assert hertz_peak_force(m, v, k, e) == pytest.approx(k * dm**e, rel=1e-14)


def test_static_and_apex():
    assert static_penetration(2.0, 8.0, 2.0) == pytest.approx(0.5, rel=1e-15)
    assert static_penetration(0.0, 8.0) == 0.0
    assert free_fall_apex(3.0, 9.0) == pytest.approx(0.5, rel=1e-15)
    assert free_fall_apex(3.0, 0.0) == math.inf


def test_bad_input_names_the_field():
    with pytest.raises(InputError, match="speed"):
        hertz_max_penetration(1.0, 0.0, 1.0)
    with pytest.raises(InputError, match="mass"):
        hertz_peak_force(-1.0, 1.0, 1.0)
