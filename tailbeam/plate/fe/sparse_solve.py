"""Sparse symmetric solves and the generalised eigenproblem K phi = omega^2 M phi.

Both go through one factorisation: SuperLU with the symmetric minimum-degree ordering
(MMD on A + A^T) and diagonal pivots only (the matrices are symmetric positive definite after
the shift). On these plate matrices that has half the fill of SuperLU's default COLAMD
ordering or of reverse Cuthill-McKee, and solves 2-4x faster, which is most of the
shift-invert Lanczos iteration's cost (scipy eigsh, ARPACK). The same
factorisation of K - value M counts the eigenvalues below ``value`` (Sylvester's inertia),
an eigensolver-independent check that no mode in a band was missed.
"""

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from tailbeam.errors import InputError, WorkLimitError

DENSE_LIMIT = 800  # below this many DOFs a dense eigensolver is faster and simpler
# Ritz-value tolerance (ARPACK's default is machine precision): measured on the 10 kHz default
# plate, 249 instead of 290 shift-invert solves with eigenvalues equal to 1e-13
ARPACK_TOL = 1e-10


class SymmetricSolver:
    """Factorisation of a sparse symmetric matrix A (n x n): SuperLU with a symmetric
    minimum-degree ordering (on A + A^T) and diagonal pivots only (A positive definite, or a
    shifted K - value M for counting), so the factorisation is LDL^T-like and
    ``negative_pivots`` is A's inertia (Sylvester)."""

    def __init__(self, matrix):
        a = sp.csc_matrix(matrix)
        self.n = a.shape[0]
        try:
            self._lu = spla.splu(
                a,
                permc_spec="MMD_AT_PLUS_A",
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
        except RuntimeError as err:  # exactly singular: the plate can move as a rigid body
            raise InputError(
                "boundary", f"the stiffness matrix is singular ({err}); the plate is not held"
            ) from None

    def solve(self, rhs) -> np.ndarray:
        """A^-1 rhs for (n,) or (n, k) right-hand sides."""
        return self._lu.solve(np.asarray(rhs, dtype=float))

    def negative_pivots(self) -> int:
        """Number of negative eigenvalues of A (valid only for a symmetric permutation)."""
        if np.any(self._lu.perm_r != self._lu.perm_c):
            raise WorkLimitError("the factorisation pivoted; the inertia count is not reliable")
        return int(np.count_nonzero(self._lu.U.diagonal() < 0.0))


def lowest_modes(stiffness, mass, count: int, *, shift: float, on_solve=None, factorize=None):
    """The ``count`` smallest eigenpairs of K phi = lambda M phi (lambda = omega^2, rad^2/s^2).

    shift: a value below the smallest eigenvalue (negative when there are rigid-body
    modes), so that K - shift M is positive definite. on_solve: called with 1 after each
    shift-invert solve (progress). factorize: the factorisation class (default
    SymmetricSolver; a solid structure passes its nested-dissection one). Returns
    (lambda (count,), phi (n, count)) with phi^T M phi = I, sorted by lambda.
    """
    n = stiffness.shape[0]
    if count < 1:
        raise ValueError("count must be >= 1")
    if count > n:
        raise WorkLimitError(
            f"{count} modes requested but the model has only {n} DOFs; refine the mesh "
            "(larger divisions) or ask for fewer modes"
        )
    if n > DENSE_LIMIT and count >= n - 1:
        raise WorkLimitError(
            f"{count} modes of a {n}-DOF model is the whole spectrum; ask for fewer modes"
        )
    if n <= DENSE_LIMIT:
        lam, phi = sla.eigh(stiffness.toarray(), mass.toarray(), subset_by_index=[0, count - 1])
    else:
        solver = (factorize or SymmetricSolver)(stiffness - shift * mass)
        lam, phi = _eigsh(stiffness, mass, count, shift, solver, on_solve)
    return _unit_modal_mass(lam, phi, mass)


def count_eigenvalues_below(stiffness, mass, value: float, factorize=None) -> int:
    """How many eigenvalues of K phi = lambda M phi lie below ``value`` (rad^2/s^2), by
    Sylvester's law of inertia: the number of negative pivots of an LDL^T-type
    factorisation of K - value M (SuperLU without pivoting keeps it symmetric). Independent
    of the eigensolver, so it catches modes the Lanczos iteration might miss."""
    return (factorize or SymmetricSolver)(stiffness - value * mass).negative_pivots()


def _eigsh(stiffness, mass, count, sigma, solver, on_solve=None):
    n = stiffness.shape[0]

    def matvec(x):
        if on_solve is not None:
            on_solve(1)
        return solver.solve(x)

    op = spla.LinearOperator((n, n), matvec=matvec, dtype=float)
    # 1.5 count + 20 Lanczos vectors: measured fastest here (2 count + 1 is scipy's default)
    ncv = min(n, max(int(1.5 * count) + 20, 2 * count + 1 if count < 20 else 0))
    try:
        return spla.eigsh(
            stiffness,
            k=count,
            M=mass,
            sigma=sigma,
            which="LM",
            OPinv=op,
            ncv=ncv,
            tol=ARPACK_TOL,
            maxiter=50 * n,
        )
    except spla.ArpackNoConvergence as err:
        raise WorkLimitError(
            f"the eigen-solver (ARPACK) did not converge for {count} modes of {n} DOFs "
            f"({err}); ask for fewer modes or use a coarser mesh"
        ) from None


def _unit_modal_mass(lam, phi, mass):
    order = np.argsort(lam)
    lam, phi = lam[order], phi[:, order]
    # enforce unit modal mass exactly (ARPACK returns M-orthonormal vectors up to roundoff)
    modal_mass = np.einsum("ij,ij->j", phi, mass @ phi)
    return lam, phi / np.sqrt(modal_mass)
