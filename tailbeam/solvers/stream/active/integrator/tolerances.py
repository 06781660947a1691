"""The error control of an active set: its relative tolerance and an absolute one per state
component (balls' positions, their velocities, the modal coordinates and their rates)."""

from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError


@dataclass(frozen=True)
class Tolerances:
    """rtol and atol of the kernel's error norm (scipy's DOP853 norm, per state component).

    Attributes
    ----------
    rtol : float
        Relative tolerance.
    atol : ndarray, shape (6 n + 2 m,) (+ 3 n with friction)
        Absolute tolerance of each state component, in the state's order: positions (m),
        velocities (m/s), modal coordinates (m sqrt(kg)), their rates (m sqrt(kg)/s) and with
        friction the angular velocities (rad/s).
    """

    rtol: float
    atol: np.ndarray

    @classmethod
    def build(cls, rtol, n_balls, phi, atol_x=None, atol_v=None, atol_q=None, atol_qd=None,
              spin_radius=None):  # fmt: skip
        """Tolerances of n balls and the modes of the mode shapes ``phi``.

        Parameters
        ----------
        rtol : float
            Relative tolerance, in [1e-14, 1e-3].
        n_balls : int
            Number of balls n.
        phi : ndarray, shape (P, m)
            Mode shapes (1/sqrt(kg)) at the pairs' contact points (m = 0: the rigid plate).
        atol_x, atol_v : float, optional
            Of positions (m; default rtol x 1 mm) and velocities (m/s; default rtol x 1 m/s).
        spin_radius : array_like, shape (n,), optional
            With friction: the balls' radii (m); their angular velocities follow the modal
            block with atol_v / r each (rad/s).
        atol_q, atol_qd : float, optional
            Of the modal coordinates and their rates (default atol_x / s, atol_v / s with
            s = max |phi| (1 if 0): the deflection under a ball is held to about atol_x).

        Raises
        ------
        InputError
            rtol outside [1e-14, 1e-3].
        """
        if not 1e-14 <= rtol <= 1e-3:
            raise InputError("rtol", f"must lie in [1e-14, 1e-3], got {rtol!r}")
        atol_x = rtol * 1e-3 if atol_x is None else float(atol_x)
        atol_v = rtol * 1.0 if atol_v is None else float(atol_v)
        scale = float(np.max(np.abs(phi))) if phi.size else 1.0
        scale = scale if scale > 0.0 else 1.0
        atol_q = atol_x / scale if atol_q is None else float(atol_q)
        atol_qd = atol_v / scale if atol_qd is None else float(atol_qd)
        n, m = 3 * n_balls, phi.shape[1]
        atol = np.concatenate([np.full(n, atol_x), np.full(n, atol_v), np.full(m, atol_q),
                               np.full(m, atol_qd)])  # fmt: skip
        if spin_radius is not None:
            spin = atol_v / np.repeat(np.asarray(spin_radius, dtype=float), 3)
            atol = np.concatenate([atol, spin])
        return cls(float(rtol), atol)
