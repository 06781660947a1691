"""A structure's modal basis and static compliances on disk (tailbeam.plate.solid.cached):
a cached basis equals the freshly solved one bit for bit (and the solver is not run again),
every field of the key misses when changed (a spring's stiffness, one mesh node, the face,
the material, the band, a hinge axis), the key ignores the mesh file's path and time, a
damaged file is recomputed with a one-line note, and the static compliances (the face
compliance matrix) read back equal the ones first computed, without solving again."""

import os
import shutil

import numpy as np
import pytest
from solid_meshes import box_mesh

from tailbeam.physics.materials import CARBON_STEEL, Material
from tailbeam.plate.solid import Support, assemble_structure, structure_modes
from tailbeam.plate.solid import cached as solid_cached
from tailbeam.plate.solid import modes as solid_modes
from tailbeam.plate.solid.cached import basis_key, static_key

FMAX = 4000.0  # Hz
FACES = {
    "top": lambda c, n: n[2] > 0.5,
    "left": lambda c, n: n[0] < -0.5,
    "right": lambda c, n: n[0] > 0.5,
}
SUPPORTS = (Support("pinned", group="left", axis=(0.0, 1.0, 0.0)),
            Support("spring", group="right", stiffness=2.0e6))  # fmt: skip


def _write(path, nudge=0.0):
    """A 0.4 x 0.2 x 0.02 m plate, 6 x 3 x 1 hexahedra; ``nudge`` m moves one node in x."""
    xs = np.linspace(-0.2, 0.2, 7)
    xs[3] += nudge
    return box_mesh(path, xs, np.linspace(-0.1, 0.1, 4), np.array([-0.02, 0.0]), FACES)


@pytest.fixture(scope="module")
def mesh(tmp_path_factory):
    return _write(tmp_path_factory.mktemp("solid_cache") / "plate.msh")


@pytest.fixture(scope="module")
def model(mesh):
    return assemble_structure(mesh, "top", SUPPORTS)


