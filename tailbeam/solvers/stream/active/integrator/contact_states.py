"""The state of each watched pair of an active set: in contact, the law's region, its accumulators.

Per pair: whether it touches, the region of the IMPACT law it is in (ramp: penetration below
the full-damping depth d, or no damping; clamped: the force held at 0 while the damped force
would pull) and its accumulators: what its contact has reached so far (peak force, its time,
maximum penetration). The compiled kernel reads and updates these arrays in place (``arrays``: the
``pstate`` tuple of ``kernel.advance``); between calls the caller opens, starts and holds
contacts here, or carries a pair's state over from another set (``of``, ``put``).
"""

import math

import numpy as np

from tailbeam.physics.contact_law import LAW_C, LAW_COLUMNS, LAW_D
from tailbeam.solvers.stream.active.compiled.friction import IMP_COLUMNS
from tailbeam.solvers.stream.active.compiled.pairs import clamp_indicator


class ContactStates:
    """Region flags and accumulators of P pairs, in/out of the kernel.

    Parameters
    ----------
    n_pairs : int
        Number of pairs P (none touching to begin with).

    Attributes
    ----------
    touching, ramp, clamped : ndarray of bool, shape (P,)
        In contact; in the law's ramp region; clamped (force 0).
    peak : ndarray, shape (P,)
        Peak force (N) of the contact so far.
    t_peak : ndarray, shape (P,)
        Its time (s; NaN before the first accepted step of the contact).
    pen : ndarray, shape (P,)
        Maximum penetration (m) of the contact so far.
    imp : ndarray, shape (P, IMP_COLUMNS)
        With friction: normal impulse (N s), tangential impulse on ball i (3, N s) and the
        energy friction dissipated (J) of the contact so far (``compiled.friction``).
    """

    def __init__(self, n_pairs: int):
        self.touching = np.zeros(n_pairs, dtype=bool)
        self.ramp = np.ones(n_pairs, dtype=bool)
        self.clamped = np.zeros(n_pairs, dtype=bool)
        self.peak = np.zeros(n_pairs)
        self.t_peak = np.full(n_pairs, math.nan)
        self.pen = np.zeros(n_pairs)
        self.imp = np.zeros((n_pairs, IMP_COLUMNS))

    def arrays(self) -> tuple:
        """The ``pstate`` tuple of ``kernel.advance`` (the arrays themselves, not copies)."""
        return (self.touching, self.ramp, self.clamped, self.peak, self.t_peak, self.pen,
                self.imp)  # fmt: skip

    def of(self, p: int) -> tuple:
        """(touching, ramp, clamped, peak N, t_peak s, pen m, impulses ``imp[p]``) of pair p."""
        return (self.touching[p], self.ramp[p], self.clamped[p], self.peak[p], self.t_peak[p],
                self.pen[p], self.imp[p].copy())  # fmt: skip

    def put(self, p: int, state) -> None:
        """Pair p takes ``state`` (as ``of`` gives it: a pair carried over from another set)."""
        (self.touching[p], self.ramp[p], self.clamped[p], self.peak[p], self.t_peak[p],
         self.pen[p], self.imp[p]) = state  # fmt: skip

    def open(self, p: int, delta: float, rate: float, law) -> None:
        """Pair p, found overlapping, touches in the region of its state: penetration
        ``delta`` > 0 (m), its rate (m/s) and its law row ``law`` (k, e, c, d, clamp, ...);
        its accumulators start from ``delta``."""
        k, e, c, d, clamp = law[:LAW_COLUMNS]  # (LAW_K ... LAW_CLAMP)
        self.touching[p] = True
        self.ramp[p] = delta < d or c <= 0.0
        ind = clamp_indicator(delta, rate, k, e, c, d, self.ramp[p])
        self.clamped[p] = bool(clamp > 0 and c > 0 and ind < 0.0)
        self.peak[p], self.t_peak[p], self.pen[p] = 0.0, math.nan, delta
        self.imp[p] = 0.0

    def start(self, p: int, delta: float) -> None:
        """Pair p starts touching at penetration ``delta`` (m, about 0: its start found by the
        caller), in the ramp, unclamped; its accumulators start from max(delta, 0)."""
        self.touching[p], self.ramp[p], self.clamped[p] = True, True, False
        self.reset_accumulators(p, delta)

    def hold(self, p: int, delta: float, law) -> None:
        """Pair p touches at the static penetration ``delta`` (m) of its law row ``law``:
        in the region of that penetration, unclamped (its accumulators kept)."""
        self.touching[p] = True
        self.ramp[p] = delta < law[LAW_D] or law[LAW_C] <= 0.0
        self.clamped[p] = False

    def reset_accumulators(self, p: int, delta: float) -> None:
        """Pair p's peak force and maximum penetration start again at penetration ``delta``
        (m)."""
        self.peak[p], self.t_peak[p], self.pen[p] = 0.0, math.nan, max(delta, 0.0)
        self.imp[p] = 0.0

    def accumulators(self, p: int) -> tuple[float, float, float]:
        """(peak force N, its time s, maximum penetration m) of pair p."""
        return float(self.peak[p]), float(self.t_peak[p]), float(self.pen[p])
