"""Triangular plate meshes with named edges: the structured generator, reading and writing
(Gmsh 2.2 via meshio, which keeps the edge names) and the project's default meshes.

Edges are named 'left' (x = -a/2), 'bottom' (y = -b/2), 'right' (x = +a/2), 'top' (y = +b/2);
the plate is centred on the origin (tailbeam.physics.bodies). Coordinates in m.
"""

import contextlib
import io
from pathlib import Path

import numpy as np
from skfem import MeshTri

from tailbeam.errors import InputError
from tailbeam.physics.bodies import Plate

EDGE_NAMES = ("left", "bottom", "right", "top")
MAX_DIVISIONS = 200  # 80 000 triangles: beyond any band this package is meant for

# The default meshes shipped in <repo>/meshes. When the folder is not there (an installed
# wheel), the identical structured mesh is regenerated: the files are a convenience for users
# (open them in Gmsh/ParaView, use them as a template for mesh=path), not a dependency.
MESH_DIR = Path(__file__).resolve().parents[3] / "meshes"


def _edge_markers(plate: Plate):
    a, b = plate.size_x, plate.size_y
    tol = 1e-9 * max(a, b)
    return {
        "left": lambda x: np.abs(x[0] + 0.5 * a) < tol,
        "bottom": lambda x: np.abs(x[1] + 0.5 * b) < tol,
        "right": lambda x: np.abs(x[0] - 0.5 * a) < tol,
        "top": lambda x: np.abs(x[1] - 0.5 * b) < tol,
    }


def grid_divisions(plate: Plate, divisions) -> tuple[int, int]:
    """(nx, ny) from an int (divisions of the longer side; the other side gets as many as keep
    the cells near square) or a pair (nx, ny)."""
    if isinstance(divisions, (tuple, list)) and len(divisions) == 2:
        nx, ny = divisions
    else:
        if (
            isinstance(divisions, bool)
            or not isinstance(divisions, (int, np.integer))
            or divisions < 1
        ):
            raise InputError("divisions", f"must be a whole number >= 1, got {divisions!r}")
        longest = max(plate.size_x, plate.size_y)
        nx = max(1, int(np.ceil(divisions * plate.size_x / longest - 1e-9)))
        ny = max(1, int(np.ceil(divisions * plate.size_y / longest - 1e-9)))
    for value in (nx, ny):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise InputError("divisions", f"must be whole numbers >= 1, got {divisions!r}")
        if value > MAX_DIVISIONS:
            raise InputError("divisions", f"must be <= {MAX_DIVISIONS} per side, got {value}")
    return int(nx), int(ny)


def structured_mesh(plate: Plate, divisions) -> MeshTri:
    """Right-triangle mesh of the plate, nx x ny rectangles each cut along a diagonal."""
    nx, ny = grid_divisions(plate, divisions)
    a, b = plate.size_x, plate.size_y
    mesh = MeshTri.init_tensor(
        np.linspace(-0.5 * a, 0.5 * a, nx + 1), np.linspace(-0.5 * b, 0.5 * b, ny + 1)
    )
    return mesh.with_boundaries(_edge_markers(plate))


def check_mesh(mesh: MeshTri, plate: Plate, field: str = "mesh") -> MeshTri:
    """Validate a user mesh: triangles, covering the plate's rectangle (centred on the origin),
    with all four named edges. Returns the mesh."""
    if not isinstance(mesh, MeshTri) or mesh.t.shape[0] != 3:
        raise InputError(field, "must be a mesh of linear triangles")
    lo, hi = mesh.p.min(axis=1), mesh.p.max(axis=1)
    half = 0.5 * np.array([plate.size_x, plate.size_y])
    if not (
        np.allclose(lo, -half, atol=1e-6 * half.max())
        and np.allclose(hi, half, atol=1e-6 * half.max())
    ):
        raise InputError(
            field,
            f"must span the plate centred on the origin, x in [{-half[0]}, {half[0]}] and y in "
            f"[{-half[1]}, {half[1]}] m; it spans [{lo[0]:.6g}, {hi[0]:.6g}] x "
            f"[{lo[1]:.6g}, {hi[1]:.6g}]",
        )
    names = set((mesh.boundaries or {}).keys())
    missing = [name for name in EDGE_NAMES if name not in names]
    if missing:
        raise InputError(
            field,
            f"needs named boundary edges {', '.join(EDGE_NAMES)} (Gmsh physical lines); "
            f"missing {', '.join(missing)}; found {sorted(names) or 'none'}",
        )
    return mesh


