"""The fast stream solver: many balls on the rigid inclined plate, cost growing with impacts.

Event-driven. Balls that touch nothing move in closed form (``tailbeam.solvers.numerics.flight``) and
carry predictions in one heap: release, plate touch, edge crossing and, among the candidate
pairs of the current epoch (``tailbeam.solvers.stream.driver.broadphase``, certified over the epoch), the
first touch of two balls. The balls in contact, and every ball that could reach one of them
within the set's horizon, form the ACTIVE SET, integrated by the compiled kernel
(``tailbeam.solvers.stream.active.set``: DOP853, every kink an event) up to the next heap event, its
horizon or its own next event. Work is therefore spent per contact and per event, never per
ball per step; memory holds the records, not the trajectories.

Persistent contact at bounded cost: a ball whose plate contact has settled (the kernel's
SETTLE: its normal excess energy below 1/2 m rest_speed^2) or that rebounds slower than
``rest_speed`` becomes a SLIDER: its height is held at the static penetration and it slides
frictionlessly downhill in closed form (its normal oscillation, below the rest energy, is
dropped: the energy removed is counted in ``stats["rest_energy_removed"]``). A slider that
something approaches joins the active set again, at its static state (an equilibrium of the
full model, so nothing jumps).

Contacts are recorded as ``Impact`` (one per ball per contact; ``end`` is
``separated``, ``rest``, ``left`` or ``duration``); the plate's contact forces are kept as
piecewise-linear histories at their contact points and sliders as dead loads, for the modal
plate's sensors.

Modules: the heap of releases, epochs and closed-form predictions (``stream_heap``), the
stepping of the active set and its events (``stream_set_events``), its membership
(``stream_membership``), the records, loads and energy ledger (``stream_records``); this
module holds the driver loop, its work bounds and the entry points.
"""

import contextlib
import heapq
import math
import time as _time
from dataclasses import dataclass, field, replace

import numpy as np

from tailbeam.errors import InputError, WorkLimitError, require_positive
from tailbeam.physics.contact_law import HERTZ_EXPONENT
from tailbeam.physics.contacts import contact_table
from tailbeam.physics.incline import InclinedPlate
from tailbeam.progress import note, quiet, task
from tailbeam.solvers.stream.driver.balls import SLIDE, Balls, LawOptions
from tailbeam.solvers.stream.driver.heap import _EPOCH, _RELEASE, StreamHeap
from tailbeam.solvers.stream.driver.membership import StreamMembership
from tailbeam.solvers.stream.driver.records import StreamRecords
from tailbeam.solvers.stream.driver.set_events import StreamSetEvents

DEFAULT_RTOL = 1e-10
DEFAULT_REST_SPEED = 0.01  # m/s, the rigid and coupled solvers' value
DEFAULT_MAX_STEPS = 50_000_000  # kernel steps + events: the work bound
MAX_PARTICLES = 200_000  # per scene: memory ~40 kB per particle (records, force histories)
GRAZING_RETRIES = 2  # runs again at rtol / 10, / 100 after a stall at one instant: a last
# safety net (the kernel no longer finds an event again at the instant it applied it)
WORK_CHECK_EVERY = 16  # loop rounds between two checks of the work bound
STUCK_LIMIT = 5_000  # loop rounds without time moving before the run is stopped


@dataclass
class StreamRun:
    """What the stream solver found (``tailbeam.solvers.stream.stream_result`` presents it)."""

    particles: list  # as released (a release onto a rebounding ball is postponed)
    contacts: list
    leaves: list
    events: list
    loads: list  # (x, y, t_nodes, forces): plate contact force histories (m, s, N)
    dead_loads: list  # (x, y, t_from, t_to, force): sliders' weight on the plate
    status: int
    message: str
    stats: dict = field(default_factory=dict)


