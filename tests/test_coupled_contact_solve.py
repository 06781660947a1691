"""The fallback of the coupled step's contact forces (tailbeam.solvers.coupled.contact_solve)
on systems where plain Newton (step._newton) fails, against an independent truth: the IMPACT
law written out here in plain Python, scipy's bracketed root finder (one contact) and scipy's
own multidimensional solver (several contacts), 40-digit decimal arithmetic (the state where
a real run failed) and the energy balance of that run.

The real failure: a sandstone ball at 4.7 m/s with contact damping 3000 N s/m. While it
unloads, its force is the small difference of the elastic term and the damping term (each
~3400 N); near the clamp the force is ~4e-4 N and its rounding ~1e-12 N, above plain
Newton's test of 1e-13 N, so Newton oscillated at the rounding level and the run stopped.

The systems have the structure of a step's (step._contact_system): -S and -Sv symmetric
positive definite (compliances), drawn at random over the ranges a step meets (compliances
1e-9-1e-6 m/N, damping 10-1e4 N s/m, penetrations within 1e-9-1e-3 m of contact, with and
without the clamp), and kept only where plain Newton fails.
"""

import math
from decimal import Decimal, getcontext

import numpy as np
import pytest
from scipy.optimize import brentq, root

from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.materials import CARBON_STEEL, SANDSTONE
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.solvers.coupled import simulate_coupled
from tailbeam.solvers.coupled.contact_solve import scalar_force, solve_forces
from tailbeam.solvers.coupled.step import _newton

K_COAL = 7.67e8  # N/m^1.5: coal ball of 10 mm on steel (ball_plate_law)
E, D = 1.5, 1e-4


def impact(delta, rate, c, clamp):
    """The IMPACT law: k delta^e + c STEP(delta; 0, 0, d, 1) delta', 0 without contact,
    max(0, .) with the clamp."""
    if delta <= 0.0:
        return 0.0
    s = min(delta / D, 1.0)
    f = K_COAL * delta**E + c * s * s * (3.0 - 2.0 * s) * rate
    return max(f, 0.0) if clamp else f


def residual(x, sys):
    dfree, vfree, S, Sv, c, clamp = sys
    dl, dv = dfree + S @ x, vfree + Sv @ x
    return np.array([x[j] - impact(dl[j], dv[j], c, clamp) for j in range(len(x))])


def failing_systems(seed=1, wanted=8, tries=6000):
    """Random step systems on which plain Newton fails, with the guess it started from."""
    rng = np.random.default_rng(seed)
    found = []
    for _ in range(tries):
        na = int(rng.integers(1, 4))
        a = rng.normal(size=(na, na)) * 10 ** rng.uniform(-9, -6)
        comp = a @ a.T + np.diag(10 ** rng.uniform(-9, -6, na))
        sys = (
            10 ** rng.uniform(-9, -3, na) * rng.choice([-1, 1, 1, 1], na),
            rng.normal(size=na) * 10 ** rng.uniform(-5, 1),
            -comp,
            -comp * 10 ** rng.uniform(3, 6),
            10 ** rng.uniform(1, 4),
            bool(rng.integers(0, 2)),
        )
        guess = np.abs(rng.normal(size=na)) * 10 ** rng.uniform(0, 3)
        if not _newton(*_args(sys), guess.copy(), *_law(sys)):
            found.append((sys, guess))
            if len(found) == wanted:
                break
    return found


def _args(sys):
    na = len(sys[0])
    s, sv = np.ascontiguousarray(sys[2]), np.ascontiguousarray(sys[3])
    return np.arange(na), na, sys[0], sys[1], s, sv


def _law(sys):
    na = len(sys[0])
    return (np.full(na, K_COAL), np.full(na, E), np.full(na, sys[4]), np.full(na, D),
            np.full(na, sys[5]))  # fmt: skip


@pytest.fixture(scope="module")
def systems():
    found = failing_systems()
    assert len(found) >= 4  # the ranges do make plain Newton fail
    return found


def test_fallback_solves_every_system_plain_newton_fails_on(systems):
    for sys, guess in systems:
        x = guess.copy()
        assert solve_forces(*_args(sys), x, *_law(sys))
        force = np.array([max(abs(v), 1.0) for v in x])
        assert np.all(np.abs(residual(x, sys)) <= 1e-9 * force.max())


def test_one_contact_matches_scipy_brentq(systems):
    singles = [(s, g) for s, g in systems if len(s[0]) == 1]
    assert singles
    for sys, guess in singles:
        x = guess.copy()
        assert solve_forces(*_args(sys), x, *_law(sys))

        def g(f, sys=sys):  # increasing in f
            return residual(np.array([f]), sys)[0]

        lo, hi = -1.0, 1.0
        while g(lo) > 0.0:
            lo *= 4.0
        while g(hi) < 0.0:
            hi *= 4.0
        truth = brentq(g, lo, hi, xtol=1e-14, rtol=1e-15)
        assert x[0] == pytest.approx(truth, rel=1e-10, abs=1e-10)


def test_several_contacts_match_scipy_root(systems):
    multis = [(s, g) for s, g in systems if len(s[0]) > 1]
    assert multis
    for sys, guess in multis:
        x = guess.copy()
        assert solve_forces(*_args(sys), x, *_law(sys))
        ref = root(lambda v, s=sys: residual(v, s), x + 1e-3 * np.abs(x) + 1e-6, method="hybr")
        assert ref.success
        assert np.allclose(x, ref.x, rtol=1e-8, atol=1e-8)


