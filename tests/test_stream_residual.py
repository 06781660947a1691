"""Residual flexibility at the stream solver's plate contacts (two-way modal plate)
against independent truths:

- the scalar solve ``plate_force_with_residual`` against scipy's brentq on the closed form
  (c = 0: F = k delta^e, delta + C F = delta0) and against its own defining equation (c > 0);
- one ball through the whole stream solver against the two-way coupled single-ball solver
  with residual flexibility (an independent integrator, 2nd order in its step, its rate term
  a BDF2 derivative of F): c = 0 to its time error; c = 800 to the measured bound of the
  stream's rate model (F' from the law's delta-slopes, delta'' from the free accelerations);
- band convergence of one ball's contact against a 40 kHz run, with and without the residual.
"""

import numpy as np
import pytest
from scipy.optimize import brentq

from tailbeam import SANDSTONE, Ball, ball_plate_law
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import CARBON_STEEL
from tailbeam.solvers.stream.active.compiled import pairs as ap
from tailbeam.solvers.stream.driver.loop import solve_stream
from tailbeam.solvers.stream.plate import StreamPlate
from tailbeam.streams.generator import Particle

R = 0.03
BALL = Ball("s", SANDSTONE, R, (0.07, -0.05, R + 1e-4), (0.0, 0.0, -2.0))


def _ssss(fmax):
    from tailbeam.physics.bodies import Plate
    from tailbeam.plate.closed_forms import ssss_kirchhoff_basis

    return ssss_kirchhoff_basis(Plate(), fmax)


def _stream_contact(basis, damping, residual, rtol=1e-12):
    """(duration s, v_out m/s, peak force N, max penetration m) of the ball's first contact
    through the stream solver on ``basis`` (1 % modal damping)."""
    particle = Particle("s", "", "coal", SANDSTONE, R, BALL.mass, 0.0, tuple(BALL.position),
                        tuple(BALL.velocity))  # fmt: skip
    plate = StreamPlate(basis, np.full(basis.n_modes, 0.01), residual_flexibility=residual)
    run = solve_stream([particle], InclinedPlate(), 1e-3, damping=damping, rtol=rtol,
                       progress=False, plate=plate)  # fmt: skip
    assert run.stats["late_starts"] == 0
    c = run.contacts[0]
    return np.array([c.t_end - c.t_start, c.v_out, c.peak_force, c.max_penetration])


def _coupled_contact(basis, damping, steps):
    from tailbeam.solvers.coupled import simulate_coupled

    law = ball_plate_law(SANDSTONE, R, CARBON_STEEL, damping=damping)
    res = simulate_coupled([BALL], basis, [law], 1e-3, gravity=InclinedPlate().gravity,
                           damping_ratio=0.01, residual_flexibility=True,
                           steps_per_contact=steps)  # fmt: skip
    imp = res.impacts[0]
    return np.array([imp.t_end - imp.t_start, imp.v_out, imp.peak_force, imp.max_penetration])


def test_residual_force_solves_the_series_spring():
    """c = 0: F = k delta^e with delta + C F = delta0 (brentq, 1e-15) to 1e-13; c > 0: the
    returned (F, delta, rate) satisfy F = region_force(delta, rate), delta = delta0 - C F to
    1e-13; C = 0 is exactly the law without residual."""
    law = ball_plate_law(SANDSTONE, R, CARBON_STEEL, damping=800.0)
    k, e, d = law.stiffness, law.exponent, law.penetration
    for delta0 in (1e-7, 3e-5, 1.5e-4):
        for cres in (1e-10, 1e-9, 1e-8):
            f = ap.plate_force_with_residual(delta0, 0.0, 0.0, 0.0, k, e, 0.0, d, True, False,
                                             cres)[0]  # fmt: skip
            root = brentq(lambda x: x - k * max(delta0 - cres * x, 0.0) ** e,  # noqa: B023
                          0.0, k * delta0**e, xtol=1e-300, rtol=1e-15)  # fmt: skip
            assert f == pytest.approx(root, rel=1e-13)
            for rate0, acc0 in ((2.0, 3e4), (-1.5, -2e4)):
                ramp = delta0 < d
                f, delta, rate = ap.plate_force_with_residual(
                    delta0, rate0, acc0, 5.0, k, e, 800.0, d, ramp, False, cres
                )
                assert delta == delta0 - cres * f
                law_f = ap.region_force(delta, rate, k, e, 800.0, d, ramp, False)
                assert abs(f - law_f) <= 1e-13 * abs(f)
    plain = ap.region_force(1e-4, 1.0, k, e, 800.0, d, True, False)
    assert ap.plate_force_with_residual(1e-4, 1.0, 5.0, 5.0, k, e, 800.0, d, True, False,
                                        0.0) == (plain, 1e-4, 1.0)  # fmt: skip


