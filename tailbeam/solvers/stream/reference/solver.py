"""Slow, independent reference for streams: all balls and the inclined plate together, the
plate rigid or modal (two-way, ``plate=ReferencePlate(...)``, see below).

One ODE for every ball (3-D translation, frictionless, normal forces only, no rotation),
integrated by scipy's DOP853 (the method of ``solve_ivp(method="DOP853")``, driven step by
step through its ``OdeSolver`` class so that every step can be checked for contacts; rtol
1e-12 by default). Every pair is watched (O(N^2): this is the slow reference):

* ball-ball and ball-plate contacts use the IMPACT law of ``tailbeam.physics.contact_law``
  (from the contact table, ``tailbeam.physics.contacts``: ball-ball R = R1 R2 / (R1 + R2),
  E* of both materials; ball-plate), the
  pair geometry of ``tailbeam.physics.pair`` and the plate frame of
  ``tailbeam.physics.incline`` (gravity g (sin theta, 0, -cos theta));
* events at every kink: contact start and end of every pair, penetration = d (STEP kink,
  when c > 0), clamp on/off (when c > 0 and the clamp is on), and a ball's centre passing an
  edge of the plate (the ball leaves and is dropped). Inside a region each pair's force is
  that region's smooth formula; a step in which an event is found is discarded and redone
  to end exactly at the event, where the integration restarts with the new region, so no
  accepted step straddles a kink.

Modules: the state vector, kinematics and right-hand side (``reference_state``), the event
rows and their search (``reference_events``), the pairs, contacts, leaves and releases
(``reference_contacts``), what an accepted step records (``reference_steps``); this module
holds the driver loop and the result.

Modal plate (``tailbeam.solvers.stream.reference.plate``: the model, exact or frozen mode shapes).
The state gains the modal coordinates [q | q'] after the balls (atol: deflections to rtol x
1 mm, rates to rtol x 1 m/s). A ball's plate rows use the gap z - w, w = phi(x, y) . q.
What is certified: with frozen shapes (a contact's) the rows are polynomials of degree <= 14
on a step, as on the rigid plate (``reference_events``). With exact shapes phi(x(s), y(s))
is not a polynomial; the 15 values are exact samples, and the certificate and the root
search act on their interpolant. Every step is bounded so that no ball moves sideways more
than 1 / k_max (k_max: the top mode's wavenumber; the step is redone shorter otherwise):
along such a path each shape's Chebyshev coefficients fall like (k L / 4)^n / n!, and the
interpolant misses the row only by products of them with the top coefficients of the dense
output (~rtol): an estimate (~1e-12 of the row's scale; measured 1.5e-14 of r^2), not a
certificate. A crossing found on the interpolant is applied only where the true row lies
within its dead band (else the step goes on and finds it again, closer), so no event is
applied early; a dip narrower than that estimate could be missed. The modes also bound the
steps (at least MODAL_STEPS_PER_PERIOD per period of the top mode: too long a run is refused
at once).
"""

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import DOP853

from tailbeam.errors import InputError, WorkLimitError, require_positive
from tailbeam.physics.contact_law import HERTZ_EXPONENT
from tailbeam.physics.contacts import LawOptions, contact_table
from tailbeam.physics.incline import InclinedPlate
from tailbeam.solvers.numerics.step_events import STEP_POINTS
from tailbeam.solvers.stream.reference.contacts import ReferenceContacts
from tailbeam.solvers.stream.reference.events import ReferenceEvents
from tailbeam.solvers.stream.reference.plate import ReferencePlate
from tailbeam.solvers.stream.reference.state import ReferenceState
from tailbeam.solvers.stream.reference.steps import ReferenceSteps

SAME_TIME = 1e-9  # events closer than this (fraction of a step) are simultaneous
MODAL_STEPS_PER_PERIOD = 5  # a lower bound of the steps per period of the top mode


@dataclass
class StreamReferenceResult:
    """Contacts (one ``Impact`` per ball per contact), leave events, the event log
    (``Event`` records in time order), and per accepted step: times, total energy (J) and states
    (names of the balls present, positions (n, 3) m, velocities (n, 3) m/s)."""

    names: tuple
    masses: np.ndarray
    contacts: list
    leaves: list
    events: list
    times: np.ndarray
    energy: np.ndarray
    states: list
    steps: int
    info: dict
    plate_states: list = field(default_factory=list)  # (q, q') per step (modal plate)

    def contacts_of(self, ball: str) -> list:
        return [c for c in self.contacts if c.ball == ball]


