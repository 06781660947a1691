"""The state vector of the stream reference: which balls it holds, in which order, and the
plate's modes after them.

The state is [positions | velocities] of the present balls (3 each, in the order of
``StateLayout.active``), followed on the modal plate by the modal coordinates [q | q'].
"""

import numpy as np


class StateLayout:
    """Where each present ball and the plate's modes sit in the state vector.

    Parameters
    ----------
    n_balls : int
        Number of balls in the scene, present or not.
    n_modes : int or None
        Number of plate modes (their coordinates [q | q'] follow the balls'); None on the
        rigid plate.
    active : list of int
        The balls present at the start (indices into the scene's balls), in state order.
    """

    def __init__(self, n_balls: int, n_modes: int | None, active):
        self.n_balls = n_balls
        self.n_modes = n_modes
        self.active = list(active)

    def split(self, y):
        """Positions (m) and velocities (m/s), (n, 3) each, of the present balls in state
        vector y."""
        n = len(self.active)
        return y[: 3 * n].reshape(n, 3), y[3 * n : 6 * n].reshape(n, 3)

    def modes(self, y):
        """(q, q') of the modal plate from a state vector y, or from states (..., len); None on
        the rigid plate."""
        if self.n_modes is None:
            return None
        off, m = 6 * len(self.active), self.n_modes
        return y[..., off : off + m], y[..., off + m : off + 2 * m]

    @staticmethod
    def join(x, v, modes):
        """The state vector of positions x, velocities v (n, 3) and modes (q, q') or None."""
        parts = [x.ravel(), v.ravel()] + ([] if modes is None else list(modes))
        return np.concatenate(parts)

    def states_at(self, dense, times):
        """Positions, velocities (K, n, 3) and modes ((K, m) each, or None) at ``times`` (K,)
        s of a step's dense output ``dense``."""
        ys = np.atleast_2d(dense(times).T)  # (K, 6n [+ 2m])
        n = len(self.active)
        x, v = ys[:, : 3 * n].reshape(-1, n, 3), ys[:, 3 * n : 6 * n].reshape(-1, n, 3)
        return x, v, self.modes(ys)

    def local(self) -> np.ndarray:
        """Position in the state of every ball of the scene (-1 where absent)."""
        loc = np.full(self.n_balls, -1)
        loc[self.active] = np.arange(len(self.active))
        return loc

    def add(self, ball: int) -> None:
        """Append ``ball`` to the state order (its position and velocity go last)."""
        self.active.append(ball)

    def remove(self, ball: int) -> list:
        """Drop ``ball`` from the state order; returns the state rows of the balls kept."""
        keep = [q for q, b in enumerate(self.active) if b != ball]
        self.active = [self.active[q] for q in keep]
        return keep
