"""The fast stream solver: many balls on an inclined plate, cost growing with impacts.

Event-driven. Balls that touch nothing move in closed form (``tailbeam.solvers.numerics.flight``)
and carry predictions in one heap (``heap``): release, plate touch, edge crossing and, among
the candidate pairs of the current epoch (``broadphase``, certified over the epoch), the first
touch of two balls (``heap_events`` handles them). The balls in contact, and every ball that
could reach one of them within the set's horizon, form the ACTIVE SET (``membership``),
integrated by the compiled kernel (``tailbeam.solvers.stream.active``: DOP853, every kink an
event) up to the next heap event, its horizon or its own next event (``set_events``); with
friction on the rigid plate as islands that cannot touch within the horizon, each with its
own step (``tailbeam.solvers.stream.active.islands``). Work is
therefore spent per contact and per event, never per ball per step; memory holds the
records, not the trajectories.

Persistent contact at bounded cost: a ball whose plate contact has settled (the kernel's
SETTLE, ``EventCode.REST``: its normal excess energy below 1/2 m rest_speed^2) or that
rebounds slower than ``rest_speed`` becomes a SLIDER: its height is held at the static
penetration and it slides frictionlessly downhill in closed form (its normal oscillation,
below the rest energy, is dropped: the energy removed is counted in
``stats["rest_energy_removed"]``, ``energy``). A slider that something approaches joins the
active set again, at its static state (an equilibrium of the full model, so nothing jumps).
With friction (rigid plate) a resting group in static equilibrium within its Coulomb and
rolling limits is frozen instead, a fixed obstacle for the balls that move on it, and a
frozen ball is woken by a touch or by a load it cannot bear (``sleep``).

Contacts are recorded as ``Impact`` (one per ball per contact; ``end`` an ``End``:
separated, rest, left or duration; ``records``); the plate's contact forces are kept as
piecewise-linear histories at their contact points and sliders as dead loads, for the modal
plate's sensors (``loads``). The run's time and counters are its ``clock``; this module wires
the parts into the loop and holds its work bounds and the entry point.
"""

import contextlib
import time as _time
from dataclasses import dataclass, field, replace

import numpy as np

from tailbeam.errors import InputError, WorkLimitError, require_positive
from tailbeam.physics.contact_law import HERTZ_EXPONENT
from tailbeam.physics.contacts import LawOptions, contact_table
from tailbeam.physics.incline import InclinedPlate
from tailbeam.progress import note, quiet, task
from tailbeam.solvers.stream.active.friction_pairs import FrictionPairs
from tailbeam.solvers.stream.active.islands import Islands
from tailbeam.solvers.stream.active.members import ActiveMembers
from tailbeam.solvers.stream.driver.balls import GONE, PENDING, SLIDE, Balls
from tailbeam.solvers.stream.driver.clock import Clock
from tailbeam.solvers.stream.driver.energy import EnergyLedger
from tailbeam.solvers.stream.driver.frames import FrameRecorder
from tailbeam.solvers.stream.driver.heap import Predictions
from tailbeam.solvers.stream.driver.heap_events import HeapEvents
from tailbeam.solvers.stream.driver.loads import PlateLoads
from tailbeam.solvers.stream.driver.membership import Membership
from tailbeam.solvers.stream.driver.records import ContactRecords
from tailbeam.solvers.stream.driver.set_events import SetEvents
from tailbeam.solvers.stream.driver.sleep import Sleepers

DEFAULT_RTOL = 1e-10
DEFAULT_REST_SPEED = 0.01  # m/s, the rigid and coupled solvers' value
DEFAULT_MAX_STEPS = 50_000_000  # kernel steps + events: the work bound
MAX_PARTICLES = 200_000  # per scene: memory ~40 kB per particle (records, force histories)
GRAZING_RETRIES = 2  # runs again at rtol / 10, / 100 after a stall at one instant: a last
# safety net (the kernel does not find an event again at the instant it applied it)
WORK_CHECK_EVERY = 16  # loop rounds between two checks of the work bound
STUCK_LIMIT = 5_000  # loop rounds without time moving before the run is stopped
_ISLANDS = True  # with friction on the rigid plate: the active set as islands (``islands``);
# a private switch (False: one set, as on the modal plate) for comparisons


