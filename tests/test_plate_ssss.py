"""FE modes of the simply supported plate against the closed forms of each theory.

Both elements are conforming, so FE frequencies approach the exact ones from above; the
meshes are the coarsest that meet each tolerance with margin (measured:
benchmarks/bench_modes.py).
"""

import numpy as np
import pytest

from tailbeam.physics.bodies import Plate
from tailbeam.plate import assemble_plate, compute_modes
from tailbeam.plate.closed_forms import ssss_mode_count, ssss_modes
from tailbeam.plate.fe.sparse_solve import count_eigenvalues_below

PLATE = Plate()


@pytest.fixture(scope="module")
def kirchhoff_20():
    # 12 divisions: measured error 8e-6 on the first 20 modes
    return compute_modes(PLATE, "SSSS", theory="kirchhoff", count=20, divisions=12, use_cache=False)


@pytest.fixture(scope="module")
def mindlin_10k():
    # 16 divisions: measured error 5.4e-4 up to 10 kHz
    return compute_modes(
        PLATE, "SSSS", theory="mindlin", fmax_hz=1e4, divisions=16, use_cache=False
    )


def test_first_20_kirchhoff_modes_within_1e4(kirchhoff_20):
    ref = ssss_modes(PLATE, "kirchhoff", count=20).frequencies_hz
    rel = kirchhoff_20.frequencies_hz / ref - 1.0
    assert np.max(np.abs(rel)) < 1e-4
    assert np.all(rel > -1e-9)  # conforming: from above


def test_mindlin_within_1e3_up_to_10khz(mindlin_10k):
    ref = ssss_modes(PLATE, "mindlin", fmax_hz=1e4).frequencies_hz
    assert mindlin_10k.n_modes == len(ref) == 112
    rel = mindlin_10k.frequencies_hz / ref - 1.0
    assert np.max(np.abs(rel)) < 1e-3
    assert np.all(rel > -1e-9)
    # and the shear/rotary-inertia effect is really there: Kirchhoff's closed form is far off
    kir = ssss_modes(PLATE, "kirchhoff", count=len(ref)).frequencies_hz
    assert kir[-1] / ref[-1] - 1.0 > 0.05


# Divisions chosen so the FE error at each threshold (Kirchhoff 20: 9e-4 at 20 kHz; Mindlin
# 18: 2.2e-3 at 20 kHz) is below the gap between the closed-form modes and the thresholds
# (1.5e-3 and 6e-3; 8.5e-4 for Mindlin at 10 kHz, where the error is 2.3e-4).
@pytest.mark.parametrize("theory, divisions", [("kirchhoff", 20), ("mindlin", 18)])
def test_mode_counts_below_5_10_20_khz(theory, divisions):
    # counted by Sylvester's inertia of K - omega^2 M, independent of the eigensolver
    model = assemble_plate(PLATE, "SSSS", theory=theory, divisions=divisions)
    for fmax in (5e3, 1e4, 2e4):
        count = count_eigenvalues_below(model.stiffness, model.mass, (2 * np.pi * fmax) ** 2)
        assert count == ssss_mode_count(PLATE, fmax, theory), (theory, fmax)


def test_eigensolver_finds_every_mode_in_the_band(mindlin_10k):
    model = mindlin_10k.fe_model()
    for fmax in (5e3, 1e4):
        count = count_eigenvalues_below(model.stiffness, model.mass, (2 * np.pi * fmax) ** 2)
        assert np.count_nonzero(mindlin_10k.frequencies_hz <= fmax) == count


@pytest.mark.parametrize("fixture", ["kirchhoff_20", "mindlin_10k"])
def test_mass_normalised_and_orthogonal(fixture, request):
    basis = request.getfixturevalue(fixture)
    model = basis.fe_model()
    phi = basis.mode_vectors
    n = basis.n_modes
    np.testing.assert_allclose(phi.T @ (model.mass @ phi), np.eye(n), atol=1e-8)
    stiff = phi.T @ (model.stiffness @ phi)
    omega2 = basis.omega**2
    np.testing.assert_allclose(np.diag(stiff), omega2, rtol=1e-8)
    off = stiff - np.diag(np.diag(stiff))
    assert np.max(np.abs(off)) < 1e-8 * omega2.max()


def test_deflection_is_the_unit_modal_mass_sine_shape(kirchhoff_20):
    # mode 1 is sin*sin with amplitude 2/sqrt(rho h a b) (unit modal mass), up to sign
    amp = 2.0 / np.sqrt(PLATE.mass_per_area * PLATE.size_x * PLATE.size_y)
    pts = np.array([[0.0, 0.0], [0.1, -0.2], [-0.25, 0.05]])
    exact = amp * np.cos(np.pi * pts[:, 0] / 0.6) * np.cos(np.pi * pts[:, 1] / 0.6)
    got = kirchhoff_20.deflection(pts)[:, 0]
    np.testing.assert_allclose(got * np.sign(got[0]), exact, rtol=1e-5)


@pytest.mark.parametrize("theory, low, high", [("kirchhoff", 7.0, 9.0), ("mindlin", 6.5, 8.5)])
def test_convergence_order(theory, low, high):
    # first 19 modes (to 2 kHz) on 8 and 12 divisions. Theory: eigenvalue error ~ dx^(2(p-1))
    # = dx^8 for the quintic Argyris (H2-conforming); dx^(2p) = dx^8 for P4 Mindlin
    # asymptotically, lower before the shear term is resolved (h/dx ~ 0.2 here): >= 6.5
    ref = ssss_modes(PLATE, theory, count=19).frequencies_hz
    errs = [
        np.sum(
            compute_modes(
                PLATE, "SSSS", theory=theory, count=19, divisions=n, use_cache=False
            ).frequencies_hz
            / ref
            - 1.0
        )
        for n in (8, 12)
    ]
    order = np.log(errs[0] / errs[1]) / np.log(12 / 8)
    assert low < order < high, order
