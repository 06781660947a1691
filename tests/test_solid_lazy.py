"""A structure built without its matrices (tailbeam.plate.solid.model): the DOF numbering,
supports, readings and checks come from the mesh and a basis without quadrature points, and
K and M are assembled on first use. Checked against an independent eager build (the vector
basis with its quadrature, the supports applied on it, K and M assembled and reduced as
``assemble_elasticity`` does): the same transform, spring, K and M bit for bit, the same
readings; a run whose basis is cached (modes, the run-cost estimate, a face compliance read
back) assembles nothing; the count of K's nonzeros kept on disk equals the assembled K's;
a free structure is still refused without assembling; a listing of the cached modes (what
`tailbeam modes` prints and writes) reads the same frequencies and info as the basis,
without its vectors, and the cached command writes the solved run's frequencies.csv; the
volume mesh kept under its file's SHA-256 reads back equal to the file's own read."""

import shutil
from pathlib import Path

import numpy as np
import pytest
from skfem import MeshTet
from solid_meshes import box_mesh

from tailbeam.errors import InputError
from tailbeam.physics.materials import CARBON_STEEL
from tailbeam.plate.solid import Support, assemble_structure, structure_modes
from tailbeam.plate.solid import cached as solid_cached
from tailbeam.plate.solid.cost import structure_cost
from tailbeam.plate.solid.elasticity import assemble_elasticity
from tailbeam.plate.solid.held import mesh_digest
from tailbeam.plate.solid.modes import cached_listing
from tailbeam.plate.solid.probe import DisplacementProbe
from tailbeam.plate.solid.supports import apply_supports, free_rigid_motions
from tailbeam.plate.solid.volume_mesh import read_volume_mesh

FACES = {
    "top": lambda c, n: n[2] > 0.5,
    "left": lambda c, n: n[0] < -0.5,
    "right": lambda c, n: n[0] > 0.5,
}
SUPPORTS = (Support("pinned", group="left", axis=(0.0, 1.0, 0.0)),
            Support("spring", group="right", stiffness=2.0e6))  # fmt: skip
GRID = (np.linspace(-0.2, 0.2, 7), np.linspace(-0.1, 0.1, 4), np.array([-0.02, 0.0]))


@pytest.fixture(scope="module", params=["hex", "tet"])
def mesh(request, tmp_path_factory):
    path = tmp_path_factory.mktemp("solid_lazy") / f"{request.param}.msh"
    cell = {"tet": MeshTet}.get(request.param)
    return box_mesh(path, *GRID, FACES, **({"cell": cell} if cell else {}))


def _eager(model):
    """(transform, spring, K, M) built the independent way, from the quadrature basis."""
    elastic = assemble_elasticity(model.vmesh.mesh, model.vmesh.kind, CARBON_STEEL)
    cons = apply_supports(elastic.basis, model.vmesh, SUPPORTS, ["a", "b"])
    assert free_rigid_motions(elastic.basis, cons) == model.rigid_modes == 0
    t = cons.transform
    k = (t.T @ ((elastic.stiffness + cons.spring) @ t)).tocsr()
    return t, cons.spring, k, (t.T @ (elastic.mass @ t)).tocsr()


def _same(a, b) -> bool:
    a, b = a.tocsr(), b.tocsr()
    parts = ("indptr", "indices", "data")
    return a.shape == b.shape and all(np.array_equal(getattr(a, k), getattr(b, k)) for k in parts)


def test_lazy_model_equals_the_eager_build_bit_for_bit(mesh):
    model = assemble_structure(mesh, "top", SUPPORTS)
    assert not model.assembled
    t, spring, k, m = _eager(model)
    assert _same(model.transform, t) and _same(model.spring, spring)
    assert model.n_dofs == t.shape[1]
    assert not model.assembled  # the DOF count, transform and springs need no assembly
    assert _same(model.stiffness, k) and _same(model.mass, m)
    assert model.assembled


def test_readings_need_no_assembly_and_match_the_quadrature_basis(mesh):
    model = assemble_structure(mesh, "top", SUPPORTS)
    elastic = assemble_elasticity(model.vmesh.mesh, model.vmesh.kind, CARBON_STEEL)
    assert np.array_equal(model.basis.doflocs, elastic.basis.doflocs)
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-0.19, 0.19, 5), rng.uniform(-0.09, 0.09, 5)])
    face = model.face_operator(pts)
    back = model.surface_operator(np.column_stack([pts, np.full(5, -0.02)]))
    assert not model.assembled
    probe = DisplacementProbe(elastic.basis)  # readings through the quadrature basis
    cells = model.face.cells_at(pts)
    xyz = np.column_stack([pts, np.zeros(5)])
    dirs = np.tile([0.0, 0.0, 1.0], (5, 1))
    assert _same(face, (probe.operator(xyz, cells, dirs) @ model.transform).tocsr())
    assert back.shape == (5, model.n_dofs)


