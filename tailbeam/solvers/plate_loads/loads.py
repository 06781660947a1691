"""Sparse load histories on the plate: what a stream of balls does to it, piece by piece.

A ``PlateLoads`` holds load pieces. Each piece acts at one point (x, y) of the plate (plate
frame, m) and has a force history F(t) (N, >= 0 presses the plate down, like a ball's contact
force) that is piecewise linear between its node times and zero outside them (so a piece may
start or end with a jump):

- a contact (``add_contact``): the force nodes (t, F) of one ball-plate contact, the contact
  point fixed for the contact;
- a dead load (``add_dead_load``): a constant force over [t_from, t_to] at a fixed point, e.g.
  one piece of a ball resting or sliding quasi-statically (m g cos(theta) at the position the
  ball has during the piece).

Pieces overlap freely in time; the plate's answer is their superposition
(``tailbeam.solvers.plate_loads.response.plate_response``). Storage is flat numpy arrays grown by
doubling: memory is O(nodes + pieces), independent of how many balls made them.
"""

import math

import numpy as np

from tailbeam.errors import InputError

_START = 64  # initial capacity of the node and piece arrays


class PlateLoads:
    """Append-only container of load pieces (see the module docstring).

    Attributes (views, read-only by convention): ``t`` (nodes,) node times s, ``force``
    (nodes,) N, ``first`` (pieces,) index of each piece's first node (its nodes are
    ``first[i]:first[i + 1]``, the last piece's run to ``n_nodes``), ``x``, ``y`` (pieces,) m,
    ``radius`` (pieces,) m: the radius of the disc the load is spread over (NaN: the
    default of ``plate_response``, ``load_radius``).
    """

    def __init__(self):
        self._t = np.empty(_START)
        self._f = np.empty(_START)
        self._first = np.empty(_START, dtype=np.int64)
        self._xyr = np.empty((_START, 3))
        self.n_nodes = 0
        self.n_pieces = 0

    # -- building -------------------------------------------------------------------------
    def add_contact(self, x, y, t_nodes, forces, *, radius=None) -> int:
        """Add one contact: force nodes ``forces`` (N) at sorted ``t_nodes`` (s, at least two,
        spanning a positive time) at the point (x, y) m; the force is linear between nodes and
        zero outside them. ``radius`` (m): the load disc (None: plate_response's default).
        Returns the piece index."""
        t = np.asarray(t_nodes, dtype=float).ravel()
        f = np.asarray(forces, dtype=float).ravel()
        if t.size < 2 or f.size != t.size:
            raise InputError(
                "t_nodes", f"need >= 2 node times and one force per node, got {t.size}/{f.size}"
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(f))):
            raise InputError("forces", "node times and forces must be finite")
        if np.any(np.diff(t) < 0.0) or not t[-1] > t[0]:
            raise InputError("t_nodes", "must be sorted and span a positive time")
        return self._append(x, y, radius, t, f)

    def add_dead_load(self, x, y, t_from, t_to, force, *, radius=None) -> int:
        """Add a constant ``force`` (N) acting at (x, y) m from ``t_from`` to ``t_to`` (s).
        Returns the piece index."""
        t_from, t_to, force = float(t_from), float(t_to), float(force)
        if not (math.isfinite(t_from) and math.isfinite(t_to) and t_to > t_from):
            raise InputError("t_to", f"must be finite and > t_from, got {t_from!r}..{t_to!r}")
        if not math.isfinite(force):
            raise InputError("force", f"must be finite, got {force!r}")
        return self._append(x, y, radius, np.array([t_from, t_to]), np.array([force, force]))

    def _append(self, x, y, radius, t, f) -> int:
        x, y = float(x), float(y)
        r = math.nan if radius is None else float(radius)
        if not (math.isfinite(x) and math.isfinite(y)):
            raise InputError("x", f"the load point must be finite, got ({x!r}, {y!r})")
        if not (math.isnan(r) or (math.isfinite(r) and r >= 0.0)):
            raise InputError("radius", f"must be >= 0 m, got {radius!r}")
        k = t.size
        self._reserve_nodes(self.n_nodes + k)
        self._t[self.n_nodes : self.n_nodes + k] = t
        self._f[self.n_nodes : self.n_nodes + k] = f
        if self.n_pieces == self._first.size:
            self._first = _grown(self._first, self.n_pieces + 1)
            self._xyr = _grown(self._xyr, self.n_pieces + 1)
        self._first[self.n_pieces] = self.n_nodes
        self._xyr[self.n_pieces] = (x, y, r)
        self.n_nodes += k
        self.n_pieces += 1
        return self.n_pieces - 1

    def _reserve_nodes(self, need):
        if need > self._t.size:
            self._t = _grown(self._t, need)
            self._f = _grown(self._f, need)

    # -- reading --------------------------------------------------------------------------
    @property
    def t(self) -> np.ndarray:
        return self._t[: self.n_nodes]

    @property
    def force(self) -> np.ndarray:
        return self._f[: self.n_nodes]

    @property
    def first(self) -> np.ndarray:
        return self._first[: self.n_pieces]

    @property
    def x(self) -> np.ndarray:
        return self._xyr[: self.n_pieces, 0]

    @property
    def y(self) -> np.ndarray:
        return self._xyr[: self.n_pieces, 1]

    @property
    def radius(self) -> np.ndarray:
        return self._xyr[: self.n_pieces, 2]

    def piece_of_node(self) -> np.ndarray:
        """(nodes,) index of the piece each node belongs to."""
        counts = np.diff(np.append(self.first, self.n_nodes))
        return np.repeat(np.arange(self.n_pieces, dtype=np.int64), counts)

    @property
    def nbytes(self) -> int:
        """Bytes held (allocated capacity)."""
        return sum(a.nbytes for a in (self._t, self._f, self._first, self._xyr))

    def __len__(self) -> int:
        return self.n_pieces

    def __repr__(self) -> str:
        return f"PlateLoads({self.n_pieces} pieces, {self.n_nodes} nodes)"


def _grown(a: np.ndarray, need: int) -> np.ndarray:
    """``a`` copied into an array of at least twice its length (and >= need rows)."""
    size = max(2 * a.shape[0], need)
    out = np.empty((size,) + a.shape[1:], dtype=a.dtype)
    out[: a.shape[0]] = a
    return out
