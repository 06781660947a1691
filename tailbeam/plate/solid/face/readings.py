"""Fast readings on a structure's impact face: the z-displacement at points (x, y) as a
small sparse operator on the reduced DOFs, and the modes' values there, vectorised over the
points.

On the flat impact face the trace of each quadratic element is a polynomial in the face
cell's own coordinates that Lagrange interpolation at a few nodes reproduces exactly: the
serendipity hexahedron's (8-node quadrilateral) by the biquadratic interpolation at the
3 x 3 nodes of the facet, the quadratic tetrahedron's (6-node triangle) by the quadratic one
at its 6 nodes. So the probe (``tailbeam.plate.solid.probe``) reads each facet once at those
nodes, and a point's reading is their interpolation: no search of the volume mesh and no
Newton inversion per point. This needs facets that are parallelograms (an affine map from
the facet's coordinates; triangles always, quadrilaterals of grid-like meshes);
``face_readings`` returns None otherwise and the caller keeps the probe.

A point is located through a uniform grid of buckets over the face's rectangle, each listing
the facets whose bounding box meets it.
"""

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from tailbeam.plate.solid.surface import cyclic_corners

INSIDE_TOL = 1e-9  # of the facet's own coordinates
QUAD_NODES = np.array([(s, t) for t in (0.0, 0.5, 1.0) for s in (0.0, 0.5, 1.0)])
TRI_NODES = np.array([(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.5, 0.0), (0.5, 0.5), (0.0, 0.5)])


@dataclass(frozen=True, eq=False)
class FaceReadings:
    """Readings of w (the z-displacement, m) at impact-face points.

    origin, inverse : (f, 2), (f, 2, 2) each facet's affine map's origin and inverse,
        (s, t) = inverse @ (x - origin);
    triangle : whether the facets are triangles (else parallelograms);
    columns : (f, c) reduced DOFs each facet's readings depend on (padded with repeats);
    values : (f, k, c) the readings at each facet's k interpolation nodes on those DOFs;
    buckets : (nx * ny, b) facets meeting each bucket (padded with -1), over the rectangle
        ``lower`` (2,) m with bucket size ``step`` (2,) m and ``counts`` (nx, ny).
    """

    origin: np.ndarray
    inverse: np.ndarray
    triangle: bool
    columns: np.ndarray
    values: np.ndarray
    n_dofs: int
    lower: np.ndarray
    step: np.ndarray
    counts: np.ndarray
    buckets: np.ndarray

    def locate(self, points):
        """(facets (p,), facet coordinates (p, 2)) of points (p, 2) m of the face."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        ij = np.floor((pts - self.lower) / self.step).astype(np.int64)
        ij = np.clip(ij, 0, self.counts - 1)
        cand = self.buckets[ij[:, 0] * self.counts[1] + ij[:, 1]]  # (p, b)
        safe = np.where(cand < 0, 0, cand)
        st = np.einsum("pbij,pbj->pbi", self.inverse[safe], pts[:, None, :] - self.origin[safe])
        outside = np.maximum(-st, 0.0).sum(axis=2) + np.maximum(st - 1.0, 0.0).sum(axis=2)
        if self.triangle:
            outside += np.maximum(st.sum(axis=2) - 1.0, 0.0)
        outside = np.where(cand < 0, np.inf, outside)
        best = np.argmin(outside, axis=1)  # inside (0) or, off by round-off, the nearest
        rows = np.arange(len(pts))
        return cand[rows, best], self._clip(st[rows, best])

    def _clip(self, st):
        st = np.clip(st, 0.0, 1.0)
        if self.triangle:
            over = st.sum(axis=1)
            st = np.where((over > 1.0)[:, None], st / np.maximum(over, 1.0)[:, None], st)
        return st

    def weights(self, st) -> np.ndarray:
        """(p, k) interpolation weights of the facet nodes at facet coordinates (p, 2)."""
        s, t = st[:, 0], st[:, 1]
        if self.triangle:
            a = 1.0 - s - t
            return np.column_stack([a * (2 * a - 1), s * (2 * s - 1), t * (2 * t - 1),
                                    4 * a * s, 4 * s * t, 4 * t * a])  # fmt: skip
        ls, lt = _lagrange3(s), _lagrange3(t)  # (p, 3) each
        return (lt[:, :, None] * ls[:, None, :]).reshape(len(st), 9)

    def operator(self, points) -> sp.csr_matrix:
        """(p, n_dofs) z-displacement (m) at points (p, 2) from reduced vectors."""
        facets, st = self.locate(points)
        rows = np.einsum("pk,pkc->pc", self.weights(st), self.values[facets])
        cols = self.columns[facets]
        p, c = cols.shape
        out = sp.csr_matrix(
            (rows.ravel(), (np.repeat(np.arange(p), c), cols.ravel())), shape=(p, self.n_dofs)
        )
        out.sum_duplicates()
        return out

    def modal(self, vectors) -> "FaceModes":
        """The readings of the columns of ``vectors`` (n_dofs, m): mode shapes on the face."""
        nodal = np.einsum("fkc,fcm->fkm", self.values, np.asarray(vectors)[self.columns])
        return FaceModes(self, np.ascontiguousarray(nodal))


@dataclass(frozen=True, eq=False)
class FaceModes:
    """Mode shapes on the impact face: ``nodal`` (f, k, m), each facet's interpolation
    nodes' modal values (1/sqrt(kg))."""

    readings: FaceReadings
    nodal: np.ndarray

    def __call__(self, points) -> np.ndarray:
        """(p, m) modal z-displacements at points (p, 2) m."""
        facets, st = self.readings.locate(points)
        return np.einsum("pk,pkm->pm", self.readings.weights(st), self.nodal[facets])


