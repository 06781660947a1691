"""Broad phase: the ball pairs that may touch within a time horizon, in ~O(N).

Certificate. If every ball's speed stays below its bound s_i (m/s) over the horizon T (s),
a ball moves at most s_i T, so the gap of a pair can shrink by at most (s_i + s_j) T. With the
swept radius rho_i = r_i + s_i T + margin / 2, a pair can touch within T only if

    |x_i - x_j| <= rho_i + rho_j,

and every such pair is returned (the same comparison as the brute-force reference below, so
the two return identical sets). The solver must choose the bounds (e.g. speed now + the
largest acceleration x T) and re-run the broad phase before the horizon ends; that is the
same certificate as the ball-plate contact starts of the rigid and coupled solvers.

Method: a uniform cell grid with cell size 2 max(rho). A candidate pair then lies in the same
or in adjacent cells; the cells are found by sorting the balls by a cell key and binary
search, and each pair is generated once (the cell itself and 13 of its 26 neighbours). Why a
grid and not sweep-and-prune: stream particles have radii within a factor ~4 and bounded
speeds, so cells hold O(1) balls and the cost is O(N log N) for the sort plus O(N + pairs);
the same grid serves the stream generator's overlap check. A ball with a far larger swept
radius than the others makes the cells coarse (then the cost degrades towards O(N^2)): the
caller should cap the horizon so that s_max T is comparable to the radii.
"""

import numpy as np

from tailbeam.errors import InputError, WorkLimitError

_HALF_NEIGHBOURS = np.array(
    [(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)
     if (dx, dy, dz) > (0, 0, 0)]
)  # fmt: skip
_MAX_KEY = 2**62


def swept_radii(radii, speed_bounds, horizon: float, margin: float = 0.0, n=None) -> np.ndarray:
    """rho_i = r_i + s_i T + margin / 2 in m for n balls (radii, speed_bounds: arrays or
    scalars; checked: all finite and >= 0)."""
    radii = np.asarray(radii, dtype=float)
    radii = np.broadcast_to(radii, (n,) if n is not None else radii.shape)
    speed_bounds = np.broadcast_to(np.asarray(speed_bounds, dtype=float), radii.shape)
    if not np.isfinite(horizon) or horizon < 0.0:
        raise InputError("horizon", f"must be finite and >= 0, got {horizon!r}")
    for name, a in (("radii", radii), ("speed_bounds", speed_bounds)):
        if not np.all(np.isfinite(a)) or np.any(a < 0.0):
            raise InputError(name, "must be finite and >= 0")
    return radii + speed_bounds * horizon + 0.5 * margin


def _close(x_i, x_j, rho_i, rho_j) -> np.ndarray:
    """The certificate's test, shared by the grid and the brute force: |d| <= rho_i + rho_j."""
    d = x_i - x_j
    return np.einsum("pk,pk->p", d, d) <= (rho_i + rho_j) ** 2


def candidate_pairs(centres, radii, speed_bounds, horizon: float, margin: float = 0.0):
    """Pairs (i < j) that may touch within ``horizon`` s, as an int64 array (K, 2) sorted by
    (i, j). centres (N, 3) m, radii (N,) m, speed_bounds (N,) or scalar m/s."""
    x = np.asarray(centres, dtype=float).reshape(-1, 3)
    rho = swept_radii(radii, speed_bounds, horizon, margin, len(x))
    if len(x) < 2:
        return np.empty((0, 2), dtype=np.int64)
    if not np.all(np.isfinite(x)):
        raise InputError("centres", "must be finite")
    cell = max(2.0 * float(rho.max()) * (1.0 + 1e-9), 1e-300)  # margin for round-off
    coords = np.floor((x - x.min(axis=0)) / cell).astype(np.int64) + 1  # >= 1: room for -1
    dims = coords.max(axis=0) + 2
    if float(np.prod(dims.astype(float))) >= _MAX_KEY:
        raise WorkLimitError(
            "broad phase: the scene spans too many cells (extent / (2 x swept radius) per "
            "axis); split the scene or lengthen the horizon"
        )
    keys = (coords[:, 0] * dims[1] + coords[:, 1]) * dims[2] + coords[:, 2]
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    parts = [_same_cell_pairs(sorted_keys)]
    for off in _HALF_NEIGHBOURS:
        nkeys = (
            ((coords[order, 0] + off[0]) * dims[1] + coords[order, 1] + off[1]) * dims[2]
            + coords[order, 2]
            + off[2]
        )
        parts.append(_neighbour_cell_pairs(sorted_keys, nkeys))
    a, b = (np.concatenate(p) for p in zip(*parts, strict=True))
    i, j = order[a], order[b]
    keep = _close(x[i], x[j], rho[i], rho[j])
    return _sorted_pairs(i[keep], j[keep])


def _ranges(starts, counts):
    """Flattened [starts[k], starts[k] + counts[k]) for all k, and the owner k of each."""
    total = int(counts.sum())
    owner = np.repeat(np.arange(len(counts)), counts)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    return np.repeat(starts, counts) + (np.arange(total) - first), owner


def _same_cell_pairs(sorted_keys):
    """Positions (a, b), a < b, of balls sharing a cell in the sorted order."""
    end = np.searchsorted(sorted_keys, sorted_keys, side="right")
    pos = np.arange(len(sorted_keys))
    b, owner = _ranges(pos + 1, end - pos - 1)
    return pos[owner], b


def _neighbour_cell_pairs(sorted_keys, neighbour_keys):
    """Positions (a, b) of each ball a and the balls b of its neighbour cell."""
    start = np.searchsorted(sorted_keys, neighbour_keys, side="left")
    end = np.searchsorted(sorted_keys, neighbour_keys, side="right")
    b, owner = _ranges(start, end - start)
    return owner, b


def _sorted_pairs(i, j):
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    order = np.lexsort((hi, lo))
    return np.stack([lo[order], hi[order]], axis=1).astype(np.int64)


def candidate_pairs_brute_force(
    centres, radii, speed_bounds, horizon: float, margin: float = 0.0, block: int = 2048
):
    """Reference: every pair tested (O(N^2) work, O(block x N) memory); same contract."""
    x = np.asarray(centres, dtype=float).reshape(-1, 3)
    rho = swept_radii(radii, speed_bounds, horizon, margin, len(x))
    n = len(x)
    found = []
    for s in range(0, n, block):
        i = np.arange(s, min(s + block, n))
        d2 = np.sum((x[i, None, :] - x[None, :, :]) ** 2, axis=-1)
        close = d2 <= (rho[i, None] + rho[None, :]) ** 2 * (1.0 + 1e-9)  # then exact test
        close &= np.arange(n)[None, :] > i[:, None]
        a, b = np.nonzero(close)
        found.append((i[a], b))
    if not found:
        return np.empty((0, 2), dtype=np.int64)
    i, j = (np.concatenate(p) for p in zip(*found, strict=True))
    # the same test as the grid, element by element, so that the sets are identical
    keep = _close(x[i], x[j], rho[i], rho[j])
    return _sorted_pairs(i[keep], j[keep])
