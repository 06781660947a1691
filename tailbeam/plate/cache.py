"""On-disk cache of computed modal bases (one .npz per basis).

The flat plate's bases (``cache_key``, ``save``, ``load``): the file name is a SHA-256 over
everything that determines the result: the code and cache format version, the mesh arrays
(points, triangles, named edges), the material (density, Young's modulus, Poisson ratio),
the plate size and thickness, the theory and element, the shear coefficient, the boundary
code and the band (fmax, count). Any change gives another key, so a stale basis is never
reused; the key is also stored in the file and checked on load.

A structure's bases (``tailbeam.plate.solid.cached``) use the same folder and writer with
their own key (``entry_key``: a dict of what determines the basis and the mesh arrays) and
``read_entry``/``write_entry``, which tell a missing entry from a damaged one.
Default folder: $TAILBEAM_CACHE_DIR, else ~/.cache/tailbeam.
"""

import hashlib
import json
import os
import tempfile
import zipfile
from pathlib import Path

import numpy as np
from skfem import MeshTri

from tailbeam._version import __version__
from tailbeam.cachedir import cache_root
from tailbeam.physics.bodies import Plate
from tailbeam.plate.closed_forms import SHEAR_COEFFICIENT

CACHE_FORMAT = 1  # bump when the stored content or its meaning changes


def default_cache_dir() -> Path:
    """tailbeam's cache folder (tailbeam.cachedir.cache_root)."""
    return cache_root()


def cache_key(
    plate: Plate, boundary: str, theory: str, element: str, mesh: MeshTri, fmax_hz, count
) -> str:
    """Hex digest identifying a modal basis (see module docstring)."""
    h = hashlib.sha256()
    mat = plate.material
    meta = {
        "format": CACHE_FORMAT,
        "version": __version__,
        "material": [float(mat.density), float(mat.youngs_modulus), float(mat.poisson_ratio)],
        "plate": [float(plate.size_x), float(plate.size_y), float(plate.thickness)],
        "theory": theory,
        "element": element,
        "shear_coefficient": SHEAR_COEFFICIENT,
        "boundary": boundary,
        "fmax_hz": None if fmax_hz is None else float(fmax_hz),
        "count": None if count is None else int(count),
    }
    h.update(json.dumps(meta, sort_keys=True).encode())
    h.update(np.ascontiguousarray(mesh.p, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(mesh.t, dtype=np.int64).tobytes())
    for name in sorted(mesh.boundaries or {}):
        h.update(name.encode())
        h.update(np.sort(np.asarray(mesh.boundaries[name], dtype=np.int64)).tobytes())
    return h.hexdigest()


def cache_path(cache_dir, key: str) -> Path:
    return Path(cache_dir) / f"modes-{key[:32]}.npz"


def save(
    path: Path,
    key: str,
    *,
    frequencies_hz,
    vectors,
    free_dofs,
    n_full: int,
    mesh: MeshTri,
    info: dict,
) -> None:
    """Write atomically (temp file + rename) so a crash never leaves a truncated entry."""
    arrays = {
        "key": np.array(key),
        "frequencies_hz": np.asarray(frequencies_hz, dtype=float),
        "vectors": np.asarray(vectors, dtype=float),
        "free_dofs": np.asarray(free_dofs, dtype=np.int64),
        "n_full": np.array(int(n_full)),
        "p": mesh.p,
        "t": mesh.t,
        "info": np.array(json.dumps(info, default=_jsonable)),
    }
    for name, facets in (mesh.boundaries or {}).items():
        arrays[f"boundary:{name}"] = np.asarray(facets, dtype=np.int64)
    _write_npz(path, arrays)


def _write_npz(path: Path, arrays: dict) -> None:
    """Write ``arrays`` to ``path`` atomically (temp file in the same folder + rename)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".modes-", suffix=".npz", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez(fh, **arrays)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def load(path: Path, key: str):
    """(frequencies_hz, vectors, free_dofs, n_full, mesh, info), or None if the entry is
    missing, unreadable or has another key."""
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            if str(data["key"]) != key:
                return None
            boundaries = {
                name.split(":", 1)[1]: data[name]
                for name in data.files
                if name.startswith("boundary:")
            }
            mesh = MeshTri(data["p"], data["t"], boundaries or None, validate=False)
            return (
                data["frequencies_hz"],
                data["vectors"],
                data["free_dofs"],
                int(data["n_full"]),
                mesh,
                json.loads(str(data["info"])),
            )
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None  # a damaged entry is recomputed (and overwritten), never trusted


def entry_key(meta: dict, arrays) -> str:
    """Hex SHA-256 of ``meta`` (JSON, with the cache format and package version added) and
    the bytes, dtypes and shapes of ``arrays`` (an iterable of (name, ndarray), in order)."""
    h = hashlib.sha256()
    h.update(json.dumps({**meta, "format": CACHE_FORMAT, "version": __version__},
                        sort_keys=True, default=_jsonable).encode())  # fmt: skip
    for name, arr in arrays:
        arr = np.ascontiguousarray(arr)
        h.update(f"{name}:{arr.dtype.str}:{arr.shape}".encode())
        h.update(arr.tobytes())
    return h.hexdigest()


def entry_path(cache_dir, prefix: str, key: str) -> Path:
    """The cache file of entry ``key``: ``<cache_dir>/<prefix>-<key[:32]>.npz``."""
    return Path(cache_dir) / f"{prefix}-{key[:32]}.npz"


def write_entry(path: Path, key: str, arrays: dict, info: dict) -> None:
    """Save ``arrays`` (name -> ndarray) with ``key`` and ``info`` (JSON), atomically."""
    out = {**arrays, "key": np.array(key), "info": np.array(json.dumps(info, default=_jsonable))}
    _write_npz(path, out)


def read_entry(path: Path, key: str):
    """("hit", arrays dict with "info" parsed), ("missing", None) for no file or another
    key's file, or ("damaged", reason) for a file that cannot be read (never trusted)."""
    if not path.is_file():
        return "missing", None
    try:
        with np.load(path, allow_pickle=False) as data:
            if str(data["key"]) != key:
                return "missing", None
            out = {name: data[name] for name in data.files if name not in ("key", "info")}
            out["info"] = json.loads(str(data["info"]))
            return "hit", out
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as err:
        return "damaged", f"{type(err).__name__}: {err}".splitlines()[0]


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return str(value)
