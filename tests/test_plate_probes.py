"""tailbeam.plate.probes against scikit-fem's own CellBasis.probes (the independent truth)."""

import numpy as np
import pytest
from skfem import Basis, ElementTriArgyris, ElementTriP2, ElementTriP3, ElementTriP4, MeshTri

from tailbeam.plate.probes import PointProbe, _monomial_coefficients

NO_POINTS = (np.zeros((2, 0)), np.zeros(0))


def _mesh():
    # an unstructured-looking mesh: a tensor mesh with its interior nodes moved
    mesh = MeshTri.init_tensor(np.linspace(-0.3, 0.3, 7), np.linspace(-0.3, 0.3, 6))
    p = mesh.p.copy()
    inner = (np.abs(p[0]) < 0.29) & (np.abs(p[1]) < 0.29)
    p[:, inner] += np.random.default_rng(3).uniform(-0.02, 0.02, (2, inner.sum()))
    return MeshTri(p, mesh.t)


def _points(mesh):
    rng = np.random.default_rng(7)
    edges = 0.5 * (mesh.p[:, mesh.facets[0]] + mesh.p[:, mesh.facets[1]]).T
    return np.vstack([rng.uniform(-0.3, 0.3, (60, 2)), mesh.p.T, edges])


@pytest.mark.parametrize("element", [ElementTriP3, ElementTriP4, ElementTriArgyris])
def test_probes_match_skfem(element):
    mesh = _mesh()
    basis = Basis(mesh, element(), quadrature=NO_POINTS)
    probe = PointProbe(basis)
    assert probe.fast == (element is not ElementTriArgyris)
    pts = _points(mesh)
    truth = basis.probes(pts.T).toarray()
    assert np.abs(probe.operator(pts).toarray() - truth).max() < 1e-12
    field = np.random.default_rng(0).normal(size=(basis.N, 4))
    values = probe.values(pts, field)
    assert values.shape == (len(pts), 4)
    assert np.abs(values - truth @ field).max() < 1e-12 * np.abs(field).max() * 30
    one = probe.values(pts[5], field)  # a single point, as the stream solver asks
    assert np.allclose(one[0], values[5], rtol=0, atol=1e-15 * 30 * np.abs(field).max())


def test_fit_refuses_a_degree_too_low():
    # P4's functions are not quadratics: the fit must say so instead of returning a bad basis
    with pytest.raises(ValueError, match="not a degree-2 polynomial basis"):
        _monomial_coefficients(ElementTriP4(), 2)
    assert _monomial_coefficients(ElementTriP2(), 2).shape == (6, 6)
