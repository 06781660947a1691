"""The plate force histories of the active set's balls, for the plate's sensors.

The compiled set writes force rows (t, pair, F) of its touching plate pairs: at interior
points of every accepted step and at contact starts and ends. They are drained after each
``advance`` (the islands: when a ball's history is taken, ``pending``) into one history
per ball, held at the ball's position when its first rows are drained, until the driver
takes it as a load (a contact ended, the ball left the set or the run ended).

With friction on the modal plate the set also writes the friction force F_t on the ball
(rows (t, pair + P, F_x) and (t, pair + 2 P, F_y), P the set's pairs). The plate takes -F_t
on its top surface, h/2 above its mid-surface: the modes feel (h/2) F_t . grad phi
(``compiled.friction``). For the sensors that moment is a couple of point loads, in x
+/-(h/2) F_x / (2 e) at x -/+ e and the same in y (e = ``COUPLE_STEP``): its modal forces
are (h/2) F_t . grad phi with grad phi a central difference of step e (relative error
~(k e)^2 / 6 for a mode of wavenumber k, as ``StreamPlate.gradients``).

With friction each drained piece of a history (the rows of one pair and part drained at
once: one ``advance`` call's, or with the islands' lazy draining those of the calls since
the last drain, ``ActiveMembers.flush_forces``) is thinned (``thinning.keep_nodes``) to
within a fraction of its largest magnitude (THIN of the contact force's, THIN_FRICTION of a
friction component's): the stiff steps of a sticking impact write 40 nodes per step, far
more than the force needs, and the friction rows wobble at the scale of those steps (the
slip held below vs by a step bounded by stability), so they thin only at a coarser
tolerance. Measured on the caving stream's first 100 particles on the modal plate
(``benchmarks/bench_friction_stream.py``): 1.56 million load nodes in place of 10.8 million;
the sensors' signals moved by 3.8e-6 of their largest value (RMS of the change: 1.3e-6 of
the signal's). Without friction every row is kept, as written.

A run whose loads nobody replays (the rigid plate's ``Result``: ``solve_stream(loads=False)``)
keeps none (``keep`` False). Kept, they grow with the plate contacts: in the friction pile-up
(``benchmarks/bench_friction_pileup.py``, 50 lumps, 1 s) 5.2 million nodes in 1029 plate
contacts, 65 % of them in the 924 contacts shorter than 5 ms (~3600 nodes each: THIN keeps a
sticking impact's pulse to 1e-8 of its peak), a lump resting alone 16 nodes per second.
``kept`` counts the nodes kept, for the driver's bound on them
(``driver.loads.MAX_LOAD_NODES``).
"""

import numpy as np

from tailbeam.solvers.stream.active.plate.thinning import keep_nodes

COUPLE_STEP = 1e-5  # m, half the distance between the two point loads of a couple
THIN = 1e-8  # with friction: a dropped contact-force node's distance / the piece's peak
THIN_FRICTION = 1e-5  # the same for the friction force's components (x, y)


class PlateForces:
    """Force histories by ball: the point (x, y) in m and pieces of (t s, F N) rows, and
    with friction on the modal plate its friction force's rows.

    Parameters
    ----------
    lever : float
        h/2 (m): the friction force's lever on the modal plate (0: its moment is not a load).
    thin : tuple of float
        (contact force, friction force): each drained piece keeps the nodes within this
        fraction of its largest magnitude of every node it drops (``thinning``); 0 keeps
        every node.

    Attributes
    ----------
    keep : bool
        False: the rows drained are dropped (no histories, ``take`` returns none).
    kept : int
        Nodes kept so far (after thinning), taken or not.
    """

    def __init__(self, lever: float = 0.0, thin=(0.0, 0.0)):
        self.lever, self.thin = float(lever), tuple(float(v) for v in thin)
        self.keep, self.kept = True, 0
        # ball -> [x, y, [t], [F], [t of F_x], [F_x], [t of F_y], [F_y]] (lists of arrays)
        self.nodes = {}
        self.pending = None  # ball -> None: drains rows of the ball still held elsewhere

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
        if not self.keep or not len(rows):
            return
        codes = rows[:, 1].astype(np.int64)
        npairs = len(keys)
        order = np.argsort(codes, kind="stable")  # (each code's rows in the order written)
        sorted_codes = codes[order]
        starts = np.flatnonzero(np.diff(sorted_codes)) + 1
        for run in np.split(order, starts):
            code = int(codes[run[0]])
            p, part = code % npairs, code // npairs
            i = keys[p][0]
            sel = rows[run]
            entry = self.nodes.get(i)
            if entry is None:
                x = s.x[local[i]]
                entry = self.nodes[i] = [float(x[0]), float(x[1]), [], [], [], [], [], []]
            t, f = sel[:, 0].copy(), sel[:, 2].copy()  # part 0: F, 1: F_x, 2: F_y
            tol = self.thin[min(part, 1)]
            if tol > 0.0:
                t, f = _thinned(t, f, tol)
            entry[2 + 2 * part].append(t)
            entry[3 + 2 * part].append(f)
            self.kept += len(t)

    def take(self, i: int) -> list:
        """Ball i's plate loads since the last take: its force, and with friction on the
        modal plate the four point loads of its friction's couples (module docstring).

        Returns
        -------
        list of tuple
            (x m, y m, t_nodes (k,) s, forces (k,) N) in time order, none for a history that
            is empty or spans a single instant (a contact flushed as it started).
        """
        if self.pending is not None:
            self.pending(i)
        entry = self.nodes.pop(i, None)
        if entry is None:
            return []
        x, y = entry[0], entry[1]
        out = _piece(x, y, entry[2], entry[3])
        if self.lever > 0.0 and entry[4]:
            e = COUPLE_STEP
            scale = self.lever / (2.0 * e)
            for dx, dy, times, part in ((e, 0.0, entry[4], entry[5]),
                                        (0.0, e, entry[6], entry[7])):  # fmt: skip
                force = [-scale * f for f in part]
                out += _piece(x + dx, y + dy, times, force)
                out += _piece(x - dx, y - dy, times, [-f for f in force])
        return out


def _thinned(t, f, fraction: float):
    """(t, f) sorted in time and thinned to within ``fraction`` of max |f|."""
    order = np.argsort(t, kind="stable")
    t, f = t[order], f[order]
    keep = keep_nodes(t, f, fraction * float(np.max(np.abs(f))))
    return t[keep], f[keep]


def _piece(x, y, times, forces) -> list:
    """[(x, y, t, F)] in time order, or [] when empty or spanning a single instant."""
    if not times:
        return []
    t = np.concatenate(times)
    f = np.concatenate(forces)
    order = np.argsort(t, kind="stable")
    if not t[order[-1]] > t[order[0]]:
        return []
    return [(x, y, t[order], f[order])]