def _lagrange3(t) -> np.ndarray:
    """(p, 3) the quadratic Lagrange polynomials of the nodes 0, 1/2, 1 at t (p,)."""
    return np.column_stack([2 * (t - 0.5) * (t - 1.0), -4 * t * (t - 1.0), 2 * t * (t - 0.5)])


def face_readings(model) -> FaceReadings | None:
    """The FaceReadings of a StructureModel's impact face, or None when a facet is not a
    parallelogram (then the probe is the reader)."""
    mesh, facets = model.vmesh.mesh, model.face.facets
    corners = mesh.facets[:, facets]
    triangle = corners.shape[0] == 3
    ordered = corners.T if triangle else cyclic_corners(mesh.p, corners)  # (f, 3 or 4)
    xy = np.transpose(mesh.p[:2, ordered], (1, 2, 0))  # (f, corners, 2)
    origin = xy[:, 0]
    e1 = xy[:, 1] - origin
    e2 = (xy[:, 2] if triangle else xy[:, 3]) - origin
    if not triangle:
        skew = np.abs(xy[:, 2] - origin - e1 - e2).max()
        if skew > 1e-9 * model.vmesh.size:
            return None
    jac = np.stack([e1, e2], axis=2)  # (f, 2, 2): x = origin + jac @ (s, t)
    inverse = np.linalg.inv(jac)
    nodes = TRI_NODES if triangle else QUAD_NODES
    k = len(nodes)
    pts = (origin[:, None, :] + np.einsum("fij,kj->fki", jac, nodes)).reshape(-1, 2)
    xyz = np.column_stack([pts, np.zeros(len(pts))])
    owners = np.repeat(mesh.f2t[0, facets], k)
    dirs = np.tile([0.0, 0.0, 1.0], (len(pts), 1))
    op = (model.probe().operator(xyz, owners, dirs) @ model.transform).tocsr()
    columns, values = _facet_blocks(op, len(facets), k)
    lower, step, counts, buckets = _buckets(xy, model.plate)
    return FaceReadings(origin, inverse, triangle, columns, values, op.shape[1], lower, step,
                        counts, buckets)  # fmt: skip


def _facet_blocks(op: sp.csr_matrix, n_facets: int, k: int):
    """Each facet's DOFs (f, c) and its k rows' values on them (f, k, c), dense."""
    blocks = [op[i * k : (i + 1) * k] for i in range(n_facets)]
    used = [np.unique(b.indices) for b in blocks]
    width = max(len(u) for u in used)
    columns = np.zeros((n_facets, width), dtype=np.int64)
    values = np.zeros((n_facets, k, width))
    for i, (b, u) in enumerate(zip(blocks, used, strict=True)):
        columns[i, : len(u)] = u
        columns[i, len(u) :] = u[0]  # padding: a repeated DOF with zero values
        values[i, :, : len(u)] = b[:, u].toarray()
    return columns, values


def _buckets(xy, plate):
    """A uniform grid over the face's rectangle, each cell listing the facets it meets."""
    half = 0.5 * np.array([plate.size_x, plate.size_y])
    lower = -half
    n = max(1, int(np.sqrt(len(xy))))
    counts = np.array([n, n], dtype=np.int64)
    step = 2.0 * half / counts
    pad = 1e-9 * step
    lo = np.clip(np.floor((xy.min(axis=1) - pad - lower) / step).astype(int), 0, counts - 1)
    hi = np.clip(np.floor((xy.max(axis=1) + pad - lower) / step).astype(int), 0, counts - 1)
    lists = [[] for _ in range(n * n)]
    for f, (a, b) in enumerate(zip(lo, hi, strict=True)):
        for i in range(a[0], b[0] + 1):
            for j in range(a[1], b[1] + 1):
                lists[i * n + j].append(f)
    width = max(len(x) for x in lists)
    buckets = np.full((n * n, width), -1, dtype=np.int64)
    for i, x in enumerate(lists):
        buckets[i, : len(x)] = x
    return lower, step, counts, buckets


__all__ = ["FaceModes", "FaceReadings", "face_readings"]
