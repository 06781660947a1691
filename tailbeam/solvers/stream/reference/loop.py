"""The stream reference's loop: scipy's DOP853 driven step by step, every step searched for
events; a step in which one is found is redone to end exactly at it, where the event is
applied and the integration restarts (``tailbeam.solvers.stream.reference.solver``).
"""

import math

import numpy as np
from scipy.integrate import DOP853

from tailbeam.errors import WorkLimitError

SAME_TIME = 1e-9  # events closer than this (fraction of a step) are simultaneous


class Integrator:
    """Starts and steps DOP853 solvers on the current state layout and contacts.

    Parameters
    ----------
    dynamics : Dynamics
        The right-hand side of the current contacts.
    layout : StateLayout
        How many balls the state holds (their absolute tolerances).
    plate : ReferencePlate or None
        The modal plate (its modes' tolerances), or None for the rigid plate.
    rtol : float
        DOP853's relative tolerance; atol = rtol x 1 mm on positions, rtol x 1 m/s on
        velocities, rtol x (1 m/s) / r on a ball's angular velocity (with friction; r its
        radius) (and ``ReferencePlate.atol`` on the modes).
    radius : ndarray, optional
        Radius of every ball (m), for the angular velocities' tolerances.
    """

    def __init__(self, dynamics, layout, plate, rtol, radius=None):
        self.dynamics = dynamics
        self.layout = layout
        self.plate = plate
        self.rtol = rtol
        self.radius = radius
        # (see Dynamics._modal_rhs: a modal trial step may overflow, DOP853 then rejects it)
        self.trial_errors = {} if plate is None else dict(over="ignore", invalid="ignore")

    def start(self, t, y, t_bound, h0, max_step):
        """A DOP853 solver from time t (s), state y, to ``t_bound`` (s), first step h0 (s;
        None: DOP853's choice) and largest step ``max_step`` (s)."""
        n = len(self.layout.active)
        atol = self.rtol * np.concatenate([np.full(3 * n, 1e-3), np.ones(3 * n)])
        if self.layout.spin:
            spin = np.repeat(1.0 / self.radius[self.layout.active], 3)
            atol = np.concatenate([atol, self.rtol * spin])
        if self.plate is not None:
            atol = np.concatenate([atol, self.plate.atol(self.rtol)])
        if h0 is not None:
            h0 = min(h0, t_bound - t) if t_bound > t else None
        return DOP853(self.dynamics.rhs(), t, y, t_bound, rtol=self.rtol, atol=atol,
                      first_step=h0, max_step=max_step)  # fmt: skip

    def step(self, solver) -> None:
        """One step of ``solver`` (RuntimeError if DOP853 fails)."""
        with np.errstate(**self.trial_errors):
            message = solver.step()
        if solver.status == "failed":
            raise RuntimeError(f"stream reference: DOP853 failed: {message}")


class StepLoop:
    """Integrates until ``duration``: steps, searches each for events, applies them and the
    releases, records the accepted steps.

    Parameters
    ----------
    integrator : Integrator
        Starts and steps the DOP853 solvers.
    search : EventSearch
        Finds the first event on a step.
    changes : SceneChanges
        Applies events and releases.
    series : StepSeries
        Records the accepted steps.
    max_steps : int
        Most DOP853 steps (accepted or redone) before a WorkLimitError.
    progress : callable or None
        Called with the time (s) reached after every accepted step.
    """

    def __init__(self, integrator, search, changes, series, max_steps, progress):
        self.integrator = integrator
        self.search = search
        self.changes = changes
        self.series = series
        self.max_steps = max_steps
        self.progress = progress
        self.steps = 0  # DOP853 steps taken
        self.solver = None
        self.h_cap = math.inf  # largest step (s): halved while a modal step goes too far
        self.fresh = set()  # keys of the events applied at the solver's start time
        self.pending = None  # (row, time) of the event the current step is redone to end at

    def run(self, t, y, duration) -> None:
        """Integrate from time t (s) and state vector y to ``duration`` (s)."""
        self.restart(t, y, self.changes.next_stop(duration), None)
        self.series.record(t, y)
        while True:
            if self.solver.status == "finished":
                if self.pending is None and self.solver.t >= duration:
                    return
                self.at_bound(duration)
            else:
                self.advance(duration)

    def restart(self, t, y, t_bound, h0) -> None:
        """A new solver from time t (s) and state y to ``t_bound`` (s), first step h0 (s)."""
        self.solver = self.integrator.start(t, y, t_bound, h0, self.h_cap)

    def at_bound(self, duration) -> None:
        """The solver reached its bound: a release time, or the end of a redone step, where
        the event is applied if its row lies within its dead band of the crossing; otherwise
        (the discarded step, which straddled the kink, placed the root early) the
        integration goes on from there and the next step finds it again, closer."""
        t, y, h0, fresh = self.solver.t, self.solver.y, None, set()
        if self.pending is None:
            y = self.changes.release_due(t, y)
        elif self.search.within_band(self.pending[0], y):
            key = self.pending[0].key
            t = float(t)
            y, h0 = self.changes.apply(key, t, y)
            fresh = {key}
        self.pending, self.fresh, self.h_cap = None, fresh, math.inf
        self.restart(t, y, self.changes.next_stop(duration), h0)

    def advance(self, duration) -> None:
        """One DOP853 step: accepted if no event lies on it, else redone to end at the event
        (or the event applied at once if it lies at the step's start)."""
        solver = self.solver
        t0, y0 = solver.t, solver.y.copy()
        self.search.set_directions(y0)  # (Coulomb's law: the step's sliding directions)
        self.integrator.step(solver)
        self.steps += 1
        if self.steps > self.max_steps:
            raise WorkLimitError(
                f"stream reference: more than max_steps={self.max_steps} steps by "
                f"t = {t0:.6g} s; raise max_steps or shorten the duration"
            )
        dense, t1 = solver.dense_output(), solver.t
        if self.search.too_far(dense, t0, t1):  # modal plate: the step bound of the gap rows
            self.h_cap = 0.5 * (t1 - t0)
            self.restart(t0, y0, solver.t_bound, self.h_cap)
            return
        found = self.search.detect(dense, t0, t1, self.fresh)
        if found is not None and self.pending is not None:
            if found[1] >= self.pending[1] - SAME_TIME * (t1 - t0):
                found = None  # (about) simultaneous with the pending event: taken after it
        if found is None:
            self.accept(dense, t0, t1)
        else:
            self.stop_at(*found, t0, y0, duration)

    def accept(self, dense, t0, t1) -> None:
        """Record the accepted step [t0, t1] (s)."""
        self.series.update_peaks(dense, t0, t1)
        self.series.record(t1, self.solver.y)
        if self.progress is not None:
            self.progress(t1)
        self.fresh = set() if t1 > t0 else self.fresh

    def stop_at(self, row, t_e, t0, y0, duration) -> None:
        """An event of ``row`` at t_e (s) on the step from t0 (s), state y0: applied there if
        t_e is t0 to round-off, else the step is redone to end at t_e."""
        if t_e <= t0 + 4.0 * np.spacing(t0):
            t = float(t0)
            y, h0 = self.changes.apply(row.key, t, y0)
            self.fresh = self.fresh | {row.key}
            self.pending = None
            self.restart(t, y, self.changes.next_stop(duration), h0)
        else:
            self.pending = (row, t_e)
            self.restart(t0, y0, t_e, t_e - t0)
