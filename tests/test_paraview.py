"""`tailbeam simulate --vtk`: the ParaView series, read back with VTK's own XML reader (the
one ParaView uses; meshio cannot read a frame without particles) and meshio (the VTU files),
and ElementTree (the .pvd collections), against independent truths.

- Frame times are k / rate; both collections list the same times and existing files.
- Particles before their first contact follow the closed-form free fall in the world frame
  (z up: x_w(t) = R x0 + R v0 t - g t^2/2 e_z, R built here from the inclination), which checks
  the solver's frames and the rotation at once; radius, material and label match
  particles.csv; a ball is present from its release until it leaves (particles.csv t_leave).
- The rigid plate is its undeformed rectangle; the modal plate's deflection at every mesh
  point equals the kept modes' response evaluated at those points by another path (the
  single-ball replay at points; the stream's load response at points), and the displacement
  is that deflection along the plate's normal.
- A structure of another kind (a volume mesh's 3-vector modes) plugs in through the
  protocol: its frames hold R sum_k shape_k q_k(t) on its own cells.
- A bad --vtk-rate or a solver without frames: one line, exit 2, nothing written.
- `tailbeam modes --vtu --mesh`: the mesh covers the plate at z = 0 and the first mode has
  the SSSS closed-form amplitude.
"""

import csv
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import meshio
import numpy as np
import pytest

from tailbeam import simulate
from tailbeam.cli.main import main
from tailbeam.io.paraview import ModalStructure, write_series
from tailbeam.io.scene_file import load_scene
from tailbeam.physics.bodies import STANDARD_GRAVITY
from tailbeam.results.frames import BallFrames
from tailbeam.solvers.plate_loads.response import plate_response

INCLINED = """duration = 0.5
[plate]
model = "rigid"
inclination = 20.0
[[balls]]
name = "c"
material = "coal"
radius = 0.02
position = [-0.1, 0.1, 0.08]
velocity = [0.2, 0.0, -0.3]
[[balls]]
name = "g"
material = "sandstone"
radius = 0.025
position = [0.1, -0.1, 0.05]
velocity = [0.5, 0.1, 0.0]
label = "gangue"
"""
MODAL = """duration = {duration}
[plate]
model = "modal"
inclination = {inclination}
size = [0.6, 0.6, 0.01]
fmax = 1500.0
boundary = "SSSS"
[[balls]]
name = "a"
material = "sandstone"
radius = 0.02
position = [0.05, 0.05, 0.03]
velocity = [0.0, 0.0, -1.0]
"""
RATE = 100.0
MESHES = Path(__file__).resolve().parents[1] / "meshes"


def rotation(inclination_deg):
    """Plate-frame vectors to the world frame: the plate's x axis points downhill."""
    t = math.radians(inclination_deg)
    ex = np.array([math.cos(t), 0.0, -math.sin(t)])
    ez = np.array([math.sin(t), 0.0, math.cos(t)])
    return np.column_stack([ex, [0.0, 1.0, 0.0], ez])


def read_pvd(path):
    root = ET.parse(path).getroot()
    assert root.get("type") == "Collection"
    sets = root.find("Collection").findall("DataSet")
    return np.array([float(d.get("timestep")) for d in sets]), [d.get("file") for d in sets]


def read_vtu(path):
    """(points (p, 3), point fields {name: array}) of a VTU file, read by VTK (imported here:
    VTK takes ~2 s to import, which every pytest-xdist worker would pay at collection)."""
    from vtk import vtkXMLUnstructuredGridReader
    from vtk.util.numpy_support import vtk_to_numpy

    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    assert reader.GetErrorCode() == 0, path
    grid = reader.GetOutput()
    data = grid.GetPointData()
    fields = {
        data.GetArrayName(i): vtk_to_numpy(data.GetArray(i))
        for i in range(data.GetNumberOfArrays())
    }
    points = grid.GetPoints()
    xyz = vtk_to_numpy(points.GetData()) if points is not None else np.zeros((0, 3))
    return xyz.reshape(-1, 3), fields


