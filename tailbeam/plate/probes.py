"""Fast point probes of the plate's deflection field: the values of its basis functions at
points, for one point at a time as the stream solver asks for them.

``skfem.CellBasis.probes`` evaluates every local basis function in its own Python call (15
calls for the P4 deflection of the Mindlin plate, ~0.5 ms a point), which made mode-shape
lookups a third of a 1000-particle stream's run. For the affine Lagrange elements of the Mindlin
deflection (P3, P4) every local basis function is a polynomial of degree p in the reference
coordinates, so all of them are one product: monomials (n, q) @ coefficients (q, nbfun).
The coefficients are read from the element itself (its ``lbasis`` sampled at points of the
reference triangle, a least-squares fit checked to round-off), so this module holds no shape
function of its own. The element containing a point is found by scikit-fem's own finder
(``MeshTri.element_finder``), kept for the mesh instead of rebuilt per call.

Other elements (Argyris, whose basis is not affine-equivalent) keep ``CellBasis.probes``.
``tests/test_plate_probes.py`` checks both against ``CellBasis.probes`` at random points,
vertices and edges.
"""

import numpy as np
import scipy.sparse as sp
from skfem import ElementTriP3, ElementTriP4

FIT_TOLERANCE = 1e-11  # max |fit - lbasis| on the sample points (the element's values are O(1))
_LAGRANGE = (ElementTriP3, ElementTriP4)


class PointProbe:
    """Values of the basis functions of ``basis`` (a ``skfem.CellBasis`` on a ``MeshTri``) at
    points: ``weights(points)`` -> (cells (p,), values (p, nbfun)), ``operator(points)`` ->
    the (p, N) sparse matrix of ``CellBasis.probes``, ``values(points, field)`` -> field's
    values (p, ...) at the points for a field (N, ...) on the basis' DOFs."""

    def __init__(self, basis):
        self.basis = basis
        self.fast = type(basis.elem) in _LAGRANGE
        if self.fast:
            self._degree = basis.elem.maxdeg
            self._coef = _monomial_coefficients(basis.elem, self._degree)
            self._finder = basis.mesh.element_finder(mapping=basis.mapping)

    def weights(self, points) -> tuple[np.ndarray, np.ndarray]:
        """(cells (p,), basis function values (p, nbfun)) at points (p, 2) m."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        cells = np.asarray(self._finder(pts[:, 0], pts[:, 1]), dtype=np.int64)
        mapping = self.basis.mapping
        local = np.einsum("ijp,pj->pi", mapping.invA[:, :, cells], pts - mapping.b[:, cells].T)
        return cells, _monomials(local, self._degree) @ self._coef

    def operator(self, points) -> sp.csr_matrix:
        """(p, N) sparse matrix: values at points (p, 2) of fields on the basis' DOFs."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        if not self.fast:
            return self.basis.probes(pts.T).tocsr()
        cells, vals = self.weights(pts)
        dofs = self.basis.element_dofs[:, cells].T  # (p, nbfun)
        rows = np.repeat(np.arange(len(pts)), dofs.shape[1])
        shape = (len(pts), self.basis.N)
        return sp.csr_matrix((vals.ravel(), (rows, dofs.ravel())), shape=shape)

    def values(self, points, field) -> np.ndarray:
        """field (N, ...) (the basis' DOFs first) at points (p, 2): (p, ...)."""
        if not self.fast:
            return np.asarray(self.operator(points) @ field[: self.basis.N])
        cells, vals = self.weights(points)
        dofs = self.basis.element_dofs[:, cells]  # (nbfun, p)
        return np.einsum("pi,ip...->p...", vals, field[dofs])


def _monomial_exponents(degree: int) -> list[tuple[int, int]]:
    return [(a, t - a) for t in range(degree + 1) for a in range(t, -1, -1)]


def _monomials(local: np.ndarray, degree: int) -> np.ndarray:
    """(p, q) monomials xi^a eta^b, a + b <= degree, of reference points local (p, 2)."""
    xi, eta = local[:, 0:1], local[:, 1:2]
    exps = np.array(_monomial_exponents(degree)).T
    return xi ** exps[0] * eta ** exps[1]


def _monomial_coefficients(elem, degree: int) -> np.ndarray:
    """(q, nbfun) coefficients of the element's local basis functions in the monomials of
    ``_monomials``, fitted to its ``lbasis`` on a lattice of the reference triangle (twice as
    many points as monomials); a fit worse than FIT_TOLERANCE raises (not a polynomial basis
    of that degree)."""
    n = 3 * degree + 1
    lattice = np.array([(i / n, j / n) for i in range(n + 1) for j in range(n + 1 - i)])
    X = lattice.T
    values = np.column_stack([elem.lbasis(X, k)[0] for k in range(elem.doflocs.shape[0])])
    mono = _monomials(lattice, degree)
    coef, *_ = np.linalg.lstsq(mono, values, rcond=None)
    misfit = float(np.max(np.abs(mono @ coef - values)))
    if misfit > FIT_TOLERANCE:
        raise ValueError(f"{type(elem).__name__}: not a degree-{degree} polynomial basis "
                         f"(fit off by {misfit:.1e})")  # fmt: skip
    return coef