def save_mesh(mesh: MeshTri, path) -> Path:
    """Write a Gmsh 2.2 ASCII file with the triangles and one physical line per named edge."""
    path = Path(path)
    names = [n for n in EDGE_NAMES if n in (mesh.boundaries or {})]
    lines, tags = [], []
    for tag, name in enumerate(names, start=1):
        facets = np.asarray(mesh.boundaries[name])
        lines.append(mesh.facets[:, facets].T)
        tags.append(np.full(len(facets), tag))
    field_data = {name: np.array([tag, 1]) for tag, name in enumerate(names, start=1)}
    field_data["plate"] = np.array([len(names) + 1, 2])
    tri_tags = np.full(mesh.t.shape[1], len(names) + 1)
    cells = [("line", np.vstack(lines))] if lines else []
    cells.append(("triangle", mesh.t.T))
    phys = ([np.concatenate(tags)] if lines else []) + [tri_tags]
    import meshio  # only for files: 0.3-0.5 s of import the default path does not need

    out = meshio.Mesh(
        np.column_stack([mesh.p.T, np.zeros(mesh.p.shape[1])]),
        cells,
        cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
        field_data=field_data,
    )
    meshio.write(path, out, file_format="gmsh22", binary=False)
    return path


def load_mesh(path, plate: Plate, field: str = "mesh") -> MeshTri:
    """Read a triangular mesh with named boundary edges (any format meshio reads; Gmsh
    physical names or meshio cell sets) and check it against the plate."""
    import meshio
    from skfem.io.meshio import from_meshio

    path = Path(path)
    if not path.is_file():
        raise InputError(field, f"mesh file {str(path)!r} does not exist")
    said = io.StringIO()
    try:
        # .msh is ambiguous to meshio (ANSYS or Gmsh); say Gmsh to skip a noisy failed try.
        # meshio prints to stderr and may call sys.exit on files it cannot read: catch both.
        with contextlib.redirect_stderr(said), contextlib.redirect_stdout(said):
            raw = meshio.read(path, file_format="gmsh" if path.suffix == ".msh" else None)
    except (Exception, SystemExit) as err:  # meshio raises many types for unreadable files
        why = " ".join(said.getvalue().split()) or str(err) or type(err).__name__
        raise InputError(field, f"cannot read mesh file {str(path)!r}: {why}") from None
    if "triangle" not in raw.cells_dict:
        raise InputError(field, f"mesh file {str(path)!r} has no triangles")
    mesh = from_meshio(raw)
    if mesh.boundaries:
        # drop orientation information: only the facet indices matter here
        mesh = MeshTri(
            mesh.p, mesh.t, {k: np.asarray(v, dtype=np.int64) for k, v in mesh.boundaries.items()}
        )
    return check_mesh(mesh, plate, field)


def default_mesh_path(plate: Plate, divisions) -> Path:
    """Where the default mesh for this plate size and divisions lives (may not exist)."""
    nx, ny = grid_divisions(plate, divisions)
    return MESH_DIR / f"plate_{plate.size_x:g}x{plate.size_y:g}_{nx}x{ny}.msh"


def default_mesh(plate: Plate, divisions) -> MeshTri:
    """The structured mesh with these divisions, generated (milliseconds); the shipped
    meshes/ files are identical copies for users (tests check this), not read here: reading
    them would cost the meshio import on every cached run."""
    return structured_mesh(plate, divisions)
