"""The plate's loads for the sensors: contact force histories at their contact points, and
the weight of the balls resting on the plate outside the active set as dead loads."""

import math

import numpy as np

DEAD_LOAD_STEP = 2e-3  # m: a slider's weight is one constant load per this much travel


class PlateLoads:
    """The loads of a run (``StreamRun.loads``, ``StreamRun.dead_loads``).

    Parameters
    ----------
    balls : Balls
        The stream's balls (sliders' motion, ``slide_since``).
    forces : PlateForces
        The active set's force histories.
    """

    def __init__(self, balls, forces):
        self.balls, self.forces = balls, forces
        self.loads = []  # (x m, y m, t_nodes s, forces N)
        self.dead_loads = []  # (x m, y m, t_from s, t_to s, force N)

    def flush(self, i: int) -> None:
        """Hand the plate force history of ball i recorded so far to the loads."""
        self.loads.extend(self.forces.take(i))

    def dead_load(self, i: int, t_to: float) -> None:
        """Ball i slid from ``slide_since`` to t_to (s): its weight as constant loads on
        pieces of at most DEAD_LOAD_STEP of travel (each at its middle point)."""
        b = self.balls
        t_from = b.slide_since[i]
        b.slide_since[i] = math.nan
        if not t_to > t_from:
            return
        x0, v0 = b.state(i, t_from)
        x1, _ = b.state(i, t_to)
        k = max(1, math.ceil(math.dist(x0[:2], x1[:2]) / DEAD_LOAD_STEP))
        edges = np.linspace(t_from, t_to, k + 1)
        mid, _ = b.states(np.full(k, i), 0.5 * (edges[:-1] + edges[1:]))
        weight = b.mass[i] * -b.g[2]
        for q in range(k):
            self.dead_loads.append((mid[q, 0], mid[q, 1], edges[q], edges[q + 1], weight))
