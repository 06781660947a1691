"""The state vector of the stream reference: which balls it holds, in which order, and the
plate's modes after them.

The state is [positions | velocities] of the present balls (3 each, in the order of
``StateLayout.active``), then, with friction (``spin``), their angular velocities (3 each,
rad/s), followed on the modal plate by the modal coordinates [q | q'].
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
    spin : bool
        Whether the state holds the balls' angular velocities (friction turns them; without
        friction they never change and are left out).
    """

    def __init__(self, n_balls: int, n_modes: int | None, active, spin: bool = False):
        self.n_balls = n_balls
        self.n_modes = n_modes
        self.active = list(active)
        self.spin = spin

    @property
    def per_ball(self) -> int:
        """State entries per present ball: 6, or 9 with the angular velocities."""
        return 9 if self.spin else 6

    def spins(self, y):
        """Angular velocities (..., n, 3) (rad/s) of the present balls in state vector(s) y
        (shape (..., len)); None without ``spin``."""
        if not self.spin:
            return None
        n = len(self.active)
        return y[..., 6 * n : 9 * n].reshape(*y.shape[:-1], n, 3)

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
        off, m = self.per_ball * len(self.active), self.n_modes
        return y[..., off : off + m], y[..., off + m : off + 2 * m]

    @staticmethod
    def join(x, v, modes, w=None):
        """The state vector of positions x, velocities v (n, 3), angular velocities w (n, 3;
        None without spin) and modes (q, q') or None."""
        parts = [x.ravel(), v.ravel()] + ([] if w is None else [w.ravel()])
        return np.concatenate(parts + ([] if modes is None else list(modes)))

    def states_at(self, dense, times):
        """Positions, velocities (K, n, 3) and modes ((K, m) each, or None) at ``times`` (K,)
        s of a step's dense output ``dense``."""
        ys = np.atleast_2d(dense(times).T)  # (K, 6n [+ 3n] [+ 2m])
        n = len(self.active)
        x, v = ys[:, : 3 * n].reshape(-1, n, 3), ys[:, 3 * n : 6 * n].reshape(-1, n, 3)
        return x, v, self.modes(ys)

    def spins_at(self, dense, times):
        """Angular velocities (K, n, 3) (rad/s) at ``times`` (K,) s of a step's dense output;
        None without ``spin``."""
        return self.spins(np.atleast_2d(dense(times).T)) if self.spin else None

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
