"""Closed-form motion between contacts (tailbeam.solvers.numerics.flight) against closed forms."""

import math

import numpy as np
import pytest

from tailbeam.solvers.numerics.flight import (
    band_time,
    edge_time,
    first_crossing,
    pair_time,
    plate_time,
)


def test_a_grazing_dip_is_found():
    """p = (t - 0.5)^2 - 1e-14 dips below zero for 2e-7 s around t = 0.5: found at its root
    (to the conditioning of the coefficients: eps x 0.25 / p'(root) = 2.8e-10 s)."""
    c = [0.25 - 1e-14, -1.0, 1.0]
    assert first_crossing(c, 1.0) == pytest.approx(0.5 - 1e-7, abs=3e-10)
    assert first_crossing([0.25 + 1e-14, -1.0, 1.0], 1.0) == math.inf  # misses by 1e-7 m^2


def test_quartic_pair_touch_matches_brute_force():
    rng = np.random.default_rng(4)
    for _ in range(50):
        dx, dv, da = rng.normal(0, 0.1, 3), rng.normal(0, 1.0, 3), rng.normal(0, 10.0, 3)
        rs = 0.05
        dx *= 2 * rs / np.linalg.norm(dx) * (1 + rng.random())  # start apart
        t = pair_time(dx, dv, da, rs, 0.2)
        ts = np.linspace(0, 0.2, 200_001)
        d = np.linalg.norm(dx + dv * ts[:, None] + 0.5 * da * ts[:, None] ** 2, axis=1)
        inside = np.flatnonzero(d <= rs)
        if inside.size:  # the first sampled touch is within one sample of the root
            assert abs(t - ts[inside[0]]) <= 1.01e-6
        else:
            assert t == math.inf or np.min(d) - rs < 1e-9


def test_plate_band_and_edge_times_are_the_closed_forms():
    g = 9.81
    assert plate_time(1.02, 0.0, -g, 0.02) == pytest.approx(math.sqrt(2 / g), rel=1e-15)
    # rising from 1 mm above the band, apex 5.1 mm higher: back down at the band
    v = 0.316
    t = band_time(0.021, v, -g, 0.022)
    assert 0.021 + v * t - 0.5 * g * t * t == pytest.approx(0.022, abs=1e-15)
    assert band_time(0.021, 0.01, -g, 0.022) == math.inf  # apex below the band
    # inside the band and descending: now (its crossing lies in the past, never returned)
    assert band_time(0.021, -0.5, -g, 0.022) == 0.0
    a = g * math.sin(math.radians(30))
    tau, edge = edge_time(np.array([0.1, 0.0, 0.02]), np.array([0.2, 0.0, 0.0]),
                          np.array([a, 0.0, 0.0]), (0.3, 0.3))  # fmt: skip
    assert edge == "x+" and 0.1 + 0.2 * tau + 0.5 * a * tau * tau == pytest.approx(0.3, abs=1e-15)
