"""A structure's static compliance anywhere on its impact face from one matrix: K^-1 on the
reduced DOFs the face's z-readings touch.

A load of 1 N along +z spread over a disc of the face is f = R^T w (R: the face readings at
the disc's points, ``tailbeam.plate.solid.face.readings``; w: the disc rule's weights), and
every such f lives on the DOFs D of the face's nodes (their z-components, through the
supports' constraint map). So the compliance f^T K^-1 f = f_D^T G f_D with G = (K^-1)_DD,
the same value as the direct solve for any point and disc radius (to round-off; no
interpolation). G is the inverse of K's Schur complement on D: one sparse factorisation of K
ordered with D last gives it as the product of the factors' trailing blocks, inverted
densely (|D| = 4 160 on the example beam: 35 s of CPU, 3.4 GB peak); it is cached on
disk, and after that a compliance costs tens of microseconds of small dense algebra.
"""

import numpy as np
import scipy.sparse as sp
from scipy.linalg import lapack

from tailbeam.errors import WorkLimitError
from tailbeam.physics.contact_patch import disc_rule
from tailbeam.plate.fe.model import check_points
from tailbeam.plate.solid.factor import OrderedSolver, nested_dissection
from tailbeam.progress import task

BLOCK = 128  # right-hand sides per solve
ROUND_OFF = 1e-12  # of the largest reading: smaller entries are round-off


class FaceCompliance:
    """Static compliance (m/N) on the impact face of ``model`` (a StructureModel) with its
    ``readings`` (FaceReadings); ``dofs`` (d,) and ``green`` (d, d) as from ``face_green``."""

    def __init__(self, model, readings, dofs, green):
        self.plate = model.plate
        self.readings = readings
        self.dofs = np.asarray(dofs, dtype=np.int64)
        self.green = np.asarray(green, dtype=float)
        self.position = np.full(readings.n_dofs, -1, dtype=np.int64)
        self.position[self.dofs] = np.arange(len(self.dofs))

    def __call__(self, points, contact_radius: float = 0.0) -> np.ndarray:
        """(p,) mean z-deflection (m/N) over the disc under 1 N spread over it."""
        pts = check_points(self.plate, points)
        return np.array([self._one(p, float(contact_radius)) for p in pts])

    def _one(self, centre, radius: float) -> float:
        pts, weights = disc_rule(self.plate, centre, radius)
        facets, st = self.readings.locate(pts)
        rows = np.einsum("pk,pkc->pc", self.readings.weights(st), self.readings.values[facets])
        cols = self.position[self.readings.columns[facets]]
        keep = cols >= 0  # the padding and round-off entries off the face's DOFs: zero
        used, where = np.unique(cols[keep], return_inverse=True)
        load = np.bincount(where, weights=(weights[:, None] * rows)[keep], minlength=len(used))
        return float(load @ self.green[np.ix_(used, used)] @ load)


def face_dofs(readings) -> np.ndarray:
    """(d,) the reduced DOFs the face readings depend on: those with a value above
    ROUND_OFF of the largest (a DOF reached by round-off only, such as a hinge's rotation
    through nodes on its axis, is left out: its entries are zeros up to round-off)."""
    size = np.abs(readings.values).max(axis=1)  # (f, c)
    return np.unique(readings.columns[size > ROUND_OFF * size.max()])


def face_green(model, dofs) -> np.ndarray:
    """(d, d) K^-1 restricted to ``dofs``: the inverse of K's Schur complement on them
    (``schur_green``), or without pymetis |dofs| solves with the stiffness' factorisation
    (``solved_green``)."""
    stiffness = sp.csr_matrix(model.stiffness)
    inner = np.setdiff1d(np.arange(stiffness.shape[0]), dofs)
    order = nested_dissection(stiffness[inner][:, inner])
    if order is None:
        return solved_green(model, dofs)
    return schur_green(stiffness, inner[order], dofs)


def schur_green(stiffness, inner, dofs) -> np.ndarray:
    """(d, d) K^-1 on ``dofs`` from one factorisation of K ordered ``inner`` (a fill-reducing
    order of the other DOFs) then ``dofs``: with K = L U so ordered, the Schur complement of
    the inner block is S = L_dd U_dd (the factors' trailing blocks), and (K^-1)_dd = S^-1 =
    U_dd^-1 L_dd^-1 (two dense triangular inverses).

    Memory: the factorisation is dropped once its trailing blocks are copied out, and the
    dense algebra works in place (the inverses overwrite the blocks), so the peak is the
    factor with a copy of one of its triangles, or three d x d arrays after it."""
    n, d = stiffness.shape[0], len(dofs)
    with task("face compliance", total=3, unit="steps") as bar:
        lower, upper, tail = _trailing_blocks(stiffness, np.concatenate([inner, dofs]), d)
        bar.update(2)
        lower, info_l = lapack.dtrtri(lower, lower=1, overwrite_c=1)
        upper, info_u = lapack.dtrtri(upper, lower=0, overwrite_c=1)
        if info_l or info_u:
            raise WorkLimitError("the face's Schur complement is singular")
        green = upper @ lower  # in the order tail - (n - d) of the factor's columns
        del lower, upper
        bar.update(1)
    back = np.argsort(tail - (n - d))
    green = green[np.ix_(back, back)]
    green += green.T  # numpy buffers the overlapping transpose: (G + G^T) exactly
    green *= 0.5
    return green


def _trailing_blocks(stiffness, order, d):
    """(L_dd, U_dd) dense (d, d), Fortran order, and the factor's last d column indices of
    the factorisation of ``stiffness`` in ``order``; the factorisation is freed on return."""
    n = stiffness.shape[0]
    lu = OrderedSolver(stiffness, order)._lu
    tail = lu.perm_c[n - d :]
    if not np.array_equal(np.sort(tail), np.arange(n - d, n)):
        raise WorkLimitError("the factorisation moved the face's DOFs out of the last block")
    lower = np.asfortranarray(lu.L[n - d :, n - d :].toarray())
    upper = np.asfortranarray(lu.U[n - d :, n - d :].toarray())
    return lower, upper, tail


def solved_green(model, dofs) -> np.ndarray:
    """(d, d) K^-1 on ``dofs`` by |dofs| solves with ``model.solver()``, in blocks of BLOCK
    right-hand sides, with progress."""
    solver = model.solver()
    n, d = model.n_dofs, len(dofs)
    green = np.empty((d, d))
    with task("face compliance", total=d, unit="solves") as bar:
        for start in range(0, d, BLOCK):
            stop = min(start + BLOCK, d)
            rhs = np.zeros((n, stop - start))
            rhs[dofs[start:stop], np.arange(stop - start)] = 1.0
            green[:, start:stop] = solver.solve(rhs)[dofs]
            bar.update(stop - start)
    return 0.5 * (green + green.T)  # symmetric up to the solves' round-off


__all__ = ["FaceCompliance", "face_dofs", "face_green", "schur_green", "solved_green"]