def _count_solves(monkeypatch):
    calls = []
    real = solid_modes.solve_band

    def counted(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(solid_modes, "solve_band", counted)
    return calls


def test_cached_basis_equals_fresh_bit_for_bit(model, tmp_path, monkeypatch):
    fresh = structure_modes(model, fmax_hz=FMAX, use_cache=False)
    assert fresh.info["cache"] == "off" and not list(tmp_path.iterdir())
    calls = _count_solves(monkeypatch)
    first = structure_modes(model, fmax_hz=FMAX, cache_dir=tmp_path)
    again = structure_modes(model, fmax_hz=FMAX, cache_dir=tmp_path)
    assert (first.info["cache"], again.info["cache"]) == ("miss", "hit")
    assert len(calls) == 1  # the second came from the file
    for basis in (first, again):
        assert np.array_equal(basis.frequencies_hz, fresh.frequencies_hz)
        assert np.array_equal(basis.mode_vectors, fresh.mode_vectors)
    pts = [[0.05, 0.03], [-0.12, -0.04]]
    assert np.array_equal(again.deflection(pts), fresh.deflection(pts))
    back = [[0.1, 0.0, -0.02]]
    assert np.array_equal(again.shape_at(back), fresh.shape_at(back))


def test_key_follows_content_not_path(mesh, model, tmp_path):
    copy = tmp_path / "elsewhere.msh"
    shutil.copy(mesh, copy)
    os.utime(copy, (1.0e9, 1.0e9))
    other = assemble_structure(copy, "top", SUPPORTS)
    assert basis_key(other, FMAX, None) == basis_key(model, FMAX, None)
    assert static_key(other) == static_key(model)


@pytest.mark.parametrize(
    "change",
    ["stiffness", "node", "face", "material", "band", "axis", "direction", "kind", "region"],
)
def test_any_key_field_misses(change, mesh, model, tmp_path):
    supports, face, material, fmax, path = list(SUPPORTS), "top", CARBON_STEEL, FMAX, mesh
    if change == "stiffness":
        supports[1] = Support("spring", group="right", stiffness=2.0e6 * (1 + 1e-12))
    elif change == "node":
        path = _write(tmp_path / "nudged.msh", nudge=1e-9)
    elif change == "face":  # the same facets under a second name: only the face differs
        path = assemble_structure(mesh, "top", SUPPORTS).vmesh
        path.faces["top-copy"] = path.faces["top"]
        model = assemble_structure(path, "top", SUPPORTS)
        face = "top-copy"
    elif change == "material":
        m = CARBON_STEEL
        material = Material("steel", m.density, m.youngs_modulus * 1.001, m.poisson_ratio)
    elif change == "band":
        fmax = FMAX + 1.0
    elif change == "axis":
        supports[0] = Support("pinned", group="left", axis=(0.0, 1.0, 1e-9))
    elif change == "direction":
        supports[1] = Support("spring", group="right", stiffness=2.0e6, direction=(1, 0, 0))
    elif change == "kind":
        supports[0] = Support("clamped", group="left")
    elif change == "region":
        supports[1] = Support("spring", region=((0.19, 0.21), (-0.1, 0.1), (-0.02, 0.0)),
                              stiffness=2.0e6)  # fmt: skip
    other = assemble_structure(path, face, supports, material=material)
    assert basis_key(other, fmax, None) != basis_key(model, FMAX, None)
    if change != "band":
        assert static_key(other) != static_key(model)


def test_damaged_file_is_recomputed_with_a_note(model, tmp_path, capsys):
    good = structure_modes(model, fmax_hz=FMAX, cache_dir=tmp_path)
    path = good.info["cache_file"]
    with open(path, "r+b") as fh:  # damage the middle of the file
        fh.seek(os.path.getsize(path) // 2)
        fh.write(b"\0" * 64)
    capsys.readouterr()
    again = structure_modes(model, fmax_hz=FMAX, cache_dir=tmp_path)
    err = capsys.readouterr().err
    assert again.info["cache"] == "miss"
    assert np.array_equal(again.mode_vectors, good.mode_vectors)
    lines = [line for line in err.splitlines() if "damaged" in line]
    assert len(lines) == 1 and path in lines[0] and "recomputing" in lines[0]
    assert structure_modes(model, fmax_hz=FMAX, cache_dir=tmp_path).info["cache"] == "hit"


def test_static_compliances_read_back(mesh, tmp_path, monkeypatch):
    pts = np.array([[0.05, 0.03], [-0.1, 0.02]])
    model = assemble_structure(mesh, "top", SUPPORTS)
    direct = model.static_compliance(pts, 0.004)  # the factorised solve
    basis = structure_modes(model, fmax_hz=FMAX, cache_dir=tmp_path)
    first = basis.static_compliance_at(pts, 0.004)
    # 6.8e-7 measured: round-off on a plate on a soft (2e6 N/m) spring, where the face
    # compliance and the direct solve differ most (tests/test_solid_face_readings.py)
    np.testing.assert_allclose(first, direct, rtol=1e-6)
    fresh_model = assemble_structure(mesh, "top", SUPPORTS)

    def no_solve(*args, **kwargs):
        raise AssertionError("the static compliance was solved again")

    monkeypatch.setattr(solid_cached, "face_green", no_solve)
    again = structure_modes(fresh_model, fmax_hz=FMAX, cache_dir=tmp_path)
    assert again.info["cache"] == "hit"
    assert np.array_equal(again.static_compliance_at(pts[::-1], 0.004), first[::-1])
    other = basis.static_compliance_at(pts, 0.005)  # a new radius: from the file, no solve
    assert np.array_equal(again.static_compliance_at(pts, 0.005), other)
    nowhere = structure_modes(assemble_structure(mesh, "top", SUPPORTS), fmax_hz=FMAX,
                              cache_dir=tmp_path / "empty")  # fmt: skip
    with pytest.raises(AssertionError, match="solved again"):  # no file: it is solved
        nowhere.static_compliance_at(pts, 0.004)


SCENE = f"""duration = 0.001
[plate]
model = "modal"
mesh = "plate.msh"
impact_face = "top"
fmax = {FMAX}
[[plate.supports]]
group = "left"
kind = "pinned"
axis = [0.0, 1.0, 0.0]
[[plate.supports]]
group = "right"
kind = "spring"
stiffness = 2.0e6
[[balls]]
name = "b"
material = "sandstone"
radius = 0.02
position = [0.0, 0.0, 0.0205]
velocity = [0.0, 0.0, -1.0]
"""


def test_modes_vtu_of_a_structure_reads_back(mesh, tmp_path, capsys):
    """`tailbeam modes SCENE --vtu`: modes.vtu read back with meshio holds the volume mesh
    and each mode's displacement, equal to shape_at's surface reading at the surface nodes
    along x, y and z; the frequencies (field data and frequencies.csv) are the basis'."""
    import csv

    import meshio

    from tailbeam.cli.main import main

    shutil.copy(mesh, tmp_path / "plate.msh")
    (tmp_path / "beam.toml").write_text(SCENE)
    out = tmp_path / "modes"
    assert main(["modes", str(tmp_path / "beam.toml"), "--vtu", "--out", str(out)]) == 0
    model = assemble_structure(mesh, "top", SUPPORTS)
    basis = structure_modes(model, fmax_hz=FMAX, use_cache=False)
    back = meshio.read(out / "modes.vtu")
    assert back.cells[0].type == "hexahedron" and len(back.cells[0].data) == 18
    assert np.array_equal(back.points, model.vmesh.mesh.p.T)
    assert np.allclose(back.field_data["frequencies_hz"], basis.frequencies_hz, rtol=1e-12)
    names = sorted(back.point_data)
    assert len(names) == basis.n_modes and names[0].startswith("mode_001_")
    shapes = np.stack([back.point_data[n] for n in names], axis=2)  # (p, 3, n)
    nodes = np.flatnonzero(np.isclose(back.points[:, 2], -0.02))[::3]  # on the bottom face
    for axis in range(3):
        dirs = np.tile(np.eye(3)[axis], (len(nodes), 1))
        expected = basis.shape_at(back.points[nodes], dirs)
        scale = np.abs(expected).max()
        assert np.allclose(shapes[nodes, axis, :], expected, rtol=0, atol=1e-9 * scale)
    with open(out / "frequencies.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert np.allclose([float(r["frequency_hz"]) for r in rows], basis.frequencies_hz, rtol=1e-9)
    capsys.readouterr()
    assert main(["modes", str(tmp_path / "beam.toml"), "--out", str(out)]) == 0
    assert "cache hit" in capsys.readouterr().out


def test_modes_scene_refuses_plate_options(mesh, tmp_path, capsys):
    from tailbeam.cli.main import main

    shutil.copy(mesh, tmp_path / "plate.msh")
    (tmp_path / "beam.toml").write_text(SCENE)
    out = tmp_path / "modes"
    for extra, name in ((["--bc", "CCCC"], "--bc"), (["--png"], "--png")):
        assert main(["modes", str(tmp_path / "beam.toml"), "--out", str(out), *extra]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and name in err[0]
        assert not out.exists()
