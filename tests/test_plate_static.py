"""Static compliance of the FE models against the Navier series (SSSS)."""

import numpy as np
import pytest

from tailbeam.physics.bodies import Plate
from tailbeam.plate import assemble_plate, compute_modes
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis, ssss_static_compliance

PLATE = Plate()
POINTS = np.array([[0.0, 0.0], [0.1, -0.15]])


@pytest.mark.parametrize("theory, radius", [("kirchhoff", 0.0), ("mindlin", 0.02)])
def test_static_compliance_matches_navier_series(theory, radius):
    ref = ssss_static_compliance(PLATE, POINTS, radius, theory)
    got = assemble_plate(PLATE, "SSSS", theory=theory, divisions=12).static_compliance(
        POINTS, radius
    )
    rel = got / ref - 1.0
    # conforming FE is too stiff (compliance from below); measured error 3e-4 .. 6e-4
    assert np.all(rel < 1e-5) and np.all(rel > -1e-3), rel


def test_navier_series_agrees_with_modal_module():
    # the independent Kirchhoff point-load series (tailbeam.plate.closed_forms)
    ref = ssss_kirchhoff_basis(PLATE, 1000.0).static_compliance_at(POINTS, 0.0)
    np.testing.assert_allclose(
        ssss_static_compliance(PLATE, POINTS, 0.0, "kirchhoff"), ref, rtol=1e-5
    )


def test_basis_residual_compliance_is_positive_and_shrinks(tmp_path):
    basis = compute_modes(
        PLATE, "SSSS", theory="kirchhoff", fmax_hz=3000.0, divisions=8, cache_dir=tmp_path
    )
    full = basis.static_compliance_at(POINTS, 0.0)
    res_all = basis.residual_compliance(POINTS, 0.0)
    res_few = basis.truncated(count=5).residual_compliance(POINTS, 0.0)
    assert np.all(res_all > 0) and np.all(res_all < res_few) and np.all(res_few < full)


def test_load_vector_is_a_unit_force():
    model = assemble_plate(PLATE, "FFFF", theory="mindlin", divisions=4)
    # rigid heave w = 1 everywhere: its work with a unit load is 1 N x 1 m, wherever and
    # however wide the load (the disc is clipped at the edge and renormalised)
    heave = np.zeros(model.n_full)
    heave[: model.deflection_basis.N] = 1.0
    for point, radius in (((0.0, 0.0), 0.0), ((0.1, 0.2), 0.03), ((0.3, 0.3), 0.05)):
        f = model.load_vector(point, radius)
        assert f @ heave[model.free_dofs] == pytest.approx(1.0, rel=1e-12)


def test_point_load_equals_skfem_point_source():
    model = assemble_plate(PLATE, "SSSS", theory="kirchhoff", divisions=4)
    point = np.array([0.07, -0.11])
    ours = model.load_vector(point, 0.0)
    theirs = model.deflection_basis.point_source(point)[model.free_dofs]
    np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-14)
