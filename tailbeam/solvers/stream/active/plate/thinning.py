"""Thinning a piecewise-linear force history: the nodes it needs within a tolerance.

The active set writes a plate pair's force at ``nodes_per_step`` interior points of every
accepted step. With friction the steps inside an impact are short (the regularised law is
stiff where the contact sticks: the step is bounded by stability, not accuracy), so the
histories carry far more nodes than their shape needs, and the sensors' replay of the loads
costs memory and time in proportion to the nodes. ``keep_nodes`` keeps a subset of the nodes
such that the piecewise-linear history through the kept nodes is within ``tol`` of every
dropped node (each dropped node lies within ``tol`` of the chord between the kept nodes on
either side of it), the first and the last node and both nodes of every repeated time (a
jump) always kept.

Greedy, one pass, O(nodes): from the last kept node (the anchor) the chord to node e is
valid if its slope lies in the interval of slopes that pass within ``tol`` of every node
between them; at the first invalid e the node before it is kept and becomes the anchor.
"""

import numpy as np

from tailbeam.jit import njit


def keep_nodes(t, f, tol: float) -> np.ndarray:
    """Which nodes of the history (t, f) to keep (module docstring).

    Parameters
    ----------
    t : (k,) array
        Node times (s), non-decreasing.
    f : (k,) array
        The values at the nodes (N).
    tol : float
        Largest distance (N) of a dropped node from the kept history, >= 0 (0: only nodes on
        a straight line through their neighbours are dropped).

    Returns
    -------
    (k,) bool array
        True for the nodes kept.
    """
    t = np.ascontiguousarray(t, dtype=float)
    f = np.ascontiguousarray(f, dtype=float)
    keep = np.zeros(t.shape[0], dtype=np.bool_)
    if t.shape[0]:
        _keep(t, f, float(tol), keep)
    return keep


@njit(cache=True)
def _keep(t, f, tol, keep):  # pragma: no cover  (compiled; tested through keep_nodes)
    k = t.shape[0]
    keep[0] = True
    keep[k - 1] = True
    for e in range(1, k):  # both nodes of a jump (a repeated time)
        if t[e] == t[e - 1]:
            keep[e] = True
            keep[e - 1] = True
    a = 0
    lo, hi = -np.inf, np.inf
    e = a + 1
    while e < k:
        if e > a + 1:  # node e - 1 lies between the anchor and e: narrow the slopes
            dt = t[e - 1] - t[a]
            lo = max(lo, (f[e - 1] - tol - f[a]) / dt)
            hi = min(hi, (f[e - 1] + tol - f[a]) / dt)
        slope = (f[e] - f[a]) / (t[e] - t[a]) if t[e] > t[a] else 0.0
        if e > a + 1 and not lo <= slope <= hi:
            keep[e - 1] = True
            a, lo, hi = e - 1, -np.inf, np.inf
            continue  # e again, from the new anchor
        if keep[e]:
            a, lo, hi = e, -np.inf, np.inf
        e += 1
