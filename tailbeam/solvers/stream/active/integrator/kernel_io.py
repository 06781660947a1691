"""What the compiled active-set kernel writes besides the state, and what it carries between
calls.

The kernel (``kernel.advance``) appends plate force rows (t, pair, F) and kink rows (t,
``EventCode``, pair) to two buffers, reports why it returned and its work in an integer array
(``iout``, indexed by ``kernel.IO_*``), and hands back the rows whose events it applied at
the instant it returned at (``fresh``), which the next call starting there takes in. A full
buffer stops a call early (``kernel.ST_BUFFER``): it is grown here and the call resumes.
"""

import math
from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.results.records import EventCode
from tailbeam.solvers.stream.active.compiled import kernel as ak
from tailbeam.solvers.stream.active.compiled.pairs import R_EDGE


@dataclass(frozen=True)
class Outcome:
    """Why ``ActiveSet.advance`` returned.

    Attributes
    ----------
    code : EventCode
        The event it stopped at: ``CONTACT_START``, ``CONTACT_END``, ``LEAVE``, ``REST`` (a
        ball's plate contact settled: SETTLE), or ``NONE`` (t_stop reached).
    t : float
        Time reached (s).
    index : int
        The pair (start, end) or the ball (leave, settle); -1 at t_stop.
    edge : int
        Leave: the edge passed, 0..3 in ``tailbeam.physics.incline.EDGES`` order; else -1.
    """

    code: EventCode
    t: float
    index: int = -1
    edge: int = -1


