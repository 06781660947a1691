"""Load-dependent Ritz pseudo-modes of the truncated modes (tailbeam.plate.ritz_tail), checked
against the full spectrum of the Argyris 8x8 test mesh (dense eigensolver: every mode) and
against the full-FE impact reference of tests/test_coupled_fe.py."""

import numpy as np
import pytest
from scipy import signal
from test_coupled_fe import IMPACT, _basis, _case

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.plate.ritz_tail import (
    choose_ritz_k,
    half_sine_response,
    ritz_tail_modes,
    with_ritz_tail,
)
from tailbeam.solvers.coupled.fe_reference import QUANTITIES, impact_quantities
from tailbeam.solvers.coupled.solver import simulate_coupled

BAND = 20000.0


@pytest.fixture(scope="module")
def kirchhoff():
    """The 8x8 test case, its 20 kHz basis and every FE mode (590 DOFs, dense)."""
    case = _case("kirchhoff")
    return case, _basis("kirchhoff", fmax_hz=BAND), _basis("kirchhoff", count=case.model.n_dofs)


def test_ritz_modes_carry_exactly_2k_moments_of_the_tail(kirchhoff):
    # The k Ritz pairs are the k-node Gauss rule of the tail's measure: sum (z.f)^2 /
    # omega^(2m+2) equals the truncated modes' sum (phi.f)^2 / lambda^(m+1) for m < 2k, and
    # not for m = 2k (measured 1e-12 relative for m < 8; 2e-2 at m = 8).
    case, basis, full = kirchhoff
    n, k = basis.n_modes, 4
    f = case.model.load_vector(IMPACT)
    omega, Z = ritz_tail_modes(basis, f[:, None], k)
    tail2 = (full.mode_vectors[:, n:].T @ f) ** 2
    lam_tail, lam_p, z2 = full.omega[n:] ** 2, omega**2, (Z.T @ f) ** 2
    rel = [abs(np.sum(z2 / lam_p ** (m + 1)) / np.sum(tail2 / lam_tail ** (m + 1)) - 1.0)
           for m in range(2 * k + 1)]  # fmt: skip
    assert max(rel[: 2 * k]) < 1e-9, rel
    assert rel[2 * k] > 1e-4, rel


def test_ritz_modes_are_orthogonal_to_the_kept_modes_and_each_other(kirchhoff):
    case, basis, _ = kirchhoff
    K, M = case.model.stiffness, case.model.mass
    loads = np.column_stack([case.model.load_vector(p) for p in (IMPACT, (-0.1, 0.2))])
    omega, Z = ritz_tail_modes(basis, loads, 8)
    assert len(omega) == 16 and omega[0] > basis.omega[-1]
    assert np.allclose(Z.T @ (M @ Z), np.eye(16), atol=1e-10)
    assert np.allclose(Z.T @ (K @ Z) / omega[None, :] ** 2, np.eye(16), atol=1e-9)
    assert np.max(np.abs(basis.mode_vectors.T @ (M @ Z))) < 1e-10


@pytest.mark.parametrize("theory, bound_800", [("kirchhoff", 5e-6), ("mindlin", 3e-6)])
def test_ritz_tail_reaches_the_fe_impact_at_20_khz(theory, bound_800):
    # The quasi-static residual leaves 3.5e-5 (Kirchhoff) / 3.6e-5 (Mindlin) at 800
    # steps/contact; 32 Ritz pseudo-modes at the contact: measured 3.7e-6 / 2.0e-6 at 800, and
    # 1.64e-5 / 1.66e-5 at the default 200 steps/contact, which is then the time-step error
    # on the restitution (docs/fe-convergence.md).
    case = _case(theory)
    ref = case.reference({"kirchhoff": 1e-7, "mindlin": 2e-7}[theory], duration=6e-4)
    basis = with_ritz_tail(_basis(theory, fmax_hz=BAND), [IMPACT], case.load_radius, k=32)
    for steps, bound in ((800, bound_800), (200, 2e-5)):
        res = simulate_coupled([case.ball], basis, [case.law], 6e-4, damping_ratio=0.0,
                               steps_per_contact=steps)  # fmt: skip
        q, q_ref = impact_quantities(res.impacts[0]), impact_quantities(ref.impacts[0])
        err = max(abs(q[name] / q_ref[name] - 1.0) for name in QUANTITIES)
        assert err < bound, (steps, err)


def test_ritz_tail_bad_input(kirchhoff):
    case, basis, _ = kirchhoff
    with pytest.raises(InputError, match="^k:"):
        with_ritz_tail(basis, [IMPACT], k=0)
    with pytest.raises(InputError, match="^points:"):
        with_ritz_tail(basis, [(0.5, 0.0)])
    with pytest.raises(InputError, match="^contact_radius:"):
        with_ritz_tail(basis, [IMPACT], contact_radius=-1e-3)
    with pytest.raises(InputError, match="^basis:"):
        with_ritz_tail(basis.truncated(count=10), [IMPACT])
    with pytest.raises(WorkLimitError, match="lower k"):
        with_ritz_tail(basis, [IMPACT, (0.1, 0.1)], k=600)


# the test contact of the FE reference (docs/fe-convergence.md): duration s, peak N, d_max m
CONTACT = (332e-6, 2539.0, 8.98e-5)


def test_half_sine_response_matches_a_state_space_integration(kirchhoff):
    # closed form against scipy's linear simulation (first-order hold: exact for a
    # piecewise-linear force) of the same undamped oscillators
    case, basis, _ = kirchhoff
    f = case.model.load_vector(IMPACT)
    omega, Z = ritz_tail_modes(basis, f[:, None], 16)
    fz2, (duration, peak, _) = (Z.T @ f) ** 2, CONTACT
    t = np.linspace(0.0, duration, 4001)
    n = len(omega)
    a = np.zeros((2 * n, 2 * n))
    a[0::2, 1::2] = np.eye(n)
    a[1::2, 0::2] = -np.diag(omega**2)
    b = np.tile([[0.0], [1.0]], (n, 1))
    c = np.zeros((1, 2 * n))
    c[0, 0::2] = fz2
    _, exact, _ = signal.lsim((a, b, c, [[0.0]]), peak * np.sin(np.pi * t / duration), t)
    closed = half_sine_response(omega, np.sqrt(fz2), duration, peak, t)
    assert np.max(np.abs(closed - exact)) < 1e-6 * np.max(np.abs(exact))


def test_choose_ritz_k_doubles_until_the_tail_settles(kirchhoff):
    # measured with the probe (reference force): k = 32 at 20 kHz, change 7.8e-6
    case, basis, _ = kirchhoff
    k, change = choose_ritz_k(basis, IMPACT, 0.0, *CONTACT)
    assert k == 32 and change < 1e-5, (k, change)
    with pytest.raises(WorkLimitError, match="k_max"):
        choose_ritz_k(basis, IMPACT, 0.0, *CONTACT, tol=1e-9, k_max=64)
    with pytest.raises(InputError, match="^duration:"):
        choose_ritz_k(basis, IMPACT, 0.0, -1.0, 2539.0, 8.98e-5)
    with pytest.raises(InputError, match="^k_max:"):
        choose_ritz_k(basis, IMPACT, 0.0, *CONTACT, k_max=4096)
