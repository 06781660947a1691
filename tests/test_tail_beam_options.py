"""The example beam's script (meshes/tail_beam.py) with its thickness options: by default it
writes the shipped mesh's geometry unchanged; with ``--top``, ``--bottom``, ``--rib`` the steel
volume is that of the plates and ribs its ``is_steel`` describes for those thicknesses
(skfem's quadrature over the written cells); bad options are one argparse line, exit 2."""

import importlib.util

import meshio
import numpy as np
import pytest
from skfem import Basis, ElementHex1

from tailbeam.plate.fe.mesh import MESH_DIR
from tailbeam.plate.solid import read_volume_mesh

pytest.importorskip("gmsh")


def _script():
    spec = importlib.util.spec_from_file_location("tail_beam", MESH_DIR / "tail_beam.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _steel_volume(script, plates) -> float:
    xs, ys, zs = script.breaks(plates)
    mid = [0.5 * (np.array(v[1:]) + np.array(v[:-1])) for v in (xs, ys, zs)]
    width = [np.diff(v) for v in (xs, ys, zs)]
    return sum(
        width[0][i] * width[1][j] * width[2][k]
        for i, x in enumerate(mid[0]) for j, y in enumerate(mid[1])
        for k, z in enumerate(mid[2]) if script.is_steel(x, y, z, plates)
    )  # fmt: skip


def test_default_is_the_shipped_geometry(tmp_path):
    script = _script()
    script.main(["--out", str(tmp_path / "beam.msh")])
    new, old = meshio.read(tmp_path / "beam.msh"), meshio.read(MESH_DIR / "tail_beam.msh")
    np.testing.assert_array_equal(new.points, old.points)
    for a, b in zip(new.cells, old.cells, strict=True):
        assert a.type == b.type
        np.testing.assert_array_equal(a.data, b.data)


def test_thickness_options_change_the_steel(tmp_path):
    script = _script()
    plates = script.Plates(top=0.04, bottom=0.03, rib=0.03)
    out = tmp_path / "thick.msh"
    script.main(["--top", "0.04", "--bottom", "0.03", "--rib", "0.03", "--out", str(out)])
    vmesh = read_volume_mesh(out)
    assert {"top", "hinge", "jack"} <= set(vmesh.faces)
    volume = Basis(vmesh.mesh, ElementHex1()).dx.sum()
    assert np.isclose(volume, _steel_volume(script, plates), rtol=1e-9)
    assert volume > 1.2 * _steel_volume(script, script.Plates())  # more steel than the default


@pytest.mark.parametrize(
    ("args", "words"),
    [(["--rib", "-0.01"], "--rib: must be > 0"), (["--rib", "0.2"], "--rib: must be below"),
     (["--top", "0.2", "--bottom", "0.15"], "below the depth")],
)  # fmt: skip
def test_bad_options_are_one_line_exit_2(tmp_path, capsys, args, words):
    with pytest.raises(SystemExit) as stop:
        _script().main([*args, "--out", str(tmp_path / "x.msh")])
    assert stop.value.code == 2
    assert words in capsys.readouterr().err
    assert not (tmp_path / "x.msh").exists()
