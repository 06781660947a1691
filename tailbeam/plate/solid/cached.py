"""A structure's modal basis and static compliances on disk (``tailbeam.plate.cache``).

The key (``basis_key``) is a SHA-256 over everything that determines the basis: the mesh's
content as read (node coordinates, cells and every named face and cell group; not the
file's path or time), the element, the material (density, Young's modulus, Poisson ratio),
the impact face, every support (kind, group or region, stiffness, direction, axis), whether
rigid-body modes are left free, the band (fmax, count) and the cache format and package
version. Any change gives another file, so a stale basis is never reused; the key is also
stored in the file and checked on load. A damaged file is recomputed and overwritten, with
a note.

The static compliances under contact discs (the residual flexibility's K^-1) come from the
impact face's compliance matrix (``tailbeam.plate.solid.face.compliance``: minutes of solves
on the example beam), kept beside the basis, one file per structure (``static_key``: the
same key without the band; ``StaticCompliances``).

The volume mesh as read (``read_mesh``: the skfem mesh's nodes and cells, and the named
groups) is kept under the mesh file's SHA-256, so a later run neither imports meshio nor
parses the file. The run-cost estimate needs the count of K's nonzeros (``stiffness_nnz``):
it is kept in a small per-structure file too (``matrices_key``), so that a run whose basis
and compliances are cached assembles nothing.
"""

import dataclasses
import json
import zipfile
from pathlib import Path

import numpy as np
from skfem import MeshHex, MeshTet

from tailbeam.plate import cache as disk
from tailbeam.plate.solid.face.compliance import FaceCompliance, face_dofs, face_green
from tailbeam.plate.solid.model import StructureModel
from tailbeam.plate.solid.volume_mesh import VolumeMesh, read_volume_mesh
from tailbeam.progress import note

BASIS_PREFIX = "structure"
STATIC_PREFIX = "structure-face-compliance"
MATRICES_PREFIX = "structure-matrices"
MESH_PREFIX = "structure-mesh"
ROUND = 12  # decimals (m) of a point's and a radius' key in the direct solves' memo


def _model_meta(model: StructureModel) -> dict:
    mat = model.plate.material
    return {
        "kind": "solid structure",
        "element": model.element,
        "cell": model.vmesh.kind,
        "material": [float(mat.density), float(mat.youngs_modulus), float(mat.poisson_ratio)],
        "impact_face": model.face.name,
        "supports": [dataclasses.asdict(s) for s in model.supports],
        "rigid_body_modes_free": int(model.rigid_modes),
    }


def _mesh_arrays(model: StructureModel):
    """(name, array) pairs of the mesh's content: points, cells and the named groups."""
    vmesh = model.vmesh
    yield "p", np.asarray(vmesh.mesh.p, dtype=np.float64)
    yield "t", np.asarray(vmesh.mesh.t, dtype=np.int64)
    for kind, groups in (("face", vmesh.faces), ("volume", vmesh.volumes)):
        for name in sorted(groups):
            yield f"{kind}:{name}", np.sort(np.asarray(groups[name], dtype=np.int64))


def basis_key(model: StructureModel, fmax_hz, count) -> str:
    """Hex key of the basis of ``model`` below ``fmax_hz`` Hz and/or the first ``count``."""
    band = {"fmax_hz": None if fmax_hz is None else float(fmax_hz),
            "count": None if count is None else int(count)}  # fmt: skip
    return disk.entry_key({**_model_meta(model), **band}, _mesh_arrays(model))


def static_key(model: StructureModel) -> str:
    """Hex key of the static compliances of ``model`` (no band)."""
    return disk.entry_key({**_model_meta(model), "static": True}, _mesh_arrays(model))


def read_mesh(path, digest: str, cache_dir=None) -> VolumeMesh:
    """The volume mesh of the file ``path`` whose bytes' SHA-256 is ``digest`` (hex): from
    ``structure-mesh-<key>.npz`` (``cache_dir``, default $TAILBEAM_CACHE_DIR or
    ~/.cache/tailbeam) when the same content was read before, else ``read_volume_mesh``
    (whose errors name plate.mesh), then kept there."""
    key = disk.entry_key({"kind": "volume mesh", "sha256": digest}, ())
    file = disk.entry_path(cache_dir or disk.default_cache_dir(), MESH_PREFIX, key)
    status, found = disk.read_entry(file, key)
    if status == "hit":
        try:
            return _mesh_from(found, str(path))
        except (KeyError, ValueError, IndexError) as err:
            status, found = "damaged", f"{type(err).__name__}: {err}"
    if status == "damaged":
        note(f"structure cache: {file} is damaged ({found}); reading the mesh file again")
    vmesh = read_volume_mesh(path)
    arrays = {"p": vmesh.mesh.p, "t": vmesh.mesh.t}
    groups = {"faces": sorted(vmesh.faces), "volumes": sorted(vmesh.volumes)}
    for kind, names in groups.items():
        for i, name in enumerate(names):
            arrays[f"{kind}{i}"] = getattr(vmesh, kind)[name]
    try:
        disk.write_entry(file, key, arrays, {"cell": vmesh.kind, **groups})
    except OSError:
        pass  # an unwritable cache: the file is read again next time
    return vmesh


def _mesh_from(found: dict, source: str) -> VolumeMesh:
    """The VolumeMesh of a ``read_mesh`` entry."""
    info = found["info"]
    cell = {"tetra": MeshTet, "hexahedron": MeshHex}[info["cell"]]
    groups = {kind: {name: found[f"{kind}{i}"] for i, name in enumerate(info[kind])}
              for kind in ("faces", "volumes")}  # fmt: skip
    return VolumeMesh(cell(found["p"], found["t"]), groups["faces"], groups["volumes"], source)


