"""Displacement of a solid at points of known cells, along given directions, as a sparse
operator on the displacement DOFs.

The reference coordinates of each point come from scikit-fem's own inverse mapping of its
cell (``mapping.invF``: exact for tetrahedra, Newton's method for hexahedra); the values of
the element's Lagrange basis functions there from the scalar element itself (``lbasis``), so
this module holds no shape function of its own.
"""

import numpy as np
import scipy.sparse as sp


class DisplacementProbe:
    """Readings of a vector ``basis`` (three components) at points of known cells; the
    scalar element and the component DOF numbers are taken from the basis once."""

    def __init__(self, basis):
        self.basis = basis
        self.scalar = basis.split_bases()[0]  # builds a whole Basis: once, not per reading
        self.indices = basis.split_indices()

    def operator(self, points, cells, directions) -> sp.csr_matrix:
        """(p, N) sparse matrix: u(point) . direction from a DOF vector of the basis.

        Parameters
        ----------
        points : (p, 3) m, each inside or on the boundary of its cell
        cells : (p,) cell index of each point
        directions : (p, 3) the direction of each reading (the reading scales with its length)
        """
        points = np.atleast_2d(np.asarray(points, dtype=float))
        cells = np.asarray(cells, dtype=np.int64)
        directions = np.atleast_2d(np.asarray(directions, dtype=float))
        elem, nb = self.scalar.elem, self.scalar.Nbfun
        local = self.basis.mapping.invF(points.T[:, :, None], tind=cells)[:, :, 0]  # (3, p)
        local = np.clip(local, 0.0, 1.0)  # the reference cells lie in [0, 1]^3: round-off in
        values = np.array([elem.lbasis(local, i)[0] for i in range(nb)])  # (nb, p)
        rows, cols, vals = [], [], []
        for c, idx in enumerate(self.indices):
            dofs = idx[self.scalar.element_dofs[:, cells]]  # (nb, p)
            rows.append(np.broadcast_to(np.arange(len(cells)), dofs.shape).ravel())
            cols.append(dofs.ravel())
            vals.append((values * directions[:, c]).ravel())
        shape = (len(cells), self.basis.N)
        return sp.csr_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=shape
        )
