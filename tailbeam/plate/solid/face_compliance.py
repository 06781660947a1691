"""A structure's static compliance anywhere on its impact face from one matrix: K^-1 on the
reduced DOFs the face's z-readings touch.

A load of 1 N along +z spread over a disc of the face is f = R^T w (R: the face readings at
the disc's points, ``tailbeam.plate.solid.face_readings``; w: the disc rule's weights), and
every such f lives on the DOFs D of the face's nodes (their z-components, through the
supports' constraint map). So the compliance f^T K^-1 f = f_D^T G f_D with G = (K^-1)_DD,
the same value as the direct solve for any point and disc radius (to round-off; no
interpolation). G takes |D| solves with the stiffness' factorisation, made once in blocks of
right-hand sides (~4 200 on the example beam) and cached on disk; after that a compliance
costs a few microseconds of small dense algebra.
"""

import numpy as np

from tailbeam.physics.contact_patch import disc_rule
from tailbeam.plate.fe.model import check_points
from tailbeam.progress import task

BLOCK = 128  # right-hand sides per solve


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
    """(d,) the reduced DOFs the face readings touch (their nonzero columns)."""
    touched = np.abs(readings.values).max(axis=1) > 0.0  # (f, c)
    return np.unique(readings.columns[touched])


def face_green(model, dofs) -> np.ndarray:
    """(d, d) K^-1 restricted to ``dofs``: |dofs| solves with the stiffness' factorisation
    (``model.solver()``), in blocks of BLOCK right-hand sides, with progress."""
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


__all__ = ["FaceCompliance", "face_dofs", "face_green"]