def read_csv(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def inclined_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inclined")
    (folder / "scene.toml").write_text(INCLINED)
    out = folder / "out"
    args = ["simulate", str(folder / "scene.toml"), "--out", str(out), "-q"]
    assert main([*args, "--vtk-rate", str(RATE)]) == 0
    return out


def test_frame_times_and_files(inclined_run):
    vtk = inclined_run / "vtk"
    times, files = read_pvd(vtk / "particles.pvd")
    np.testing.assert_allclose(times, np.arange(51) / RATE, rtol=0, atol=1e-15)
    plate_times, plate_files = read_pvd(vtk / "structure.pvd")
    assert np.array_equal(plate_times, times)
    assert all((vtk / f).is_file() for f in files + plate_files)
    assert len(set(files)) == len(times) and set(plate_files) == {"structure.vtu"}


def test_particles_fly_in_closed_form_in_the_world_frame(inclined_run):
    vtk = inclined_run / "vtk"
    times, files = read_pvd(vtk / "particles.pvd")
    rows = read_csv(inclined_run / "particles.csv")
    impacts = read_csv(inclined_run / "impacts.csv")
    codes = json.loads((inclined_run / "manifest.json").read_text())["files"]
    codes = codes["vtk/particles.pvd"]
    rot = rotation(20.0)
    checked = 0
    absent = 0
    for t, name in zip(times, files, strict=True):
        points, fields = read_vtu(vtk / name)
        assert set(fields) == {"radius", "velocity", "material", "label", "id"}
        ids = list(fields["id"])
        absent += not ids
        for b, row in enumerate(rows):
            t_leave = float(row["t_leave"]) if row["t_leave"] not in ("", "nan") else math.inf
            assert (b in ids) == (float(row["t_release"]) <= t < t_leave), (t, row["name"])
            if b not in ids:
                continue
            k = ids.index(b)
            assert fields["radius"][k] == float(row["radius"])
            assert fields["material"][k] == codes["material_codes"][row["material"]]
            assert fields["label"][k] == codes["label_codes"][row["label"]]
            first = min(float(r["t_start"]) for r in impacts if r["ball"] == row["name"])
            if t >= first:
                continue
            x0 = np.array([float(row[c]) for c in ("x0", "y0", "z0")])
            v0 = np.array([float(row[c]) for c in ("vx0", "vy0", "vz0")])
            s = t - float(row["t_release"])
            x = rot @ x0 + rot @ v0 * s - np.array([0, 0, 0.5 * STANDARD_GRAVITY * s * s])
            v = rot @ v0 - np.array([0, 0, STANDARD_GRAVITY * s])
            np.testing.assert_allclose(points[k], x, rtol=0, atol=1e-12)
            np.testing.assert_allclose(fields["velocity"][k], v, rtol=0, atol=1e-12)
            checked += 1
    assert checked >= 6  # both balls in flight over several frames
    assert absent >= 1  # the frames after both left: empty, and readable


def test_the_rigid_plate_is_its_rectangle(inclined_run):
    mesh = meshio.read(inclined_run / "vtk" / "structure.vtu")
    corners = np.array([[x, y, 0.0] for x in (-0.3, 0.3) for y in (-0.3, 0.3)])
    expected = corners @ rotation(20.0).T
    got = mesh.points[np.lexsort((mesh.points[:, 1], mesh.points[:, 0]))]
    np.testing.assert_allclose(got, expected[np.lexsort((expected[:, 1], expected[:, 0]))],
                               atol=1e-15)  # fmt: skip
    tris = mesh.cells_dict["triangle"]
    area = 0.5 * np.linalg.norm(
        np.cross(*(mesh.points[tris[:, i]] - mesh.points[tris[:, 0]] for i in (1, 2))), axis=1
    )
    assert area.sum() == pytest.approx(0.36, rel=1e-12)


def modal_series(tmp_path, inclination, duration, solver):
    path = tmp_path / "scene.toml"
    path.write_text(MODAL.format(inclination=inclination, duration=duration))
    scene = load_scene(path)
    times = np.arange(int(round(duration * 1000)) + 1) / 1000.0
    result = simulate(scene, solver=solver, frames=times, progress=False)
    write_series(tmp_path / "vtk", scene, result)
    got = [meshio.read(tmp_path / "vtk" / f) for f in read_pvd(tmp_path / "vtk/structure.pvd")[1]]
    return scene, result, times, got


def check_field(frames, w, rot):
    """The series' deflection is w (points, frames) and its displacement w along R e_z."""
    deflection = np.array([m.point_data["deflection"] for m in frames]).T
    scale = np.abs(w).max()
    assert scale > 1e-7  # the ball did move the plate
    np.testing.assert_allclose(deflection, w, rtol=0, atol=1e-9 * scale)
    u = np.array([m.point_data["displacement"] for m in frames])
    np.testing.assert_allclose(u, w.T[:, :, None] * rot[:, 2], rtol=0, atol=1e-9 * scale)


def test_single_ball_modal_plate_deflection_is_the_replay_at_the_points(tmp_path):
    scene, result, times, frames = modal_series(tmp_path, 0.0, 0.02, "single-ball")
    points = frames[0].points[:, :2]
    w = result.plate.sample(times, points, quasi_static=False)["w"]
    check_field(frames, w, rotation(0.0))
    z = meshio.read(tmp_path / "vtk/particles_00003.vtu").points[0, 2]
    assert z == pytest.approx(0.03 - 0.003 - 0.5 * STANDARD_GRAVITY * 0.003**2, abs=1e-12)


def test_stream_modal_plate_deflection_is_the_load_response_at_the_points(tmp_path):
    scene, result, times, frames = modal_series(tmp_path, 20.0, 0.03, "stream")
    rot = rotation(20.0)
    points = (frames[0].points @ rot)[:, :2]  # back to the plate frame
    response = result.plate
    w = plate_response(response.basis, response.zeta, response.loads, points, times,
                       quasi_static=False)["w"]  # fmt: skip
    check_field(frames, w, rot)


def test_a_volume_structure_plugs_in_through_the_protocol(tmp_path):
    """A tetrahedron moving in two 3-vector modes, q(t) = (sin 50 t, cos 50 t): each frame's
    displacement is R sum_k shape_k q_k(t), its cell a VTK tetra."""
    rng = np.random.default_rng(3)
    shapes = rng.normal(size=(4, 3, 2))
    points = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, -0.1]], dtype=float)
    structure = ModalStructure(points, [("tetra", np.array([[0, 1, 2, 3]]))], shapes,
                               lambda t: np.vstack([np.sin(50 * t), np.cos(50 * t)]))  # fmt: skip
    times = np.arange(5) / 100.0
    run = SimpleNamespace(frames=BallFrames.empty(times, 0), particles=())
    write_series(tmp_path / "vtk", SimpleNamespace(inclination=30.0), run, structure)
    rot = rotation(30.0)
    for t, name in zip(*read_pvd(tmp_path / "vtk/structure.pvd"), strict=True):
        xyz, fields = read_vtu(tmp_path / "vtk" / name)
        np.testing.assert_allclose(xyz, points @ rot.T, atol=1e-15)
        u = shapes @ np.array([np.sin(50 * t), np.cos(50 * t)])
        np.testing.assert_allclose(fields["displacement"], u @ rot.T, atol=1e-14)
        np.testing.assert_allclose(fields["deflection"], u[:, 2], atol=1e-14)
    assert meshio.read(tmp_path / "vtk/structure_00002.vtu").cells[0].type == "tetra"