def solve_stream(
    particles,
    incline: InclinedPlate,
    duration: float,
    *,
    damping: float = 0.0,
    penetration: float = 1e-4,
    clamp: bool = True,
    exponent: float = HERTZ_EXPONENT,
    rtol: float = DEFAULT_RTOL,
    rest_speed: float = DEFAULT_REST_SPEED,
    max_work: int = DEFAULT_MAX_STEPS,
    progress=True,
    plate=None,
    contacts=None,
) -> StreamRun:
    """Simulate ``particles`` (``tailbeam.streams.generator.Particle``: released at their
    t_release with their position and velocity, plate frame) on ``incline`` for ``duration``
    s. IMPACT parameters shared by every pair (stiffness from Hertz for each pair); rtol: the
    kernel's relative tolerance; rest_speed (m/s): see the module docstring; max_work: bound
    on kernel steps plus events (WorkLimitError beyond); plate: a ``StreamPlate`` (the modal
    plate, two-way) or None (the rigid plate); contacts: the particles' ``ContactTable``
    (its settings then replace the IMPACT parameters given here)."""
    duration = require_positive("duration", duration)
    if not 1e-14 <= rtol <= 1e-4:
        raise InputError("rtol", f"must lie in [1e-14, 1e-4], got {rtol!r}")
    if rest_speed < 0:
        raise InputError("rest_speed", f"must be >= 0, got {rest_speed!r}")
    if contacts is None:
        contacts = LawOptions(exponent, damping, penetration, clamp)
    contacts = contact_table(particles, contacts, incline.plate.material)
    for attempt in range(GRAZING_RETRIES + 1):
        if plate is not None:
            plate.reset()
        sim = _Stream(particles, incline, duration, contacts, rtol, rest_speed, max_work, plate)
        try:
            run = _run(sim, duration, progress)
        except _Stuck as err:
            if attempt == GRAZING_RETRIES:
                raise WorkLimitError(str(err)) from None
            rtol *= 0.1
            note(f"{err}; running again with rtol {rtol:g}")
            continue
        run.stats["rtol"] = rtol
        return run


def _run(sim, duration, progress) -> "StreamRun":
    label = f"simulating {duration:g} s, {len(sim.balls.names)} particles"
    with contextlib.ExitStack() as stack:
        if callable(progress):
            bar = _CallbackBar(progress)
        else:
            if not progress:
                stack.enter_context(quiet())
            bar = stack.enter_context(task(label, total=1e3 * duration, unit="ms simulated"))
        return sim.run(bar)


class _Stuck(WorkLimitError):
    """Contacts start and end again at one instant: no progress (a grazing contact). The
    active set carries the events it applied at an instant into its next call from there
    (``active_kernel.advance``), the cause seen before; the retry stays as a safety net."""


class _CallbackBar:
    """A progress 'bar' that reports the simulated time reached (s) to a callable."""

    def __init__(self, report):
        self.report, self.ms = report, 0.0

    def update(self, ms):
        self.ms += ms
        self.report(self.ms / 1e3)


