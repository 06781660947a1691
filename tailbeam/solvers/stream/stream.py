"""The fast stream solver: many balls on the rigid inclined plate, cost growing with impacts.

Event-driven. Balls that touch nothing move in closed form (``tailbeam.solvers.stream.flight``) and
carry predictions in one heap: release, plate touch, edge crossing and, among the candidate
pairs of the current epoch (``tailbeam.solvers.stream.broadphase``, certified over the epoch), the
first touch of two balls. The balls in contact, and every ball that could reach one of them
within the set's horizon, form the ACTIVE SET, integrated by the compiled kernel
(``tailbeam.solvers.stream.active_set``: DOP853, every kink an event) up to the next heap event, its
horizon or its own next event. Work is therefore spent per contact and per event, never per
ball per step; memory holds the records, not the trajectories.

Persistent contact at bounded cost: a ball whose plate contact has settled (the kernel's
SETTLE: its normal excess energy below 1/2 m rest_speed^2) or that rebounds slower than
``rest_speed`` becomes a SLIDER: its height is held at the static penetration and it slides
frictionlessly downhill in closed form (its normal oscillation, below the rest energy, is
dropped: the energy removed is counted in ``stats["rest_energy_removed"]``). A slider that
something approaches joins the active set again, at its static state (an equilibrium of the
full model, so nothing jumps).

Contacts are recorded as ``ContactRecord`` (one per ball per contact; ``end`` is
``separated``, ``rest``, ``left`` or ``duration``); the plate's contact forces are kept as
piecewise-linear histories at their contact points and sliders as dead loads, for the modal
plate's sensors.
"""

import contextlib
import heapq
import math
import time as _time
from dataclasses import dataclass, field, replace

import numpy as np

from tailbeam.errors import InputError, WorkLimitError, require_positive
from tailbeam.physics.contact_law import HERTZ_EXPONENT, elastic_energy
from tailbeam.physics.contacts import contact_table
from tailbeam.physics.incline import InclinedPlate
from tailbeam.progress import note, quiet, task
from tailbeam.solvers.records import PLATE, Event, EventKind, LeaveEvent
from tailbeam.solvers.stream.broadphase import candidate_pairs
from tailbeam.solvers.stream.stream_records import StreamRecords
from tailbeam.solvers.stream.stream_state import ACTIVE, FLY, GONE, SLIDE, Balls, LawOptions

DEFAULT_RTOL = 1e-10
DEFAULT_REST_SPEED = 0.01  # m/s, the rigid and coupled solvers' value
DEFAULT_MAX_STEPS = 50_000_000  # kernel steps + events: the work bound
MAX_PARTICLES = 200_000  # per scene: memory ~40 kB per particle (records, force histories)
GRAZING_RETRIES = 2  # runs again at rtol / 10, / 100 after a grazing contact stalls it
WORK_CHECK_EVERY = 16  # loop rounds between two checks of the work bound
STUCK_LIMIT = 5_000  # loop rounds without time moving before the run is stopped
SET_HORIZON = 1e-3  # s: the active set looks this far ahead for balls that could reach it
RELEASE_RETRY = 1e-3  # s: a particle that would overlap a ball at its release waits this long
SHAPE_TRAVEL = 1e-3  # m: modal plate: mode shapes refreshed after this much lateral travel
# heap event kinds (the order breaks ties at equal times: releases first)
_RELEASE, _EPOCH, _PLATE, _PAIR, _EDGE = range(5)


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


def simulate_stream(
    particles, incline: InclinedPlate, duration: float, *, laws, rtol: float = DEFAULT_RTOL,
    max_steps: int = DEFAULT_MAX_STEPS, progress=True, rest_speed: float = DEFAULT_REST_SPEED,
    plate=None,
):  # fmt: skip
    """The stream solver as ``tailbeam.solvers.stream.engine`` calls it: a ``StreamResult``.

    laws: the particles' ``ContactTable`` (``Scene.contacts()``) or the IMPACT settings
    shared by every pair (``tailbeam.scene.ContactSettings``: exponent, damping,
    penetration, clamp). progress: True (a bar), False, or a callable taking the simulated
    time reached (s)."""
    from tailbeam.solvers.stream.stream_result import StreamResult

    contacts = contact_table(particles, laws, incline.plate.material)
    run = solve_stream(
        particles, incline, duration, rtol=rtol, rest_speed=rest_speed,
        max_work=max_steps, progress=progress, plate=plate, contacts=contacts,
    )  # fmt: skip
    result = StreamResult(
        run.particles, run.contacts, run.leaves, run.events, incline, duration,
        status=run.status, message=run.message, stats=run.stats,
        info={"solver": "fast stream solver (event-driven, active-set DOP853)"},
    )  # fmt: skip
    result.loads = (run.loads, run.dead_loads)
    return result


