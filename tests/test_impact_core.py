"""The IMPACT law's one definition (tailbeam.physics.impact) against independent truths:
eq. 5 evaluated by hand, Adams' STEP end conditions, finite differences for the derivatives,
the integral of the elastic force; the law written nowhere else; one table of event kinds.

Tolerances: the hand formula differs from the core only by rounding (x sqrt(x) for x^1.5), so
1e-14; central differences with step h have error ~h^2 f''' / 6 and rounding ~eps f / h, so
h = 1e-5 of the scale and 1e-7 relative.
"""

import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from tailbeam.physics import impact
from tailbeam.results.records import EventCode, EventKind

K, C, D = 3e9, 900.0, 1e-4
EXPONENTS = (1.0, 1.5, 2.0, 2.2)


def _by_hand(delta, rate, k, e, c, d, clamp):
    """Eq. 5 as printed, with Adams' STEP written out and the optional max(0, .)."""
    if delta <= 0.0:
        return 0.0
    s = min(delta / d, 1.0)
    f = k * delta**e + c * (3.0 * s**2 - 2.0 * s**3) * rate
    return max(f, 0.0) if clamp else f


def _samples(n=300, seed=3):
    rng = np.random.default_rng(seed)
    return rng.uniform(1e-8, 3e-4, n), rng.uniform(-3.0, 3.0, n)


@pytest.mark.parametrize("e", EXPONENTS)
def test_force_is_eq_5(e):
    delta, rate = _samples()
    for clamp in (True, False):
        ours = [impact.force(x, u, K, e, C, D, clamp) for x, u in zip(delta, rate, strict=True)]
        want = [_by_hand(x, u, K, e, C, D, clamp) for x, u in zip(delta, rate, strict=True)]
        np.testing.assert_allclose(ours, want, rtol=1e-14, atol=1e-12 * K * D**e)
    assert impact.force(-1e-6, 5.0, K, e, C, D, False) == 0.0
    assert impact.force(0.0, 5.0, K, e, C, D, False) == 0.0


def test_step_meets_its_end_conditions():
    x0, h0, x1, h1 = 0.2, -1.0, 0.7, 3.0
    assert impact.step(x0, x0, h0, x1, h1) == h0
    assert impact.step(x1, x0, h0, x1, h1) == h1
    assert impact.step(0.45, x0, h0, x1, h1) == pytest.approx(0.5 * (h0 + h1), rel=1e-15)
    # zero slope at both ends: the ramp's damping and its slope at the kinks
    assert impact.region_damping_slope(0.0, C, D, True) == 0.0
    assert impact.region_damping_slope(D, C, D, True) == 0.0
    assert impact.region_damping(D, C, D, True) == C == impact.region_damping(D, C, D, False)


def _central(fun, x, h):
    return (fun(x + h) - fun(x - h)) / (2.0 * h)


def _check_derivatives(x, u, e, a=-3e4):
    """Partials and dF/dt along delta(t) = x + u t + a t^2 / 2 against central differences."""
    ramp = x < D

    def law(delta, rate):
        return impact.region_force(delta, rate, K, e, C, D, ramp, False)

    f, fd, fv, raw = impact.force_partials(x, u, K, e, C, D, False)
    assert f == raw == pytest.approx(_by_hand(x, u, K, e, C, D, False), rel=1e-14)
    hx, scale = 1e-5 * x, K * x**e + C * abs(u)  # (the terms' size: f may cancel)
    assert fd == pytest.approx(_central(lambda d: law(d, u), x, hx), rel=1e-7, abs=1e-7 * scale / x)
    assert fv == pytest.approx(_central(lambda r: law(x, r), u, 1e-5), rel=1e-7, abs=1e-9 * C)
    h = hx / max(abs(u), 1e-3)
    along = _central(lambda t: law(x + u * t + 0.5 * a * t * t, u + a * t), 0.0, h)
    got = impact.region_force_rate(x, u, a, K, e, C, D, ramp)
    assert got == pytest.approx(along, rel=1e-6, abs=1e-10 * scale / h)