def test_scalar_force_brackets_a_root_far_from_the_guess():
    # one contact: penetration 5e-5 m free, compliance 1e-8 m/N, undamped; root by hand
    a, s = 5e-5, -1e-8
    x, ok = scalar_force(1e6, a, 0.0, s, 0.0, K_COAL, E, 0.0, D, True)
    truth = brentq(lambda f: f - K_COAL * max(a + s * f, 0.0) ** E, 0.0, 1e6, xtol=1e-12)
    assert ok
    assert x == pytest.approx(truth, rel=1e-12)
    assert math.isfinite(x)


# the step where the run below failed: one contact, its system as step._contact_system built it
FAILED = {
    "dfree": 0.0001070777224710906, "vfree": -1.1331534707554738,
    "S": -8.883328870233521e-10, "Sv": -0.0011750114852896677, "guess": -5.480980558580974,
    "k": 3068043799.957093, "c": 3000.0,
}  # fmt: skip
RUN_BALL = Ball("b", SANDSTONE, 0.031741882267633144,
                (0.19, -0.16437217384574226, 0.06196009959191077),
                (0.0, 0.0, -4.699433863816461))  # fmt: skip


def _decimal_root(p):
    """The root of x = IMPACT(dfree + S x, vfree + Sv x) by bisection in 40 digits."""
    getcontext().prec = 40
    k, c, d = Decimal(p["k"]), Decimal(p["c"]), Decimal(D)

    def g(x):
        delta = Decimal(p["dfree"]) + Decimal(p["S"]) * x
        rate = Decimal(p["vfree"]) + Decimal(p["Sv"]) * x
        if delta <= 0:
            return x
        s = min(delta / d, Decimal(1))
        f = k * delta * delta.sqrt() + c * s * s * (3 - 2 * s) * rate
        return x - max(f, Decimal(0))

    lo, hi = Decimal(-10), Decimal(10)
    assert g(lo) < 0 < g(hi)
    for _ in range(200):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if g(mid) < 0 else (lo, mid)
    return float((lo + hi) / 2)


def test_the_failed_step_is_solved_to_its_rounding():
    p = FAILED
    system = (np.array([p["dfree"]]), np.array([p["vfree"]]), np.array([[p["S"]]]),
              np.array([[p["Sv"]]]))  # fmt: skip
    law = (np.array([p["k"]]), np.array([E]), np.array([p["c"]]), np.array([D]),
           np.array([True]))  # fmt: skip
    idx = np.array([0])
    assert not _newton(idx, 1, *system, np.array([p["guess"]]), *law)  # plain Newton fails here
    x = np.array([p["guess"]])
    assert solve_forces(idx, 1, *system, x, *law)
    truth = _decimal_root(p)
    assert 3e-4 < truth < 5e-4  # the unloading force near the clamp
    # both force terms are ~3400 N: their rounding, ~1e-12 N, is what the answer can reach
    assert x[0] == pytest.approx(truth, abs=2e-12)


def test_the_failed_run_ends_and_balances_its_energy():
    # The run that stopped at t = 6.64 ms with plain Newton. Truth: energy conservation. Ball
    # loss = plate energy + modal damping + contact work (elastic and damping) + the residual
    # spring, as tests/test_coupled_physics.py checks it on a converging run.
    basis = ssss_kirchhoff_basis(Plate(), 12000.0)
    law = ball_plate_law(SANDSTONE, RUN_BALL.radius, CARBON_STEEL, damping=3000.0)
    res = simulate_coupled([RUN_BALL], basis, [law], 0.0072)
    assert res.status == 0 and len(res.impacts) == 1 and res.impacts[0].t_end < 0.0072
    imp = res.impacts[0]
    t = np.linspace(imp.t_start - 1e-5, imp.t_end + 1e-5, 8001)  # the contact, 30 ns apart
    s = res.sample(t)["b"]
    q, qd, _ = res.plate.modal_sample(t)
    om = basis.omega[:, None]
    m, g = RUN_BALL.mass, 9.80665
    e_ball = 0.5 * m * s["vz"] ** 2 + m * g * s["z"]
    e_plate = 0.5 * np.sum(qd**2 + om**2 * q**2, axis=0)

    def cumtrapz(y, x):
        return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))])

    d_modal = cumtrapz(np.sum(2 * res.plate.zeta[:, None] * om * qd**2, axis=0), t)
    xy = RUN_BALL.position[:2]
    phi, comp = basis.deflection([xy])[0], basis.residual_compliance([xy])[0]
    force = s["force"]
    delta_c = RUN_BALL.radius - s["z"] + phi @ q - comp * force
    w_contact = cumtrapz(force, delta_c)  # the work of the force along delta_c
    e0 = e_plate[0] + 0.5 * comp * force[0] ** 2
    imbalance = (e_ball[0] - e_ball) - (e_plate + d_modal + w_contact + 0.5 * comp * force**2 - e0)
    loss = e_ball[0] - e_ball[-1]
    assert w_contact[-1] > 0.1 * loss  # the contact damping takes a sizeable share
    assert np.max(np.abs(imbalance)) < 1e-6 * loss
