"""Sparse symmetric factorisation for solid structures: SuperLU after a nested-dissection
ordering from METIS (``pymetis``, in the ``mesh`` extra).

A volume mesh's matrices are three-dimensional graphs, where the minimum-degree ordering the
flat plate uses (``tailbeam.plate.fe.sparse_solve.SymmetricSolver``) fills badly: on the
example tail beam (81 640 DOFs) SuperLU's MMD gave 100 M factor entries, 84 s to factorise
and 0.44 s a solve; METIS's nested dissection 75 M entries, 4 s to order plus 17 s to
factorise and 0.13 s a solve (2 shared cores, loaded). Without pymetis the MMD solver is used
(and said once on stderr).
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.plate.fe.sparse_solve import SymmetricSolver
from tailbeam.progress import note

_SAID = {"fallback": False}


def nested_dissection(matrix) -> np.ndarray | None:
    """A fill-reducing symmetric permutation of ``matrix`` (METIS NodeND on its graph), or
    None without pymetis."""
    try:
        import pymetis
    except ImportError:
        if not _SAID["fallback"]:
            note("pymetis is not installed (pip install tailbeam[mesh]): the solid's "
                 "factorisations use SuperLU's minimum degree, several times slower")  # fmt: skip
            _SAID["fallback"] = True
        return None
    graph = sp.csr_matrix(matrix, copy=True)
    graph.setdiag(0)
    graph.eliminate_zeros()
    adjacency = pymetis.CSRAdjacency(graph.indptr, graph.indices)
    perm, _ = pymetis.nested_dissection(adjacency)
    return np.asarray(perm, dtype=np.int64)


def factorize(matrix):
    """An OrderedSolver of ``matrix``, or SymmetricSolver without pymetis."""
    perm = nested_dissection(matrix)
    return SymmetricSolver(matrix) if perm is None else OrderedSolver(matrix, perm)


class OrderedSolver:
    """Factorisation of a symmetric matrix A in the order ``perm``: SuperLU of P A P^T with
    the natural order and diagonal pivots only (LDL^T-like), so ``negative_pivots`` counts
    A's negative eigenvalues (Sylvester). The interface of SymmetricSolver: ``solve``,
    ``negative_pivots``."""

    def __init__(self, matrix, perm):
        a = sp.csr_matrix(matrix)
        self.n = a.shape[0]
        self._perm = np.asarray(perm, dtype=np.int64)
        b = sp.csc_matrix(a[self._perm][:, self._perm])
        try:
            self._lu = spla.splu(b, permc_spec="NATURAL", diag_pivot_thresh=0.0,
                                 options={"SymmetricMode": True})  # fmt: skip
        except RuntimeError as err:  # exactly singular: the structure can move rigidly
            raise InputError(
                "plate.supports", f"the stiffness matrix is singular ({err}); it is not held"
            ) from None

    def solve(self, rhs) -> np.ndarray:
        """A^-1 rhs for (n,) or (n, k) right-hand sides."""
        rhs = np.asarray(rhs, dtype=float)
        out = np.empty_like(rhs)
        out[self._perm] = self._lu.solve(rhs[self._perm])
        return out

    def negative_pivots(self) -> int:
        """Number of negative eigenvalues of A."""
        if np.any(self._lu.perm_r != self._lu.perm_c):
            raise WorkLimitError("the factorisation pivoted; the inertia count is not reliable")
        return int(np.count_nonzero(self._lu.U.diagonal() < 0.0))