class _Stream(StreamHeap, StreamSetEvents, StreamMembership, StreamRecords):
    """The event loop; see the module docstring."""

    def __init__(self, particles, incline, duration, contacts, rtol, rest_speed, max_events, plate):
        from tailbeam.solvers.stream.active.members import ActiveMembers

        self.balls = Balls(particles, incline, contacts)
        self.incline, self.duration = incline, duration
        self.rest_speed, self.max_events = rest_speed, max_events
        self.plate = plate
        self.act = ActiveMembers(
            self.balls, rtol, self._settle_energy, plate, self._resting_outside
        )
        self.landing = set()  # modal plate: balls within the deflection bound, touching nothing
        self.hold = {}  # ball -> time of a contact end: core until time moves on
        self.grazing = {}  # ball -> (time of its last plate contact end, how many then)
        self.w_margin = 0.0  # modal plate: plate touches are predicted this far above it
        self.heap, self.seq, self.t, self.rounds = [], 0, 0.0, 0
        self.epoch_end, self.set_end = 0.0, 0.0
        self.core = set()
        self.contacts, self.leaves, self.events = [], [], []
        self.open = {}  # (i, j) -> [Impact(s)] of the contacts in progress
        self.limit = {}  # i -> time at which ball i's plate contact is declared at rest
        self.loads, self.dead_loads = [], []
        self.stats = dict.fromkeys(
            (
                "heap_events",
                "stale",
                "set_events",
                "set_calls",
                "epochs",
                "late_starts",
                "postponed_releases",
            ),
            0,
        )
        # the energy ledger (J): released = left + at the end + removed at rest + dissipated
        for key in ("rest_energy_removed", "energy_released", "energy_left", "energy_final"):
            self.stats[key] = 0.0
        self.epoch = self._epoch_length()

    # --- setup ----------------------------------------------------------------------------
    def _epoch_length(self) -> float:
        """Epochs short enough that balls move ~ their radius: O(1) candidates per ball."""
        b = self.balls
        if not len(b.names):
            return self.duration
        speed = np.linalg.norm(b.v0, axis=1).max() + 1.0
        return float(min(self.duration, max(1e-4, 0.5 * b.radius.min() / speed)))

    def _settle_energy(self, i: int) -> float:
        return 0.5 * self.balls.mass[i] * self.rest_speed**2

    # --- the loop ---------------------------------------------------------------------------
    def run(self, bar) -> StreamRun:
        wall = _time.perf_counter()
        for i, t in enumerate(self.balls.t_release):
            self.push(float(t), _RELEASE, i)
        self.push(0.0, _EPOCH)
        shown, stuck, t_last = 0.0, 0, -1.0
        while True:
            self._check_work()
            stuck = stuck + 1 if self.t == t_last else 0
            t_last = self.t
            if stuck > STUCK_LIMIT:
                raise _Stuck(self._stuck_message())
            t_next = self.heap[0][0] if self.heap else math.inf
            target = min(t_next, self.duration)
            if self.act.members and self._advance_set(target):
                continue
            self.t = self.act.now = target
            if self.t - shown > 1e-3:
                bar.update(1e3 * (self.t - shown))
                shown = self.t
            if t_next >= self.duration:
                break
            self._handle(heapq.heappop(self.heap))
        bar.update(1e3 * (self.duration - shown))
        return self._finish(_time.perf_counter() - wall)

    def _stuck_message(self) -> str:
        """The loop has not moved time for STUCK_LIMIT rounds: what is going on."""
        names = [self.balls.names[i] for i in sorted(self.core)][:4]
        return (
            f"rtol: the stream solver makes no progress at t = {self.t:.9g} s: contacts of "
            f"{', '.join(names)} start and end again at one instant (a grazing contact the "
            "event restart cannot resolve, a known limitation); a tighter rtol resolves it"
        )

    def _check_work(self):
        self.rounds += 1
        if self.rounds % WORK_CHECK_EVERY:
            return
        n = self.stats["heap_events"] + self.stats["set_events"] + self.act.steps()
        if n > self.max_events:
            raise WorkLimitError(
                f"max_steps: more than {self.max_events} steps and events by t = {self.t:.6g}"
                " s; raise max_steps, shorten duration or lower the stream rates"
            )

    def _released(self) -> list:
        """The particles with their actual release times."""
        b = self.balls
        return [
            p if b.t_release[q] == p.t_release else replace(p, t_release=float(b.t_release[q]))
            for q, p in enumerate(b.particles)
        ]

    def _finish(self, wall: float) -> StreamRun:
        b = self.balls
        self.t = self.duration
        self.stats["energy_final"] = self._final_energy()
        if self.plate is not None:
            self.plate.propagate(self.duration)
            # the tails of contacts still in progress are the plate's too (contact_tail)
            self.stats["energy_plate_final"] = self.plate.energy() + self.act.tail_energy()
            if self.plate.tail is not None:
                self.stats["tail_energy_dropped"] = self.act.tail_energy_dropped
        for key in list(self.open):
            recs = self.open.pop(key)
            peak, t_peak, pen = self.act.accumulators(key)
            for rec in recs:
                rec.peak_force, rec.t_peak, rec.max_penetration = peak, t_peak, pen
        for i in self.act.members:
            self._flush_nodes(i)
        for i in np.flatnonzero(b.status == SLIDE):
            if not b.in_set[i]:
                self._dead_load(int(i), self.duration)
        self.contacts.sort(key=lambda r: (r.t_start, r.ball))
        self.stats.update(self.act.stats())
        self.stats["wall_s"] = wall
        self.stats["contacts"] = len(self.contacts)
        return StreamRun(
            self._released(), self.contacts, self.leaves, self.events, self.loads,
            self.dead_loads, 0, "reached the end of the simulated time", self.stats,
        )  # fmt: skip