@pytest.mark.parametrize("e", EXPONENTS)
def test_partials_and_force_rate_are_the_derivatives(e):
    delta, rate = _samples(60, seed=5)
    for x, u in zip(delta, rate, strict=True):
        _check_derivatives(x, u, e)


def test_clamp_holds_the_force_and_its_partials_at_zero():
    x, u = 5e-5, -2.0  # separating fast at a small penetration: eq. 1 pulls
    f, fd, fv, raw = impact.force_partials(x, u, 1e9, 1.5, 800.0, 1e-4, True)
    assert raw < 0.0
    assert raw == pytest.approx(_by_hand(x, u, 1e9, 1.5, 800.0, 1e-4, False), rel=1e-14)
    assert (f, fd, fv) == (0.0, 0.0, 0.0)


@pytest.mark.parametrize("e", EXPONENTS)
def test_clamp_indicator_has_the_sign_of_the_force_and_its_limit_at_contact(e):
    delta, rate = _samples(400, seed=9)
    for ramp in (True, False):
        for x, u in zip(delta, rate, strict=True):
            raw = impact.region_force(x, u, K, e, C, D, ramp, False)
            ind = impact.clamp_indicator(x, u, K, e, C, D, ramp)
            assert (ind < 0.0) == (raw < 0.0)
            assert ind == pytest.approx(raw / (K * x**e), rel=1e-12)
    # delta <= 0 gives the limit at delta -> 0+ (approached here at delta = 1e-13 d)
    for ramp in (True, False):
        for u in (-2.0, 2.0):
            near = impact.clamp_indicator(1e-13 * D, u, K, e, C, D, ramp)
            at = impact.clamp_indicator(0.0, u, K, e, C, D, ramp)
            if math.isfinite(near) and abs(near) < 1e3:
                assert at == pytest.approx(near, rel=1e-5)
            else:  # the damping term dominates: only its sign survives
                assert at == math.copysign(1.0, near)


@pytest.mark.parametrize("e", EXPONENTS)
def test_elastic_energy_is_the_work_of_the_elastic_force(e):
    work, _ = quad(lambda x: K * x**e, 0.0, 2e-4, epsabs=0.0, epsrel=1e-13)
    assert impact.elastic_energy(2e-4, K, e) == pytest.approx(work, rel=1e-12)
    assert impact.elastic_energy(-1e-6, K, e) == 0.0


def test_the_law_is_written_once():
    """No module but tailbeam/physics/impact.py spells out STEP's cubic or k delta^e."""
    root = Path(__file__).resolve().parents[1] / "tailbeam"
    cubic = re.compile(r"3\.0 - 2\.0 \*")
    elastic = re.compile(r"\bk\w* \* (delta|dp|pos|x)\w* ?\*\*")
    found = [
        str(path.relative_to(root))
        for path in root.rglob("*.py")
        if path.name != "impact.py" and (cubic.search(t := path.read_text()) or elastic.search(t))
    ]
    assert found == []


def test_event_kinds_print_as_their_values_and_every_solver_uses_them():
    from tailbeam import CARBON_STEEL, COAL, Ball, Plate, ball_plate_law
    from tailbeam.solvers.rigid import simulate_rigid

    assert f"{EventKind.REST}" == str(EventKind.REST) == EventKind.REST == "rest"
    # one code per kind, and back: the kernels' integers and the outputs' names are one table
    codes = [c for c in EventCode if c is not EventCode.NONE]
    assert sorted(c.kind for c in codes) == sorted(EventKind) and len(codes) == len(EventKind)
    assert all(k.code.kind is k for k in EventKind)
    law = ball_plate_law(COAL, 0.03, CARBON_STEEL, damping=800.0)
    ball = Ball("A", COAL, 0.03, (0.0, 0.0, 0.031), (0.0, 0.0, -2.0))
    res = simulate_rigid([ball], Plate(), [law], 0.05)
    kinds = [e.kind for e in res.events]
    assert {EventKind.CONTACT_START, EventKind.FULL_DAMPING, EventKind.CONTACT_END} <= set(kinds)
    assert all(isinstance(k, EventKind) for k in kinds)
