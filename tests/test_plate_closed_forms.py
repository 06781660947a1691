"""Closed forms of tailbeam.plate.closed_forms against independent derivations."""

import numpy as np
import pytest
import scipy.linalg as sla

from tailbeam.physics.bodies import Plate
from tailbeam.physics.materials import Material
from tailbeam.plate.closed_forms import (
    SHEAR_COEFFICIENT,
    bending_wavenumber,
    kirchhoff_model_error,
    leissa_frequencies,
    mindlin_flexural_omega,
    ssss_modes,
)

PLATE = Plate()


def navier_3x3_lowest_omega(plate, m, n):
    """Independent route to the SSSS Mindlin frequency: insert w = W sin sin,
    beta_x = X cos sin, beta_y = Y sin cos into the Mindlin energies and take the lowest root
    of the 3x3 problem (the other two are thickness-shear modes)."""
    mat = plate.material
    h, nu = plate.thickness, mat.poisson_ratio
    d = plate.bending_stiffness
    s = SHEAR_COEFFICIENT * mat.youngs_modulus / (2 * (1 + nu)) * h
    al, ga = m * np.pi / plate.size_x, n * np.pi / plate.size_y
    k = np.array(
        [
            [s * (al**2 + ga**2), -s * al, -s * ga],
            [-s * al, d * (al**2 + 0.5 * (1 - nu) * ga**2) + s, 0.5 * d * (1 + nu) * al * ga],
            [-s * ga, 0.5 * d * (1 + nu) * al * ga, d * (ga**2 + 0.5 * (1 - nu) * al**2) + s],
        ]
    )
    rho_i = mat.density * h**3 / 12
    mass = np.diag([plate.mass_per_area, rho_i, rho_i])
    return np.sqrt(sla.eigh(k, mass, eigvals_only=True)[0])


@pytest.mark.parametrize("m, n", [(1, 1), (2, 1), (3, 5), (12, 7), (20, 1)])
def test_mindlin_root_matches_3x3_navier_problem(m, n):
    k2 = (m * np.pi / PLATE.size_x) ** 2 + (n * np.pi / PLATE.size_y) ** 2
    assert mindlin_flexural_omega(PLATE, k2) == pytest.approx(
        navier_3x3_lowest_omega(PLATE, m, n), rel=1e-10
    )


def test_mindlin_tends_to_kirchhoff_for_a_thin_plate():
    thin = Plate(thickness=1e-4)
    kir = ssss_modes(thin, "kirchhoff", count=20).frequencies_hz
    mind = ssss_modes(thin, "mindlin", count=20).frequencies_hz
    # corrections scale like (k h)^2 ~ (20 * 1e-4)^2 = 4e-6
    np.testing.assert_allclose(mind, kir, rtol=2e-5)
    assert np.all(mind < kir)


def test_kirchhoff_overestimates_as_the_brief_states():
    # brief: ~3 % at 5 kHz and ~7 % at 10 kHz for the 10 mm steel plate
    assert 0.025 < kirchhoff_model_error(PLATE, 5e3) < 0.045
    assert 0.06 < kirchhoff_model_error(PLATE, 1e4) < 0.09


@pytest.mark.parametrize("theory", ["kirchhoff", "mindlin"])
def test_wavenumber_inverts_the_dispersion_relation(theory):
    f = np.array([100.0, 5e3, 2e4])
    k2 = bending_wavenumber(PLATE, f, theory) ** 2
    if theory == "mindlin":
        omega = mindlin_flexural_omega(PLATE, k2)
    else:
        omega = k2 * np.sqrt(PLATE.bending_stiffness / PLATE.mass_per_area)
    np.testing.assert_allclose(omega, 2 * np.pi * f, rtol=1e-12)


def test_ssss_modes_band_and_count_agree():
    by_band = ssss_modes(PLATE, "mindlin", fmax_hz=5e3)
    by_count = ssss_modes(PLATE, "mindlin", count=len(by_band.frequencies_hz))
    np.testing.assert_allclose(by_band.frequencies_hz, by_count.frequencies_hz)
    assert (
        by_band.frequencies_hz[-1]
        <= 5e3
        < ssss_modes(PLATE, "mindlin", count=len(by_band.frequencies_hz) + 1).frequencies_hz[-1]
    )


def test_leissa_lookup_rotations_and_poisson_ratio():
    nu03 = Plate(material=Material("s", 7850.0, 2.06e11, 0.3))
    np.testing.assert_allclose(leissa_frequencies(nu03, "FCFF"), leissa_frequencies(nu03, "CFFF"))
    assert leissa_frequencies(PLATE, "FFFF") is None  # table is for nu = 0.3, steel has 0.28
    assert leissa_frequencies(PLATE, "CCCC") is not None  # clamped lambda is nu-free
    assert leissa_frequencies(Plate(size_x=0.5), "CCCC") is None  # not square
