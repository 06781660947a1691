"""Meshes with named edges, bad input, and the modal cache."""

import meshio
import numpy as np
import pytest
from skfem import MeshTri

from tailbeam.errors import InputError
from tailbeam.physics.bodies import Plate
from tailbeam.physics.materials import Material
from tailbeam.plate import compute_modes, load_mesh, save_mesh, structured_mesh
from tailbeam.plate.cache import cache_key
from tailbeam.plate.closed_forms import levy_frequencies
from tailbeam.plate.fe import modes as fe_modes
from tailbeam.plate.fe.mesh import MESH_DIR, default_mesh_path

PLATE = Plate()


def test_structured_mesh_has_named_edges_on_the_plate_edges():
    mesh = structured_mesh(PLATE, 5)
    for name, axis, value in (
        ("left", 0, -0.3),
        ("bottom", 1, -0.3),
        ("right", 0, 0.3),
        ("top", 1, 0.3),
    ):
        mid = mesh.p[:, mesh.facets[:, mesh.boundaries[name]]].mean(axis=1)
        assert len(mesh.boundaries[name]) == 5
        np.testing.assert_allclose(mid[axis], value)


def test_shipped_default_meshes_equal_the_generated_ones():
    files = sorted(MESH_DIR.glob("plate_0.6x0.6_*.msh"))
    assert files, "no default meshes in meshes/"
    for path in files:
        n = int(path.stem.split("_")[-1].split("x")[0])
        assert default_mesh_path(PLATE, n) == path
        assert path.stat().st_size < 1_000_000
        read, made = load_mesh(path, PLATE), structured_mesh(PLATE, n)
        np.testing.assert_array_equal(read.p, made.p)
        np.testing.assert_array_equal(read.t, made.t)
        for name in ("left", "bottom", "right", "top"):
            np.testing.assert_array_equal(
                np.sort(read.boundaries[name]), np.sort(made.boundaries[name])
            )


def test_mesh_file_round_trip_gives_the_same_modes(tmp_path):
    path = save_mesh(structured_mesh(PLATE, 6), tmp_path / "p.msh")
    by_file = compute_modes(PLATE, "CSFS", theory="kirchhoff", count=5, mesh=path, use_cache=False)
    by_div = compute_modes(PLATE, "CSFS", theory="kirchhoff", count=5, divisions=6, use_cache=False)
    np.testing.assert_allclose(by_file.frequencies_hz, by_div.frequencies_hz, rtol=1e-12)


def test_mesh_without_named_edges_is_refused(tmp_path):
    mesh = structured_mesh(PLATE, 4)
    path = tmp_path / "plain.vtu"
    meshio.write(path, meshio.Mesh(mesh.p.T, [("triangle", mesh.t.T)]))
    with pytest.raises(InputError) as err:
        compute_modes(PLATE, "SSSS", count=2, mesh=path, use_cache=False)
    assert err.value.field == "mesh" and "left" in err.value.rule
    with pytest.raises(InputError, match="mesh"):
        compute_modes(PLATE, "SSSS", count=2, mesh=MeshTri(mesh.p, mesh.t), use_cache=False)


@pytest.mark.parametrize(
    "call, field",
    [
        (lambda: compute_modes(PLATE, "SSXS", count=2), "boundary"),
        (lambda: compute_modes(PLATE, "SSS", count=2), "boundary"),
        (lambda: compute_modes(Plate(thickness=-0.01), "SSSS", count=2), "plate.thickness"),
        (
            lambda: compute_modes(PLATE, "SSSS", fmax_hz=50.0, divisions=4, use_cache=False),
            "fmax_hz",
        ),
        (lambda: compute_modes(PLATE, "SSSS", fmax_hz=-1.0), "fmax_hz"),
        (lambda: compute_modes(PLATE, "SSSS", count=0), "count"),
        (lambda: compute_modes(PLATE, "SSSS", theory="plate", count=2), "theory"),
        (lambda: compute_modes(PLATE, "SSSS", count=2, divisions=0), "divisions"),
        (lambda: compute_modes(PLATE, "SSSS", count=2, accuracy=0.0), "accuracy"),
        (lambda: compute_modes(PLATE, "SSSS", count=2, mesh="/nonexistent.msh"), "mesh"),
    ],
)
def test_bad_input_names_the_field(call, field, tmp_path, monkeypatch):
    monkeypatch.setenv("TAILBEAM_CACHE_DIR", str(tmp_path))
    with pytest.raises(InputError) as err:
        call()
    assert err.value.field == field


def test_cache_reload_equals_computed_and_solves_nothing(tmp_path, monkeypatch):
    kw = dict(theory="kirchhoff", fmax_hz=3000.0, divisions=8, cache_dir=tmp_path)
    cold = compute_modes(PLATE, "SSSS", **kw)

    def no_solve(*args, **kwargs):
        raise AssertionError("a cache hit assembled or solved the FE model")

    with monkeypatch.context() as mp:  # the reload does no FE work (what takes the time)
        mp.setattr(fe_modes, "_solve_fresh", no_solve)
        mp.setattr(fe_modes, "assemble_plate", no_solve)
        warm = compute_modes(PLATE, "SSSS", **kw)
    assert cold.info["cache"] == "miss" and warm.info["cache"] == "hit"
    np.testing.assert_array_equal(warm.frequencies_hz, cold.frequencies_hz)
    pts = np.array([[0.01, 0.02], [-0.2, 0.25]])
    np.testing.assert_allclose(warm.deflection(pts), cold.deflection(pts), rtol=1e-12)
    np.testing.assert_allclose(
        warm.static_compliance_at(pts, 0.0), cold.static_compliance_at(pts, 0.0), rtol=1e-10
    )
    # a different band is a different entry, never the stored one
    other = compute_modes(PLATE, "SSSS", **{**kw, "fmax_hz": 2000.0})
    assert other.info["cache"] == "miss" and other.n_modes < cold.n_modes