@pytest.mark.parametrize("rate", ["0", "-5", "nan", "inf", "1e9", "1"])
def test_a_bad_rate_is_one_line_and_writes_nothing(tmp_path, capsys, rate):
    (tmp_path / "scene.toml").write_text(INCLINED)
    out = tmp_path / "out"
    code = main(["simulate", str(tmp_path / "scene.toml"), "--out", str(out), "--vtk-rate", rate])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "--vtk-rate:" in err, err
    assert "Traceback" not in err and not out.exists()


def test_a_solver_without_frames_is_refused(tmp_path, capsys):
    (tmp_path / "scene.toml").write_text(INCLINED)
    out = tmp_path / "out"
    args = ["simulate", str(tmp_path / "scene.toml"), "--out", str(out), "--vtk"]
    assert main([*args, "--solver", "stream-reference"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--vtk:" in err and not out.exists()


def test_modes_vtu_on_a_mesh_covers_the_plate_with_the_closed_form_amplitude(tmp_path):
    out = tmp_path / "modes"
    args = ["modes", "--mesh", str(MESHES / "plate_0.6x0.6_8x8.msh"), "--count", "3", "--vtu"]
    assert main([*args, "--theory", "kirchhoff", "--out", str(out)]) == 0
    mesh = meshio.read(out / "modes.vtu")
    assert np.all(mesh.points[:, 2] == 0.0)
    tris = mesh.cells_dict["triangle"]
    a, b = (mesh.points[tris[:, i], :2] - mesh.points[tris[:, 0], :2] for i in (1, 2))
    assert np.sum(0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])) == pytest.approx(0.36)
    first = next(v for k, v in mesh.point_data.items() if k.startswith("mode_001_"))
    mass = 7850.0 * 0.6 * 0.6 * 0.01  # carbon steel; SSSS: phi_11 = 2 / sqrt(m) at the centre
    assert np.abs(first).max() == pytest.approx(2.0 / math.sqrt(mass), rel=2e-3)
