"""Volume meshes for the solid-structure tests: tensor-product hexahedra (scikit-fem) with
cells removed where the structure is hollow, written as Gmsh 2.2 files by meshio with named
physical surfaces, so the tests read them through the same path as a user's file."""

import meshio
import numpy as np
from skfem import MeshHex, MeshTet
from skfem.io.meshio import to_meshio


def box_mesh(path, xs, ys, zs, faces, keep=None, cell=MeshHex):
    """Write a hexahedral (``cell`` MeshHex) or tetrahedral (MeshTet) mesh of the grid
    xs x ys x zs (m) to ``path``.

    faces: name -> predicate(centroid (3,), normal (3,)) -> bool on boundary facets;
    keep: predicate(cell centroid (3,)) -> bool (default all cells).
    """
    mesh = cell.init_tensor(np.asarray(xs), np.asarray(ys), np.asarray(zs))
    if keep is not None:
        centroids = mesh.p[:, mesh.t].mean(axis=1).T
        drop = np.flatnonzero([not keep(c) for c in centroids])
        if len(drop):
            mesh = mesh.remove_elements(drop)
    out = to_meshio(mesh)
    volume, facet = ("hexahedron", "quad") if cell is MeshHex else ("tetra", "triangle")
    hexes = out.cells_dict[volume]
    boundary = mesh.boundary_facets()
    owner = mesh.f2t[0, boundary]
    quads, tags = [], []
    field_data = {"solid": np.array([len(faces) + 1, 3])}
    for tag, (name, pred) in enumerate(faces.items(), start=1):
        field_data[name] = np.array([tag, 2])
        for f, cell in zip(boundary, owner, strict=True):
            nodes = mesh.facets[:, f]
            c = mesh.p[:, nodes].mean(axis=1)
            x = mesh.p[:, nodes]
            normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
            if np.linalg.norm(normal) == 0:  # quad corners 0, 1, 2 on a line: use another
                normal = np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0])
            outward = c - mesh.p[:, mesh.t[:, cell]].mean(axis=1)
            normal = normal * np.sign(normal @ outward)
            normal = np.round(normal / np.linalg.norm(normal), 6)
            if pred(c, normal):
                quads.append(nodes)
                tags.append(tag)
    cells = [(volume, hexes)]
    phys = [np.full(len(hexes), len(faces) + 1)]
    if quads:
        cells.insert(0, (facet, np.array(quads)))
        phys.insert(0, np.array(tags))
    written = meshio.Mesh(
        out.points,
        cells,
        cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
        field_data=field_data,
    )
    meshio.write(path, written, file_format="gmsh22", binary=False)
    return path


def plate_mesh(path, size=0.6, thickness=0.01, divisions=24, layers=1, cell=MeshHex):
    """The flat plate (size x size x thickness m, top at z = 0) with faces 'top', 'sides',
    'bottom'."""
    xs = np.linspace(-0.5 * size, 0.5 * size, divisions + 1)
    zs = np.linspace(-thickness, 0.0, layers + 1)
    faces = {"top": lambda c, n: n[2] > 0.5, "sides": lambda c, n: abs(n[2]) < 0.5,
             "bottom": lambda c, n: n[2] < -0.5}  # fmt: skip
    return box_mesh(path, xs, xs, zs, faces, cell=cell)


def tet_plate_mesh(path, **kwargs):
    """``plate_mesh`` in tetrahedra (each grid cell cut in six)."""
    return plate_mesh(path, cell=MeshTet, **kwargs)


def box_beam_mesh(path, length, width, height, wall, cells_x, cells_y=4, cells_z=2):
    """A thin-walled rectangular box beam along x (x in [-length/2, length/2], y in
    [-width/2, width/2], z in [-height, 0]; all walls ``wall`` m thick) with faces 'top',
    'root' (x = -length/2) and 'tip' (x = +length/2)."""
    hw = 0.5 * width
    ys = np.concatenate([[-hw], np.linspace(-hw + wall, hw - wall, cells_y + 1), [hw]])
    zs = np.concatenate([[-height], np.linspace(-height + wall, -wall, cells_z + 1), [0.0]])
    xs = np.linspace(-0.5 * length, 0.5 * length, cells_x + 1)

    def in_wall(c):
        return abs(c[1]) > hw - wall or c[2] < -height + wall or c[2] > -wall

    faces = {"top": lambda c, n: n[2] > 0.5 and c[2] > -1e-9,
             "root": lambda c, n: n[0] < -0.5, "tip": lambda c, n: n[0] > 0.5}  # fmt: skip
    return box_mesh(path, xs, ys, zs, faces, keep=in_wall)


def clamped_plate_scenes(mesh: str, duration: float, fmax: float) -> tuple[str, str]:
    """Scene-file heads of the clamped 0.6 x 0.6 x 0.01 m plate with a quasi-static tail: as
    a structure from ``mesh`` (clamped on its group "sides") and as the flat Mindlin CCCC
    plate, ``duration`` s, band to ``fmax`` Hz."""
    head = f'duration = {duration}\n[plate]\nmodel = "modal"\n'
    tail = f'fmax = {fmax}\ntail = "quasi-static"\n'
    structure = (f'{head}mesh = "{mesh}"\nimpact_face = "top"\n{tail}'
                 '[[plate.supports]]\ngroup = "sides"\nkind = "clamped"\n')  # fmt: skip
    flat = f'{head}size = [0.6, 0.6, 0.01]\nboundary = "CCCC"\ntheory = "mindlin"\n{tail}'
    return structure, flat
