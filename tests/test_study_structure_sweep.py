"""`tailbeam sweep` over a structure's parameters: the jack spring's stiffness
(``plate.supports[i].stiffness``) and the mesh itself (``plate.mesh``, a list of mesh files:
the geometric parameter by re-meshing), with sensors on the structure's surface read along
directions and three axes. Truth: each case's signals against the same scene written out by
hand with that value and simulated here, the structure's modes solved afresh in a cache folder
of their own (so a basis served for the wrong value, or a value set on the wrong support,
shows); bad values: one line naming the swept key, exit 2, nothing written."""

import numpy as np
import pytest

pytest.importorskip("dask.distributed")
pytest.importorskip("xarray")

import pandas as pd  # noqa: E402
import xarray as xr  # noqa: E402
from solid_meshes import box_mesh  # noqa: E402

from tailbeam.cli import main  # noqa: E402
from tailbeam.io.scene_file import loads_scene  # noqa: E402
from tailbeam.plate.solid.cached import MATRICES_PREFIX, MESH_PREFIX, STATIC_PREFIX  # noqa: E402
from tailbeam.plate.solid.face.influence import PREFIX as INFLUENCE_PREFIX  # noqa: E402
from tailbeam.simulation import simulate  # noqa: E402

LENGTH, WIDTH = 0.4, 0.2
STIFFNESS = (1.0e4, 1.0e6)  # N/m: below and above the cantilever's own tip stiffness ~1.6e5
THICKNESS = {"thin.msh": 0.010, "thick.msh": 0.012}

SCENE = """duration = 0.004
[plate]
model = "modal"
mesh = "{mesh}"
impact_face = "top"
fmax = 2000.0
tail = "quasi-static"
[[plate.supports]]
group = "root"
kind = "clamped"
[[plate.supports]]
group = "pad"
kind = "spring"
stiffness = {stiffness}
[[balls]]
name = "rock"
material = "sandstone"
radius = 0.02
position = [0.1, 0.0, 0.0205]
velocity = [0.0, 0.0, -1.0]
[[sensors]]
name = "top"
position = [0.0, 0.05]
sample_rate = 8000.0
[[sensors]]
name = "tip"
position = [0.2, 0.0, -0.004]
axes = "xz"
sample_rate = 8000.0
[[sensors]]
name = "side"
position = [0.0, 0.1, -0.004]
direction = [0.0, 0.6, 0.8]
sample_rate = 8000.0
"""

SIGNALS = ["top", "tip_x", "tip_z", "side"]


def _cantilever(path, thickness):
    """A 0.4 x 0.2 m steel plate clamped at x = -0.2 ('root'), a spring patch under its free
    end ('pad': the bottom face at x > 0.1), 8 x 4 x 1 hexahedra."""
    xs = np.linspace(-0.5 * LENGTH, 0.5 * LENGTH, 9)
    ys = np.linspace(-0.5 * WIDTH, 0.5 * WIDTH, 5)
    faces = {"top": lambda c, n: n[2] > 0.5, "root": lambda c, n: n[0] < -0.5,
             "pad": lambda c, n: n[2] < -0.5 and c[0] > 0.1}  # fmt: skip
    return box_mesh(path, xs, ys, [-thickness, 0.0], faces)


@pytest.fixture(scope="module")
def meshes(tmp_path_factory):
    root = tmp_path_factory.mktemp("structure_sweep")
    (root / "meshes").mkdir()
    for name, h in THICKNESS.items():
        _cantilever(root / "meshes" / name, h)
    return root


def _write(root, axes: str, base_mesh="meshes/thin.msh") -> str:
    (root / "base.toml").write_text(SCENE.format(mesh=base_mesh, stiffness=STIFFNESS[0]))
    (root / "sweep.toml").write_text(f'scene = "base.toml"\n[axes]\n{axes}')
    return str(root / "sweep.toml")


@pytest.fixture(scope="module")
def swept(meshes, tmp_path_factory):
    """The 2 x 2 sweep over the jack's stiffness (the support picked by its group) and the
    mesh, on one local worker, with a cache folder of its own."""
    cache = tmp_path_factory.mktemp("structure_sweep_cache")
    axes = (f'"plate.supports.pad.stiffness" = [{STIFFNESS[0]}, {STIFFNESS[1]}]\n'
            '"plate.mesh" = ["meshes/thin.msh", "meshes/thick.msh"]\n')  # fmt: skip
    with pytest.MonkeyPatch.context() as mp:
        from tailbeam.cachedir import numba_cache_dir

        mp.setenv("NUMBA_CACHE_DIR", str(numba_cache_dir()))
        mp.setenv("TAILBEAM_CACHE_DIR", str(cache))
        out = meshes / "out"
        code = main(["sweep", _write(meshes, axes), "--out", str(out), "--workers", "1"])
    return code, out, cache


