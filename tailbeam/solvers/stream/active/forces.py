"""The plate force histories of the active set's balls, for the plate's sensors.

The compiled set writes force rows (t, pair, F) of its touching plate pairs: at interior
points of every accepted step and at contact starts and ends. They are drained after each
``advance`` into one history per ball, held at the point of its first row, until the driver
takes it as a load (a contact ended, the ball left the set or the run ended).
"""

import numpy as np


class PlateForces:
    """Force histories by ball: the point (x, y) in m and pieces of (t s, F N) rows."""

    def __init__(self):
        self.nodes = {}  # ball -> [x, y, [t arrays], [F arrays]]

    def drain(self, s, keys, local) -> None:
        """Move the force rows of ``s`` (an ``ActiveSet``) into the histories.

        Parameters
        ----------
        s : ActiveSet
            The built set (its rows are left for the caller to clear).
        keys : list of tuple
            The pair key of each of its pairs ((i, -1) for ball i on the plate).
        local : dict
            Ball number -> its index in ``s``.
        """
        rows = s.force_rows()
        if not len(rows):
            return
        pairs = rows[:, 1].astype(np.int64)
        for p in np.unique(pairs):
            i = keys[p][0]
            sel = rows[pairs == p]
            entry = self.nodes.get(i)
            if entry is None:
                x = s.x[local[i]]
                entry = self.nodes[i] = [float(x[0]), float(x[1]), [], []]
            entry[2].append(sel[:, 0].copy())
            entry[3].append(sel[:, 2].copy())

    def take(self, i: int):
        """Ball i's plate force since the last take.

        Returns
        -------
        tuple or None
            (x m, y m, t_nodes (k,) s, forces (k,) N) in time order, or None when there is
            none or it spans a single instant (a contact flushed as it started).
        """
        entry = self.nodes.pop(i, None)
        if entry is None:
            return None
        t = np.concatenate(entry[2])
        f = np.concatenate(entry[3])
        order = np.argsort(t, kind="stable")
        if not t[order[-1]] > t[order[0]]:
            return None
        return entry[0], entry[1], t[order], f[order]
