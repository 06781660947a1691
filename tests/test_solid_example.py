"""The example tail beam (meshes/tail_beam.msh, made by meshes/tail_beam.py) is what its
script says: the dimensions stated at the top of the script, its named groups, a held
structure with the hinge pinned and the jack a spring."""

import importlib.util

import numpy as np
from skfem import Basis, ElementHex1

from tailbeam.physics.materials import CARBON_STEEL
from tailbeam.plate.fe.mesh import MESH_DIR
from tailbeam.plate.solid import read_volume_mesh
from tailbeam.plate.solid.face.plane import impact_face


def _script():
    spec = importlib.util.spec_from_file_location("tail_beam", MESH_DIR / "tail_beam.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # gmsh is imported only when the script builds
    return module


def test_example_beam_matches_its_script():
    script = _script()
    vmesh = read_volume_mesh(MESH_DIR / "tail_beam.msh")
    assert vmesh.kind == "hexahedron"
    assert {"top", "hinge", "jack"} <= set(vmesh.faces)
    span = np.ptp(vmesh.mesh.p, axis=1)
    assert np.allclose(span, [script.LENGTH, script.WIDTH, script.DEPTH], rtol=1e-9)
    face = impact_face(vmesh, "top", CARBON_STEEL)
    assert np.isclose(face.plate.size_x, script.LENGTH) and np.isclose(face.plate.size_y,
                                                                        script.WIDTH)  # fmt: skip
    assert np.isclose(face.plate.thickness, script.TOP)  # the top plate under the centre
    # the jack's bearing patch: its stated extent, on the bottom plate
    mesh = vmesh.mesh
    jack = mesh.p[:, mesh.facets[:, vmesh.faces["jack"]]]
    assert np.allclose(jack[2], -script.DEPTH)
    assert np.isclose(jack[0].min(), script.JACK_X[0]) and np.isclose(jack[0].max(),
                                                                      script.JACK_X[1])  # fmt: skip
    hinge = mesh.p[:, mesh.facets[:, vmesh.faces["hinge"]]]
    assert np.allclose(hinge[0], -0.5 * script.LENGTH)
    # volume of steel: the union of the plates and ribs as the script's is_steel describes
    xs, ys, zs = script.breaks()
    grid = [0.5 * (np.array(v[1:]) + np.array(v[:-1])) for v in (xs, ys, zs)]
    widths = [np.diff(v) for v in (xs, ys, zs)]
    expected = sum(
        widths[0][i] * widths[1][j] * widths[2][k]
        for i, x in enumerate(grid[0]) for j, y in enumerate(grid[1])
        for k, z in enumerate(grid[2]) if script.is_steel(x, y, z)
    )  # fmt: skip
    volume = Basis(mesh, ElementHex1()).dx.sum()  # skfem's quadrature of 1 over the cells
    assert np.isclose(volume, expected, rtol=1e-9)