def test_a_process_reads_a_cache_file_once_and_again_when_it_changes(tmp_path):
    kw = dict(theory="kirchhoff", fmax_hz=2000.0, divisions=6, cache_dir=tmp_path)
    compute_modes(PLATE, "SSSS", **kw)  # computed and stored (a miss)
    first = compute_modes(PLATE, "SSSS", **kw, accuracy=0.02)
    second = compute_modes(PLATE, "SSSS", **kw, accuracy=0.03)
    assert first.info["cache"] == second.info["cache"] == "hit"
    assert second.mode_vectors is first.mode_vectors  # read once: the same arrays
    assert (first.info["accuracy"], second.info["accuracy"]) == (0.02, 0.03)  # own info
    path = first.info["cache_file"]
    with open(path, "wb") as fh:  # replaced on disk (size and time change): read again
        fh.write(b"not a zip file")
    again = compute_modes(PLATE, "SSSS", **kw)
    assert again.info["cache"] == "miss"
    np.testing.assert_array_equal(again.frequencies_hz, first.frequencies_hz)


def test_every_input_changes_the_cache_key():
    mesh = structured_mesh(PLATE, 4)
    base = dict(
        plate=PLATE,
        boundary="SSSS",
        theory="mindlin",
        element="lagrange-p4",
        mesh=mesh,
        fmax_hz=1e4,
        count=None,
    )
    steel = PLATE.material
    variants = {
        "density": {
            "plate": Plate(
                material=Material("x", 7851.0, steel.youngs_modulus, steel.poisson_ratio)
            )
        },
        "modulus": {
            "plate": Plate(material=Material("x", steel.density, 2.0e11, steel.poisson_ratio))
        },
        "poisson": {
            "plate": Plate(material=Material("x", steel.density, steel.youngs_modulus, 0.3))
        },
        "thickness": {"plate": Plate(thickness=0.011)},
        "size": {"plate": Plate(size_x=0.61)},
        "boundary": {"boundary": "SSSC"},
        "theory": {"theory": "kirchhoff"},
        "element": {"element": "lagrange-p3"},
        "mesh": {"mesh": structured_mesh(PLATE, 5)},
        "mesh_edges": {"mesh": MeshTri(mesh.p, mesh.t, {"left": mesh.boundaries["left"]})},
        "fmax": {"fmax_hz": 1.1e4},
        "count": {"count": 50},
    }
    keys = {"base": cache_key(**base)}
    for name, change in variants.items():
        keys[name] = cache_key(**{**base, **change})
    assert cache_key(**base) == keys["base"]  # deterministic
    assert len(set(keys.values())) == len(keys)
    # the material's name is not physics: same numbers, same key
    renamed = Plate(
        material=Material("other", steel.density, steel.youngs_modulus, steel.poisson_ratio)
    )
    assert cache_key(**{**base, "plate": renamed}) == keys["base"]


def test_a_damaged_cache_entry_is_recomputed(tmp_path):
    kw = dict(theory="kirchhoff", count=3, divisions=4, cache_dir=tmp_path)
    first = compute_modes(PLATE, "SSSS", **kw)
    path = first.info["cache_file"]
    with open(path, "wb") as fh:
        fh.write(b"not a zip file")
    again = compute_modes(PLATE, "SSSS", **kw)
    assert again.info["cache"] == "miss"
    np.testing.assert_allclose(again.frequencies_hz, first.frequencies_hz)


def test_auto_theory_records_its_choice():
    low = compute_modes(PLATE, "SSSS", fmax_hz=1000.0, accuracy=0.05, use_cache=False)
    high = compute_modes(PLATE, "SSSS", fmax_hz=2000.0, accuracy=1e-3, use_cache=False)
    assert low.theory == "kirchhoff" and "suffices" in low.info["reason"]
    assert high.theory == "mindlin" and "Mindlin" in high.info["reason"]


def test_an_unwritable_cache_does_not_lose_the_result(tmp_path):
    blocker = tmp_path / "not_a_dir"
    blocker.write_text("x")
    basis = compute_modes(
        PLATE, "SSSS", theory="kirchhoff", count=3, divisions=4, cache_dir=blocker / "cache"
    )
    assert basis.n_modes == 3 and basis.info["cache"].startswith("not written")


def test_an_irregular_user_mesh_works():
    # interior nodes moved randomly by up to 30 % of a cell: general triangles, same edges
    mesh = structured_mesh(PLATE, 12)
    pts = mesh.p.copy()
    inside = np.ones(pts.shape[1], dtype=bool)
    inside[mesh.boundary_nodes()] = False
    rng = np.random.default_rng(1)
    pts[:, inside] += rng.uniform(-0.015, 0.015, (2, int(inside.sum())))
    irregular = MeshTri(pts, mesh.t, mesh.boundaries)
    exact = levy_frequencies(PLATE, "CSFS", 1500.0)
    basis = compute_modes(
        PLATE, "CSFS", theory="kirchhoff", count=len(exact), mesh=irregular, use_cache=False
    )
    np.testing.assert_allclose(basis.frequencies_hz, exact, rtol=1e-4)