class KernelIO:
    """The kernel's output buffers, its integer outputs and the fresh rows, with their limits.

    Parameters
    ----------
    max_steps : int
        Accepted steps allowed per call (>= 1).
    nodes_per_step : int
        Interior force rows per accepted step (>= 0).
    row_capacity, log_capacity : int
        Initial rows of the force and kink buffers (grown as needed).

    Attributes
    ----------
    max_steps, nodes : int
        As given.
    rows : ndarray, shape (R, 3)
        Force rows (t s, pair, F N); the first ``iout[IO_ROWS]`` written.
    log : ndarray, shape (L, 3)
        Kink rows (t s, ``EventCode``, pair); the first ``iout[IO_LOG]`` written.
    iout : ndarray of int64, shape (IO_SIZE,)
        Status, event index and edge, work counters, buffer and fresh-row counts.
    fresh : ndarray of int64, shape (MAX_FRESH, 2)
        Rows (kind, index) whose events were applied at ``t_fresh``; the first
        ``iout[IO_FRESH]``.
    t_fresh : float
        The time (s) the fresh rows were applied at (NaN: none yet).
    """

    def __init__(self, max_steps: int, nodes_per_step: int, row_capacity: int,
                 log_capacity: int):  # fmt: skip
        self.max_steps, self.nodes = int(max_steps), int(nodes_per_step)
        if self.nodes < 0:
            raise InputError("nodes_per_step", f"must be >= 0, got {nodes_per_step!r}")
        if self.max_steps < 1:
            raise InputError("max_steps", f"must be >= 1, got {max_steps!r}")
        self.rows = np.zeros((int(row_capacity), 3))
        self.log = np.zeros((int(log_capacity), 3))
        self.iout = np.zeros(ak.IO_SIZE, dtype=np.int64)
        self.fresh = np.zeros((ak.MAX_FRESH, 2), dtype=np.int64)
        self.t_fresh = math.nan

    # --- outputs ---------------------------------------------------------------------------
    def force_rows(self) -> np.ndarray:
        """(R, 3) rows (t s, pair, F N) of the plate forces written so far."""
        return self.rows[: self.iout[ak.IO_ROWS]]

    def kink_log(self) -> list:
        """(t s, ``EventKind``, pair) of the kinks handled inside so far."""
        out = self.log[: self.iout[ak.IO_LOG]]
        return [(float(t), EventCode(int(k)).kind, int(p)) for t, k, p in out]

    def clear_outputs(self, rows: bool = True) -> None:
        """Forget the kink log and (``rows``) the force rows: the caller has consumed them."""
        if rows:
            self.clear_rows()
        self.iout[ak.IO_LOG] = 0

    def clear_rows(self) -> None:
        """Forget the force rows (the caller has consumed them)."""
        self.iout[ak.IO_ROWS] = 0

    @property
    def stats(self) -> dict:
        """Accepted steps, attempted steps, right-hand-side evaluations and events found
        again at the instant they were applied (searched again: ``kernel.advance``)."""
        return {"steps": int(self.iout[ak.IO_STEPS]), "attempts": int(self.iout[ak.IO_ATTEMPTS]),
                "nfev": int(self.iout[ak.IO_NFEV]),
                "found_again": int(self.iout[ak.IO_AGAIN])}  # fmt: skip

    def reset_stats(self) -> None:
        """Start the work counters of ``stats`` again from 0."""
        for io in (ak.IO_STEPS, ak.IO_ATTEMPTS, ak.IO_NFEV, ak.IO_AGAIN):
            self.iout[io] = 0

    # --- the events just applied (carried to the next call at the same time) ----------------
    def fresh_rows(self) -> tuple[float, list]:
        """(t s, [(kind, index)]): the rows whose events were applied at the time t the last
        call returned at (kind ``pairs.R_CONTACT``, ``R_FULL``, ``R_CLAMP``: index a pair;
        ``R_EDGE``: index 4 ball + edge). The next call from t does not find them again at
        t (``kernel.advance``)."""
        n = int(self.iout[ak.IO_FRESH])
        return self.t_fresh, [(int(k), int(i)) for k, i in self.fresh[:n]]

    def set_fresh(self, t: float, rows) -> None:
        """Rows (kind, index) whose events were applied at time t (s), as ``fresh_rows``
        gives them (at most ``kernel.MAX_FRESH`` kept): a set rebuilt at t carries those of
        the set it replaces."""
        rows = list(rows)[: ak.MAX_FRESH]
        for q, (k, i) in enumerate(rows):
            self.fresh[q] = k, i
        self.iout[ak.IO_FRESH] = len(rows)
        self.t_fresh = float(t)

    def forget_fresh(self, p: int) -> None:
        """Pair p's state was changed by the caller: its rows are no longer fresh."""
        t, rows = self.fresh_rows()
        kept = [(k, i) for k, i in rows if k == R_EDGE or i != p]
        if len(kept) < len(rows):
            self.set_fresh(t, kept)

    # --- one call ----------------------------------------------------------------------------
    def begin(self, t0: float) -> None:
        """A call starts at t0 (s): the fresh rows are carried into it only if they were
        applied at t0."""
        if t0 != self.t_fresh:
            self.iout[ak.IO_FRESH] = 0

    def buffer_full(self) -> bool:
        """Whether the last call stopped early on a full buffer (``grow``, then call again)."""
        return int(self.iout[ak.IO_STATUS]) == ak.ST_BUFFER

    def grow(self, n_pairs: int) -> None:
        """Enlarge the force and kink buffers (keeping their rows) so that a call resumed
        with ``n_pairs`` pairs goes on."""
        need = 4 * (self.nodes + 1) * n_pairs
        if self.iout[ak.IO_ROWS] + need > self.rows.shape[0] // 2:
            rows = np.zeros((2 * self.rows.shape[0] + need, 3))
            rows[: self.rows.shape[0]] = self.rows
            self.rows = rows
        if self.iout[ak.IO_LOG] + 2 > self.log.shape[0] // 2:
            log = np.zeros((2 * self.log.shape[0] + 4, 3))
            log[: self.log.shape[0]] = self.log
            self.log = log

    def outcome(self, t: float) -> Outcome:
        """The ``Outcome`` of a call that returned at t (s); its fresh rows are those applied
        at t.

        Raises
        ------
        WorkLimitError
            The call took ``max_steps`` steps.
        RuntimeError
            Its step size underflowed.
        """
        self.t_fresh = t
        status = int(self.iout[ak.IO_STATUS])
        if status == ak.ST_STEP_LIMIT:
            raise WorkLimitError(
                f"active set: more than max_steps={self.max_steps} steps in one advance by "
                f"t = {t:.6g} s; raise max_steps or hand smaller sets/intervals"
            )
        if status == ak.ST_STEP_TINY:
            raise RuntimeError(f"active set: step size underflow at t = {t:.17g} s")
        code = EventCode(status)
        index = int(self.iout[ak.IO_INDEX]) if code != EventCode.NONE else -1
        edge = int(self.iout[ak.IO_EDGE]) if code == EventCode.LEAVE else -1
        return Outcome(code, t, index, edge)