def matrices_key(model: StructureModel) -> str:
    """Hex key of the quantities of ``model``'s assembled K and M kept on disk (no band)."""
    return disk.entry_key({**_model_meta(model), "matrices": True}, _mesh_arrays(model))


def stiffness_nnz(model: StructureModel, cache_dir=None) -> int:
    """Stored nonzeros of the reduced stiffness K of ``model``: the count kept in
    ``structure-matrices-<key>.npz`` (``cache_dir``, default $TAILBEAM_CACHE_DIR or
    ~/.cache/tailbeam), else K's own (assembled if it is not yet), then kept there."""
    key = matrices_key(model)
    path = disk.entry_path(cache_dir or disk.default_cache_dir(), MATRICES_PREFIX, key)
    status, found = disk.read_entry(path, key)
    if status == "hit" and "stiffness_nnz" in found:
        return int(found["stiffness_nnz"])
    if status == "damaged":
        note(f"structure cache: {path} is damaged ({found}); recomputing it")
    nnz = int(model.stiffness.nnz)
    try:
        disk.write_entry(path, key, {"stiffness_nnz": np.array(nnz, dtype=np.int64)},
                         {"what": "nonzeros of the reduced stiffness K"})  # fmt: skip
    except OSError:
        pass  # an unwritable cache: the next run counts them again
    return nnz


def basis_path(cache_dir, key: str) -> Path:
    return disk.entry_path(cache_dir or disk.default_cache_dir(), BASIS_PREFIX, key)


def load_basis(path: Path, key: str, n_dofs: int):
    """(frequencies Hz, vectors (n_dofs, k), info) of the entry, or None: missing, or
    damaged (then a note says it is recomputed)."""
    status, found = disk.read_entry(path, key)
    if status == "hit":
        freqs, phi = found.get("frequencies_hz"), found.get("vectors")
        if freqs is not None and phi is not None and phi.shape == (n_dofs, len(freqs)):
            return freqs, phi, found["info"]
        status, found = "damaged", "its arrays do not fit the structure"
    if status == "damaged":
        note(f"basis cache: {path} is damaged ({found}); recomputing it")
    return None


def load_frequencies(path: Path, key: str):
    """(frequencies Hz, info) of the entry, without reading its vectors (a listing of the
    modes), or None: missing, another key's, or unreadable (``load_basis`` then decides)."""
    try:
        with np.load(path, allow_pickle=False) as data:
            if "vectors.npy" not in data.zip.namelist() or str(data["key"]) != key:
                return None
            return data["frequencies_hz"], json.loads(str(data["info"]))
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None


def store_basis(path: Path, key: str, freqs, phi, info: dict) -> None:
    """Save the basis; an unwritable cache is noted in ``info``, not raised (a finished
    computation must not be lost)."""
    try:
        disk.write_entry(path, key, {"frequencies_hz": freqs, "vectors": phi}, info)
    except OSError as err:
        info.update(cache=f"not written: {err}", cache_file=None)


class StaticCompliances:
    """``model.static_compliance`` on the impact face (1 N spread over a disc): through the
    face's compliance matrix (``tailbeam.plate.solid.face.compliance``: K^-1 on the face's
    DOFs, the direct solve's value for any point and radius), made on the first call with
    the model's factorisation and kept in a per-structure file (``static_key``) that later
    runs read. ``cache_dir`` None: no file. A face whose facets are not parallelograms has
    no fast readings: each point is then solved directly and kept in memory."""

    def __init__(self, model: StructureModel, cache_dir=None):
        self.model = model
        self.cache_dir = cache_dir
        self._face = None  # the FaceCompliance, made on first need
        self._values = {}  # the direct solves' values, without fast readings

    def __call__(self, points, contact_radius: float = 0.0) -> np.ndarray:
        """(p,) mean z-deflection (m/N) over the disc under 1 N spread over it."""
        readings = self.model.face_readings()
        if readings is None:
            return self._direct(points, contact_radius)
        if self._face is None:
            self._face = self._load_or_make(readings)
        return self._face(points, contact_radius)

    def _load_or_make(self, readings) -> FaceCompliance:
        dofs = face_dofs(readings)
        path = key = None
        if self.cache_dir is not None:
            key = static_key(self.model)
            path = disk.entry_path(self.cache_dir, STATIC_PREFIX, key)
            status, found = disk.read_entry(path, key)
            if status == "hit" and np.array_equal(found.get("dofs"), dofs):
                return FaceCompliance(self.model, readings, dofs, found["green"])
            if status != "missing":
                why = found if status == "damaged" else "its DOFs do not fit the structure"
                note(f"static compliance cache: {path} is damaged ({why}); recomputing it")
        green = face_green(self.model, dofs)
        if path is not None:
            try:
                disk.write_entry(path, key, {"dofs": dofs, "green": green},
                                 {"what": "K^-1 on the impact face's DOFs, m/N"})  # fmt: skip
            except OSError:
                pass  # an unwritable cache: the matrix stays in memory for this run
        return FaceCompliance(self.model, readings, dofs, green)

    def _direct(self, points, contact_radius):
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        keys = [(round(float(x), ROUND), round(float(y), ROUND),
                 round(float(contact_radius), ROUND)) for x, y in pts]  # fmt: skip
        todo = [i for i, k in enumerate(keys) if k not in self._values]
        if todo:
            fresh = self.model.static_compliance(pts[todo], contact_radius)
            self._values.update({keys[i]: float(v) for i, v in zip(todo, fresh, strict=True)})
        return np.array([self._values[k] for k in keys])


__all__ = ["StaticCompliances", "basis_key", "basis_path", "load_basis", "load_frequencies",
           "matrices_key", "read_mesh",
           "static_key", "stiffness_nnz", "store_basis"]  # fmt: skip