def estimate(n_particles: int, max_steps: int) -> tuple[float, float]:
    """Upper-bound-style estimates (bytes, s) for ``tailbeam.simulation``'s preflight: per
    particle ~30 contact records and force histories (~40 kB), and the measured ~5 ms of
    wall time per particle of the reference stream (benchmarks/bench_stream.py) x 4."""
    return 4e4 * n_particles + 5e7, 2e-2 * n_particles


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
    """Contacts start and end again at one instant: no progress (a grazing contact)."""


class _CallbackBar:
    """A progress 'bar' that reports the simulated time reached (s) to a callable."""

    def __init__(self, report):
        self.report, self.ms = report, 0.0

    def update(self, ms):
        self.ms += ms
        self.report(self.ms / 1e3)


class _Stream(StreamRecords):
    """The event loop; see the module docstring."""

    def __init__(self, particles, incline, duration, contacts, rtol, rest_speed, max_events, plate):
        from tailbeam.solvers.stream.active_members import ActiveMembers

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
        self.open = {}  # (i, j) -> [ContactRecord(s)] of the contacts in progress
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

    def push(self, t, kind, i=-1, j=-1, edge=""):
        vi = self.balls.version[i] if i >= 0 else 0
        vj = self.balls.version[j] if j >= 0 else 0
        self.seq += 1
        heapq.heappush(self.heap, (t, kind, self.seq, i, j, vi, vj, edge))

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

    def _advance_set(self, target: float) -> bool:
        """Advance the active set towards ``target``; True if it stopped earlier (an event
        of its own, or its horizon: the loop then starts over)."""
        stop = min(target, self.set_end)
        kind, key, t_new = self.act.advance(self.t, stop)
        self.stats["set_calls"] += 1
        self.t = self.act.now = t_new
        self._check_margin()
        self._log_kinks()
        if kind is not None:
            self.stats["set_events"] += 1
            getattr(self, f"_on_{kind}")(key)
            self._refresh_set()
            return True
        if stop < target:
            self._refresh_set()
            return True
        return False

    def _log_kinks(self):
        for t, name, p in self.act.kinks:
            i, j = self.act.keys[p]
            partner = PLATE if j < 0 else self.balls.names[j]
            self.events.append(Event(t, self.balls.names[i], EventKind(name), partner))

    def _handle(self, entry):
        t, kind, _seq, i, j, vi, vj, edge = entry
        b = self.balls
        if (i >= 0 and b.version[i] != vi) or (j >= 0 and b.version[j] != vj):
            self.stats["stale"] += 1
            return
        self.stats["heap_events"] += 1
        if kind == _RELEASE:
            self._release(i)
        elif kind == _EPOCH:
            self._new_epoch()
        elif kind == _PLATE and b.status[i] == FLY and not b.in_set[i]:
            if self.plate is None:
                self._join([i], t, (i, -1))
            else:  # near the vibrating plate: the integrator finds the real start
                self._absorb(i)
                self.landing.add(i)
                self._make_core(i)
                self._refresh_set()
        elif kind == _PAIR and not (b.in_set[i] and b.in_set[j]):
            if b.status[i] in (FLY, SLIDE) and b.status[j] in (FLY, SLIDE):
                self._join([i, j], t, (min(i, j), max(i, j)))
        elif kind == _EDGE and b.status[i] in (FLY, SLIDE) and not b.in_set[i]:
            self._leave(i, edge, t)

    # --- heap events --------------------------------------------------------------------------
    def _release(self, i: int):
        b = self.balls
        if self._overlaps_at_release(i):
            self.stats["postponed_releases"] += b.t_release[i] == b.particles[i].t_release
            b.t_release[i] = self.t + RELEASE_RETRY
            self.push(b.t_release[i], _RELEASE, i)
            return
        b.set_motion(i, FLY, self.t, b.x0[i].copy(), b.v0[i].copy())
        x, v = b.state(i, self.t)
        on_plate = float(elastic_energy(b.radius[i] - x[2], b.plate_law(i)))  # released there
        self.stats["energy_released"] += self._ball_energy(i, x, v) + on_plate
        self.events.append(Event(self.t, b.names[i], EventKind.RELEASE, ""))
        self._predict(i)
        if self.act.members:
            self._refresh_set()

    def _overlaps_at_release(self, i: int) -> bool:
        """Does particle i, released now, overlap a ball already there (the generator
        only knows the free flights of earlier particles, not their rebounds)?"""
        b = self.balls
        others = b.closed_form()
        centres = b.states(others, self.t)[0] if len(others) else np.empty((0, 3))
        core = [k for k in self.act.members if b.status[k] == ACTIVE]
        if core:
            centres = np.vstack([centres, self.act.positions(core)])
            others = np.concatenate([others, np.array(core, dtype=np.int64)])
        reach = b.radius[others] + b.radius[i]
        return bool(np.any(np.sum((centres - b.x0[i]) ** 2, axis=1) < reach**2))

    def _new_epoch(self):
        """Certified candidate pairs of the closed-form balls over the next epoch."""
        b, t = self.balls, self.t
        self.stats["epochs"] += 1
        self.epoch_end = min(t + self.epoch, self.duration)
        if self.epoch_end < self.duration:
            self.push(self.epoch_end, _EPOCH)
        idx = b.closed_form()
        if len(idx) < 2:
            return
        horizon = self.epoch_end - t
        x, _ = b.states(idx, t)
        pairs = candidate_pairs(x, b.radius[idx], b.speed_bounds(idx, t, horizon), horizon)
        for a, c in pairs:
            i, j = int(idx[a]), int(idx[c])
            if not (b.in_set[i] and b.in_set[j]):
                self._predict_pair(i, j, horizon)

    def _predict(self, i: int):
        """Own events of closed-form ball i, and its touches with the other closed-form
        balls within the epoch."""
        for t_ev, what, edge in self.balls.own_events(i, self.t, self.w_margin):
            self.push(t_ev, _PLATE if what == "plate" else _EDGE, i, edge=edge)
        self._predict_pairs(i)

    def _predict_pairs(self, i: int):
        """Touches of closed-form ball i with the others within the epoch (not the pairs
        the active set watches)."""
        b, t = self.balls, self.t
        horizon = self.epoch_end - t
        others = b.closed_form()
        others = others[(others != i) & ~(b.in_set[others] & b.in_set[i])]
        if horizon <= 0.0 or not len(others):
            return
        xo, _ = b.states(others, t)
        xi, _ = b.state(i, t)
        reach = (
            b.radius[others] + b.radius[i]
            + (b.speed_bounds(others, t, horizon) + b.speed_bounds([i], t, horizon)) * horizon
        )  # fmt: skip
        for j in others[np.sum((xo - xi) ** 2, axis=1) <= reach**2]:
            self._predict_pair(i, int(j), horizon)

    def _predict_pair(self, i: int, j: int, horizon: float):
        t_ev = self.balls.pair_event(i, j, self.t, horizon)
        if math.isfinite(t_ev):
            self.push(t_ev, _PAIR, min(i, j), max(i, j))

    def _join(self, ids, t: float, key):
        """Closed-form balls ``ids`` start the contact ``key`` at time t."""
        for i in ids:
            if not self.balls.in_set[i]:
                self._absorb(i)
        self.act.start_contact(key)
        self._on_start(key)
        self._refresh_set()

    def _leave(self, i: int, edge: str, t: float):
        b = self.balls
        self.stats["energy_left"] += self._ball_energy(i, *b.state(i, t)) + self._elastic(i)
        if b.status[i] == SLIDE:
            self._dead_load(i, t)
        b.status[i] = GONE
        b.version[i] += 1
        self.leaves.append(LeaveEvent(b.names[i], t, edge))
        self.events.append(Event(t, b.names[i], EventKind.LEAVE, edge))

    # --- events of the active set -------------------------------------------------------------
    def _on_start(self, key):
        self.landing.discard(key[0])
        self._open(key)
        for k in key:
            if k >= 0:
                self._make_core(k)

    def _on_end(self, key):
        i, j = key
        for k in key:  # the set keeps its members until time moves on (no rebuild at the end
            if k >= 0:  # instant: a rebuilt set could find the same contact starting again)
                self.hold[k] = self.t
        if key not in self.open:  # a pair the set found overlapping (counted in late_starts)
            return
        if j >= 0:
            self._close(key, "separated")
            return
        others = [p for p in self.act.touching_pairs(i) if p != key]
        v_out = self.act.state(i)[1][2]
        slow = 0.0 <= v_out < self.rest_speed and self.balls.g[2] < 0.0
        if self._grazing(i):  # ends and starts again at one instant: it rests on the plate
            slow = True
            self.stats["grazing_rests"] = self.stats.get("grazing_rests", 0) + 1
        self._close(key, "rest" if slow and not others else "separated")
        self._flush_nodes(i)
        if slow and not others:
            self.stats["rest_energy_removed"] += self.act.make_quiet(i)

    def _grazing(self, i: int) -> bool:
        """The plate contact of ball i ended at this instant before (it started again at
        once: zero speed relative to the vibrating plate): the second time, True."""
        t_prev, count = self.grazing.get(i, (None, 0))
        count = count + 1 if t_prev == self.t else 1
        self.grazing[i] = (self.t, count)
        return count >= 2

    def _on_settle(self, i):
        self._close((i, -1), "rest")
        self.stats["rest_energy_removed"] += self.act.make_quiet(i)

    def _on_leave(self, what):
        i, edge = what
        b = self.balls
        self.stats["energy_left"] += self._ball_energy(i, *self.act.state(i)) + self._elastic(i)
        for key in self.act.touching_pairs(i):
            if key in self.open:
                self._close(key, "left")
        self._flush_nodes(i)
        self.act.remove(i)
        b.in_set[i] = False
        b.status[i] = GONE
        b.version[i] += 1
        self.core.discard(i)
        self.landing.discard(i)
        self.leaves.append(LeaveEvent(b.names[i], self.t, edge))
        self.events.append(Event(self.t, b.names[i], EventKind.LEAVE, edge))

    # --- membership -----------------------------------------------------------------------------
    def _persistent_to_rest(self):
        """Plate contacts older than their limit, with no other contact: at rest (their
        normal oscillation is dropped: bounded work; the energy is counted)."""
        for i, t_limit in list(self.limit.items()):
            if t_limit <= self.t and self.act.touching_pairs(i) == [(i, -1)]:
                self._on_settle(i)

    def _is_core(self, i: int) -> bool:
        if i in self.landing or self.hold.get(i) == self.t:
            return True
        return any(key in self.open for key in self.act.touching_pairs(i))

    def _make_core(self, i: int):
        """Ball i takes part in a contact: its closed-form motion ends; a ball resting on the
        plate gets its plate contact back as a record (v_in ~ 0: a resumed contact)."""
        b = self.balls
        if b.status[i] != ACTIVE:
            b.status[i] = ACTIVE
            b.version[i] += 1
        self.core.add(i)
        self.act.wake(i)
        plate = (i, -1)
        if plate not in self.open and plate in self.act.touching_pairs(i):
            self._open(plate)

    def _absorb(self, i: int):
        b = self.balls
        if b.status[i] == SLIDE:
            self._dead_load(i, self.t)
        x, v = b.state(i, self.t)
        self._audit_overlap(i, x)
        self.act.add(i, x, v, quiet=b.status[i] == SLIDE)
        b.in_set[i] = True

    def _audit_overlap(self, i: int, x):
        """Count a ball that enters the set already overlapping a member or the plate (a
        missed start: must never happen after its release; tests check stats)."""
        b = self.balls
        if self.t == b.t_release[i]:
            return
        depth = b.radius[i] - (x[2] - self._plate_deflection(x)) if b.status[i] == FLY else 0.0
        what = "plate"
        if self.act.members:
            m = np.array(self.act.members)
            d = np.linalg.norm(self.act.positions(m) - x, axis=1)
            overlap = b.radius[m] + b.radius[i] - d
            if overlap.max() > depth:
                depth, what = float(overlap.max()), b.names[int(m[np.argmax(overlap)])]
        if depth > 1e-12:
            self.stats["late_starts"] += 1
            log = self.stats.setdefault("late_start_log", [])
            if len(log) < 10:
                log.append((self.t, b.names[i], what, depth))

    def _plate_deflection(self, x) -> float:
        """The modal plate's deflection (m) under the point x now (0 for the rigid plate)."""
        if self.plate is None:
            return 0.0
        self.plate.propagate(self.t)
        return float(self.plate.shapes(x[:2])[0] @ self.plate.q)

    def _release_from_core(self, i: int):
        """Core ball i touches nothing any more (or only rests on the plate): closed form."""
        b = self.balls
        x, v = self.act.state(i)
        quiet = (i, -1) in self.act.touching_pairs(i)
        if not quiet and self.plate is not None and self._stays_near_plate(i, x, v):
            self.landing.add(i)  # it comes back within the plate's deflection bound
            return
        b.set_motion(i, SLIDE if quiet else FLY, self.t, x, v)
        if quiet:
            b.slide_since[i] = self.t
        self.core.discard(i)
        self._predict(i)

    def _stays_near_plate(self, i: int, x, v) -> bool:
        """Modal plate: does ball i's flight keep it within the margin above the plate?"""
        gn = -self.balls.g[2]
        apex = x[2] + (v[2] ** 2 / (2.0 * gn) if v[2] > 0.0 and gn > 0.0 else 0.0)
        return apex < self.balls.radius[i] + self.w_margin

    def _check_margin(self):
        """Modal plate: keep the plate-touch predictions above the plate's deflection bound;
        when it has grown past the margin, double the margin and predict again."""
        if self.plate is None:
            return
        bound = self.plate.deflection_bound()
        if bound <= self.w_margin:
            return
        self.w_margin = max(2.0 * bound, 1e-9)
        self.stats["margin_updates"] = self.stats.get("margin_updates", 0) + 1
        b = self.balls
        for i in np.flatnonzero((b.status == FLY) & ~b.in_set):
            for t_ev, what, _edge in b.own_events(int(i), self.t, self.w_margin):
                if what == "plate":
                    self.push(t_ev, _PLATE, int(i))

    def _resting_outside(self):
        """(xy (p, 2) m, weights (p,) N) of the balls resting on the plate outside the set."""
        b = self.balls
        idx = np.flatnonzero((b.status == SLIDE) & ~b.in_set)
        if not len(idx):
            return np.empty((0, 2)), np.empty(0)
        x, _ = b.states(idx, self.t)
        return x[:, :2], b.mass[idx] * -b.g[2]

    def _exit(self, i: int):
        b = self.balls
        self._flush_nodes(i)
        self.act.remove(i)
        b.in_set[i] = False
        if b.status[i] == SLIDE:
            b.slide_since[i] = self.t
        # its own events (a plate touch or edge crossing that came due while the set watched
        # it was dropped then) and its pairs with the balls the set watched
        self._predict(i)

    def _refresh_set(self):
        """Core = members with a contact in progress; members = core + every closed-form
        ball that could reach a core ball within SET_HORIZON (certified bounds)."""
        b, t = self.balls, self.t
        self.hold = {i: th for i, th in self.hold.items() if th == t}
        self._persistent_to_rest()
        for i in [i for i in self.core if not self._is_core(i)]:
            self._release_from_core(i)
        core = np.array(sorted(self.core), dtype=np.int64)
        cand = b.closed_form()
        if not len(core):
            for i in cand[b.in_set[cand]]:
                self._exit(int(i))
            self.set_end = t
            return
        h = SET_HORIZON
        # (a limit already reached waits for the ball's other contacts to end)
        limits = [self.limit[i] for i in core if i in self.limit and self.limit[i] > t]
        self.set_end = min([t + h] + limits)
        if self.plate is not None:  # mode shapes where the landing balls will touch
            self.act.refresh_shapes()
            for i in self.landing:
                lateral = float(np.hypot(*self.act.state(i)[1][:2]))
                if lateral > 0.0:
                    self.set_end = min(self.set_end, t + SHAPE_TRAVEL / lateral)
        xc = self.act.positions(core)
        # energy a core ball can receive: the core's kinetic and elastic energy, plus what
        # gravity can give in h (a 1 cm drop of every core ball: far more than they fall)
        g = np.linalg.norm(b.g)
        energy = self.act.energy(core) + np.sum(b.mass[core]) * g * 0.01
        sc = np.sqrt(2.0 * energy / b.mass[core]) + g * h
        if not len(cand):
            return
        x, _ = b.states(cand, t)
        s = b.speed_bounds(cand, t, h)
        d2 = np.sum((x[:, None, :] - xc[None, :, :]) ** 2, axis=2)
        reach = b.radius[cand][:, None] + b.radius[core][None, :] + (s[:, None] + sc) * h
        near = np.any(d2 <= reach**2, axis=1)
        for i in cand[near & ~b.in_set[cand]]:
            self._absorb(int(i))
        for i in cand[~near & b.in_set[cand]]:
            self._exit(int(i))

    def _finish(self, wall: float) -> StreamRun:
        b = self.balls
        self.t = self.duration
        self.stats["energy_final"] = self._final_energy()
        if self.plate is not None:
            self.plate.propagate(self.duration)
            self.stats["energy_plate_final"] = self.plate.energy()
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