def _direct(meshes, mesh: str, stiffness: float, cache) -> dict:
    """The scene with these values, written here and simulated in this process, its modes
    solved afresh (an empty cache folder)."""
    text = SCENE.format(mesh=meshes / "meshes" / mesh, stiffness=stiffness)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("TAILBEAM_CACHE_DIR", str(cache))
        result = simulate(loads_scene(text))
    return {name: a for name, (_t, a) in result.sensor_signals.items()}


def test_each_case_runs_on_the_structure_of_its_values(swept, meshes, tmp_path):
    code, out, cache = swept
    assert code == 0
    # one basis per stiffness and mesh, solved in the warm-up and cached (beside each, its
    # impact face's static compliance, structure-face-compliance-*.npz; the mesh as read and
    # K's nonzero count, structure-mesh-*.npz and structure-matrices-*.npz; the sensors' static
    # influences, structure-sensor-influence-*.npz)
    others = (STATIC_PREFIX, MESH_PREFIX, MATRICES_PREFIX, INFLUENCE_PREFIX)
    bases = [p for p in cache.glob("structure-*.npz") if not p.name.startswith(others)]
    assert len(bases) == 4
    ds = xr.open_zarr(out / "dataset.zarr")
    assert list(ds["sensor"].values) == SIGNALS
    cases = pd.read_csv(out / "cases.csv")
    assert sorted(
        zip(cases["plate.supports.pad.stiffness"], cases["plate.mesh"], strict=True)
    ) == sorted((k, m) for k in STIFFNESS for m in ("meshes/thin.msh", "meshes/thick.msh"))
    truths = {}
    for mesh in THICKNESS:
        for k in STIFFNESS:
            truths[mesh, k] = _direct(meshes, mesh, k, tmp_path / f"{mesh}-{k:g}")
    for _i, row in cases.iterrows():
        one = ds.sel(case=row["case"])
        mesh = row["plate.mesh"].split("/")[-1]
        truth = truths[mesh, row["plate.supports.pad.stiffness"]]
        for s, name in enumerate(SIGNALS):
            got, want = one["acceleration"].values[s], truth[name]
            scale = np.max(np.abs(want))
            assert scale > 0
            assert np.max(np.abs(got - want)) <= 1e-5 * scale, (mesh, name)
        # the other stiffness, or the other mesh, reads differently: the check has teeth
        k = row["plate.supports.pad.stiffness"]
        k_other = STIFFNESS[1] if k == STIFFNESS[0] else STIFFNESS[0]
        mesh_other = "thick.msh" if mesh == "thin.msh" else "thin.msh"
        for wrong in (truths[mesh, k_other]["tip_z"], truths[mesh_other, k]["tip_z"]):
            miss = np.max(np.abs(one["acceleration"].values[2] - wrong))
            assert miss > 1e-2 * np.max(np.abs(wrong))


def test_the_dataset_places_every_signal(swept):
    _code, out, _cache = swept
    ds = xr.open_zarr(out / "dataset.zarr")
    place = np.stack([ds[c].values[0] for c in ("sensor_x", "sensor_y", "sensor_z")], axis=1)
    np.testing.assert_allclose(
        place, [[0.0, 0.05, 0.0], [0.2, 0.0, -0.004], [0.2, 0.0, -0.004], [0.0, 0.1, -0.004]]
    )
    along = np.stack([ds[c].values[0] for c in ("sensor_dx", "sensor_dy", "sensor_dz")], axis=1)
    np.testing.assert_allclose(along, [[0, 0, 1], [1, 0, 0], [0, 0, 1], [0, 0.6, 0.8]], atol=1e-15)


BAD = {  # axis line -> (field the one line names, words of the rule)
    '"plate.supports[2].stiffness" = [1.0e5, -1.0]': ("plate.supports[2].stiffness", "> 0"),
    '"plate.mesh" = ["meshes/thin.msh", "meshes/none.msh"]': ("plate.mesh", "cannot read"),
    '"plate.supports.jack.stiffness" = [1.0e5]': ('axes."plate.supports.jack.stiffness"', "jack"),
}


@pytest.mark.parametrize("axis", BAD)
def test_bad_structure_values_are_one_line_naming_the_key(meshes, tmp_path, capsys, axis):
    field, words = BAD[axis]
    sweep = _write(meshes, axis + "\n")
    code = main(["sweep", sweep, "--out", str(tmp_path / "out"), "--workers", "1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert not (tmp_path / "out").exists()
    assert len(err) == 1 and field in err[0] and words in err[0], err
    if "case 2" in err[0]:  # the case's swept value is shown with the key it was swept by
        assert axis.split('"')[1] in err[0]
