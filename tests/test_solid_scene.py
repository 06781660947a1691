"""A scene file on a structure from a mesh (plate.mesh, impact_face, [[plate.supports]]) runs
through `tailbeam simulate` on the single-ball solver: the same run as the library's coupled
solver on the structure's own basis (the wiring), and the flat clamped plate's impact within
the solid-Mindlin difference of docs/structures.md (the physics); bad keys are refused in one
line, exit 2, nothing written."""

import csv

import numpy as np
import pytest
from solid_meshes import clamped_plate_scenes, plate_mesh

from tailbeam.cli.main import main
from tailbeam.io.scene_dump import dumps_scene
from tailbeam.io.scene_file import load_scene, loads_scene
from tailbeam.plate.solid import Support, assemble_structure, structure_modes
from tailbeam.solvers.coupled import simulate_coupled

FMAX = 3000.0  # Hz, the band of docs/structures.md's one-ball comparison
BALL = """
[[balls]]
name = "b"
material = "sandstone"
radius = 0.03
position = [0.05, 0.0, 0.0305]
velocity = [0.0, 0.0, -2.0]
"""
SENSOR = """
[[sensors]]
name = "S1"
position = [-0.1, 0.12]
"""
STRUCTURE, FLAT = clamped_plate_scenes("meshes/plate.msh", 0.002, FMAX)
# The solid's static compliance under the contact disc is 1.6 % below the Mindlin plate's
# on the 24 x 24 x 1 clamped plate (docs/structures.md): the contact sees that compliance in
# series with the Hertz contact, so restitution and peak force may differ by at most that.
SOLID_MINDLIN = 0.016


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The structure scene and the flat Mindlin scene through `tailbeam simulate`."""
    root = tmp_path_factory.mktemp("solid_scene")
    (root / "meshes").mkdir()
    plate_mesh(root / "meshes" / "plate.msh", divisions=24)
    out = {}
    for name, text in (("structure", STRUCTURE), ("flat", FLAT)):
        (root / f"{name}.toml").write_text(text + BALL + SENSOR)
        code = main(["simulate", str(root / f"{name}.toml"), "--out", str(root / name), "-q"])
        assert code == 0
        out[name] = _impact(root / name), _sensor(root / name)
    return root, out


def _impact(out) -> dict:
    with open(out / "impacts.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 1
    return {k: float(rows[0][k]) for k in ("restitution", "peak_force")}


def _sensor(out) -> np.ndarray:
    data = np.loadtxt(out / "sensors.csv", delimiter=",", skiprows=1)
    return data[:, 1]


def test_scene_runs_the_library_coupled_solver_on_the_structure(runs):
    root, out = runs
    scene = load_scene(root / "structure.toml")
    model = assemble_structure(root / "meshes" / "plate.msh", "top",
                               [Support("clamped", group="sides")])  # fmt: skip
    basis = structure_modes(model, fmax_hz=FMAX)
    res = simulate_coupled(scene.balls, basis, scene.contacts(), scene.duration,
                           sensors=scene.sensors, gravity=scene.gravity)  # fmt: skip
    (hit,) = res.impacts_of("b")
    impact, signal = out["structure"]
    assert impact["restitution"] == pytest.approx(hit.restitution, rel=1e-9)
    assert impact["peak_force"] == pytest.approx(hit.peak_force, rel=1e-9)
    library = np.asarray(res.sensor_signals["S1"][1])
    assert library.shape == signal.shape
    assert np.max(np.abs(signal - library)) <= 1e-9 * np.max(np.abs(library))


def test_flat_plate_mesh_matches_the_mindlin_plate(runs):
    _root, out = runs
    solid, flat = out["structure"][0], out["flat"][0]
    for key in ("restitution", "peak_force"):
        assert abs(solid[key] / flat[key] - 1.0) < SOLID_MINDLIN, key


def test_scene_round_trips_through_its_dump(runs):
    root, _out = runs
    scene = load_scene(root / "structure.toml")
    again = loads_scene(dumps_scene(scene))
    assert again.modal == scene.modal and again.plate == scene.plate


def _refused(tmp_path, capsys, text, field):
    (tmp_path / "bad.toml").write_text(text)
    code = main(["simulate", str(tmp_path / "bad.toml"), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert not (tmp_path / "out").exists()
    assert len(err) == 1 and field in err[0] and "Traceback" not in err[0], err
    return err[0]


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    root = tmp_path_factory.mktemp("solid_bad")
    (root / "meshes").mkdir()
    plate_mesh(root / "meshes" / "plate.msh", divisions=3)
    (root / "meshes" / "junk.msh").write_text("not a mesh\n")
    return root


SUPPORT = '[[plate.supports]]\ngroup = "sides"\nkind = "clamped"\n'
SENSOR_3D = '[[sensors]]\nname = "back"\nposition = [0.0, 0.0, -0.005]\n'  # inside: off the surface
BAD = {  # case: (text replaced, by, field named), "" replaced: appended
    "unreadable": ("plate.msh", "junk.msh", "plate.mesh"),
    "missing": ("plate.msh", "missing.msh", "plate.mesh"),
    "face": ('impact_face = "top"', 'impact_face = "roof"', "plate.impact_face"),
    "group": ('group = "sides"', 'group = "hinge"', "plate.supports[1].group"),
    "spring": ('kind = "clamped"', 'kind = "spring"', "plate.supports[1].stiffness"),
    "unheld": (SUPPORT, "", "plate.supports"),
    "size": ('model = "modal"', 'model = "modal"\nsize = [1, 1, 0.01]', "plate.size"),
    "rigid": ('model = "modal"\n', "", "plate.mesh"),
    "no mesh": ('mesh = "meshes/plate.msh"\n', "", "plate.impact_face"),
    "3D sensor": ("", SENSOR_3D, "sensors[1].position"),
}


@pytest.mark.parametrize("case", BAD)
def test_bad_structure_keys_are_one_line(small, tmp_path, capsys, case):
    old, new, field = BAD[case]
    text = STRUCTURE + BALL
    text = text + new if not old else text.replace(old, new)
    _refused(tmp_path, capsys, text.replace("meshes/", f"{small / 'meshes'}/"), field)