def simulate_stream_reference(
    balls,
    incline: InclinedPlate,
    duration: float,
    *,
    damping: float = 0.0,
    penetration: float = 1e-4,
    clamp: bool = True,
    exponent: float = HERTZ_EXPONENT,
    rtol: float = 1e-12,
    max_steps: int = 200_000,
    release_times=None,
    progress=None,
    plate: ReferencePlate | None = None,
    contacts=None,
) -> StreamReferenceResult:
    """Integrate ``balls`` (``tailbeam.Ball``, positions and velocities in the plate frame)
    on ``incline`` for ``duration`` s; see the module docstring.

    damping c (N s/m), penetration d (m), clamp, exponent e: the IMPACT parameters of every
    pair (stiffness from Hertz). rtol: DOP853's relative tolerance (atol = rtol x 1 mm on
    positions, rtol x 1 m/s on velocities). max_steps bounds the work (WorkLimitError).
    release_times (s, one per ball, default all 0): a ball enters the scene at its time, at
    its given position and velocity (event ``release``; the energy series jumps there).
    progress: optional callable, called with the time (s) reached after every accepted step.
    plate: a ``ReferencePlate`` (the modal plate, two-way,
    ``tailbeam.solvers.stream.reference.plate``) or None (the rigid plate). contacts: the
    balls' ``ContactTable`` (its settings then replace the IMPACT parameters given here).
    """
    duration = require_positive("duration", duration)
    if not 1e-14 <= rtol <= 1e-3:
        raise InputError("rtol", f"must lie in [1e-14, 1e-3], got {rtol!r}")
    options = LawOptions(exponent, damping, penetration, clamp) if contacts is None else contacts
    balls = list(balls)
    release = _release_times(release_times, len(balls))
    if plate is not None:
        if not isinstance(plate, ReferencePlate):
            raise InputError("plate", "must be a ReferencePlate (a modal basis and its damping)")
        plate.check_size(incline)
        _check_modal_work(plate, duration, max_steps)
    sim = _Reference(balls, incline, options, rtol, max_steps, release, plate)
    sim.progress = progress
    return sim.run(duration)


