"""A structure's fast impact-face readings (tailbeam.plate.solid.face.readings) and its face
compliance matrix (tailbeam.plate.solid.face.compliance) against the slow paths they replace
on the stream solver: the probe's reading (scikit-fem's inverse mapping and basis functions
in the owning cell) and the direct factorised solve per point, on hexahedra and tetrahedra,
with a hinge (a DOF shared by the face's edge) and a spring; a face of non-parallelogram
facets keeps the slow paths."""

import meshio
import numpy as np
import pytest
from solid_meshes import box_mesh, tet_plate_mesh

from tailbeam.plate.solid import Support, assemble_structure, structure_modes
from tailbeam.plate.solid.face.readings import face_readings
from tailbeam.solvers.stream.plate import StreamPlate

FACES = {
    "top": lambda c, n: n[2] > 0.5,
    "left": lambda c, n: n[0] < -0.5,
    "right": lambda c, n: n[0] > 0.5,
    "sides": lambda c, n: abs(n[2]) < 0.5,
}
HINGED = (Support("pinned", group="left", axis=(0.0, 1.0, 0.0)),
          Support("spring", group="right", stiffness=2.0e8))  # fmt: skip  # the beam's jack
# The face compliance (K's Schur complement on the face, inverted) and the direct solve
# (an ND-ordered factorisation of K) round off differently; the gap grows with the
# stiffness ratio between the plate and its softest support (measured on the hinged plate:
# 2.7e-9 with the 2e8 N/m spring, 7e-8 with 2e6, 2e-10 with 2e10; 1e-11 clamped).
COMPLIANCE_RTOL = 1e-8
COUNT = 12


def _hex(path):
    """A 0.4 x 0.2 x 0.02 m plate of uneven 6 x 3 x 1 hexahedra."""
    xs = np.array([-0.2, -0.13, -0.07, 0.0, 0.05, 0.12, 0.2])
    return box_mesh(path, xs, np.array([-0.1, -0.04, 0.03, 0.1]), np.array([-0.02, 0.0]), FACES)


@pytest.fixture(scope="module", params=["hexahedra", "tetrahedra"])
def case(request, tmp_path_factory):
    folder = tmp_path_factory.mktemp("face_readings")
    if request.param == "hexahedra":
        model = assemble_structure(_hex(folder / "plate.msh"), "top", HINGED)
    else:
        path = tet_plate_mesh(folder / "plate.msh", size=0.3, thickness=0.01, divisions=4)
        model = assemble_structure(path, "top", (Support("clamped", group="sides"),))
    basis = structure_modes(model, count=COUNT, cache_dir=folder)
    return model, basis, folder


def _points(plate, n=60, seed=3):
    """Random points, the face's corners, its centre and points on cell edges."""
    rng = np.random.default_rng(seed)
    a, b = 0.5 * plate.size_x, 0.5 * plate.size_y
    rand = rng.uniform([-a, -b], [a, b], (n, 2))
    fixed = [[-a, -b], [a, b], [a, -b], [0.0, 0.0], [0.05, 0.0], [-0.07, 0.03], [0.0, b]]
    return np.vstack([rand, fixed])


def test_face_shapes_equal_the_probe(case):
    model, basis, _ = case
    readings = face_readings(model)
    assert readings is not None
    pts = _points(model.plate)
    slow = basis.deflection(pts)
    fast = readings.modal(basis.mode_vectors)(pts)[:, : basis.n_modes]
    assert np.max(np.abs(fast - slow)) <= 1e-10 * np.max(np.abs(slow))
    op_slow, op_fast = model.face_operator(pts), readings.operator(pts)
    assert abs(op_fast - op_slow).max() <= 1e-10 * abs(op_slow).max()


def test_face_compliance_equals_the_direct_solve(case):
    model, basis, folder = case
    rng = np.random.default_rng(5)
    pts = _points(model.plate, n=8)[[0, 1, 2, 3, 8, 9, 11, 12]]
    radii = rng.choice([0.0, 0.001, 0.004, 0.012, 0.03], len(pts))
    pairs = list(zip(pts, radii, strict=True))
    direct = np.array([model.static_compliance([p], r)[0] for p, r in pairs])
    fast = np.array([basis.static_compliance_at([p], r)[0] for p, r in pairs])
    np.testing.assert_allclose(fast, direct, rtol=COMPLIANCE_RTOL)


def test_stream_plate_uses_them(case):
    model, basis, _ = case
    plate = StreamPlate(basis, np.full(basis.n_modes, 0.01))
    assert plate._face is not None
    pts = _points(model.plate, n=5)
    np.testing.assert_allclose(plate.shapes(pts), basis.deflection(pts), rtol=0, atol=1e-10 *
                               np.abs(basis.deflection(pts)).max())  # fmt: skip
    radii = [0.0, 0.002, 0.006, 0.01, 0.02] + [0.003] * (len(pts) - 5)
    fast = plate.compliance(pts, radii)
    pairs = list(zip(pts, radii, strict=True))
    slow = np.array([basis.residual_compliance([p], r)[0] for p, r in pairs])
    full = np.array([basis.static_compliance_at([p], r)[0] for p, r in pairs])
    assert np.all(np.abs(fast - slow) <= 1e-10 * full)  # the same full value, shapes to 1e-10


def test_skewed_facets_keep_the_slow_paths(tmp_path):
    path = _hex(tmp_path / "plate.msh")
    mesh = meshio.read(path)
    column = np.isclose(mesh.points[:, 0], 0.0) & np.isclose(mesh.points[:, 1], 0.03)
    mesh.points[column, 0] += 0.01  # one column of nodes moved: trapezoids around it
    mesh.write(path, file_format="gmsh22", binary=False)
    model = assemble_structure(path, "top", HINGED)
    assert face_readings(model) is None
    basis = structure_modes(model, count=COUNT, use_cache=False)
    plate = StreamPlate(basis, np.full(basis.n_modes, 0.01))
    assert plate._face is None
    pts = [[0.01, 0.03], [-0.1, -0.05]]
    direct = model.static_compliance(pts, 0.004)
    np.testing.assert_allclose(basis.static_compliance_at(pts, 0.004), direct, rtol=1e-12)