def test_single_ball_with_residual_matches_the_coupled_solver_elastic():
    """c = 0 (the rate model plays no part): the stream solver (rtol 1e-12) against the
    coupled solver at 1600 and 3200 steps per contact, 52 modes. The difference falls 4x per
    doubling of the coupled solver's steps (measured 1.3e-7 -> 3.2e-8 of t_end-t_start at
    10 kHz; 5.6e-7 -> 1.4e-7 -> 3.5e-8 at 5 kHz): it is the coupled solver's time error.
    Richardson-extrapolated, the two agree to <= 2e-9 (measured 1.1e-10, 2.1e-10, 4.3e-10);
    max penetration (the coupled solver's node maximum, no refinement) to 1e-7 (8e-8)."""
    basis = _ssss(5000.0)
    ours = _stream_contact(basis, 0.0, True)
    a, b = _coupled_contact(basis, 0.0, 1600), _coupled_contact(basis, 0.0, 3200)
    da, db = np.abs(ours - a) / np.abs(a), np.abs(ours - b) / np.abs(b)
    assert np.all(db[:3] < 0.4 * da[:3])  # the gap closes at the coupled solver's order
    truth = b + (b - a) / 3.0
    err = np.abs(ours - truth) / np.abs(truth)
    print("c = 0, stream vs Richardson(coupled 1600, 3200):", err)
    assert np.all(err[:3] < 2e-9) and err[3] < 1e-7
    without = _stream_contact(basis, 0.0, False)
    assert np.all(np.abs(without[:3] - truth[:3]) > 1e-2 * np.abs(truth[:3]))  # (it matters)


def test_single_ball_with_residual_matches_the_coupled_solver_damped():
    """c = 800 N s/m: the stream's rate model drops C F'' from delta'' (docs/streams.md);
    measured against the coupled solver (converged: 1600 vs 3200 steps agree to 3e-7)
    at 52 modes: duration 1.0e-5, v_out 4.2e-4, peak force 8.6e-5, max penetration 2.7e-4
    (bound 6e-4); without the residual 2.2e-2, 6.0e-2, 2.9e-2, 1.7e-2."""
    basis = _ssss(5000.0)
    ours = _stream_contact(basis, 800.0, True)
    a, b = _coupled_contact(basis, 800.0, 1600), _coupled_contact(basis, 800.0, 3200)
    assert np.all(np.abs(a - b) < 1e-6 * np.abs(b))  # the coupled solver has converged
    err = np.abs(ours - b) / np.abs(b)
    print("c = 800, stream vs coupled 3200:", err)
    assert np.all(err < 6e-4)


BANDS = (10e3, 14e3, 20e3, 28e3)


@pytest.mark.parametrize("damping", [0.0, 800.0])
def test_band_convergence_with_residual(damping):
    """One ball at 10/14/20/28 kHz against 40 kHz (closed-form SSSS basis, 106-308 of 445
    modes): with the residual the worst relative error of duration, v_out and peak force
    falls at a fitted order >= 2.3 in the band (measured 2.6 at c = 0, 3.3 at c = 800) and
    is <= 2e-3 at 10 kHz (measured 5.4e-4, 1.6e-3); without it the order is lower by 0.5 or
    more (1.93, 1.95) and the error at 10 kHz >= 1e-2 (1.7e-2, 2.1e-2)."""
    full = _ssss(40e3)
    orders, first = {}, {}
    for residual in (True, False):
        ref = _stream_contact(full, damping, residual, rtol=1e-10)[:3]
        errs = []
        for fmax in BANDS:
            v = _stream_contact(full.truncated(fmax_hz=fmax), damping, residual, rtol=1e-10)
            errs.append(np.max(np.abs(v[:3] - ref) / np.abs(ref)))
        orders[residual] = -np.polyfit(np.log(BANDS), np.log(errs), 1)[0]
        first[residual] = errs[0]
    print(f"c = {damping}: order {orders}, error at 10 kHz {first}")
    assert orders[True] >= 2.3 and first[True] <= 2e-3
    assert orders[False] <= orders[True] - 0.5 and first[False] >= 1e-2