class _Reference(ReferenceState, ReferenceEvents, ReferenceContacts, ReferenceSteps):
    """The driver: DOP853 step by step, every step checked for events (module docstring)."""

    def __init__(self, balls, incline, options, rtol, max_steps, release, plate=None):
        _check_balls(balls, incline)
        self.plate, self.h_cap = plate, math.inf
        self.trial_errors = {} if plate is None else dict(over="ignore", invalid="ignore")
        self.balls, self.incline, self.rtol, self.max_steps = balls, incline, rtol, max_steps
        self.g = incline.gravity_vector
        self.mass = np.array([b.mass for b in balls])
        self.table = contact_table(balls, options, incline.plate.material)  # the pairs' laws
        self.active = [i for i in range(len(balls)) if release[i] <= 0.0]
        self.waiting = sorted((float(release[i]), i) for i in range(len(balls)) if release[i] > 0)
        self.pairs = {}
        for i in self.active:
            self.add_pairs(i)
        self.contacts, self.leaves, self.events = [], [], []
        self.times, self.energy, self.states, self.plate_states = [], [], [], []
        self.steps = 0
        self.progress = None
        pos = np.array([balls[i].position for i in self.active], dtype=float).reshape(-1, 3)
        vel = np.array([balls[i].velocity for i in self.active], dtype=float).reshape(-1, 3)
        m = 0 if plate is None else plate.n_modes
        self.y = self.join(pos, vel, (np.zeros(m), np.zeros(m)) if m else None)
        self.t = 0.0
        self.touch(list(self.pairs.values()), 0.0)

    # --- main loop ------------------------------------------------------------------------
    def run(self, duration):
        fresh, pending, h0 = set(), None, None
        t_bound = self.next_stop(duration)
        solver = self.new_solver(self.t, self.y, t_bound, h0)
        self.record_step(self.t, self.y)
        while True:
            if solver.status == "finished":
                if pending is None and solver.t >= duration:
                    break
                if pending is None:  # a release time
                    fresh, h0 = set(), self.release_due(solver.t, solver.y)
                else:
                    fresh, h0 = self.finish_redo(pending[0], solver.t, solver.y)
                pending, t_bound = None, self.next_stop(duration)
                self.h_cap = math.inf
                solver = self.new_solver(self.t, self.y, t_bound, h0)
                continue
            t0, y0 = solver.t, solver.y.copy()
            with np.errstate(**self.trial_errors):  # (see make_modal_rhs)
                message = solver.step()
            if solver.status == "failed":
                raise RuntimeError(f"stream reference: DOP853 failed: {message}")
            self.steps += 1
            if self.steps > self.max_steps:
                raise WorkLimitError(
                    f"stream reference: more than max_steps={self.max_steps} steps by "
                    f"t = {t0:.6g} s; raise max_steps or shorten the duration"
                )
            dense, t1 = solver.dense_output(), solver.t
            if self.too_far(dense, t0, t1):  # modal plate: the step bound of the gap rows
                self.h_cap = 0.5 * (t1 - t0)
                solver = self.new_solver(t0, y0, t_bound, self.h_cap)
                continue
            found = self.detect(dense, t0, t1, fresh)
            if found is not None and pending and found[1] >= pending[1] - SAME_TIME * (t1 - t0):
                found = None  # (about) simultaneous with the pending event: taken after it
            if found is None:
                self.accept(dense, t0, t1)
                self.record_step(t1, solver.y)
                if self.progress is not None:
                    self.progress(t1)
                fresh = set() if t1 > t0 else fresh
                continue
            row, t_e = found
            if t_e <= t0 + 4.0 * np.spacing(t0):  # at the restart (to round-off): apply there
                h0 = self.apply(row[0], t0, y0)
                fresh = fresh | {row[0]}
                pending, t_bound = None, self.next_stop(duration)
            else:  # redo the step so that it ends exactly at the event
                self.t, self.y = t0, y0
                pending, t_bound, h0 = (row, t_e), t_e, t_e - t0
            solver = self.new_solver(self.t, self.y, t_bound, h0)
        self.finish()
        return self.result(duration)

    def finish_redo(self, row, t, y):
        """At the end of a redone step: apply the event if its row is within its dead band
        of the crossing; otherwise (the discarded step, which straddled the kink, placed the
        root early) go on from here: the next step finds it again, closer. Returns the
        fresh set and the next first step."""
        x, v = self.split(y)
        key, sign, _, band = row
        modes = self.modes(y[None])
        if sign * self.row_values([row], x[None], v[None], modes)[0, 0] <= band:
            return {key}, self.apply(key, t, y)
        self.t, self.y = t, y
        return set(), None

    def new_solver(self, t, y, t_bound, h0):
        self.t, self.y = t, y
        n = len(self.active)  # atol: rtol x 1 mm on positions, rtol x 1 m/s on velocities
        atol = self.rtol * np.concatenate([np.full(3 * n, 1e-3), np.ones(3 * n)])
        if self.plate is not None:
            atol = np.concatenate([atol, self.plate.atol(self.rtol)])
        if h0 is not None:
            h0 = min(h0, t_bound - t) if t_bound > t else None
        return DOP853(self.make_rhs(), t, y, t_bound, rtol=self.rtol, atol=atol, first_step=h0,
                      max_step=self.h_cap)  # fmt: skip

    def too_far(self, dense, t0, t1) -> bool:
        """Modal plate: whether a ball moved more than 1 / k_max sideways on the step (k_max:
        the top mode's wavenumber). Below it the mode shapes along the path are so smooth that
        the 15-point interpolant of the plate gap rows is exact to round-off (module
        docstring); the step is then redone shorter."""
        if self.plate is None or t1 <= t0 or not self.active:
            return False
        x = self.states_at(dense, t0 + STEP_POINTS * (t1 - t0))[0]
        travel = np.max(np.linalg.norm(x[:, :, :2] - x[:1, :, :2], axis=-1))
        return bool(self.plate.k_max * travel > 1.0)

    def result(self, duration):
        info = {
            "solver": f"stream reference: scipy DOP853 rtol={self.rtol:g}, restarted at kinks",
            "plate": "rigid"
            if self.plate is None
            else f"modal, two-way: {self.plate.n_modes} modes, {self.plate.shapes} shapes",
            "duration": duration,
        }
        return StreamReferenceResult(
            tuple(b.name for b in self.balls), self.mass, self.contacts, self.leaves,
            self.events, np.array(self.times), np.array(self.energy), self.states,
            self.steps, info, self.plate_states,
        )  # fmt: skip


def _check_modal_work(plate, duration, max_steps):
    """The modes bound the steps: at least MODAL_STEPS_PER_PERIOD per period of the top mode
    (measured 9-20 at rtol 1e-12); refuse a run that cannot fit max_steps before it starts."""
    estimate = MODAL_STEPS_PER_PERIOD * duration * float(np.max(plate.omega)) / (2.0 * math.pi)
    if estimate > max_steps:
        raise WorkLimitError(
            f"stream reference: the modal plate (top mode {np.max(plate.omega) / 2 / math.pi:.4g}"
            f" Hz) needs at least ~{estimate:.3g} steps for {duration:g} s, above "
            f"max_steps={max_steps}; raise max_steps, shorten the duration or keep fewer modes"
        )


def _release_times(release_times, n):
    if release_times is None:
        return np.zeros(n)
    times = np.asarray(release_times, dtype=float)
    if times.shape != (n,) or not np.all(np.isfinite(times)) or np.any(times < 0.0):
        raise InputError("release_times", f"must be {n} finite times >= 0 s (one per ball)")
    return times


def _check_balls(balls, incline):
    names = set()
    for b in balls:
        field_ = f"balls[{b.name}]"
        if b.name in names:
            raise InputError(f"{field_}.name", "is used by an earlier ball")
        names.add(b.name)
        if b.position[2] <= 0.0:
            raise InputError(f"{field_}.position", "the centre must lie above the plate (z > 0)")
        if np.any(incline.edge_distances(b.position[:2]) < 0.0):
            raise InputError(f"{field_}.position", "the centre must lie over the plate")
