"""The rows whose events were just applied, carried by key across rebuilds of the set.

An ``ActiveSet`` hands back the rows (kind, index) whose events it applied at the time it
returned at (``KernelIO.fresh_rows``), so that a call restarting there does not apply the
same event again at once (``kernel.advance``). The driver's set is rebuilt with other
indices when its members change: the rows are kept here by pair key, or (ball, edge) for an
edge row, and given to the rebuilt set under its own indices.
"""

import math

from tailbeam.solvers.stream.active.compiled.pairs import R_EDGE


class CarriedRows:
    """Fresh rows by key: the time (s) they were applied at and [(row kind, key)]."""

    def __init__(self):
        self.t = math.nan
        self.rows = []

    def save(self, s, members, keys) -> None:
        """Keep the fresh rows of ``s`` (an ``ActiveSet`` of ``members``, pairs ``keys``)."""
        t, rows = s.io.fresh_rows()
        self.t = t
        self.rows = [(k, (members[i // 4], i % 4) if k == R_EDGE else keys[i]) for k, i in rows]

    def restore(self, s, local, index) -> None:
        """Give the kept rows to ``s``, rebuilt with ball indices ``local`` and pair indices
        ``index`` (rows of balls or pairs it no longer has are dropped)."""
        kept = []
        for k, key in self.rows:
            if k == R_EDGE:
                if key[0] in local:
                    kept.append((k, 4 * local[key[0]] + key[1]))
            elif key in index:
                kept.append((k, index[key]))
        s.io.set_fresh(self.t, kept)
