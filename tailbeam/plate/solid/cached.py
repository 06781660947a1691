"""A structure's modal basis and static compliances on disk (``tailbeam.plate.cache``).

The key (``basis_key``) is a SHA-256 over everything that determines the basis: the mesh's
content as read (node coordinates, cells and every named face and cell group; not the
file's path or time), the element, the material (density, Young's modulus, Poisson ratio),
the impact face, every support (kind, group or region, stiffness, direction, axis), whether
rigid-body modes are left free, the band (fmax, count) and the cache format and package
version. Any change gives another file, so a stale basis is never reused; the key is also
stored in the file and checked on load. A damaged file is recomputed and overwritten, with
a note.

The static compliances under contact discs (the residual flexibility's K^-1, which needs a
factorisation of K, tens of seconds on the example beam) are kept beside the basis, one file
per structure (``static_key``: the same key without the band), point by point as runs ask
for them (``StaticCompliances``).
"""

import dataclasses
import weakref
from pathlib import Path

import numpy as np

from tailbeam.plate import cache as disk
from tailbeam.plate.solid.model import StructureModel
from tailbeam.progress import note

BASIS_PREFIX = "structure"
STATIC_PREFIX = "structure-static"
ROUND = 12  # decimals (m) of a point's and a radius' key in the static compliances


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


def store_basis(path: Path, key: str, freqs, phi, info: dict) -> None:
    """Save the basis; an unwritable cache is noted in ``info``, not raised (a finished
    computation must not be lost)."""
    try:
        disk.write_entry(path, key, {"frequencies_hz": freqs, "vectors": phi}, info)
    except OSError as err:
        info.update(cache=f"not written: {err}", cache_file=None)


class StaticCompliances:
    """``model.static_compliance`` through a per-structure file of the values already
    computed (points and disc radii rounded to ``ROUND`` decimals of a metre); new values
    are computed by the model (its factorisation, made on first need). The file is rewritten
    atomically, merged with what another run wrote, after the first new value and then
    whenever the new values reach the number saved (a stream's thousands of contact points
    cost O(n) writes), and at exit. ``cache_dir`` None: no file, the model's values."""

    def __init__(self, model: StructureModel, cache_dir=None):
        self.model = model
        self.values = {}
        self.unsaved = [0]  # new values not yet in the file (a list: the exit hook reads it)
        self.path = self.key = None
        if cache_dir is not None:
            self.key = static_key(model)
            self.path = disk.entry_path(cache_dir, STATIC_PREFIX, self.key)
            self.values.update(_read_static(self.path, self.key))
            weakref.finalize(self, _flush, self.path, self.key, self.values, self.unsaved)

    def __call__(self, points, contact_radius: float = 0.0) -> np.ndarray:
        """(p,) mean z-deflection (m/N) over the disc under 1 N spread over it."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        keys = [(round(float(x), ROUND), round(float(y), ROUND),
                 round(float(contact_radius), ROUND)) for x, y in pts]  # fmt: skip
        todo = [i for i, k in enumerate(keys) if k not in self.values]
        if todo:
            fresh = self.model.static_compliance(pts[todo], contact_radius)
            self.values.update({keys[i]: float(v) for i, v in zip(todo, fresh, strict=True)})
            self.unsaved[0] += len(todo)
            if self.path is not None and self.unsaved[0] >= max(1, len(self.values) // 2):
                _flush(self.path, self.key, self.values, self.unsaved)
        return np.array([self.values[k] for k in keys])


def _read_static(path: Path, key: str) -> dict:
    status, found = disk.read_entry(path, key)
    if status == "damaged":
        note(f"static compliance cache: {path} is damaged ({found}); recomputing it")
    if status != "hit":
        return {}
    return {tuple(k): float(v) for k, v in zip(found["points"], found["values"], strict=True)}


def _flush(path: Path, key: str, values: dict, unsaved: list) -> None:
    """Merge ``values`` (updated in place) with the file's and write them when ``unsaved[0]``
    new ones are not in it yet (unwritable: kept in memory only)."""
    if not unsaved[0]:
        return
    unsaved[0] = 0
    for k, v in _read_static(path, key).items():
        values.setdefault(k, v)
    arrays = {"points": np.array(list(values), dtype=float).reshape(-1, 3),
              "values": np.array(list(values.values()), dtype=float)}  # fmt: skip
    try:
        disk.write_entry(path, key, arrays, {"what": "static compliance m/N"})
    except OSError:
        pass  # an unwritable cache: the values stay in memory for this run


__all__ = ["StaticCompliances", "basis_key", "basis_path", "load_basis", "static_key",
           "store_basis"]  # fmt: skip
