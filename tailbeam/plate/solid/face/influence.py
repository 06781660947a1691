"""The static influence of sensor channels on a structure's impact face, by reciprocity.

A channel reads the displacement at a surface point along a direction: the row r of the
structure's displacement operator (``StructureModel.surface_operator``). Under 1 N along +z
at an impact-face point, spread by the face readings R (``face.readings``: f = R^T), the
channel reads r K^-1 R^T = R (K^-1 r^T) (K symmetric: Maxwell-Betti). So one static solve
per channel, u = K^-1 r^T (m/N on the reduced DOFs), gives the channel's static reading
under a unit load anywhere on the face: the face's z-displacement under a unit force at the
channel along its direction, read where the load acts.

The vectors u are kept in the cache folder beside the structure's basis, one file per
channel (``influence_key``: the structure's static key, ``cached.static_key``, with the
channel's point and unit direction), so the runs after the first factorise K for no
sensor. Reading them at face points costs one small interpolation per point (the face's
fast readings, ``FaceReadings.modal``), or the probe's operator when the face has none.
"""

import numpy as np

from tailbeam.plate import cache as disk
from tailbeam.plate.solid.cached import static_key
from tailbeam.progress import note

PREFIX = "structure-sensor-influence"


def channel_points(channels) -> tuple:
    """(p, 3) m points and (p, 3) unit directions of single-direction sensor channels
    (``SensorSpec.channels``): a 2-D position lies on the impact face (z = 0); no direction
    reads along +z."""
    pts, dirs = [], []
    for c in channels:
        pts.append(tuple(c.position) + (0.0,) * (3 - len(c.position)))
        dirs.append(c.direction if c.direction is not None else (0.0, 0.0, 1.0))
    return np.array(pts, dtype=float).reshape(-1, 3), np.array(dirs, dtype=float).reshape(-1, 3)


def all_cached(model, channels, cache_dir=None, structure_key=None) -> bool:
    """Whether the cache folder (default: tailbeam's) holds the influence of every channel
    of ``channels`` on ``model``: then no run needs to factorise K for them.
    ``structure_key``: the model's ``static_key`` when known."""
    folder = cache_dir or disk.default_cache_dir()
    key = structure_key or static_key(model)
    points, directions = channel_points(channels)
    return all(disk.entry_path(folder, PREFIX, influence_key(model, x, d, key)).is_file()
               for x, d in zip(points, directions, strict=True))  # fmt: skip


def influence_key(model, point, direction, structure_key=None) -> str:
    """Hex key of the influence vector of the channel at surface ``point`` (3,) m along the
    unit ``direction`` (3,) on ``model`` (a StructureModel); ``structure_key``: its
    ``static_key`` when known (a hash of the whole mesh)."""
    meta = {"static_key": structure_key or static_key(model),
            "sensor_point": [float(v) for v in point],
            "sensor_direction": [float(v) for v in direction]}  # fmt: skip
    return disk.entry_key(meta, ())


class FaceInfluence:
    """The static readings (m/N) of channels under 1 N along +z at impact-face points.

    Parameters
    ----------
    model : StructureModel
        The held structure.
    operator : (p, n) sparse
        The channels' displacement operator on the reduced DOFs (``surface_operator``).
    points, directions : (p, 3) arrays
        The channels' surface points (m) and unit directions, as located by the operator
        (they key the cache).
    cache_dir : path or None
        The cache folder (None: solve, keep nothing on disk).
    """

    def __init__(self, model, operator, points, directions, cache_dir=None):
        self.model = model
        self.vectors = _influence_vectors(model, operator, points, directions, cache_dir)
        readings = model.face_readings()
        self._face = None if readings is None else readings.modal(self.vectors)

    def __call__(self, loads) -> np.ndarray:
        """(q, p): channel j's static reading (m/N) under 1 N along +z at load point i
        (loads (q, 2) m of the impact face)."""
        loads = np.atleast_2d(np.asarray(loads, dtype=float))
        if self._face is not None:
            return self._face(loads)
        return np.asarray(self.model.face_operator(loads) @ self.vectors)


def _influence_vectors(model, operator, points, directions, cache_dir) -> np.ndarray:
    """(n, p) u_j = K^-1 r_j^T of every channel: read from the cache, the missing ones
    solved together (one factorisation of K) and stored."""
    n, p = model.n_dofs, operator.shape[0]
    out = np.empty((n, p))
    paths, todo = [None] * p, []
    structure_key = static_key(model) if cache_dir is not None else None
    for j in range(p):
        if cache_dir is not None:
            key = influence_key(model, points[j], directions[j], structure_key)
            paths[j] = (disk.entry_path(cache_dir, PREFIX, key), key)
            status, found = disk.read_entry(*paths[j])
            vector = found.get("vector") if status == "hit" else None
            if vector is not None and vector.shape == (n,):
                out[:, j] = vector
                continue
            if status != "missing":
                why = found if status == "damaged" else "its vector does not fit the structure"
                note(f"sensor influence cache: {paths[j][0]} is damaged ({why}); recomputing it")
        todo.append(j)
    if todo:
        where = "cached" if cache_dir is not None else "not cached"
        note(f"sensor influence: one static solve for each of {len(todo)} sensor signal(s), "
             f"{where}")  # fmt: skip
        rhs = np.asarray(operator[todo].T.todense())
        out[:, todo] = model.solver().solve(rhs).reshape(rhs.shape)
        for j in todo:
            _store(paths[j], out[:, j], points[j], directions[j])
    return out


def _store(where, vector, point, direction) -> None:
    """Write one channel's vector; an unwritable cache keeps it in memory only."""
    if where is None:
        return
    info = {"what": "K^-1 of a unit force at a sensor channel, m/N on the reduced DOFs",
            "point": list(map(float, point)), "direction": list(map(float, direction))}  # fmt: skip
    try:
        disk.write_entry(where[0], where[1], {"vector": vector}, info)
    except OSError:
        pass


__all__ = ["FaceInfluence", "all_cached", "channel_points", "influence_key"]
