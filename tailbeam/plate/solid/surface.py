"""The structure's outer surface: which boundary face a 3D point lies on.

The boundary facets (triangles; quadrilaterals split in two) are searched for the closest
point to each query point (the standard closest point on a triangle: the projection on its
plane when that falls inside, else the nearest point of its edges). A point farther than
``SURFACE_TOLERANCE`` times the structure's size from every facet is not on the surface.
"""

from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError

SURFACE_TOLERANCE = 1e-3  # of the bounding-box diagonal: 2 mm on a 2 m beam


@dataclass(frozen=True, eq=False)
class Surface:
    """Boundary triangles (t, 3, 3) m and the cell each belongs to (t,)."""

    triangles: np.ndarray
    cells: np.ndarray
    size: float

    def locate(self, points, field: str):
        """(closest surface points (p, 3), their cells (p,), outward normals (p, 3)); an
        InputError naming ``field`` for a point off the surface."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        out, cells, normals = [], [], []
        for point in points:
            closest, distance = _closest_points(self.triangles, point)
            best = int(np.argmin(distance))
            if distance[best] > SURFACE_TOLERANCE * self.size:
                where = ", ".join(f"{v:.6g}" for v in point)
                raise InputError(
                    field,
                    f"point ({where}) m is not on the structure's surface (nearest surface "
                    f"point {distance[best]:.3g} m away)",
                )
            out.append(closest[best])
            cells.append(self.cells[best])
            normals.append(_normal(self.triangles[best]))
        return np.array(out), np.array(cells, dtype=np.int64), np.array(normals)


def surface_of(mesh) -> Surface:
    """The outer surface of an skfem volume mesh, with outward normals."""
    facets = mesh.boundary_facets()
    cells = mesh.f2t[0, facets]
    corners = mesh.facets[:, facets]
    tris, owners = [], []
    if corners.shape[0] == 3:
        tris.append(corners.T)
        owners.append(cells)
    else:
        ordered = cyclic_corners(mesh.p, corners)
        tris += [ordered[:, [0, 1, 2]], ordered[:, [0, 2, 3]]]
        owners += [cells, cells]
    tri = np.vstack(tris)
    owner = np.concatenate(owners)
    xyz = np.transpose(mesh.p[:, tri], (1, 2, 0))  # (t, 3 corners, 3 coords)
    # orient outward: away from the owning cell's centroid
    centroid = mesh.p[:, mesh.t[:, owner]].mean(axis=1).T
    normal = np.cross(xyz[:, 1] - xyz[:, 0], xyz[:, 2] - xyz[:, 0])
    flip = np.einsum("ij,ij->i", normal, xyz[:, 0] - centroid) < 0
    xyz[flip] = xyz[flip][:, [0, 2, 1]]
    size = float(np.linalg.norm(np.ptp(mesh.p, axis=1)))
    return Surface(xyz, owner, size)


def cyclic_corners(p, corners) -> np.ndarray:
    """(f, 4) quadrilateral corners in cyclic order (by angle about their centroid)."""
    xyz = p[:, corners]  # (3, 4, f)
    center = xyz.mean(axis=1, keepdims=True)
    e1 = xyz[:, 0] - center[:, 0]
    normal = np.cross((xyz[:, 1] - xyz[:, 0]).T, (xyz[:, 2] - xyz[:, 0]).T).T
    e2 = np.cross(normal.T, e1.T).T  # in the face's plane, normal to e1
    rel = xyz - center
    angle = np.arctan2(np.einsum("ikf,if->kf", rel, e2), np.einsum("ikf,if->kf", rel, e1))
    order = np.argsort(angle, axis=0)
    return np.take_along_axis(corners, order, axis=0).T


def _normal(tri) -> np.ndarray:
    n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    return n / np.linalg.norm(n)


def _closest_points(tri, point):
    """Closest point on each triangle (t, 3) and its distance (t,) to ``point`` (3,)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    n2 = np.einsum("ij,ij->i", n, n)
    proj = point - (np.einsum("ij,ij->i", point - a, n) / n2)[:, None] * n
    # barycentric signs of the projection
    inside = np.ones(len(tri), dtype=bool)
    for p, q in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(q - p, proj - p), n) >= 0
    best = np.where(inside[:, None], proj, 0.0)
    dist = np.where(inside, np.linalg.norm(proj - point, axis=1), np.inf)
    for p, q in ((a, b), (b, c), (c, a)):
        d = q - p
        s = np.clip(np.einsum("ij,ij->i", point - p, d) / np.einsum("ij,ij->i", d, d), 0, 1)
        on_edge = p + s[:, None] * d
        de = np.linalg.norm(on_edge - point, axis=1)
        closer = de < dist
        best[closer], dist[closer] = on_edge[closer], de[closer]
    return best, dist
