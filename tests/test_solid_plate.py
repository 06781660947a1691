"""The flat 0.6 x 0.6 x 0.01 m plate as a volume mesh (tailbeam.plate.solid) against today's
plate models (tailbeam.plate: Reissner-Mindlin and Kirchhoff finite elements), and the solid's
static compliance against its own complete modal sum.

Truth for the frequencies: the free plate (no support to model differently in 3D) of the
Mindlin plate; each of the first 30 solid frequencies must lie within the difference between
the plate theories, |solid/Mindlin - 1| <= |Mindlin/Kirchhoff - 1| (3D elasticity departs
from Mindlin's plate by less than Mindlin's first-order shear and rotary-inertia terms depart
from Kirchhoff's plate).
"""

from types import SimpleNamespace

import numpy as np
import pytest
from solid_meshes import plate_mesh

from tailbeam.physics.bodies import Plate
from tailbeam.plate import compute_modes
from tailbeam.plate.solid import Support, assemble_structure, structure_modes

COUNT = 30


@pytest.fixture(scope="module")
def free_solid(tmp_path_factory):
    path = plate_mesh(tmp_path_factory.mktemp("plate") / "plate.msh", divisions=24)
    model = assemble_structure(path, "top", [], free=True)
    return structure_modes(model, count=COUNT)


def test_free_plate_within_the_theories_difference(free_solid):
    mindlin = compute_modes(Plate(), "FFFF", theory="mindlin", count=COUNT)
    kirchhoff = compute_modes(Plate(), "FFFF", theory="kirchhoff", count=COUNT)
    assert free_solid.info["rigid_body_modes_excluded"] == 6
    solid_error = np.abs(free_solid.frequencies_hz / mindlin.frequencies_hz - 1)
    theories = np.abs(mindlin.frequencies_hz / kirchhoff.frequencies_hz - 1)
    assert np.all(solid_error <= theories), np.flatnonzero(solid_error > theories)


def test_impact_face_reading_is_the_surface_reading(free_solid):
    """deflection_at (the face finder) and shape_at (the surface search) are two lookups of
    the same field: they agree to round-off at random points of the top."""
    pts = np.random.default_rng(3).uniform(-0.3, 0.3, (7, 2))
    on_top = np.column_stack([pts, np.zeros(len(pts))])
    a = free_solid.deflection(pts)
    b = free_solid.shape_at(on_top, np.tile([0.0, 0.0, 1.0], (len(pts), 1)))
    assert np.allclose(a, b, rtol=0, atol=1e-10 * np.abs(a).max())
    # default direction: the outward normal, +z on the top
    assert np.allclose(free_solid.shape_at(on_top), b, rtol=0, atol=1e-10 * np.abs(a).max())


def test_paraview_structure_is_the_same_field(free_solid):
    """vtk_structure (the mode shapes at the surface's corner nodes, from the DOFs) against
    the point readings (the probe through each node's cell): the same field."""
    points, cells, shapes = free_solid.vtk_structure()
    assert cells[0][0] == "quad" and cells[0][1].max() == len(points) - 1
    top = np.flatnonzero(points[:, 2] == 0.0)[::37]
    scale = np.abs(shapes).max()
    assert np.allclose(shapes[top, 2], free_solid.deflection(points[top, :2]),
                       rtol=0, atol=1e-10 * scale)  # fmt: skip
    side = np.flatnonzero(np.isclose(points[:, 0], 0.3))[::11]
    along_x = free_solid.shape_at(points[side], np.tile([1.0, 0.0, 0.0], (len(side), 1)))
    assert np.allclose(shapes[side, 0], along_x, rtol=0, atol=1e-10 * scale)


def test_static_compliance_is_the_complete_modal_sum(tmp_path):
    """K^-1 = sum_i phi_i phi_i^T / omega_i^2 over all modes: the static compliance under a
    disc load equals the modal sum when every mode of a small model is kept."""
    path = plate_mesh(tmp_path / "small.msh", divisions=3)
    model = assemble_structure(path, "top", [Support("clamped", group="sides")])
    basis = structure_modes(model, count=model.n_dofs)
    point, radius = np.array([[0.05, -0.07]]), 0.02
    full = basis.static_compliance_at(point, radius)[0]
    phibar = basis.load_deflection(point, radius)[0]
    modal = np.sum(phibar**2 / basis.omega**2)
    assert abs(modal / full - 1) < 1e-9
    assert basis.residual_compliance(point, radius)[0] < 1e-9 * full


def test_a_solid_run_writes_its_surface_to_paraview(tmp_path):
    """The ParaView series (tailbeam.io.paraview finds the basis' vtk_structure) of a run on
    the clamped solid plate, modal coordinates q(t) = (sin 300 t, cos 700 t, 0, ...), read
    back with meshio: the top's deflection in every frame is sum_k phi_k q_k read by the
    probe (another route), and the surface is the mesh's outer faces."""
    import xml.etree.ElementTree as ET

    import meshio

    from tailbeam.io.paraview import write_series
    from tailbeam.results.frames import BallFrames

    path = plate_mesh(tmp_path / "plate.msh", divisions=6)
    model = assemble_structure(path, "top", [Support("clamped", group="sides")])
    basis = structure_modes(model, count=5)

    def coordinates(t):
        q = np.zeros((basis.n_modes, len(t)))
        q[0], q[1] = 1e-4 * np.sin(300.0 * t), 1e-4 * np.cos(700.0 * t)
        return q

    times = np.arange(5) / 1000.0
    plate = SimpleNamespace(basis=basis, modal_coordinates=coordinates)
    run = SimpleNamespace(frames=BallFrames.empty(times, 0), particles=(), plate=plate)
    write_series(tmp_path / "vtk", SimpleNamespace(inclination=0.0), run)
    index = ET.parse(tmp_path / "vtk" / "structure.pvd").getroot()
    names = [d.get("file") for d in index.find("Collection").findall("DataSet")]
    frames = [meshio.read(tmp_path / "vtk" / name) for name in names]
    assert len(frames) == len(times) and frames[0].cells[0].type == "quad"
    assert len(frames[0].cells[0].data) == len(model.vmesh.mesh.boundary_facets())
    top = np.flatnonzero(frames[0].points[:, 2] == 0.0)
    w = basis.deflection(frames[0].points[top, :2]) @ coordinates(times)
    got = np.array([m.point_data["deflection"][top] for m in frames]).T
    assert np.abs(w).max() > 0
    assert np.allclose(got, w, rtol=0, atol=1e-9 * np.abs(w).max())