@dataclass
class StreamRun:
    """What the stream driver found (``tailbeam.solvers.stream.solver`` makes it a Result).

    Attributes
    ----------
    particles : list of Particle
        The particles as released (a release onto a rebounding ball is postponed).
    contacts : list of Impact
        One record per ball per contact, in order of start and ball; ``end`` an ``End``.
    leaves : list of LeaveEvent
        The balls that left the plate over an edge.
    events : list of Event
        Every event in time order.
    loads : list of tuple
        (x m, y m, t_nodes (k,) s, forces (k,) N): plate contact force histories.
    dead_loads : list of tuple
        (x m, y m, t_from s, t_to s, force N): the sliders' weight on the plate.
    status : int
        0: the end of the simulated time was reached.
    message : str
        What ``status`` means.
    stats : dict
        Work counters and the energy ledger (J).
    frames : BallFrames or None
        Every ball's state at the frame times asked for (``solve_stream(frames=...)``).
    angular_velocity : dict
        With friction: every ball's angular velocity (3,) rad/s when it left or at the end,
        by name (empty without friction).
    final : dict
        Name -> (position (3,) m, velocity (3,) m/s) at the end of every ball still on the
        plate (released, not gone).
    """

    particles: list
    contacts: list
    leaves: list
    events: list
    loads: list
    dead_loads: list
    status: int
    message: str
    stats: dict = field(default_factory=dict)
    frames: object = None
    angular_velocity: dict = field(default_factory=dict)
    final: dict = field(default_factory=dict)


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
    frames=(),
    friction=None,
    sleep=True,
    loads=True,
) -> StreamRun:
    """Simulate a stream of particles on an inclined plate.

    Parameters
    ----------
    particles : list of Particle
        ``tailbeam.streams.generator.Particle``: released at their t_release (s) with their
        position (m) and velocity (m/s), plate frame.
    incline : InclinedPlate
        The plate and gravity.
    duration : float
        Simulated time (s).
    damping, penetration, clamp, exponent : float, float, bool, float
        IMPACT parameters shared by every pair: damping c (N s/m), full-damping penetration
        d (m), the clamp, Hertz exponent (stiffness from Hertz for each pair).
    rtol : float
        The active set's relative tolerance, in [1e-14, 1e-4].
    rest_speed : float
        Speed (m/s) below which a plate contact ends at rest (see the module docstring).
    max_work : int
        Bound on kernel steps plus events (``WorkLimitError`` beyond).
    progress : bool or callable
        Show a progress bar, or a callable told the simulated time reached (s).
    plate : StreamPlate, optional
        The two-way modal plate (None: the rigid plate).
    contacts : ContactTable or LawOptions, optional
        The particles' contact laws (their settings then replace the IMPACT parameters).
    frames : sequence of float
        Frame times (s, increasing, within [0, duration]) at which every ball's state is
        recorded (``StreamRun.frames``); the integration stops at each, so a run with frames
        agrees with one without to the tolerance ``rtol``, not bit for bit.
    friction : FrictionModel, optional
        Friction and rolling resistance of every contact, the balls' rotation
        (``tailbeam.physics.friction``; on the modal plate also between the balls and the
        plate's top surface, the force's moment driving the modes). None: frictionless.
        With friction no contact is put at rest by ``rest_speed`` or SETTLE: a ball on the
        plate is integrated while it touches it, until its cluster is frozen (``sleep``, on
        the rigid plate only).
    sleep : bool
        With friction on the rigid plate: freeze resting clusters
        (``tailbeam.solvers.stream.driver.sleep``); False integrates them for as long as
        they rest.
    loads : bool
        Keep the plate loads (``StreamRun.loads`` and ``dead_loads``) for a replay on a
        modal plate; False keeps none (both empty; every other output the same). Kept, their
        force nodes are bounded (``driver.loads.MAX_LOAD_NODES``, WorkLimitError beyond).

    Returns
    -------
    StreamRun
        The records, loads and counters (``stats["rtol"]``: the tolerance used; it is
        tightened when contacts stall at one instant).
    """
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
        sim = _Stream(particles, incline, duration, contacts, rtol, rest_speed, max_work, plate,
                      friction, frames, sleep, loads)  # fmt: skip
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
    (``tailbeam.solvers.stream.active.compiled.kernel.advance``); the retry is a safety net."""


class _CallbackBar:
    """A progress 'bar' that reports the simulated time reached (s) to a callable."""

    def __init__(self, report):
        self.report, self.ms = report, 0.0

    def update(self, ms):
        self.ms += ms
        self.report(self.ms / 1e3)


class _Stream:
    """The event loop of one run, wiring the driver's parts (see the module docstring).

    Parameters
    ----------
    particles : list of Particle
        The stream's particles.
    incline : InclinedPlate
        The plate and gravity.
    duration : float
        Simulated time (s).
    contacts : ContactTable
        The particles' contact laws.
    rtol : float
        The active set's relative tolerance.
    rest_speed : float
        Speed (m/s) below which a plate contact ends at rest.
    max_events : int
        Bound on kernel steps plus events (WorkLimitError beyond).
    plate : StreamPlate or None
        The two-way modal plate, or None (the rigid plate).
    friction : FrictionModel or None
        The contacts' friction (rigid plate), or None.
    frames : sequence of float
        Frame times (s) at which every ball's state is recorded (``FrameRecorder``).
    sleep : bool
        With friction: freeze resting clusters (``Sleepers``).
    loads : bool
        Keep the plate loads (``PlateLoads``).
    """

    def __init__(self, particles, incline, duration, contacts, rtol, rest_speed, max_events, plate,
                 friction=None, frames=(), sleep=True, loads=True):  # fmt: skip
        self.clock = clock = Clock(duration)
        self.balls = balls = Balls(particles, incline, contacts)
        self.plate, self.max_events, self.rounds = plate, max_events, 0
        pairs, sleep = None, sleep and friction is not None and plate is None
        hop_speed = rest_speed  # a plate contact ending slower than this holds the ball
        if friction is not None:
            pairs = FrictionPairs(friction, [p.material.name for p in particles], balls.radius,
                                  incline.plate.material.name)  # fmt: skip
            rest_speed = 0.0  # (no SETTLE, no slider: the ball rolls, slides or is held)
            hop_speed = hop_speed if sleep else 0.0  # (held on the plate, integrated on)

        def settle_energy(i: int) -> float:
            return 0.5 * balls.mass[i] * rest_speed**2

        if pairs is not None and plate is None and _ISLANDS:  # each island its own step
            self.act = act = Islands(balls, rtol, settle_energy, pairs)
        else:
            self.act = act = ActiveMembers(balls, rtol, settle_energy, plate,
                                           lambda: balls.resting(clock.t), pairs)  # fmt: skip
        self.ledger = EnergyLedger(balls, act, clock.stats)
        self.records = ContactRecords(balls, act, clock, rest_speed)
        self.loads = PlateLoads(balls, act.forces, loads)
        self.heap = Predictions(balls, clock, plate)
        parts = (balls, act, clock, self.heap)
        sleepers = None
        if sleep:
            sleepers = Sleepers(*parts, self.records, self.loads, self.ledger)
        self.membership = Membership(*parts, self.records, self.loads, self.ledger, plate,
                                     sleepers)  # fmt: skip
        shared = (*parts, self.membership, self.records, self.loads, self.ledger)
        self.set_events = SetEvents(*shared, hop_speed)
        self.heap_events = HeapEvents(*shared, plate)
        self.frames = FrameRecorder(frames, balls, act)

    def run(self, bar) -> StreamRun:
        """Run to the end; ``bar.update(ms)`` is told the simulated time reached."""
        wall = _time.perf_counter()
        clock, act, heap = self.clock, self.act, self.heap
        heap.start()
        shown, stuck, t_last = 0.0, 0, -1.0
        while True:
            self._check_work()
            stuck = stuck + 1 if clock.t == t_last else 0
            t_last = clock.t
            if stuck > STUCK_LIMIT:
                raise _Stuck(self._stuck_message())
            t_next = heap.next_time()
            target = min(t_next, clock.duration, self.frames.next_time)
            if act.members and self.set_events.advance(target):
                continue
            clock.t = act.now = target
            if clock.t - shown > 1e-3:
                bar.update(1e3 * (clock.t - shown))
                shown = clock.t
            if target < t_next or t_next >= clock.duration:  # a frame time or the end
                self.frames.take(target)  # after the heap events due at that time
                if target >= clock.duration:
                    break
                continue
            entry = heap.pop()
            if entry is not None:
                self.heap_events.handle(entry)
        bar.update(1e3 * (clock.duration - shown))
        return self._finish(_time.perf_counter() - wall)

    def _stuck_message(self) -> str:
        """The loop has not moved time for STUCK_LIMIT rounds: what is going on."""
        names = [self.balls.names[i] for i in sorted(self.membership.core)][:4]
        return (
            f"rtol: the stream solver makes no progress at t = {self.clock.t:.9g} s: contacts "
            f"of {', '.join(names)} start and end again at one instant (a grazing contact the "
            "event restart cannot resolve, a known limitation); a tighter rtol resolves it"
        )

    def _check_work(self):
        self.rounds += 1
        if self.rounds % WORK_CHECK_EVERY:
            return
        stats = self.clock.stats
        self.loads.check(self.clock.t)
        n = stats["heap_events"] + stats["set_events"] + self.act.steps()
        if n > self.max_events:
            raise WorkLimitError(
                f"max_steps: more than {self.max_events} steps and events by "
                f"t = {self.clock.t:.6g} s; raise max_steps, shorten duration or lower the "
                "stream rates"
            )

    def _released(self) -> list:
        """The particles with their actual release times and positions."""
        b = self.balls
        out = []
        for q, p in enumerate(b.particles):
            if b.t_release[q] != p.t_release:
                p = replace(p, t_release=float(b.t_release[q]))
            if np.any(b.release_position[q] != np.asarray(p.position)):
                p = replace(p, position=tuple(float(c) for c in b.release_position[q]))
            out.append(p)
        return out

    def _finish(self, wall: float) -> StreamRun:
        """The end of the simulated time: final energies, the records and loads of what is
        still in progress, the counters."""
        b, act, stats, loads = self.balls, self.act, self.clock.stats, self.loads
        duration = self.clock.t = self.clock.duration
        self.ledger.final(duration)
        if self.plate is not None:
            self.plate.propagate(duration)
            # the tails of contacts still in progress are the plate's too (contact_tail)
            stats["energy_plate_final"] = self.plate.energy() + act.tail_energy()
            if self.plate.tail is not None:
                stats["tail_energy_dropped"] = act.tail_energy_dropped
        self.records.finish()
        for i in act.members:
            loads.flush(i)
        for i in np.flatnonzero(b.status == SLIDE):
            if not b.in_set[i]:
                loads.dead_load(int(i), duration)
        stats.update(act.stats())
        if self.membership.sleepers is not None:
            stats["asleep_final"] = self.membership.sleepers.asleep()
        stats["wall_s"] = wall
        stats["contacts"] = len(self.records.contacts)
        rec = self.records
        spins = {}
        if act.friction is not None:
            act.sync_spins()
            spins = {name: b.w[q].copy() for q, name in enumerate(b.names)}
        return StreamRun(
            self._released(), rec.contacts, rec.leaves, rec.events, loads.loads,
            loads.dead_loads, 0, "reached the end of the simulated time", stats,
            frames=self.frames.frames if len(self.frames.frames.times) else None,
            angular_velocity=spins, final=self._final_states(duration),
        )  # fmt: skip

    def _final_states(self, t: float) -> dict:
        """Name -> (x, v) at time t (s) of the balls released and not gone."""
        b, out = self.balls, {}
        for i in np.flatnonzero((b.status != GONE) & (b.status != PENDING)):
            i = int(i)
            x, v = self.act.state(i) if b.in_set[i] else b.state(i, t)
            out[b.names[i]] = (np.array(x, dtype=float), np.array(v, dtype=float))
        return out
