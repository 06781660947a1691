"""The plate's loads for the sensors: contact force histories at their contact points, and
the weight of the balls resting on the plate outside the active set as dead loads.

The loads are kept only for a run that replays them on a modal plate (``solve_stream(loads=
...)``), and their force nodes are bounded (``check``): past MAX_LOAD_NODES the sensors'
replay would refuse them (~40 bytes per node, at most ``plate_loads.response.MAX_BYTES``), so
the run stops there with the setting to change, not after the work.
"""

import math

import numpy as np

from tailbeam.errors import WorkLimitError
from tailbeam.solvers.plate_loads.response import MAX_BYTES

DEAD_LOAD_STEP = 2e-3  # m: a slider's weight is one constant load per this much travel
REPLAY_BYTES_PER_NODE = 40  # the sensors' replay (plate_loads.response._check_memory: 8 x 5)
MAX_LOAD_NODES = int(MAX_BYTES / REPLAY_BYTES_PER_NODE)  # force nodes a run may keep


class PlateLoads:
    """The loads of a run (``StreamRun.loads``, ``StreamRun.dead_loads``).

    Parameters
    ----------
    balls : Balls
        The stream's balls (sliders' motion, ``slide_since``).
    forces : PlateForces
        The active set's force histories.
    keep : bool
        False: no loads are kept (``forces.keep`` off, no dead loads).
    """

    def __init__(self, balls, forces, keep: bool = True):
        self.balls, self.forces = balls, forces
        forces.keep = self.keep = bool(keep)
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
        if not self.keep or not t_to > t_from:
            return
        x0, v0 = b.state(i, t_from)
        x1, _ = b.state(i, t_to)
        k = max(1, math.ceil(math.dist(x0[:2], x1[:2]) / DEAD_LOAD_STEP))
        edges = np.linspace(t_from, t_to, k + 1)
        mid, _ = b.states(np.full(k, i), 0.5 * (edges[:-1] + edges[1:]))
        weight = b.mass[i] * -b.g[2]
        for q in range(k):
            self.dead_loads.append((mid[q, 0], mid[q, 1], edges[q], edges[q + 1], weight))

    def check(self, t: float) -> None:
        """Raise WorkLimitError, naming ``duration``, once the force histories keep more than
        MAX_LOAD_NODES nodes (t: the time reached, s)."""
        if self.forces.kept > MAX_LOAD_NODES:
            raise WorkLimitError(
                f"duration: the plate loads keep more than {MAX_LOAD_NODES} force nodes by "
                f"t = {t:.6g} s, beyond what the sensors' replay takes "
                f"({MAX_BYTES / 1e9:g} GB at {REPLAY_BYTES_PER_NODE} bytes per node); shorten "
                "duration or lower the stream rates (a library call whose loads are not "
                "replayed: solve_stream(loads=False))"
            )
