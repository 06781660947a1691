"""The impact face: the named flat face of a structure where the particles land.

It lies in the plane z = 0 of the mesh coordinates (the plate frame), its outward normal is +z
and the whole structure lies below it (z <= 0). Today's solvers take the plate as a
rectangle centred on the origin (``tailbeam.physics.bodies.Plate``), so the face must also
be one: its bounding rectangle centred on the origin and covered by it. The ``Plate`` it
stands for has the face's sides and the thickness of material straight below its centre.
"""

from dataclasses import dataclass, field

import numpy as np
from skfem import MeshTri

from tailbeam.errors import InputError
from tailbeam.physics.bodies import Plate
from tailbeam.physics.materials import Material
from tailbeam.plate.solid.surface import cyclic_corners, surface_of

FIELD = "plate.impact_face"


@dataclass(frozen=True, eq=False)
class ImpactFace:
    """A checked impact face: its ``plate`` rectangle and a finder of the cell under points
    (x, y) of the face."""

    name: str
    plate: Plate
    facets: np.ndarray
    _triangles: MeshTri
    _triangle_cell: np.ndarray
    _finder: dict = field(default_factory=dict, repr=False)  # built on first use, kept

    def cells_at(self, points) -> np.ndarray:
        """(p,) the cell under each point (p, 2) m of the face (on the face's rectangle)."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        half = 0.5 * np.array([self.plate.size_x, self.plate.size_y]) * (1.0 - 1e-12)
        pts = np.clip(pts, -half, half)  # points exactly on the rim stay inside
        if "finder" not in self._finder:
            self._finder["finder"] = self._triangles.element_finder()
        return self._triangle_cell[self._finder["finder"](pts[:, 0], pts[:, 1])]


def impact_face(vmesh, name: str, material: Material) -> ImpactFace:
    """Check the named face (one-line InputError naming plate.impact_face) and return it."""
    if not isinstance(name, str) or not name:
        raise InputError(FIELD, f"must name a face group of the mesh, got {name!r}")
    facets = vmesh.face(name, FIELD)
    mesh, tol = vmesh.mesh, 1e-9 * vmesh.size
    nodes = np.unique(mesh.facets[:, facets])
    z = mesh.p[2, nodes]
    if np.max(np.abs(z)) > tol:
        raise InputError(
            FIELD,
            f"face {name!r} must be flat in the plane z = 0 of the mesh; its z spans "
            f"[{z.min():.6g}, {z.max():.6g}] m",
        )
    if mesh.p[2].max() > tol:
        raise InputError(
            FIELD,
            f"the structure must lie below its impact face {name!r} (z <= 0); it reaches "
            f"z = {mesh.p[2].max():.6g} m",
        )
    owners = mesh.f2t[0, facets]
    if np.any(mesh.p[2, mesh.t[:, owners]].mean(axis=0) >= 0):
        raise InputError(FIELD, f"face {name!r} must face up (+z), with the structure below")
    tri, tri_cell, area = _face_triangles(mesh, facets, owners)
    plate = _plate(name, mesh.p[:2, nodes], area, material, vmesh)
    return ImpactFace(name, plate, facets, tri, tri_cell)


def _face_triangles(mesh, facets, owners):
    """The face as a planar triangle mesh (quadrilaterals split) with each triangle's cell,
    and the face's area (m^2)."""
    corners = mesh.facets[:, facets]
    if corners.shape[0] == 3:
        tri, cell = corners, owners
    else:
        ordered = cyclic_corners(mesh.p, corners).T
        tri = np.hstack([ordered[[0, 1, 2]], ordered[[0, 2, 3]]])
        cell = np.concatenate([owners, owners])
    used, tri = np.unique(tri, return_inverse=True)
    tri = tri.reshape(3, -1)
    xy = np.ascontiguousarray(mesh.p[:2, used])
    a, b, c = (xy[:, tri[k]] for k in range(3))
    area = 0.5 * np.abs((b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0])
    return MeshTri(xy, tri, validate=False), cell, float(area.sum())


def _plate(name, xy, area, material, vmesh) -> Plate:
    lo, hi = xy.min(axis=1), xy.max(axis=1)
    tol = 1e-9 * vmesh.size
    sides = hi - lo
    if np.any(np.abs(lo + hi) > tol) or abs(area - sides.prod()) > 1e-9 * sides.prod():
        raise InputError(
            FIELD,
            f"face {name!r} must be a full rectangle centred on the origin of x, y; it spans "
            f"x [{lo[0]:.6g}, {hi[0]:.6g}], y [{lo[1]:.6g}, {hi[1]:.6g}] m with area "
            f"{area:.6g} m^2",
        )
    thickness = _depth_below(vmesh.mesh, np.zeros(2))
    return Plate(material=material, size_x=float(sides[0]), size_y=float(sides[1]),
                 thickness=thickness)  # fmt: skip


def _depth_below(mesh, xy) -> float:
    """Thickness of material straight below the point (x, y, 0): where a vertical line
    through it first leaves the solid (the highest boundary face below z = 0)."""
    tri = surface_of(mesh).triangles  # (t, 3, 3)
    a, b, c = tri[:, 0, :2], tri[:, 1, :2], tri[:, 2, :2]
    det = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    ok = np.abs(det) > 1e-14 * np.max(np.abs(det))
    r = xy - a
    s = np.where(ok, (r[:, 0] * (c - a)[:, 1] - r[:, 1] * (c - a)[:, 0]) / np.where(ok, det, 1), -1)
    t = np.where(ok, ((b - a)[:, 0] * r[:, 1] - (b - a)[:, 1] * r[:, 0]) / np.where(ok, det, 1), -1)
    hit = ok & (s >= -1e-12) & (t >= -1e-12) & (s + t <= 1 + 1e-12)
    z = tri[:, 0, 2] + s * (tri[:, 1, 2] - tri[:, 0, 2]) + t * (tri[:, 2, 2] - tri[:, 0, 2])
    below = hit & (z < -1e-9 * float(np.ptp(mesh.p[2])))
    return float(-z[below].max())
