"""The Adams CONTACT friction law and rolling resistance (tailbeam.physics.friction) against
the closed form of Adams' cubic STEP, and its settings' validation."""

import numpy as np
import pytest

from tailbeam.errors import InputError
from tailbeam.physics.friction import (
    DEFAULT_STICTION_VELOCITY,
    DEFAULT_TRANSITION_VELOCITY,
    FrictionModel,
    FrictionSettings,
    coefficient,
    rolling_torque,
    step,
    tangential_force,
)

MU_S, MU_D, V_S, V_D = 0.5, 0.3, 1e-3, 4e-3


def cubic(s):
    """The STEP's shape on s in [0, 1], written out: 3 s^2 - 2 s^3."""
    return 3.0 * s**2 - 2.0 * s**3


def test_step_matches_its_cubic_and_is_flat_at_both_ends():
    x = np.linspace(-1.0, 3.0, 401)
    s = np.clip((x - 0.5) / 1.5, 0.0, 1.0)
    assert step(x, 0.5, 2.0, 2.0, -1.0) == pytest.approx(2.0 - 3.0 * cubic(s), abs=1e-14)
    h = 1e-7  # one-sided slopes at the ends vanish (C^1 joins)
    assert abs(step(0.5 + h, 0.5, 2.0, 2.0, -1.0) - 2.0) / h < 1e-5
    assert abs(step(2.0 - h, 0.5, 2.0, 2.0, -1.0) + 1.0) / h < 1e-5


def test_coefficient_rises_to_static_then_falls_to_dynamic():
    v = np.concatenate([np.linspace(0.0, V_S, 50), np.linspace(V_S, V_D, 50), [V_D, 0.1, 5.0]])
    expected = np.where(
        v < V_S,
        MU_S * cubic(v / V_S),
        MU_S + (MU_D - MU_S) * cubic(np.clip((v - V_S) / (V_D - V_S), 0.0, 1.0)),
    )
    assert coefficient(v, MU_S, MU_D, V_S, V_D) == pytest.approx(expected, abs=1e-14)
    assert coefficient(np.array([0.0, V_S, V_D, 1.0]), MU_S, MU_D, V_S, V_D) == pytest.approx(
        [0.0, MU_S, MU_D, MU_D], abs=1e-15
    )
    assert coefficient(0.5 * V_S, MU_S, MU_D, V_S, V_D) == pytest.approx(0.5 * MU_S)


def test_tangential_force_opposes_the_slip_with_mu_times_the_normal_force():
    rng = np.random.default_rng(3)
    slip = rng.normal(size=(20, 3)) * rng.choice([1e-4, 1e-3, 1.0], size=(20, 1))
    slip[:, 2] = 0.0
    fn = rng.uniform(-5.0, 50.0, size=20)  # |F_n| counts (an unclamped law may pull)
    f = tangential_force(slip, fn, MU_S, MU_D, V_S, V_D)
    speed = np.linalg.norm(slip, axis=1)
    mu = coefficient(speed, MU_S, MU_D, V_S, V_D)
    assert np.linalg.norm(f, axis=1) == pytest.approx(mu * np.abs(fn), rel=1e-12)
    cos = np.einsum("pk,pk->p", f, slip) / (np.linalg.norm(f, axis=1) * speed)
    assert cos == pytest.approx(-np.ones(20), abs=1e-12)
    assert np.all(tangential_force(np.zeros((2, 3)), [3.0, 4.0], MU_S, MU_D, V_S, V_D) == 0.0)


def test_rolling_torque_is_constant_beyond_the_stiction_velocity_and_zero_at_rest():
    w = np.array([[0.0, 10.0, 0.0], [3.0, -4.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1e-3, 0.0]])
    r, fn, mu_r = 0.03, 12.0, 0.1
    tau = rolling_torque(w, fn, mu_r, r, V_S)
    assert tau[0] == pytest.approx([0.0, -mu_r * r * fn, 0.0], rel=1e-12)
    assert tau[1] == pytest.approx(-mu_r * r * fn * w[1] / 5.0, rel=1e-12)
    assert np.all(tau[2] == 0.0)
    s = r * 1e-3 / V_S  # rolling speed r |w| below v_s: the STEP's share
    assert tau[3] == pytest.approx([0.0, -mu_r * r * fn * cubic(s), 0.0], rel=1e-12)


def test_settings_take_the_adams_defaults_and_name_the_bad_key():
    s = FrictionSettings(0.5, 0.4)
    assert (s.stiction_velocity, s.transition_velocity, s.rolling) == (0.1, 1.0, 0.0)
    assert (DEFAULT_STICTION_VELOCITY, DEFAULT_TRANSITION_VELOCITY) == (0.1, 1.0)
    cases = [
        (dict(static=0.5, dynamic=-0.1), "contact.friction.dynamic"),
        (dict(static=0.3, dynamic=0.4), "contact.friction.dynamic"),
        (
            dict(static=0.5, dynamic=0.4, stiction_velocity=-1e-3),
            "contact.friction.stiction_velocity",
        ),
        (  # 0: Coulomb's law, whose transition velocity is 0 too
            dict(static=0.5, dynamic=0.4, stiction_velocity=0.0),
            "contact.friction.transition_velocity",
        ),
        (
            dict(static=0.5, dynamic=0.4, stiction_velocity=1e-3, transition_velocity=1e-3),
            "contact.friction.transition_velocity",
        ),
        (dict(static=0.5, dynamic=0.4, rolling="a"), "contact.friction.rolling"),
    ]
    for kwargs, field in cases:
        with pytest.raises(InputError) as err:
            FrictionSettings(**kwargs)
        assert err.value.field == field


def test_pairs_override_the_default_in_either_order():
    model = FrictionModel(FrictionSettings(0.5, 0.4))
    pair = model.pair_settings(1, ["coal", "carbon_steel"], {"static": 0.7, "dynamic": 0.6})
    model = FrictionModel(model.default, (pair,))
    assert model.between("carbon_steel", "coal").dynamic == 0.6
    assert model.between("coal", "coal").dynamic == 0.4
    with pytest.raises(InputError) as err:
        model.pair_settings(2, ["coal", "x"], {"dynamic": 0.9})
    assert err.value.field == "contact.friction.pairs[2].dynamic"
    with pytest.raises(InputError) as err:
        FrictionModel(model.default, (pair, (("carbon_steel", "coal"), pair[1])))
    assert err.value.field == "contact.friction.pairs[2].materials"
