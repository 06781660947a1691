"""A structure's volume mesh read from a file (meshio; Gmsh first) with its named groups.

The volume cells are tetrahedra or hexahedra (first or second order: only the corner nodes
are kept, so the geometry is straight-sided and the elements' own quadratic fields come from
``tailbeam.plate.solid.elasticity``). Gmsh physical groups become named groups: a physical
surface names a set of boundary faces (``faces``), a physical volume a set of cells
(``volumes``). Coordinates are the plate frame in m (z = 0 on the impact face, z < 0 below).
"""

import contextlib
import io
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from skfem import MeshHex, MeshTet

from tailbeam.errors import InputError

# meshio cell type -> (the linear cell it is reduced to, its corner count, the face type)
_VOLUME_CELLS = {
    "tetra": ("tetra", 4),
    "tetra10": ("tetra", 4),
    "hexahedron": ("hexahedron", 8),
    "hexahedron20": ("hexahedron", 8),
    "hexahedron27": ("hexahedron", 8),
}
_FACE_CELLS = {"triangle": 3, "triangle6": 3, "quad": 4, "quad8": 4, "quad9": 4}


@dataclass(frozen=True, eq=False)
class VolumeMesh:
    """A volume mesh with named groups.

    Parameters
    ----------
    mesh : skfem.MeshTet or skfem.MeshHex
        The linear cells; coordinates in m.
    faces : dict
        Group name -> indices of boundary facets of ``mesh`` (``mesh.facets`` columns).
    volumes : dict
        Group name -> indices of cells of ``mesh``.
    source : str
        Where the mesh came from (a path, or a description).
    """

    mesh: MeshTet | MeshHex
    faces: dict = field(default_factory=dict)
    volumes: dict = field(default_factory=dict)
    source: str = "in memory"

    @property
    def kind(self) -> str:
        """'tetra' or 'hexahedron'."""
        return "tetra" if isinstance(self.mesh, MeshTet) else "hexahedron"

    @property
    def size(self) -> float:
        """Diagonal of the bounding box (m)."""
        return float(np.linalg.norm(np.ptp(self.mesh.p, axis=1)))

    def face(self, name: str, field_name: str) -> np.ndarray:
        """Facet indices of the named face group, else InputError naming ``field_name``."""
        if name not in self.faces:
            known = ", ".join(sorted(self.faces)) or "none"
            raise InputError(
                field_name, f"the mesh has no face group {name!r} (its face groups: {known})"
            )
        return self.faces[name]


def _read_meshio(path: Path, field_name: str):
    import meshio  # 0.3-0.5 s of import: only where a mesh file is read

    if not path.is_file():
        raise InputError(field_name, f"mesh file {str(path)!r} does not exist")
    said = io.StringIO()
    try:
        # meshio prints to stderr and may call sys.exit on files it cannot read: catch both
        with contextlib.redirect_stderr(said), contextlib.redirect_stdout(said):
            fmt = "gmsh" if path.suffix == ".msh" else None
            return meshio.read(path, file_format=fmt)
    except (Exception, SystemExit) as err:  # meshio raises many types for unreadable files
        why = " ".join(said.getvalue().split()) or str(err) or type(err).__name__
        raise InputError(field_name, f"cannot read mesh file {str(path)!r}: {why}") from None


def _group_names(raw) -> dict:
    """Gmsh physical tag -> (name, dimension) from meshio's field_data."""
    out = {}
    for name, value in (raw.field_data or {}).items():
        value = np.asarray(value).ravel()
        if len(value) >= 2:
            out[int(value[0]), int(value[1])] = name
    return out


def _physical(raw, index: int):
    tags = (raw.cell_data or {}).get("gmsh:physical")
    return None if tags is None else np.asarray(tags[index], dtype=np.int64)


def _volume_block(raw, path, field_name):
    kinds = {_VOLUME_CELLS[b.type][0] for b in raw.cells if b.type in _VOLUME_CELLS}
    if not kinds:
        found = ", ".join(sorted({b.type for b in raw.cells})) or "no cells"
        raise InputError(
            field_name,
            f"mesh file {str(path)!r} has no tetrahedra or hexahedra (found {found}); "
            "a structure needs a volume mesh",
        )
    if len(kinds) > 1:
        raise InputError(field_name, f"mesh file {str(path)!r} mixes tetrahedra and hexahedra")
    return kinds.pop()


def _cells(raw, kind):
    """Corner nodes (c, corners) of every volume cell, and their physical tags (or -1)."""
    corners, tags = [], []
    for i, block in enumerate(raw.cells):
        if block.type in _VOLUME_CELLS:
            n = _VOLUME_CELLS[block.type][1]
            corners.append(np.asarray(block.data)[:, :n])
            tag = _physical(raw, i)
            tags.append(tag if tag is not None else np.full(len(block.data), -1))
    return np.vstack(corners), np.concatenate(tags)


def _skfem_mesh(raw, kind, corners):
    """skfem mesh on the used nodes only (second-order mid-nodes dropped)."""
    import meshio
    from skfem.io.meshio import from_meshio

    used, inverse = np.unique(corners, return_inverse=True)
    t = inverse.reshape(corners.shape)
    compact = meshio.Mesh(np.asarray(raw.points, dtype=float)[used], [(kind, t)])
    return from_meshio(compact), used


def _face_groups(raw, mesh, used, names) -> dict:
    """Named boundary-facet groups: Gmsh surface cells matched to the mesh's boundary facets."""
    old_to_new = np.full(len(raw.points), -1, dtype=np.int64)
    old_to_new[used] = np.arange(len(used))
    boundary = mesh.boundary_facets()
    lookup = {tuple(sorted(mesh.facets[:, f])): int(f) for f in boundary}
    groups: dict = {}
    for i, block in enumerate(raw.cells):
        tags = _physical(raw, i)
        if block.type not in _FACE_CELLS or tags is None:
            continue
        nodes = old_to_new[np.asarray(block.data)[:, : _FACE_CELLS[block.type]]]
        for tag in np.unique(tags):
            name = names.get((int(tag), 2))
            if name is None:
                continue
            rows = nodes[tags == tag]
            found = [lookup.get(tuple(sorted(r))) for r in rows if (r >= 0).all()]
            facets = [f for f in found if f is not None]
            groups[name] = np.union1d(groups.get(name, []), facets).astype(np.int64)
    return groups


def read_volume_mesh(path, field_name: str = "plate.mesh") -> VolumeMesh:
    """Read a volume mesh and its named groups (Gmsh physical surfaces and volumes).

    Parameters
    ----------
    path : str or Path
        Any file meshio reads with tetrahedra or hexahedra (``.msh``: Gmsh 2.2 or 4.1).
    field_name : str
        How the user names the file, for errors (default ``plate.mesh``).

    Returns
    -------
    VolumeMesh
    """
    path = Path(path)
    raw = _read_meshio(path, field_name)
    kind = _volume_block(raw, path, field_name)
    corners, cell_tags = _cells(raw, kind)
    mesh, used = _skfem_mesh(raw, kind, corners)
    names = _group_names(raw)
    volumes = {}
    for tag in np.unique(cell_tags):
        name = names.get((int(tag), 3))
        if name is not None:
            volumes[name] = np.flatnonzero(cell_tags == tag)
    faces = _face_groups(raw, mesh, used, names)
    return VolumeMesh(mesh=mesh, faces=faces, volumes=volumes, source=str(path))
