"""Clamped, simply supported and free edges (Kirchhoff FE) against Levy's exact solution.

Levy: with two opposite edges simply supported, w = X(x) sin(n pi y'/b) and each frequency
is a root of a 4x4 (or, for equal edges, 2x2) determinant of the edge conditions. Roots are
found independently of the FE code (tailbeam.plate.closed_forms.levy_frequencies), so these
checks pin down the C and F DOF choices to 1e-4, far tighter than Leissa's tables allow.
"""

import numpy as np
import pytest

from tailbeam.physics.bodies import Plate
from tailbeam.plate import compute_modes
from tailbeam.plate.closed_forms import kirchhoff_model_error, levy_frequencies, ssss_modes

PLATE = Plate()
FMAX = 2000.0


def test_levy_solver_reproduces_the_ssss_closed_form():
    np.testing.assert_allclose(
        levy_frequencies(PLATE, "SSSS", FMAX),
        ssss_modes(PLATE, "kirchhoff", fmax_hz=FMAX).frequencies_hz,
        rtol=1e-12,
    )


@pytest.mark.parametrize("boundary", ["CSCS", "FSFS", "CSFS", "SCSF", "FSSS"])
def test_fe_matches_levy(boundary):
    exact = levy_frequencies(PLATE, boundary, FMAX)
    # 12 divisions: measured max error 4e-5 up to 3 kHz on these cases
    basis = compute_modes(
        PLATE, boundary, theory="kirchhoff", fmax_hz=FMAX, divisions=12, use_cache=False
    )
    assert basis.n_modes == len(exact)  # same modes in the band: none missed on either side
    rel = basis.frequencies_hz / exact - 1.0
    assert np.all(rel < 1e-4) and np.all(rel > -1e-9), rel  # conforming: from above


def test_levy_needs_two_opposite_supported_edges():
    assert levy_frequencies(PLATE, "CCCC", FMAX) is None
    assert levy_frequencies(PLATE, "SSFF", FMAX) is None


@pytest.mark.parametrize("boundary", ["CSCS", "FSFS"])
def test_thin_mindlin_plate_tends_to_levy(boundary):
    # Mindlin's C and F edges: for a 1 mm plate the shear/rotary-inertia difference to
    # Kirchhoff is O((k h)^2), estimated by kirchhoff_model_error; edges add effects of the
    # same order, so allow 3x that plus the FE error (1e-4 at 12 divisions)
    thin = Plate(thickness=0.001)
    exact = levy_frequencies(thin, boundary, 300.0)[:10]
    basis = compute_modes(
        thin, boundary, theory="mindlin", count=len(exact), divisions=12, use_cache=False
    )
    tol = 1e-4 + 3.0 * kirchhoff_model_error(thin, exact[-1])
    assert np.max(np.abs(basis.frequencies_hz / exact - 1.0)) < tol