def test_cached_run_assembles_nothing(mesh, tmp_path, monkeypatch):
    monkeypatch.setenv("TAILBEAM_CACHE_DIR", str(tmp_path))
    first = assemble_structure(mesh, "top", SUPPORTS)
    solved = structure_modes(first, fmax_hz=4000.0, cache_dir=tmp_path)
    cost = structure_cost(first, 4000.0)  # K assembled: its own count, kept on disk
    assert first.assembled
    solved.static_compliance_at([[0.05, 0.02]], 0.01)  # the face compliance, made and kept

    again = assemble_structure(mesh, "top", SUPPORTS)
    basis = structure_modes(again, fmax_hz=4000.0, cache_dir=tmp_path)
    assert basis.info["cache"] == "hit"
    assert structure_cost(again, 4000.0) == cost
    assert solid_cached.stiffness_nnz(again) == first.stiffness.nnz
    value = basis.static_compliance_at([[0.05, 0.02]], 0.01)
    basis.deflection([[0.1, 0.0]])
    basis.shape_at([[0.1, 0.0, -0.02]])
    assert not again.assembled
    assert value == solved.static_compliance_at([[0.05, 0.02]], 0.01)


def test_nonzero_count_file_missing_or_damaged_is_recounted(mesh, tmp_path):
    model = assemble_structure(mesh, "top", SUPPORTS)
    key = solid_cached.matrices_key(model)
    path = tmp_path / f"{solid_cached.MATRICES_PREFIX}-{key[:32]}.npz"
    assert solid_cached.stiffness_nnz(model, tmp_path) == model.stiffness.nnz
    assert path.is_file()
    path.write_bytes(b"not a zip")
    fresh = assemble_structure(mesh, "top", SUPPORTS)
    assert solid_cached.stiffness_nnz(fresh, tmp_path) == model.stiffness.nnz
    assert fresh.assembled  # counted again from the assembled K, and the file rewritten
    other = assemble_structure(mesh, "top", SUPPORTS)
    assert solid_cached.stiffness_nnz(other, tmp_path) == model.stiffness.nnz
    assert not other.assembled


def test_free_structure_refused_without_assembly(mesh):
    with pytest.raises(InputError, match="not held"):
        assemble_structure(mesh, "top", SUPPORTS[1:])
    free = assemble_structure(mesh, "top", (), free=True)
    assert free.rigid_modes == 6 and not free.assembled


def test_cached_listing_reads_the_basis_frequencies_without_vectors(mesh, tmp_path):
    model = assemble_structure(mesh, "top", SUPPORTS)
    assert cached_listing(model, fmax_hz=4000.0, cache_dir=tmp_path) is None  # no file
    basis = structure_modes(model, fmax_hz=4000.0, cache_dir=tmp_path)
    again = structure_modes(model, fmax_hz=4000.0, cache_dir=tmp_path)
    listing = cached_listing(model, fmax_hz=4000.0, cache_dir=tmp_path)
    assert np.array_equal(listing.frequencies_hz, basis.frequencies_hz)
    assert listing.info == again.info and listing.info["cache"] == "hit"
    assert (listing.boundary, listing.theory, listing.n_modes) == (
        basis.boundary, basis.theory, basis.n_modes)  # fmt: skip
    assert cached_listing(model, fmax_hz=3000.0, cache_dir=tmp_path) is None  # another band
    Path(listing.info["cache_file"]).write_bytes(b"damaged")
    assert cached_listing(model, fmax_hz=4000.0, cache_dir=tmp_path) is None


def test_cached_modes_command_writes_the_solved_frequencies(mesh, tmp_path, capsys, monkeypatch):
    from test_solid_cache import SCENE

    monkeypatch.setenv("TAILBEAM_CACHE_DIR", str(tmp_path / "cache"))  # a cache of its own

    from tailbeam.cli.main import main

    shutil.copy(mesh, tmp_path / "plate.msh")
    (tmp_path / "beam.toml").write_text(SCENE)
    runs = []
    for i in range(2):
        out = tmp_path / f"modes{i}"
        assert main(["modes", str(tmp_path / "beam.toml"), "--out", str(out)]) == 0
        runs.append(((out / "frequencies.csv").read_bytes(), capsys.readouterr().out))
    assert "cache miss" in runs[0][1] and "cache hit" in runs[1][1]
    assert runs[0][0] == runs[1][0]


def test_mesh_read_back_from_the_cache_equals_the_file_read(mesh, tmp_path, capsys):
    fresh = read_volume_mesh(mesh)
    digest = mesh_digest(mesh)
    first = solid_cached.read_mesh(mesh, digest, tmp_path)  # read from the file, kept
    again = solid_cached.read_mesh(mesh, digest, tmp_path)  # from the cache
    for got in (first, again):
        assert type(got.mesh) is type(fresh.mesh) and got.kind == fresh.kind
        for name in ("p", "t", "facets", "t2f", "f2t"):
            assert np.array_equal(getattr(got.mesh, name), getattr(fresh.mesh, name))
        for kind in ("faces", "volumes"):
            ours, theirs = getattr(got, kind), getattr(fresh, kind)
            assert ours.keys() == theirs.keys()
            assert all(np.array_equal(ours[k], theirs[k]) for k in ours)
    assert again.source == str(mesh)
    (entry,) = tmp_path.glob(f"{solid_cached.MESH_PREFIX}-*.npz")
    entry.write_bytes(b"damaged")
    capsys.readouterr()
    back = solid_cached.read_mesh(mesh, digest, tmp_path)
    assert "damaged" in capsys.readouterr().err
    assert np.array_equal(back.mesh.t, fresh.mesh.t)
    other = solid_cached.read_mesh(mesh, "0" * 64, tmp_path)  # another content: another file
    assert len(list(tmp_path.glob(f"{solid_cached.MESH_PREFIX}-*.npz"))) == 2
    assert np.array_equal(other.mesh.p, fresh.mesh.p)
